"""bearing_lab: import rig recordings, simulate defective ball bearings, analyse
both the same way, and write validation reports.

Public API
----------
``__all__`` holds every name below; each is served lazily from the module named::

    simulate, load_scene, Scene, list_scenes  -- scene -> xarray.Dataset (bearing_lab.sim)
    open_recording, list_engines              -- file -> xarray.Dataset, the readers (bearing_lab.io)
    to_netcdf, to_uff58b                      -- write a Dataset (bearing_lab.io)
    analyze                                   -- signal -> speed, envelope spectrum, diagnosis (bearing_lab.analysis)
    get_bearing, BearingGeometry, CATALOG     -- catalog geometry and kinematic fault frequencies (bearing_lab.bearings)
    check_dataset                             -- the Dataset contract of recordings and simulations (bearing_lab.schema)
    run_sweep                                 -- many scenes on Dask (bearing_lab.sweep)
    identify                                  -- defect geometry from a recording (bearing_lab.validation.identify)
    BearingLabError, SceneError, RecordingError, AnalysisError, SolverError, ValidationCaseError
                                              -- the error types (bearing_lab.errors)
    __version__

Subpackages (``dir(bearing_lab)`` lists them, ``import *`` does not): analysis, datasets, io,
report, sim, studies, sweep, validation.

Imports are lazy (SPEC 1, ``lazy_loader.attach``): ``import bearing_lab`` loads no
numpy, xarray, scipy, numba or matplotlib; a name above, or a subpackage
(``bearing_lab.analysis`` ...), is imported the first time it is used.  Each
subpackage face does the same, so a command pays only for the libraries it uses
(``docs/architecture.md``, "Imports").  ``EAGER_IMPORT=1`` resolves every lazy
name at import (a check that they all exist).
"""
import lazy_loader as _lazy

from ._version import __version__

_SUBPACKAGES = ["analysis", "datasets", "io", "report", "sim", "studies", "sweep", "validation"]
#: module -> the public names it serves
_PUBLIC = {
    "errors": ["AnalysisError", "BearingLabError", "RecordingError", "SceneError", "SolverError",
               "ValidationCaseError"],
    "bearings": ["get_bearing", "BearingGeometry", "CATALOG"],
    "schema": ["check_dataset"],
    "sim": ["simulate", "load_scene", "Scene", "list_scenes"],
    "io": ["open_recording", "list_engines", "to_netcdf", "to_uff58b"],
    "analysis": ["analyze"],
    "sweep": ["run_sweep"],
    "validation.identify": ["identify"],
}
__getattr__, _, _ = _lazy.attach(__name__, submodules=_SUBPACKAGES, submod_attrs=_PUBLIC)
# ``from bearing_lab import *`` gives every public name, not the subpackages; dir() lists both
__all__ = [name for names in _PUBLIC.values() for name in names] + ["__version__"]


def __dir__():
    return sorted(__all__ + _SUBPACKAGES)
