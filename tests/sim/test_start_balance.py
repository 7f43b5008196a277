"""The start's ring balance in 2-D: Newton's method reaches the balance the 1-D search along the load only
approaches, and an unbalanced start is refused (never taken silently)."""
import numpy as np
import pytest

from bearing_lab.errors import SceneError
from bearing_lab.sim.statics import _solve_relative


def _force(e):
    # a stiffening, anisotropic, cross-coupled spring: along the load alone it does not balance
    k = np.array([[3.0e9, 0.4e9], [0.4e9, 1.5e9]])
    return k @ e * (1.0 + 1e4 * np.hypot(*e))


def test_the_2d_balance_is_reached():
    target = np.array([300.0, -480.0])
    e = _solve_relative(target, _force, 1e-5, "load")
    assert np.max(np.abs(_force(e) - target)) < 1e-8 * 480.0
    along = target / np.hypot(*target)
    u = e / np.hypot(*e)
    assert abs(u[0] * along[1] - u[1] * along[0]) > 1e-3      # the balance is off the load direction


def test_an_unbalanceable_force_law_is_refused():
    def flat(e):                                              # carries nothing across the load: no balance
        d = np.array([0.0, -1.0])
        return 1e9 * (e @ d) * d
    with pytest.raises(SceneError, match="static equilibrium not found"):
        _solve_relative(np.array([100.0, -480.0]), flat, 1e-5, "load")


@pytest.mark.parametrize("name", ["paper-O1", "paper-healthy", "cwru-or007-6"])
def test_the_planar_start_is_the_balance_scipy_finds(name):
    """The start's final 2-D solve (Newton's method) lands on the root Powell's hybrid method
    (scipy.optimize.root, an independent solver) finds from the same equations, to rounding, and
    each ring's spring holds the balls' force and the ring's load there."""
    from scipy.optimize import root

    from bearing_lab.sim import load_scene
    from bearing_lab.sim.assembly import scene_statics
    from bearing_lab.sim.statics import ball_contact_loads

    scene = load_scene(name)
    _, hi, ho, st, _ = scene_statics(scene)
    d = scene.data
    ks = np.array([d["shaft"]["stiffness_x_n_m"], d["shaft"]["stiffness_y_n_m"]])
    km = np.array([d["mount"]["stiffness_x_n_m"], d["mount"]["stiffness_y_n_m"]])
    u = np.stack([np.cos(st["phis"]), np.sin(st["phis"])])

    def ring_forces(e):
        q_in, q_out = ball_contact_loads(e, st["phis"], hi.stiffness, ho.stiffness, scene.clearance,
                                         st["ball_body_force"], d["contact"]["exponent"])
        return -u @ q_in, u @ q_out

    def gap(e):            # each ring where its spring balances the balls and its load, against e (um)
        fi, fo = ring_forces(e)
        xi = st["rest_i"] + (fi + st["f_in"]) / ks
        xo = st["rest_o"] + (fo + st["f_out"]) / km
        return (xi - xo - e) * 1e6

    e = st["xi"] - st["xo"]
    ref = root(gap, e * (1 + 1e-3), method="hybr", options={"xtol": 1e-15}).x
    assert np.max(np.abs(e - ref)) <= 1e-12 * np.max(np.abs(e))
    fi, fo = ring_forces(e)
    load = max(np.hypot(*st["load_vec"]), 1.0)
    assert np.max(np.abs(fi + st["f_in"] - ks * (st["xi"] - st["rest_i"]))) < 1e-9 * load
    assert np.max(np.abs(fo + st["f_out"] - km * (st["xo"] - st["rest_o"]))) < 1e-9 * load
