"""A recording case run end to end: the recording and declared scene (:mod:`.recording_case`), the
rig's path and background (:mod:`.rig`), the rows (:mod:`.evaluate`), the ratio companion, the
healthy reference, and the assembly of rows, signals and figures into a
:class:`~bearing_lab.validation.evaluate.CaseResult`.

The result lists its report sections as plain data ``(kind, title, payload)``; the page
is rendered by :mod:`bearing_lab.validation.pages`.

Public API
----------
run_recording_case(case, *, steps, mirror=None) -> CaseResult
ratio_companion(case, prep, path, *, mirror=None), healthy_reference(case, prep, path, background, reference)
assemble(case, prep, *, path, background, signals, rows, numerical_error, healthy, context) -> CaseResult
"""
from __future__ import annotations

import numpy as np

from ..analysis.measurement import measure
from ..compare import align_by_impulse_phase, compare, shift
from ..units import G
from . import figures, simulation
from .case import ratio_spec
from .evaluate import CaseResult, context, evaluate_rows
from .recording import open_spec
from .recording_case import comparison_band, measure_signals, prepare, simulate_signals
from .rig import background_for, path_for
from .speed import resolve_speed

__all__ = ["run_recording_case", "ratio_companion", "healthy_reference", "assemble"]


def ratio_companion(case, prep, path, *, mirror=None) -> dict:
    """Impulse strength of the ``[ratio]`` companion: its recording, and its scene through the same path."""
    cfg = case.section("ratio")
    spec = ratio_spec(case, cfg)
    spec.duration_s, spec.start_s = case.recording.duration_s, case.recording.start_s
    rec = open_spec(spec, case.name, mirror)
    speed = resolve_speed(spec.speed, rec.dataset, rec.x, bearing=prep.bearing, case_name=case.name,
                          where="ratio.speed")
    n = int(round(spec.duration_s * rec.fs))
    m_exp = measure(rec.segment(n), rec.fs, bearing=prep.bearing, rpm=speed.rpm, shaft_hz=speed.rpm / 60,
                    fault=prep.fault)
    scene = simulation.scene_from(cfg["scene"], rpm=speed.rpm, fs=rec.fs, duration=n / rec.fs,
                                  overrides={**(cfg.get("set") or {}), **simulation.SENSOR_OFF}, case_name=case.name)
    xs = path.apply(simulation.signal(simulation.run(scene))[:n], rec.fs)
    m_sim = measure(xs, rec.fs, bearing=prep.bearing, rpm=speed.rpm, shaft_hz=speed.rpm / 60, fault=prep.fault)
    e, s = m_exp["impulse_strength"], m_sim["impulse_strength"]
    this_e, this_s = prep.measured["segment"]["impulse_strength"], None
    note = (f"median impact peaks (m s-2): recording {this_e:.3g} / {rec.path.name} {e:.3g}; the companion "
            f"simulated ({cfg['scene']}, same fixed path) {s:.3g}")
    return {"experiment": e, "simulation": s, "label": cfg.get("label", f"this / {rec.path.name}"), "note": note,
            "recording": str(rec.path), "sha256": rec.sha256, "speed": speed.source, "scene": str(cfg["scene"]),
            "simulation_this": this_s}


def _decomposition(parts: dict) -> list:
    total = parts.get("recording")
    out = []
    for label, rms in parts.items():
        out.append({"signal": label, "RMS (m s-2)": rms, "RMS (g)": rms / G,
                    "share of the recording's RMS (%)": 100.0 * rms / total if total else float("nan")})
    return out


def healthy_reference(case, prep, path, background, reference) -> dict:
    """The healthy bearing simulated against the healthy reference recording of the same rig."""
    spec_speed = reference.spec.speed if reference.spec.speed is not None else case.speed
    speed = resolve_speed(spec_speed, reference.dataset, reference.x, bearing=prep.bearing, case_name=case.name,
                          where="reference.speed")
    fs, n = prep.fs, prep.n
    xr = reference.at_rate(fs)
    scene = simulation.build_scene(case, rpm=speed.rpm, fs=fs, duration=n / fs, healthy=True,
                                   overrides=simulation.SENSOR_OFF)
    x = simulation.signal(simulation.run(scene))[:n]
    sig = {"model": x, "path": path.apply(x, fs)}
    sig["path+background"] = sig["path"] + (background.synthesize(n, seed=1) if background is not None else 0.0)
    kw = {"bearing": prep.bearing, "rpm": speed.rpm, "shaft_hz": speed.rpm / 60}
    exp = {"record": measure(xr, fs, **kw), "segment": measure(xr[:n], fs, **kw)}
    sim = {k: measure(v, fs, **kw, duration_band=exp["segment"]["extras"]["band"]) for k, v in sig.items()}
    ctx = {"path": path, "path_fitted_here": False, "speed_estimated": spec_speed == "estimate",
           "span_text": {"record": f"reference: whole record ({xr.size / fs:.3g} s)",
                         "segment": f"reference: first {n / fs:g} s"}}
    rows = evaluate_rows(case.reference_tolerances, exp, sim, context=ctx, group="healthy")
    rms = _rms_parts({"experiment": xr[:n], **sig}, background, n)
    return {"rows": rows, "decomposition": _decomposition(rms), "speed": speed.source, "signals": sig, "xr": xr[:n],
            "recording": str(reference.path), "sha256": reference.sha256}


def _rms_parts(signals, background, n) -> dict:
    rms = {"recording": float(np.nanstd(signals["experiment"])),
           "bearing model alone": float(np.nanstd(signals["model"])),
           "bearing model through the structural path": float(np.nanstd(signals["path"]))}
    if background is not None:
        rms["rig background (tones and broadband)"] = background.rms
        rms["model through the path + background"] = float(np.nanstd(signals["path+background"]))
    return rms


def _aligned(prep, signals):
    xe = prep.recording.segment(prep.n)
    m = prep.measured["record"]
    period = m["excitation_period"]
    k = (align_by_impulse_phase(xe, signals["path"], prep.fs, period, band=m["extras"]["band"])
         if np.isfinite(period) else 0)
    return {"experiment": xe, **{name: shift(v, k, prep.n) for name, v in signals.items()}}, k


def _path_table(path) -> list:
    rows = [{"parameter": f"resonance {i + 1}: frequency (Hz)", "value": r.frequency_hz} for i, r in
            enumerate(path.resonances)]
    rows += [{"parameter": f"resonance {i + 1}: damping ratio", "value": r.damping_ratio} for i, r in
             enumerate(path.resonances)]
    rows.append({"parameter": "gain (low-frequency)", "value": path.gain})
    f = path.fit
    if f.get("failed"):
        rows.append({"parameter": "not identified", "value": "; ".join(path.problems)})
    elif f:
        rows += [{"parameter": "fit residual, RMS of log-amplitude residuals (dB)", "value": f["residual_db"]},
                 {"parameter": "the same for the simulation without a path (dB)", "value": f["initial_db"]},
                 {"parameter": "impacts pooled (recording / simulation)",
                  "value": f"{f['n_impacts_recording']} / {f['n_impacts_simulation']}"}]
        rows += [{"parameter": f"search bounds: {k}", "value": f"{v[0]:.4g} to {v[1]:.4g}"}
                 for k, v in f["bounds"].items()]
        if "signature_residual_rms_db" in f:
            rows.append({"parameter": "shape residual of the impact signature, RMS (dB; removed when another "
                                      "recording is compared through this path)",
                         "value": f["signature_residual_rms_db"]})
    return rows


def _sections(prep, result, *, path, background, aligned, shift_k, healthy):
    rec = prep.recording
    secs = [("rows", "Comparison table", {"rows": result.rows})]
    intro = f"{path.source}. Status: {path.status}."
    if path.problems:
        secs.append(("notice", "Structural path", (f"The structural path is {path.status}: " + "; ".join(path.problems)
                                                   + ". Rows after the path are not trusted and fail.", "bad")))
    secs.append(("table", "Structural path", {"rows": _path_table(path), "intro": intro
                                              + " ".join(path.fit.get("notes", []) if path.fit else [])}))
    if path.resonances:
        secs.append(("figures", "Structural path", [figures.structural_path(path, prep.fs)]))
    if background is not None:
        bg = background.to_dict()
        tones = ", ".join(f"{t['frequency_hz']:.2f} Hz ({t['amplitude_m_s2'] / G:.3g} g)" for t in bg["tones"][:8])
        secs.append(("table", "Background model", {"rows": [
            {"measured on": bg["source"], "RMS (g)": bg["rms_m_s2"] / G, "tones RMS (g)": bg["rms_tones_m_s2"] / G,
             "broadband RMS (g)": bg["rms_broadband_m_s2"] / G, "strongest tones": tones or "none"}],
            "intro": "Added to the simulation after the structural path (signal 'path+background'), so RMS, crest "
                     "factor and kurtosis compare like with like (docs/validation.md, 'Background model')."}))
        secs.append(("figures", "Background model", [figures.psd_overlay(
            {"recording": aligned["experiment"], "simulation through the path": aligned["path"],
             "background": background.synthesize(prep.n), "path + background": aligned["path+background"]},
            prep.fs, "power spectral densities of the compared segment")]))
    if healthy:
        secs.append(("rows", "Healthy reference: what the bearing contributes and what the rig does",
                     {"rows": healthy["rows"]}))
        secs.append(("table", "Healthy reference: what the bearing contributes and what the rig does",
                     {"rows": healthy["decomposition"], "intro": f"Healthy simulation at {healthy['speed']}."}))
    secs.append(("table", "What the bearing contributes and what the rig does", {
        "rows": _decomposition(_rms_parts(aligned, background, prep.n)),
        "intro": "RMS over the compared segment of the recording and of each part of the simulation."}))
    figs = [figures.waveforms(aligned, prep.fs, recording_label=f"{rec.path.name} ({rec.channel})", shift=shift_k),
            figures.spectra(aligned, prep.fs), figures.envelope_spectra(result)]
    secs.append(("figures", "Waveforms, spectra and squared envelope spectra", figs))
    return secs


def assemble(case, prep, *, path, background, signals, rows, numerical_error, healthy, context):
    """The case's result: the comparison on one time base, the rows, the page's sections, the provenance."""
    ctx = context
    aligned, k = _aligned(prep, signals)
    m = prep.measured["record"]
    ff = m["extras"]["analysis"]["fault_frequencies"]
    result = compare(aligned, prep.fs, rows, n=prep.n, band=m["extras"]["band"], ses_fmax=1000.0,
                     attrs={"case": case.name, "kind": "recording", "alignment_shift_samples": k,
                            "bpfo_hz": ff["bpfo"]["expected_hz"], "bpfi_hz": ff["bpfi"]["expected_hz"],
                            "shaft_hz": prep.speed.rpm / 60.0, "speed_source": prep.speed.source,
                            "structural_path": path.to_dict()})
    ds = prep.dataset
    extra = {"speed": {"rpm": prep.speed.rpm, "source": prep.speed.source}, "model": simulation.model_details(ds),
             "structural_path": path.to_dict(), "background": background.to_dict() if background else None,
             "numerical_error": numerical_error, "ratio": {k_: v for k_, v in (ctx.get("ratio") or {}).items()},
             "healthy": {"decomposition": healthy["decomposition"], "speed": healthy["speed"]} if healthy else None,
             "compute": {"wall_time_s": float(ds.attrs["wall_time_s"]),
                         "compile_time_s": float(ds.attrs.get("compile_time_s", 0.0)),
                         "solver_rtol": float(ds.attrs.get("solver_rtol", float("nan"))),
                         "solver_steps": int(ds.attrs.get("solver_steps", 0))}}
    rec = prep.recording
    prov = {"recording file": str(rec.path), "recording sha256": rec.sha256, "channel": rec.channel,
            "reader": rec.dataset.attrs.get("reader", ""), "calibration factor": rec.spec.scale,
            "speed": prep.speed.source, "structural path": path.source, "scene": prep.scene.to_toml()}
    if healthy:
        prov["healthy reference"] = f"{healthy['recording']} (sha256 {healthy['sha256']})"
    if ctx.get("ratio"):
        prov["ratio companion"] = f"{ctx['ratio']['recording']} (sha256 {ctx['ratio']['sha256']})"
    sections = _sections(prep, result, path=path, background=background, aligned=aligned, shift_k=k, healthy=healthy)
    return CaseResult(rows, result, extra, prov, sections, path)


def run_recording_case(case, *, steps, mirror=None) -> CaseResult:
    """Run a recording case (see the module docstring); the report is assembled by the caller."""
    prep = prepare(case, mirror=mirror)
    steps.step("recording and declared scene")
    path = path_for(case, prep, mirror=mirror)
    reference = open_spec(case.reference, case.name, mirror) if case.reference is not None else None
    model = path.apply(prep.simulated["model"], prep.fs) if path.status in ("ok", "given") else None
    background = background_for(case, prep.recording, prep.measured["record"], reference, model=model,
                                band=comparison_band(prep.fs))
    steps.step("structural path and background")
    signals = simulate_signals(prep, path, background)
    sim_m = measure_signals(prep, signals)
    ctx = context(case, prep, path, background)
    if "ratio" in case.data:
        ctx["ratio"] = ratio_companion(case, prep, path, mirror=mirror)
    rows = evaluate_rows(case.tolerances, prep.measured, sim_m, context=ctx)
    steps.step("measure and compare")
    healthy = healthy_reference(case, prep, path, background, reference) if reference is not None else None
    if healthy:
        rows += healthy["rows"]
    err = (simulation.numerical_error(prep.scene, prep.dataset,
                                      duration=float(case.section("numerical_error").get("duration_s", 0.25)))
           if case.section("numerical_error").get("enabled", True) else {})
    steps.step("numerical error")
    return assemble(case, prep, path=path, background=background, signals=signals, rows=rows, numerical_error=err,
                    healthy=healthy, context=ctx)
