"""Validation cases: TOML files read, checked and turned into one object, before anything runs.

Why TOML cases: what a validation compares, against what, and how close counts as
agreement are decisions a reviewer must be able to read and argue with.  Every key
is documented in ``docs/case-format.md`` (the table :data:`CASE_KEYS` is its source);
an unknown key is refused naming the key, a tolerance without a reason falls back to
the quantity table's documented one, and a case never names code to run.

Public API
----------
CASE_KEYS                         -- section -> {key: description} of every accepted key
RecordingSpec                     -- one recording: file or registry name, channel, calibration, span
ValidationCase                    -- a checked case
shipped_cases()                   -- {name: Traversable} of the cases shipped as package data
case_dir()                        -- their folder
case_error, check_keys, check_number, check_speed, parse_tolerances, recording_spec, ratio_spec
                                  -- the checks every section uses (:mod:`.case_checks`), one wording

A case is loaded by :func:`bearing_lab.validation.load.load_case`, which runs the checks.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from .. import datasets
from ..errors import BearingLabError, ValidationCaseError
from ..units import parse_sensitivity
from .quantities import QUANTITIES
from .rows import Tolerance

__all__ = ["CASE_KEYS", "RecordingSpec", "ValidationCase", "shipped_cases", "case_dir", "DEFAULT_CASE",
           "SCALE_RANGE", "case_error", "check_keys", "check_number", "check_speed", "parse_tolerances",
           "recording_spec", "ratio_spec"]

DEFAULT_CASE = "paper"
#: a calibration factor outside this range is a typo, not a sensor
SCALE_RANGE = (1e-6, 1e6)

_REC = {"file": "recording file, relative to the case file (or absolute)",
        "name": "registry name of a public recording (instead of file)",
        "channel": "channel to compare (default: the file's default channel)",
        "format": "reader name (default: sniffed from the content)",
        "sensitivity": "sensor sensitivity for channels stored in volts, e.g. \"9.91 mV/g\"",
        "units": "unit of the stored values when the file names none, e.g. \"g\"",
        "fs": "sampling rate, Hz, for files that store none",
        "scale": "calibration factor applied to the SI values (default 1)",
        "start_s": "start of the compared segment in the recording, s (default 0)",
        "duration_s": "compared and simulated duration, s (default 1)"}
#: section -> key -> description (the source of docs/case-format.md's key tables)
CASE_KEYS = {
    "": {"name": "case name (default: the file name)", "title": "one line shown in the index",
         "description": "free text", "kind": "\"recording\" (default) or \"paper\"",
         "default": "part of the default set of `bearing-lab validate` (shipped cases)",
         "bearing": "catalog name (6308, 6205, ...) or a [bearing] table",
         "speed": "shaft speed: r/min, \"file\" (stored in the recording) or \"estimate\" (from the signal)",
         "reference": "paper cases: the file of the paper's figures"},
    "recording": _REC,
    "reference": {**_REC, "speed": "speed of the reference recording (default: the case's)",
                  "tolerances": "rows of the healthy comparison (default: shaft_hz)"},
    "bearing": {"name": "catalog name, or a label for a custom geometry",
                "n_balls": "Z", "ball_diameter_mm": "D_b", "pitch_diameter_mm": "d_m", "bore_mm": "bore",
                "outer_diameter_mm": "outer diameter", "width_mm": "ring width",
                "inner_conformity": "inner groove radius / D_b", "outer_conformity": "outer groove radius / D_b"},
    "load": {"radial_n": "radial load, N", "on": "ring the load acts on: \"inner\" (default) or \"outer\"",
             "direction_deg": "direction of the load on the ring (270 = downward, default)"},
    "defect": {"race": "\"outer\", \"inner\" or \"ball\"", "shape": "\"rectangle\", \"ellipse\" or \"polygon\"",
               "length_mm": "extent along the track", "width_mm": "extent across the track",
               "depth_mm": "depth", "offset_mm": "axial offset H of the centre from the track centre line",
               "skew_deg": "skew θ of the long axis against the centre line",
               "angle_deg": "position around the ring, from the load-zone centre",
               "diameter_mm": "ellipse/circle diameter", "vertices_mm": "polygon vertices",
               "contact_model": "defect contact model (default: the simulator's)"},
    "scene": {"base": "built-in scene or scene TOML the case starts from",
              "set": "table of scene keys (as `bearing-lab simulate --set`)"},
    "structural_path": {"method": "\"fit\" (default), \"fixed\" or \"none\"",
                        "from_case": "use the path fitted by another case (same rig)",
                        "file": "a path saved by an earlier run (structural_path.json)",
                        "resonances": "modes of the path: 1 (default) or 2",
                        "frequency_hz": "fit: [low, high] bounds; fixed: the value(s)",
                        "damping_ratio": "fit: [low, high] bounds; fixed: the value(s)",
                        "gain": "fit: [low, high] bounds; fixed: the value"},
    "background": {"enabled": "add the rig's measured background to the simulation (default true)",
                   "source": "\"auto\" (default), \"reference\" or \"recording\"",
                   "max_tones": "machine tones kept (default 20)", "tone_snr_db": "tone threshold (default 15 dB)",
                   "seed": "seed of the synthesised noise (default 0)"},
    "ratio": {"recording": "registry name or file of the companion recording", "channel": "its channel",
              "scene": "its scene (built-in or TOML)", "set": "scene keys", "label": "shown in the table",
              "speed": "its speed (default: \"file\")"},
    "numerical_error": {"enabled": "rerun with rtol / 10 (default true)", "duration_s": "seconds rerun (default 0.25)"},
    "tolerances": {"<quantity>": "{pct | factor, reason, known_limitation}: see the quantity table"},
    "run": {"label": "paper cases: run label", "scene": "scene", "duration_s": "simulated s", "set": "scene keys"},
    "studies": {"enabled": "paper cases: run the section-5 studies"},
}


def case_error(case, msg):
    return ValidationCaseError(f"validation case {case!r}: {msg}")


@dataclass
class RecordingSpec:
    """Where a recording is and how to read it: the ``[recording]`` (or ``[reference]``) table of a
    case, keys as in ``docs/case-format.md``.

    See Also
    --------
    ValidationCase, bearing_lab.io.open_recording
    """

    file: Path | None = None
    name: str | None = None
    channel: str | None = None
    format: str | None = None
    sensitivity: str | None = None
    units: str | None = None
    fs: float | None = None
    scale: float = 1.0
    start_s: float = 0.0
    duration_s: float = 1.0
    speed: object = None

    @property
    def label(self) -> str:
        return self.name or (self.file.name if self.file else "?")

    def read_options(self) -> dict:
        return {k: v for k, v in (("format", self.format), ("sensitivity", self.sensitivity),
                                  ("units", self.units), ("fs", self.fs)) if v is not None}


@dataclass
class ValidationCase:
    """A checked case.  ``data`` keeps the TOML mapping, ``text`` the file as written.

    See Also
    --------
    load_case : makes one from a shipped name or a TOML file.
    run_case : runs it.
    """

    name: str
    title: str
    kind: str
    source: str
    text: str
    data: dict
    base_dir: object = None
    default: bool = False
    tolerances: dict = field(default_factory=dict)
    recording: RecordingSpec | None = None
    reference: RecordingSpec | None = None
    reference_tolerances: dict = field(default_factory=dict)
    speed: object = "file"

    @property
    def author(self) -> str:
        """Who wrote the case, and so declared its known limitations: the project (a shipped case)
        or the author of a case file."""
        if self.source.startswith("shipped case"):
            return f"bearing_lab (shipped case {self.name})"
        return f"the author of {self.source}"

    def section(self, key) -> dict:
        v = self.data.get(key)
        return dict(v) if isinstance(v, dict) else {}

    @property
    def recording_labels(self) -> list:
        out = [s for s in (self.recording, self.reference) if s is not None]
        ratio = self.section("ratio")
        if ratio.get("recording"):
            out.append(ratio_spec(self, ratio))
        return out


# ------------------------------------------------------------------ shipped cases
def case_dir():
    """The folder of the shipped cases (package data)."""
    return resources.files("bearing_lab.validation").joinpath("cases")


def shipped_cases() -> dict:
    """``{name: Traversable}`` of the cases shipped in ``bearing_lab/validation/cases`` (package data).

    See Also
    --------
    list_cases : the same names with their titles.
    load_case : a shipped case by its name.

    Examples
    --------
    >>> cases = shipped_cases()
    >>> "paper" in cases, cases["paper"].name
    (True, 'paper.toml')
    """
    d = case_dir()
    items = sorted((p for p in d.iterdir() if p.name.endswith(".toml") and not p.name.endswith("_reference.toml")),
                   key=lambda p: p.name)
    return {p.name[:-5]: p for p in items}


# ------------------------------------------------------------------ checks
def check_keys(name, where, mapping, allowed):
    if not isinstance(mapping, dict):
        raise case_error(name, f"[{where}] must be a table")
    bad = sorted(set(mapping) - set(allowed))
    if bad:
        raise case_error(name, f"unknown key {bad[0]!r} in [{where}]; allowed keys are {', '.join(sorted(allowed))}")


def check_number(name, where, v, *, lo=None, hi=None, positive=False):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise case_error(name, f"{where} = {v!r} must be a finite number")
    if positive and not v > 0:
        raise case_error(name, f"{where} = {v!r} must be positive")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise case_error(name, f"{where} = {v!r} must lie between {lo:g} and {hi:g}")
    return float(v)


def check_speed(name, where, v):
    """A speed key: r/min (positive number), "file" or "estimate"."""
    if v in ("file", "estimate"):
        return v
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and v > 0):
        raise case_error(name, f"{where} = {v!r}: give the shaft speed in r/min, \"file\" (stored in the recording) "
                         "or \"estimate\" (from the signal)")
    return float(v)


def recording_spec(name, where, raw, base_dir, *, allowed=None) -> RecordingSpec:
    check_keys(name, where, raw, allowed or CASE_KEYS["recording"])
    if bool(raw.get("file")) == bool(raw.get("name")):
        raise case_error(name, f"[{where}] needs exactly one of file (a path) or name (a registry recording)")
    spec = RecordingSpec(name=raw.get("name"), channel=raw.get("channel"), format=raw.get("format"),
                         sensitivity=raw.get("sensitivity"), units=raw.get("units"))
    if raw.get("file"):
        p = Path(str(raw["file"])).expanduser()
        spec.file = p if p.is_absolute() or base_dir is None else Path(str(base_dir)) / p
    else:
        try:
            datasets.get(spec.name)
        except BearingLabError as exc:
            raise case_error(name, f"{where}.name: {exc}") from None
    if "fs" in raw:
        spec.fs = check_number(name, f"{where}.fs", raw["fs"], positive=True)
    if "scale" in raw:
        s = raw["scale"]
        spec.scale = check_number(name, f"{where}.scale", s, lo=SCALE_RANGE[0], hi=SCALE_RANGE[1]) if (
            isinstance(s, (int, float)) and not isinstance(s, bool) and math.isfinite(s) and s > 0) else None
        if spec.scale is None:
            raise case_error(name, f"{where}.scale = {s!r}: a calibration factor must be a finite positive number "
                             f"between {SCALE_RANGE[0]:g} and {SCALE_RANGE[1]:g} (1 = the file's values are right)")
    if spec.sensitivity is not None:
        try:
            parse_sensitivity(spec.sensitivity)
        except BearingLabError as exc:
            raise case_error(name, f"{where}.sensitivity: {exc}") from None
    spec.start_s = check_number(name, f"{where}.start_s", raw.get("start_s", 0.0), lo=0.0, hi=1e6)
    spec.duration_s = check_number(name, f"{where}.duration_s", raw.get("duration_s", 1.0), positive=True)
    if "speed" in raw:
        spec.speed = check_speed(name, f"{where}.speed", raw["speed"])
    return spec


def ratio_spec(case, raw) -> RecordingSpec:
    """The ``[ratio]`` companion: a registry name when the registry knows it, else a file."""
    rec = str(raw["recording"])
    spec = RecordingSpec(channel=raw.get("channel"), speed=raw.get("speed", "file"))
    if _is_registry(rec):
        spec.name = rec
    else:
        p = Path(rec).expanduser()
        spec.file = p if p.is_absolute() or case.base_dir is None else Path(str(case.base_dir)) / p
    return spec


def _is_registry(name) -> bool:
    try:
        datasets.get(name)
        return True
    except BearingLabError:
        return False


def parse_tolerances(name, raw, *, where="tolerances", allowed=None) -> dict:
    allowed = allowed or QUANTITIES
    if not isinstance(raw, dict) or not raw:
        raise case_error(name, f"needs a [{where}] table: one entry per compared quantity")
    out = {}
    for q, spec in raw.items():
        if q not in allowed:
            raise case_error(name, f"unknown quantity {where}.{q}; allowed are {', '.join(allowed)}")
        if not isinstance(spec, dict):
            raise case_error(name, f"{where}.{q} must be a table such as {{ pct = 1.0, reason = \"...\" }} "
                             "(or {} for the quantity's default)")
        check_keys(name, f"{where}.{q}", spec, {"pct", "factor", "reason", "known_limitation"})
        kinds = [k for k in ("pct", "factor") if k in spec]
        if len(kinds) > 1:
            raise case_error(name, f"{where}.{q} needs one of pct or factor, not both")
        default = QUANTITIES[q].tolerance if q in QUANTITIES else None
        if kinds and not str(spec.get("reason", "")).strip():
            raise case_error(name, f"{where}.{q} sets {kinds[0]} but gives no reason: every tolerance needs one")
        if default is None and not kinds:
            raise case_error(name, f"{where}.{q} has no default: give pct or factor, and a reason")
        kind = kinds[0] if kinds else default.kind
        value = spec[kind] if kinds else default.value
        reason = str(spec.get("reason") or default.reason).strip()
        try:
            out[q] = Tolerance(kind, value, reason, str(spec.get("known_limitation", "")).strip())
        except ValidationCaseError as exc:
            raise case_error(name, f"{where}.{q}: {exc}") from None
    return out
