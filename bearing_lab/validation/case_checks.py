"""Section checks of the two case kinds (recording, paper), run by :func:`~bearing_lab.validation.load.load_case`.

Every value is checked here, once, with one wording: ``validation case 'NAME':
section.key = value: what is wrong``.  A scene the case describes is built once with a
placeholder speed, so an invalid scene key fails at load time, before anything runs.
"""
from __future__ import annotations

from functools import partial

import math
import tomllib
from pathlib import Path

from ..errors import SceneError, ValidationCaseError, check_choice
from ..sim import load_scene
from . import simulation
from .case import (CASE_KEYS, case_error, check_keys, check_number, check_speed, parse_tolerances,
                   recording_spec)

__all__ = ["check_recording", "check_paper", "PAPER_QUANTITIES", "HEALTHY_QUANTITIES"]

PAPER_QUANTITIES = ("shaft_hz", "bpfo", "bpfi", "excitation_period", "peak_model", "offset_ratio")
HEALTHY_QUANTITIES = ("shaft_hz", "bpfo", "bpfi", "rms_model", "rms_path", "kurtosis_model", "kurtosis_path",
                      "crest_factor_model", "crest_factor_path")


def _bearing(case):
    b = case.data.get("bearing")
    if b is None or isinstance(b, str):
        return
    check_keys(case.name, "bearing", b, CASE_KEYS["bearing"])
    for k, v in b.items():
        if k == "name":
            continue
        check_number(case.name, f"bearing.{k}", v, positive=True)


def _load_and_defects(case):
    load = case.data.get("load", {})
    check_keys(case.name, "load", load, CASE_KEYS["load"])
    if "radial_n" in load:
        check_number(case.name, "load.radial_n", load["radial_n"], lo=0.0, hi=1e7)
    check_choice(load.get("on", "inner"), ("inner", "outer"), "load.on", partial(case_error, case.name))
    defects = case.data.get("defect", [])
    if not isinstance(defects, list):
        raise case_error(case.name, "defects are [[defect]] tables (an array of tables)")
    for i, d in enumerate(defects):
        check_keys(case.name, f"defect[{i}]", d, CASE_KEYS["defect"])
    base = case.section("scene").get("base")
    if not base:
        if "bearing" not in case.data:
            raise case_error(case.name, "give bearing (a catalog name or a [bearing] table), or a [scene] base")
        if "radial_n" not in load:
            raise case_error(case.name, "give [load] radial_n (N), or a [scene] base that has one")


def _bounds_or_values(case, sp, key, method, n):
    v = sp.get(key)
    if v is None:
        return
    where = f"structural_path.{key}"
    if method == "fit":
        if not (isinstance(v, list) and len(v) == 2):
            raise case_error(case.name, f"{where} = {v!r}: with method = \"fit\" give the bounds [low, high]")
        lo, hi = (check_number(case.name, where, x, positive=True) for x in v)
        if not lo < hi:
            raise case_error(case.name, f"{where} = {v!r}: the low bound must be below the high one")
    else:
        vals = v if isinstance(v, list) else [v]
        if key != "gain" and len(vals) != n:
            raise case_error(case.name, f"{where} = {v!r}: give {n} value(s), one per resonance")
        for x in vals:
            check_number(case.name, where, x, positive=True)


def _structural_path(case):
    sp = case.data.get("structural_path", {})
    check_keys(case.name, "structural_path", sp, CASE_KEYS["structural_path"])
    method = sp.get("method", "fit")
    check_choice(method, ("fit", "fixed", "none"), "structural_path.method", partial(case_error, case.name))
    n = check_choice(sp.get("resonances", 1), (1, 2), "structural_path.resonances", partial(case_error, case.name))
    if sp.get("from_case") and sp.get("file"):
        raise case_error(case.name, "structural_path: give from_case or file, not both")
    if (sp.get("from_case") or sp.get("file")) and method != "fit":
        raise case_error(case.name, "structural_path: from_case and file take a path identified elsewhere; "
                              "leave method at \"fit\"")
    if sp.get("from_case") == case.name:
        raise case_error(case.name, "structural_path.from_case names this case itself")
    given = [k for k in ("frequency_hz", "damping_ratio", "gain") if k in sp]
    if method == "none" and given:
        raise case_error(case.name, f"structural_path: method = \"none\" compares the bare model and takes no "
                              f"{', '.join(given)}; remove {'it' if len(given) == 1 else 'them'} (or use method = "
                              "\"fit\" with bounds, \"fixed\" with values)")
    if method == "fixed":
        for key in ("frequency_hz", "damping_ratio", "gain"):
            if key not in sp:
                raise case_error(case.name, f"structural_path.method = \"fixed\" needs {key}")
    for key in ("frequency_hz", "damping_ratio", "gain"):
        _bounds_or_values(case, sp, key, method, n)


def _background(case):
    bg = case.data.get("background", {})
    check_keys(case.name, "background", bg, CASE_KEYS["background"])
    if not isinstance(bg.get("enabled", True), bool):
        raise case_error(case.name, f"background.enabled = {bg['enabled']!r} must be true or false")
    src = bg.get("source", "auto")
    check_choice(src, ("auto", "reference", "recording"), "background.source", partial(case_error, case.name))
    if src == "reference" and "reference" not in case.data:
        raise case_error(case.name, "background.source = \"reference\" needs a [reference] recording")
    for key, lo, hi in (("max_tones", 0, 200), ("tone_snr_db", 3, 60), ("seed", 0, 2 ** 32)):
        if key in bg:
            check_number(case.name, f"background.{key}", bg[key], lo=lo, hi=hi)


def _sections(case):
    ne = case.data.get("numerical_error", {})
    check_keys(case.name, "numerical_error", ne, CASE_KEYS["numerical_error"])
    if "duration_s" in ne:
        check_number(case.name, "numerical_error.duration_s", ne["duration_s"], positive=True)
    sc = case.data.get("scene", {})
    check_keys(case.name, "scene", sc, CASE_KEYS["scene"])
    if not isinstance(sc.get("set", {}), dict):
        raise case_error(case.name, "scene.set must be a table of scene keys")
    ratio = case.data.get("ratio")
    if ratio is not None:
        check_keys(case.name, "ratio", ratio, CASE_KEYS["ratio"])
        if not ratio.get("recording") or not ratio.get("scene"):
            raise case_error(case.name, "[ratio] needs recording and scene")
        check_speed(case.name, "ratio.speed", ratio.get("speed", "file"))


def _scenes(case):
    rpm = case.speed if isinstance(case.speed, float) else 1800.0
    simulation.build_scene(case, rpm=rpm, fs=20000.0, duration=0.1)
    ratio = case.section("ratio")
    if ratio:
        scene = str(ratio["scene"])
        if scene.endswith(".toml") and case.base_dir is not None and not Path(scene).is_absolute():
            scene = str(Path(str(case.base_dir)) / scene)
            case.data["ratio"]["scene"] = scene
        try:
            load_scene(scene, **(ratio.get("set") or {}))
        except SceneError as exc:
            raise case_error(case.name, f"ratio.scene: {exc}") from None


def check_recording(case):
    """Check a recording case in place (sets recording, reference, speed, tolerances)."""
    name = case.name
    if "recording" not in case.data:
        raise case_error(name, "needs a [recording] table (file or name, channel, ...)")
    case.recording = recording_spec(name, "recording", case.data["recording"], case.base_dir)
    case.speed = check_speed(name, "speed", case.data.get("speed", "file"))
    if "reference" in case.data:
        ref = dict(case.data["reference"])
        tol = ref.pop("tolerances", None)
        allowed = {k: v for k, v in CASE_KEYS["reference"].items() if k != "tolerances"}
        case.reference = recording_spec(name, "reference", ref, case.base_dir, allowed=allowed)
        case.reference_tolerances = parse_tolerances(name, tol if tol is not None else {"shaft_hz": {}},
                                                where="reference.tolerances", allowed=HEALTHY_QUANTITIES)
    _bearing(case)
    _load_and_defects(case)
    _structural_path(case)
    _background(case)
    _sections(case)
    case.tolerances = parse_tolerances(name, case.data.get("tolerances"))
    if "impulse_strength_ratio" in case.tolerances and "ratio" not in case.data:
        raise case_error(name, "tolerances.impulse_strength_ratio needs a [ratio] table (the companion recording)")
    _scenes(case)


def check_paper(case):
    """Check a paper case in place (runs, reference figures, tolerances)."""
    name = case.name
    runs = case.data.get("run")
    if not isinstance(runs, list) or not runs:
        raise case_error(name, "a paper case needs [[run]] tables (label, scene)")
    for i, r in enumerate(runs):
        check_keys(name, f"run[{i}]", r, CASE_KEYS["run"])
        if "label" not in r or "scene" not in r:
            raise case_error(name, f"run[{i}] needs a label and a scene")
        try:
            load_scene(r["scene"], **(r.get("set") or {}))
        except SceneError as exc:
            raise case_error(name, f"run[{i}].scene: {exc}") from None
    check_keys(name, "studies", case.data.get("studies", {}), CASE_KEYS["studies"])
    ref = str(case.data.get("reference", "paper_reference.toml"))
    target = case.base_dir.joinpath(ref) if case.base_dir is not None else Path(ref)
    try:
        case.data["_reference_text"] = target.read_text(encoding="utf-8")
        case.data["_reference_data"] = tomllib.loads(case.data["_reference_text"])
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise case_error(name, f"reference data {ref!r} cannot be read ({exc})") from None
    labels = [r["label"] for r in runs]
    allowed = list(PAPER_QUANTITIES) + [f"{lb}.{q}" for lb in labels for q in PAPER_QUANTITIES if q != "offset_ratio"]
    raw = case.data.get("tolerances")
    # "<run label>.<quantity>" overrides a quantity's tolerance for one run; its default is the plain quantity's
    defaults = {k: raw[k.split(".", 1)[1]] for k in (raw or {}) if "." in k and k.split(".", 1)[1] in (raw or {})}
    merged = {k: ({**defaults.get(k, {}), **v} if isinstance(v, dict) else v) for k, v in (raw or {}).items()}
    case.tolerances = parse_tolerances(name, merged, allowed=allowed)
    if not math.isfinite(float(case.data["_reference_data"].get("speed_rpm", float("nan")))):
        raise ValidationCaseError(f"validation case {name!r}: reference data {ref!r} has no speed_rpm")
