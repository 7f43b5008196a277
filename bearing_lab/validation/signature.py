"""The impact signature: what a local defect's geometry controls in a recording, and a misfit between two.

A ball crossing a local race defect makes an *event*: it drops in at the entry edge, rides
(or not) over the defect, and strikes the exit edge.  The defect's along-track length sets
the time between entry and exit, its axial offset H and skew θ set how gradually the ball
enters and leaves and how hard it strikes, and the structural path turns each event into a
ringing impulse.  All of this is in the *mean impact envelope*: the Hilbert envelope of the
band-passed signal, cut around every impact, aligned on the impact and averaged.  Averaging
over the impacts keeps the event and lowers the background (noise, tones) by √(impacts).

The same function makes the signature of the recording and of a simulation (after the
fixed structural path and the rig's background), so they are compared like with like.

Score (documented in docs/identification.md):

- ``level_db``: 20 log10 of the ratio of the two signatures' peaks (the impulse amplitude
  after the fixed path);
- ``shape_db``: the RMS difference, in dB, of the two signatures each normalised to its
  peak, over the window, at the lag that minimises it (entry/exit timing, rise, decay);
- ``score_db = shape_db + level_weight · max(|level_db| - level_tolerance_db, 0)``;
  ``level_weight = 1`` by default; 0 drops the amplitude when the path's gain is not
  independent of the geometry.  ``level_tolerance_db`` is the level the path's gain cannot
  vouch for (a multiple of its standard uncertainty): a level inside it costs nothing.  A sum,
  not a sum of squares: every candidate carries about the same systematic shape residual
  (the model's path is not the rig's), and in quadrature that common part would swamp the
  amplitude differences that tell offsets apart.

Below a floor (``floor`` × the recording signature's peak) both envelopes are clipped, so
the noise floor between events does not dominate the log difference.

The path's shape residual (``residual_db``): the model's structural path is not the rig's (one
resonance for several, a damping that fits the pooled impacts), so even the right geometry
leaves a shape residual, and a wrong geometry whose shape happens to lean the same way can
score as well as the right one.  When the path was identified on a *calibration* recording of
the rig (a known defect), the residual of that recording's known scene is the path's own: it
is measured there once (:func:`shape_residual`), and a comparison through the same path adds
it to the recording's log-envelope (the recording as the model's path would render it) before
the difference is taken.  It is never measured on the compared recording itself: that would
make its declared geometry fit by construction.

Public API
----------
Signature                                       -- time (s, relative to the impact), envelope (m s-2), n_impacts
impact_signature(x, fs, times, *, band, window_s=(-0.002, 0.006)) -> Signature
misfit(sim, meas, *, level_weight=1.0, level_tolerance_db=0.0, floor=0.05, max_lag_s=0.001,
       residual_db=None) -> dict
shape_residual(sim, meas, *, floor=0.05, max_lag_s=0.001) -> ndarray  -- the model's log-envelope residual
                                                                        (meas's frame)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import butter, hilbert, sosfiltfilt

from ..errors import AnalysisError

__all__ = ["Signature", "impact_signature", "misfit", "shape_residual", "WINDOW_S"]

#: default window around an impact, s: 2 ms before (the entry may precede the strongest
#: strike by the event's duration) and 6 ms after (the ring-down of a housing mode)
WINDOW_S = (-0.002, 0.006)
#: what a misfit compares when the period P is known: from -0.35 P to 0.65 P around the impact (the
#: event and its ring-down, not the neighbouring impacts; at 1793 r/min on a 6308's outer race this
#: holds the whole default window)
ONE_PERIOD = (-0.35, 0.65)


@dataclass
class Signature:
    """Mean impact envelope: ``time`` (s, 0 = the impact) and ``envelope`` (m s-2)."""

    time: np.ndarray
    envelope: np.ndarray
    n_impacts: int
    band_hz: tuple
    period_s: float | None = None       # impact period: the misfit reads one period around the impact

    @property
    def peak(self) -> float:
        return float(np.max(self.envelope))


def _envelope(x, fs, band):
    lo, hi = float(band[0]), float(band[1])
    hi = min(hi, 0.49 * fs)
    if not 0 <= lo < hi:
        raise AnalysisError(f"impact signature: band {band} Hz is empty at fs = {fs:g} Hz")
    sos = (butter(4, [lo, hi], btype="bandpass", fs=fs, output="sos") if lo > 0
           else butter(4, hi, btype="lowpass", fs=fs, output="sos"))
    return np.abs(hilbert(sosfiltfilt(sos, np.asarray(x, float))))


def _cut(env, fs, idx, i0, i1):
    rows = [env[k + i0: k + i1] for k in idx if k + i0 >= 0 and k + i1 <= env.size]
    return np.asarray(rows)


def impact_signature(x, fs, times, *, band, window_s=WINDOW_S, period=None) -> Signature:
    """Mean Hilbert envelope of ``x`` band-passed to ``band`` (Hz), around the impact ``times`` (s).

    ``period`` (s, optional): the impact period.  Kept with the signature, it limits what a misfit
    compares to one period around the impact (:data:`ONE_PERIOD`): where the window is longer than
    a period (high speeds) it holds the neighbouring impacts, whose place relative to this one
    wanders with the shaft speed in a recording and not in a simulation at constant speed.

    Each impact is first placed at its envelope maximum within ±1 ms of the given time,
    then re-aligned once on the mean by cross-correlation (so an event whose entry and exit
    strikes are about equal is not split between two alignments).
    """
    times = np.asarray(times, float)
    if times.size < 3:
        raise AnalysisError(f"impact signature: {times.size} impacts; at least 3 are needed")
    env = _envelope(x, fs, band)
    i0, i1 = int(round(window_s[0] * fs)), int(round(window_s[1] * fs))
    w = max(1, int(round(0.001 * fs)))
    idx = []
    for t in times:
        k = int(round(t * fs))
        a, b = max(0, k - w), min(env.size, k + w + 1)
        if b > a:
            idx.append(a + int(np.argmax(env[a:b])))
    rows = _cut(env, fs, idx, i0 - w, i1 + w)
    if rows.shape[0] < 3:
        raise AnalysisError(f"impact signature: only {rows.shape[0]} impacts fit the window {window_s} s")
    ref = rows[:, w:-w].mean(axis=0)
    shifts = []
    for r in rows:
        c = [float(np.dot(r[s: s + ref.size], ref)) for s in range(2 * w + 1)]
        shifts.append(int(np.argmax(c)))
    mean = np.mean([r[s: s + ref.size] for r, s in zip(rows, shifts)], axis=0)
    t = (np.arange(ref.size) + i0) / fs
    return Signature(t, mean, int(rows.shape[0]), (float(band[0]), float(band[1])),
                     None if period is None else float(period))


def _inside(sim, meas) -> np.ndarray:
    """The samples a misfit compares: one period around the impact when either signature knows its
    period (:data:`ONE_PERIOD`), else the whole window."""
    periods = [p for p in (sim.period_s, meas.period_s) if p]
    if not periods:
        return np.ones(meas.time.size, bool)
    p = min(periods)
    return (meas.time > ONE_PERIOD[0] * p) & (meas.time < ONE_PERIOD[1] * p)


def _logs(sim, meas, floor):
    """The two log-envelopes, each normalised to its peak and clipped at ``floor``.  When either signature
    knows its period, only one period around the impact counts: the peaks are taken there and the
    samples outside are NaN."""
    if sim.time.size != meas.time.size:
        raise AnalysisError("impact signature misfit: the two signatures have different windows")
    inside = _inside(sim, meas)
    out = []
    for sig in (sim, meas):
        peak = max(float(np.max(sig.envelope[inside])), 1e-300)
        out.append(np.where(inside, 20 * np.log10(np.maximum(sig.envelope / peak, floor)), np.nan))
    return out[0], out[1]


def _shifted(la, lb, s):
    """``la`` moved by ``s`` samples against ``lb``: (the overlapping part of la, its index range in lb)."""
    if s >= 0:
        return la[s:], slice(0, lb.size - s)
    return la[: la.size + s], slice(-s, lb.size)


def _best_lag(la, lb, m):
    best, lag = np.inf, 0
    for s in range(-m, m + 1):
        a, sl = _shifted(la, lb, s)
        d = a - lb[sl]
        v = float(np.sqrt(np.nanmean(d * d)))
        if v < best:
            best, lag = v, s
    return best, lag


def shape_residual(sim: Signature, meas: Signature, *, floor=0.05, max_lag_s=0.001) -> np.ndarray:
    """The simulated signature's log-envelope (each normalised to its peak) minus the measured one's, dB,
    at the lag that minimises it, on the measured signature's time axis (0 where the two do not overlap)."""
    la, lb = _logs(sim, meas, floor)
    fs = 1.0 / float(sim.time[1] - sim.time[0])
    _, lag = _best_lag(la, lb, int(round(max_lag_s * fs)))
    a, sl = _shifted(la, lb, lag)
    r = np.zeros_like(lb)
    r[sl] = np.nan_to_num(a - lb[sl])
    return r


def misfit(sim: Signature, meas: Signature, *, level_weight=1.0, level_tolerance_db=0.0, floor=0.05,
           max_lag_s=0.001, residual_db=None) -> dict:
    """Misfit of a simulated signature against the measured one (see the module docstring), dB.

    ``residual_db``: the path's shape residual on ``meas``'s time axis (:func:`shape_residual` of a
    calibration recording), added to the measured log-envelope before the difference; None: none.
    """
    la, lb = _logs(sim, meas, floor)
    if residual_db is not None:
        r = np.asarray(residual_db, float)
        if r.shape != lb.shape:
            raise AnalysisError(f"impact signature misfit: the path's shape residual has {r.size} samples, the "
                                f"signature {lb.size}")
        lb = lb + r
    fs = 1.0 / float(sim.time[1] - sim.time[0])
    inside = _inside(sim, meas)
    level = 20.0 * np.log10(max(float(np.max(sim.envelope[inside])), 1e-300)
                            / max(float(np.max(meas.envelope[inside])), 1e-300))
    best, lag = _best_lag(la, lb, int(round(max_lag_s * fs)))
    score = float(best + level_weight * max(abs(level) - level_tolerance_db, 0.0))
    return {"score_db": score, "shape_db": best, "level_db": float(level), "lag_s": lag / fs}
