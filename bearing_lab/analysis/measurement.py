"""One ruler for recordings and simulations: the quantities a validation compares.

Why: a comparison is only as honest as its measurement.  Both signals go through
this one function (same window, same band selection, same line search, same
impact cutting), and a quantity the signal does not show (no line found, no
impulse) is NaN with a note saying why, never a default number.

Public API
----------
measure(x, fs, *, bearing, rpm=None, shaft_hz=None, fault=None, duration_level=0.1,
        duration_band="own")
    -- dict of frequencies, metrics and impact quantities, plus ``extras``
shaft_line(x, fs, expected_hz, *, tolerance=0.03) -- (measured Hz or None, SNR dB)
"""
from __future__ import annotations

import math

import numpy as np

from .._docdict import fill_doc
from ..errors import AnalysisError
from ._faults import fault_line
from ._impulse import impulses
from ._spectral import amplitude_spectrum, fast_kurtogram
from .impacts import impact_times, impulse_strength
from .pipeline import analyze

__all__ = ["measure", "shaft_line", "MEASURED"]

#: the keys :func:`measure` returns (besides ``extras``), with their SI units
MEASURED = {"shaft_hz": "Hz", "bpfo": "Hz", "bpfi": "Hz", "excitation_period": "s", "rms": "m s-2",
            "peak": "m s-2", "crest_factor": "1", "kurtosis": "1", "impulse_duration": "s",
            "impulse_strength": "m s-2"}


def shaft_line(x, fs, expected_hz, *, tolerance=0.03):
    """The shaft line near ``expected_hz`` in the Hann amplitude spectrum.

    Returns ``(measured_hz, snr_db)``; ``measured_hz`` is None when no fundamental stands
    above the fault search's threshold (:data:`bearing_lab.analysis._faults.FUNDAMENTAL_SNR_DB`).
    """
    f, a = amplitude_spectrum(x, fs, window="hann")
    r = fault_line(f, a, expected_hz, tolerance=tolerance, n_harmonics=1)
    return r["measured_hz"], float(r["snr_db"])


def _band_for(x, fs, fmax_line):
    try:
        return fast_kurtogram(x, fs, min_bandwidth=min(fmax_line, 0.2 * fs)).band
    except AnalysisError:
        return None


def _num(v) -> float:
    return float(v) if v is not None else float("nan")


def _duration_band(duration_band, fs):
    """The band the impulse duration is measured in: "own" (the signal's kurtogram band), None (the whole
    band) or a (low, high) pair in Hz inside (0, fs / 2)."""
    if duration_band is None or (isinstance(duration_band, str) and duration_band == "own"):
        return duration_band
    try:
        lo, hi = (float(v) for v in duration_band)
    except (TypeError, ValueError):
        raise AnalysisError(f"measure: duration_band={duration_band!r} must be 'own', None or a (low, high) "
                            "pair in Hz") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo < hi <= fs / 2):
        raise AnalysisError(f"measure: duration_band=({lo:g}, {hi:g}) Hz must be increasing and lie within "
                            f"0 to fs / 2 = {fs / 2:g} Hz")
    return lo, hi


def _impact_quantities(x, fs, period, level, out, notes, duration_band="own"):
    band = _band_for(x, fs, 4.0 / period)
    times = impact_times(x, fs, period, band=band)
    out["impulse_strength"] = impulse_strength(x, fs, period, band=band)
    dband = band if isinstance(duration_band, str) else duration_band
    try:
        imp = impulses(x, fs, band=dband, min_separation=0.5 * period, level=level)
        d = np.asarray(imp.duration, float)
        out["impulse_duration"] = float(np.median(d)) if d.size else float("nan")
        if not d.size:
            notes["impulse_duration"] = "no impulse above the detection threshold"
    except AnalysisError as exc:
        out["impulse_duration"] = float("nan")
        notes["impulse_duration"] = str(exc)
    return band, times


def _fault_families(res, out, notes) -> dict:
    """BPFO and BPFI into ``out`` (Hz, NaN without a detected family, the reason in ``notes``).

    A family's frequency only where a route of the analysis detects the family (noise rule and
    decoys): the best line of a slip window always exists in a dense spectrum, and comparing two
    such picks compares chance.  The routes that decided the diagnosis are asked first.  Returns,
    per family, ``detected``, the ``route`` and ``evidence_margin_score`` (the best route's evidence
    score over its decoy threshold)."""
    ev = res.get("evidence", {})
    routes = ev.get("routes", {})
    order = [r for r in [*(ev.get("decided_by") or []), ev.get("reported_route")] + sorted(routes) if r in routes]
    families = {}
    for k in ("bpfo", "bpfi"):
        found = next(((r, routes[r]["families"][k]) for r in dict.fromkeys(order)
                      if routes[r]["families"][k]["detected"] and not routes[r]["families"][k]["explained_by"]),
                     None)
        fk = res["fault_frequencies"][k]
        margins = [f["evidence_score"] - f["decoy_threshold_score"] for f in (routes[r]["families"][k] for r in routes)
                   if f.get("decoy_threshold_score") is not None]
        families[k] = {"detected": found is not None, "route": None if found is None else found[0],
                       "evidence_margin_score": max(margins) if margins else None}
        out[k] = _num(found[1]["measured_hz"]) if found is not None else float("nan")
        if found is None:
            best = ("no line in the slip window" if fk["measured_hz"] is None else
                    f"best candidate {fk['measured_hz']:.2f} Hz, {fk['snr_db']:.1f} dB, "
                    f"{fk['harmonics']} harmonic(s)")
            notes[k] = (f"no {k.upper()} line family in the squared envelope spectrum (expected "
                        f"{fk['expected_hz']:.2f} Hz; {best}: below the detection rule)")
    return families


@fill_doc
def measure(x, fs, *, bearing, rpm=None, shaft_hz=None, fault=None, duration_level=0.1, duration_band="own"):
    """The quantities of a validation table for one signal, measured the same way for recording
    and simulation.

    Parameters
    ----------
    x : array_like, 1-D
        Acceleration, m s-2.
    %(fs)s
    bearing : str or BearingGeometry
        Catalog name or geometry.
    rpm : float, optional
        Nominal speed prior, r/min (the recording's stored speed, or the scene's).
    shaft_hz : float, optional
        Known shaft frequency, Hz: the kinematic fault frequencies are searched around it.
    fault : {"bpfo", "bpfi"}, optional
        Fault family whose period and impulses are measured (default: from the diagnosis).
    duration_level : float
        Relative level of the impulse duration (default 0.1).
    duration_band : "own", None or (float, float)
        Band (Hz) the impulse duration is measured in: "own" (default) this signal's kurtogram
        band, None the whole band, or a given band.  A duration depends on the band (a ringing
        outside it is not seen), so a simulation compared with a recording is measured in the
        recording's band (its ``extras["band"]``).

    Returns
    -------
    dict
        The keys of :data:`MEASURED` (NaN where the signal shows nothing) and ``extras``:
        ``analysis`` (the :func:`bearing_lab.analysis.analyze` result), ``band``,
        ``impact_times``, ``duration_band`` (the band the impulse duration was measured in), ``notes``
        (why a value is NaN), ``fault``, ``shaft_hz_used``,
        ``families`` (per BPFO/BPFI: ``detected``, the ``route`` that detected it, and
        ``evidence_margin_score``, the best route's evidence above its decoy threshold: how far the
        detection is from flipping).  BPFO and BPFI carry a value only where a route of the
        analysis *detects* the family; the best line of a slip window alone is no measurement.

    Examples
    --------
    >>> import numpy as np
    >>> fs = 12000.0; t = np.arange(60000) / fs; fr = 1797 / 60
    >>> tau = t % (1 / (3.5848 * fr))
    >>> x = np.exp(-900 * tau) * np.sin(2 * np.pi * 3000 * tau)
    >>> x = x + np.random.default_rng(0).normal(0, 0.1, t.size)
    >>> m = measure(x, fs, bearing="6205", rpm=1797, fault="bpfo")
    >>> round(m["bpfo"], 1), bool(np.isnan(m["bpfi"]))
    (107.4, True)
    """
    x = np.asarray(x, dtype=float)
    res = analyze(x, fs, bearing=bearing, rpm=rpm, shaft_hz=shaft_hz)
    duration_band = _duration_band(duration_band, fs)
    fr = res["shaft_hz"]
    ff = res["fault_frequencies"]
    notes, out = {}, {}
    fi, snr = shaft_line(x, fs, fr if rpm is None else rpm / 60.0)
    out["shaft_hz"] = _num(fi)
    if fi is None:
        notes["shaft_hz"] = f"no shaft line in the amplitude spectrum (best candidate {snr:.1f} dB above the floor)"
    families = _fault_families(res, out, notes)
    key = fault or {"outer_race": "bpfo", "inner_race": "bpfi"}.get(res["diagnosis"])
    period = res["excitation_period_s"]
    if period is None and key is not None and ff[key]["measured_hz"]:
        period = 1.0 / ff[key]["measured_hz"]
    out["excitation_period"] = _num(period)
    if period is None:
        notes["excitation_period"] = "no fault diagnosed: no impact train to time"
    for k in ("rms", "peak", "crest_factor", "kurtosis"):
        out[k] = float(res["metrics"][k])
    band, times = None, np.array([])
    if period is not None and math.isfinite(period):
        band, times = _impact_quantities(x, fs, period, duration_level, out, notes, duration_band)
    else:
        out["impulse_strength"] = out["impulse_duration"] = float("nan")
        notes["impulse_strength"] = notes["impulse_duration"] = "no impact train"
    out["extras"] = {"analysis": res, "band": band, "impact_times": times, "notes": notes, "families": families,
                     "fault": key, "shaft_hz_used": fr,
                     "duration_band": band if isinstance(duration_band, str) else duration_band}
    return out
