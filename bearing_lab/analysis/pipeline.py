"""The full analysis of one channel: what ``bearing-lab analyze`` prints.

Why one function: the CLI, the validation cases and users' notebooks must get
the same numbers from the same signal.  :func:`analyze` runs, in this order,
with one fixed method for every recording (no per-file tuning):

1. metrics of the raw signal (:func:`~bearing_lab.analysis.metrics`);
2. shaft frequency (:func:`~bearing_lab.analysis.shaft_frequency`, rectangular
   window / Quinn).  With ``rpm`` the estimate is searched within +-5 % of
   rpm/60 and used when at least ``MIN_SHAFT_LINES`` (5) harmonics support it;
   otherwise rpm/60 itself is used.  Without ``rpm`` the estimate is used as is.
   ``shaft_hz`` overrides both.  A file's stored rpm is never read here;
3. kinematic fault frequencies of ``bearing`` at that shaft frequency;
4. demodulation band: the fast kurtogram's best band among bands at least as
   wide as the highest line searched (``n_harmonics * max(BPFI, 2 BSF) * 1.02 + f_r``),
   so the SES holds every line the search needs (optionally after cepstral
   pre-whitening);
5. squared envelope spectrum (Hann window) and the fault search and diagnosis of
   :func:`~bearing_lab.analysis.diagnose_ses`;
6. excitation period: when a fault is diagnosed, the impact rate refined by
   :func:`~bearing_lab.analysis.excitation_period` within +-1 % of the measured
   line, in the same band.

The result follows contract.md's ``analyze --json`` schema exactly.  BSF is
reported on the BSF scale (the search runs at 2 BSF, where ball faults show;
``measured_hz`` is half the line found there).
"""
from __future__ import annotations

import math

import numpy as np

from ..bearings import BearingGeometry, get_bearing
from ..errors import AnalysisError, BearingLabError
from ._faults import diagnose_ses
from ._impulse import excitation_period
from ._metrics import METRIC_NAMES, metrics
from ._spectral import amplitude_spectrum, cepstral_prewhitening, fast_kurtogram, squared_envelope_spectrum
from ._speed import shaft_frequency
from ._util import check_fs, check_signal

__all__ = ["analyze", "plot_analysis", "MIN_SHAFT_LINES"]

#: Harmonics needed before a signal-based shaft estimate overrides a given rpm.
MIN_SHAFT_LINES = 5


def _bearing(bearing):
    if isinstance(bearing, BearingGeometry):
        return bearing
    if bearing is None:
        raise AnalysisError("analyze: bearing is required (a catalog name such as '6205' or a "
                            "BearingGeometry)")
    try:
        return get_bearing(bearing)
    except BearingLabError as exc:
        raise AnalysisError(f"analyze: {exc}") from None


def _run(x, fs, *, bearing, rpm=None, shaft_hz=None, tolerance=0.02, n_harmonics=5, prewhiten=False):
    fs = check_fs(fs, func="analyze")
    x = check_signal(x, func="analyze", min_samples=1024)
    if x.ndim != 1:
        raise AnalysisError(f"analyze: x must be one channel (1-D), got shape {x.shape}")
    geom = _bearing(bearing)
    m = metrics(x)
    if shaft_hz is not None:
        fr = float(shaft_hz)
        if not (math.isfinite(fr) and fr > 0):
            raise AnalysisError(f"analyze: shaft_hz={shaft_hz!r} must be a positive frequency in Hz")
    else:
        if rpm is not None and not (math.isfinite(rpm) and rpm > 0):
            raise AnalysisError(f"analyze: rpm={rpm!r} must be a positive speed in r/min")
        fr, nlines = shaft_frequency(x, fs, window="boxcar", rpm=rpm)
        if rpm is not None and nlines < MIN_SHAFT_LINES:
            fr = rpm / 60.0
    ff = geom.fault_frequencies(fr)
    top = n_harmonics * max(ff["bpfi"], 2 * ff["bsf"], ff["bpfo"]) * (1 + tolerance) + fr
    if top + 20.0 >= fs / 2:
        raise AnalysisError(f"analyze: fs={fs:g} Hz is too low to see {n_harmonics} harmonics of the "
                            f"fault frequencies (up to {top:.0f} Hz) of bearing {geom.name!r}")
    xx = cepstral_prewhitening(x) if prewhiten else x
    try:
        band = fast_kurtogram(xx, fs, min_bandwidth=top).band
    except AnalysisError:
        band = None  # too short for a kurtogram: demodulate the whole band
    f, ses = squared_envelope_spectrum(xx, fs, window="hann", band=band, fmax=top + 20.0)
    diagnosis, lines = diagnose_ses(f, ses, ff, shaft_hz=fr, tolerance=tolerance, n_harmonics=n_harmonics)
    period = None
    key = {"outer_race": "bpfo", "inner_race": "bpfi", "ball": "bsf"}.get(diagnosis)
    if key is not None:
        f1 = lines[key]["measured_hz"]
        try:
            period, _ = excitation_period(xx, fs, frequency_range=(0.99 * f1, 1.01 * f1), band=band)
        except AnalysisError as exc:  # too few clear harmonics for the refined estimate
            period = 1.0 / f1
            import warnings
            warnings.warn(f"excitation period from the {key.upper()} line alone (1/{f1:.4f} Hz), not the "
                          f"harmonic fit: {exc}", stacklevel=2)
    result = {
        "channel": "",
        "sampling_rate_hz": fs,
        "shaft_hz": float(fr),
        "diagnosis": diagnosis,
        "fault_frequencies": {},
        "excitation_period_s": None if period is None else float(period),
        "metrics": {k: float(m[k]) for k in METRIC_NAMES},
        "units": "",
    }
    for k in ("bpfo", "bpfi", "bsf", "ftf"):
        ln = lines[k]
        scale = 0.5 if k == "bsf" else 1.0
        result["fault_frequencies"][k] = {
            "expected_hz": float(ff[k]),
            "measured_hz": None if ln["measured_hz"] is None else float(ln["measured_hz"] * scale),
            "snr_db": float(ln["snr_db"]),
            "harmonics": int(ln["harmonics"]),
        }
    extras = {"f": f, "ses": ses, "band": band, "lines": lines, "bearing": geom}
    return result, extras


def analyze(x, fs, *, bearing, rpm=None, shaft_hz=None, channel="", units="m s-2", tolerance=0.02,
            n_harmonics=5, prewhiten=False):
    """Analyse one vibration channel: metrics, shaft speed, fault lines, diagnosis.

    Parameters
    ----------
    x : array_like, 1-D
        Acceleration (or any vibration signal), in ``units``.
    fs : float
        Sampling rate, Hz.
    bearing : str or BearingGeometry
        Catalog name (``"6205"``, ``"ZA-2115"``, ``"MFPT"``, ...) or geometry.
    rpm : float, optional
        Nominal shaft speed, r/min: a prior for the speed estimate (module docstring).
    shaft_hz : float, optional
        Known shaft frequency, Hz; skips the estimate.
    channel : str
        Channel name, copied into the result.
    units : str
        Unit of ``x`` (default "m s-2"), copied into the result.
    tolerance : float
        Slip tolerance of the fault search (default 0.02).
    n_harmonics : int
        Harmonics examined per fault (default 5).
    prewhiten : bool
        Cepstral pre-whitening before band selection and SES (default False).

    Returns
    -------
    dict
        contract.md's ``analyze --json`` object: ``channel``, ``sampling_rate_hz``,
        ``shaft_hz``, ``diagnosis``, ``fault_frequencies`` (bpfo, bpfi, bsf,
        ftf: ``expected_hz``, ``measured_hz`` or None, ``snr_db``,
        ``harmonics``), ``excitation_period_s`` (None without a diagnosis),
        ``metrics`` (eight floats, kurtosis Pearson) and ``units``.

    Notes
    -----
    The shaft speed comes from shaft harmonics in the spectrum.  A signal without
    them (a noise-free simulation, say) needs ``rpm`` or ``shaft_hz``: without
    either, the impact family itself would be taken for the shaft.

    References
    ----------
    .. [1] Randall & Antoni, "Rolling element bearing diagnostics - a tutorial",
       MSSP 25 (2011) 485-520.

    Examples
    --------
    An outer-race fault of a 6205 at 1797 r/min (impacts at 3.5848 f_r ringing 3 kHz):

    >>> import numpy as np
    >>> from bearing_lab.analysis import analyze
    >>> fs = 12000.0; t = np.arange(120000) / fs; fr = 1797 / 60
    >>> tau = t % (1 / (3.5848 * fr))
    >>> x = np.exp(-900 * tau) * np.sin(2 * np.pi * 3000 * tau) + np.cos(2 * np.pi * fr * t)
    >>> x = x + np.random.default_rng(0).normal(0, 0.3, t.size)
    >>> r = analyze(x, fs, bearing="6205", rpm=1797)
    >>> r["diagnosis"], round(r["fault_frequencies"]["bpfo"]["measured_hz"], 1)
    ('outer_race', 107.4)
    """
    result, _ = _run(x, fs, bearing=bearing, rpm=rpm, shaft_hz=shaft_hz, tolerance=tolerance,
                     n_harmonics=n_harmonics, prewhiten=prewhiten)
    result["channel"] = str(channel)
    result["units"] = str(units)
    return result


def plot_analysis(x, fs, *, bearing, rpm=None, shaft_hz=None, channel="", units="m s-2", path=None,
                  fig=None, **kwargs):
    """Figure of one analysis: waveform, amplitude spectrum, SES with fault markers.

    Parameters
    ----------
    x, fs, bearing, rpm, shaft_hz, channel, units, **kwargs
        As in :func:`analyze`.
    path : str or Path, optional
        Save the figure there (PNG, PDF, SVG by extension).
    fig : matplotlib.figure.Figure, optional
        Figure to draw into (default: a new 10 x 9 in figure).

    Returns
    -------
    fig : matplotlib.figure.Figure
    result : dict
        The :func:`analyze` result.

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import plot_analysis
    >>> fs = 12000.0; t = np.arange(60000) / fs
    >>> fig, r = plot_analysis(np.random.default_rng(0).normal(size=t.size), fs, bearing="6205",
    ...                        shaft_hz=29.95)
    >>> len(fig.axes)
    3
    """
    if fig is None:
        # a bare Figure (no pyplot): no backend switch, no global state; savefig works headless
        from matplotlib.figure import Figure
        fig = Figure(figsize=(10, 9), layout="constrained")
    result, ex = _run(x, fs, bearing=bearing, rpm=rpm, shaft_hz=shaft_hz, **kwargs)
    result["channel"], result["units"] = str(channel), str(units)
    x = np.asarray(x, float)
    ax1, ax2, ax3 = fig.subplots(3, 1)
    t = np.arange(x.size) / fs
    ax1.plot(t, x, lw=0.4, color="k")
    ax1.set(xlabel="time (s)", ylabel=f"{channel or 'signal'} ({units})",
            title=f"{channel or 'signal'}: diagnosis {result['diagnosis']}, "
                  f"f_r = {result['shaft_hz']:.3f} Hz, kurtosis {result['metrics']['kurtosis']:.2f}")
    f, a = amplitude_spectrum(x, fs, window="hann")
    ax2.semilogy(f, np.maximum(a, 1e-300), lw=0.4, color="k")
    if ex["band"] is not None:
        ax2.axvspan(*ex["band"], color="tab:orange", alpha=0.2, label="demodulation band (kurtogram)")
        ax2.legend(loc="upper right")
    ax2.set(xlabel="frequency (Hz)", ylabel=f"amplitude ({units})", title="amplitude spectrum (Hann)",
            xlim=(0, fs / 2))
    ax3.plot(ex["f"], ex["ses"], lw=0.6, color="k")
    ses_units = f"({units})^2"
    ax3.set(xlabel="cyclic frequency (Hz)", ylabel=f"SES {ses_units}", title="squared envelope spectrum",
            xlim=(0, ex["f"][-1]))
    colors = {"bpfo": "tab:red", "bpfi": "tab:blue", "bsf": "tab:green", "ftf": "tab:purple"}
    ymax = float(np.max(ex["ses"][1:])) if ex["ses"].size > 1 else 1.0
    for k, c in colors.items():
        fe = result["fault_frequencies"][k]["expected_hz"] * (2 if k == "bsf" else 1)
        name = "2·BSF" if k == "bsf" else k.upper()
        for h in range(1, 6):
            if h * fe < ex["f"][-1]:
                ax3.axvline(h * fe, color=c, ls="--", lw=0.8, alpha=0.7,
                            label=f"{name} {fe:.1f} Hz (expected)" if h == 1 else None)
        fm = result["fault_frequencies"][k]["measured_hz"]
        if fm is not None:
            fm = fm * (2 if k == "bsf" else 1)
            i = int(np.argmin(np.abs(ex["f"] - fm)))
            ax3.plot([fm], [ex["ses"][i] * 1.04 + 0.02 * ymax], marker="v", ls="none", color=c, ms=7,
                     label=f"{name} found {fm:.2f} Hz, {result['fault_frequencies'][k]['harmonics']} "
                           f"harmonics, SNR {result['fault_frequencies'][k]['snr_db']:.0f} dB")
    ax3.set_ylim(0, 1.15 * ymax)
    ax3.legend(loc="upper right", fontsize=8)
    if path is not None:
        from .._files import savefig
        savefig(fig, path, dpi=110)  # atomic: an existing figure survives a failed write
    return fig, result
