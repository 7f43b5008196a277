"""Defect description and exact rigid-drop geometry (bearing_lab.sim.defects)."""
import math

import numpy as np
import pytest

from bearing_lab.bearings import get_bearing
from bearing_lab.errors import SceneError
from bearing_lab.sim.defects import Defect, RaceGeometry, rigid_drop
from bearing_lab.sim.defects.geometry import drop_profile_1d, drop_profile_2d

B6308 = get_bearing("6308")


# How far a rigid ball can move into an outer-race defect, from two computations independent of
# this code (a brute-force grid over the raceway; an exact reduction along lines of constant axial
# position), which agree: 6308, r_o = 0.53 D_b,
# rectangle removed to 0.5 mm depth, ball centred over the defect.  (L, B, H/B, theta_deg, µm)
REFERENCE_DROPS = [
    (1, 1, 0, 0, 0.9413),
    (1, 1, 1 / 3, 0, 0.1043),
    (1, 1, 1 / 2, 0, 0.0),
    (3, 1, 0, 0, 0.9413),
    (6, 1, 0, 0, 0.9413),
    (3, 1, 0, 30, 1.2275),
    (3, 1, 0, 60, 3.1287),
    (1, 23, 0, 0, 13.473),
]


@pytest.mark.parametrize("L,B,h_frac,theta,expected_um", REFERENCE_DROPS)
def test_rigid_drop_matches_reference(L, B, h_frac, theta, expected_um):
    d = Defect(race="outer", shape="rectangle", length=L * 1e-3, width=B * 1e-3, depth=0.5e-3,
               offset=h_frac * B * 1e-3, skew=math.radians(theta))
    got = rigid_drop(d, B6308) * 1e6
    assert got == pytest.approx(expected_um, rel=0.01, abs=0.01)


def test_rigid_drop_closed_form_bounds():
    """Along the track (L^2/8)(1/r_b - 1/R_o); across (B^2/8)(1/r_b - 1/r_o) (circle sagitta)."""
    g = RaceGeometry.from_bearing(B6308, "outer")
    slot = Defect(length=1e-3, width=23e-3)
    assert rigid_drop(slot, B6308) == pytest.approx(1e-6 / 8 / g.rx, rel=0.005)
    narrow = Defect(length=20e-3, width=1e-3)
    assert rigid_drop(narrow, B6308) == pytest.approx(1e-6 / 8 / g.ry, rel=0.005)
    # inner race: convex along the track, 1/R_x = 1/r_b + 1/R_i
    gi = RaceGeometry.from_bearing(B6308, "inner")
    slot_i = Defect(race="inner", length=1e-3, width=23e-3)
    assert rigid_drop(slot_i, B6308) == pytest.approx(1e-6 / 8 / gi.rx, rel=0.005)


def test_drop_capped_by_depth_and_clearance_shifts_nothing():
    shallow = Defect(length=1e-3, width=23e-3, depth=5e-6)
    assert rigid_drop(shallow, B6308) == pytest.approx(5e-6)
    d = Defect(length=1e-3, width=1e-3)
    assert rigid_drop(d, B6308, clearance=20e-6) == pytest.approx(rigid_drop(d, B6308), rel=1e-3)


def test_race_geometry_intact_gap():
    for race in ("outer", "inner"):
        g = RaceGeometry.from_bearing(B6308, race, clearance=10e-6)
        assert float(g.approach(0.0, 0.0)) == pytest.approx(0.0, abs=1e-15)
        s, z = 0.05e-3, 0.2e-3
        h = float(g.approach(s / g.track_radius, z))
        assert h == pytest.approx(s * s / (2 * g.rx) + z * z / (2 * g.ry), rel=1e-3)
        assert float(g.approach(0.0, 0.0, depth=1e-4)) == pytest.approx(1e-4, rel=1e-9)


@pytest.mark.parametrize("race", ["outer", "inner"])
def test_reach_bounds_the_interpenetration_region(race):
    """The closed-form reach: on each axis the exact gap (RaceGeometry.approach) equals the approach
    at the reach within 1e-9 of it, is below it just inside and above it just outside, over 0.01-100
    µm; and at small approaches the extents follow the paraboloid, sqrt(2 R_x delta) along and
    sqrt(2 R_y delta) across (within 0.1 % at 0.01 µm)."""
    g = RaceGeometry.from_bearing(B6308, race)
    R = g.track_radius
    for d in (1e-8, 1e-6, 4.04e-6, 2e-5, 1e-4):
        s, z = g.reach(d)
        assert abs(float(g.approach(s / R, 0.0)) - d) < 1e-9 * d
        assert abs(float(g.approach(0.0, z)) - d) < 1e-9 * d
        assert float(g.approach(0.999 * s / R, 0.0)) < d < float(g.approach(1.001 * s / R, 0.0))
        assert float(g.approach(0.0, 0.999 * z)) < d < float(g.approach(0.0, 1.001 * z))
    s, z = g.reach(1e-8)
    assert s == pytest.approx(math.sqrt(2 * g.rx * 1e-8), rel=1e-3)
    assert z == pytest.approx(math.sqrt(2 * g.ry * 1e-8), rel=1e-3)


def test_drop_profiles_symmetric_and_zero_off_defect():
    g = RaceGeometry.from_bearing(B6308, "outer")
    d = Defect(length=3e-3, width=1e-3, skew=math.radians(30))
    psi = np.linspace(-3e-3, 3e-3, 41) / g.track_radius
    h = drop_profile_2d(d, g, psi)
    np.testing.assert_allclose(h, h[::-1], atol=1e-12)
    assert h[0] == 0 and h[-1] == 0
    h1 = drop_profile_1d(d, g, psi)
    assert np.all(h1 >= h - 1e-12)  # the 1-D reduction ignores the flanks


@pytest.mark.parametrize("race,defect,psi_radius", [
    ("outer", Defect(length=6e-3, width=1e-3), None),
    ("outer", Defect(length=1e-3, width=1e-3, offset=0.5e-3), None),          # drop exactly 0 over it
    ("outer", Defect(length=3e-3, width=1e-3, offset=0.3e-3, skew=math.radians(30)), None),
    ("inner", Defect(length=1e-3, width=1e-3, race="inner"), None),
    ("outer", Defect(shape="ellipse", length=2e-3, width=1e-3, offset=0.2e-3), None),
    ("outer", Defect(length=1e-3, width=1e-3, offset=0.2e-3, race="ball"), B6308.ball_diameter / 2),
])
def test_compiled_drop_pass_is_the_numpy_pass(race, defect, psi_radius, monkeypatch):
    """A table's drop profile (hundreds of ball positions x thousands of outline points) takes the
    compiled pass that keeps the outline points near the lowest and evaluates ``approach`` on those
    only; the numpy pass over every pair gives the same drops to the last bit, zeros included, and
    so does the numpy pass the compiled one falls back to when its candidates would not fit."""
    from bearing_lab.sim.defects import _halfspace_kernels, geometry
    g = RaceGeometry.from_bearing(B6308, race)
    R = g.track_radius if psi_radius is None else psi_radius
    s0, s1, _, _ = defect.track_extent()
    psi = np.linspace(s0 - 1e-3, s1 + 1e-3, 401) / R
    monkeypatch.setattr(geometry, "_COMPILED_PAIRS", 10 ** 12)
    numpy_pass = drop_profile_2d(defect, g, psi, psi_radius=psi_radius)
    monkeypatch.setattr(geometry, "_COMPILED_PAIRS", 0)
    compiled = drop_profile_2d(defect, g, psi, psi_radius=psi_radius)
    assert np.count_nonzero(numpy_pass) > 50 or defect.offset == 0.5e-3
    np.testing.assert_array_equal(compiled, numpy_pass)
    monkeypatch.setattr(_halfspace_kernels, "outline_candidates", lambda *a: -1)
    np.testing.assert_array_equal(drop_profile_2d(defect, g, psi, psi_radius=psi_radius), numpy_pass)


def test_from_mapping_units_and_defaults():
    d = Defect.from_mapping({"length_mm": 3, "width_mm": 1, "offset_mm": 0.2, "skew_deg": 30,
                             "angle_deg": 90})
    assert d.race == "outer" and d.shape == "rectangle"
    assert d.length == pytest.approx(3e-3) and d.width == pytest.approx(1e-3)
    assert d.depth == pytest.approx(0.5e-3) and d.offset == pytest.approx(0.2e-3)
    assert d.skew == pytest.approx(math.pi / 6) and d.angle == pytest.approx(math.pi / 2)
    c = Defect.from_mapping({"shape": "ellipse", "diameter_mm": 0.1778, "depth_mm": 0.2794})
    assert c.length == c.width == pytest.approx(0.1778e-3)
    p = Defect.from_mapping({"shape": "polygon", "vertices_mm": [[-1, -0.5], [1, -0.5], [0, 0.5]]})
    assert p.length == pytest.approx(2e-3) and p.width == pytest.approx(1e-3)
    assert p.contains(0.0, 0.0) and not p.contains(0.9e-3, 0.4e-3)


@pytest.mark.parametrize("mapping,key", [
    ({"length_mm": -1, "width_mm": 1}, "defect.length_mm"),
    ({"length_mm": 1, "width_mm": float("nan")}, "defect.width_mm"),
    ({"length_mm": 1, "width_mm": 1, "depth_mm": 0}, "defect.depth_mm"),
    ({"length_mm": 1, "width_mm": 1, "skew_deg": float("inf")}, "defect.skew_deg"),
    ({"length_mm": 1, "width_mm": 1, "colour": "red"}, "colour"),
    ({"length_mm": 1}, "defect.width_mm"),
    ({"length_mm": 1, "width_mm": 1, "race": "cage"}, "defect.race"),
    ({"shape": "polygon"}, "defect.vertices_mm"),
    ({"shape": "polygon", "vertices_mm": [[0, 0], [1, 1], [1, 0], [0, 1]]}, "defect.vertices"),
])
def test_from_mapping_refuses(mapping, key):
    with pytest.raises(SceneError, match=key.replace(".", r"\.")):
        Defect.from_mapping(mapping)


def test_from_mapping_where_prefix():
    with pytest.raises(SceneError, match=r"defects\[1\]\.length_mm"):
        Defect.from_mapping({"length_mm": -1, "width_mm": 1}, where="defects[1]")


def test_validate_against_bearing():
    Defect(length=1e-3, width=23e-3).validate(B6308)           # the paper's slot fits exactly
    with pytest.raises(SceneError, match="leaves the ring"):
        Defect(length=4e-3, width=23e-3, skew=math.radians(10)).validate(B6308)
    with pytest.raises(SceneError, match="leaves the ring"):
        Defect(length=1e-3, width=1e-3, offset=11.2e-3).validate(B6308)
    with pytest.raises(SceneError, match="depth_mm"):
        Defect(length=1e-3, width=1e-3, depth=5e-3).validate(B6308)   # section 4.96 mm
    with pytest.raises(SceneError, match="depth_mm"):
        Defect(race="inner", length=1e-3, width=1e-3, depth=5e-3).validate(B6308)
    Defect(length=1e-3, width=1e-3, depth=4.9e-3).validate(B6308)


def test_misses_track():
    far = Defect(length=1e-3, width=1e-3, offset=4e-3)
    near = Defect(length=1e-3, width=1e-3, offset=1.5e-3)
    assert far.misses_track(B6308, 20e-6)
    assert not near.misses_track(B6308, 20e-6)       # reach across at 20 µm is ~2.3 mm
    assert near.misses_track(B6308, 2e-6)
    assert rigid_drop(far, B6308) == 0.0


def test_polygon_and_ellipse_outlines():
    """A polygon drawn as the rectangle gives the rectangle's tables; a 1 mm circle is held
    by its axial extremes like the 1 x 1 mm square (0.9413 µm)."""
    from bearing_lab.sim.defects import contact_table
    rect = Defect(length=3e-3, width=1e-3, skew=math.radians(30), offset=0.2e-3)
    poly = Defect(shape="polygon", length=3e-3, width=1e-3, skew=rect.skew, offset=rect.offset,
                  vertices=tuple(map(tuple, rect.local_vertices().tolist())))
    assert rigid_drop(poly, B6308) == pytest.approx(rigid_drop(rect, B6308), rel=1e-6)
    Tr = contact_table(rect, B6308, model="area", delta_max=20e-6)
    Tp = contact_table(poly, B6308, model="area", delta_max=20e-6, n_psi=Tr.psi.size)
    np.testing.assert_allclose(Tp.G, Tr.G, rtol=1e-9, atol=1e-12 * 20e-6 ** 1.5)
    circle = Defect(shape="ellipse", length=1e-3, width=1e-3)
    assert rigid_drop(circle, B6308) * 1e6 == pytest.approx(0.9413, rel=0.01)


@pytest.mark.parametrize("race,load,k,a_mm,b_mm", [
    ("outer", 50, 3.27e10, 0.49, 0.09), ("outer", 300, 3.27e10, 0.90, 0.16),
    ("outer", 600, 3.27e10, 1.13, 0.20), ("inner", 300, 3.50e10, 1.09, 0.11)])
def test_hertz_semi_axes_reference(race, load, k, a_mm, b_mm):
    """Hand values (Harris & Kotzalas's Hertz solution): semi-axes (a across, b along) and kappa = a/b (5.639 outer, 9.550 inner)."""
    from bearing_lab.sim.defects.geometry import hertz_semi_axes
    g = RaceGeometry.from_bearing(B6308, race)
    a, b = hertz_semi_axes(g, (load / k) ** (2 / 3))
    assert a * 1e3 == pytest.approx(a_mm, abs=0.006)
    assert b * 1e3 == pytest.approx(b_mm, abs=0.006)
    assert a / b == pytest.approx(5.639 if race == "outer" else 9.550, rel=1e-3)


def test_drop_against_brute_force_grid():
    """Slow check of the outline-minimum argument: the smallest approach over a dense grid
    of the remaining surface (intact cells outside the outline, floor inside) equals the
    fast drop, for an offset, skewed rectangle and a polygon."""
    g = RaceGeometry.from_bearing(B6308, "outer")
    defects = [Defect(length=3e-3, width=1e-3, skew=math.radians(40), offset=0.15e-3),
               Defect(shape="polygon", vertices=((-0.8e-3, -0.3e-3), (0.6e-3, -0.5e-3),
                                                 (0.9e-3, 0.4e-3), (-0.2e-3, 0.6e-3)))]
    s = np.linspace(-2.5e-3, 2.5e-3, 1001)
    z = np.linspace(-1.5e-3, 1.5e-3, 601)
    S, Z = np.meshgrid(s, z, indexing="ij")
    for d in defects:
        inside = d.contains(S, Z)
        for psi_s in (0.0, 0.2e-3, -0.35e-3):
            h = np.where(inside, g.approach((S - psi_s) / g.track_radius, Z, depth=d.depth),
                         g.approach((S - psi_s) / g.track_radius, Z))
            brute = h.min()
            fast = drop_profile_2d(d, g, [psi_s / g.track_radius])[0]
            # the grid is 5 µm: its minimum overestimates the drop by at most ~|grad h| * 3.5 µm
            assert fast <= brute + 1e-12
            assert brute - fast < 0.02e-6


def test_ball_defect_validation():
    Defect(race="ball", length=1e-3, width=1e-3).validate(B6308)
    with pytest.raises(SceneError, match="ball"):
        Defect(race="ball", length=13e-3, width=1e-3).validate(B6308)
    with pytest.raises(SceneError, match="depth_mm"):
        Defect(race="ball", length=1e-3, width=1e-3, depth=8e-3).validate(B6308)
