"""The per-kind compiled copies of the right-hand side and the loop (bearing_lab/sim/_variants.py)
compute what the full kernel computes, stop on a scene of another kind, and a simulation compiles
only its own kind."""
import json
import subprocess
import sys

import numpy as np
import pytest

from bearing_lab.sim import _kernels as K, _variants as V
from bearing_lab.sim.assembly import assemble
from bearing_lab.sim.integrate import _KIND_SCENES, METHODS, _run
from bearing_lab.sim.scene import load_scene


def _asm(kind):
    sc = load_scene({"output": {"duration_s": 1e-3, "settle_s": 0.0}, **_KIND_SCENES[kind]})
    return assemble(sc, fidelity=sc.data["fidelity"].replace("auto", "multibody"))


def _eval(rhs, asm, t=1.3e-3):
    y = asm.y0.copy()
    y[:8] += 1e-7 * np.arange(1, 9)  # off the equilibrium, rings moving
    dy, fi, fo = np.zeros_like(y), np.zeros(asm.n_balls), np.zeros(asm.n_balls)
    rhs(t, y, asm.model._replace(hbuf=asm.hbuf.copy(), gbuf=asm.gbuf.copy()), dy, fi, fo)
    return dy, fi, fo


@pytest.mark.parametrize("kind", list(V.KINDS))
def test_each_kind_is_the_full_kernel_bit_for_bit(kind):
    asm = _asm(kind)
    assert V.kind_of(asm.p) == kind
    for a, b in zip(_eval(V.kernels(kind).rhs, asm), _eval(K.rhs, asm)):
        np.testing.assert_array_equal(a, b)
    assert np.any(_eval(K.rhs, asm)[1] != 0)  # balls carry load: the live branch ran


def test_a_copy_handed_another_kind_gives_nan_not_numbers():
    asm = _asm("quasi_static")
    dy, _, _ = _eval(V.kernels("kinematic").rhs, asm)
    assert np.isnan(dy).any()


def test_the_ball_loads_compile_once_for_every_chunk():
    from bearing_lab.sim import simulate
    simulate("paper-O1", duration=0.12, progress=False)  # three 50 ms chunks and the warm-up's one sample
    kern = V.kernels("kinematic", METHODS["bs32"])  # what auto picks for paper-O1
    assert len(kern.loads_at.signatures) == 1
    assert len(kern.integrate.signatures) == 1


@pytest.mark.parametrize("method", ["dp54", "rk4"])
def test_a_loop_fixed_to_one_method_is_the_loop_of_every_method(method):
    sc = load_scene("paper-O1", **{"output.duration_s": 0.01})
    asm = assemble(sc)
    kw = dict(progress=False, step=1e-6 if method == "rk4" else None)
    fixed = _run(asm, METHODS[method], 1e-4, fixed_method=True, **kw)
    every = _run(asm, METHODS[method], 1e-4, fixed_method=False, **kw)
    for key in ("acc", "disp", "fi", "fo"):
        np.testing.assert_array_equal(fixed[key], every[key])
    assert V.kernels("kinematic", METHODS[method]).integrate.signatures


def test_a_simulation_compiles_its_own_kind_and_method_only():
    code = ("import json\nfrom bearing_lab.sim import simulate, _variants as V\n"
            "simulate('paper-O1', duration=0.01, progress=False)\nprint(json.dumps(sorted(V._LOADED)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert json.loads(out.stdout.strip().splitlines()[-1]) == [["kinematic", METHODS["bs32"]]]
