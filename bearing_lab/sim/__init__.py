"""The simulator: scene -> assembly -> integrator -> Dataset.

simulate      -- run a scene, return the contract Dataset
load_scene    -- built-in name / TOML path / dict (+ --set overrides) -> Scene
list_scenes   -- built-in scenes and their descriptions
Scene         -- a validated scene (user units in .data, SI accessors)
"""
from .scene import Scene, list_scenes, load_scene
from .integrate import simulate
from . import _numba  # noqa: F401,E402  (numba's start asks for BLAS without importing scipy.linalg)
from .. import _accessor  # noqa: F401,E402  (registers da.bearing for the simulations)

__all__ = ["simulate", "load_scene", "list_scenes", "Scene"]
