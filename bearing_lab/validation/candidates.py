"""Candidate defect geometries scored against a recording through the fixed path and background.

The recording is prepared once (:func:`~bearing_lab.validation.recording_case.prepare`);
every candidate is simulated, passed through the *same* structural path and background
(never re-fitted), and its impact signature (:mod:`.signature`) compared with the
recording's.  The lower the score, the better the candidate explains the recording.

Public API
----------
Setting                                                   -- what every candidate is compared with
setting_for(prep, path, background, *, level_weight=None, band_hz=None) -> Setting
candidate_signature(setting, x) -> Signature              -- a simulated signal's signature (path + background applied)
score_candidates(prep, path, background, candidates, **kw) -> {label: misfit dict}, best first
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..analysis.impacts import impact_times
from ..analysis.structural_path import StructuralPath
from ..errors import AnalysisError, ValidationCaseError
from . import simulation
from .evaluate import context
from .recording_case import comparison_band, comparison_overrides, impact_period
from .signature import WINDOW_S, impact_signature, misfit

__all__ = ["Setting", "setting_for", "candidate_signature", "score_candidates"]

#: a level within LEVEL_K standard uncertainties of the path's signature gain (``fit["signature_gain_sigma_db"]``) costs
#: nothing in the score: two standard uncertainties cover about 95 % of a normal error
LEVEL_K = 2.0


@dataclass
class Setting:
    """The recording side of a comparison, fixed for every candidate."""

    prep: object
    path: object
    background: object
    period_s: float
    band_hz: tuple
    measured: object                    # Signature of the recording
    level_weight: float
    level_reason: str
    level_tolerance_db: float           # level the path's gain cannot vouch for (LEVEL_K x its uncertainty)
    noise_db: float                     # misfit of the recording's two halves of impacts
    seed: int = 0
    notes: list = field(default_factory=list)
    residual_db: object = None          # the path's shape residual (calibration recording), or None

    def score(self, sig) -> dict:
        """Misfit of a candidate's signature against the recording's, as every comparison scores it."""
        return misfit(sig, self.measured, level_weight=self.level_weight, level_tolerance_db=self.level_tolerance_db,
                      residual_db=self.residual_db)


def _level_weight(prep, path, level_weight):
    sp = prep.case.section("structural_path")
    fitted_here = context(prep.case, prep, path)["path_fitted_here"]
    if level_weight is not None:
        return float(level_weight), "set by the caller"
    if sp.get("method") == "none":
        return 0.0, ("no structural path (method = \"none\"): the simulated amplitude is the outer ring's, "
                     "not the sensor's, so only the shape is compared")
    if fitted_here:
        return 0.0, ("the structural path's gain was fitted on this recording against the declared defect, so "
                     "the amplitude is not independent of the geometry: only the shape is compared (use a path "
                     "identified on another recording of the rig, from_case or file, to use the amplitude)")
    return 1.0, f"the structural path is independent of this recording ({path.source})"


def _halves_noise(x, fs, times, band, period=None):
    """Misfit between the signatures of the odd and the even impacts: the score's own noise."""
    if times.size < 6:
        return float("nan")
    a = impact_signature(x, fs, times[0::2], band=band, period=period)
    b = impact_signature(x, fs, times[1::2], band=band, period=period)
    return float(misfit(a, b, level_weight=1.0)["score_db"])


def _period(prep) -> tuple:
    """The impact period: the measured one, else the declared race's measured fault line."""
    return impact_period(prep.case, prep.measured["record"])


def _signature_path(path):
    """The path as signatures are compared through it: with its signature gain when it has one (see
    :func:`bearing_lab.validation.rig.identify_path`)."""
    g = path.fit.get("signature_gain")
    if not g or abs(g - path.gain) <= 1e-12 * path.gain:
        return path, ""
    note = (f"the path's gain for the impact signature is {g:.4g} (fitted {path.gain:.4g}, matched to the impact "
            "peaks): the declared scene's signature on the path's own recording peaks where that recording's does")
    return StructuralPath(path.resonances, g, path.source, dict(path.fit)), note


def setting_for(prep, path, background, *, level_weight=None, band_hz=None, seed=None) -> Setting:
    """The measured signature, period, band and level weight every candidate is scored with."""
    m = prep.measured["record"]
    period, period_note = _period(prep)
    if not np.isfinite(period):
        raise ValidationCaseError(
            f"validation case {prep.case.name!r}: the recording shows no impact train, so there is no defect "
            f"event to identify ({m['extras']['notes'].get('excitation_period', '')})")
    if path.status == "failed":
        raise ValidationCaseError(f"validation case {prep.case.name!r}: the structural path failed "
                                  f"({'; '.join(path.problems)}); a geometry cannot be compared through it")
    band = comparison_band(prep.fs, band_hz)
    x = prep.recording.segment(prep.n)
    times = impact_times(x, prep.fs, period, band=band)
    try:
        meas = impact_signature(x, prep.fs, times, band=band, period=period)
    except AnalysisError as exc:
        raise ValidationCaseError(f"validation case {prep.case.name!r}: {exc}") from None
    w, why = _level_weight(prep, path, level_weight)
    path, gain_note = _signature_path(path)
    tol = LEVEL_K * float(path.fit.get("signature_gain_sigma_db") or 0.0) if w else 0.0
    seed = int(prep.case.section("background").get("seed", 0)) if seed is None else int(seed)
    notes = [] if path.status == "ok" else [f"the structural path is {path.status}: " + "; ".join(path.problems)]
    notes += [period_note] if period_note else []
    notes += [gain_note] if gain_note and w else []
    if tol > 0:
        notes.append(f"a level within ±{tol:.3f} dB costs nothing: {LEVEL_K:g} × the standard uncertainty of the "
                     "path's gain")
    residual, note = _path_residual(prep, path, meas)
    notes += [note] if note else []
    return Setting(prep, path, background, period, band, meas, w, why, tol,
                   _halves_noise(x, prep.fs, times, band, period), seed, notes, residual)


def _path_residual(prep, path, meas) -> tuple:
    """The path's shape residual to remove (see :mod:`.signature`) and a note: only for a path identified on
    another recording (a calibration of the rig), at this recording's sampling rate and window."""
    r = path.fit.get("signature_residual_db")
    if r is None or context(prep.case, prep, path)["path_fitted_here"]:
        return None, ""
    r = np.asarray(r, float)
    measured_at = float(path.fit.get("signature_residual_fs_hz", 0.0))
    if abs(measured_at - prep.fs) > 1e-6 * prep.fs or r.shape != meas.envelope.shape:
        return None, (f"the path's shape residual was measured at {measured_at:g} Hz, "
                      f"this recording is at {prep.fs:g} Hz: not removed")
    return r, (f"the path's shape residual ({float(np.sqrt(np.mean(r * r))):.2f} dB RMS, measured on the recording the "
               "path was identified on, against its declared scene) is removed from every candidate's shape misfit")


def candidate_signature(setting: Setting, x):
    """Signature of a simulated outer-ring signal ``x`` after the fixed path and background."""
    prep = setting.prep
    x = np.asarray(x, float)[: prep.n]
    y = setting.path.apply(x, prep.fs)
    if setting.background is not None:
        y = y + setting.background.synthesize(y.size, seed=setting.seed)
    times = impact_times(y, prep.fs, setting.period_s, band=setting.band_hz)
    return impact_signature(y, prep.fs, times, band=setting.band_hz, window_s=WINDOW_S, period=setting.period_s)


def score_candidates(prep, path, background, candidates: dict, *, level_weight=None, band_hz=None) -> dict:
    """Score candidate geometries (label -> scene keys, e.g. ``{"defect.offset_mm": 0.33}``).

    Returns label -> misfit dict (``score_db``, ``shape_db``, ``level_db``, ``lag_s``), ordered
    best (lowest score) first; ``"_setting"`` is not a key, see :func:`setting_for` for that.
    """
    st = setting_for(prep, path, background, level_weight=level_weight, band_hz=band_hz)
    out = {}
    for label, ov in candidates.items():
        scene = simulation.build_scene(prep.case, rpm=prep.speed.rpm, fs=prep.fs, duration=prep.n / prep.fs,
                                       overrides={**comparison_overrides(prep.case), **ov})
        sig = candidate_signature(st, simulation.signal(simulation.run(scene)))
        out[label] = st.score(sig)
    return dict(sorted(out.items(), key=lambda kv: kv[1]["score_db"]))
