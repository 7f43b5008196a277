"""The simulator's own root finder and elliptic integrals (bearing_lab.sim.numerics): scipy's
brentq, ellipk and ellipe are the independent reference (the same float for the same input, so
the simulator's start did not move when it stopped importing them), and closed forms."""
import math

import numpy as np
import pytest

from bearing_lab.errors import SolverError
from bearing_lab.sim.numerics import brentq, ellipe, ellipk

scipy_optimize = pytest.importorskip("scipy.optimize")
scipy_special = pytest.importorskip("scipy.special")

FUNCTIONS = [
    (lambda x: x ** 3 - 2 * x - 5, 2.0, 3.0),                          # Wallis's cubic
    (lambda x: math.cos(x) - x, 0.0, 1.0),
    (lambda x: math.exp(x) - 1e-3, -20.0, 5.0),                         # far from the bracket's middle
    (lambda x: math.tanh(50 * (x - 0.3)), -1.0, 2.0),                   # a steep step
    (lambda x: (x - 1e-6) ** 1.5 if x > 1e-6 else -(1e-6 - x), 0.0, 1.0),   # a contact law's kink
]
TOLERANCES = [(2e-12, 4 * np.finfo(float).eps), (1e-16, 1e-14), (1e-13, 1e-13), (1e-3, 1e-3)]


@pytest.mark.parametrize("f,a,b", FUNCTIONS)
@pytest.mark.parametrize("xtol,rtol", TOLERANCES)
def test_brentq_gives_scipys_float(f, a, b, xtol, rtol):
    ours = brentq(f, a, b, xtol=xtol, rtol=rtol)
    assert ours == scipy_optimize.brentq(f, a, b, xtol=xtol, rtol=rtol)
    assert abs(f(ours)) <= abs(f(ours + 10 * (xtol + rtol * abs(ours))))  # a root, not a bracket end


def test_brentq_closed_form_and_ends():
    assert brentq(lambda x: x * x - 2.0, 0.0, 2.0, xtol=1e-15) == pytest.approx(math.sqrt(2), rel=1e-15)
    assert brentq(lambda x: x - 1.0, 1.0, 5.0) == 1.0           # a root at an end is returned as it is


@pytest.mark.parametrize("f,a,b,match", [
    (lambda x: x * x + 1.0, -1.0, 1.0, "no sign change"),
    (lambda x: math.nan, 0.0, 1.0, "NaN"),
])
def test_brentq_refuses_what_it_cannot_solve(f, a, b, match):
    with pytest.raises(SolverError, match=f"ball 3 start.*{match}"):
        brentq(f, a, b, where="ball 3 start")


def test_brentq_says_when_it_runs_out_of_iterations():
    with pytest.raises(SolverError, match="no root within 3 iterations"):
        brentq(lambda x: x ** 3 - 2 * x - 5, 2.0, 3.0, xtol=1e-15, maxiter=3)


def test_elliptic_integrals_are_scipys():
    rng = np.random.default_rng(7)
    ms = np.concatenate([rng.random(3000), 1 - 10 ** -rng.uniform(0, 15.5, 500), [0.0, 5e-324, 0.5]])
    for m in ms:
        assert ellipk(m) == scipy_special.ellipk(m), m
        assert ellipe(m) == scipy_special.ellipe(m), m


def test_elliptic_integrals_closed_forms():
    assert ellipk(0.0) == pytest.approx(math.pi / 2, rel=1e-15)
    assert ellipe(0.0) == pytest.approx(math.pi / 2, rel=1e-15)
    # Legendre's relation at m = 1/2: 2 E K - K^2 = pi / 2
    k, e = ellipk(0.5), ellipe(0.5)
    assert 2 * e * k - k * k == pytest.approx(math.pi / 2, rel=1e-15)
    # K(1/2) = Gamma(1/4)^2 / (4 sqrt(pi))
    assert k == pytest.approx(math.gamma(0.25) ** 2 / (4 * math.sqrt(math.pi)), rel=1e-15)
    # near m = 1 (m1 = 1 - m exact in floats): K ~ ln(4 / sqrt(m1)), E ~ 1 + m1/2 (ln(4 / sqrt(m1)) - 1/2)
    m1 = 2.0 ** -40
    big = math.log(4 / math.sqrt(m1))
    assert ellipk(1 - m1) == pytest.approx(big, rel=1e-10)
    assert ellipe(1 - m1) == pytest.approx(1 + m1 / 2 * (big - 0.5), rel=1e-14)


@pytest.mark.parametrize("m", [-0.1, 1.0, 2.0, math.nan])
def test_elliptic_parameter_outside_its_range_is_refused(m):
    with pytest.raises(SolverError, match=r"m = k\^2 must be in \[0, 1\)"):
        ellipk(m)
    with pytest.raises(SolverError, match=r"m = k\^2 must be in \[0, 1\)"):
        ellipe(m)
