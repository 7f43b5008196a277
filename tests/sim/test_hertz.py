"""Hertz point-contact constants against values computed by hand with Harris & Kotzalas's
method (*Rolling Bearing Analysis*: F(rho), kappa, delta*, K_c) for the 6308 of Liu et al., 1 %."""
import pytest

from bearing_lab.sim.hertz import race_contact, series_stiffness
from tests.naive import hertz_stiffness_harris

DB, DM = 15.081e-3, 65.0e-3


@pytest.mark.parametrize("race,f,sum_rho,f_rho,kappa,dstar,k", [
    ("inner", 0.52, 0.17778, 0.94262, 9.550, 0.5967, 3.50e10),
    ("outer", 0.53, 0.11515, 0.86962, 5.639, 0.7219, 3.27e10),
])
def test_6308_constants(race, f, sum_rho, f_rho, kappa, dstar, k):
    c = race_contact(DB, DM, f, race)
    assert c.curvature_sum / 1e3 == pytest.approx(sum_rho, rel=1e-3)
    assert c.curvature_difference == pytest.approx(f_rho, rel=1e-3)
    assert c.ellipticity == pytest.approx(kappa, rel=1e-3)
    assert c.delta_star == pytest.approx(dstar, rel=1e-3)
    assert c.stiffness == pytest.approx(k, rel=0.01)
    # and Harris's steel shortcut, computed independently from Σρ and δ*
    assert c.stiffness == pytest.approx(hertz_stiffness_harris(sum_rho, dstar), rel=0.01)


def test_series_and_other_conformities():
    ki = race_contact(DB, DM, 0.52, "inner").stiffness
    ko = race_contact(DB, DM, 0.53, "outer").stiffness
    assert series_stiffness(ki, ko) == pytest.approx(1.19e10, rel=0.01)
    ki2 = race_contact(DB, DM, 0.515, "inner").stiffness
    ko2 = race_contact(DB, DM, 0.525, "outer").stiffness
    assert ki2 == pytest.approx(3.88e10, rel=0.01)
    assert ko2 == pytest.approx(3.48e10, rel=0.01)
    assert series_stiffness(ki2, ko2) == pytest.approx(1.30e10, rel=0.01)


@pytest.mark.parametrize("race,f,force,a_mm,b_mm", [
    ("outer", 0.53, 50.0, 0.49, 0.09),
    ("outer", 0.53, 300.0, 0.90, 0.16),
    ("outer", 0.53, 600.0, 1.13, 0.20),
    ("inner", 0.52, 300.0, 1.09, 0.11),
])
def test_contact_ellipse(race, f, force, a_mm, b_mm):
    a, b = race_contact(DB, DM, f, race).semi_axes(force)
    # the hand values carry two significant figures: half a unit of the last digit
    assert a * 1e3 == pytest.approx(a_mm, abs=0.005 + 0.01 * a_mm)
    assert b * 1e3 == pytest.approx(b_mm, abs=0.005 + 0.01 * b_mm)


def test_force_approach_inverse():
    c = race_contact(DB, DM, 0.53, "outer")
    assert float(c.force(c.approach(300.0))) == pytest.approx(300.0, rel=1e-12)
