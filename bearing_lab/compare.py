"""Measured against simulated: one ruler, one time base, one table.

Why a module of its own: a validation is only as honest as its comparison.
Both signals go through the *same* functions of :mod:`bearing_lab.analysis`
(same window, same band selection, same line search), are cut to the same
length and sampled at the same rate, and every quantity lands in one table
with its tolerance and the reason for that tolerance.  A quantity the model
does not produce (no line found, no impulse) is kept as NaN and fails: rows are
never dropped or loosened to make a case pass.

Public API
----------
Tolerance                           -- a pass rule ("pct", "factor", "ordering") with its reason
QUANTITIES                          -- quantity key -> (label, units)
measure(x, fs, *, bearing, rpm)     -- dict of the table's quantities for one signal (+ extras)
impact_times(x, fs, period, *, band) -- impact instants found one period after another
impulse_strength(x, fs, period)     -- median impact peak (the @6 / @3 ordering ruler)
align_by_impulse_phase(exp, sim, fs, period) -- integer sample shift that puts sim impacts on exp's
sensor_response(f, frequency_hz, damping_ratio, gain) -- the scene's [sensor] resonator, H(f)
apply_sensor(x, fs, ...)            -- filter a sensor-off simulation through that resonator
calibrate_sensor(exp, sim, fs, period, ...) -> CalibrationResult: least-squares fit of the resonator
compare(experiment, simulation, ...) -> ComparisonResult
ComparisonResult                    -- .dataset, .rows, plot_waveforms/plot_spectra/plot_envelope(ax=None),
                                       to_netcdf(path), load(path)
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from .errors import ValidationCaseError

__all__ = ["Tolerance", "QUANTITIES", "measure", "impact_times", "impulse_strength",
           "align_by_impulse_phase", "sensor_response", "apply_sensor", "calibrate_sensor",
           "CalibrationResult", "compare", "ComparisonResult", "make_row", "G0"]

G0 = 9.80665

#: quantity key -> (label shown in tables, SI units)
QUANTITIES = {
    "shaft_hz": ("f_i (shaft frequency)", "Hz"),
    "bpfo": ("BPFO", "Hz"),
    "bpfi": ("BPFI", "Hz"),
    "excitation_period": ("excitation period", "s"),
    "rms": ("RMS", "m s-2"),
    "peak": ("peak |a| (max over the record)", "m s-2"),
    "crest_factor": ("crest factor", "1"),
    "kurtosis": ("kurtosis (Pearson)", "1"),
    "impulse_duration": ("impulse duration (median, 10 % level)", "s"),
    "impulse_strength": ("impulse strength (median impact peak)", "m s-2"),
}


#: quantities that are spectral lines: absent from both signals counts as agreement
LINE_QUANTITIES = ("shaft_hz", "bpfo", "bpfi")

# ------------------------------------------------------------------ tolerances and rows
@dataclass(frozen=True)
class Tolerance:
    """A pass rule with its reason.

    kind "pct": |sim - exp| <= value % of |exp|; "factor": 1/value <= sim/exp <= value;
    "ordering": sim and exp lie on the same side of 1 (ratios such as @6 / @3).
    """

    kind: str
    value: float | None
    reason: str

    def __post_init__(self):
        if self.kind not in ("pct", "factor", "ordering"):
            raise ValidationCaseError(f"tolerance kind {self.kind!r}: allowed are 'pct', 'factor', 'ordering'")
        if not (self.reason or "").strip():
            raise ValidationCaseError("every tolerance needs a reason (key 'reason')")
        if self.kind != "ordering" and not (self.value is not None and self.value > 0):
            raise ValidationCaseError(f"tolerance {self.kind}: value must be positive, got {self.value!r}")
        if self.kind == "factor" and self.value < 1:
            raise ValidationCaseError(f"tolerance factor must be >= 1, got {self.value!r}")

    @property
    def pct(self) -> float | None:
        """Tolerance as a percentage of the experiment (factor f -> (f - 1) * 100 on the high side)."""
        if self.kind == "pct":
            return float(self.value)
        if self.kind == "factor":
            return float((self.value - 1.0) * 100.0)
        return None

    def text(self) -> str:
        if self.kind == "pct":
            return f"±{self.value:g} %"
        if self.kind == "factor":
            return f"factor {self.value:g}"
        return "same ordering"

    def check(self, sim: float, exp: float) -> bool:
        if not (np.isfinite(sim) and np.isfinite(exp)):
            return False
        if self.kind == "pct":
            return abs(sim - exp) <= self.value / 100.0 * abs(exp) * (1 + 1e-12)
        if self.kind == "factor":
            if exp == 0 or sim == 0 or (sim > 0) != (exp > 0):
                return False
            r = sim / exp
            return 1.0 / self.value <= r <= self.value
        return (sim - 1.0) * (exp - 1.0) > 0


def _f(v) -> float:
    try:
        return float(v) if v is not None else float("nan")
    except (TypeError, ValueError):
        return float("nan")


def make_row(quantity: str, simulation, experiment, tolerance: Tolerance, *, label=None, units=None,
             reference="experiment", note="", paper_experiment=None, paper_simulation=None,
             group="") -> dict:
    """One table row: simulation, experiment, difference, % difference, tolerance, pass."""
    s, e = _f(simulation), _f(experiment)
    # a row without two finite numbers never passes (NaN against NaN is not an agreement)
    ok = bool(np.isfinite(s) and np.isfinite(e) and tolerance.check(s, e))
    if quantity in LINE_QUANTITIES and np.isnan(s) and np.isnan(e):
        note = ("neither signal shows this line: nothing to compare, so not passed. " + note).strip()
    diff = s - e
    pct = 100.0 * diff / abs(e) if (np.isfinite(diff) and e != 0) else float("nan")
    lab, un = QUANTITIES.get(quantity, (quantity, "1"))
    return {
        "quantity": quantity if not group else f"{group}: {quantity}",
        "label": label or (lab if not group else f"{group}: {lab}"),
        "units": units or un,
        "simulation": s, "experiment": e, "difference": diff, "difference_pct": pct,
        "tolerance_pct": tolerance.pct, "tolerance": tolerance.text(), "rule": tolerance.kind,
        "pass": ok, "reason": tolerance.reason, "reference": reference,
        "note": note, "paper_experiment": _f(paper_experiment), "paper_simulation": _f(paper_simulation),
    }


# ------------------------------------------------------------------ measuring one signal
def _line_in_amplitude_spectrum(x, fs, expected_hz, *, tolerance=0.03):
    """Fundamental line near ``expected_hz`` in the Hann amplitude spectrum (analysis.fault_line)."""
    from . import analysis as A
    f, a = A.amplitude_spectrum(x, fs, window="hann")
    r = A.fault_line(f, a, expected_hz, tolerance=tolerance, n_harmonics=1)
    # a fundamental standing above analysis' FUNDAMENTAL_SNR_DB gets a measured_hz; harmonics not required
    return r["measured_hz"], float(r["snr_db"])


def impact_times(x, fs, period, *, band=None, start=None):
    """Impact instants: the envelope maximum in each window of one period.

    Starting at the strongest envelope value in the first period (or ``start``),
    every next impact is searched within +-40 % of a period around the last one
    plus ``period``: slip jitter never accumulates.
    """
    from scipy.signal import hilbert
    from . import analysis as A
    x = np.asarray(x, float)
    y = A.bandpass(x, fs, band=band) if band is not None else x - np.mean(x)
    env = np.abs(hilbert(y))
    n_per = period * fs
    if len(x) < 2 * n_per:
        return np.array([])
    k = int(np.argmax(env[: int(n_per)])) if start is None else int(start)
    out = [k]
    half = int(0.4 * n_per)
    while True:
        c = int(round(out[-1] + n_per))
        lo, hi = c - half, c + half + 1
        if hi >= len(env):
            break
        out.append(lo + int(np.argmax(env[lo:hi])))
    return np.asarray(out) / fs


def impulse_strength(x, fs, period, *, band=None):
    """Median over impacts of the largest |x| within +-20 % of a period around each impact."""
    x = np.asarray(x, float) - np.mean(x)
    t = impact_times(x, fs, period, band=band)
    if t.size < 3:
        return float("nan")
    w = max(1, int(0.2 * period * fs))
    peaks = [np.max(np.abs(x[max(0, int(k * fs) - w): int(k * fs) + w + 1])) for k in t]
    return float(np.median(peaks))


def _band_for(x, fs, fmax_line):
    from . import analysis as A
    from .errors import AnalysisError
    try:
        return A.fast_kurtogram(x, fs, min_bandwidth=min(fmax_line, 0.2 * fs)).band
    except AnalysisError:
        return None


def measure(x, fs, *, bearing, rpm=None, shaft_hz=None, fault=None, duration_level=0.1):
    """The table's quantities for one signal, measured the same way for recording and simulation.

    Parameters
    ----------
    x : 1-D array (m s-2); fs : Hz; bearing : catalog name or geometry;
    rpm : nominal speed prior (the recording's speed, or the scene's);
    shaft_hz : known shaft frequency (kinematic fault frequencies are searched around it);
    fault : "bpfo" | "bpfi" | None: the fault family whose period and impulses are measured
        (default: from the diagnosis).

    Returns
    -------
    dict with the keys of :data:`QUANTITIES` (NaN where the signal shows nothing) and
    ``extras``: the analysis result, band, impact times, notes.
    """
    from . import analysis as A
    from .errors import AnalysisError
    x = np.asarray(x, dtype=float)
    res = A.analyze(x, fs, bearing=bearing, rpm=rpm, shaft_hz=shaft_hz)
    fr = res["shaft_hz"]
    ff = res["fault_frequencies"]
    notes = {}
    out = {}
    fi, snr = _line_in_amplitude_spectrum(x, fs, fr if rpm is None else rpm / 60.0)
    out["shaft_hz"] = _f(fi)
    if fi is None:
        notes["shaft_hz"] = f"no shaft line in the amplitude spectrum (best candidate {snr:.1f} dB above the floor)"
    for k in ("bpfo", "bpfi"):
        out[k] = _f(ff[k]["measured_hz"])
        if ff[k]["measured_hz"] is None:
            notes[k] = (f"no {k.upper()} line family in the squared envelope spectrum "
                        f"(expected {ff[k]['expected_hz']:.2f} Hz; best {ff[k]['snr_db']:.1f} dB)")
    key = fault or {"outer_race": "bpfo", "inner_race": "bpfi"}.get(res["diagnosis"])
    period = res["excitation_period_s"]
    if period is None and key is not None and ff[key]["measured_hz"]:
        period = 1.0 / ff[key]["measured_hz"]
    out["excitation_period"] = _f(period)
    if period is None:
        notes["excitation_period"] = "no fault diagnosed: no impact train to time"
    m = res["metrics"]
    for k in ("rms", "peak", "crest_factor", "kurtosis"):
        out[k] = float(m[k])
    band = None
    times = np.array([])
    if period is not None and math.isfinite(period):
        band = _band_for(x, fs, 4.0 / period)
        times = impact_times(x, fs, period, band=band)
        out["impulse_strength"] = impulse_strength(x, fs, period, band=band)
        try:
            imp = A.impulses(x, fs, band=band, min_separation=0.5 * period, level=duration_level)
            d = np.asarray(imp.duration, float)
            out["impulse_duration"] = float(np.median(d)) if d.size else float("nan")
            if not d.size:
                notes["impulse_duration"] = "no impulse above the detection threshold"
        except AnalysisError as exc:
            out["impulse_duration"] = float("nan")
            notes["impulse_duration"] = str(exc)
    else:
        out["impulse_strength"] = float("nan")
        out["impulse_duration"] = float("nan")
    out["extras"] = {"analysis": res, "band": band, "impact_times": times, "notes": notes,
                     "fault": key, "shaft_hz_used": fr}
    return out


# ------------------------------------------------------------------ alignment
def align_by_impulse_phase(experiment, simulation, fs, period, *, band=None):
    """Samples to delay ``simulation`` by so that its first impact falls on the experiment's.

    Both signals at the same rate ``fs``.  Returns ``shift`` in [0, period*fs): the
    aligned simulation is ``sim[n - shift]``.
    """
    te = impact_times(experiment, fs, period, band=band)
    ts = impact_times(simulation, fs, period, band=band)
    if te.size == 0 or ts.size == 0:
        return 0
    n_per = period * fs
    return int(round((te[0] * fs - ts[0] * fs) % n_per))


def _shift(x, shift, n):
    out = np.full(n, np.nan)
    x = np.asarray(x, float)
    m = min(n - shift, len(x))
    if m > 0:
        out[shift: shift + m] = x[:m]
    return out


# ------------------------------------------------------------------ the sensor resonator
def sensor_response(f, frequency_hz, damping_ratio, gain=1.0):
    """Absolute-acceleration transmissibility of the scene's ``[sensor]`` resonator.

    The simulator integrates a base-excited oscillator on the outer ring,
    ``z'' + 2 zeta w z' + w^2 z = -a_ring``, and records ``gain * (a_ring + z'')``;
    so ``H = gain * (w^2 + 2j zeta w W) / (w^2 - W^2 + 2j zeta w W)`` at ``W = 2 pi f``.
    """
    w = 2 * np.pi * frequency_hz
    W = 2 * np.pi * np.asarray(f, float)
    num = w * w + 2j * damping_ratio * w * W
    return gain * num / (w * w - W * W + 2j * damping_ratio * w * W)


def apply_sensor(x, fs, frequency_hz, damping_ratio, gain=1.0):
    """Filter a sensor-off simulated acceleration through the resonator (FFT, zero-padded)."""
    x = np.asarray(x, float)
    n = len(x)
    nfft = 1 << int(math.ceil(math.log2(2 * n)))
    X = np.fft.rfft(x, nfft)
    H = sensor_response(np.fft.rfftfreq(nfft, 1 / fs), frequency_hz, damping_ratio, gain)
    return np.fft.irfft(X * H, nfft)[:n]


@dataclass
class CalibrationResult:
    """Fitted ``[sensor]`` parameters and how well they fit."""

    frequency_hz: float
    damping_ratio: float
    gain: float
    fit_error_db: float          # RMS of the residuals at the optimum, dB
    initial_error_db: float      # the same residuals for the uncalibrated simulation
    n_impacts_experiment: int
    n_impacts_simulation: int
    bounds: dict = field(default_factory=dict)
    envelope_time: np.ndarray | None = None
    envelope_experiment: np.ndarray | None = None
    envelope_before: np.ndarray | None = None
    envelope_after: np.ndarray | None = None
    limits: str = ""

    def as_dict(self):
        return {"frequency_hz": self.frequency_hz, "damping_ratio": self.damping_ratio, "gain": self.gain,
                "fit_error_db": self.fit_error_db, "initial_error_db": self.initial_error_db,
                "n_impacts_experiment": self.n_impacts_experiment,
                "n_impacts_simulation": self.n_impacts_simulation, "limits": self.limits}

    def overrides(self) -> dict:
        """``--set`` keys that put the fitted resonator into the scene."""
        return {"sensor.enabled": True, "sensor.frequency_hz": float(self.frequency_hz),
                "sensor.damping_ratio": float(self.damping_ratio), "sensor.gain": float(self.gain)}


def _segments(x, fs, times, pre, post):
    i0, i1 = int(round(pre * fs)), int(round(post * fs))
    idx = [int(round(t * fs)) for t in times]
    idx = [i for i in idx if i - i0 >= 0 and i + i1 < len(x)]
    if not idx:
        return np.zeros((0, i0 + i1))
    return np.stack([x[i - i0: i + i1] for i in idx])


def _mean_envelope(x, fs, times, pre, post):
    from scipy.signal import hilbert
    env = np.abs(hilbert(np.asarray(x, float) - np.mean(x)))
    seg = _segments(env, fs, times, pre, post)
    return seg.mean(axis=0) if seg.size else None


def _segment_spectrum(x, fs, times, pre, post):
    seg = _segments(np.asarray(x, float) - np.mean(x), fs, times, pre, post)
    if not seg.size:
        return None, None
    w = np.hanning(seg.shape[1])
    P = np.mean(np.abs(np.fft.rfft(seg * w, axis=1)) ** 2, axis=0)
    return np.fft.rfftfreq(seg.shape[1], 1 / fs), P


class _CalibrationProblem:
    """Residuals of the resonator fit (see :func:`calibrate_sensor`)."""

    #: weight of the impact-peak residual against the three shape views (each normalised to 1)
    PEAK_WEIGHT = 3.0

    def __init__(self, experiment, simulation, fs, period, *, band=None, pre=0.5e-3, post=None):
        from scipy.signal import hilbert
        from . import analysis as A
        self.A = A
        self.fs, self.period = fs, period
        e = np.asarray(experiment, float) - np.mean(experiment)
        s = np.asarray(simulation, float) - np.mean(simulation)
        self.e, self.s = e, s
        self.pre = pre
        self.post = post = 0.6 * period if post is None else post
        self.te = te = impact_times(e, fs, period, band=band)
        self.ts = ts = impact_times(s, fs, period, band=band)
        if te.size < 5 or ts.size < 5:
            raise ValidationCaseError(f"calibration needs at least 5 impacts in each signal; found "
                                      f"{te.size} measured and {ts.size} simulated")
        self.env_e = _mean_envelope(e, fs, te, pre, post)
        self.pk = int(np.argmax(self.env_e))
        self.floor = float(np.median(np.abs(hilbert(e))))
        fseg, self.Pe = _segment_spectrum(e, fs, te, pre, post)
        edges = np.geomspace(300.0, 0.45 * fs, 25)
        bins = [(fseg >= lo) & (fseg < hi) for lo, hi in zip(edges[:-1], edges[1:])]
        bins = [b for b in bins if b.any()]
        # where the impacts ring: bins within 20 dB of the strongest (below that the recording's
        # segments hold machine vibration and noise the model has no reason to match)
        level = np.array([self.Pe[b].mean() for b in bins])
        self.bins = [b for b, lv in zip(bins, level) if lv >= 0.01 * level.max()]
        self.f_ses, self.ses_e = A.squared_envelope_spectrum(e[: len(s)], fs, window="hann", fmax=6.0 / period)
        self.kh = [int(np.argmin(np.abs(self.f_ses - h / period))) for h in range(1, 6)]
        self.peak_e = self.impact_peak(e, te)

    def impact_peak(self, y, times):
        """90th percentile over impacts of max |y| within +-20 % of a period around each impact
        (a high percentile: inner-race impacts outside the load zone are weak, and the median
        of a strongly modulated train says little about its strong impacts)."""
        w = max(1, int(0.2 * self.period * self.fs))
        idx = (np.asarray(times) * self.fs).astype(int)
        return float(np.percentile([np.max(np.abs(y[max(0, i - w): i + w + 1])) for i in idx], 90))

    @staticmethod
    def _ses_at(ses, k):
        return max(ses[max(0, k - 1): k + 2].max(), 1e-30)

    def model(self, params):
        fn, zeta, g = np.exp(params)
        return apply_sensor(self.s, self.fs, fn, zeta, g)

    def envelope(self, y):
        env = np.sqrt(_mean_envelope(y, self.fs, self.ts, self.pre, self.post) ** 2 + self.floor ** 2)
        return np.roll(env, self.pk - int(np.argmax(env)))

    def residuals(self, params, parts=False):
        return self.residuals_of(self.model(params), parts=parts)

    def residuals_of(self, y, parts=False):
        fs, pk = self.fs, self.pk
        env_m = self.envelope(y)
        r1 = np.log(env_m[pk:] / np.maximum(self.env_e[pk:], 1e-30))
        _, Pm = _segment_spectrum(y, fs, self.ts, self.pre, self.post)
        r2 = np.array([0.5 * np.log((Pm[b].mean() + 1e-30) / (self.Pe[b].mean() + 1e-30)) for b in self.bins])
        _, ses_m = self.A.squared_envelope_spectrum(y, fs, window="hann", fmax=6.0 / self.period)
        r3 = np.array([0.25 * np.log(self._ses_at(ses_m, k) / self._ses_at(self.ses_e, k)) for k in self.kh])
        r0 = np.array([self.PEAK_WEIGHT * np.log(max(self.impact_peak(y, self.ts), 1e-30) / max(self.peak_e, 1e-30))])
        r = np.concatenate([r0, r1 / math.sqrt(len(r1)), r2 / math.sqrt(len(r2)), r3 / math.sqrt(len(r3))])
        return (r, (r0, r1, r2, r3)) if parts else r


def calibrate_sensor(experiment, simulation, fs, period, *, band=None,
                     frequency_bounds=(500.0, None), damping_bounds=(0.005, 0.5),
                     gain_bounds=(1e-3, 1e3), pre=0.5e-3, post=None, n_starts=3):
    """Fit the scene's ``[sensor]`` resonator (frequency, damping ratio, gain) to a recording.

    Least squares, in log amplitude, on four views of the impacts:

    0. the 90th percentile of the impact peaks (max |a| around each impact), weighted 3:
       it mostly sets the gain;
    1. the measured *impulse ringing*: the mean Hilbert envelope of the segments that
       start ``pre`` before each impact and last ``post`` (default 60 % of a period),
       experiment against the filtered simulation, peaks aligned;
    2. the mean power spectrum of the same segments, between 300 Hz and 0.45 fs in
       log-spaced bins, kept where the measured ringing is within 20 dB of its strongest bin;
    3. the squared envelope spectrum at the first five harmonics of the impact rate.

    The experiment's noise floor (median envelope between impacts) is added to the
    model's envelope in quadrature, so a quiet simulation is not pushed to fit noise.
    The resonance frequency is searched within +-30 % of the strongest peak of the measured
    impact-segment spectrum inside ``frequency_bounds``: one resonator stands for one
    dominant ringing band (a recording with two bands keeps the weaker one unfitted).
    ``simulation`` must be sensor-off (the resonator is applied with :func:`apply_sensor`);
    both signals at ``fs``.  Several starting frequencies avoid local minima.
    """
    from scipy.optimize import least_squares
    prob = _CalibrationProblem(experiment, simulation, fs, period, band=band, pre=pre, post=post)
    te, ts, env_e, pk, s = prob.te, prob.ts, prob.env_e, prob.pk, prob.s
    residuals, model = prob.residuals, prob.model

    fmax_b = frequency_bounds[1] or 0.45 * fs
    # the resonance is searched around the strongest peak of the measured impact-segment spectrum
    # (smoothed over ~150 Hz) inside the bounds: one resonator can fit one dominant ringing band only
    fseg, Pe = _segment_spectrum(prob.e, fs, te, prob.pre, prob.post)
    k = max(1, int(round(150.0 / (fseg[1] - fseg[0]))))
    Ps = np.convolve(Pe, np.ones(k) / k, mode="same")
    inside = (fseg >= frequency_bounds[0]) & (fseg <= fmax_b)
    f_peak = float(fseg[inside][np.argmax(Ps[inside])]) if inside.any() else 0.5 * (frequency_bounds[0] + fmax_b)
    f_lo, f_hi = max(frequency_bounds[0], 0.7 * f_peak), min(fmax_b, 1.3 * f_peak)
    lo = np.log([f_lo, damping_bounds[0], gain_bounds[0]])
    hi = np.log([f_hi, damping_bounds[1], gain_bounds[1]])
    best = None
    for fn0 in (0.9 * f_peak, f_peak, 1.1 * f_peak):
        for z0 in (0.03, 0.1):
            y = apply_sensor(s, fs, fn0, z0, 1.0)
            g0 = float(np.clip(prob.peak_e / max(prob.impact_peak(y, ts), 1e-30),
                               gain_bounds[0] * 1.01, gain_bounds[1] * 0.99))
            x0 = np.clip(np.log([fn0, z0, g0]), lo + 1e-6, hi - 1e-6)
            try:
                r = least_squares(residuals, x0, bounds=(lo, hi), x_scale=[0.2, 0.5, 1.0], max_nfev=40)
            except ValueError:
                continue
            if best is None or r.cost < best.cost:
                best = r
    if best is None:
        raise ValidationCaseError("calibration: the least-squares fit did not start (check the bounds)")

    def rms_db(vec):
        return float(20.0 / math.log(10) * math.sqrt(np.mean(np.square(vec))))

    _, parts = residuals(best.x, parts=True)
    allr = np.concatenate(parts)
    # "before": the same residuals for the simulation as it is (no resonator, unit gain)
    _, parts0 = prob.residuals_of(s, parts=True)
    env_b = prob.envelope(s)
    fn, zeta, g = (float(v) for v in np.exp(best.x))
    env_a = prob.envelope(model(best.x))
    at_bound = [name for name, v, a, b in zip(("frequency", "damping", "gain"), best.x, lo, hi)
                if abs(v - a) < 1e-3 or abs(v - b) < 1e-3]
    limits = ("one base-excited single-mode resonator stands for the whole housing and sensor path; "
              "the recording also holds noise and machine vibration the model does not simulate")
    if at_bound:
        limits += f"; the fit ended at a bound for: {', '.join(at_bound)}"
    return CalibrationResult(
        frequency_hz=fn, damping_ratio=zeta, gain=g, fit_error_db=rms_db(allr), initial_error_db=rms_db(np.concatenate(parts0)),
        n_impacts_experiment=int(te.size), n_impacts_simulation=int(ts.size),
        bounds={"frequency_hz": (float(f_lo), float(f_hi)),
                "damping_ratio": tuple(map(float, damping_bounds)), "gain": tuple(map(float, gain_bounds))},
        envelope_time=(np.arange(len(env_e)) - pk) / fs, envelope_experiment=env_e,
        envelope_before=env_b, envelope_after=env_a, limits=limits)


# ------------------------------------------------------------------ the comparison
def _spectrum(x, fs, n):
    from . import analysis as A
    x = np.asarray(x, float)[:n]
    f, a = A.amplitude_spectrum(x - np.mean(x), fs, window="hann")
    return f, a


def _ses(x, fs, n, band, fmax):
    from . import analysis as A
    x = np.asarray(x, float)[:n]
    return A.squared_envelope_spectrum(x, fs, window="hann", band=band, fmax=fmax)


class ComparisonResult:
    """Measured against simulated: a Dataset (waveforms, spectra, SES, table) and its plots.

    ``dataset`` dims: ``signal`` (e.g. "experiment", "simulation", "simulation_calibrated"),
    ``time`` (one time base, impacts aligned), ``frequency``, ``cyclic_frequency``,
    ``quantity`` (table rows).  Table variables: ``simulation``, ``experiment``,
    ``difference``, ``difference_pct``, ``tolerance_pct``, ``pass`` (+ labels, units,
    reasons).  Attributes hold the case name, fault frequencies and provenance (JSON).
    """

    def __init__(self, dataset: xr.Dataset):
        self.dataset = dataset

    # ---- table
    @property
    def rows(self) -> list[dict]:
        ds = self.dataset
        if "quantity" not in ds.dims:
            return []
        out = []
        for i in range(ds.sizes["quantity"]):
            row = {}
            for k in ("quantity", "label", "units", "tolerance", "rule", "reason", "reference", "note"):
                row[k] = str(ds[k].values[i]) if k in ds else ""
            for k in ("simulation", "experiment", "difference", "difference_pct", "tolerance_pct",
                      "paper_experiment", "paper_simulation"):
                v = float(ds[k].values[i]) if k in ds else float("nan")
                row[k] = v
            if not np.isfinite(row["tolerance_pct"]):
                row["tolerance_pct"] = None
            row["pass"] = bool(ds["pass"].values[i])
            out.append(row)
        return out

    @property
    def passed(self) -> bool:
        return all(r["pass"] for r in self.rows)

    # ---- plots
    def _ax(self, ax, figsize=(9, 3.2)):
        if ax is None:
            import matplotlib.pyplot as plt
            _, ax = plt.subplots(figsize=figsize, layout="constrained")
        return ax

    def plot_waveforms(self, ax=None, *, signals=None, window_s=None, acceleration_units="g"):
        """Waveforms on the common time base (impacts aligned); ``window_s`` (start, stop)."""
        ax = self._ax(ax)
        ds = self.dataset
        scale = G0 if acceleration_units == "g" else 1.0
        t = ds["time"].values
        sel = slice(None)
        if window_s is not None:
            sel = (t >= window_s[0]) & (t <= window_s[1])
        for s in signals or list(ds["signal"].values):
            if s not in list(ds["signal"].values):
                continue
            y = ds["waveform"].sel(signal=s).values / scale
            ax.plot(t[sel], y[sel], lw=0.7, label=str(s).replace("_", " "))
        ax.set_xlabel("time (s)")
        ax.set_ylabel(f"acceleration ({acceleration_units})")
        ax.legend(loc="upper right", fontsize=8)
        return ax

    def plot_spectra(self, ax=None, *, signals=None, fmax=None, acceleration_units="g", log=True):
        """Amplitude spectra on the common frequency axis."""
        ax = self._ax(ax)
        ds = self.dataset
        scale = G0 if acceleration_units == "g" else 1.0
        f = ds["frequency"].values
        sel = f <= (fmax or f[-1])
        for s in signals or list(ds["signal"].values):
            if s not in list(ds["signal"].values):
                continue
            y = ds["spectrum"].sel(signal=s).values / scale
            ax.plot(f[sel], y[sel], lw=0.6, label=str(s).replace("_", " "))
        if log:
            ax.set_yscale("log")
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel(f"amplitude ({acceleration_units})")
        ax.legend(loc="upper right", fontsize=8)
        return ax

    def plot_envelope(self, ax=None, *, signals=None, frequency_units="Hz", fmax=None, normalize=True,
                      markers=("bpfo", "bpfi", "shaft")):
        """Squared envelope spectra with fault-frequency markers (harmonics 1-5)."""
        ax = self._ax(ax)
        ds = self.dataset
        f = ds["cyclic_frequency"].values
        fscale = {"Hz": 1.0, "kHz": 1e3}.get(frequency_units, 1.0)
        sel = f <= (fmax or f[-1])
        for s in signals or list(ds["signal"].values):
            if s not in list(ds["signal"].values):
                continue
            y = ds["ses"].sel(signal=s).values.astype(float)
            if normalize:
                pos = y[sel & (f > 5)]
                y = y / (np.nanmax(pos) if pos.size and np.nanmax(pos) > 0 else 1.0)
            ax.plot(f[sel] / fscale, y[sel], lw=0.7, label=str(s).replace("_", " "))
        colors = {"bpfo": "tab:red", "bpfi": "tab:green", "shaft": "0.5"}
        for m in markers:
            fm = ds.attrs.get(f"{m}_hz")
            if not fm:
                continue
            for h in range(1, 6):
                if h * fm <= f[sel][-1]:
                    ax.axvline(h * fm / fscale, color=colors.get(m, "k"), ls="--", lw=0.6,
                               label=m.upper() if h == 1 else None)
        ax.set_xlabel(f"cyclic frequency ({frequency_units})")
        ax.set_ylabel("SES (normalised)" if normalize else "SES")
        ax.legend(loc="upper right", fontsize=8)
        return ax

    # ---- save / load
    def to_netcdf(self, path):
        from .io_netcdf import write_netcdf
        write_netcdf(self.dataset, path)
        return path

    @classmethod
    def load(cls, path) -> "ComparisonResult":
        with xr.open_dataset(path) as ds:
            ds = ds.load()
        if "pass" in ds:
            ds["pass"] = ds["pass"].astype(bool)
        return cls(ds)

    def __repr__(self):
        n = len(self.rows)
        ok = sum(r["pass"] for r in self.rows)
        return f"<ComparisonResult {self.dataset.attrs.get('case', '')!r}: {ok}/{n} rows pass>"


def table_dataset(rows: list[dict]) -> xr.Dataset:
    """The rows as Dataset variables along ``quantity``."""
    q = [r["quantity"] for r in rows]
    data = {}
    for k in ("label", "units", "tolerance", "rule", "reason", "reference", "note"):
        data[k] = ("quantity", np.array([str(r.get(k, "")) for r in rows], dtype=object))
    for k in ("simulation", "experiment", "difference", "difference_pct", "tolerance_pct",
              "paper_experiment", "paper_simulation"):
        data[k] = ("quantity", np.array([_f(r.get(k)) for r in rows], dtype=float))
    data["pass"] = ("quantity", np.array([bool(r["pass"]) for r in rows], dtype=bool))
    return xr.Dataset(data, coords={"quantity": ("quantity", np.array(q, dtype=object))})


def compare(signals: dict, fs: float, rows: list[dict], *, n=None, band=None, ses_fmax=1000.0,
            attrs=None) -> ComparisonResult:
    """Assemble a :class:`ComparisonResult` from signals already on one time base.

    Parameters
    ----------
    signals : {name: 1-D array} sampled at ``fs`` and aligned (NaN where a shifted signal has no data).
    rows : table rows from :func:`make_row`.
    n : samples kept (default: the shortest signal).
    band : demodulation band of the SES (the same for every signal), or None.
    """
    names = list(signals)
    n = n or min(len(v) for v in signals.values())
    wave = np.stack([np.asarray(signals[k], float)[:n] for k in names])
    spec, ses = [], []
    for k in names:
        y = np.nan_to_num(wave[names.index(k)], nan=0.0)
        f, a = _spectrum(y, fs, n)
        fc, sv = _ses(y, fs, n, band, ses_fmax)
        spec.append(a)
        ses.append(sv)
    ds = xr.Dataset(
        {"waveform": (("signal", "time"), wave, {"units": "m s-2", "long_name": "acceleration"}),
         "spectrum": (("signal", "frequency"), np.stack(spec),
                      {"units": "m s-2", "long_name": "amplitude spectrum (Hann, peak amplitude)"}),
         "ses": (("signal", "cyclic_frequency"), np.stack(ses),
                 {"units": "m2 s-4", "long_name": "squared envelope spectrum"})},
        coords={"signal": ("signal", np.array(names, dtype=object)),
                "time": ("time", np.arange(n) / fs, {"units": "s"}),
                "frequency": ("frequency", f, {"units": "Hz"}),
                "cyclic_frequency": ("cyclic_frequency", fc, {"units": "Hz"})})
    if rows:
        ds = ds.merge(table_dataset(rows))
    ds.attrs.update({"sampling_rate_hz": float(fs), "ses_band": json.dumps(band and list(map(float, band)))})
    for k, v in (attrs or {}).items():
        ds.attrs[k] = v if isinstance(v, (str, int, float)) else json.dumps(v, default=str)
    return ComparisonResult(ds)
