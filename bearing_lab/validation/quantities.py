"""The table of validation quantities: what is compared, on which signal and span, how close by default.

Why a table: which quantity is measured on the full record and which on the compared
segment, on the bare model or after the structural path, is a property of the quantity, not
of the code that happens to compute it.  Here each quantity says it, once, and the runner only
looks it up.  Adding a quantity is one entry here (and one test).

Signals (simulation side):

- ``model``: the simulated outer-ring acceleration as the model gives it (no sensor, no
  housing, no background);
- ``path``: the model through the structural path, identified once and held fixed;
- ``path+background``: the same plus the measured background of the rig (tones and
  broadband noise), when the case enables the background model; otherwise equal to
  ``path``.

Spans (experiment side): ``record`` (the whole recording: finest spectral lines) or
``segment`` (the stretch of the recording compared sample for sample with the
simulation: the same duration at the same rate).  Frequencies of the simulation are
measured on its whole run.

Public API
----------
Quantity                      -- one entry (key, label, units, measured, signal, span, tolerance, path_fit)
QUANTITIES                    -- key -> Quantity
SIGNALS, SPANS                -- the allowed signals and spans
default_tolerance(key)        -- the entry's default Tolerance (with its reason)
value_of(quantity, measured)  -- the quantity's number from a measure() dict (NaN if absent)
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from .rows import Tolerance

__all__ = ["Quantity", "QUANTITIES", "SIGNALS", "SPANS", "default_tolerance", "value_of"]

SIGNALS = ("model", "path", "path+background")
SPANS = ("record", "segment")

_LINE = ("the same line search on both signals (squared envelope spectrum, interpolated); kinematic "
         "fault frequencies hold to 1-2 % under rolling-element slip (Randall & Antoni, MSSP 25, 2011)")
_AMP = ("a factor 2: the rig's load, mount stiffness and housing are known to tens of percent, and the "
        "impact amplitude grows with them (docs/validation.md, 'Tolerances')")
_SHAPE = ("a factor 2 on a signal-shape statistic (independent of the gain): impulsiveness against the "
          "background (docs/validation.md, 'Tolerances')")


@dataclass(frozen=True)
class Quantity:
    """One compared quantity.

    ``measured`` is a key of :func:`bearing_lab.analysis.measurement.measure`'s result, or a
    function ``(x, fs, measured_dict) -> float``.  ``path_fit`` marks quantities the
    structural-path fit uses (not independent evidence on the recording the path was fitted on).
    ``ratio`` compares this recording against the case's ``[ratio]`` companion.

    See Also
    --------
    QUANTITIES : every quantity by its key.
    make_row, Tolerance

    Examples
    --------
    >>> from bearing_lab.validation import QUANTITIES
    >>> q = QUANTITIES["bpfo"]
    >>> q.units, q.tolerance.text()
    ('Hz', '±1 %')
    """

    key: str
    label: str
    units: str
    measured: str | Callable
    signal: str
    span: str
    tolerance: Tolerance
    path_fit: bool = False
    ratio: bool = False

    def __post_init__(self):
        if self.signal not in SIGNALS or self.span not in SPANS:
            raise ValueError(f"quantity {self.key}: signal {self.signal!r} / span {self.span!r} unknown")

    @property
    def where(self) -> str:
        return f"{self.signal}; recording: {'whole record' if self.span == 'record' else 'compared segment'}"


def _frequency(key, label, units="Hz", pct=1.0, reason=_LINE):
    return Quantity(key, label, units, key, "model", "record", Tolerance("pct", pct, reason))


_AMPLITUDES = {
    "rms": ("RMS", "m s-2", _AMP, True),
    "peak": ("peak |a| (max over the segment)", "m s-2", _AMP, True),
    "crest_factor": ("crest factor", "1", _SHAPE, False),
    "kurtosis": ("kurtosis (Pearson, Gaussian = 3)", "1", _SHAPE, False),
    "impulse_strength": ("impulse strength (median impact peak)", "m s-2", _AMP, True),
    "impulse_duration": ("impulse duration (median, 10 % level)", "s",
                         "a factor 2: the duration is set by the housing's ringing decay, a property of the "
                         "structural path (docs/validation.md, 'Tolerances')", True),
}
_SUFFIX = {"path+background": ("", "after the structural path, with the rig's background"),
           "path": ("_path", "after the structural path, no background"),
           "model": ("_model", "bearing model alone")}


def _build() -> dict:
    table = {q.key: q for q in (
        _frequency("shaft_hz", "f_i (shaft line)", reason=(
            "the shaft line of the amplitude spectrum, the same search on both; the model's shaft-synchronous "
            "source is its residual unbalance (ISO 21940-11)")),
        _frequency("bpfo", "BPFO"),
        _frequency("bpfi", "BPFI"),
        _frequency("excitation_period", "excitation period", units="s", reason=(
            "impact period from the squared-envelope line family, interpolated; exact for periodic impacts, "
            "defined to ~0.03 % under 1 % random slip (Randall & Antoni, MSSP 25, 2011)")),
    )}
    for m, (label, units, reason, fit) in _AMPLITUDES.items():
        for signal, (suffix, what) in _SUFFIX.items():
            key = m + suffix
            table[key] = Quantity(key, f"{label} ({what})", units, m, signal, "segment",
                                  Tolerance("factor", 2.0, reason), path_fit=fit and signal != "model")
    table["impulse_strength_ratio"] = Quantity(
        "impulse_strength_ratio", "impulse strength ratio, this recording / the [ratio] companion", "1",
        "impulse_strength", "path", "segment",
        Tolerance("factor", 2.0, "a ratio of two recordings of the same rig through the same fixed path: the "
                  "path's gain cancels, so the ratio tests where and how strongly the model's impacts occur"),
        ratio=True)
    return table


#: key -> Quantity
QUANTITIES: dict[str, Quantity] = _build()


def default_tolerance(key: str) -> Tolerance:
    return QUANTITIES[key].tolerance


def value_of(q: Quantity, measured: dict, x=None, fs=None) -> float:
    """The quantity's number from a :func:`~bearing_lab.analysis.measurement.measure` dict."""
    if callable(q.measured):
        return float(q.measured(x, fs, measured))
    v = measured.get(q.measured)
    return float(v) if v is not None else float("nan")
