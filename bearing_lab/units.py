"""Unit labels as real files spell them, and sensor sensitivities.

Why this module exists: recordings label their channels ``g``, ``m/s2``,
``m/s²``, ``m/s^2``, the mojibake ``m/sÂ²`` or ``Pa``, and voltage-only sources
need a sensor sensitivity such as ``9.91mV/g`` before they mean anything.  Every
reader turns its channel into SI through this one table, so a spelling is either
known (and converted exactly the same way everywhere) or refused with a message
that says how to tell bearing_lab what it is.  Nothing is guessed silently.

Public API
----------
lookup_unit        -- label -> :class:`Unit` (SI unit, factor, offset, quantity)
normalize_label    -- clean a label (mojibake, superscripts, spaces) before lookup
parse_sensitivity  -- "9.91mV/g" -> :class:`Sensitivity` (V per SI unit)
parse_quantity     -- "5 V" or "500 g" -> (value in SI, Unit)
G                  -- standard gravity, 9.80665 m s-2
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from .errors import RecordingError

G = 9.80665
INCH = 0.0254
LBF = 4.4482216152605
PSI = 6894.757293168361


@dataclass(frozen=True)
class Unit:
    """A unit a channel may be recorded in.

    Attributes
    ----------
    label : canonical spelling of the original unit (e.g. ``"g"``, ``"m/s2"``).
    si : CF-style SI unit of the converted values (e.g. ``"m s-2"``).
    factor, offset : ``value_si = value * factor + offset``.
    quantity : physical quantity (``"acceleration"``, ``"pressure"``, ...).
    """

    label: str
    si: str
    factor: float
    quantity: str
    offset: float = 0.0


def _u(label, si, factor, quantity, offset=0.0):
    return Unit(label, si, float(factor), quantity, float(offset))


# canonical label -> Unit; spellings are mapped onto these by normalize_label + _ALIASES
_TABLE = {u.label: u for u in [
    _u("g", "m s-2", G, "acceleration"),
    _u("mg", "m s-2", G * 1e-3, "acceleration"),
    _u("m/s2", "m s-2", 1.0, "acceleration"),
    _u("mm/s2", "m s-2", 1e-3, "acceleration"),
    _u("in/s2", "m s-2", INCH, "acceleration"),
    _u("m/s", "m s-1", 1.0, "velocity"),
    _u("mm/s", "m s-1", 1e-3, "velocity"),
    _u("um/s", "m s-1", 1e-6, "velocity"),
    _u("in/s", "m s-1", INCH, "velocity"),
    _u("m", "m", 1.0, "displacement"),
    _u("mm", "m", 1e-3, "displacement"),
    _u("um", "m", 1e-6, "displacement"),
    _u("nm", "m", 1e-9, "displacement"),
    _u("in", "m", INCH, "displacement"),
    _u("mil", "m", INCH * 1e-3, "displacement"),
    _u("Pa", "Pa", 1.0, "pressure"),
    _u("kPa", "Pa", 1e3, "pressure"),
    _u("MPa", "Pa", 1e6, "pressure"),
    _u("bar", "Pa", 1e5, "pressure"),
    _u("mbar", "Pa", 1e2, "pressure"),
    _u("psi", "Pa", PSI, "pressure"),
    _u("N", "N", 1.0, "force"),
    _u("kN", "N", 1e3, "force"),
    _u("lbf", "N", LBF, "force"),
    _u("V", "V", 1.0, "voltage"),
    _u("mV", "V", 1e-3, "voltage"),
    _u("uV", "V", 1e-6, "voltage"),
    _u("s", "s", 1.0, "time"),
    _u("ms", "s", 1e-3, "time"),
    _u("rad", "rad", 1.0, "angle"),
    _u("deg", "rad", 3.141592653589793 / 180.0, "angle"),
    _u("rad/s", "rad s-1", 1.0, "angular_velocity"),
    _u("rpm", "rad s-1", 2 * 3.141592653589793 / 60.0, "angular_velocity"),
    _u("K", "K", 1.0, "temperature"),
    _u("degC", "K", 1.0, "temperature", 273.15),
    _u("1", "1", 1.0, "dimensionless"),
]}

# normalised spelling (lower-case, no spaces) -> canonical label
_ALIASES = {
    "g": "g", "gn": "g", "g0": "g", "gs": "g", "grav": "g", "mg": "mg",
    "m/s2": "m/s2", "m/s^2": "m/s2", "m/s**2": "m/s2", "ms-2": "m/s2", "m.s-2": "m/s2",
    "ms^-2": "m/s2", "m/(s2)": "m/s2", "m/s/s": "m/s2", "m/sec2": "m/s2", "m/sec^2": "m/s2",
    "mm/s2": "mm/s2", "mm/s^2": "mm/s2", "mms-2": "mm/s2",
    "in/s2": "in/s2", "in/s^2": "in/s2",
    "m/s": "m/s", "ms-1": "m/s", "mm/s": "mm/s", "mms-1": "mm/s", "um/s": "um/s",
    "in/s": "in/s", "ips": "in/s",
    "m": "m", "mm": "mm", "um": "um", "micron": "um", "nm": "nm", "in": "in", "inch": "in",
    "mil": "mil", "mils": "mil",
    "pa": "Pa", "kpa": "kPa", "bar": "bar", "mbar": "mbar", "psi": "psi",
    "n": "N", "kn": "kN", "lbf": "lbf",
    "v": "V", "volt": "V", "volts": "V", "mv": "mV", "uv": "uV",
    "s": "s", "sec": "s", "msec": "ms",
    "rad": "rad", "deg": "deg", "rad/s": "rad/s", "rpm": "rpm", "1/min": "rpm",
    "degc": "degC", "°c": "degC",
    "1": "1", "-": "1",
}
# case matters for these spellings (mPa vs MPa, ms vs m/s are all easy to confuse)
_CASE_SENSITIVE = {"MPa": "MPa", "mPa": None, "ms": "ms", "Ms": None}


def normalize_label(label) -> str:
    """Return ``label`` cleaned of mojibake, superscripts, brackets and spaces.

    Parameters
    ----------
    label : str or bytes
        A unit label as found in a file, e.g. ``"m/sÂ²"`` or ``"[m/s^2]"``.

    Returns
    -------
    str
        The cleaned spelling (case kept); ``""`` for an empty label.

    Examples
    --------
    >>> normalize_label("m/sÂ²")
    'm/s2'
    >>> normalize_label(" [ m/s^2 ] ")
    'm/s^2'
    """
    if isinstance(label, bytes):
        try:
            label = label.decode("utf-8")
        except UnicodeDecodeError:
            label = label.decode("latin-1")
    s = str(label).strip()
    s = s.replace("Â²", "2").replace("Â³", "3").replace("Âµ", "u").replace("Â°", "°")
    s = s.replace("²", "2").replace("³", "3").replace("µ", "u").replace("μ", "u")
    s = s.replace("⁻", "-").replace("·", ".").replace("\u2212", "-")
    if len(s) >= 2 and s[0] in "[(" and s[-1] in "])":
        s = s[1:-1]
    s = s.strip().replace(" ", "")
    return s


def lookup_unit(label, *, what: str = "unit") -> Unit:
    """Return the :class:`Unit` for a label as real files spell it.

    Parameters
    ----------
    label : str
        The unit label (``g``, ``m/s2``, ``m/s²``, ``m/sÂ²``, ``Pa``, ``mV`` ...).
    what : str
        Names the label's owner in the error message (e.g. ``"channel 'DE' of x.uff"``).

    Returns
    -------
    Unit

    Raises
    ------
    RecordingError
        If the label is empty or not in the table (never guessed).

    Examples
    --------
    >>> u = lookup_unit("g")
    >>> u.si, round(u.factor, 5), u.quantity
    ('m s-2', 9.80665, 'acceleration')
    """
    s = normalize_label(label)
    if s in _CASE_SENSITIVE:
        canon = _CASE_SENSITIVE[s]
        if canon is None:
            msg = (f"{what}: unit {label!r} is ambiguous (did you mean MPa or m/s?); "
                   f"pass units='...' with one of {', '.join(sorted(_TABLE))}")
            raise RecordingError(msg)
        return _TABLE[canon]
    if s in _TABLE:
        return _TABLE[s]
    key = s.lower()
    canon = _ALIASES.get(key)
    if canon is None:
        got = f"{label!r}" if str(label).strip() else "no unit label"
        msg = (f"{what}: unknown unit {got}; pass units='g' (or another of "
               f"{', '.join(sorted(_TABLE))}) to say what it is")
        raise RecordingError(msg)
    return _TABLE[canon]


def known_units() -> list[str]:
    """Return the canonical labels the table knows."""
    return sorted(_TABLE)


@dataclass(frozen=True)
class Sensitivity:
    """A sensor sensitivity, output volts per SI unit of the measured quantity.

    Attributes
    ----------
    volts_per_si : V per SI unit (V per m s-2 for an accelerometer).
    unit : the :class:`Unit` of the measured quantity as written (``g`` in ``9.91mV/g``).
    text : the string it was parsed from.
    """

    volts_per_si: float
    unit: Unit
    text: str

    def to_si(self, volts):
        """Convert volts to the SI quantity: ``a = u / S``."""
        return volts / self.volts_per_si


_NUM = r"[-+]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][-+]?\d+)?"


def parse_sensitivity(text) -> Sensitivity:
    """Parse a sensitivity such as ``"9.91mV/g"``, ``"100 mV/(m/s2)"`` or ``"1.02 V/g"``.

    Parameters
    ----------
    text : str or Sensitivity
        ``<number> <voltage unit>/<quantity unit>``.

    Returns
    -------
    Sensitivity

    Raises
    ------
    RecordingError
        If the text is not of that form, the numerator is not a voltage, or
        the value is not positive.

    Examples
    --------
    >>> s = parse_sensitivity("9.91mV/g")
    >>> round(s.volts_per_si * 9.80665, 6)
    0.00991
    """
    if isinstance(text, Sensitivity):
        return text
    raw = str(text)
    m = re.fullmatch(rf"\s*({_NUM})\s*([^/\s]+)\s*/\s*(.+?)\s*", raw)
    if not m:
        msg = (f"sensitivity {raw!r} is not of the form '<number><voltage unit>/<unit>'; "
               "write e.g. '9.91mV/g' or '100 mV/(m/s2)'")
        raise RecordingError(msg)
    value = float(m.group(1).replace(",", "."))
    num = lookup_unit(m.group(2), what=f"sensitivity {raw!r}")
    if num.quantity != "voltage":
        msg = (f"sensitivity {raw!r}: numerator unit {m.group(2)!r} is not a voltage; "
               "write e.g. '9.91mV/g'")
        raise RecordingError(msg)
    den = lookup_unit(m.group(3), what=f"sensitivity {raw!r}")
    if not value > 0 or value != value or value == float("inf"):
        msg = f"sensitivity {raw!r} must be a positive finite number; got {value}"
        raise RecordingError(msg)
    if den.offset:
        msg = f"sensitivity {raw!r}: an offset unit ({den.label}) cannot be a denominator"
        raise RecordingError(msg)
    return Sensitivity(value * num.factor / den.factor, den, raw.strip())


def parse_quantity(text) -> tuple[float, Unit]:
    """Parse ``"5 V"`` or ``"500 g"`` into (value in SI, Unit).

    Examples
    --------
    >>> parse_quantity("500 mV")[0]
    0.5
    """
    raw = str(text)
    m = re.fullmatch(rf"\s*({_NUM})\s*(.+?)\s*", raw)
    if not m:
        msg = f"quantity {raw!r} is not of the form '<number> <unit>'; write e.g. '5 V' or '50 g'"
        raise RecordingError(msg)
    u = lookup_unit(m.group(2), what=f"quantity {raw!r}")
    value = float(m.group(1).replace(",", "."))
    return value * u.factor + u.offset, u


UFF_LABELS = {"m s-2": "m/s2", "m s-1": "m/s", "m": "m", "Pa": "Pa", "N": "N", "V": "V",
              "1": "NONE", "rad": "rad", "rad s-1": "rad/s", "K": "K", "s": "s"}
"""SI unit (CF spelling) -> the label UFF/Testlab files use."""
