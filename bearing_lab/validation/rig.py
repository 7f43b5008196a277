"""What belongs to the rig, not to the defect: the structural path and the background, each obtained once.

A case says how (``[structural_path]``, ``[background]``):

- the path is *fitted* on this case's recording against its declared scene, taken from
  *another case* of the same rig (``from_case``: that case's fit), read from a *file*
  written by an earlier run, *fixed* to given values, or *none*;
- the background is measured on the healthy ``[reference]`` recording of the same rig
  when the case has one (independent of the compared recording), else between the
  impacts of the recording itself (then the rows that include it are marked as not
  independent evidence).

Both are then held fixed for every simulation the case compares, so a different defect
geometry shows as a different result instead of being absorbed by a re-fit.

Public API
----------
identify_path(case, *, mirror=None, prep=None) -> StructuralPath   -- (one per case) the fitted path of a case
path_for(case, prep, *, mirror=None) -> StructuralPath
background_for(case, rec, measured, reference=None, *, model=None, band=None) -> Background | None
"""
from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

import numpy as np

from ..analysis.background import estimate_background
from ..analysis.impacts import impact_times
from ..analysis.structural_path import Resonance, StructuralPath, fit_structural_path
from ..errors import AnalysisError, ValidationCaseError
from .case import shipped_cases
from .load import load_case
from .recording_case import comparison_band, impact_period, prepare
from .signature import impact_signature, shape_residual

__all__ = ["identify_path", "path_for", "background_for", "PATH_DEFAULT_BOUNDS"]

#: default search bounds of the path fit: housing modes of bench rigs sit at 1-10 kHz; the
#: damping ratio of bolted housings is 1-30 %; the gain is free over six decades
PATH_DEFAULT_BOUNDS = {"frequency_hz": (500.0, None), "damping_ratio": (0.005, 0.5), "gain": (1e-3, 1e3)}

#: the fitted paths, {(case source, case content, mirror): (digest of the simulation fitted on, path)}
_CACHE: dict = {}


def _fixed(case, sp) -> StructuralPath:
    freqs = sp["frequency_hz"] if isinstance(sp["frequency_hz"], list) else [sp["frequency_hz"]]
    zetas = sp["damping_ratio"] if isinstance(sp["damping_ratio"], list) else [sp["damping_ratio"]]
    path = StructuralPath(tuple(Resonance(float(f), float(z)) for f, z in zip(freqs, zetas)), float(sp["gain"]),
                          "given by the case (method = \"fixed\")")
    try:
        path.check()
    except AnalysisError as exc:
        raise ValidationCaseError(f"validation case {case.name!r}: structural_path: {exc}") from None
    return path


def _fit(case, rec, measured, sim_x) -> StructuralPath:
    sp = case.section("structural_path")
    period = measured["excitation_period"]
    if not np.isfinite(period):
        raise AnalysisError("structural path: the recording shows no impact train to fit the path on "
                            f"({measured['extras']['notes'].get('excitation_period', '')}); use method = "
                            "\"fixed\", from_case or \"none\"")
    bounds = {k: tuple(sp.get(k, v)) for k, v in PATH_DEFAULT_BOUNDS.items()}
    path = fit_structural_path(rec.x, sim_x, rec.fs, period, band=measured["extras"]["band"],
                               n_resonances=int(sp.get("resonances", 1)), frequency_bounds=bounds["frequency_hz"],
                               damping_bounds=bounds["damping_ratio"], gain_bounds=bounds["gain"],
                               source=f"fitted on {rec.path.name} ({rec.channel}) against the scene of case "
                                      f"{case.name!r}, pooled over all impacts")
    if path.status == "ok":
        _gain_on_signature(case, path, rec, measured, sim_x, period)
    return path


#: passes of the signature gain's fixed-point iteration (the background does not scale with the gain)
_GAIN_PASSES = 4


def _gain_on_signature(case, path, rec, measured, sim_x, period):
    """The gain an impact-signature comparison reads the path with (``fit["signature_gain"]``, its standard
    uncertainty ``fit["signature_gain_sigma_db"]``): the declared scene's signature through the path, plus the
    recording's own background, then peaks where the recording's does.  The fitted ``gain`` (matched to the
    impact peaks, for the validation's waveform quantities) is left as it is."""
    fs = rec.fs
    band = comparison_band(fs)
    seed = int(case.section("background").get("seed", 0))
    try:
        bg = _measured_background(case, rec, measured, None).synthesize(np.asarray(sim_x).size, seed=seed)
        t_rec = impact_times(rec.x, fs, period, band=band)
        meas = impact_signature(rec.x, fs, t_rec, band=band).peak
        trial, x = StructuralPath(path.resonances, path.gain), np.asarray(sim_x, float)
        for _ in range(_GAIN_PASSES):
            y = trial.apply(x, fs) + bg
            t_sim = impact_times(y, fs, period, band=band)
            trial.gain *= meas / impact_signature(y, fs, t_sim, band=band).peak
        sigma = math.hypot(_subsets_db(rec.x, fs, t_rec, band), _subsets_db(y, fs, t_sim, band))
    except AnalysisError as exc:
        path.fit.setdefault("notes", []).append(f"no signature gain: {exc}; signature comparisons use the "
                                                "fitted gain")
        return
    path.fit["signature_gain"] = trial.gain
    path.fit["signature_gain_sigma_db"] = sigma
    _shape_residual(path, trial, rec, model=x, background=bg, period=period, band=band)
    path.fit.setdefault("notes", []).append(
        f"impact-signature comparisons read the path with gain {trial.gain:.4g} "
        f"({20 * math.log10(trial.gain / path.gain):+.2f} dB from the fitted {path.gain:.4g}): the declared "
        f"scene's signature ({band[0]:g}-{band[1]:g} Hz, path + background) then peaks where the recording's "
        f"does; standard uncertainty {sigma:.3f} dB (4 interleaved subsets of the impacts)")


def _shape_residual(path, trial, rec, *, model, background, period, band):
    """The path's shape residual (``fit["signature_residual_db"]``, on the recording signature's time axis,
    and its RMS ``fit["signature_residual_rms_db"]``): how the declared scene's impact signature through the
    path differs in shape from the recording's.  Comparisons of *other* recordings through this path add it
    to their recording's log-envelope (see :mod:`bearing_lab.validation.signature`)."""
    fs = rec.fs
    y = trial.apply(model, fs) + background
    sim = impact_signature(y, fs, impact_times(y, fs, period, band=band), band=band, period=period)
    meas = impact_signature(rec.x, fs, impact_times(rec.x, fs, period, band=band), band=band, period=period)
    r = shape_residual(sim, meas)
    path.fit["signature_residual_db"] = [float(v) for v in r]
    path.fit["signature_residual_fs_hz"] = float(fs)
    path.fit["signature_residual_rms_db"] = float(np.sqrt(np.mean(r * r)))


def _subsets_db(x, fs, times, band, groups=4):
    """Standard uncertainty (dB) of a signature's peak from ``groups`` interleaved subsets of its impacts:
    the subsets' standard deviation over sqrt(groups) (each subset holds 1/groups of the impacts)."""
    if times.size < 3 * groups:
        raise AnalysisError(f"{times.size} impacts: at least {3 * groups} are needed to split them in {groups}")
    db = [20.0 * math.log10(impact_signature(x, fs, times[k::groups], band=band).peak) for k in range(groups)]
    return float(np.std(db, ddof=1) / math.sqrt(groups))


def _fit_or_fail(case, rec, measured, sim_x) -> StructuralPath:
    try:
        return _fit(case, rec, measured, sim_x)
    except AnalysisError as exc:
        return StructuralPath.failed(f"the path could not be identified: {exc}",
                                     f"fit on {rec.path.name} ({rec.channel}) for case {case.name!r}")


def identify_path(case, *, mirror=None, prep=None) -> StructuralPath:
    """The path a case fits on its own recording against its declared scene; one fit per case and scene.

    The same fit serves the case's own comparison and every case that names it (``from_case``), so a
    path "identified by case X" is the one X's own report shows, whichever case runs first.  It is
    fitted on the simulation the case itself compares (so a recording the model made is explained by
    a gain of 1 and no background).  ``prep``: the case's prepared recording, when the caller has it;
    a remembered fit is used only for the same case content and, when ``prep`` is given, the same
    simulation (another scene for the case, e.g. a changed load, is fitted anew; without ``prep``, as for
    a case that names X, X's latest fit is used).
    """
    key = (case.source, json.dumps(case.data, sort_keys=True, default=str), mirror)
    hit = _CACHE.get(key)
    if hit is not None and (prep is None or hit[0] == _digest(prep.simulated["model"])):
        return hit[1]
    prep = prep if prep is not None else prepare(case, mirror=mirror)
    x = prep.simulated["model"]
    _CACHE[key] = (_digest(x), _fit_or_fail(case, prep.recording, prep.measured["record"], x))
    return _CACHE[key][1]


def _digest(x) -> str:
    """The simulated signal's identity (its samples' bytes)."""
    return hashlib.sha256(np.ascontiguousarray(x).tobytes()).hexdigest()


def path_for(case, prep, *, mirror=None) -> StructuralPath:
    """The structural path this case compares through (see the module docstring); ``prep``: the case's
    prepared recording (:func:`~bearing_lab.validation.recording_case.prepare`)."""
    sp = case.section("structural_path")
    method = sp.get("method", "fit")
    if method == "none":
        return StructuralPath.identity()
    if method == "fixed":
        return _fixed(case, sp)
    if sp.get("file"):
        p = Path(str(sp["file"]))
        p = p if p.is_absolute() or case.base_dir is None else Path(str(case.base_dir)) / p
        path = StructuralPath.load(p)
        path.source = f"read from {p.name} ({path.source})"
        return path
    if sp.get("from_case"):
        ref = str(sp["from_case"])
        if ref not in shipped_cases() and case.base_dir is not None and not Path(ref).expanduser().is_absolute():
            beside = Path(str(case.base_dir)) / ref      # a relative file is read beside this case's file
            ref = str(beside) if beside.is_file() else ref
        other = load_case(ref)
        path = identify_path(other, mirror=mirror)
        return StructuralPath(path.resonances, path.gain, f"identified by case {other.name!r}: {path.source}",
                              dict(path.fit), dict(path.curves))
    return identify_path(case, mirror=mirror, prep=prep)


def background_for(case, rec, measured, reference=None, *, model=None, band=None):
    """The rig's background (tones and broadband), or None when ``[background] enabled = false``.

    ``model``: the declared scene's signal through the path; measured on the recording itself, the
    background is then what that model does not explain (its own power is removed, so a recording the
    model explains fully gets no background added a second time).  ``band``: the band (Hz) the
    comparison times impacts in, where the recording's own impact train is not diagnosed (default
    :func:`~bearing_lab.validation.recording_case.comparison_band` at the recording's rate)."""
    if not case.section("background").get("enabled", True):
        return None
    return _measured_background(case, rec, measured, reference, model=model, band=band)


def _measured_background(case, rec, measured, reference, *, model=None, band=None):
    cfg = case.section("background")
    src = cfg.get("source", "auto")
    opts = {"max_tones": int(cfg.get("max_tones", 20)), "tone_snr_db": float(cfg.get("tone_snr_db", 15.0))}
    fr = measured["extras"]["shaft_hz_used"]
    if reference is not None and src in ("auto", "reference"):
        x = reference.at_rate(rec.fs)
        return estimate_background(x, rec.fs, shaft_hz=fr, source=(
            f"the healthy reference recording {reference.path.name} ({reference.channel}), whole record"
            + (f", resampled from {reference.fs:g} Hz" if abs(reference.fs - rec.fs) > 1e-6 else "")), **opts)
    period = measured["excitation_period"]
    times = measured["extras"]["impact_times"] if np.isfinite(period) else None
    where = "between impacts"
    if times is None:
        # no impact train diagnosed on its own: time the impacts at the declared defect's fault line,
        # as the comparison does; measured over the whole record the background would hold the impacts
        period, note = impact_period(case, measured)
        if np.isfinite(period):
            times = impact_times(rec.x, rec.fs, period, band=band or comparison_band(rec.fs))
            where = f"between impacts ({note})"
    rates = [measured[k] for k in ("bpfo", "bpfi") if np.isfinite(measured[k])]
    if times is None or len(times) < 3:
        times, where = None, "whole record (no impact train)"
    extra = {}
    if model is not None:
        y = np.asarray(model, float)
        mt = impact_times(y, rec.fs, period, band=measured["extras"]["band"]) if times is not None else None
        extra = {"model": y, "model_times": mt}
        where += ", less what the declared scene through the path explains"
    return estimate_background(rec.x, rec.fs, times=times, period=period if times is not None else None,
                               exclude_hz=rates, shaft_hz=fr,
                               source=f"the recording {rec.path.name} ({rec.channel}), {where}", **opts, **extra)
