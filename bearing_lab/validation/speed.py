"""The shaft speed a case simulates at, and where it came from.

Why the care: every fault frequency scales with the speed, and a simulation at a wrong
speed compares nothing.  A case says ``speed = <r/min>`` (given), ``"file"`` (stored in
the recording, e.g. by ``bearing-lab import --rpm``) or ``"estimate"`` (from the
signal).  The estimate is the analysis layer's public estimator,
:func:`bearing_lab.analysis.shaft_speed`, with its guards: a line family that could
be a fault comb of the bearing (an outer-race comb at BPFO looks like shaft harmonics
at BPFO) is never taken for the shaft.  An estimate the signal cannot settle is
*unresolved*: the case stops with the candidates, never simulating at a guessed speed.

Public API
----------
Speed(rpm, source, resolved=True, candidates=())  -- the resolved speed and its source
estimate_speed(x, fs, *, bearing, prior_rpm=None) -> Speed
resolve_speed(spec, dataset, x, *, bearing, case_name, where="speed") -> Speed  (raises when unresolved)
"""
from __future__ import annotations

from dataclasses import dataclass

from .. import analysis
from ..errors import AnalysisError, ValidationCaseError

__all__ = ["Speed", "estimate_speed", "resolve_speed"]


@dataclass(frozen=True)
class Speed:
    """A shaft speed (r/min) with its source; ``resolved`` False means "do not simulate"."""

    rpm: float
    source: str
    resolved: bool = True
    candidates: tuple = ()


def _candidates(sp, first=None):
    out = [] if first is None else [float(first)]
    for c in sp.get("candidates", ()):
        if c.get("shaft_hz") and all(abs(60.0 * c["shaft_hz"] / o - 1) > 1e-3 for o in out):
            out.append(60.0 * float(c["shaft_hz"]))
    return tuple(out)


def estimate_speed(x, fs, *, bearing, prior_rpm=None) -> Speed:
    """Estimate the shaft speed with :func:`bearing_lab.analysis.shaft_speed` (one estimator).

    Without a prior, the estimate is resolved only when the analysis layer resolves it
    (a 1x family confirmed by a fault family of ``bearing`` in the pre-whitened envelope
    spectrum, or a plain 1x family no fault reading explains).  With a stored prior, the
    signal's 1x family within 5 % refines it; a prior the signal does not confirm is used
    as it is (and said so); a prior the signal contradicts stops the case.
    """
    try:
        sp = analysis.shaft_speed(x, fs, bearing=bearing, rpm=prior_rpm, rpm_source="file")
    except AnalysisError as exc:
        return Speed(float("nan"), f"estimate failed: {exc}", False)
    fr = sp["shaft_hz"]
    rpm = float("nan") if fr is None else 60.0 * float(fr)
    if prior_rpm is None:
        if sp["source"] == "estimated":
            return Speed(rpm, f"estimated from the recording ({sp['harmonics']} shaft harmonics at {fr:.3f} Hz; "
                              f"{sp['note']})")
        return Speed(rpm, f"unresolved: {sp['note']}", False, _candidates(sp, None if fr is None else rpm))
    if sp["status"] == "confirmed":
        return Speed(rpm, f"estimated from the recording within 5 % of the stored {prior_rpm:g} r/min "
                          f"({sp['harmonics']} shaft harmonics)")
    if sp["status"] == "contradicted":
        return Speed(float(prior_rpm), f"unresolved: {sp['note']}", False, _candidates(sp, prior_rpm))
    return Speed(float(prior_rpm), f"stored in the recording ({prior_rpm:g} r/min), not confirmed by the "
                                   f"signal: {sp['note']}")


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
