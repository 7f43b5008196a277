"""``fidelity = "auto"`` and ``solver.method = "auto"``: model only what the scene needs.

The rules come from the work-precision study (``bearing-lab bench``, which writes
``reports/performance/auto_rules.toml``; the copy shipped here is the one measured for
this release).  Each rule is the cheapest (fidelity, method, tolerance, step ceiling)
that stayed within half of the 1 % peak-acceleration and 0.1 % period tolerance against a
converged reference on EVERY bench scene of its kind.  The promise is the whole tolerance; the
other half is room for what one run of the study does not sample (the same run perturbed at
rounding level moved a thin setting's peak error by up to 0.3 % of the peak):

- ``healthy``: no defect, or every defect misses the ball track (no defect geometry is
  built then).  The track is the one the scene runs on: the groove bottom in the planar model;
  under an axial load or preload (the 3-D model) the track at the static contact angle, where
  each race defect is met as its contact table sees it (turned across the groove by that
  angle), so a defect the displaced track leaves is missed and one it moves onto is struck;
- ``defect-slow``: a defect at shaft speeds up to the slow bench scene's (300 r/min);
- ``defect``: any other defect.

A kind may carry rules by output rate (``[[defect.by_rate]]``, from the rate study of
``bearing-lab bench``, ``auto_rate_study.csv``): a higher output rate resolves a sharper
impulse peak, which needs a more accurate integration, so the rule measured at the lowest
studied rate at or above the scene's output rate is used (a 50 kHz scene takes the 100 kHz
rule); above the highest studied rate the highest one is used and the reason says it was not
measured there.  Kinds without rate rules were measured at 20 kHz output.

The choice and its expected error go into the output's attributes.  Without a rule
for a kind the conservative default is used (multibody, dp54, rtol 1e-5).
"""
from __future__ import annotations

from functools import lru_cache
import math
from pathlib import Path
import tomllib
import warnings

import numpy as np

from ..errors import BearingLabError, SolverError
from .bearing3d import groove_offsets, load_zone_angle, needs_3d, static_3d, track_offset
from .defects.geometry import RaceGeometry
from .limits import SceneWarning

RULES_FILE = Path(__file__).with_name("auto_rules.toml")
DEFAULT = {"fidelity": "multibody", "method": "dp54", "rtol": 1e-5, "max_step_s": 2.5e-5,
           "expected_peak_error": None}
SLOW_RPM = 300.0


@lru_cache(maxsize=1)
def load_rules() -> dict:
    """The measured rules, ``{kind: rule}`` from ``auto_rules.toml`` (``{}`` when the file is absent).

    See Also
    --------
    resolve : the rule a scene gets.
    """
    if not RULES_FILE.is_file():
        return {}
    with open(RULES_FILE, "rb") as fh:
        return tomllib.load(fh)


MISS_DELTA = 20e-6  # an approach no bench scene reaches: beyond it a defect cannot be touched


def _track_3d(scene, fid):
    """(each defect as the 3-D contact track meets it, what the track is): a race defect turned across
    the groove by the static contact angle at its position, as its contact table is built
    (:func:`.bearing3d.track_offset`); a ball defect as it is."""
    try:
        with np.errstate(all="ignore"):
            st = static_3d(scene, fid)
    except (ValueError, ArithmeticError, RuntimeError) as exc:
        if isinstance(exc, BearingLabError):
            raise
        raise SolverError(f"scene {scene.name!r}: no 3-D static equilibrium found to place the contact track "
                          f"({type(exc).__name__}: {exc})") from exc
    b, lz = scene.bearing, load_zone_angle(scene)
    out, parts = [], []
    for k, d in enumerate(scene.defects):
        if d.race == "ball":
            out.append(d)
            parts.append(f"defect {k} (ball): as on the planar track")
            continue
        met, alpha = track_offset(d, st, d.race, lz + d.angle, b)
        r_g = groove_offsets(b)[0 if d.race == "inner" else 1] + b.ball_diameter / 2
        gap = max(_gap(scene, met), 0.0)
        parts.append(f"defect {k} ({d.race}): contact angle {math.degrees(alpha):.2f} deg, track "
                     f"{r_g * math.sin(alpha) * 1e3:+.3f} mm across the groove from its bottom, the defect's "
                     f"nearest point {met.min_abs_axial() * 1e3:.3f} mm from the track ({gap * 1e6:.3g} um "
                     f"from the ball: {'missed' if gap >= MISS_DELTA else 'met'} at {MISS_DELTA * 1e6:g} um)")
        out.append(met)
    return out, f"3-D contact track at the static contact angles ({fid}): " + "; ".join(parts)


def track_defects(scene, fid=None):
    """(the defects as the scene's contact track meets them, which track): the planar track (groove
    bottom) for a planar scene; for a 3-D scene (axial load or preload) the track at the static
    contact angles of fidelity ``fid`` (default: the scene's, multibody for "auto").

    See Also
    --------
    scene_kind, resolve
    """
    if not scene.defects or not needs_3d(scene):
        return scene.defects, "planar contact track (groove bottom)"
    fid = fid or (scene.fidelity if scene.fidelity != "auto" else DEFAULT["fidelity"])
    return _track_3d(scene, fid)


def scene_kind(scene, defects=None) -> str:
    """The rule kind, "healthy", "defect-slow" or "defect" (module docstring); ``defects`` as the
    contact track meets them (:func:`track_defects`; default: the scene's, on the groove bottom).

    See Also
    --------
    resolve, track_defects

    Examples
    --------
    >>> from bearing_lab.sim import load_scene
    >>> scene_kind(load_scene("paper-healthy")), scene_kind(load_scene("paper-slot", speed_rpm=300))
    ('healthy', 'defect-slow')
    """
    defects = scene.defects if defects is None else defects
    if all(d.misses_track(scene.bearing, MISS_DELTA, clearance=scene.clearance) for d in defects):
        return "healthy"
    return "defect-slow" if scene.nominal_rpm <= SLOW_RPM else "defect"


def rate_rule(rule: dict, fs: float) -> tuple[dict, str]:
    """(the rule for output rate ``fs`` Hz, how it was chosen) from a kind's rule and its
    ``by_rate`` bands; the kind's rule itself when it has none.  Above the highest studied rate the
    highest band is used and the text says that rate was not studied.

    See Also
    --------
    resolve

    Examples
    --------
    >>> rule = {"method": "dp54", "by_rate": [{"max_rate_hz": 20e3, "rtol": 1e-4},
    ...                                       {"max_rate_hz": 100e3, "rtol": 1e-5}]}
    >>> rate_rule(rule, 50e3)
    ({'max_rate_hz': 100000.0, 'rtol': 1e-05}, 'measured at 100 kHz output (rule for up to it)')
    >>> rate_rule(rule, 200e3)[1]
    'measured at up to 100 kHz output only: the 200 kHz asked for was not studied'
    """
    bands = sorted(rule.get("by_rate", ()), key=lambda b: b["max_rate_hz"])
    if not bands:
        return rule, "measured at 20 kHz output"
    for b in bands:
        if fs <= b["max_rate_hz"] * (1 + 1e-9):
            return b, f"measured at {b['max_rate_hz'] / 1e3:g} kHz output (rule for up to it)"
    b = bands[-1]
    return b, (f"measured at up to {b['max_rate_hz'] / 1e3:g} kHz output only: the {fs / 1e3:g} kHz asked for "
               "was not studied")


#: the setting a defect the track only grazes takes (the defect rules' tolerances miss its shallow impacts),
#: measured by ``benchmarks/grazed_peak.py`` (benchmarks/results/grazed_peak.txt): five grazed scenes (cwru-or007-6
#: at 300 and 125 N axial, cwru-or007-3 and cwru-or021-6 at 250 N, cwru-ir007 at 125 N; 0.3 s), each run
#: unperturbed and with its tables or start changed by 1e-12 (9 runs), against dp54 rtol 1e-11.  The converged
#: peak is well-posed: at rtol 1e-10 the 9 runs agree to 3e-5.  dp54 rtol 1e-6 (the rule before) read it 0.3-1.7 %
#: off on cwru-or007-6 at 300 N and up to 3.4 % on cwru-or007-3, so whether it held 1 % was a matter of rounding;
#: rtol 1e-7 up to 0.33 % and 0.46 % (and 4.2 % in the impulse strength of cwru-or007-3); rtol 1e-8 within
#: 0.06 % in peak, impulse strength, RMS and the 99.9th percentile on every scene, at 1.4-1.9 times the CPU time
#: of rtol 1e-6 (0.08-0.10 CPU s per 0.3 s run); bs32 rtol 1e-5 read the peak at 1.63 and 10 times the converged one
GRAZED = {"method": "dp54", "rtol": 1e-8}
GRAZED_PEAK_ERROR = 6e-4


def resolve(scene) -> dict:
    """The settings auto picks for ``scene``: fidelity, method, rtol, max_step_s, kind, reason, track.

    The kind is decided on the contact track the scene runs on (:func:`track_defects`); with
    ``fidelity = "auto"`` the 3-D track is that of the rule's fidelity (decided again on it if the
    rule's fidelity is not the one first assumed).  A defect the track only grazes takes
    :data:`GRAZED` (dp54, rtol 1e-8), said in the reason; a scene that sets its own solver method then
    gets a ``SceneWarning`` naming that setting.

    Parameters
    ----------
    scene : Scene

    Returns
    -------
    dict
        ``fidelity``, ``method``, ``rtol``, ``max_step_s``, ``expected_peak_error``, ``kind``,
        ``reason`` (the rule and how it was measured) and ``track``.

    See Also
    --------
    bearing_lab.sim.simulate : uses it for ``"auto"`` settings and records it in the attributes.
    scene_kind, rate_rule

    Examples
    --------
    >>> from bearing_lab.sim import load_scene
    >>> choice = resolve(load_scene("paper-healthy"))
    >>> choice["kind"], choice["track"]
    ('healthy', 'planar contact track (groove bottom)')
    """
    defects, track = track_defects(scene)
    kind = scene_kind(scene, defects)
    rules = load_rules()
    rule = rules.get(kind) or (rules.get("defect") if kind == "defect-slow" else None)
    fid = (rule or DEFAULT).get("fidelity", DEFAULT["fidelity"])
    if scene.fidelity == "auto" and fid != DEFAULT["fidelity"] and track.startswith("3-D"):
        defects, track = track_defects(scene, fid)
        kind = scene_kind(scene, defects)
        rule = rules.get(kind) or (rules.get("defect") if kind == "defect-slow" else None)
    out = dict(DEFAULT)
    if rule:
        rule, how = rate_rule(rule, float(scene.fs_out))
        out.update({k: rule[k] for k in ("fidelity", "method", "rtol", "max_step_s", "step_s") if k in rule})
        out["expected_peak_error"] = rule.get("expected_peak_error")
        out["reason"] = (f"auto rule '{kind}' from the work-precision study: cheapest setting within half "
                         "of the 1 % peak-acceleration and 0.1 % period tolerance (the rest a margin for "
                         f"rounding-level spread) on {rule.get('scenes')}, {how}")
    else:
        out["reason"] = f"no measured rule for '{kind}': conservative default"
    grazed = _grazed(scene, defects) if kind.startswith("defect") else []
    if grazed:
        said = ", ".join(f"defect {k} is only grazed ({gap * 1e6:.3g} um of approach before the ball reaches it)"
                         for k, gap in grazed)
        out.update(GRAZED)
        setting = f"solver.method = '{GRAZED['method']}', solver.rtol = {GRAZED['rtol']:g}"
        out["expected_peak_error"] = GRAZED_PEAK_ERROR
        out["reason"] += (f"; {said}: the defect rules do not hold there (a grazed pit's peak came out at 1.63 "
                          "times the converged one at bs32 rtol 1e-5, and up to 3.4 % off at dp54 rtol 1e-6), so the "
                          f"grazed-defect setting is taken: {setting} (peak within {GRAZED_PEAK_ERROR * 100:.2g} % "
                          "of a converged run on every grazed scene measured, under rounding-level changes of the "
                          "tables and start)")
        solver = scene.data["solver"]
        tight = solver["method"] == GRAZED["method"] and (solver["rtol"] or 1.0) <= GRAZED["rtol"]
        if solver["method"] != "auto" and not tight:
            warnings.warn(f"scene {scene.name!r}: {said}: the solver set by the scene may miss the impacts (the "
                          f"automatic choice for a grazed defect is {setting})",
                          SceneWarning, stacklevel=3)
    out["kind"] = kind
    out["track"] = track
    return out


def _gap(scene, defect) -> float:
    """The approach (m) a ball on the track needs before it reaches the race defect's nearest point."""
    return float(RaceGeometry.from_bearing(scene.bearing, defect.race, clearance=scene.clearance)
                 .approach(0.0, defect.min_abs_axial()))


#: an approach below this is float noise, not a gap: the track runs over the defect
GRAZE_MIN = 1e-8


def _grazed(scene, defects) -> list:
    """[(index, gap)]: the race defects the track meets only off its centre line, ``gap`` (m) the approach
    the ball needs before it reaches the defect's nearest point (0 < gap < :data:`MISS_DELTA`)."""
    out = []
    for k, d in enumerate(defects):
        if d.race == "ball":
            continue
        gap = _gap(scene, d)
        if GRAZE_MIN < gap < MISS_DELTA:
            out.append((k, gap))
    return out


def warn_off_track(scene) -> None:
    """A defect the balls never touch makes a healthy bearing: say so (a 5 for a 0.5?).  Judged on
    the track the scene runs on (:func:`track_defects`: under an axial load, the 3-D track at
    the static contact angle; a 3-D start that is not found is reported by the run, not here)."""
    try:
        defects, track = track_defects(scene)
    except BearingLabError:
        return
    for i, defect in enumerate(defects):
        if not defect.misses_track(scene.bearing, MISS_DELTA, clearance=scene.clearance):
            continue
        where = "defect" if len(scene.defects) == 1 else f"defect[{i}]"
        raw = scene.data["defect"][i]
        on = "" if track.startswith("planar") else " at the contact angle of the axial load"
        warnings.warn(f"{where} misses the ball track{on}: no part of it comes within reach of the "
                      f"balls (offset_mm={raw.get('offset_mm', 0)}, width_mm="
                      f"{raw.get('width_mm', '-')}, skew_deg={raw.get('skew_deg', 0)}), so "
                      "this simulates a healthy bearing; check defect.offset_mm",
                      SceneWarning, stacklevel=4)
