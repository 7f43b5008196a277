"""A paper case: the simulation against the figures a paper reports (its experiment and its studies).

The experiment column holds what the paper *measured* (its Table 2 lines, its impact
period, its waveform amplitudes); the kinematic value at the paper's stated speed is
shown in a separate reference column, never as the experiment.  The paper's own
simulated numbers are shown beside ours.  The section-5 studies run through a normal
import of :func:`bearing_lab.studies.paper.run_paper_studies`.

Public API
----------
run_paper_case(case, out_dir, *, steps) -> CaseResult
study_rows(case, table, reference) -> (rows, trends)  -- offset ratios and the four trends from the studies table
"""
from __future__ import annotations

import time

import numpy as np

from ..analysis.measurement import measure
from ..bearings import get_bearing
from ..compare import compare
from ..studies.paper import run_paper_studies
from ..units import G
from ..utils._files import sha256_bytes
from . import figures, simulation
from .evaluate import CaseResult
from .quantities import QUANTITIES, value_of
from .rows import make_row
from .simulation import model_details

__all__ = ["run_paper_case", "study_rows"]

_FREQ = {"shaft_hz": "shaft_hz", "bpfo": "bpfo", "bpfi": "bpfi"}


def _tolerance(case, label, q):
    return case.tolerances.get(f"{label}.{q}") or case.tolerances.get(q)


def _run_rows(case, label, m, ref, rpm, kin) -> list:
    """Rows of one run: frequencies, period and amplitude against the paper's measured figures."""
    pe = ref.get(label, {}).get("experiment", {})
    ps = ref.get(label, {}).get("simulation", {})
    rows = []
    for q in ("shaft_hz", "bpfo", "bpfi"):
        tol = _tolerance(case, label, q)
        if tol is None or q not in pe:
            continue
        kq = rpm / 60.0 if q == "shaft_hz" else kin[q]
        rows.append(make_row(f"{label}: {q}", m[q], pe[q], tol, label=f"{label}: {QUANTITIES[q].label}",
                             units="Hz", reference_value=kq, reference_label=f"kinematic at {rpm:g} r/min",
                             note=m["extras"]["notes"].get(q, ""), signal="model", span="paper, measured (Table 2)",
                             paper_simulation=ps.get(q)))
    tol = _tolerance(case, label, "excitation_period")
    if tol is not None and "excitation_period_s" in pe:
        rows.append(make_row(f"{label}: excitation_period", m["excitation_period"], pe["excitation_period_s"], tol,
                             label=f"{label}: excitation period", units="s", reference_value=1.0 / kin["bpfo"],
                             reference_label=f"1 / kinematic BPFO at {rpm:g} r/min", signal="model",
                             span="paper, measured", note=m["extras"]["notes"].get("excitation_period", ""),
                             paper_simulation=ps.get("excitation_period_s")))
    tol = _tolerance(case, label, "peak_model")
    if tol is not None and "amplitude_g" in pe:
        rows.append(make_row(f"{label}: peak_model", value_of(QUANTITIES["peak_model"], m), pe["amplitude_g"] * G,
                             tol, label=f"{label}: waveform amplitude (max |a| of the simulation)", units="m s-2",
                             signal="model", span="paper, measured (read from its waveform figure)",
                             note=f"the paper gives 'about ±{pe['amplitude_g']:g} g' for its experiment",
                             paper_simulation=(ps.get("amplitude_g") or float("nan")) * G))
    return rows


def _trend_rows(study, label, acc, dur):
    def vals(s, arr):
        return [float(a) for st, a in zip(study, arr) if st == s], [lb for st, lb in zip(study, label) if st == s]

    trends = []
    for s, what, arr, up, paper in (
            ("size", "excitation duration", dur * 1e3, True, "T1 < T2 < T3"),
            ("size", "peak acceleration", acc, True, "amplitude grows with size"),
            ("offset", "peak acceleration", acc, False, "amplitude falls as H grows (28.82, 22.48, 15.64 g)"),
            ("skew", "excitation duration", dur * 1e3, False, "duration falls as θ grows"),
            ("skew", "peak acceleration", acc, True, "amplitude grows with θ"),
            ("speed", "excitation duration", dur * 1e3, False, "duration falls with speed"),
            ("speed", "peak acceleration", acc, True, "amplitude grows with speed")):
        v, labs = vals(s, arr)
        if len(v) < 2:
            continue
        d = np.diff(v)
        unit = "ms" if "duration" in what else "g"
        trends.append({"study": s, "quantity": what, "paper reports": paper,
                       "ours": ", ".join(f"{lb}: {x:.3g} {unit}" for lb, x in zip(labs, v)),
                       "agrees": bool(np.all(d > 0) if up else np.all(d < 0))})
    return trends


def study_rows(case, table, reference):
    """Rows (the offset study's amplitude ratios) and the trend table, from the studies' Dataset."""
    study = [str(s) for s in table["study"].values]
    label = [str(s) for s in table["label"].values]
    acc = np.asarray(table["peak_acceleration"].values, float) / G
    dur = np.asarray(table["excitation_duration"].values, float)
    rows = []
    tol = case.tolerances.get("offset_ratio")
    paper = reference.get("section5", {}).get("offset_acceleration_ratios", [1.0, 0.78, 0.54])
    a = [x for s, x in zip(study, acc) if s == "offset"]
    if tol is not None and len(a) >= 3 and a[0] > 0:
        for i, h in ((1, "B/3"), (2, "B/2")):
            rows.append(make_row(f"offset_ratio_{h}", a[i] / a[0], paper[i], tol, units="1",
                                 label=f"section 5.2: peak acceleration ratio H = {h} / H = 0",
                                 signal="model", span="paper, its section 5.2 (28.82, 22.48, 15.64 g)",
                                 note=f"ours {a[0]:.3g}, {a[1]:.3g}, {a[2]:.3g} g (one passage at 100 kHz)"))
    return rows, _trend_rows(study, label, acc, dur)


def _studies(case, out_dir):
    if not case.section("studies").get("enabled", False):
        return None
    t0 = time.perf_counter()
    table = run_paper_studies(out_dir / "studies", progress=False)
    rows, trends = study_rows(case, table, case.data["_reference_data"])
    return {"rows": rows, "trends": trends, "seconds": time.perf_counter() - t0,
            "table": table.to_dataframe().reset_index().to_dict("records")}


def run_paper_case(case, out_dir, *, steps):
    ref = case.data["_reference_data"]
    rpm = float(ref["speed_rpm"])
    geom = get_bearing(case.data.get("bearing", ref.get("bearing", "6308")))
    kin = {**geom.fault_frequencies(rpm / 60.0), "shaft_hz": rpm / 60.0}
    rows, signals, figs, extra = [], {}, [], {"numerical_error": {}, "compute": {}}
    fs, prov = None, {"experiment": "figures reported by the paper: " + str(ref.get("source", ""))}
    for run in case.data["run"]:
        label = run["label"]
        scene = simulation.scene_from(run["scene"], rpm=rpm, fs=float(ref.get("sampling_rate_hz", 20000.0)),
                                      duration=float(run.get("duration_s", 1.0)), overrides=run.get("set"),
                                      case_name=case.name)
        ds = simulation.run(scene)
        fs = float(ds.attrs["sampling_rate_hz"])
        x = simulation.signal(ds)
        signals[f"simulation_{label}"] = x
        m = measure(x, fs, bearing=geom, rpm=rpm, shaft_hz=rpm / 60.0)
        rows += _run_rows(case, label, m, ref, rpm, kin)
        pe = ref.get(label, {}).get("experiment", {})
        figs.append(figures.paper_run(label, x, fs, kinematic=kin, measured=pe, amplitude_g=pe.get("amplitude_g"),
                                      paper_simulation=ref.get(label, {}).get("simulation", {})))
        if case.section("numerical_error").get("enabled", True):
            extra["numerical_error"][label] = simulation.numerical_error(
                scene, ds, duration=float(case.section("numerical_error").get("duration_s", 0.25)))
        extra["compute"][label] = {"wall_time_s": float(ds.attrs["wall_time_s"]),
                                   "compile_time_s": float(ds.attrs.get("compile_time_s", 0.0))}
        prov[f"scene ({label})"] = scene.to_toml()
        extra.setdefault("model", {})[label] = model_details(ds)
        steps.step(f"simulate {label}")
    studies = _studies(case, out_dir)
    steps.step("studies")
    if studies:
        rows += studies["rows"]
    n = min(v.size for v in signals.values())
    result = compare(signals, fs, rows, n=n, ses_fmax=1000.0,
                     attrs={"case": case.name, "kind": "paper", "bpfo_hz": kin["bpfo"], "bpfi_hz": kin["bpfi"],
                            "shaft_hz": rpm / 60.0})
    prov["reference file sha256"] = sha256_bytes(case.data["_reference_text"].encode("utf-8"))
    sections = [("rows", "Comparison table", {"rows": rows, "show_reference": True, "show_paper": True, "intro": (
        "Experiment: what the paper measured. Reference: the kinematic value at the paper's stated speed (not "
        "the experiment). The paper's own simulation is shown beside ours.")}),
        ("figures", "Waveforms and spectra (the paper's Figs 8-11)", figs + [figures.envelope_spectra(result)])]
    if studies:
        sections.append(("table", "Section 5 trends (2-D defect studies)", {"rows": studies["trends"], "intro": (
            f"From bearing_lab.studies.paper.run_paper_studies ({studies['seconds']:.1f} s); its own page with the "
            "pulse figures: studies/index.html. A trend counts as reproduced when it is monotonic over the "
            "study's three cases.")}))
        extra["studies"] = {"trends": studies["trends"], "table": studies["table"]}
    return CaseResult(rows, result, extra, prov, sections, None)
