"""``load.axial_preload_um``: the rings pushed axially together by a displacement.

Independent numbers: Harris & Kotzalas (2007, sec. 7.2), rigid rings, written out here. With the
groove curvature centres A = (f_i + f_o - 1) D_b apart at zero load and the free contact angle
cos(a_f) = 1 - P_d / (2 A), an axial displacement d_a beyond the taking-up of the play gives
    tan(a) = tan(a_f) + d_a / (A cos(a_f)),
    delta_n = A (cos(a_f) / cos(a) - 1)       (the normal approach of a ball's two contacts),
    Q = K delta_n^1.5,  F_a = Z Q sin(a),
with K the two Hertz contacts in series.  And Harris's force-to-angle table (the one
tests/sim/test_bearing3d.py checks the force model against): the displacement that gives its
contact angle must give its force.
"""
import math

import numpy as np
import pytest

from bearing_lab.bearings import get_bearing
from bearing_lab.errors import SceneError
from bearing_lab.sim import load_scene, simulate
from bearing_lab.sim.assembly import assemble
from bearing_lab.sim.hertz import race_contact, series_stiffness

# (bearing, F_a N, alpha deg, Q N): Harris's relation solved independently (f_i 0.52, f_o 0.53, E 208 GPa)
HARRIS = [("6308", 100, 6.252, 114.8), ("6308", 300, 8.220, 262.3), ("6308", 1000, 11.085, 650.1),
          ("6205", 100, 8.357, 76.5), ("6205", 500, 12.458, 257.5)]
BASE = {"6308": "paper-healthy", "6205": "cwru-normal"}


def _pure_preload(bearing, um, fidelity="quasi-static", clearance_um=0.0, **more):
    return load_scene(BASE[bearing], **{"load.axial_preload_um": float(um), "load.radial_n": 0.0,
                                        "clearance.radial_um": clearance_um, "gravity.enabled": False,
                                        "speed.rpm": 1.0, "fidelity": fidelity, "shaft.unbalance_g_mm": 0.0,
                                        **more})


def _harris(bearing, d_a, clearance):
    """(alpha rad, Q N, F_a N) of a rigid-ring axial displacement d_a (m) beyond the play."""
    b = get_bearing(bearing)
    a = (b.inner_conformity + b.outer_conformity - 1.0) * b.ball_diameter
    a_f = math.acos(1.0 - clearance / (2.0 * a))
    alpha = math.atan(math.tan(a_f) + d_a / (a * math.cos(a_f)))
    dn = a * (math.cos(a_f) / math.cos(alpha) - 1.0)
    hi = race_contact(b.ball_diameter, b.pitch_diameter, b.inner_conformity, "inner")
    ho = race_contact(b.ball_diameter, b.pitch_diameter, b.outer_conformity, "outer")
    q = series_stiffness(hi.stiffness, ho.stiffness) * dn ** 1.5
    return alpha, q, b.n_balls * q * math.sin(alpha)


@pytest.mark.parametrize("bearing,fa,alpha_deg,q_n", HARRIS)
@pytest.mark.parametrize("fidelity", ["quasi-static", "multibody"])
def test_the_displacement_of_harris_contact_angle_gives_harris_force(bearing, fa, alpha_deg, q_n, fidelity):
    """Zero clearance: d_a = A tan(alpha) for the table's angle; the start must carry the table's force."""
    b = get_bearing(bearing)
    a = (b.inner_conformity + b.outer_conformity - 1.0) * b.ball_diameter
    d_a = a * math.tan(math.radians(alpha_deg))
    st = assemble(_pure_preload(bearing, d_a * 1e6, fidelity)).static
    assert st["axial_force_n"] == pytest.approx(fa, rel=0.01)
    assert st["ball_loads_outer"] == pytest.approx(q_n, rel=0.01)
    for al in (st["alpha_o"], st["alpha_i"]):
        assert np.degrees(np.abs(al)) == pytest.approx(alpha_deg, rel=0.005)


@pytest.mark.parametrize("clearance_um,preload_um", [(20.0, 30.0), (20.0, 80.0), (-5.0, 40.0), (0.0, 5.0)])
@pytest.mark.parametrize("on", ["outer", "inner"])
def test_preload_against_the_hand_calculation_with_clearance(clearance_um, preload_um, on):
    """A radial clearance is axial play: the displacement counts from where it is taken up (a_f);
    a negative clearance (radial preload) has none and counts from the centred rings (a_f = 0 there,
    the radial interference then adds to delta_n: not covered by the formula above, so it is
    written out with the exact geometry)."""
    b = get_bearing("6308")
    a = (b.inner_conformity + b.outer_conformity - 1.0) * b.ball_diameter
    sc = _pure_preload("6308", preload_um, clearance_um=clearance_um, **{"load.on": on})
    st = assemble(sc).static
    if clearance_um >= 0:
        alpha, q, fa = _harris("6308", preload_um * 1e-6, clearance_um * 1e-6)
    else:
        rho, zeta = a - clearance_um * 1e-6 / 2, preload_um * 1e-6
        alpha, dn = math.atan2(zeta, rho), math.hypot(rho, zeta) - a
        hi = race_contact(b.ball_diameter, b.pitch_diameter, b.inner_conformity, "inner")
        ho = race_contact(b.ball_diameter, b.pitch_diameter, b.outer_conformity, "outer")
        q = series_stiffness(hi.stiffness, ho.stiffness) * dn ** 1.5
        fa = b.n_balls * q * math.sin(alpha)
    assert st["axial_force_n"] == pytest.approx(fa, rel=1e-3)
    assert st["ball_loads_outer"] == pytest.approx(q, rel=1e-3)
    assert np.degrees(np.abs(st["alpha_o"])) == pytest.approx(math.degrees(alpha), rel=1e-4)
    # the loaded ring moved along +Z relative to the other: the sign a +Z force on it gives
    signed = float(np.mean(st["alpha_o"]))
    ref = float(np.mean(assemble(load_scene("paper-healthy", **{"load.axial_n": 100.0, "load.on": on,
                                                                 "fidelity": "quasi-static"})).static["alpha_o"]))
    assert signed * ref > 0
    # the supports hold the force: the ring positions differ by the preload's offset
    zeta_total = a * math.sin(math.acos(1.0 - max(clearance_um, 0) * 1e-6 / (2 * a))) + preload_um * 1e-6
    assert abs(st["zi"] - st["zo"]) == pytest.approx(zeta_total, rel=1e-9)


def test_the_time_loop_keeps_the_preload_and_reports_its_force():
    """6308, zero clearance, the displacement of 300 N in Harris's table: through the run the contact
    angles stay at 8.22 deg and the ball loads at 262.3 N (massless balls: no centrifugal shift)."""
    b = get_bearing("6308")
    d_a = (b.inner_conformity + b.outer_conformity - 1.0) * b.ball_diameter * math.tan(math.radians(8.220))
    ds = simulate(_pure_preload("6308", d_a * 1e6, **{"speed.rpm": 60.0}), duration=0.03, progress=False)
    assert ds.attrs["axial_force_n"] == pytest.approx(300.0, rel=0.01)
    assert "displacement preload" in ds.attrs["bearing_model"]
    for v in ("contact_angle_outer_deg", "contact_angle_inner_deg"):
        assert np.abs(ds[v].values) == pytest.approx(8.220, rel=0.01)
    assert ds["ball_load_outer"].values == pytest.approx(262.3, rel=0.01)


def test_zero_preload_is_none():
    ds = simulate("paper-healthy", duration=0.01, progress=False, **{"load.axial_preload_um": 0.0})
    assert ds.attrs["bearing_model"].startswith("planar")


@pytest.mark.parametrize("value,match", [
    (-5.0, r"load\.axial_preload_um: -5\.0 must not be negative"),
    ("-5 um", r"load\.axial_preload_um: -5\.0 must not be negative"),
    (1000.0, r"load\.axial_preload_um=1000: presses each ball .* µm into its grooves .* at most 34\d µm"),
    ("2 mm", r"load\.axial_preload_um=2000: presses each ball"),
    (float("inf"), r"load\.axial_preload_um: inf must be finite"),
])
def test_impossible_preloads_are_refused_naming_the_key(value, match):
    with pytest.raises(SceneError, match=match):
        load_scene("paper-healthy", **{"load.axial_preload_um": value})


def test_the_largest_allowed_preload_is_the_one_the_error_names():
    """The refusal's 'at most' is the displacement that presses each ball 0.5 % of D_b in."""
    b = get_bearing("6308")
    a = (b.inner_conformity + b.outer_conformity - 1.0) * b.ball_diameter
    most = math.sqrt((a + 0.005 * b.ball_diameter) ** 2 - a * a)
    load_scene("paper-healthy", **{"load.axial_preload_um": most * 1e6 * 0.999})
    with pytest.raises(SceneError, match="crushes the balls"):
        load_scene("paper-healthy", **{"load.axial_preload_um": most * 1e6 * 1.001})


def test_a_force_and_a_displacement_preload_together_are_refused():
    with pytest.raises(SceneError, match=r"load\.axial_preload_um=10 and load\.axial_n=100 are both given"):
        load_scene("paper-healthy", **{"load.axial_preload_um": 10.0, "load.axial_n": 100.0})


def test_a_support_too_soft_to_hold_the_preload_is_refused():
    with pytest.raises(SceneError, match=r"shaft\.stiffness_z_n_m=100 .* off centre"):
        assemble(_pure_preload("6308", 100.0, **{"shaft.stiffness_z_n_m": 100.0}))


def test_the_dynamic_cage_refusal_names_the_fix():
    with pytest.raises(SceneError, match=r"load\.axial_preload_um=10 with cage\.model='dynamic'.*cage\.model = "
                                         r"'kinematic'"):
        assemble(load_scene("paper-healthy", **{"load.axial_preload_um": 10.0, "cage.model": "dynamic"}))


def test_a_light_preload_that_finds_no_start_says_so_naming_the_key():
    """5 µm on the 6308 presses each ball 0.017 µm in (about 0.001 N): the multibody start with the
    inner ring's weight alone may stall; it then names the preload and what it amounts to."""
    from bearing_lab.errors import SolverError
    sc = load_scene("paper-healthy", **{"load.axial_preload_um": 5.0, "load.radial_n": 0.0, "speed.rpm": 1.0,
                                        "load.on": "inner", "fidelity": "multibody"})
    try:
        st = assemble(sc).static
    except SolverError as exc:
        assert "load.axial_preload_um=5 presses each ball 0.0166 µm" in str(exc)
    else:
        assert st["residual"] < 1e-8
