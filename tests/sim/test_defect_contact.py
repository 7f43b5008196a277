"""Contact tables over a defect (bearing_lab.sim.defects.contact) and the half-space check."""
import math
import time

import numpy as np
import pytest

from bearing_lab.bearings import get_bearing
from bearing_lab.errors import SceneError
from bearing_lab.sim.defects import Defect, RaceGeometry, contact_table, rigid_drop

B6308 = get_bearing("6308")
DMAX = 20e-6


def _col(T, delta):
    return int(np.argmin(np.abs(T.delta - delta)))


def _row(T, s):
    return int(np.argmin(np.abs(T.psi * T.track_radius - s)))


@pytest.mark.parametrize("race,within_1pct", [("outer", 8e-6), ("inner", 5e-6)])
def test_area_law_intact_limit(race, within_1pct):
    """The raw local law c * sum(sqrt(delta - h)) dA with c = 3/(4 pi sqrt(Rx Ry)) sums to
    K delta^1.5 on intact surface within 1 % up to 8 µm (outer; 5 µm inner).  Above that
    the exact torus gap grows faster than Hertz's paraboloid (by z^4/8 (1/r_b^3 - 1/r_g^3)
    across the track), the law falls 0.12 %/µm (outer) and 0.18 %/µm (inner) below
    delta^1.5; the paraboloid test below shows the constant itself is right.  The table
    divides by the intact sum on the same lattice, so it is exact on intact surface."""
    T = contact_table(Defect(race=race, length=1e-3, width=1e-3), B6308, model="area",
                      delta_max=DMAX, n_delta=41)
    law = T.info["intact_law_ratio"]
    ok = (T.delta > 0) & (T.delta <= within_1pct + 1e-12)
    np.testing.assert_allclose(law[ok], 1.0, atol=0.01)
    np.testing.assert_allclose(law[1:], 1.0, atol=0.04)
    # the table itself is normalised on the same lattice: exact on intact surface
    np.testing.assert_allclose(T.G[0], T.delta ** 1.5, rtol=1e-12, atol=0)
    np.testing.assert_allclose(T.G[-1], T.delta ** 1.5, rtol=1e-12, atol=0)


def test_area_law_paraboloid_normalisation():
    """Same lattice, paraboloid gap: the law's constant is right to 0.5 % at every delta."""
    g = RaceGeometry.from_bearing(B6308, "outer")
    b, a = g.reach(DMAX)
    ds, dz = b / 60, a / 60
    s = np.arange(-70, 71) * ds
    z = (np.arange(-70, 70) + 0.5) * dz
    h = s[:, None] ** 2 / (2 * g.rx) + z[None, :] ** 2 / (2 * g.ry)
    c = 3 / (4 * math.pi * math.sqrt(g.rx * g.ry))
    for d in (1e-6, 5e-6, 8e-6, 20e-6):
        total = c * np.sqrt(np.maximum(d - h, 0)).sum() * ds * dz
        assert total / d ** 1.5 == pytest.approx(1.0, abs=0.005)


def test_outside_table_is_intact_and_lookup():
    T = contact_table(Defect(length=1e-3, width=1e-3), B6308, model="area", delta_max=DMAX)
    d = np.array([0.0, 3e-6, 8e-6, 25e-6, -1e-6])
    far = T.lookup(np.full(5, T.psi_max + 0.01), d)
    np.testing.assert_allclose(far, np.maximum(d, 0) ** 1.5)
    # nodes are reproduced, scalars work
    j, k = _row(T, 0.0), _col(T, 8e-6)
    assert float(T.lookup(T.psi[j], T.delta[k])) == pytest.approx(T.G[j, k], rel=1e-12)
    assert T.psi_min < 0 < T.psi_max and T.G.shape == (T.psi.size, T.delta.size)
    assert T.intact_fraction.shape == T.G.shape and T.drop.shape == T.psi.shape
    psi0, dpsi, dd, G = T.kernel_arrays()
    assert G.flags.c_contiguous and dpsi > 0 and dd > 0


def test_models_order_and_reference_drop():
    """area <= drop <= intact; the tables' drop at psi = 0 is the exact 0.9413 µm."""
    d = Defect(length=1e-3, width=1e-3)
    Ta = contact_table(d, B6308, model="area", delta_max=DMAX)
    Td = contact_table(d, B6308, model="drop", delta_max=DMAX, n_psi=Ta.psi.size)
    Tp = contact_table(d, B6308, model="profile", delta_max=DMAX, n_psi=Ta.psi.size)
    np.testing.assert_allclose(Ta.psi, Td.psi)
    intact = Ta.delta[None, :] ** 1.5
    assert np.all(Td.G <= intact * (1 + 1e-12))
    assert np.all(Ta.G <= Td.G + 0.02 * intact)
    j = _row(Ta, 0.0)
    assert Ta.drop[j] == pytest.approx(0.9413e-6, rel=0.01)
    assert Tp.drop[j] == pytest.approx(13.473e-6, rel=0.01)   # profile: full-width slot
    k = _col(Ta, 8e-6)
    assert Ta.G[j, k] < 0.8 * Td.G[j, k]                        # area loss dominates


def test_full_width_slot_profile_is_exact():
    slot = Defect(length=1e-3, width=23e-3)
    Tp = contact_table(slot, B6308, model="profile", delta_max=DMAX)
    Td = contact_table(slot, B6308, model="drop", delta_max=DMAX, n_psi=Tp.psi.size)
    np.testing.assert_allclose(Tp.drop, Td.drop, atol=1e-10)
    np.testing.assert_allclose(Tp.G, Td.G, atol=1e-9 * DMAX ** 1.5)
    assert Tp.drop[_row(Tp, 0.0)] == pytest.approx(13.473e-6, rel=0.01)


def test_offset_effect_without_drop():
    """At H = B/2 the rigid ball cannot drop, yet the area model still loses load."""
    vals = []
    for h in (0.0, 1 / 3, 1 / 2):
        T = contact_table(Defect(length=1e-3, width=1e-3, offset=h * 1e-3), B6308, model="area",
                          delta_max=DMAX)
        j, k = _row(T, 0.0), _col(T, 8e-6)
        vals.append(T.G[j, k] / T.delta[k] ** 1.5)
        if h == 0.5:
            assert T.drop[j] == pytest.approx(0.0, abs=1e-12)
    assert vals[0] < vals[1] < vals[2] < 0.9


def test_flat_section_on_length_edges():
    """L = 3 mm, B = 1 mm, theta = 0: while the contact lies inside the defect's length the
    ball rides on the length edges and G is flat (paper's flat section), from geometry."""
    T = contact_table(Defect(length=3e-3, width=1e-3), B6308, model="area", delta_max=DMAX)
    k = _col(T, 8e-6)
    g = RaceGeometry.from_bearing(B6308, "outer")
    b8, _ = g.reach(8e-6)
    s = T.psi * T.track_radius
    flat = np.abs(s) < 1.5e-3 - b8
    vals = T.G[flat, k]
    assert vals.size > 20
    assert np.ptp(vals) / vals.mean() < 0.005
    assert vals.mean() < 0.6 * T.delta[k] ** 1.5


def test_skew_symmetry_and_gradual_entry():
    T0 = contact_table(Defect(length=3e-3, width=1e-3), B6308, model="area", delta_max=DMAX)
    T60 = contact_table(Defect(length=3e-3, width=1e-3, skew=math.radians(60)), B6308,
                        model="area", delta_max=DMAX)
    k = _col(T60, 8e-6)
    r60 = T60.G[:, k] / T60.delta[k] ** 1.5
    np.testing.assert_allclose(r60, r60[::-1], atol=1e-9)
    # a skewed defect occupies a shorter stretch of track than the straight one
    s0 = T0.psi[T0.G[:, k] < 0.99 * T0.delta[k] ** 1.5] * T0.track_radius
    s60 = T60.psi[r60 < 0.99] * T60.track_radius
    assert np.ptp(s60) < np.ptp(s0)


def test_defect_missing_track_is_healthy():
    d = Defect(length=1e-3, width=1e-3, offset=4e-3)
    assert d.misses_track(B6308, DMAX)
    for model in ("profile", "drop", "area"):
        T = contact_table(d, B6308, model=model, delta_max=DMAX)
        np.testing.assert_allclose(T.G, np.broadcast_to(T.delta ** 1.5, T.G.shape), rtol=1e-12)


def test_inner_race_table():
    d = Defect(race="inner", length=1e-3, width=1e-3)
    T = contact_table(d, B6308, model="area", delta_max=DMAX)
    j, k = _row(T, 0.0), _col(T, 8e-6)
    assert T.race == "inner"
    assert T.drop[j] == pytest.approx(rigid_drop(d, B6308), rel=1e-9)
    assert 0.3 < T.G[j, k] / T.delta[k] ** 1.5 < 0.9
    np.testing.assert_allclose(T.G[0], T.delta ** 1.5, rtol=1e-12)


def test_table_grid_follows_the_arguments():
    """(Build times are measured in benchmarks/defect_tables.py, not asserted here.)"""
    T = contact_table(Defect(length=1e-3, width=1e-3, depth=0.4999e-3), B6308, model="area",
                      delta_max=DMAX, n_psi=200, n_delta=41)
    assert T.G.shape == (200, 41) and T.info["build_cpu_s"] > 0


def test_tables_cached_and_read_only():
    d = Defect(length=1e-3, width=1e-3, angle=0.3)
    T1 = contact_table(d, B6308, model="drop", delta_max=DMAX)
    T2 = contact_table(Defect(length=1e-3, width=1e-3, angle=1.2), B6308, model="drop",
                       delta_max=DMAX)
    assert T1 is T2
    with pytest.raises(ValueError):
        T1.G[0, 0] = 1.0


def test_halfspace_model_table():
    """The half-space table: intact at the ends, keeps more load than the local law."""
    d = Defect(length=1e-3, width=1e-3)
    Th = contact_table(d, B6308, model="halfspace", delta_max=DMAX)
    Ta = contact_table(d, B6308, model="area", delta_max=DMAX, n_psi=Th.psi.size)
    k = _col(Th, 8e-6)
    j = _row(Th, 0.0)
    np.testing.assert_allclose(Th.G[0], Th.delta ** 1.5, rtol=1e-12)
    assert Ta.G[j, k] < Th.G[j, k] < Th.delta[k] ** 1.5


def test_bad_arguments():
    d = Defect(length=1e-3, width=1e-3)
    with pytest.raises(SceneError, match="model"):
        contact_table(d, B6308, model="hertz", delta_max=DMAX)
    with pytest.raises(SceneError, match="delta_max"):
        contact_table(d, B6308, model="area", delta_max=-1.0)


def test_halfspace_against_hertz_and_local_law():
    """Elastic half-space (Boussinesq/Love, CG) on a fine grid: intact force and semi-axes at
    300 N against Hertz (0.90 x 0.16 mm, K_o = 3.27e10 N/m^1.5; Harris & Kotzalas 2007); the
    local law overstates the load lost over a centred 1 x 1 mm defect, the half-space table
    follows the fine solve."""
    from bearing_lab.sim.defects.compare_law import compare_local_law
    r = compare_local_law(s_positions=(0.0, 0.5e-3))
    assert r["intact_force"] == pytest.approx(300.0, rel=0.01)
    assert r["a"] == pytest.approx(0.90e-3, rel=0.03)
    assert r["b"] == pytest.approx(0.16e-3, rel=0.05)
    centre, edge = r["positions"]
    assert centre["local_law"] < centre["halfspace"] < 1.0
    assert edge["local_law"] < edge["halfspace"] < 1.0
    for p in (centre, edge):
        assert p["table"] == pytest.approx(p["halfspace"], abs=0.01)


def test_ball_defect_tables():
    """A ball defect against a race: the same contact-plane geometry as a race defect, with
    psi measured on the ball (arc = ball radius * psi)."""
    ball = Defect(race="ball", length=1e-3, width=1e-3)
    race = Defect(race="outer", length=1e-3, width=1e-3)
    assert rigid_drop(ball, B6308, against="outer") == pytest.approx(rigid_drop(race, B6308))
    Tb = contact_table(ball, B6308, model="area", delta_max=DMAX, against="outer")
    Tr = contact_table(race, B6308, model="area", delta_max=DMAX)
    assert Tb.race == "ball/outer"
    assert Tb.track_radius == pytest.approx(B6308.ball_diameter / 2)
    k = _col(Tb, 8e-6)
    assert Tb.G[_row(Tb, 0.0), k] == pytest.approx(Tr.G[_row(Tr, 0.0), k], rel=0.01)
    s_b = Tb.psi * Tb.track_radius
    s_r = Tr.psi * Tr.track_radius
    assert s_b[0] == pytest.approx(s_r[0], rel=0.02) and s_b[-1] == pytest.approx(s_r[-1], rel=0.02)
    Ti = contact_table(ball, B6308, model="drop", delta_max=DMAX, against="inner")
    assert Ti.drop[_row(Ti, 0.0)] == pytest.approx(
        rigid_drop(Defect(race="inner", length=1e-3, width=1e-3), B6308), rel=1e-6)
    with pytest.raises(SceneError, match="against"):
        contact_table(ball, B6308, model="area", delta_max=DMAX)
    with pytest.raises(SceneError, match="against"):
        contact_table(race, B6308, model="area", delta_max=DMAX, against="inner")


def test_intact_fraction_of_hertz_ellipse():
    """Ball centred on a 1 x 1 mm defect at 300 N: the Hertz ellipse (0.90 x 0.16 mm) keeps
    only its parts beyond |z| = 0.5 mm: 1 - (2/pi)(asin(c) + c sqrt(1 - c^2)), c = 0.5/a."""
    T = contact_table(Defect(length=1e-3, width=1e-3), B6308, model="area", delta_max=DMAX,
                      n_delta=81)
    d300 = (300 / 3.27e10) ** (2 / 3)
    a = 0.897e-3
    c = 0.5e-3 / a
    expected = 1 - (2 / math.pi) * (math.asin(c) + c * math.sqrt(1 - c * c))
    j = _row(T, 0.0)
    got = np.interp(d300, T.delta, T.intact_fraction[j])
    assert got == pytest.approx(expected, abs=0.01)
    assert np.all(T.intact_fraction[:, 0] == 1.0)
    assert np.all(T.intact_fraction[0] == 1.0)


def test_table_dataset_roundtrip_and_plot(tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    import xarray as xr
    T = contact_table(Defect(length=1e-3, width=1e-3), B6308, model="area", delta_max=DMAX)
    path = tmp_path / "table.nc"
    T.to_dataset().to_netcdf(path)
    back = xr.load_dataset(path)
    np.testing.assert_array_equal(back["G"].values, T.G)
    assert back.attrs["model"] == "area" and back["delta"].attrs["units"] == "m"
    fig = T.plot()
    assert len(fig.axes[0].lines) == 4


def test_area_table_against_direct_sum():
    """Slow check of the lattice/FFT evaluation: the local law summed directly on a fine
    ball-centred grid (point-in-outline mask) at a few positions."""
    d = Defect(length=3e-3, width=1e-3, skew=math.radians(30), offset=0.2e-3)
    T = contact_table(d, B6308, model="area", delta_max=DMAX)
    g = RaceGeometry.from_bearing(B6308, "outer")
    delta = 8e-6
    s = np.linspace(-0.5e-3, 0.5e-3, 801)
    z = np.linspace(-1.8e-3, 1.8e-3, 721)
    S, Z = np.meshgrid(s, z, indexing="ij")
    h0 = g.approach(S / g.track_radius, Z)
    hf = g.approach(S / g.track_radius, Z, depth=d.depth)
    w0 = np.sqrt(np.maximum(delta - h0, 0))
    for sb in (-1.2e-3, -0.4e-3, 0.0, 0.7e-3, 1.5e-3):
        ins = d.contains(S + sb, Z)
        direct = np.where(ins, np.sqrt(np.maximum(delta - hf, 0)), w0).sum() / w0.sum()
        table = float(T.lookup(sb / T.track_radius, delta)) / delta ** 1.5
        assert table == pytest.approx(direct, abs=0.01)


def test_registry_is_the_one_list_of_contact_models(monkeypatch):
    """Scenes, contact_table and the time loop read CONTACT_MODELS: a model registered there
    (here a copy of "drop" under another name) is accepted at scene load and simulated,
    identically to the original."""
    import dataclasses

    from bearing_lab import simulate
    from bearing_lab.sim.defects import contact
    from bearing_lab.sim.scene import load_scene
    with pytest.raises(SceneError, match="contact_model: invalid value 'rigid2d'"):
        load_scene("paper-O1", **{"defect.contact_model": "rigid2d"})
    extra = dict(contact.CONTACT_MODELS,
                 rigid2d=dataclasses.replace(contact.CONTACT_MODELS["drop"], name="rigid2d"))
    monkeypatch.setattr(contact, "CONTACT_MODELS", extra)
    kw = dict(duration=0.03, progress=False)
    a = simulate("paper-O1", **{"defect.contact_model": "rigid2d"}, **kw)
    b = simulate("paper-O1", **{"defect.contact_model": "drop"}, **kw)
    assert a.attrs["defect_contact_models"] == "rigid2d"
    ch = a.attrs["default_channel"]
    np.testing.assert_array_equal(a[ch].values, b[ch].values)



def test_rowwise_monotone_cubic_is_scipys_pchip():
    """The tables' G^(2/3) interpolation between approach nodes, all rows at once, against scipy's
    PchipInterpolator row by row: rows through (0, 0) and a drop like the tables' (rising, a
    plateau, a falling stretch, an overshooting end slope), knots uneven; equal within 1e-12 of the
    values' range, and within each row's data range (monotone: no overshoot)."""
    from scipy.interpolate import PchipInterpolator
    from bearing_lab.sim.defects.contact import pchip_rows
    rng = np.random.default_rng(7)
    xq = np.linspace(0.0, 1.0, 97)
    for n in (3, 4, 6, 11):
        x = np.sort(rng.uniform(0.02, 0.98, (40, n - 2)), axis=1)
        x = np.column_stack([np.zeros(40), x, np.ones(40)])
        y = np.cumsum(rng.choice([0.0, 0.0, 1.0, -0.3, 2.0], (40, n)) * rng.uniform(0.1, 1.0, (40, n)), axis=1)
        y[:, 0] = 0.0
        y[:4, 1] = 0.0                                  # a rigid drop: two zero knots
        got = pchip_rows(x, y, xq)
        want = np.array([PchipInterpolator(xr, yr)(xq) for xr, yr in zip(x, y)])
        assert np.abs(got - want).max() <= 1e-12 * max(1.0, np.abs(y).max())
        assert np.all(got >= y.min(axis=1, keepdims=True) - 1e-12)
        assert np.all(got <= y.max(axis=1, keepdims=True) + 1e-12)
