"""The compiled loop a scene runs: one copy per kind of scene, compiled when a scene of that kind first runs.

Why: :func:`._kernels.rhs` serves every kind of scene (multibody balls in a kinematic or a
dynamic cage, massless balls, the 3-D bearing of either) behind flags of the parameter vector,
and numba compiles everything a function can reach, so the first simulation of a fresh install
compiled all five ball models (each inlined into the right-hand side) for a scene that runs one
of them: 15 of its 18 CPU s (paper-O1).  Here each kind gets its own copy of ``rhs`` (the same
bytecode, compiled and cached under its own name, ``rhs__kinematic`` ...) in which the ball models
of the other kinds are stubs, and its own copy of the loops that call it
(:func:`._stepper.integrate`, :func:`._stepper.loads_at`); ``simulate`` also fixes the
integration method of its loop (the stages of the other methods are not compiled).  The
kernels' source is not touched: a copy is the original function object's code with other
globals.

A stub returns NaN (and the 3-D stub writes NaN into the derivative): a copy handed a scene of
another kind would stop the integration with a non-finite state (status 1), never return
numbers.  :func:`kind_of` reads the flags ``rhs`` branches on, so it does not happen.

Changing ``_kernels``: a ball model whose returned values change in number needs its entry in
:data:`BALL_MODELS` (the copies then fail to compile, loudly); a new ball model is compiled into
every copy until it gets its entries here (correct, only slower to compile); a new flag that
selects a model needs :func:`kind_of` to read it.  ``tests/sim/test_variants.py`` compares every
kind with the full kernel bit for bit.
"""
from __future__ import annotations

import inspect
import math
import types

from numba import njit

from . import _kernels  # the global of _stepper.py a per-kind copy rebinds
from . import _loopargs
from . import _stepper

#: the ball models of ``rhs`` and ``_rhs_3d``, with the number of values each returns
BALL_MODELS = {"_balls_kinematic": 4, "_balls_quasi_static": 4, "_balls_dynamic": 5,
               "_balls_kinematic_3d": 6, "_balls_quasi_static_3d": 6}
#: kind of scene -> the ball model it runs (3-D kinds run it inside ``_rhs_3d``)
KINDS = {"kinematic": "_balls_kinematic", "quasi_static": "_balls_quasi_static", "dynamic": "_balls_dynamic",
         "3d_kinematic": "_balls_kinematic_3d", "3d_quasi_static": "_balls_quasi_static_3d"}
METHOD_NAMES = ("dp54", "bs32", "rk4")
_LOADED: dict = {}
_MODULES: dict = {}


def kind_of(p) -> str:
    """The kind of scene parameter vector ``p`` describes (the flags ``_kernels.rhs`` branches on)."""
    qs = p[_kernels.P_FID] > 0.5
    if p[_kernels.P_3D] > 0.5:
        return "3d_quasi_static" if qs else "3d_kinematic"
    if qs:
        return "quasi_static"
    return "dynamic" if p[_kernels.P_CAGE] > 0.5 else "kinematic"


def _stub(name):
    """A compiled stand-in for ``_kernels.<name>`` with its parameters, returning NaN."""
    params = list(inspect.signature(getattr(_kernels, name).py_func).parameters)
    if name == "_rhs_3d":
        body = "    dy[0] = math.nan\n"
    else:
        body = f"    return {', '.join(['math.nan'] * BALL_MODELS[name])}\n"
    ns = {"math": math}
    exec(f"def {name}__stub({', '.join(params)}):\n{body}", ns)  # noqa: S102 (source built above)
    return njit(inline="always")(ns[f"{name}__stub"])


def _copy(dispatcher, qualname, *, cache, **glb):
    """``dispatcher``'s function compiled anew with some of its globals replaced."""
    f = dispatcher.py_func
    g = dict(f.__globals__)
    g.update(glb)
    nf = types.FunctionType(f.__code__, g, f.__name__, f.__defaults__, f.__closure__)
    nf.__qualname__ = qualname
    nf.__module__ = f.__module__
    opts = {k: v for k, v in dispatcher.targetoptions.items() if k != "nopython"}
    return njit(cache=cache, **opts)(nf)


def _drop_stale(fns):
    """These copies also depend on ``_kernels.py``, ``_stepper.py``, ``_loopargs.py`` (their
    arguments' layout) and this file."""
    _stepper.drop_stale_machine_code(fns, (_kernels.__file__, _stepper.__file__, _loopargs.__file__, __file__))


def _stages_of(method):
    """The stage input and step finish of ``_stepper`` with the method fixed (a compile-time constant)."""
    @njit(inline="always")
    def stage_input(m, st, y, k, h, ytmp):
        _stepper._stage_input(method, st, y, k, h, ytmp)

    @njit(inline="always")
    def finish(m, y, k, h, ynew, err):
        _stepper._finish(method, y, k, h, ynew, err)
    return {"_stage_input": stage_input, "_finish": finish}


def kernels(kind, method=None):
    """Namespace with ``rhs``, ``integrate`` and ``loads_at`` for scenes of ``kind`` (see
    :data:`KINDS`).  With ``method`` (0 dp54, 1 bs32, 2 rk4) the loop compiles that method's
    stages only (0.7 CPU s less to compile) and must be called with it; without, every method."""
    key = (kind, method)
    if key in _LOADED:
        return _LOADED[key]
    if kind not in _MODULES:
        live = KINDS[kind]
        stubs = {name: _stub(name) for name in BALL_MODELS if name != live}
        if kind.startswith("3d"):
            rhs3d = _copy(_kernels._rhs_3d, f"_rhs_3d__{kind}", cache=False, **stubs)
            rhs = _copy(_kernels.rhs, f"rhs__{kind}", cache=True, _rhs_3d=rhs3d, **stubs)
        else:
            rhs = _copy(_kernels.rhs, f"rhs__{kind}", cache=True, _rhs_3d=_stub("_rhs_3d"), **stubs)
        mod = types.ModuleType(_kernels.__name__)
        mod.__dict__.update(_kernels.__dict__)
        mod.rhs = rhs
        loads = _copy(_stepper.loads_at, f"loads_at__{kind}", cache=True, _kernels=mod)
        _drop_stale([rhs, loads])
        _MODULES[kind] = (mod, loads)
    mod, loads = _MODULES[kind]
    if method is None:
        integ = _copy(_stepper.integrate, f"integrate__{kind}", cache=True, _kernels=mod)
    else:
        integ = _copy(_stepper.integrate, f"integrate__{kind}__{METHOD_NAMES[method]}", cache=True, _kernels=mod,
                      **_stages_of(int(method)))
    _drop_stale([integ])
    _LOADED[key] = types.SimpleNamespace(kind=kind, method=method, rhs=mod.rhs, integrate=integ, loads_at=loads)
    return _LOADED[key]
