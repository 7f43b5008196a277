"""A recording case's rows: measured quantities of both sides against the case's tolerances.

Public API
----------
CaseResult                                               -- what a case computed, for the report and summary.json
context(case, prep, path, background=None) -> dict       -- what the rows need to know about their evidence
evaluate_rows(tolerances, exp, sim, *, context, group="") -> rows
compare_candidates(prep, path, background, candidates, *, tolerances=None, context=None) -> {label: rows}
"""
from __future__ import annotations

from dataclasses import dataclass, field

from . import simulation
from .quantities import QUANTITIES, value_of
from .recording_case import measure_signals, scene_overrides, simulate_signals
from .rows import make_row

__all__ = ["CaseResult", "context", "evaluate_rows", "compare_candidates"]


@dataclass
class CaseResult:
    """What a case computed, for the report and summary.json."""

    rows: list
    comparison: object
    extra: dict = field(default_factory=dict)
    provenance: dict = field(default_factory=dict)
    sections: list = field(default_factory=list)   # (kind, title, payload) in page order
    path: object = None


def context(case, prep, path, background=None) -> dict:
    sp = case.section("structural_path")
    fitted_here = sp.get("method", "fit") == "fit" and not sp.get("from_case") and not sp.get("file")
    rec = prep.recording
    t0 = rec.spec.start_s
    from_rec = background is not None and background.source.startswith("the recording")
    return {"path": path, "path_fitted_here": fitted_here, "speed_estimated": case.speed == "estimate",
            "background_from_recording": from_rec,
            "span_text": {"record": f"recording: whole record ({rec.x.size / rec.fs:.3g} s)",
                          "segment": f"recording: {t0:g}-{t0 + prep.n / rec.fs:g} s"}}


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
