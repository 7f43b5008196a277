"""Defect outlines: one class per shape, registered by name in :data:`OUTLINES`.

An outline knows its own geometry in the defect's local coordinates ``(u, v)`` (``u`` along
the length axis L, ``v`` along the width axis B, origin at the defect centre; SI units) and
how it is given in a scene.  Everything else -- the placement on the track (offset, skew),
the contact tables, the checks against the bearing -- is shape-independent and lives in
:class:`~bearing_lab.sim.defects.model.Defect`, which asks the outline named by its
``shape``.

Adding an outline: write a subclass of :class:`Outline` here, register it in ``OUTLINES``
and add its test; the scene key ``defect.shape`` then accepts its name.

Public API
----------
Outline                         -- the interface (class methods, no instances)
Rectangle, Ellipse, Polygon     -- the shapes shipped
OUTLINES                        -- {name: Outline subclass}
"""
from __future__ import annotations

import math

import numpy as np

from bearing_lab.errors import SceneError

__all__ = ["Outline", "Rectangle", "Ellipse", "Polygon", "OUTLINES"]


def finite(where, key, value, *, positive=False):
    """``value`` as a finite float (positive if asked), else a SceneError naming ``where.key``."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SceneError(f"{where}.{key}={value!r} is not a number") from None
    if not math.isfinite(x):
        raise SceneError(f"{where}.{key}={value!r} must be finite")
    if positive and not x > 0:
        raise SceneError(f"{where}.{key}={value!r} must be positive")
    return x


def polygon_area(v: np.ndarray) -> float:
    """Signed area of a closed polygon (shoelace formula), m²."""
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _segments_cross(p1, p2, p3, p4) -> bool:
    def orient(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    d1, d2 = orient(p3, p4, p1), orient(p3, p4, p2)
    d3, d4 = orient(p1, p2, p3), orient(p1, p2, p4)
    return (d1 * d2 < 0) and (d3 * d4 < 0)


def _edges_boundary(verts: np.ndarray, spacing: float, max_points: int) -> np.ndarray:
    pts = []
    for i in range(len(verts)):
        p, q = verts[i], verts[(i + 1) % len(verts)]
        n = int(min(max(math.hypot(*(q - p)) / spacing, 16), max_points))
        t = np.linspace(0, 1, n, endpoint=False)[:, None]
        pts.append(p + t * (q - p))
    return np.concatenate(pts)


class Outline:
    """One defect shape.  Every method takes the :class:`Defect` it describes (its
    ``length``, ``width``, ``vertices``, ``skew``, ``offset``)."""

    #: the scene's name of the shape (``defect.shape``)
    name = ""
    #: True if the outline is symmetric about both local axes (so the contact over it is even
    #: in the ball position when the defect is centred on the track or not skewed)
    symmetric = True
    #: True if the outline's axial reach follows from its extent (no boundary walk needed)
    exact_extent = True

    @classmethod
    def size_from_mapping(cls, m: dict, where: str):
        """(length m, width m, vertices (n, 2) m or None) from the scene keys, user units."""
        if "diameter_mm" in m:
            raise SceneError(f"{where}.diameter_mm is only for shape='ellipse' (a circle) "
                             "and replaces length_mm and width_mm")
        if "vertices_mm" in m:
            raise SceneError(f"{where}.vertices_mm is only used with shape='polygon'")
        for key in ("length_mm", "width_mm"):
            if key not in m:
                raise SceneError(f"{where}.{key} is required for shape={cls.name!r}")
        return (finite(where, "length_mm", m["length_mm"], positive=True) * 1e-3,
                finite(where, "width_mm", m["width_mm"], positive=True) * 1e-3, None)

    @classmethod
    def check(cls, defect, where: str):
        """Refuse an inconsistent defect; may return normalised vertices (or None)."""
        if defect.vertices is not None:
            raise SceneError(f"{where}.vertices is only used with shape='polygon', not with shape={cls.name!r}")
        return None

    @classmethod
    def vertices(cls, defect) -> np.ndarray:
        """Corners in local coordinates, (n, 2) m."""
        raise ValueError(f"a {cls.name} has no vertices")

    @classmethod
    def boundary(cls, defect, spacing: float, max_points: int) -> np.ndarray:
        """Boundary points (n, 2) in local coordinates, about ``spacing`` apart."""
        return _edges_boundary(cls.vertices(defect), spacing, max_points)

    @classmethod
    def contains(cls, defect, u, v) -> np.ndarray:
        """True where the local point (u, v) lies inside (boundary: either)."""
        raise NotImplementedError

    @classmethod
    def track_extent(cls, defect) -> tuple[float, float, float, float]:
        """(s_min, s_max, z_min, z_max) of the outline on the track, m."""
        s, z = defect.to_track(*cls.vertices(defect).T)
        return float(s.min()), float(s.max()), float(z.min()), float(z.max())


class Rectangle(Outline):
    """L × B rectangle, sides along the local axes."""
    name = "rectangle"

    @classmethod
    def vertices(cls, defect):
        a, b = defect.length / 2, defect.width / 2
        return np.array([[-a, -b], [a, -b], [a, b], [-a, b]])

    @classmethod
    def contains(cls, defect, u, v):
        return (np.abs(u) <= defect.length / 2) & (np.abs(v) <= defect.width / 2)


class Ellipse(Outline):
    """Ellipse with semi-axes L/2 (along u) and B/2 (along v); ``diameter_mm`` gives a circle."""
    name = "ellipse"

    @classmethod
    def size_from_mapping(cls, m, where):
        if "diameter_mm" in m:
            if "length_mm" in m or "width_mm" in m:
                raise SceneError(f"{where}.diameter_mm is only for shape='ellipse' (a circle) "
                                 "and replaces length_mm and width_mm")
            if "vertices_mm" in m:
                raise SceneError(f"{where}.vertices_mm is only used with shape='polygon'")
            d = finite(where, "diameter_mm", m["diameter_mm"], positive=True) * 1e-3
            return d, d, None
        return super().size_from_mapping(m, where)

    @classmethod
    def boundary(cls, defect, spacing, max_points):
        a, b = defect.length / 2, defect.width / 2
        perim = math.pi * (3 * (a + b) - math.sqrt((3 * a + b) * (a + 3 * b)))   # Ramanujan
        n = int(min(max(perim / spacing, 256), 4 * max_points))
        t = np.linspace(0, 2 * math.pi, n, endpoint=False)
        return np.column_stack([a * np.cos(t), b * np.sin(t)])

    @classmethod
    def contains(cls, defect, u, v):
        return (u / (defect.length / 2)) ** 2 + (v / (defect.width / 2)) ** 2 <= 1.0

    @classmethod
    def track_extent(cls, defect):
        a, b = defect.length / 2, defect.width / 2
        c, s_ = math.cos(defect.skew), math.sin(defect.skew)
        hs = math.hypot(a * c, b * s_)
        hz = math.hypot(a * s_, b * c)
        return -hs, hs, defect.offset - hz, defect.offset + hz


class Polygon(Outline):
    """Simple polygon given by its vertices ``[along, across]`` about the centre;
    ``length``/``width`` are its u/v extents."""
    name = "polygon"
    symmetric = False
    exact_extent = False

    @classmethod
    def size_from_mapping(cls, m, where):
        if "diameter_mm" in m:
            raise SceneError(f"{where}.diameter_mm is only for shape='ellipse' (a circle) "
                             "and replaces length_mm and width_mm")
        if "vertices_mm" not in m:
            raise SceneError(f"{where}.vertices_mm is required for shape='polygon'")
        raw = m["vertices_mm"]
        try:
            v = np.asarray(raw, dtype=float) * 1e-3
        except (TypeError, ValueError):
            raise SceneError(f"{where}.vertices_mm must be a list of [along, across] pairs of numbers") from None
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3:
            raise SceneError(f"{where}.vertices_mm must be a list of at least 3 [along, across] pairs, got {raw!r}")
        if not np.all(np.isfinite(v)):
            raise SceneError(f"{where}.vertices_mm must be finite, got {raw!r}")
        for key in ("length_mm", "width_mm"):
            if key in m:
                raise SceneError(f"{where}.{key} is not used with shape='polygon' (the vertices give the size)")
        length, width = float(np.ptp(v[:, 0])), float(np.ptp(v[:, 1]))
        if not (length > 0 and width > 0):
            raise SceneError(f"{where}.vertices_mm enclose no area")
        return length, width, v

    @classmethod
    def check(cls, defect, where):
        if defect.vertices is None:
            raise SceneError(f"{where}.vertices: a polygon defect needs at least 3 vertices")
        v = np.asarray(defect.vertices, dtype=float)
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3:
            raise SceneError(f"{where}.vertices must be a list of at least 3 [along, across] pairs, "
                             f"got shape {v.shape}")
        if not np.all(np.isfinite(v)):
            raise SceneError(f"{where}.vertices must be finite")
        if abs(polygon_area(v)) <= 0:
            raise SceneError(f"{where}.vertices enclose no area")
        n = len(v)
        for i in range(n):
            for j in range(i + 2, n):
                if not (i == 0 and j == n - 1) and _segments_cross(v[i], v[(i + 1) % n], v[j], v[(j + 1) % n]):
                    raise SceneError(f"{where}.vertices: the polygon intersects itself (edges {i} and {j})")
        return tuple(map(tuple, v.tolist()))

    @classmethod
    def vertices(cls, defect):
        return np.asarray(defect.vertices, dtype=float)

    @classmethod
    def contains(cls, defect, u, v):
        verts = cls.vertices(defect)
        inside = np.zeros(np.broadcast(u, v).shape, dtype=bool)
        n = len(verts)
        for i in range(n):       # even-odd ray casting along +u
            x1, y1 = verts[i]
            x2, y2 = verts[(i + 1) % n]
            if y1 == y2:
                continue
            crosses = (y1 > v) != (y2 > v)
            xint = x1 + (v - y1) * (x2 - x1) / (y2 - y1)
            inside ^= crosses & (u < xint)
        return inside


#: every outline a scene can name, by ``defect.shape``
OUTLINES: dict[str, type[Outline]] = {c.name: c for c in (Rectangle, Ellipse, Polygon)}
