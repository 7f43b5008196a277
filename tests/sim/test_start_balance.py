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
