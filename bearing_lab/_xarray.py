"""xarray, without importing dask before this process uses dask.

Why: with dask installed (the ``sweep`` and ``test`` extras), xarray imports ``dask.array``
(0.4 s of CPU, scipy.fft and pandas' friends with it) the first time it makes a Variable,
only to ask "is this a dask array?", ``dask.base`` (0.1-0.17 s, dask's core) for an index
coordinate, only to ask "is this a dask collection?", and ``dask.distributed`` (0.2 s) each
time it writes a netCDF file, only to ask "which dask scheduler runs?".  Before the process
has imported ``dask.array`` no dask array can exist; dask's own collection test only asks the
object for a ``__dask_graph__()`` that is not None, which needs no dask; and before the process
has imported ``distributed`` (with no scheduler set in dask's config) no dask scheduler runs,
so the three answers are known without the imports.  Importing this module teaches xarray
those answers; the moment the process imports dask itself, xarray asks dask.  ``bearing_lab._accessor``
imports it, so every path that makes a Dataset (``simulate``, ``open_recording``, ``analysis``) has it.

The hooks use xarray internals (``namedarray.pycompat._cached_duck_array_modules``,
``namedarray.utils.is_dask_collection``, ``backends.locks.get_dask_scheduler``); on an xarray without
them this module does nothing and xarray imports dask itself (slower, never wrong).  ``tests/test_imports.py``
checks both that dask stays out and that chunked Datasets still write through dask.
"""
from __future__ import annotations

import sys

import xarray as xr

__all__ = ["xr"]


class _DaskArrayOnceImported:
    """xarray's record of dask as a duck-array library, made when dask.array is imported."""

    def __init__(self, pycompat):
        self._pycompat = pycompat

    def _real(self):
        real = self._pycompat.DuckArrayModule("dask")
        self._pycompat._cached_duck_array_modules["dask"] = real
        return real

    @property
    def type(self):
        if "dask.array" not in sys.modules:
            return ()  # isinstance(x, ()) is False: no dask array exists yet
        return self._real().type

    def __getattr__(self, name):  # module, version, available: ask dask
        return getattr(self._real(), name)


def _install_duck_array_hook():
    try:
        from xarray.namedarray import pycompat
        cache = pycompat._cached_duck_array_modules
        pycompat.DuckArrayModule  # noqa: B018 - present on the xarray versions this knows
    except (ImportError, AttributeError):
        return
    if "dask" not in cache and "dask.array" not in sys.modules:
        cache["dask"] = _DaskArrayOnceImported(pycompat)


def _no_scheduler_yet(original):
    def get_dask_scheduler(get=None, collection=None):
        dask = sys.modules.get("dask")
        if (get is None and collection is None and "distributed" not in sys.modules
                and (dask is None or (dask.config.get("scheduler", None) is None
                                      and dask.config.get("get", None) is None))):
            return None  # what dask would answer after importing distributed to find no client
        return original(get, collection)
    get_dask_scheduler.__wrapped__ = original
    get_dask_scheduler.__doc__ = original.__doc__
    return get_dask_scheduler


def _install_scheduler_hook():
    try:
        from xarray.backends import locks, writers
        original = locks.get_dask_scheduler
    except (ImportError, AttributeError):
        return
    if hasattr(original, "__wrapped__"):
        return
    hooked = _no_scheduler_yet(original)
    for mod in (locks, writers):
        if getattr(mod, "get_dask_scheduler", None) is original:
            mod.get_dask_scheduler = hooked


def _no_dask_yet(original):
    def is_dask_collection(x):
        if "dask" in sys.modules:
            return original(x)
        # dask.base.is_dask_collection, which needs nothing of dask: a collection is an object
        # (not a class) whose __dask_graph__() gives a graph
        if isinstance(x, type) or not hasattr(x, "__dask_graph__"):
            return False
        try:
            return x.__dask_graph__() is not None
        except (AttributeError, TypeError):
            return False
    is_dask_collection.__wrapped__ = original
    is_dask_collection.__doc__ = original.__doc__
    return is_dask_collection


def _install_collection_hook():
    try:
        from xarray.namedarray import utils
        original = utils.is_dask_collection
    except (ImportError, AttributeError):
        return
    if hasattr(original, "__wrapped__"):
        return
    hooked = _no_dask_yet(original)
    # every xarray module holding the function by name (xarray.core.utils re-exports it)
    for name, mod in list(sys.modules.items()):
        if name.startswith("xarray.") and getattr(mod, "is_dask_collection", None) is original:
            mod.is_dask_collection = hooked


_install_duck_array_hook()
_install_collection_hook()
_install_scheduler_hook()
