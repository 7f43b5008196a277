"""The 3-D bearing: axial load, contact angles, axial ring motion.

Independent numbers: the rigid-ring axial-load relation of Harris & Kotzalas (2007, sec. 7.2)
F_a = Z K_n (B D_b)^1.5 sin(a) (1/cos(a) - 1)^1.5, tabulated for the 6308 and the 6205 (zero
clearance, no speed); a quasi-static solve of combined radial and axial load written here (Newton
on the ring displacement, exact geometry, massless balls); the ball's own force balance with its
centrifugal force at the kinematic cage speed."""
import math

import numpy as np
import pytest

from bearing_lab.bearings import get_bearing
from bearing_lab.sim import load_scene, simulate
from bearing_lab.sim.assembly import assemble
from bearing_lab.sim.hertz import race_contact, series_stiffness

# (bearing, F_a N, alpha deg, Q N): Harris's relation solved independently (f_i 0.52, f_o 0.53, E 208 GPa)
HARRIS = [("6308", 100, 6.252, 114.8), ("6308", 300, 8.220, 262.3), ("6308", 500, 9.334, 385.4),
          ("6308", 1000, 11.085, 650.1), ("6205", 100, 8.357, 76.5), ("6205", 300, 10.978, 175.0),
          ("6205", 500, 12.458, 257.5), ("6205", 1000, 14.782, 435.5)]

BASE = {"paper-healthy": "6308", "cwru-normal": "6205"}


def _pure_axial(bearing, fa, fidelity, rpm=1.0):
    name = next(k for k, v in BASE.items() if v == bearing)
    return load_scene(name, **{"load.axial_n": float(fa), "load.radial_n": 0.0, "clearance.radial_um": 0.0,
                               "gravity.enabled": False, "speed.rpm": rpm, "fidelity": fidelity,
                               "shaft.unbalance_g_mm": 0.0})


@pytest.mark.parametrize("bearing,fa,alpha_deg,q_n", HARRIS)
@pytest.mark.parametrize("fidelity", ["quasi-static", "multibody"])
def test_pure_axial_load_contact_angle_and_ball_load_against_harris(bearing, fa, alpha_deg, q_n, fidelity):
    st = assemble(_pure_axial(bearing, fa, fidelity)).static
    for a in (st["alpha_o"], st["alpha_i"]):
        assert np.degrees(np.abs(a)) == pytest.approx(alpha_deg, rel=0.01)
    assert st["ball_loads_outer"] == pytest.approx(q_n, rel=0.01)
    # every ball carries F_a / (Z sin a)
    z = get_bearing(bearing).n_balls
    assert st["ball_loads_outer"] == pytest.approx(fa / (z * math.sin(math.radians(alpha_deg))), rel=0.01)


def test_the_time_loop_holds_the_axial_equilibrium_and_reports_contact_angles():
    ds = simulate(_pure_axial("6308", 300, "multibody", rpm=60.0), duration=0.05, progress=False)
    assert "3-D" in ds.attrs["bearing_model"]
    for v in ("contact_angle_outer_deg", "contact_angle_inner_deg"):
        assert ds[v].dims == ("ball", "time") and ds[v].attrs["units"] == "degree"
        assert np.abs(ds[v].values) == pytest.approx(8.220, rel=0.01)
    assert ds["ball_load_outer"].values == pytest.approx(262.3, rel=0.01)
    assert {"outer_ring_disp_z", "outer_ring_acc_z"} <= set(ds.data_vars)


def _independent_qs(bearing, fr, fa, clearance):
    """Rigid rings, massless balls, exact geometry: Newton on the inner ring's displacement (x, z)
    relative to the outer ring under a radial load fr (-Y on the outer... here +X on the inner) and an
    axial load fa, both on the inner ring.  Returns (ball loads Q (Z,), angles (Z,) rad, residual)."""
    b = get_bearing(bearing)
    hi = race_contact(b.ball_diameter, b.pitch_diameter, b.inner_conformity, "inner")
    ho = race_contact(b.ball_diameter, b.pitch_diameter, b.outer_conformity, "outer")
    k = series_stiffness(hi.stiffness, ho.stiffness)
    a0 = (b.inner_conformity + b.outer_conformity - 1) * b.ball_diameter
    psi = 2 * np.pi * np.arange(b.n_balls) / b.n_balls

    def balls(d):
        rho = a0 - clearance / 2 + d[0] * np.cos(psi)
        zeta = np.full_like(psi, d[1])
        ln = np.hypot(rho, zeta)
        q = k * np.maximum(ln - a0, 0) ** 1.5
        return q, rho / ln, zeta / ln

    def resid(d):
        q, cr, cz = balls(d)
        return np.array([np.sum(q * cr * np.cos(psi)) - fr, np.sum(q * cz) - fa])
    d = np.array([1e-6, a0 * 0.15])
    for _ in range(100):
        r = resid(d)
        J = np.empty((2, 2))
        for m in range(2):
            h = np.zeros(2)
            h[m] = 1e-10
            J[:, m] = (resid(d + h) - r) / 1e-10
        d = d - np.linalg.solve(J, r)
    q, cr, cz = balls(d)
    return q, np.arctan2(cz, cr), resid(d)


@pytest.mark.parametrize("fr,fa", [(480.0, 300.0), (150.0, 200.0), (1000.0, 100.0)])
def test_combined_load_ball_loads_against_an_independent_quasi_static_solve(fr, fa):
    sc = load_scene("paper-healthy", **{"load.radial_n": fr, "load.axial_n": fa, "load.on": "inner",
                                        "load.direction_deg": 0.0, "gravity.enabled": False, "speed.rpm": 1.0,
                                        "fidelity": "quasi-static", "shaft.unbalance_g_mm": 0.0})
    asm = assemble(sc)
    st = asm.static
    q_ref, a_ref, res = _independent_qs("6308", fr, fa, sc.clearance)
    assert np.max(np.abs(res)) < 1e-6 * (fr + fa)
    # the balls sit at the same azimuths (one in the load direction)
    order = np.argsort(np.mod(st["phis"] - st["phis"][0] + 1e-9, 2 * np.pi))
    q = st["ball_loads_outer"][order]
    np.testing.assert_allclose(q, q_ref, rtol=0.01, atol=1e-3 * q_ref.max())
    np.testing.assert_allclose(np.abs(st["alpha_o"][order]), np.abs(a_ref), rtol=0.01, atol=1e-4)
    # the axial balance: the balls carry the axial load to 0.1 %
    assert abs(np.sum(st["ball_loads_outer"] * np.sin(np.abs(st["alpha_o"]))) - fa) < 1e-3 * fa


def test_centrifugal_force_makes_the_outer_contact_angle_smaller():
    """At 3600 r/min the ball's centrifugal force m_b (d_m/2) omega_c^2 loads the outer contact more
    and flattens it: a_o < a_i, and each ball's radial balance Q_o cos a_o - Q_i cos a_i equals that
    force (omega_c the kinematic cage speed), its axial balance Q_o sin a_o = Q_i sin a_i."""
    sc = _pure_axial("6308", 300, "multibody", rpm=3600.0)
    st = assemble(sc).static
    b = sc.bearing
    m_b = sc.masses()[2]
    w_c = b.frequency_factors()["ftf"] * 3600 * 2 * math.pi / 60
    ao, ai = np.abs(st["alpha_o"]), np.abs(st["alpha_i"])
    assert np.all(ao < ai - math.radians(0.1))
    qo, qi = st["ball_loads_outer"], st["ball_loads_inner"]
    fc = qo * np.cos(ao) - qi * np.cos(ai)
    assert fc == pytest.approx(m_b * (b.pitch_diameter / 2) * w_c ** 2, rel=0.01)
    assert qo * np.sin(ao) == pytest.approx(qi * np.sin(ai), rel=1e-6)


def test_without_an_axial_load_the_planar_model_runs():
    ds = simulate("paper-O1", duration=0.02, progress=False)
    assert ds.attrs["bearing_model"].startswith("planar")
    assert "contact_angle_outer_deg" not in ds and "outer_ring_acc_z" not in ds


def test_an_axial_load_moves_the_contact_track_off_a_centred_defect():
    """O1 (1 x 1 mm at H = 0): 300 N axial moves the outer contact 1.14 mm across the groove
    (f_o D_b sin a, toward -Z for a +Z force on the outer ring), past the defect's 0.5 mm half-width: the
    impacts all but vanish; at H = -1.14 mm
    the track runs over the defect again."""
    peaks = {}
    for h_mm, fa in ((0.0, 0.0), (0.0, 300.0), (-1.14, 300.0), (1.14, 300.0)):
        ds = simulate("paper-O1", duration=0.1, progress=False,
                      **{"load.axial_n": fa, "defect.offset_mm": h_mm, "load.on": "outer"})
        peaks[(h_mm, fa)] = float(np.abs(ds["outer_ring_acc_y"]).max())
    assert peaks[(0.0, 300.0)] < 0.2 * peaks[(0.0, 0.0)]
    assert peaks[(-1.14, 300.0)] > 0.5 * peaks[(0.0, 0.0)]
    assert peaks[(1.14, 300.0)] < 0.2 * peaks[(0.0, 0.0)]


def test_the_dynamic_cage_is_refused_with_an_axial_load():
    from bearing_lab.errors import SceneError
    with pytest.raises(SceneError, match="kinematic cage"):
        assemble(load_scene("paper-healthy", **{"load.axial_n": 100.0, "cage.model": "dynamic"}))


def test_break_it_a_table_blind_to_the_contact_track_keeps_striking_the_centred_defect(monkeypatch):
    """With the defect table built at the groove bottom whatever the contact angle, the centred defect is
    struck under 300 N axial as without it: the previous test would fail."""
    from bearing_lab.sim import assembly, auto
    for user in (assembly, auto):    # the tables and the auto choice, both blind to the track
        monkeypatch.setattr(user, "track_offset", lambda defect, st, race, psi0, bearing: (defect, 0.0))
    p0 = float(np.abs(simulate("paper-O1", duration=0.1, progress=False, **{"load.on": "outer"})
                      ["outer_ring_acc_y"]).max())
    p1 = float(np.abs(simulate("paper-O1", duration=0.1, progress=False, **{"load.on": "outer", "load.axial_n": 300.0})
                      ["outer_ring_acc_y"]).max())
    assert p1 > 0.5 * p0


def _brute_drop_at_angle(defect, bearing, alpha):
    """Largest rigid drop of a ball meeting the outer race at contact angle alpha (rad, its contact point
    toward +Z for alpha > 0), over ball positions along the track: the ball centre moved along the contact
    normal until its sphere meets the groove surface outside the outline (grid over the torus)."""
    rb, rg = bearing.ball_diameter / 2, bearing.outer_conformity * bearing.ball_diameter
    R = bearing.pitch_diameter / 2 + rb
    Rc = R - rg
    s0, s1, _, _ = defect.track_extent()
    s = np.arange(s0 - 0.6e-3, s1 + 0.6e-3, 2e-6)
    zc = rg * math.sin(alpha)
    beta = np.arcsin(np.arange(zc - 1.2e-3, zc + 1.2e-3, 2e-6) / rg)      # 2 um across the groove
    S, Bt = np.meshgrid(s, beta, indexing="ij")
    Z = rg * np.sin(Bt)
    keep = ~defect.contains(S, Z)
    th = S / R
    rad = Rc + rg * np.cos(Bt)
    px, py, pz = (rad * np.cos(th))[keep], (rad * np.sin(th))[keep], Z[keep]
    worst = 0.0
    for sb in np.linspace(s0, s1, 11):
        ph = sb / R
        n = np.array([math.cos(alpha) * math.cos(ph), math.cos(alpha) * math.sin(ph), math.sin(alpha)])
        vx, vy, vz = px - Rc * math.cos(ph), py - Rc * math.sin(ph), pz
        vn = vx * n[0] + vy * n[1] + vz * n[2]
        disc = vn ** 2 - (vx ** 2 + vy ** 2 + vz ** 2) + rb ** 2
        ok = disc >= 0
        d = vn[ok] - np.sqrt(disc[ok]) - (rg - rb)
        worst = max(worst, float(d.min()))
    return worst


@pytest.mark.parametrize("h_mm", [1.143, 0.95, 1.35])
def test_the_turned_table_sees_the_drop_a_ball_meets_at_its_contact_angle(h_mm):
    """A 1 x 1 mm defect at offset H met at 8.22 deg (300 N axial on the 6308): the drop the 3-D model's
    table holds (the defect turned about the groove's curvature centre) against brute force on the
    torus with the ball centre moved along the contact normal."""
    from bearing_lab.sim.bearing3d import track_offset
    from bearing_lab.sim.defects import Defect
    from bearing_lab.sim.defects.geometry import RaceGeometry, drop_profile_2d
    b = get_bearing("6308")
    alpha = math.radians(8.220)
    d = Defect(race="outer", shape="rectangle", length=1e-3, width=1e-3, depth=0.5e-3, offset=h_mm * 1e-3)
    st = {"phis": np.array([0.0, math.pi]), "alpha_o": np.array([alpha, alpha])}
    turned, _ = track_offset(d, st, "outer", 0.0, b)
    g = RaceGeometry.from_bearing(b, "outer")
    psi = np.linspace(-1.2e-3, 1.2e-3, 481) / g.track_radius
    table_drop = float(np.max(drop_profile_2d(turned, g, psi)))
    brute = _brute_drop_at_angle(d, b, alpha)
    assert brute > 0.05e-6
    assert table_drop == pytest.approx(brute, rel=0.03, abs=0.02e-6)


@pytest.mark.parametrize("fa", [1.0, 10.0, 50.0, -40.0])
@pytest.mark.parametrize("fidelity", ["quasi-static", "multibody"])
def test_a_small_axial_load_beside_a_large_radial_one_finds_its_equilibrium(fa, fidelity):
    """480 N radial with 1-50 N axial: the axial play is barely taken up and the balls outside the load
    zone carry only their centrifugal force; the start still balances the axial load to 0.1 %."""
    st = assemble(load_scene("paper-O1", **{"load.axial_n": fa, "load.on": "outer", "fidelity": fidelity})).static
    q, a = st["ball_loads_outer"], st["alpha_o"]
    assert abs(abs(np.sum(q * np.sin(a))) - abs(fa)) < 1e-3 * abs(fa) + 1e-6


@pytest.mark.parametrize("fidelity", ["quasi-static", "multibody"])
def test_the_compiled_contact_angles_follow_the_geometry(fidelity):
    """The contact angles the time loop writes (one compiled pass over the output samples) against the
    geometry evaluated here with numpy's arctan2 on perturbed states (the rings and balls moved by
    tens of microns, so every term counts)."""
    from bearing_lab.sim import _kernels as K, _stepper as S
    from bearing_lab.sim.bearing3d import groove_offsets
    asm = assemble(load_scene("paper-healthy", **{"load.axial_n": 300.0, "fidelity": fidelity}))
    p, z, zb = asm.p, asm.n_balls, int(asm.p[K.P_ZOFF])
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 0.01, 7)
    states = asm.y0[None, :] + 20e-6 * rng.standard_normal((t.size, asm.y0.size))
    out = np.zeros((2, z, t.size))
    S.contact_angles_at(t, states, asm.model, out)
    rpm = asm.scene.speed_profile()[1][0]
    phis = p[K.P_PHI0] + p[K.P_FTF] * rpm * 2 * np.pi / 60 * t[:, None] + 2 * np.pi * np.arange(z) / z
    a_i, a_o = groove_offsets(asm.scene.bearing)
    c, s = np.cos(phis), np.sin(phis)
    ui = states[:, [0]] * c + states[:, [1]] * s
    uo = states[:, [4]] * c + states[:, [5]] * s
    zi, zo = states[:, [zb]], states[:, [zb + 1]]
    if fidelity == "multibody":
        q, w = states[:, 8:8 + z], states[:, zb + 4:zb + 4 + z]
        ref_o = np.arctan2(w - zo, q - uo - p[K.P_PD] / 4 + a_o)
        ref_i = np.arctan2(zi - w, ui - q - p[K.P_PD] / 4 + a_i)
    else:
        ref_o = ref_i = np.arctan2(zi - zo + 0 * ui, a_i + a_o - p[K.P_PD] / 2 + ui - uo)
    np.testing.assert_allclose(out[0], -np.degrees(ref_o).T, rtol=0, atol=1e-9)
    np.testing.assert_allclose(out[1], -np.degrees(ref_i).T, rtol=0, atol=1e-9)
    assert np.ptp(out) > 1.0     # the perturbation moved the angles by degrees: the check has teeth


def test_the_record_starts_after_the_axial_start_transient():
    """A healthy bearing under a constant axial load runs stationary: the record's halves carry the same
    RMS (a start transient still ringing decays across the record) and the radial signal's kurtosis
    stays that of a periodic signal (the ringing's bursts drove it to 15 after 0.02 s of plain
    settling, 1.8 after 0.1 s)."""
    from scipy.stats import kurtosis
    ds = simulate("cwru-normal", duration=0.2, progress=False, **{"fidelity": "multibody", "load.axial_n": 188.0})
    for ch in ("outer_ring_acc_y", "outer_ring_acc_z"):
        x = ds[ch].values
        h = x.size // 2
        assert np.sqrt(np.mean(x[:h] ** 2)) == pytest.approx(np.sqrt(np.mean(x[h:] ** 2)), rel=0.2), ch
    assert kurtosis(ds["outer_ring_acc_y"].values, fisher=False) < 1.6


def test_break_it_without_the_settling_damping_the_record_rings(monkeypatch):
    """The previous test fails with the balls' axial motion left undamped while settling."""
    from scipy.stats import kurtosis
    from bearing_lab.sim import scene
    monkeypatch.setattr(scene, "SETTLE_AXIAL_RATE", 0.0)
    ds = simulate("cwru-normal", duration=0.2, progress=False, **{"fidelity": "multibody", "load.axial_n": 188.0})
    x = ds["outer_ring_acc_z"].values
    h = x.size // 2
    assert np.sqrt(np.mean(x[:h] ** 2)) > 1.5 * np.sqrt(np.mean(x[h:] ** 2))
    assert kurtosis(ds["outer_ring_acc_y"].values, fisher=False) > 1.6
