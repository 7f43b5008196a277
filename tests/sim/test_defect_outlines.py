"""Defect outlines: one class each in a registry; areas against closed forms, and a new outline
added by registering one class (the worked example of the extension point)."""
import math

import numpy as np
import pytest

from bearing_lab.errors import SceneError
from bearing_lab.sim.defects import outlines
from bearing_lab.sim.defects.model import Defect
from bearing_lab.sim.defects.outlines import OUTLINES, Outline, polygon_area


def _area(d: Defect, n=400_000, seed=0):
    """Monte-Carlo area of the outline in track coordinates, m²."""
    s0, s1, z0, z1 = d.track_extent()
    rng = np.random.default_rng(seed)
    s = rng.uniform(s0, s1, n)
    z = rng.uniform(z0, z1, n)
    return (s1 - s0) * (z1 - z0) * float(np.mean(d.contains(s, z)))


L, B = 2e-3, 1e-3
SHAPES = {
    "rectangle": (dict(shape="rectangle", length=L, width=B), L * B),
    "ellipse": (dict(shape="ellipse", length=L, width=B), math.pi * L * B / 4),
    "polygon": (dict(shape="polygon", length=L, width=B,
                     vertices=((-L / 2, -B / 2), (L / 2, -B / 2), (0.0, B / 2))), L * B / 2),
}


@pytest.mark.parametrize("name", sorted(SHAPES))
@pytest.mark.parametrize("skew_deg", [0.0, 30.0])
def test_area_and_extent_against_closed_forms(name, skew_deg):
    kw, area = SHAPES[name]
    d = Defect(skew=math.radians(skew_deg), offset=0.2e-3, **kw)
    assert _area(d) == pytest.approx(area, rel=0.01)
    s, z = d.boundary_track(spacing=2e-6)            # the boundary lies within the extent
    s0, s1, z0, z1 = d.track_extent()
    assert s.min() >= s0 - 1e-12 and s.max() <= s1 + 1e-12 and z.min() >= z0 - 1e-12 and z.max() <= z1 + 1e-12
    assert max(s.max() - s1, s0 - s.min(), z.max() - z1, z0 - z.min()) > -2e-6   # and reaches it


def test_every_registered_outline_is_accepted_by_name():
    assert set(OUTLINES) == {"rectangle", "ellipse", "polygon"}
    with pytest.raises(SceneError, match="defect.shape: invalid value 'star'"):
        Defect.from_mapping({"shape": "star", "length_mm": 1, "width_mm": 1})


class Rhombus(Outline):
    """Worked example: a rhombus with diagonals L (along u) and B (along v)."""
    name = "rhombus"

    @classmethod
    def vertices(cls, defect):
        a, b = defect.length / 2, defect.width / 2
        return np.array([[-a, 0.0], [0.0, -b], [a, 0.0], [0.0, b]])

    @classmethod
    def contains(cls, defect, u, v):
        return np.abs(u) / (defect.length / 2) + np.abs(v) / (defect.width / 2) <= 1.0


def test_a_new_outline_is_one_registered_class(monkeypatch):
    monkeypatch.setitem(outlines.OUTLINES, "rhombus", Rhombus)
    d = Defect.from_mapping({"shape": "rhombus", "length_mm": 2.0, "width_mm": 1.0})
    assert _area(d) == pytest.approx(L * B / 2, rel=0.01)
    assert abs(polygon_area(Rhombus.vertices(d))) == pytest.approx(L * B / 2)
    (a, b), = d.centreline_intervals()                # the track centre line crosses it along L
    assert b - a == pytest.approx(L, rel=1e-6)
    skewed = Defect.from_mapping({"shape": "rhombus", "length_mm": 2.0, "width_mm": 1.0, "skew_deg": 90.0})
    (a, b), = skewed.centreline_intervals()           # turned a quarter: the centre line crosses B
    assert b - a == pytest.approx(B, rel=1e-6)
