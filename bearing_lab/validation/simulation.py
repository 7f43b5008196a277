"""Scenes from cases, and every simulation a validation runs: the one place that calls the simulator.

Why one place: a validation, and the defect identification built on it, simulate the
same rig many times (the declared defect, a healthy bearing, a companion recording,
candidate geometries, a finer-tolerance rerun).  They differ only in scene keys; the
scene is built here from the case, and :func:`run` is the only call into
:func:`bearing_lab.sim.simulate`, so caching or a sweep backend can be added in one spot.

The simulated signal is the Dataset's ``default_channel`` (the accelerometer signal), so
nothing here names a simulator variable.

Public API
----------
scene_mapping(case, *, healthy=False)         -- the case's scene as a mapping (base scene + case keys)
build_scene(case, *, rpm, fs, duration, healthy=False, overrides=None) -> Scene
scene_from(scene, *, rpm, fs, duration, overrides=None)  -- a named scene (e.g. a companion recording's) at a speed
run(scene, **overrides) -> xarray.Dataset    -- simulate (no progress bar)
signal(ds) -> ndarray                        -- the accelerometer signal of a simulation
numerical_error(scene, ds, *, duration)      -- peak difference against a rerun at rtol / 10
"""
from __future__ import annotations

import copy
from pathlib import Path

import numpy as np

from ..errors import SceneError, ValidationCaseError
from ..sim import load_scene, simulate

__all__ = ["scene_mapping", "build_scene", "scene_from", "run", "signal", "numerical_error", "SENSOR_OFF"]

#: the validation applies the structural path itself: the simulator's own resonator stays off
SENSOR_OFF = {"sensor.enabled": False}


def _base_mapping(case) -> dict:
    base = case.section("scene").get("base")
    if not base:
        return {"name": case.name}
    if str(base).endswith(".toml") and case.base_dir is not None:
        p = Path(str(base))
        base = str(p if p.is_absolute() else Path(str(case.base_dir)) / p)
    try:
        return copy.deepcopy(load_scene(base).data)
    except SceneError as exc:
        raise ValidationCaseError(f"validation case {case.name!r}: scene.base: {exc}") from None


def scene_mapping(case, *, healthy=False) -> dict:
    """The scene the case describes: its ``[scene] base`` (if any), then the case's bearing, load
    and defects on top, as a scene mapping (user units)."""
    raw = _base_mapping(case)
    raw["name"] = case.name if not healthy else f"{case.name} (healthy)"
    bearing = case.data.get("bearing")
    if isinstance(bearing, str):
        raw["bearing"] = bearing
    elif isinstance(bearing, dict):
        geo = {k: v for k, v in bearing.items() if k != "name"}
        raw["bearing"] = str(bearing.get("name", "custom"))
        raw["bearing_geometry"] = {**raw.get("bearing_geometry", {}), **geo}
    load = case.section("load")
    if load:
        raw["load"] = {**raw.get("load", {}), **load}
        raw["load"].setdefault("on", "inner")
    if "defect" in case.data:
        raw["defect"] = copy.deepcopy(case.data["defect"])
    if healthy:
        raw["defect"] = []
    return raw


def build_scene(case, *, rpm, fs, duration, healthy=False, overrides=None):
    """A :class:`~bearing_lab.sim.Scene` of the case at ``rpm`` r/min, sampled at ``fs`` for ``duration`` s.

    ``overrides`` are scene keys applied last (after the case's ``[scene] set``).
    """
    ov = dict(case.section("scene").get("set", {}) or {})
    ov.update({"speed_rpm": float(rpm), "output.sample_rate_hz": float(fs), "output.duration_s": float(duration)})
    ov.update(overrides or {})
    try:
        return load_scene(scene_mapping(case, healthy=healthy), **ov)
    except SceneError as exc:
        raise ValidationCaseError(f"validation case {case.name!r}: scene: {exc}") from None


def run(scene, **overrides):
    """Simulate ``scene`` (a Scene, name or path) with scene-key ``overrides``; no progress bar."""
    return simulate(scene, progress=False, **overrides)


def signal(ds) -> np.ndarray:
    """The accelerometer signal of a simulated Dataset (its ``default_channel``)."""
    return np.asarray(ds[ds.attrs["default_channel"]].values, float)


def numerical_error(scene, ds, *, duration=0.25, overrides=None) -> dict:
    """Peak difference between ``ds`` and a rerun at a tenth of its solver tolerance (first ``duration`` s).

    The difference estimates the integration error of the compared signal.
    """
    rtol = float(ds.attrs.get("solver_rtol", 1e-5))
    fs = float(ds.attrs["sampling_rate_hz"])
    fine = run(scene, duration=min(duration, ds.sizes["time"] / fs), fs=fs, rtol=rtol / 10, **(overrides or {}))
    a = signal(fine)
    b = signal(ds)[: a.size]
    d = float(np.max(np.abs(a - b)))
    pk = float(np.max(np.abs(b))) or 1.0
    return {"rtol": rtol, "rtol_check": rtol / 10, "duration_s": a.size / fs,
            "peak_difference_m_s2": d, "peak_difference_pct_of_peak": 100.0 * d / pk,
            "wall_time_fine_s": float(fine.attrs["wall_time_s"])}


def scene_from(scene, *, rpm, fs, duration, overrides=None, case_name=""):
    """A built-in scene or scene file at ``rpm``, sampled at ``fs`` for ``duration`` s (plus ``overrides``)."""
    ov = dict(overrides or {})
    ov.update({"speed_rpm": float(rpm), "output.sample_rate_hz": float(fs), "output.duration_s": float(duration)})
    try:
        return load_scene(scene, **ov)
    except SceneError as exc:
        raise ValidationCaseError(f"validation case {case_name!r}: scene {scene!r}: {exc}") from None


def model_details(ds) -> dict:
    """What the simulation that ran assumed (fidelity, contact and cage models, load path, solver)."""
    keys = ("bearing", "fidelity", "defect_contact_models", "cage_model", "load_path", "solver_method",
            "solver_rtol", "sensor_resonator", "anti_alias")
    return {k: ds.attrs.get(k) for k in keys if k in ds.attrs}
