"""The full analysis of one channel: what ``bearing-lab analyze`` prints.

Why one function: the CLI, the validation cases and users' notebooks must get
the same numbers from the same signal.  :func:`analyze` runs, in this order,
with one fixed method for every recording (no per-file tuning):

1. metrics of the raw signal (:func:`~bearing_lab.analysis.metrics`);
2. shaft speed, in this order of preference: ``shaft_hz`` as given; a tacho
   signal (pulse times; the signal is order-tracked first when the speed varies
   by more than 0.4 %); a given or stored speed used as a prior and checked
   against the signal's 1x line family; or the signal alone, which names a
   speed only when the bearing's kinematics rule out that the line family is a
   fault comb (:mod:`._shaft`), and otherwise says "unresolved";
3. kinematic fault frequencies of ``bearing`` at that speed;
4. three routes to the fault families (:mod:`._diagnosis`): the SES of the fast
   kurtogram's band (bands at least as wide as the highest line searched,
   ``n_harmonics * max(BPFO, BPFI, 2 BSF) (1 + tolerance) + f_r``), the SES of
   the cepstrum-pre-whitened signal, and the enhanced envelope spectrum;
   families are searched with harmonics, sidebands and decoys
   (:mod:`._families`);
5. the three-level verdict (diagnosed / uncertain / no fault evidence) with
   its evidence, and flags where a fault line sits next to a shaft or cage
   harmonic;
6. excitation period: when a fault is diagnosed, the impact rate refined by
   :func:`~bearing_lab.analysis.excitation_period` within +-1 % of the
   measured line, in the deciding route's signal and band.

BSF is reported on the BSF scale (the search runs at 2 BSF, where ball faults
show; ``measured_hz`` is half the line found there).  The JSON layout is
documented in ``docs/analysis.md``.
"""
from __future__ import annotations

import math
import warnings
from types import SimpleNamespace

import numpy as np

from .._docdict import fill_doc
from ..bearings import BearingGeometry, get_bearing
from ..errors import AnalysisError, BearingLabError, check_choice
from ..utils._files import savefig
from ..utils.figures import new_figure  # detached from pyplot, shown inline as a cell's value
from ._diagnosis import (coincidences, combine, deciding_route, interpretations, line_stats, route_summary,
                         run_routes, runner_up, spectrum_top)
from ._families import LABELS, SK_MIN, CyclicSpectrum
from ._floor import band_rms, floor_in_units
from ._hump import apply as apply_humps
from ._impulse import excitation_period
from ._kurtogram import KurtogramTree
from ._metrics import METRIC_NAMES, metrics
from ._shaft import BLIND_RANGE_HZ, resolve_speed
from ._spectral import Prewhitened, amplitude_spectrum, record_ses
from ._speed import SpectrumFloors, shaft_frequency
from ._tacho import ORDER_TRACK_VARIATION, order_track, tacho_pulses, tacho_speed
from ._util import check_fs, check_signal

__all__ = ["analyze", "plot_analysis", "shaft_speed", "SPEED_SOURCES"]

SPEED_SOURCES = ("given", "file", "tacho", "estimated", "unresolved")


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


def _fixed_speed(fr, source, status, note, **extra):
    return {"shaft_hz": float(fr), "source": source, "status": status, "prior_hz": extra.pop("prior_hz", None),
            "harmonics": 0, "snr_db": 0.0, "deviation_pct": None, "candidates": [], "note": note, **extra}


def _tacho_speed(x, fs, tacho, pulses_per_rev):
    """(signal to analyse, speed dict) from a tacho signal."""
    tacho = check_signal(tacho, func="analyze", name="tacho", min_samples=16)
    if tacho.shape != x.shape:
        raise AnalysisError(f"analyze: the tacho signal has {tacho.size} samples, the channel {x.size}")
    pulses = tacho_pulses(tacho, fs)
    fr, per_rev, variation = tacho_speed(pulses, pulses_per_rev=pulses_per_rev)
    extra = {"pulses": int(pulses.size), "variation_pct": 100 * variation,
             "min_rpm": float(60 * per_rev.min()), "max_rpm": float(60 * per_rev.max())}
    if variation > ORDER_TRACK_VARIATION:
        xa, fr = order_track(x, fs, pulses, pulses_per_rev=pulses_per_rev)
        note = (f"speed varies {100 * variation:.2f} % peak to peak ({extra['min_rpm']:.0f}-"
                f"{extra['max_rpm']:.0f} r/min): order-tracked to a constant {60 * fr:.1f} r/min before "
                "the envelope analysis")
        return xa, _fixed_speed(fr, "tacho", "order-tracked", note, **extra)
    note = f"{pulses.size} tacho pulses, speed steady within {100 * variation:.2f} %"
    return x, _fixed_speed(fr, "tacho", "measured", note, **extra)


def _speed(x, fs, geom, *, rpm, rpm_source, shaft_hz, tacho, pulses_per_rev, tolerance, n_harmonics,
           fallback=True, units="m s-2"):
    """(signal to analyse, speed dict, what was computed for :func:`run_routes` to reuse: the envelope
    spectra ``{key: (f, spectrum, fmax)}``, key "cpw" or ("x", band), "prewhitened": the record's
    :class:`Prewhitened` (its DFT "rfft", its whitened DFT "whitened"), "floors": a SpectrumFloors
    of the record's DFT, and "kurtogram": the record's :class:`KurtogramTree` once a kurtogram was
    asked for; empty when the speed was given or came from a tacho)."""
    if shaft_hz is not None:
        fr = float(shaft_hz)
        if not (math.isfinite(fr) and fr > 0):
            raise AnalysisError(f"analyze: shaft_hz={shaft_hz!r} must be a positive frequency in Hz")
        return x, _fixed_speed(fr, "given", "exact", "shaft frequency given"), {}
    if tacho is not None:
        xa, sp = _tacho_speed(x, fs, tacho, pulses_per_rev)
        return xa, sp, {}
    if rpm is not None and not (math.isfinite(rpm) and rpm > 0):
        raise AnalysisError(f"analyze: rpm={rpm!r} must be a positive speed in r/min")
    check_choice(rpm_source, ("given", "file"), "analyze: rpm_source", AnalysisError)
    pw = Prewhitened(x)  # the record's DFT and its whitened one, for every spectrum below
    X, W = pw.X, pw.W
    cache, ses = {}, {"prewhitened": pw, "rfft": X, "whitened": W, "floors": SpectrumFloors(X, amp=pw.mag)}

    def spectra(f0):
        """Pre-whitened SES (once, reaching the fastest blind candidate's decoys) and the SES of
        the kurtogram band the diagnosis would demodulate at f0 (cached by band width)."""
        ff = geom.fault_frequencies(f0)
        if "cpw" not in cache:
            fmax = min(0.49 * fs, spectrum_top(geom.fault_frequencies(BLIND_RANGE_HZ[1]), BLIND_RANGE_HZ[1],
                                               tolerance=tolerance, n_harmonics=n_harmonics))
            # (the pre-whitened signal itself only when its DFT cannot serve)
            ses["cpw"] = (*record_ses(lambda: pw.signal, fs, window="hann", fmax=fmax, spectrum=W, n=x.size), fmax)
            cache["cpw"] = CyclicSpectrum(*ses["cpw"][:2])
        line_top = n_harmonics * max(ff["bpfi"], 2 * ff["bsf"], ff["bpfo"]) * (1 + tolerance) + f0
        nb = int(2 ** np.floor(np.log2(max(1.0, fs / 2 / line_top))))
        if nb not in cache:
            try:
                if "kurtogram" not in ses:  # one DFT and one pass per level for every band width asked
                    ses["kurtogram"] = KurtogramTree(x, fs)
                kg = ses["kurtogram"].kurtogram(min_bandwidth=fs / 2 / nb)
            except AnalysisError:
                cache[nb] = None
            else:
                cache[nb] = _band_spectrum(x, fs, kg, geom, tolerance, n_harmonics, ses)
        return [cache["cpw"], cache[nb]]

    sp = resolve_speed(x, fs, geom, rpm=rpm, rpm_source=rpm_source, cs=spectra, tolerance=tolerance,
                       min_family_rms=floor_in_units(units), spectrum=X,
                       floors=ses["floors"])
    if sp["shaft_hz"] is None and fallback:
        # nothing to go by: the strongest harmonic family, for the fault-frequency table only
        sp["shaft_hz"] = float(shaft_frequency(x, fs, window="boxcar")[0])
        sp["note"] += f"; fault frequencies shown at the strongest line family, {sp['shaft_hz']:.3f} Hz"
    return x, sp, ses


def _band_spectrum(x, fs, kg, geom, tolerance, n_harmonics, ses):
    """The kurtogram band's SES as the speed search reads it: a band below ``SK_MIN`` holds no impact
    comb, and the search reads only its kurtosis then, so its SES is not computed (the routes compute
    it if they need it)."""
    if float(kg.kurtosis_max) < SK_MIN:
        return SimpleNamespace(band=kg.band, kurtosis=float(kg.kurtosis_max))
    top = min(0.49 * fs, spectrum_top(geom.fault_frequencies(BLIND_RANGE_HZ[1]), BLIND_RANGE_HZ[1],
                                      tolerance=tolerance, n_harmonics=n_harmonics))
    ses[("x", kg.band)] = (*record_ses(x, fs, window="hann", band=kg.band, fmax=top, spectrum=ses["rfft"]), top)
    cs = CyclicSpectrum(*ses[("x", kg.band)][:2])
    cs.band, cs.kurtosis = kg.band, float(kg.kurtosis_max)
    return cs


def _period(routes, decided, key, x, pw, fs, band):
    """Excitation period of the diagnosed family in the deciding route's signal (``pw``: the
    :class:`Prewhitened` of x)."""
    ev = routes[decided]["families"][key]
    f1 = ev["measured_hz"]
    xx, bb = (x, band) if decided == "kurtogram_ses" else (pw.signal, None)
    try:
        period, _ = excitation_period(xx, fs, frequency_range=(0.99 * f1, 1.01 * f1), band=bb)
    except AnalysisError as exc:  # too few clear harmonics for the refined estimate
        period = 1.0 / f1
        warnings.warn(f"excitation period from the {key.upper()} line alone (1/{f1:.4f} Hz), not the "
                      f"harmonic fit: {exc}", stacklevel=3)
    return float(period)


def _evidence(res, verdict, speed, fs, n, tolerance, n_harmonics, decided):
    routes = res["routes"]
    lead, second, margin = runner_up(routes[decided])
    ff = res["fault_hz"]
    fams = routes[decided]["families"]
    ev = {"candidates": verdict["candidates"], "secondary": verdict["secondary"], "runner_up": LABELS[second],
          "margin_score": margin, "leader_lines": line_stats(fams[lead]), "runner_up_lines": line_stats(fams[second]),
          "decided_by": verdict["decided_by"], "reason": verdict["reason"],
          "band": {"low_hz": None if res["band"] is None else float(res["band"][0]),
                   "high_hz": None if res["band"] is None else float(res["band"][1]),
                   "spectral_kurtosis": float(res["spectral_kurtosis"]), "impulsive": bool(res["impulsive"])},
          "routes": {name: route_summary(r) for name, r in routes.items()},
          "flags": [c["text"] for c in coincidences(ff, speed["shaft_hz"], fs / n, tolerance=tolerance,
                                                    n_harmonics=n_harmonics)] + res["notes"]}
    return ev


def _run(x, fs, *, bearing, rpm=None, shaft_hz=None, tolerance=0.02, n_harmonics=5, prewhiten=False,
         rpm_source="given", tacho=None, pulses_per_rev=1, units="m s-2"):
    fs = check_fs(fs, func="analyze")
    x = check_signal(x, func="analyze", min_samples=1024)
    if x.ndim != 1:
        raise AnalysisError(f"analyze: x must be one channel (1-D), got shape {x.shape}")
    geom = _bearing(bearing)
    m = metrics(x)
    xa, speed, ses = _speed(x, fs, geom, rpm=rpm, rpm_source=rpm_source, shaft_hz=shaft_hz, tacho=tacho,
                           pulses_per_rev=pulses_per_rev, tolerance=tolerance, n_harmonics=n_harmonics,
                           units=units)
    fr = float(speed["shaft_hz"])
    if speed["status"] == "unresolved":
        out = _unresolved(speed, geom, fs, xa.size, m, tolerance, n_harmonics)
        rms = band_rms(xa, fs, None, spectrum=ses.get("rfft") if xa is x else None)
        return _below_floor_unresolved(out, rms, floor_in_units(units, fs / 2), units)
    res = run_routes(xa, fs, geom, fr, tolerance=tolerance, n_harmonics=n_harmonics, prewhiten=prewhiten,
                     ses=ses if xa is x else None)
    routes = res["routes"]
    verdict, humps = apply_humps(combine(routes, speed), routes, res["fault_hz"], shaft_hz=fr,
                                 factors=geom.frequency_factors(), speed_status=speed["status"], tolerance=tolerance)
    width = fs / 2 if res["band"] is None else res["band"][1] - res["band"][0]
    floor = floor_in_units(units, width)
    rms = band_rms(xa, fs, res["band"], spectrum=res["rfft"] if xa is x else None)
    verdict = _floor_verdict(verdict, rms, floor, units)
    decided = deciding_route(routes)
    key = {v: k for k, v in LABELS.items()}.get(verdict["diagnosis"]) if verdict["verdict"] == "diagnosed" else None
    period = None
    if key is not None:
        by = verdict["decided_by"]
        if verdict.get("hump"):  # a smeared family has no line to refine: the kinematic rate
            period = 1.0 / (2.0 * res["fault_hz"]["bsf"])
        elif by == ["ees"]:
            period = 1.0 / routes["ees"]["families"][key]["measured_hz"]
        else:
            period = _period(routes, by[0], key, xa, res["prewhitened"], fs, res["band"])
    result = _result(fs, fr, verdict, period, m, speed)
    fams = routes[decided]["families"]
    for k in ("bpfo", "bpfi", "bsf", "ftf"):
        scale = 0.5 if k == "bsf" else 1.0
        ln = fams[k]
        result["fault_frequencies"][k] = {
            "expected_hz": float(res["fault_hz"][k]),
            "measured_hz": None if ln["measured_hz"] is None else float(ln["measured_hz"] * scale),
            "snr_db": float(ln["snr_db"]), "harmonics": int(ln["harmonics"]),
            "sidebands": int(ln["sidebands"]),
            "detected": bool(ln["detected"] and ln.get("explained_by") is None)}
    result["evidence"] = _evidence(res, verdict, speed, fs, xa.size, tolerance, n_harmonics, decided)
    result["evidence"]["reported_route"] = decided
    result["evidence"]["band"].update(rms=verdict["band_rms"], floor_rms=floor)
    result["evidence"]["ball_humps"] = humps
    extras = {"f": routes[decided]["f"], "ses": routes[decided]["spectrum"], "band": res["band"],
              "lines": fams, "bearing": geom, "routes": routes, "route": decided}
    return result, extras


def _floor_verdict(verdict, rms, floor, units):
    """No fault evidence when the demodulation band carries less than the 1 mg floor (:mod:`._floor`)."""
    verdict = dict(verdict, band_rms=rms)
    if floor is None or rms >= floor or verdict["verdict"] == "no fault evidence":
        return verdict
    said = verdict["diagnosis"] if verdict["verdict"] == "diagnosed" else "uncertain"
    return dict(verdict, diagnosis="none", verdict="no fault evidence", decided_by=[],
                reason=f"the demodulation band carries {rms:.3g} {units} rms, {rms / floor:.2g} times the "
                       f"measurability floor of an accelerometer chain ({floor:.3g} {units} in this band: 1 mg "
                       f"over 10 kHz): the routes' reading ({said}: {verdict['reason']}) is not evidence of a "
                       "fault")


def _below_floor_unresolved(out, rms, floor, units):
    """An unresolved speed on a signal below the floor: nothing measurable, no fault evidence."""
    result, extras = out
    if floor is not None and rms < floor:
        ev = result["evidence"]
        result.update(diagnosis="none", verdict="no fault evidence")
        ev["reason"] = (f"the signal carries {rms:.3g} {units} rms, {rms / floor:.2g} times the measurability "
                        f"floor of an accelerometer chain ({floor:.3g} {units} over 0-fs/2: 1 mg over 10 kHz); the "
                        f"speed is unresolved too ({ev['reason']})")
        ev["candidates"] = []
    return result, extras


def _result(fs, fr, verdict, period, m, speed):
    result = {
        "channel": "",
        "sampling_rate_hz": fs,
        "shaft_hz": fr,
        "diagnosis": verdict["diagnosis"],
        "fault_frequencies": {},
        "excitation_period_s": period,
        "metrics": {k: float(m[k]) for k in METRIC_NAMES},
        "units": "",
        "speed_source": speed["source"],
        "speed": {k: v for k, v in speed.items() if k != "source"},
        "verdict": verdict["verdict"],
    }
    result["speed"]["rpm"] = 60.0 * fr
    return result


def _unresolved(speed, geom, fs, n, m, tolerance, n_harmonics):
    """Result when the blind speed is unresolved: no family search (its frequencies are unknown)."""
    fr = float(speed["shaft_hz"])
    comb = speed["candidates"][0]["shaft_hz"] if speed["candidates"] else None
    readings = interpretations(comb, geom, BLIND_RANGE_HZ) if comb else []
    verdict = {"diagnosis": "uncertain", "verdict": "uncertain",
               "candidates": list(dict.fromkeys(r["diagnosis"] for r in readings)),
               "decided_by": [], "secondary": [], "reason": "shaft speed unresolved: " + speed["note"]}
    result = _result(fs, fr, verdict, None, m, speed)
    ff = geom.fault_frequencies(fr)
    for k in ("bpfo", "bpfi", "bsf", "ftf"):
        result["fault_frequencies"][k] = {"expected_hz": float(ff[k]), "measured_hz": None, "snr_db": 0.0,
                                          "harmonics": 0, "sidebands": 0, "detected": False}
    result["evidence"] = {"candidates": verdict["candidates"], "secondary": [], "runner_up": None, "margin_score": None,
                          "leader_lines": None, "runner_up_lines": None,
                          "decided_by": [], "reason": verdict["reason"], "band": None, "routes": {},
                          "flags": [], "interpretations": readings, "reported_route": None}
    extras = {"f": None, "ses": None, "band": None, "lines": None, "bearing": geom, "routes": {}, "route": None}
    return result, extras


@fill_doc
def shaft_speed(x, fs, *, bearing, rpm=None, rpm_source="given", tolerance=0.02, n_harmonics=5,
                units="m s-2"):
    """Shaft speed of a vibration signal, checked against the bearing's kinematics.

    The speed step of :func:`analyze` on its own: a given or stored ``rpm`` is a
    prior refined by the signal's 1x line family; without one the signal alone
    names a speed only when no fault comb of the bearing can explain that family.

    Parameters
    ----------
    x : array_like, 1-D
    %(fs)s
    bearing : str or BearingGeometry
    rpm : float, optional
        Prior speed, r/min (None: blind).
    rpm_source : {"given", "file"}
        Where ``rpm`` comes from.
    tolerance, n_harmonics, units
        As in :func:`analyze` (``units`` sets the 1 mg floor a plain 1x family must reach).

    Returns
    -------
    dict
        ``shaft_hz`` (the prior, the refined or the estimated value; None when a
        blind search finds no 1x family at all), ``source`` ("given", "file",
        "estimated", "unresolved"), ``status`` ("confirmed", "unconfirmed",
        "contradicted", "resolved", "unresolved"), ``prior_hz``, ``harmonics`` and
        ``snr_db`` of the 1x family, ``deviation_pct``, ``candidates``, ``note``.

    Examples
    --------
    Outer-race impacts of a 6308 at 30 Hz and no shaft line at all: the impact comb
    is not taken for the shaft.

    >>> import numpy as np
    >>> from bearing_lab.analysis import shaft_speed
    >>> fs = 20000.0; t = np.arange(100000) / fs; bpfo = 3.0719 * 30.0
    >>> x = np.exp(-1500 * (t % (1 / bpfo))) * np.sin(2 * np.pi * 3000 * t)
    >>> x = x + np.random.default_rng(0).normal(0, 0.1, t.size)
    >>> shaft_speed(x, fs, bearing="6308")["source"]
    'unresolved'
    >>> round(shaft_speed(x, fs, bearing="6308", rpm=1800)["shaft_hz"], 3)
    30.0
    """
    fs = check_fs(fs, func="shaft_speed")
    x = check_signal(x, func="shaft_speed", min_samples=1024)
    if x.ndim != 1:
        raise AnalysisError(f"shaft_speed: x must be one channel (1-D), got shape {x.shape}")
    _, sp, _ = _speed(x, fs, _bearing(bearing), rpm=rpm, rpm_source=rpm_source, shaft_hz=None, tacho=None,
                      pulses_per_rev=1, tolerance=tolerance, n_harmonics=n_harmonics, fallback=False, units=units)
    return sp


@fill_doc
def analyze(x, fs, *, bearing, rpm=None, shaft_hz=None, channel="", units="m s-2", tolerance=0.02,
            n_harmonics=5, prewhiten=False, rpm_source="given", tacho=None, pulses_per_rev=1):
    """Analyse one vibration channel: metrics, shaft speed, fault families and a graded diagnosis.

    Parameters
    ----------
    x : array_like, 1-D
        Acceleration (or any vibration signal), in ``units``.
    %(fs)s
    bearing : str or BearingGeometry
        Catalog name (``"6205"``, ``"ZA-2115"``, ``"MFPT"``, ...) or geometry.
    rpm : float, optional
        Shaft speed, r/min, used as a prior: refined within +-5 % when the
        signal's 1x family supports it, used as it is otherwise.  None: the
        speed comes from the signal alone (blind).
    shaft_hz : float, optional
        Known shaft frequency, Hz; used exactly.
    channel : str
        Channel name, copied into the result.
    units : str
        Unit of ``x`` (default "m s-2"), copied into the result.
    tolerance : float
        Slip tolerance of the fault search (default 0.02).
    n_harmonics : int
        Harmonics examined per fault (default 5).
    prewhiten : bool
        Run the kurtogram route on the cepstrum-pre-whitened signal (default False).
    rpm_source : {"given", "file"}
        Where ``rpm`` comes from, reported as ``speed_source`` ("file": stored in
        the recording).
    tacho : array_like, optional
        Tachometer signal sampled with ``x`` (same length); its pulses give the
        speed, and the signal is order-tracked when the speed varies.
    pulses_per_rev : int
        Tacho pulses per shaft revolution (default 1).

    Returns
    -------
    dict
        ``channel``, ``sampling_rate_hz``, ``shaft_hz``, ``diagnosis``
        ("outer_race", "inner_race", "ball", "none" or "uncertain"),
        ``fault_frequencies`` (bpfo, bpfi, bsf, ftf: ``expected_hz``,
        ``measured_hz`` or None, ``snr_db``, ``harmonics``, ``sidebands``,
        ``detected``), ``excitation_period_s`` (None without a diagnosis),
        ``metrics`` (eight floats, kurtosis Pearson), ``units``,
        ``speed_source`` ("given", "file", "tacho", "estimated", "unresolved"),
        ``speed`` (how the signal supports it), ``verdict`` ("diagnosed",
        "uncertain", "no fault evidence") and ``evidence`` (candidates,
        runner-up and margin, demodulation band and its spectral kurtosis, each
        route's families, flags).  ``docs/analysis.md`` describes every field.

    See Also
    --------
    plot_analysis : the same analysis as a figure.
    shaft_speed : the speed step alone.
    bearing_lab.io.open_recording, bearing_lab.sim.simulate : signals to analyse.

    Notes
    -----
    Without a speed, a noise-free simulation (no shaft lines) or any record
    whose only line family is the fault's own comb has an unresolved speed: the
    diagnosis is then "uncertain", never a fault family read as the shaft.

    References
    ----------
    .. [1] Randall & Antoni, "Rolling element bearing diagnostics - a tutorial",
       MSSP 25 (2011) 485-520.
    .. [2] Smith & Randall, "Rolling element bearing diagnostics using the Case Western
       Reserve University data: a benchmark study", MSSP 64-65 (2015) 100-131.

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
    >>> r["diagnosis"], r["verdict"], round(r["fault_frequencies"]["bpfo"]["measured_hz"], 1)
    ('outer_race', 'diagnosed', 107.4)
    """
    result, _ = _run(x, fs, bearing=bearing, rpm=rpm, shaft_hz=shaft_hz, tolerance=tolerance,
                     n_harmonics=n_harmonics, prewhiten=prewhiten, rpm_source=rpm_source, tacho=tacho,
                     pulses_per_rev=pulses_per_rev, units=units)
    result["channel"] = str(channel)
    result["units"] = str(units)
    return result


def plot_analysis(x, fs, *, bearing, rpm=None, shaft_hz=None, channel="", units="m s-2", path=None,
                  fig=None, **kwargs):
    """Figure of one analysis: waveform, amplitude spectrum, envelope spectrum with fault markers.

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
        fig = new_figure(figsize=(10, 9), layout="constrained")
    result, ex = _run(x, fs, bearing=bearing, rpm=rpm, shaft_hz=shaft_hz, units=units, **kwargs)
    result["channel"], result["units"] = str(channel), str(units)
    x = np.asarray(x, float)
    ax1, ax2, ax3 = fig.subplots(3, 1)
    t = np.arange(x.size) / fs
    ax1.plot(t, x, lw=0.4, color="k")
    ax1.set(xlabel="time (s)", ylabel=f"{channel or 'signal'} ({units})",
            title=f"{channel or 'signal'}: {result['verdict']} ({result['diagnosis']}), "
                  f"f_r = {result['shaft_hz']:.3f} Hz ({result['speed_source']}), "
                  f"kurtosis {result['metrics']['kurtosis']:.2f}")
    f, a = amplitude_spectrum(x, fs, window="hann")
    ax2.semilogy(f, np.maximum(a, 1e-300), lw=0.4, color="k")
    if ex["band"] is not None:
        sk = result["evidence"]["band"]["spectral_kurtosis"]
        ax2.axvspan(*ex["band"], color="tab:orange", alpha=0.2,
                    label=f"demodulation band (kurtogram, SK {sk:.2f})")
        ax2.legend(loc="upper right")
    ax2.set(xlabel="frequency (Hz)", ylabel=f"amplitude ({units})", title="amplitude spectrum (Hann)",
            xlim=(0, fs / 2))
    _plot_envelope(ax3, ex, result, units)
    if path is not None:
        savefig(fig, path, dpi=110)  # atomic: an existing figure survives a failed write
    return fig, result


def _plot_envelope(ax3, ex, result, units):
    """Envelope spectrum of the reported route with expected and found fault lines."""
    route = ex["route"]
    if route is None:
        ax3.text(0.5, 0.5, "shaft speed unresolved: fault frequencies unknown, no family search\n"
                 + result["evidence"]["reason"][:160], ha="center", va="center", wrap=True,
                 transform=ax3.transAxes, fontsize=8)
        ax3.set(title="envelope analysis not run", xticks=[], yticks=[])
        return
    top = 1.05 * max(result["fault_frequencies"][k]["expected_hz"] * (2 if k == "bsf" else 1)
                     for k in ("bpfo", "bpfi", "bsf")) * 5
    keep = ex["f"] <= top
    f, s = ex["f"][keep], ex["ses"][keep]
    ax3.plot(f, s, lw=0.6, color="k")
    name = {"kurtogram_ses": "squared envelope spectrum, kurtogram band",
            "cpw_ses": "squared envelope spectrum, cepstrum pre-whitened"}[route]
    ax3.set(xlabel="cyclic frequency (Hz)", ylabel=f"SES ({units})^2" if route == "kurtogram_ses" else "SES (1)",
            title=name, xlim=(0, f[-1]))
    colors = {"bpfo": "tab:red", "bpfi": "tab:blue", "bsf": "tab:green", "ftf": "tab:purple"}
    ymax = float(np.max(s[1:])) if s.size > 1 else 1.0
    for k, c in colors.items():
        ffk = result["fault_frequencies"][k]
        fe = ffk["expected_hz"] * (2 if k == "bsf" else 1)
        label = "2·BSF" if k == "bsf" else k.upper()
        for h in range(1, 6):
            if h * fe < f[-1]:
                ax3.axvline(h * fe, color=c, ls="--", lw=0.8, alpha=0.7,
                            label=f"{label} {fe:.1f} Hz (expected)" if h == 1 else None)
        if ffk["measured_hz"] is not None:
            fm = ffk["measured_hz"] * (2 if k == "bsf" else 1)
            i = int(np.argmin(np.abs(f - fm)))
            ax3.plot([fm], [s[i] * 1.04 + 0.02 * ymax], marker="v", ls="none", color=c, ms=7,
                     label=f"{label} found {fm:.2f} Hz, {ffk['harmonics']} harmonics, "
                           f"SNR {ffk['snr_db']:.0f} dB{' (detected)' if ffk['detected'] else ''}")
    ax3.set_ylim(0, 1.15 * ymax)
    ax3.legend(loc="upper right", fontsize=8)
