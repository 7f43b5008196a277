"""A recording case, step by step: open, speed, simulate, fixed path, background, measure, rows.

Each step is one function with plain inputs, so the defect identification that follows
(many candidate geometries against one recording) reuses :func:`prepare` (the
recording side, done once), :func:`simulate_signals` (one candidate through the fixed
path and background) and :func:`evaluate_rows`.

Public API
----------
Prepared                                  -- recording, speed, bearing, scene, measurements, simulation
prepare(case, *, mirror=None) -> Prepared -- recording opened and measured; declared scene simulated
simulate_signals(prep, path, background, *, scene=None) -> (signals, datasets)
measure_signals(prep, signals) -> {signal: measure() dict}
evaluate_rows(case, tolerances, exp, sim, *, context, group="") -> rows
run_recording_case(case, *, steps, mirror=None) -> CaseResult
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..analysis.measurement import measure
from . import simulation
from .quantities import QUANTITIES, value_of
from .recording import open_spec
from .rows import make_row
from .speed import resolve_speed

__all__ = ["Prepared", "prepare", "simulate_signals", "measure_signals", "evaluate_rows", "run_recording_case",
           "CaseResult"]


@dataclass
class CaseResult:
    """What a case computed, for the report and summary.json."""

    rows: list
    comparison: object
    extra: dict = field(default_factory=dict)
    provenance: dict = field(default_factory=dict)
    sections: list = field(default_factory=list)   # (kind, title, payload) in page order
    path: object = None


@dataclass
class Prepared:
    case: object
    recording: object
    speed: object
    bearing: object
    scene: object
    n: int
    measured: dict                                  # "record", "segment" -> measure() dict
    simulated: dict = field(default_factory=dict)   # "model" -> the declared scene's signal
    dataset: object = None

    @property
    def fs(self) -> float:
        return self.recording.fs

    @property
    def fault(self):
        return self.measured["record"]["extras"]["fault"]


def scene_overrides(case) -> dict:
    return {} if case.section("structural_path").get("method") == "none" else dict(simulation.SENSOR_OFF)


def declared_fault(case):
    """The fault family of the case's declared defects: "bpfo" (outer race), "bpfi" (inner race), or None
    (healthy, ball defects, or defects on both races)."""
    defects = case.data.get("defect") or []
    defects = [defects] if isinstance(defects, dict) else defects
    keys = {{"outer": "bpfo", "inner": "bpfi"}.get(str(d.get("race", "outer"))) for d in defects}
    return keys.pop() if len(keys) == 1 else None


def prepare(case, *, mirror=None) -> Prepared:
    """Open and measure the case's recording, resolve the speed, simulate the declared scene."""
    rec = open_spec(case.recording, case.name, mirror)
    fs = rec.fs
    probe = simulation.build_scene(case, rpm=1800.0, fs=fs, duration=0.1)
    speed = resolve_speed(case.speed, rec.dataset, rec.x, bearing=probe.bearing, case_name=case.name)
    n = int(round(case.recording.duration_s * fs))
    # the speed is known (given, stored or estimated): the fault lines are searched around it
    kw = {"bearing": probe.bearing, "rpm": speed.rpm, "shaft_hz": speed.rpm / 60.0}
    m_rec = measure(rec.x, fs, **kw)
    declared = declared_fault(case)
    fam = m_rec["extras"]["families"].get(declared or "", {})
    if m_rec["extras"]["fault"] is None and fam.get("detected"):
        # the blind diagnosis abstained, but the declared defect's family is detected (by the
        # noise rule and the decoys) on a route: its impacts are timed on that family
        m_rec = measure(rec.x, fs, fault=declared, **kw)
        m_rec["extras"]["notes"]["fault"] = (
            f"the blind diagnosis is {m_rec['extras']['analysis']['diagnosis']}; the impacts are timed on the "
            f"declared defect's {declared.upper()} family, which the {fam['route']} route detects")
    m_seg = measure(rec.segment(n), fs, fault=m_rec["extras"]["fault"], **kw)
    scene = simulation.build_scene(case, rpm=speed.rpm, fs=fs, duration=n / fs, overrides=scene_overrides(case))
    ds = simulation.run(scene)
    return Prepared(case, rec, speed, probe.bearing, scene, n, {"record": m_rec, "segment": m_seg},
                    {"model": simulation.signal(ds)[:n]}, ds)


def simulate_signals(prep, path, background, *, scene=None, seed=None):
    """The three compared simulation signals of ``scene`` (default: the declared one, already run).

    Returns ``{"model", "path", "path+background"}`` arrays of ``prep.n`` samples; the path and
    the background are the fixed ones, never re-fitted here.
    """
    if scene is None:
        x = prep.simulated["model"]
    else:
        x = simulation.signal(simulation.run(scene))[: prep.n]
    xp = path.apply(x, prep.fs)
    seed = int(prep.case.section("background").get("seed", 0)) if seed is None else seed
    xb = xp + background.synthesize(x.size, seed=seed) if background is not None else xp
    return {"model": x, "path": xp, "path+background": xb}


def measure_signals(prep, signals: dict) -> dict:
    """The simulation signals measured as the recording is; impulse durations in the recording's band."""
    rpm = prep.speed.rpm
    band = prep.measured["segment"]["extras"]["band"]
    return {k: measure(v, prep.fs, bearing=prep.bearing, rpm=rpm, shaft_hz=rpm / 60.0, fault=prep.fault,
                       duration_band=band) for k, v in signals.items()}


def _notes(q, sim_m, exp_m) -> str:
    if not isinstance(q.measured, str):
        return ""
    parts = []
    for who, m in (("simulation", sim_m), ("recording", exp_m)):
        if q.measured in m["extras"]["notes"]:
            parts.append(f"{who}: " + m["extras"]["notes"][q.measured])
    margins = [(who, m["extras"].get("families", {}).get(q.measured, {}).get("evidence_margin_score"))
               for who, m in (("simulation", sim_m), ("recording", exp_m))]
    if any(v is not None for _, v in margins):
        parts.append("family evidence score over the decoy threshold (a sum of line-to-floor ratios in dB over "
                     "the family's lines: a score, not a level): " + ", ".join(
                         f"{who} {v:+.1f}" for who, v in margins if v is not None))
    return "; ".join(parts)


def evaluate_rows(tolerances: dict, exp: dict, sim: dict, *, context: dict, group="") -> list:
    """Rows for the case's tolerances from measured dicts.

    ``exp``: span -> measure() dict of the recording; ``sim``: signal -> measure() dict.
    ``context``: ``path`` (StructuralPath), ``path_fitted_here``, ``speed_estimated`` and
    ``background_from_recording`` (bools: the number then is not independent evidence),
    ``ratio`` (companion: {"experiment": value, "simulation": value, "label": str}) and
    ``span_text`` (span -> description).
    """
    rows = []
    path = context["path"]
    for key, tol in tolerances.items():
        q = QUANTITIES[key]
        s, e = value_of(q, sim[q.signal]), value_of(q, exp[q.span])
        note = _notes(q, sim[q.signal], exp[q.span])
        if q.ratio:
            other = context.get("ratio") or {}
            s = s / other["simulation"] if other.get("simulation") else float("nan")
            e = e / other["experiment"] if other.get("experiment") else float("nan")
            note = other.get("note", "")
        untrusted = ""
        if q.signal != "model" and path.status in ("degraded", "failed"):
            untrusted = f"the structural path is {path.status} (" + "; ".join(path.problems) + ")"
        independent = not ((q.path_fit and context.get("path_fitted_here"))
                           or (key == "shaft_hz" and context.get("speed_estimated"))
                           or (q.signal == "path+background" and context.get("background_from_recording")))
        label = (f"{group}: " if group else "") + q.label + (f" ({context['ratio']['label']})" if q.ratio else "")
        rows.append(make_row((f"{group}: " if group else "") + key, s, e, tol, label=label, units=q.units,
                             note=note, signal=q.signal, span=context["span_text"][q.span],
                             independent=independent, untrusted=untrusted,
                             absence_agrees=key in ("bpfo", "bpfi")))
    return rows


def run_recording_case(case, *, steps, mirror=None) -> CaseResult:
    """Run a recording case (see the module docstring); the report is assembled by the caller."""
    from . import recording_parts as parts
    prep = prepare(case, mirror=mirror)
    steps.step("recording and declared scene")
    from .rig import background_for, path_for
    path = path_for(case, prep.recording, prep.measured["record"], prep.simulated["model"], mirror=mirror)
    reference = open_spec(case.reference, case.name, mirror) if case.reference is not None else None
    model = path.apply(prep.simulated["model"], prep.fs) if path.status in ("ok", "given") else None
    background = background_for(case, prep.recording, prep.measured["record"], reference, model=model)
    steps.step("structural path and background")
    signals = simulate_signals(prep, path, background)
    sim_m = measure_signals(prep, signals)
    context = parts.context(case, prep, path, background)
    if "ratio" in case.data:
        context["ratio"] = parts.ratio_companion(case, prep, path, mirror=mirror)
    rows = evaluate_rows(case.tolerances, prep.measured, sim_m, context=context)
    steps.step("measure and compare")
    healthy = parts.healthy_reference(case, prep, path, background, reference) if reference is not None else None
    if healthy:
        rows += healthy["rows"]
    err = (simulation.numerical_error(prep.scene, prep.dataset,
                                      duration=float(case.section("numerical_error").get("duration_s", 0.25)))
           if case.section("numerical_error").get("enabled", True) else {})
    steps.step("numerical error")
    return parts.assemble(case, prep, path, background, signals, rows, err, healthy, context)


def compare_candidates(prep, path, background, candidates: dict, *, tolerances=None, context=None) -> dict:
    """Rows of candidate defect geometries against the recording, through the *same* fixed path and
    background (never re-fitted per candidate).

    ``candidates``: label -> scene keys (``{"defect.offset_mm": 0.33}``) applied to the case's scene.
    Returns label -> rows.
    """
    case = prep.case
    tolerances = tolerances or case.tolerances
    ctx = context or {"path": path, "span_text": {"record": "recording: whole record", "segment": "recording: segment"}}
    out = {}
    for label, ov in candidates.items():
        scene = simulation.build_scene(case, rpm=prep.speed.rpm, fs=prep.fs, duration=prep.n / prep.fs,
                                       overrides={**scene_overrides(case), **ov})
        sig = simulate_signals(prep, path, background, scene=scene)
        out[label] = evaluate_rows({k: v for k, v in tolerances.items() if not QUANTITIES[k].ratio},
                                   prep.measured, measure_signals(prep, sig), context=ctx)
    return out
