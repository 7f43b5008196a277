"""The structural path from the bearing's outer ring to the accelerometer, identified once.

Why: a rig's housing, mounting and sensor turn each impact at the bearing into a
ringing at the housing's resonance(s).  The simulator computes the outer ring; the
accelerometer sits on the housing.  Fitting the path afresh for every compared
defect geometry lets gain and resonance absorb the geometry's effect, so every
geometry "agrees".  Here the path is a fixed linear filter, identified once on
the impulse responses pooled over all impacts of one recording (against the
declared scene), reported with its residual and its status, and then applied
unchanged to every simulation of the same rig.

Model: ``H(f) = gain * sum_k w_k T_k(f) / sum_k w_k`` with ``T_k`` the
absolute-acceleration transmissibility of a base-excited single-mode resonator
(frequency ``f_k``, damping ratio ``zeta_k``; ``T_k(0) = 1``), so ``gain`` is the
path's low-frequency gain.  With one resonance this is exactly the simulator's
``[sensor]`` resonator (:meth:`StructuralPath.scene_overrides`).

Fit: least squares in log amplitude on three views of the impacts (Ewins, *Modal
Testing*, 2000, ch. 4, for single-mode fitting of measured responses):

Each impact is pooled at the centroid of its envelope power (:func:`._impact_views.centred_times`),
in the recording and in the simulation through the path (the fit is repeated with the simulation's
impacts located on the fitted path's ringing until they stay):

0. the 90th percentile of the impact peaks (weight 3): it mostly sets the gain;
1. the Hilbert envelope pooled over the impacts (the measured impulse ringing), from
   its peak on, where it exceeds :data:`FIT_ABOVE_FLOOR` times the recording's floor
   (below that the pooled envelope is the floor's and says nothing of the decay): the
   decay sets the damping;
2. the mean power spectrum of the impact windows in 40 log-spaced bins from 300 Hz
   to 0.45 fs, kept where the recording rings (within 20 dB of its strongest bin):
   it sets the resonance frequency.

The recording's background is held apart in both shape views, measured between the
impacts (0.45 to 0.85 of a period after each, where the ringing has died out): the part
of its floor (median envelope there) that the model's own floor does not hold is added to
the model envelope in quadrature (independent powers add), and the part of its power in
each spectrum bin that the model's own background does not hold is added to the model's
impact spectrum.  So a quiet simulation is not pushed to fit background (under sensor
noise, a sharp resonance where there is only noise would otherwise win the spectrum
view), and a simulation that already holds the recording's background (the model's own
recording) is not given it twice.  Both are fixed before the fit, at the gain that
matches the impact peaks.  The search
starts at the strongest peaks of the measured impact spectrum inside the given
bounds; the bounds are used as given (an upper frequency bound above 0.45 fs is
lowered to 0.45 fs, and the fit says so).  A fit that ends at a bound, does not
converge, or ends no better than the unfitted simulation is *degraded*, and says
why.  Such a fit is then compared with the path without a resonance (the gain alone,
fitted on the same residuals): when the gain alone explains the impacts as well, the
recording shows no housing resonance, and the path is that gain (a note says so).  Each
evaluation filters the simulation's transform (taken once) and reads windows indexed once.

Public API
----------
transmissibility(f, frequency_hz, damping_ratio) -- complex T(f) of one resonator (T(0) = 1)
Resonance(frequency_hz, damping_ratio, weight)   -- one mode of the path
StructuralPath(resonances, gain, source, fit)    -- .response(f), .apply(x, fs), .status, .problems,
                                                    .to_dict(), .from_dict(), .save(path), .load(path)
StructuralPath.identity()                        -- no path (gain 1, no resonance)
StructuralPath.failed(reason)                    -- a path that could not be identified (status "failed")
fit_structural_path(recording, simulation, fs, period, *, n_resonances=1, ...) -> StructuralPath
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from ..errors import AnalysisError, check_choice
from ..utils._files import atomic_open
from ._impact_views import (ImpactWindows, background_power, centred_times, floor_level, frequency_runs,
                            hilbert_envelope, signal_of)
from .impacts import impact_peaks, impact_times, segment_spectrum

__all__ = ["transmissibility", "Resonance", "StructuralPath", "fit_structural_path", "MIN_IMPACTS"]

#: impacts needed in each signal before a path is fitted on them
MIN_IMPACTS = 5
#: weight of the impact-peak view against the two shape views (each normalised to 1)
PEAK_WEIGHT = 3.0
#: the envelope's decay is fitted where the recording's pooled envelope exceeds this many times its floor
FIT_ABOVE_FLOOR = 3.0


def transmissibility(f, frequency_hz, damping_ratio):
    """Absolute-acceleration transmissibility of a base-excited single-mode resonator.

    ``z'' + 2 zeta w z' + w^2 z = -a_base``; the sensor reads ``a_base + z''``, so
    ``T = (w^2 + 2j zeta w W) / (w^2 - W^2 + 2j zeta w W)`` at ``W = 2 pi f``.

    Examples
    --------
    >>> float(abs(transmissibility(0.0, 3000.0, 0.05)))
    1.0
    >>> round(float(abs(transmissibility(3000.0, 3000.0, 0.05))), 2)   # ~ 1 / (2 zeta)
    10.05
    """
    w = 2 * np.pi * frequency_hz
    W = 2 * np.pi * np.asarray(f, float)
    num = w * w + 2j * damping_ratio * w * W
    return num / (w * w - W * W + 2j * damping_ratio * w * W)


def padded_length(n):
    """The transform length the path filters ``n`` samples at: a power of two, at least 2 n (no wrap-around)."""
    return 1 << int(math.ceil(math.log2(2 * n)))


@dataclass(frozen=True)
class Resonance:
    """One mode of the path: frequency (Hz), damping ratio, relative weight."""

    frequency_hz: float
    damping_ratio: float
    weight: float = 1.0


@dataclass
class StructuralPath:
    """A fixed linear path from the simulated outer-ring acceleration to the sensor.

    ``fit`` holds how it was identified (residuals in dB before and after, bounds, impacts
    used, problems); ``curves`` the pooled envelopes for a figure (not saved).
    """

    resonances: tuple = ()
    gain: float = 1.0
    source: str = "given"
    fit: dict = field(default_factory=dict)
    curves: dict = field(default_factory=dict, repr=False)

    @classmethod
    def identity(cls) -> "StructuralPath":
        return cls((), 1.0, "none: the simulation as it is")

    # ---- the filter
    def response(self, f):
        """Complex frequency response at ``f`` (Hz)."""
        f = np.asarray(f, float)
        if not self.resonances:
            return np.full(f.shape, complex(self.gain))
        wsum = sum(r.weight for r in self.resonances)
        h = sum(r.weight * transmissibility(f, r.frequency_hz, r.damping_ratio) for r in self.resonances)
        return self.gain * h / wsum

    def apply(self, x, fs):
        """Filter ``x`` (sampled at ``fs``) through the path (FFT, zero-padded: no wrap-around)."""
        x = np.asarray(x, float)
        if not self.resonances:
            return self.gain * x
        n = x.size
        nfft = padded_length(n)
        spec = np.fft.rfft(x, nfft) * self.response(np.fft.rfftfreq(nfft, 1 / fs))
        return np.fft.irfft(spec, nfft)[:n]

    # ---- status
    @property
    def problems(self) -> list:
        return list(self.fit.get("problems", []))

    @property
    def status(self) -> str:
        """"given" (not fitted), "ok", "degraded" or "failed" (see :attr:`problems`)."""
        if not self.fit:
            return "given"
        if self.fit.get("failed"):
            return "failed"
        return "degraded" if self.problems else "ok"

    @classmethod
    def failed(cls, reason: str, source: str = "") -> "StructuralPath":
        """A path that could not be identified: the bare model, with the reason (every row after it fails)."""
        return cls((), 1.0, source or "not identified", {"failed": True, "problems": [reason]})

    def describe(self) -> str:
        modes = ", ".join(f"{r.frequency_hz:.0f} Hz (ζ = {r.damping_ratio:.3f})" for r in self.resonances)
        return f"gain {self.gain:.3g}" + (f", resonance {modes}" if modes else ", no resonance")

    def scene_overrides(self) -> dict:
        """``--set`` keys putting a one-resonance path into the simulator's ``[sensor]``."""
        if len(self.resonances) != 1:
            raise AnalysisError(f"scene_overrides: the simulator's [sensor] holds one resonance; this path "
                                f"has {len(self.resonances)}: apply it with StructuralPath.apply instead")
        r = self.resonances[0]
        return {"sensor.enabled": True, "sensor.frequency_hz": float(r.frequency_hz),
                "sensor.damping_ratio": float(r.damping_ratio), "sensor.gain": float(self.gain)}

    # ---- saving
    def to_dict(self) -> dict:
        return {"resonances": [{"frequency_hz": r.frequency_hz, "damping_ratio": r.damping_ratio,
                                "weight": r.weight} for r in self.resonances],
                "gain": self.gain, "source": self.source, "status": self.status, "fit": self.fit}

    @classmethod
    def from_dict(cls, d: dict) -> "StructuralPath":
        try:
            res = tuple(Resonance(float(r["frequency_hz"]), float(r["damping_ratio"]), float(r.get("weight", 1.0)))
                        for r in d.get("resonances", []))
            path = cls(res, float(d["gain"]), str(d.get("source", "given")), dict(d.get("fit") or {}))
        except (KeyError, TypeError, ValueError) as exc:
            raise AnalysisError(f"structural path: invalid description ({type(exc).__name__}: {exc}); needs "
                                "gain and resonances [{frequency_hz, damping_ratio}]") from None
        path.check()
        return path

    def check(self):
        """Raise AnalysisError for a path that is not a physical filter."""
        if not (math.isfinite(self.gain) and 0 < self.gain < 1e6):
            raise AnalysisError(f"structural path: gain={self.gain!r} must be positive and finite")
        for r in self.resonances:
            if not (math.isfinite(r.frequency_hz) and r.frequency_hz > 0):
                raise AnalysisError(f"structural path: frequency_hz={r.frequency_hz!r} must be positive")
            if not (math.isfinite(r.damping_ratio) and 0 < r.damping_ratio < 1):
                raise AnalysisError(f"structural path: damping_ratio={r.damping_ratio!r} must lie in (0, 1)")
            if not (math.isfinite(r.weight) and r.weight > 0):
                raise AnalysisError(f"structural path: weight={r.weight!r} must be positive")

    def save(self, path):
        """Write the path as JSON (atomically); :meth:`load` reads it back."""
        with atomic_open(path, "w", encoding="utf-8") as fh:
            json.dump(_jsonable(self.to_dict()), fh, indent=1)
        return path

    @classmethod
    def load(cls, path) -> "StructuralPath":
        try:
            with open(path, encoding="utf-8") as fh:
                d = json.load(fh)
        except (OSError, ValueError) as exc:
            raise AnalysisError(f"{path}: not a readable structural-path JSON file ({exc})") from None
        return cls.from_dict(d)


def _jsonable(v):
    if isinstance(v, dict):
        return {k: _jsonable(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, (np.floating, float)):
        return float(v) if math.isfinite(v) else None
    if isinstance(v, np.integer):
        return int(v)
    return v


# ------------------------------------------------------------------ the fit
class _PathProblem:
    """Residuals of the path fit (see the module docstring)."""

    def __init__(self, recording, simulation, fs, period, *, band, pre, post, n_resonances):
        self.fs, self.period, self.nres = fs, period, n_resonances
        self.e = np.asarray(recording, float) - np.mean(recording)
        self.s = np.asarray(simulation, float) - np.mean(simulation)
        self.pre, self.post = pre, post
        self.band = band
        env_e, env_s = hilbert_envelope(self.e), hilbert_envelope(self.s)
        self.te, self.ts = self._locate(self.e, env_e), self._locate(self.s, env_s)
        if self.te.size < MIN_IMPACTS or self.ts.size < MIN_IMPACTS:
            raise AnalysisError(f"structural path: the fit needs at least {MIN_IMPACTS} impacts in each signal; "
                                f"found {self.te.size} in the recording and {self.ts.size} in the simulation")
        self.env_e = ImpactWindows(self.e.size, fs, self.te, period, pre=pre, post=post).mean_of(env_e)
        if self.env_e is None:
            raise AnalysisError("structural path: no impact window fits inside the recording")
        self.pk = int(np.argmax(self.env_e))
        self.floor = floor_level(self.e, fs, self.te, period, env=env_e)
        # the decay is fitted where the recording's envelope stands clear of its floor: below it
        # the pooled envelope is the floor's, which says nothing about the path's damping
        tail = self.env_e[self.pk:]
        clear = tail > FIT_ABOVE_FLOOR * self.floor
        self.fit_tail = clear if clear.sum() >= 5 else np.ones(tail.size, bool)
        self.f_seg, self.p_e = segment_spectrum(self.e, fs, self.te, pre=pre, post=post)
        edges = np.geomspace(300.0, 0.45 * fs, 41)
        bins = [((self.f_seg >= lo) & (self.f_seg < hi), (lo, hi)) for lo, hi in zip(edges[:-1], edges[1:])]
        bins = [b for b in bins if b[0].any()]
        level = np.array([self.p_e[b].mean() for b, _ in bins])
        kept = [b for b, lv in zip(bins, level) if lv >= 0.01 * level.max()]
        self.bins = [b for b, _ in kept]
        self.runs = frequency_runs(self.bins)
        self.peak_e = self.impact_peak(self.e, self.te)
        self.ranges = [r for _, r in kept]
        self.p_e_bins = np.array([self.p_e[b].mean() for b in self.bins])
        self.w2 = float(np.sum(np.hanning(int(round(pre * fs)) + int(round(post * fs))) ** 2))
        self.noise_e = background_power(self.e, fs, self.te, period, self.ranges, self.w2)
        # the bare simulation's transform, zero-padded as StructuralPath.apply pads it, taken once
        n = self.s.size
        self.nfft = padded_length(n)
        omega = 2 * np.pi * np.fft.rfftfreq(self.nfft, 1 / fs)
        self.j_omega, self.omega2 = 1j * omega, omega * omega
        self.spec_s_w2 = np.fft.rfft(self.s, self.nfft) * self.omega2
        self._set_windows()
        self._hold_background(self.s, env_s)

    def _set_windows(self):
        """The simulation's impact windows (at ``self.ts``), and no remembered views (they read them)."""
        self.win = ImpactWindows(self.s.size, self.fs, self.ts, self.period, pre=self.pre, post=self.post)
        self._seen = {}

    def _locate(self, y, env):
        """The impacts of ``y`` (its Hilbert envelope ``env``), each at the centroid of its envelope power."""
        return centred_times(y, self.fs, impact_times(y, self.fs, self.period, band=self.band), self.period, env=env)

    def relocate(self, y) -> bool:
        """Pool the simulation's impacts where ``y`` (the simulation through a path) has them, and hold
        apart the background ``y`` does not hold; False (nothing changed) when ``y`` shows too few impacts.

        The recording's impacts are located on its ringing; the resonance moves each impact's centroid
        after its onset, so the bare simulation's windows would sit early on the impact (0.1 ms on the
        stand-in below) and the pooled views would compare different parts of the ringing.  On the
        paper-O2 600 N stand-in (4300 Hz, 5 %; speed jitter, tones, noise) the fit gave 4314 Hz with the
        windows on the bare simulation, 4305 Hz with them moved onto the fitted path's ringing.
        """
        env = hilbert_envelope(y)
        ts = self._locate(y, env)
        if ts.size < MIN_IMPACTS:
            return False
        changed = not np.array_equal(ts, self.ts)
        self.ts = ts
        self._set_windows()
        self._hold_background(y, env)
        return changed

    def _hold_background(self, y, env):
        """The recording's background that ``y`` (impacts at ``self.ts``; its Hilbert envelope ``env``) does not
        hold, in the envelope and the spectrum views."""
        ts = self.ts
        # the part of the recording's floor the model does not hold, fixed before each fit: the
        # model's own floor at the gain that matches the impact peaks (a floor that followed the
        # fitted gain would let the gain trade impact level for floor, and bias it)
        peak_s = self.impact_peak(y, ts)
        g0 = self.peak_e / peak_s if peak_s > 0 else 0.0
        self.floor_add2 = max(self.floor ** 2 - (g0 * floor_level(y, self.fs, ts, self.period, env=env)) ** 2, 0.0)
        # the same for the spectrum view: the background's power in each bin (measured between the
        # impacts, scaled to an impact window) that the model's own background does not hold
        noise_s = background_power(y, self.fs, ts, self.period, self.ranges, self.w2)
        self.spec_add = np.maximum(self.noise_e - g0 ** 2 * noise_s, 0.0)

    def impact_peak(self, y, times):
        return float(np.percentile(impact_peaks(y, self.fs, times, self.period), 90))

    def path_of(self, params) -> StructuralPath:
        p = np.exp(params)
        k = self.nres
        freqs, zetas, gain = p[:k], p[k:2 * k], p[2 * k]
        weights = np.ones(k) if k == 1 else np.r_[1.0, np.exp(params[2 * k + 1:])]
        return StructuralPath(tuple(Resonance(float(f), float(z), float(w)) for f, z, w in zip(freqs, zetas, weights)),
                              float(gain), "fit")

    def shape_output(self, params):
        """The simulation through the path of ``params`` at gain 1, as :meth:`StructuralPath.apply` gives it, from
        the bare simulation's transform ``S`` taken once: with ``T = 1 + W^2 / D``, ``D = w^2 - W^2 + 2j zeta w W``
        (:func:`transmissibility`), it is the simulation plus the inverse of ``sum_k w_k S W^2 / D_k / sum w``."""
        p, k = np.exp(params), self.nres
        weights = np.ones(k) if k == 1 else np.r_[1.0, p[2 * k + 1:]]
        spec = 0.0
        for f, z, w in zip(p[:k], p[k:2 * k], weights / weights.sum()):
            wn = 2 * np.pi * f
            d = (2 * z * wn) * self.j_omega
            d.real += wn * wn
            d.real -= self.omega2
            term = np.divide(self.spec_s_w2, d, out=d)
            spec = spec + w * term if k > 1 else term
        return self.s + np.fft.irfft(spec, self.nfft)[:self.s.size]

    def views_at(self, params):
        """The views of the path ``params``'s output at gain 1, remembered for the last few shapes: a step
        in the gain alone (a column of the Jacobian) costs no evaluation."""
        key = tuple(np.delete(params, 2 * self.nres))
        if key not in self._seen:
            if len(self._seen) >= 8:
                self._seen.pop(next(iter(self._seen)))
            self._seen[key] = self.win.views(self.shape_output(params), self.pk, self.runs)
        return self._seen[key]

    def residuals(self, params):
        return self.residuals_from(self.views_at(params), math.exp(params[2 * self.nres]))

    def residuals_from(self, views, gain, parts=False):
        """The residuals of a signal scaled by ``gain``, from its views (:meth:`ImpactWindows.views`)."""
        env, bins, peak = views
        env_m = np.sqrt((gain * env) ** 2 + self.floor_add2)
        r1 = np.log(env_m[self.pk:] / np.maximum(self.env_e[self.pk:], 1e-30))[self.fit_tail]
        r2 = 0.5 * np.log((gain * gain * bins + self.spec_add + 1e-30) / (self.p_e_bins + 1e-30))
        r0 = np.array([PEAK_WEIGHT * np.log(max(gain * peak, 1e-30) / max(self.peak_e, 1e-30))])
        r = np.concatenate([r0, r1 / math.sqrt(r1.size), r2 / math.sqrt(max(r2.size, 1))])
        return (r, (r0, r1, r2)) if parts else r

    def spectral_peaks(self, lo, hi, n):
        """The ``n`` strongest local maxima of the smoothed impact spectrum in [lo, hi], >= 20 % apart."""
        k = max(1, int(round(150.0 / (self.f_seg[1] - self.f_seg[0]))))
        smooth = np.convolve(self.p_e, np.ones(k) / k, mode="same")
        inside = np.flatnonzero((self.f_seg >= lo) & (self.f_seg <= hi))
        if inside.size == 0:
            return [math.sqrt(lo * hi)]
        order = inside[np.argsort(smooth[inside])[::-1]]
        picked = []
        for i in order:
            f = float(self.f_seg[i])
            if all(abs(f / p - 1) > 0.2 for p in picked):
                picked.append(f)
            if len(picked) == n:
                break
        return picked


def _rms_db(vec) -> float:
    return float(20.0 / math.log(10) * math.sqrt(np.mean(np.square(vec))))


def _starts(prob, lo, hi, f_lo, f_hi):
    """Starting vectors: the strongest spectral peaks (pairs of them for two resonances) x 2 dampings."""
    k = prob.nres
    peaks = prob.spectral_peaks(f_lo, f_hi, 3 if k == 1 else 4)
    if k == 1:
        combos = [(p,) for p in peaks]
    else:
        combos = [(a, b) for i, a in enumerate(peaks) for b in peaks[i + 1:]] or [(peaks[0], 1.3 * peaks[0])]
    for freqs in combos:
        for z0 in (0.03, 0.1):
            x = np.r_[np.log(freqs), np.log([z0] * k), 0.0, np.zeros(k - 1)]
            x[2 * k] = math.log(max(prob.peak_e / max(prob.views_at(x)[2], 1e-30), 1e-30))
            yield np.clip(x, lo + 1e-6, hi - 1e-6)


def _fit_problems(best, lo, hi, names, fit_db, before_db, bounds_given):
    problems = []
    at = [f"{n} at its {'lower' if abs(v - a) < 1e-3 else 'upper'} bound "
          f"({bounds_given[n][0 if abs(v - a) < 1e-3 else 1]:.4g})"
          for n, v, a, b in zip(names, best.x, lo, hi) if (abs(v - a) < 1e-3 or abs(v - b) < 1e-3)
          and n in bounds_given]
    if at:
        problems.append("the fit ended at a bound: " + ", ".join(at))
    if best.status <= 0:
        problems.append(f"the least-squares search did not converge ({best.message})")
    if not fit_db < before_db:
        problems.append(f"the fit ends no better than the unfitted simulation ({fit_db:.1f} dB against "
                        f"{before_db:.1f} dB before)")
    return problems


def _check_bounds(frequency_bounds, damping_bounds, gain_bounds, fs):
    """The search bounds as used, and notes on any change (an upper frequency above 0.45 fs is lowered)."""
    notes = []
    f_hi = frequency_bounds[1] if frequency_bounds[1] is not None else 0.45 * fs
    if f_hi > 0.45 * fs:
        notes.append(f"upper frequency bound {f_hi:g} Hz lowered to 0.45 fs = {0.45 * fs:g} Hz: the "
                     "recording holds nothing above its anti-alias band")
        f_hi = 0.45 * fs
    bounds = {"frequency_hz": (float(frequency_bounds[0]), float(f_hi)),
              "damping_ratio": tuple(map(float, damping_bounds)), "gain": tuple(map(float, gain_bounds))}
    for name, (a, b) in bounds.items():
        if not (0 < a < b and math.isfinite(b)):
            raise AnalysisError(f"structural path: bounds {name}=({a:g}, {b:g}) must be positive and increasing")
    return bounds, notes


def _finish(prob, best, lo, hi, bounds, notes, source) -> StructuralPath:
    """The fitted path with its report: residuals before and after, bounds, impacts, problems."""
    k = prob.nres
    path = prob.path_of(best.x)
    fit_db, before_db = _score(prob, path)
    names = ([f"frequency_hz[{i}]" if k > 1 else "frequency_hz" for i in range(k)]
             + [f"damping_ratio[{i}]" if k > 1 else "damping_ratio" for i in range(k)] + ["gain"])
    given = {n: bounds[n.split("[")[0]] for n in names}
    path.source = source or "fitted on the pooled impulse responses"
    path.fit = {"residual_db": fit_db, "initial_db": before_db, "bounds": bounds,
                "n_impacts_recording": int(prob.te.size), "n_impacts_simulation": int(prob.ts.size),
                "evaluations": int(best.nfev), "notes": notes,
                "problems": _fit_problems(best, lo, hi, names, fit_db, before_db, given)}
    return path


def _score(prob, path):
    """The RMS residuals (dB) of ``path`` and of the unfitted simulation; their pooled envelopes (with the
    recording's floor that they do not hold) in ``path.curves``, for a figure."""
    fit, bare = (prob.win.views(y, prob.pk, prob.runs) for y in (path.apply(prob.s, prob.fs), prob.s))
    path.curves = {"time_s": (np.arange(prob.env_e.size) - prob.pk) / prob.fs, "recording": prob.env_e,
                   "before": np.sqrt(bare[0] ** 2 + prob.floor_add2), "after": np.sqrt(fit[0] ** 2 + prob.floor_add2)}
    return tuple(_rms_db(np.concatenate(prob.residuals_from(v, 1.0, parts=True)[1])) for v in (fit, bare))


def fit_structural_path(recording, simulation, fs, period, *, band=None, n_resonances=1,
                        frequency_bounds=(500.0, None), damping_bounds=(0.005, 0.5), gain_bounds=(1e-3, 1e3),
                        pre=0.5e-3, post=None, source="") -> StructuralPath:
    """Identify the structural path once, on the impulse responses pooled over all impacts.

    Parameters
    ----------
    recording : array_like, 1-D, or Dataset
        The measured acceleration (m s-2), as long as available (a recording Dataset: its
        default channel).
    simulation : array_like, 1-D, or Dataset
        The simulated outer-ring acceleration of the declared scene *without* a sensor
        resonator, at the same rate (a simulated Dataset: its default channel).
    fs : float or None
        Sampling rate, Hz (None: from the Datasets, which must agree).
    period : float
        Impact period of the recording, s.
    band : (float, float), optional
        Band in which impacts are located (e.g. the recording's kurtogram band).
    n_resonances : {1, 2}
        Modes of the path.
    frequency_bounds, damping_bounds, gain_bounds : (low, high)
        Search bounds, used as given (high frequency None: 0.45 fs).
    pre, post : float
        Impact window from ``pre`` s before to ``post`` s after each impact (default post:
        60 % of a period).
    source : str
        What the path was fitted on (kept with the path for the report).

    Returns
    -------
    StructuralPath
        With ``fit``: ``residual_db`` and ``initial_db`` (RMS of the log-amplitude residuals
        after the fit and for the unfitted simulation), ``bounds``, ``n_impacts_recording``,
        ``n_impacts_simulation``, ``problems`` (empty when the fit is sound), ``notes``.

    Raises
    ------
    AnalysisError
        Fewer than :data:`MIN_IMPACTS` impacts in either signal, invalid bounds, a signal that is
        empty, not 1-D, not finite or zero throughout, or a period not shorter than the recording.
    """
    recording, fs_r = signal_of(recording, fs, "recording")
    simulation, fs_s = signal_of(simulation, fs, "simulation")
    if abs(fs_r - fs_s) > 1e-9 * fs_r:
        raise AnalysisError(f"structural path: recording at {fs_r:g} Hz and simulation at {fs_s:g} Hz; "
                            "simulate at the recording's rate")
    fs = fs_r
    check_choice(n_resonances, (1, 2), "structural path: n_resonances", AnalysisError)
    bounds, notes = _check_bounds(frequency_bounds, damping_bounds, gain_bounds, fs)
    f_hi = bounds["frequency_hz"][1]
    if not (np.isfinite(period) and 0 < period < recording.size / fs):
        raise AnalysisError(f"structural path: the impact period must be positive and shorter than the "
                            f"recording ({recording.size / fs:.6g} s); got {period!r} s")
    post = 0.6 * period if post is None else post
    prob = _PathProblem(recording, simulation, fs, period, band=band, pre=pre, post=post, n_resonances=n_resonances)
    k = n_resonances
    lo = np.r_[np.log([bounds["frequency_hz"][0]] * k), np.log([damping_bounds[0]] * k),
               math.log(gain_bounds[0]), [-4.0] * (k - 1)]
    hi = np.r_[np.log([f_hi] * k), np.log([damping_bounds[1]] * k), math.log(gain_bounds[1]), [4.0] * (k - 1)]
    best = None
    for x0 in _starts(prob, lo, hi, *bounds["frequency_hz"]):
        r = least_squares(prob.residuals, x0, bounds=(lo, hi), x_scale=0.3, max_nfev=60)
        if best is None or r.cost < best.cost:
            best = r
    for _ in range(RELOCATE_PASSES):         # the windows on the fitted path's ringing, then fitted again
        if not prob.relocate(prob.path_of(best.x).apply(prob.s, fs)):
            break
        best = least_squares(prob.residuals, best.x, bounds=(lo, hi), x_scale=0.3, max_nfev=60)
    path = _finish(prob, best, lo, hi, bounds, notes, source)
    if path.problems:
        flat = _flat_path(prob, bounds, notes, source)
        if flat is not None and flat.fit["residual_db"] <= path.fit["residual_db"] + FLAT_MARGIN_DB:
            flat.fit["notes"] = list(notes) + [
                f"no resonance: a flat gain explains the impacts ({flat.fit['residual_db']:.2f} dB residual) as well "
                f"as the best {'resonance' if k == 1 else 'pair of resonances'} ({path.describe()}, "
                f"{path.fit['residual_db']:.2f} dB; " + "; ".join(path.problems) + "): the recording shows no "
                "housing resonance, and the path is the gain alone"]
            flat.fit["resonant_fit"] = {"path": path.describe(), "residual_db": path.fit["residual_db"],
                                        "problems": path.problems}
            return flat
    return path


#: times the simulation's impact windows are moved onto the fitted path's ringing (and the path refitted)
RELOCATE_PASSES = 3

#: a flat gain replaces a resonant fit that ended at a bound when its residual is at most this much larger (dB)
FLAT_MARGIN_DB = 0.05


def _flat_path(prob, bounds, notes, source):
    """The path without a resonance (the gain alone), fitted on the same residuals; None when it cannot be."""
    glo, ghi = (math.log(v) for v in bounds["gain"])
    prob.relocate(prob.s)                   # a gain alone rings as the bare simulation does
    peak_s = prob.impact_peak(prob.s, prob.ts)
    if not peak_s > 0:
        return None
    g0 = min(max(math.log(prob.peak_e / peak_s), glo + 1e-6), ghi - 1e-6)
    views = prob.win.views(prob.s, prob.pk, prob.runs)
    best = least_squares(lambda p: prob.residuals_from(views, math.exp(p[0])), [g0], bounds=([glo], [ghi]),
                         x_scale=0.3, max_nfev=60)
    path = StructuralPath((), float(math.exp(best.x[0])), source or "fitted on the pooled impulse responses")
    fit_db, before_db = _score(prob, path)
    problems = []
    if abs(best.x[0] - glo) < 1e-3 or abs(best.x[0] - ghi) < 1e-3:
        problems.append(f"the fit ended at a bound: gain at its {'lower' if abs(best.x[0] - glo) < 1e-3 else 'upper'}"
                        f" bound ({math.exp(best.x[0]):.4g})")
    if fit_db > before_db + FLAT_MARGIN_DB:
        problems.append(f"the fit ends worse than the unfitted simulation ({fit_db:.1f} dB against "
                        f"{before_db:.1f} dB before)")
    path.fit = {"residual_db": fit_db, "initial_db": before_db, "bounds": bounds,
                "n_impacts_recording": int(prob.te.size), "n_impacts_simulation": int(prob.ts.size),
                "evaluations": int(best.nfev), "notes": list(notes), "problems": problems}
    return path
