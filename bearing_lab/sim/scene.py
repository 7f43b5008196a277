"""Declarative scenes: what to simulate, in physical units, validated on entry.

A scene is a TOML file (or a dict, or a built-in name) whose keys carry their unit in the name
(``radial_n``, ``length_mm``, ``stiffness_y_n_m``). A value may also be a string with a unit (``"1 mm"``,
``"1800 rpm"``, ``"150 N"``); it is converted, and a unit of the wrong kind is refused. Unknown keys, wrong
types and impossible values raise :class:`~bearing_lab.errors.SceneError` naming the key and the reason.

Defaults where the paper is silent (each settable; see ``docs`` in :data:`SCHEMA`):

- steel balls and rings: E = 208 GPa, ν = 0.3, ρ = 7850 kg/m³ (AISI 52100 handbook values);
- groove conformities f_i = 0.52, f_o = 0.53 (Harris & Kotzalas, *Rolling Bearing Analysis*, typical
  deep-groove values);
- radial internal clearance 0 (mounted: an interference fit takes most of a C0 6308's 6–20 µm, ISO 5753-1);
- ring masses from the ring envelope (steel annuli between bore / outer diameter and the raceway shoulders),
  ball mass from D_b and ρ;
- shaft (inner ring to ground) and mount (outer-ring bushing) stiffness 1e8 N/m: the order of the bearing's
  own linearised radial stiffness (≈1.2e8 N/m near 1 kN from the Hertz constants, and the
  13e6·Z^(2/3)·D_b^(1/3)·F^(1/3) rule of thumb), as in lumped rotor–bearing–pedestal models (e.g. Sawalhi &
  Randall, MSSP 22 (2008) 1924–1951);
- their damping 1000 N·s/m: ~1e-5 × stiffness, inside the paper's 0.25–2.5e-5 rule (its section 2.1, citing
  Liu & Shao);
- contact damping c_max = 350 N·s/m (paper) reached at penetration d = 1 µm (not given by the paper; 1 µm is
  ~10 % of the static deflection, so damping is fully on in a loaded contact and fades smoothly at
  touch-down);
- load path "bearing": the support spring of the ring that takes the external load is preloaded (its rest
  position is the ring's static equilibrium), so the whole load goes through the balls, as in the paper's
  experiment where the load is applied through the bearing. ``load.path = "springs"`` leaves both supports
  unstressed at the nominal centre (most load then bypasses the bearing and amplitudes drop three- to
  five-fold).
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, field
import math
from pathlib import Path
import re
import tomllib

import numpy as np

from .._docdict import fill_doc
from ..bearings import BearingGeometry, CATALOG, get_bearing
from ..errors import SceneError, check_choice
from ..units import G
from .auto import warn_off_track
from .bearing3d import check_axial_keys, needs_3d
from .defects import Defect  # the 2-D defect description
from .defects import contact  # its registry CONTACT_MODELS, read at call time (models register at run time)
from .limits import check_limits
from .scene_keys import _NUM, DEFECT_KEYS, SCHEMA


#: the shortest settling time of a scene with an axial load (the 3-D bearing), s
SETTLE_3D_S = 0.03
#: damping rate (1/s) on the balls' axial motion (relative to the rings') while a 3-D multibody scene
#: settles, switched off ``SETTLE_FREE_S`` before the record starts (see :attr:`Scene.settle`)
SETTLE_AXIAL_RATE = 1e3
SETTLE_FREE_S = 0.01


# ---------------------------------------------------------------- units
_UNITS = {
    "length": {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "in": 0.0254, "mil": 2.54e-5},
    "force": {"n": 1.0, "kn": 1e3, "lbf": 4.4482216152605},
    "speed": {"rpm": 1.0, "r/min": 1.0, "hz": 60.0},
    "time": {"s": 1.0, "ms": 1e-3},
    "frequency": {"hz": 1.0, "khz": 1e3},
    "angle": {"deg": 1.0, "rad": 180 / math.pi},
    "stiffness": {"n/m": 1.0, "n/mm": 1e3, "n/um": 1e6},
    "damping": {"n s/m": 1.0, "ns/m": 1.0, "n*s/m": 1.0},
    "mass": {"kg": 1.0, "g": 1e-3},
    "pressure": {"gpa": 1.0, "pa": 1e-9, "mpa": 1e-3},
    "density": {"kg/m3": 1.0, "kg/m^3": 1.0},
    "acceleration": {"m/s2": 1.0, "m/s^2": 1.0, "g": G},
}
# unit kind and the scale of the key's own unit in that kind's base unit
_SUFFIX = {
    "_mm": ("length", 1e-3), "_um": ("length", 1e-6), "_m": ("length", 1.0),
    "_n": ("force", 1.0), "_rpm": ("speed", 1.0), "_s": ("time", 1.0),
    "_hz": ("frequency", 1.0), "_deg": ("angle", 1.0), "_n_m": ("stiffness", 1.0),
    "_n_s_m": ("damping", 1.0), "_kg": ("mass", 1.0), "_gpa": ("pressure", 1.0),
    "_kg_m3": ("density", 1.0), "_m_s2": ("acceleration", 1.0),
}


def _suffix(key: str):
    for suf in sorted(_SUFFIX, key=len, reverse=True):
        if key.endswith(suf):
            return _SUFFIX[suf]
    return None


def convert_value(value, key: str, where: str):
    """Convert a "1 mm"-style string to the unit the key names."""
    if not isinstance(value, str):
        return value
    spec = _suffix(key)
    m = re.fullmatch(r"\s*([-+0-9.eE]+)\s*(\S.*?)?\s*", value)
    if spec is None or m is None:
        return value
    try:
        number = float(m.group(1))
    except ValueError:
        raise SceneError(f"{where}: {value!r} is not a number with a unit") from None
    unit = (m.group(2) or "").lower().replace("·", " ").strip()
    kind, own_scale = spec
    table = _UNITS[kind]
    if unit not in table:
        other = [k for k, t in _UNITS.items() if unit in t]
        hint = f" (that is a {other[0]} unit)" if other else ""
        raise SceneError(f"{where}: unit {m.group(2)!r} is not a {kind} unit{hint}; "
                         f"use one of {', '.join(table)}")
    return number * table[unit] / own_scale


MAX_MAGNITUDE = 1e15
"""Largest magnitude of a number key in the key's own unit (mm, N/m, Hz ...): far beyond any
bearing, yet small enough that the physics (squares, products of keys) stays finite."""


def _check(value, key, spec, where):
    default, typ, check, _ = spec
    value = convert_value(value, key, where)
    if typ is bool:
        if not isinstance(value, bool):
            raise SceneError(f"{where}: {value!r} must be true or false")
        return value
    if typ is int and isinstance(value, float) and value.is_integer():
        value = int(value)
    if typ in (_NUM, int):
        if isinstance(value, bool) or not isinstance(value, typ if typ is int else _NUM):
            raise SceneError(f"{where}: {value!r} must be a number"
                             + (" (an integer)" if typ is int else "")
                             + (f" in the key's unit ({key.rsplit('_', 1)[-1]})" if _suffix(key) else ""))
        value = float(value) if typ is _NUM else int(value)
        if not math.isfinite(value):
            raise SceneError(f"{where}: {value!r} must be finite")
        if abs(value) > MAX_MAGNITUDE:  # 1e308 would overflow the first square taken of it
            raise SceneError(f"{where}: {float(value):.6g} is beyond any physical value of this key "
                             f"(magnitude above {MAX_MAGNITUDE:.0e} in its unit)")
        if check == "pos" and not value > 0:
            raise SceneError(f"{where}: {value!r} must be positive")
        if check == "nonneg" and value < 0:
            raise SceneError(f"{where}: {value!r} must not be negative")
        if check == "frac" and not 0 <= value < 0.5:
            raise SceneError(f"{where}: {value!r} must lie in [0, 0.5)")
        return value
    if typ is str:
        if not isinstance(value, str):
            raise SceneError(f"{where}: {value!r} must be a string")
        if isinstance(check, tuple):
            check_choice(value, check, where, SceneError)
        return value
    if typ is list:
        if not isinstance(value, list):
            raise SceneError(f"{where}: {value!r} must be a list")
        return value
    return value


def _validate_mapping(raw: dict) -> dict:
    """Return a complete nested dict (defaults filled in) or raise SceneError."""
    if not isinstance(raw, dict):
        raise SceneError(f"a scene must be a table of keys, got {type(raw).__name__}")
    out = {}
    for sec, keys in SCHEMA.items():
        if sec == "":
            continue
        out[sec] = {k: spec[0] for k, spec in keys.items()}
    for k, spec in SCHEMA[""].items():
        out[k] = spec[0]
    defects = []
    for key, value in raw.items():
        if key in ("defect", "defects"):
            items = value if isinstance(value, list) else [value]
            for i, d in enumerate(items):
                if not isinstance(d, dict):
                    raise SceneError(f"{key}[{i}]: must be a table of defect keys")
                bad = set(d) - DEFECT_KEYS
                if bad:
                    raise SceneError(f"unknown key {key}.{sorted(bad)[0]!s}; defect keys are "
                                     + ", ".join(sorted(DEFECT_KEYS)))
                defects.append(dict(d))
            continue
        if key in SCHEMA[""]:
            out[key] = _check(value, key, SCHEMA[""][key], key)
            continue
        if key not in SCHEMA:
            raise SceneError(f"unknown key {key!r}; top-level keys are "
                             + ", ".join(sorted([*SCHEMA[""], *[s for s in SCHEMA if s], "defect"])))
        if not isinstance(value, dict):
            raise SceneError(f"{key}: must be a table, got {value!r}")
        for sub, v in value.items():
            where = f"{key}.{sub}"
            if sub not in SCHEMA[key]:
                raise SceneError(f"unknown key {where!r}; [{key}] keys are " + ", ".join(SCHEMA[key]))
            if v is None:  # an unset optional key (as stored in Scene.data): keep the default
                continue
            out[key][sub] = _check(v, sub, SCHEMA[key][sub], where)
    out["defect"] = defects
    return out


# ---------------------------------------------------------------- the Scene
@dataclass(frozen=True)
class Scene:
    """A validated scene: ``data`` holds the user-unit mapping (what TOML shows), the properties
    SI values; :func:`load_scene` makes one, :meth:`replace` a changed copy.

    See Also
    --------
    load_scene, simulate, list_scenes
    """

    data: dict
    bearing: BearingGeometry
    defects: tuple = field(default_factory=tuple)

    # ---- construction
    @classmethod
    def from_mapping(cls, raw: dict) -> "Scene":
        d = _validate_mapping(copy.deepcopy(raw))
        bearing = _bearing_from(d)
        defects = []
        for i, m in enumerate(d["defect"]):
            where = "defect" if len(d["defect"]) == 1 else f"defect[{i}]"
            m = {k: convert_value(v, k, f"{where}.{k}") for k, v in m.items()}
            check_choice(m.pop("contact_model", "auto"), ("auto", *contact.CONTACT_MODELS),
                         f"{where}.contact_model", SceneError)
            defect = Defect.from_mapping(m, where=where)
            defect.validate(bearing)
            defects.append(defect)
        scene = cls(d, bearing, tuple(defects))
        scene._check_physics()
        warn_off_track(scene)
        return scene

    def replace(self, **overrides) -> "Scene":
        """Return a new scene with ``--set``-style overrides (``{"load.radial_n": 480}``)."""
        raw = copy.deepcopy(self.data)
        for key, value in overrides.items():
            _apply_override(raw, key, value)
        return Scene.from_mapping(raw)

    # ---- physics checks that need several keys
    def _check_physics(self):
        d = self.data
        prof = d["speed"]["profile"]
        if prof is not None:
            try:
                arr = np.asarray(prof, dtype=float)
            except (TypeError, ValueError):
                raise SceneError("speed.profile: must be a list of [t_s, rpm] pairs") from None
            if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 1:
                raise SceneError("speed.profile: must be a list of [t_s, rpm] pairs")
            if np.any(np.diff(arr[:, 0]) <= 0):
                raise SceneError("speed.profile: times must increase strictly")
            if np.any(arr[:, 1] < 0) or not np.all(np.isfinite(arr)):
                raise SceneError("speed.profile: speeds must be finite and not negative")
        pd = self.clearance
        b = self.bearing
        max_preload = 0.005 * b.ball_diameter  # interference of 0.5 % of D_b: ~1 GPa-class overload
        if pd < -max_preload:
            raise SceneError(f"clearance.radial_um={pd*1e6:g}: a preload this large "
                             f"(> {max_preload*1e6:.0f} µm) crushes the balls")
        if pd > 0.02 * b.ball_diameter:
            raise SceneError(f"clearance.radial_um={pd*1e6:g} is larger than 2 % of the ball diameter: "
                             "not a bearing")
        check_axial_keys(self)
        if self.fs_out < 1000:
            raise SceneError(f"output.sample_rate_hz={self.fs_out:g} is below 1 kHz: too coarse for bearing vibration")
        if d["output"]["duration_s"] > 600:
            raise SceneError(f"output.duration_s={d['output']['duration_s']:g} s exceeds 600 s; split the run")
        check_limits(self)

    # ---- SI accessors
    @property
    def name(self) -> str:
        return self.data["name"]

    @property
    def fidelity(self) -> str:
        return self.data["fidelity"]

    @property
    def clearance(self) -> float:
        return self.data["clearance"]["radial_um"] * 1e-6

    @property
    def fs_out(self) -> float:
        return self.data["output"]["sample_rate_hz"]

    @property
    def duration(self) -> float:
        return self.data["output"]["duration_s"]

    @property
    def settle(self) -> float:
        """Seconds simulated and discarded before the record starts (``output.settle_s``); with an
        axial load at least ``SETTLE_3D_S``.  The start from the static equilibrium (which leaves
        out the damping of the orbiting contacts) excites the balls' axial modes (1.5-4.5 kHz on
        the 6308 and the 6205), which the contacts barely damp (damping ratios 0-0.0025 at the
        start: the contact damping acts along the contact line, nearly across the axial motion), so
        with multibody balls their motion relative to the rings is damped at ``SETTLE_AXIAL_RATE``
        (a 2 ms time constant) while settling, until ``SETTLE_FREE_S`` before the record.  On
        cwru-normal with 188 N axial, against a 0.5 s undamped settle: 0.1 s undamped left the
        peak acceleration 120 % and the axial RMS 100 times too high (kurtosis 1.77 against 1.50);
        0.03 s with 0.02 s damped is within 0.2 % (peak, RMS) and 1.3 % (axial RMS), and on
        paper-healthy under 300 N it removes an axial ringing that 0.5 s undamped still holds
        (axial RMS -96 %).  Massless balls (no axial ball states) settle within 0.03 s alike."""
        s = self.data["output"]["settle_s"]
        if needs_3d(self):
            return max(s, SETTLE_3D_S)
        return s

    def speed_profile(self):
        """(t, rpm) arrays of the piecewise-linear speed, t from the start of settling."""
        prof = self.data["speed"]["profile"]
        if prof is None:
            return np.array([0.0]), np.array([self.data["speed"]["rpm"]], dtype=float)
        arr = np.asarray(prof, dtype=float)
        return arr[:, 0] + self.settle, arr[:, 1]

    @property
    def nominal_rpm(self) -> float:
        t, rpm = self.speed_profile()
        return float(rpm[-1]) if len(rpm) == 1 else float(np.max(rpm))

    def masses(self) -> tuple[float, float, float]:
        """(inner ring, outer ring, ball) masses, kg."""
        b = self.bearing
        rho = self.data["material"]["density_kg_m3"]
        m = self.data["mass"]
        ball = m["ball_kg"] or rho * math.pi / 6 * b.ball_diameter ** 3
        width = b.width or 1.5 * b.ball_diameter
        bore = b.bore or (b.pitch_diameter - 2.2 * b.ball_diameter)
        od = b.outer_diameter or (b.pitch_diameter + 2.2 * b.ball_diameter)
        # shoulders at 60 % of the ball radius beyond the raceway bottoms (typical 6xxx)
        shoulder_i = b.pitch_diameter - 0.6 * b.ball_diameter
        shoulder_o = b.pitch_diameter + 0.6 * b.ball_diameter
        inner = m["inner_ring_kg"] or rho * math.pi / 4 * (shoulder_i ** 2 - bore ** 2) * width
        outer = m["outer_ring_kg"] or rho * math.pi / 4 * (od ** 2 - shoulder_o ** 2) * width
        return float(inner), float(outer), float(ball)

    def to_toml(self) -> str:
        return dumps_toml(self.data)


def _bearing_from(d: dict) -> BearingGeometry:
    name = d["bearing"]
    if name in CATALOG:
        base = get_bearing(name)
    elif d["bearing_geometry"]["n_balls"] is not None:
        base = None
    else:
        raise SceneError(f"bearing: unknown bearing {name!r}; the catalog has "
                         + ", ".join(sorted(CATALOG)) + " (or give [bearing_geometry] n_balls, "
                         "ball_diameter_mm, pitch_diameter_mm, ...)")
    g = d["bearing_geometry"]
    mm = 1e-3
    kw = {}
    for key, attr, scale in (("n_balls", "n_balls", 1), ("ball_diameter_mm", "ball_diameter", mm),
                             ("pitch_diameter_mm", "pitch_diameter", mm), ("bore_mm", "bore", mm),
                             ("outer_diameter_mm", "outer_diameter", mm), ("width_mm", "width", mm),
                             ("inner_conformity", "inner_conformity", 1),
                             ("outer_conformity", "outer_conformity", 1)):
        if g[key] is not None:
            kw[attr] = g[key] * scale
    try:
        if base is None:
            missing = [k for k in ("ball_diameter", "pitch_diameter") if k not in kw]
            if missing:
                raise SceneError("bearing_geometry: a user-defined bearing needs "
                                 + " and ".join(m + "_mm" for m in missing))
            return BearingGeometry(name, **kw)
        return base.with_(**kw) if kw else base
    except SceneError as exc:
        raise SceneError(f"bearing_geometry: {exc}") from None


# ---------------------------------------------------------------- overrides
SET_ALIASES = {"speed_rpm": "speed.rpm", "rpm": "speed.rpm", "duration": "output.duration_s",
            "fs": "output.sample_rate_hz"}


def _key_type(parts):
    """The schema type of a ``--set`` key (None if unknown: the scene check names the key)."""
    if parts[0] in ("defect", "defects"):
        return list if parts[-1] == "vertices_mm" else None
    spec = SCHEMA[""].get(parts[0]) if len(parts) == 1 else SCHEMA.get(parts[0], {}).get(parts[1])
    return spec[1] if spec else None


def parse_value(text, typ=None, key=""):
    """A ``--set`` value: the text itself for a text key (``bearing=6205``), a TOML array for a
    list key (``speed.profile=[[0, 1000], [0.05, 1800]]``), else a bool, int, float or text."""
    if not isinstance(text, str):
        return text
    stripped = text.strip()
    if typ is str:
        if len(stripped) >= 2 and stripped[0] == stripped[-1] and stripped[0] in "'\"":
            return stripped[1:-1]
        return stripped
    if stripped.startswith("["):
        try:
            return tomllib.loads(f"v = {stripped}")["v"]
        except tomllib.TOMLDecodeError as exc:
            raise SceneError(f"--set {key}: {stripped!r} is not a list in TOML syntax ({exc}); write "
                             "e.g. [[0, 1000], [0.05, 1800]]") from None
    low = stripped.lower()
    if low in ("true", "false"):
        return low == "true"
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text.strip()


def _apply_override(raw: dict, key: str, value):
    key = SET_ALIASES.get(key, key)
    parts = key.split(".")
    value = parse_value(value, _key_type(parts), key)
    if parts[0] in ("defect", "defects"):
        if len(parts) != 2:
            raise SceneError(f"--set {key}: use defect.<key>, e.g. defect.length_mm=1")
        items = raw.get("defect") or raw.get("defects") or []
        if isinstance(items, dict):
            items = [items]
        if not items:
            items = [{"race": "outer", "shape": "rectangle"}]
        raw.pop("defects", None)
        items[0][parts[1]] = value
        raw["defect"] = items
        return
    if len(parts) == 1:
        raw[parts[0]] = value
    elif len(parts) == 2:
        sec = raw.setdefault(parts[0], {})
        if not isinstance(sec, dict):
            raise SceneError(f"--set {key}: {parts[0]!r} is not a table")
        sec[parts[1]] = value
    else:
        raise SceneError(f"--set {key}: keys have at most one dot (section.key)")


def parse_set(items) -> dict:
    """Turn ``["load.radial_n=480", ...]`` into a dict, refusing malformed items.

    Aliases (``fs``, ``duration``, ``speed_rpm`` ...) become their scene keys, so
    ``--set fs=40000`` is ``output.sample_rate_hz`` like everywhere else; a key given
    twice (also through an alias) is refused.
    """
    out, given = {}, {}
    for item in items or []:
        if "=" not in item:
            raise SceneError(f"--set {item!r}: expected KEY=VALUE")
        k, v = item.split("=", 1)
        k = k.strip()
        if not k:
            raise SceneError(f"--set {item!r}: no key before '='")
        key = SET_ALIASES.get(k, k)
        if key in out:
            raise SceneError(f"--set {k}: the key {key} is already given (--set {given[key]}); give "
                             "it once")
        out[key], given[key] = v, item
    return out


def merge_overrides(overrides: dict, **named) -> dict:
    """``overrides`` plus keyword settings such as ``{"output.duration_s": 0.1}`` (None: unset).

    All keys are taken through the aliases; one key set to two values is refused.
    """
    out = {}
    for k, v in overrides.items():
        key = SET_ALIASES.get(k, k)
        if key in out and out[key] != v:
            raise SceneError(f"{k}={v!r}: the key {key} is already set to {out[key]!r}")
        out[key] = v
    for key, v in named.items():
        if v is None:
            continue
        if key in out and parse_value(out[key]) != parse_value(v):
            raise SceneError(f"{key} is given twice, as {out[key]!r} and {v!r}; give it once")
        out[key] = v
    return out


# ---------------------------------------------------------------- TOML
def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {v!r} to TOML")


def dumps_toml(d: dict) -> str:
    """Write a scene mapping as TOML (None values are omitted)."""
    lines = []
    for k, v in d.items():
        if not isinstance(v, (dict, list)) or (isinstance(v, list) and k != "defect"):
            if v is not None:
                lines.append(f"{k} = {_toml_value(v)}")
    for k, v in d.items():
        if isinstance(v, dict):
            body = [f"{kk} = {_toml_value(vv)}" for kk, vv in v.items() if vv is not None]
            if body:
                lines += ["", f"[{k}]", *body]
    for item in d.get("defect", []) or []:
        lines += ["", "[[defect]]", *[f"{kk} = {_toml_value(vv)}" for kk, vv in item.items()]]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- loading
_SCENE_DIR = Path(__file__).with_name("scenes")


def list_scenes() -> dict[str, str]:
    """Built-in scene names with their one-line descriptions.

    See Also
    --------
    load_scene, simulate

    Examples
    --------
    >>> list_scenes()["paper-healthy"]
    'Paper section 4: healthy 6308 at 1800 r/min, 150 N on the outer ring along -Y'
    """
    out = {}
    for p in sorted(_SCENE_DIR.glob("*.toml")):
        with open(p, "rb") as fh:
            out[p.stem] = tomllib.load(fh).get("description", "")
    return out


@fill_doc
def load_scene(scene, **overrides) -> Scene:
    """Return a checked :class:`Scene` (nothing is simulated); an unknown scene or key, or a value
    out of range, raises :class:`~bearing_lab.errors.SceneError` naming the key.

    Parameters
    ----------
    %(scene)s
    %(overrides)s

    See Also
    --------
    simulate, list_scenes, Scene.replace

    Examples
    --------
    >>> sc = load_scene("paper-healthy", **{"load.radial_n": 480, "clearance.radial_um": "10 um"})
    >>> sc.data["load"]["radial_n"], sc.nominal_rpm, round(sc.clearance, 12)   # user units; SI: m
    (480.0, 1800.0, 1e-05)
    """
    if isinstance(scene, Scene):
        return scene.replace(**overrides) if overrides else scene
    if isinstance(scene, dict):
        raw = copy.deepcopy(scene)
    else:
        name = str(scene)
        path = Path(name)
        if path.suffix == ".toml" or path.exists():
            if not path.is_file():
                raise SceneError(f"scene file {name!r} does not exist")
            try:
                with open(path, "rb") as fh:
                    raw = tomllib.load(fh)
            except tomllib.TOMLDecodeError as exc:
                raise SceneError(f"scene file {name!r} is not valid TOML: {exc}") from None
        elif (_SCENE_DIR / f"{name}.toml").is_file():
            with open(_SCENE_DIR / f"{name}.toml", "rb") as fh:
                raw = tomllib.load(fh)
        else:
            raise SceneError(f"unknown scene {name!r}: not a file, and the built-in scenes are "
                             + ", ".join(list_scenes()))
    for key, value in overrides.items():
        _apply_override(raw, key, value)
    return Scene.from_mapping(raw)
