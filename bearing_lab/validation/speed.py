"""The shaft speed a case simulates at, and where it came from.

Why the care: every fault frequency scales with the speed, and a simulation at a wrong
speed compares nothing.  A case says ``speed = <r/min>`` (given), ``"file"`` (stored in
the recording, e.g. by ``bearing-lab import --rpm``) or ``"estimate"`` (from the
signal).  The estimate goes through :func:`estimate_speed`, the one adapter to the
analysis layer's tacholess estimator, so a better estimator plugs in here.  An estimate
that cannot tell the shaft family from a fault family (an outer-race comb at BPFO looks
like shaft harmonics at BPFO) is *unresolved*: the case stops with the candidates,
never simulating at a guessed speed.

Public API
----------
Speed(rpm, source, resolved=True, candidates=())  -- the resolved speed and its source
estimate_speed(x, fs, *, bearing, prior_rpm=None) -> Speed
resolve_speed(spec, dataset, x, *, bearing, case_name, where="speed") -> Speed  (raises when unresolved)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import AnalysisError, ValidationCaseError

__all__ = ["Speed", "estimate_speed", "resolve_speed"]

#: a harmonic family this long in a signal this impulsive (Pearson kurtosis; Gaussian = 3) looks like an
#: impact train, not like the few shaft harmonics unbalance and misalignment give
_COMB_LINES = 10
_IMPULSIVE = 4.0


@dataclass(frozen=True)
class Speed:
    """A shaft speed (r/min) with its source; ``resolved`` False means "do not simulate"."""

    rpm: float
    source: str
    resolved: bool = True
    candidates: tuple = ()


def _has_line(x, fs, f0) -> bool:
    """Whether a line stands at ``f0`` (+-1 %) in the amplitude spectrum (the fault search's threshold)."""
    from ..analysis.measurement import shaft_line
    try:
        return shaft_line(x, fs, f0, tolerance=0.01)[0] is not None
    except AnalysisError:
        return False


def estimate_speed(x, fs, *, bearing, prior_rpm=None) -> Speed:
    """Estimate the shaft speed from the signal (the analysis layer's estimator) and check it.

    A result of the estimator that returns a ``speed_source`` (and may say ``unresolved``)
    is passed through.  Today's estimator returns a frequency only: it is then checked
    against the fault families of ``bearing``: when the found family could equally be
    a BPFO or BPFI comb of a slower shaft (whose own line is present, or the family is
    long and the signal impulsive, as an impact train is), the estimate is unresolved
    and the candidates are returned.
    """
    from ..analysis import shaft_frequency
    from ..bearings import get_bearing
    geom = get_bearing(bearing) if isinstance(bearing, str) else bearing
    try:
        res = shaft_frequency(x, fs, window="hann", rpm=prior_rpm)
    except AnalysisError as exc:
        return Speed(float("nan"), f"estimate failed: {exc}", False)
    if isinstance(res, dict):  # an estimator that reports its own source and resolution
        rpm = 60.0 * float(res.get("shaft_hz", float("nan")))
        ok = res.get("speed_source", "") != "unresolved" and rpm > 0
        return Speed(rpm, f"estimated from the recording ({res.get('speed_source', '')})", ok,
                     tuple(60.0 * float(c) for c in res.get("candidates", ())))
    fr, nlines = float(res[0]), int(res[1])
    source = f"estimated from the recording's shaft line family ({nlines} harmonics at {fr:.3f} Hz)"
    if prior_rpm is not None:
        return Speed(60.0 * fr, source + f", searched within 5 % of {prior_rpm:g} r/min")
    factors = geom.frequency_factors()
    rivals = [(60.0 * fr / factors[k], k) for k in ("bpfo", "bpfi") if fr / factors[k] > 2.0
              and _has_line(x, fs, fr / factors[k])]
    if not rivals and nlines >= _COMB_LINES and _kurtosis(x) > _IMPULSIVE:
        # a long harmonic family in an impulsive signal is what an impact train looks like: without a
        # shaft line of its own, nothing says it is the shaft's family and not a fault comb
        rivals = [(60.0 * fr / factors[k], k) for k in ("bpfo", "bpfi") if fr / factors[k] > 2.0]
    if rivals:
        cands = (60.0 * fr,) + tuple(r for r, _ in rivals)
        what = "; ".join(f"{r:.1f} r/min if the lines are its {k.upper()}" for r, k in rivals)
        return Speed(60.0 * fr, f"unresolved: a line family at {fr:.3f} Hz ({60 * fr:.1f} r/min as the shaft), "
                                f"or {what}", False, cands)
    return Speed(60.0 * fr, source)


def _kurtosis(x) -> float:
    x = np.asarray(x, float) - np.mean(x)
    v = np.mean(x * x)
    return float(np.mean(x ** 4) / v ** 2) if v > 0 else 0.0


def resolve_speed(spec, dataset, x, *, bearing, case_name, where="speed") -> Speed:
    """The speed a case simulates at: given, stored in the file, or estimated (never a guess).

    Raises
    ------
    ValidationCaseError
        ``"file"`` without a stored speed, or an unresolved estimate (the message lists the
        candidates and how to give the speed).
    """
    stored = dataset.attrs.get("shaft_speed_rpm")
    stored = float(stored) if stored not in (None, "") else None
    if isinstance(spec, (int, float)):
        note = f" (the file stores {stored:g} r/min)" if stored else ""
        return Speed(float(spec), f"given by the case: {float(spec):g} r/min{note}")
    if spec == "file":
        if stored is None:
            msg = (f"validation case {case_name!r}: {where} = \"file\" but the recording stores no shaft speed; "
                   "give the speed in r/min in the case, or store it with `bearing-lab import --rpm`")
            raise ValidationCaseError(msg)
        src = dataset.attrs.get("shaft_speed_source", "")
        return Speed(stored, f"stored in the recording: {stored:g} r/min" + (f" ({src})" if src else ""))
    sp = estimate_speed(x, float(dataset.attrs["sampling_rate_hz"]), bearing=bearing, prior_rpm=stored)
    if not sp.resolved:
        cands = ", ".join(f"{c:.1f}" for c in sp.candidates) or "none"
        msg = (f"validation case {case_name!r}: {where} = \"estimate\" is {sp.source}; candidates (r/min): {cands}. "
               "Give the speed in r/min in the case (or store it with `bearing-lab import --rpm`)")
        raise ValidationCaseError(msg)
    return sp
