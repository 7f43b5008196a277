"""numba, without importing scipy.linalg before this process uses it.

Why: the first call of any compiled function (a cached one included) makes numba set up its
CPU target, which imports ``numba.np.arraymath``, whose module level asks "is there a BLAS?"
(for ``np.dot``) by ``import scipy.linalg.cython_blas``.  Python imports the package first:
all of ``scipy.linalg`` and, through scipy's array-API layer, ``numpy.testing`` and
``numpy.f2py``: 0.13 s of CPU in every process that simulates, for an answer the extension
module alone gives (``scipy.linalg.cython_blas`` loads in 2 ms without its package; 0.015 s with
scipy's top package and the ``scipy.__config__`` numba reads).

Importing this module wraps numba's set-up (``CPUContext.load_additional_registries``) once:
during it, the extension module is loaded on its own and stands in ``sys.modules`` for numba's
question; afterwards it is taken out again, so a later ``import scipy.linalg`` imports the package
as always (and finds the same extension module object, ``scipy.linalg.cython_blas`` set on the
package).  A compiled function that calls BLAS imports it when it runs, as before.  When scipy.linalg
is already imported, when the extension cannot be found, or on a numba without that method,
nothing changes (scipy.linalg imported as before: slower, never wrong).
``tests/test_imports.py`` checks that a simulation leaves scipy.linalg out and that numba's
``np.dot`` and scipy.linalg work afterwards.
"""
from __future__ import annotations

import contextlib
import importlib.machinery
import importlib.util
import os
import sys

try:
    from numba.core.cpu import CPUContext
except ImportError:  # a numba that moved its CPU target: nothing to wrap
    CPUContext = None

__all__: list[str] = []

_BLAS = "scipy.linalg.cython_blas"


def _blas_alone():
    """scipy.linalg.cython_blas loaded without its package, or None (then numba imports it)."""
    try:
        spec = importlib.util.find_spec("scipy")
        roots = list(spec.submodule_search_locations or []) if spec else []
        for root in roots:
            finder = importlib.machinery.FileFinder(
                os.path.join(root, "linalg"),
                (importlib.machinery.ExtensionFileLoader, importlib.machinery.EXTENSION_SUFFIXES))
            blas = finder.find_spec(_BLAS)
            if blas is not None:
                module = importlib.util.module_from_spec(blas)
                blas.loader.exec_module(module)
                return module
    except (ImportError, OSError, ValueError):
        pass
    return None


@contextlib.contextmanager
def _blas_without_scipy_linalg():
    if "scipy.linalg" in sys.modules or _BLAS in sys.modules:
        yield
        return
    blas = _blas_alone()
    if blas is not None:
        sys.modules[_BLAS] = blas
    try:
        yield
    finally:
        if blas is not None and sys.modules.get(_BLAS) is blas:
            linalg = sys.modules.get("scipy.linalg")
            if linalg is None:
                del sys.modules[_BLAS]              # imported again, as a submodule, when asked for
            elif not hasattr(linalg, "cython_blas"):
                linalg.cython_blas = blas           # scipy.linalg came meanwhile: its attribute


def _install():
    original = getattr(CPUContext, "load_additional_registries", None)
    if original is None:
        return
    if hasattr(original, "__wrapped__"):
        return

    def load_additional_registries(self):
        if "numba.np.arraymath" in sys.modules:    # the BLAS question asked already
            return original(self)
        with _blas_without_scipy_linalg():
            return original(self)
    load_additional_registries.__wrapped__ = original
    load_additional_registries.__doc__ = original.__doc__
    CPUContext.load_additional_registries = load_additional_registries


_install()
