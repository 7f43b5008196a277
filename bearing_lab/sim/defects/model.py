"""Defect description: an outline on a raceway surface, a depth, a position.

Why a separate, geometry-only object: the same :class:`Defect` feeds the rigid-drop
figure (:func:`~bearing_lab.sim.defects.geometry.rigid_drop`), the contact tables
(:func:`~bearing_lab.sim.defects.contact.contact_table`) and the scene validation, so
its coordinate conventions are stated once, here.

Coordinates (SI)
----------------
*Local* defect coordinates ``(u, v)``: ``u`` along the defect's length axis L, ``v``
along its width axis B, origin at the defect centre.

*Track* coordinates ``(s, z)`` on the raceway surface: ``s`` is arc length along the
track, measured at the groove-bottom radius of the race (``s = R_track * phi``) in the
direction of increasing angle ``phi``; ``z`` is the axial distance from the track centre
line. A local point maps to the track by a rotation through the skew angle and a shift by
the axial offset::

    s = u cos(theta) - v sin(theta)
    z = H + u sin(theta) + v cos(theta)

so ``theta = 0`` puts L along the track, and a positive ``theta`` turns the +u end of the
defect toward +z.  ``angle`` is where the defect centre sits around the ring (measured from
the load-zone centre; for the inner race, at t = 0); it does not enter the local geometry.

Depth is a flat floor: the floor is the intact surface moved ``depth`` radially into the
ring (outward for the outer race, inward for the inner race), so it keeps the groove's
shape.  The defect walls are radial.
"""
from __future__ import annotations

from dataclasses import dataclass, field
import math

import numpy as np

from bearing_lab.errors import SceneError, check_choice

from .geometry import RaceGeometry
from .outlines import OUTLINES, finite as _finite

RACES = ("outer", "inner", "ball")
#: the outline names a scene accepts (``defect.shape``): the registry in :mod:`.outlines`
SHAPES = tuple(OUTLINES)
#: Default defect depth (m): 0.5 mm.  The reference paper (Liu et al.) does not state one; any depth much larger
#: than the ball's drop (micrometres) gives the same response.
DEFAULT_DEPTH = 0.5e-3

_KEYS = ("race", "shape", "length_mm", "width_mm", "depth_mm", "offset_mm", "skew_deg",
         "angle_deg", "vertices_mm", "diameter_mm")


@dataclass(frozen=True)
class Defect:
    """A local defect on a raceway (or ball) surface; SI units.

    Attributes
    ----------
    race : "outer", "inner" or "ball".
    shape : "rectangle", "ellipse" (semi-axes L/2, B/2) or "polygon".
    length : L, m, along the defect's u axis (along the track when skew = 0).
    width : B, m, along the v axis (across the track when skew = 0).
    depth : m, flat floor (see the module docstring).
    angle : rad, defect centre around the ring from the load-zone centre (inner race:
        at t = 0; ball: initial angle of the defect on the ball, for the simulator).
    offset : H, m, axial offset of the defect centre from the track centre line.
    skew : theta, rad, angle between the L axis and the track centre line.
    vertices : polygon vertices in local (u, v) coordinates, m, shape (n, 2); None for
        rectangle and ellipse.  For a polygon, ``length``/``width`` are its u/v extents.
    """

    race: str = "outer"
    shape: str = "rectangle"
    length: float = 1e-3
    width: float = 1e-3
    depth: float = DEFAULT_DEPTH
    angle: float = 0.0
    offset: float = 0.0
    skew: float = 0.0
    vertices: tuple | None = field(default=None)

    def __post_init__(self):
        where = "defect"
        check_choice(self.race, RACES, f"{where}.race", SceneError)
        check_choice(self.shape, tuple(OUTLINES), f"{where}.shape", SceneError)
        for key, unit in (("length", "m"), ("width", "m"), ("depth", "m")):
            x = getattr(self, key)
            if not (isinstance(x, (int, float)) and math.isfinite(x) and x > 0):
                raise SceneError(f"{where}.{key}={x!r} {unit} must be positive and finite")
        for key in ("angle", "offset", "skew"):
            x = getattr(self, key)
            if not (isinstance(x, (int, float)) and math.isfinite(x)):
                raise SceneError(f"{where}.{key}={x!r} must be finite")
        vertices = self.outline.check(self, where)
        if vertices is not None:
            object.__setattr__(self, "vertices", vertices)

    @property
    def outline(self):
        """The outline class of this defect's shape (:mod:`.outlines`)."""
        return OUTLINES[self.shape]

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_mapping(cls, m: dict, *, where: str = "defect") -> "Defect":
        """Build a Defect from scene keys in user units.

        Keys: ``race`` ("outer"), ``shape`` ("rectangle"), ``length_mm``, ``width_mm``
        (required unless ``shape = "polygon"``; ``diameter_mm`` sets both for a circular
        ``ellipse``), ``depth_mm`` (0.5), ``offset_mm`` (0), ``skew_deg`` (0), ``angle_deg``
        (0), ``vertices_mm`` (polygon: list of [along, across] in mm, about the centre).
        """
        if not isinstance(m, dict):
            raise SceneError(f"{where} must be a table of keys, got {type(m).__name__}")
        unknown = sorted(set(m) - set(_KEYS))
        if unknown:
            raise SceneError(f"{where}: unknown key(s) {', '.join(unknown)}; allowed keys are "
                             f"{', '.join(_KEYS)}")
        race = m.get("race", "outer")
        shape = m.get("shape", "rectangle")
        check_choice(race, RACES, f"{where}.race", SceneError)
        check_choice(shape, tuple(OUTLINES), f"{where}.shape", SceneError)
        length, width, vertices = OUTLINES[shape].size_from_mapping(m, where)
        depth = _finite(where, "depth_mm", m.get("depth_mm", DEFAULT_DEPTH * 1e3), positive=True) * 1e-3
        offset = _finite(where, "offset_mm", m.get("offset_mm", 0.0)) * 1e-3
        skew = math.radians(_finite(where, "skew_deg", m.get("skew_deg", 0.0)))
        angle = math.radians(_finite(where, "angle_deg", m.get("angle_deg", 0.0)))
        if abs(skew) > math.pi / 2 + 1e-12:
            raise SceneError(f"{where}.skew_deg={m.get('skew_deg')!r} must lie in [-90, 90] "
                             "(the outline is symmetric under a half turn only for some shapes; "
                             "give a polygon for other orientations)")
        try:
            return cls(race=race, shape=shape, length=length, width=width, depth=depth,
                       angle=angle, offset=offset, skew=skew,
                       vertices=None if vertices is None else tuple(map(tuple, vertices.tolist())))
        except SceneError as exc:
            raise SceneError(str(exc).replace("defect.", f"{where}.")) from None

    # ------------------------------------------------------------------ outline
    def _local_boundary(self, spacing: float, max_points: int = 20000) -> np.ndarray:
        """Boundary points (n, 2) in local (u, v) coordinates, about ``spacing`` apart."""
        return self.outline.boundary(self, spacing, max_points)

    def local_vertices(self) -> np.ndarray:
        """Corners in local (u, v) coordinates (rectangle and polygon), shape (n, 2)."""
        return self.outline.vertices(self)

    def to_track(self, u, v):
        """Local (u, v) -> track (s, z), m."""
        c, s_ = math.cos(self.skew), math.sin(self.skew)
        u = np.asarray(u, dtype=float)
        v = np.asarray(v, dtype=float)
        return u * c - v * s_, self.offset + u * s_ + v * c

    def to_local(self, s, z):
        """Track (s, z) -> local (u, v), m."""
        c, s_ = math.cos(self.skew), math.sin(self.skew)
        s = np.asarray(s, dtype=float)
        zz = np.asarray(z, dtype=float) - self.offset
        return s * c + zz * s_, -s * s_ + zz * c

    def boundary_track(self, spacing: float = 2e-6) -> tuple[np.ndarray, np.ndarray]:
        """Outline points in track coordinates (s, z), about ``spacing`` m apart."""
        p = self._local_boundary(spacing)
        return self.to_track(p[:, 0], p[:, 1])

    def contains(self, s, z) -> np.ndarray:
        """True where the track point (s, z) lies inside the outline (boundary: either)."""
        u, v = self.to_local(s, z)
        return self.outline.contains(self, u, v)

    def track_extent(self) -> tuple[float, float, float, float]:
        """(s_min, s_max, z_min, z_max) of the outline in track coordinates, m."""
        return self.outline.track_extent(self)

    def min_abs_axial(self) -> float:
        """Smallest |z| over the outline (0 when it covers the track centre line), m."""
        s0, s1, z0, z1 = self.track_extent()
        if z0 <= 0 <= z1:
            # does the centre line actually cross the outline?
            ss = np.linspace(s0, s1, 4001)
            if np.any(self.contains(ss, np.zeros_like(ss))):
                return 0.0
        s, z = self.boundary_track(spacing=max(self.length, self.width) / 4000)
        return float(np.min(np.abs(z)))

    def centreline_intervals(self, n: int = 20001) -> list[tuple[float, float]]:
        """Intervals [s_a, s_b] (m) where the track centre line z = 0 crosses the outline."""
        s0, s1, z0, z1 = self.track_extent()
        if not (z0 <= 0 <= z1):
            return []
        ss = np.linspace(s0, s1, n)
        inside = self.contains(ss, np.zeros_like(ss))
        out = []
        i = 0
        while i < n:
            if inside[i]:
                j = i
                while j + 1 < n and inside[j + 1]:
                    j += 1
                a = ss[i] if i == 0 else self._refine_crossing(ss[i - 1], ss[i])
                b = ss[j] if j == n - 1 else self._refine_crossing(ss[j + 1], ss[j])
                if b > a:
                    out.append((float(a), float(b)))
                i = j + 1
            else:
                i += 1
        return out

    def _refine_crossing(self, s_out, s_in, iters=60):
        for _ in range(iters):
            mid = 0.5 * (s_out + s_in)
            if self.contains(mid, 0.0):
                s_in = mid
            else:
                s_out = mid
        return 0.5 * (s_out + s_in)

    # ------------------------------------------------------------------ checks
    def validate(self, bearing, *, where: str = "defect") -> "Defect":
        """Refuse a defect that does not fit the bearing; returns self.

        Checks: the outline stays on the ring (|z| <= width/2 everywhere; skipped when
        the bearing has no width); the depth is less than the ring's section under the
        groove bottom, ``(outer_diameter - pitch_diameter - ball_diameter)/2`` for the
        outer race and ``(pitch_diameter - ball_diameter - bore)/2`` for the inner race
        (``ball_diameter/2`` for a ball defect, and for a ring whose envelope is unknown);
        the length along the track is less than a quarter of the track circumference; a
        ball defect's outline fits in a quarter of the ball's circumference.
        """
        db, dm = bearing.ball_diameter, bearing.pitch_diameter
        s0, s1, z0, z1 = self.track_extent()
        if self.race == "ball":
            section = db / 2
            sec_txt = "ball_diameter/2"
            halfw = math.pi * db / 8
            reach = max(abs(z0), abs(z1), abs(s0), abs(s1))
            if reach > halfw + 1e-12:
                raise SceneError(f"{where}: the outline reaches {reach*1e3:.3f} mm "
                                 f"from the defect centre; on a ball of {db*1e3:.3f} mm keep it within "
                                 f"{halfw*1e3:.3f} mm (an eighth of the circumference)")
        else:
            if bearing.width is not None:
                zmax = max(abs(z0), abs(z1))
                if not self.outline.exact_extent:
                    _, zb = self.boundary_track(spacing=max(self.length, self.width) / 2000)
                    zmax = float(np.max(np.abs(zb)))
                if zmax > bearing.width / 2 * (1 + 1e-9):
                    raise SceneError(
                        f"{where}: the outline leaves the ring: it reaches |axial| = {zmax*1e3:.3f} mm "
                        f"from the track centre line but the ring is {bearing.width*1e3:.3f} mm wide "
                        f"(limit {bearing.width/2*1e3:.3f} mm); reduce {where}.width_mm, "
                        f"{where}.offset_mm or {where}.skew_deg")
            if self.race == "outer" and bearing.outer_diameter is not None:
                section = (bearing.outer_diameter - dm - db) / 2
                sec_txt = "(outer_diameter - pitch_diameter - ball_diameter)/2"
            elif self.race == "inner" and bearing.bore is not None:
                section = (dm - db - bearing.bore) / 2
                sec_txt = "(pitch_diameter - ball_diameter - bore)/2"
            else:
                section = db / 2
                sec_txt = "ball_diameter/2 (ring envelope unknown)"
            track_r = dm / 2 + (db / 2 if self.race == "outer" else -db / 2)
            if s1 - s0 > math.pi * track_r / 2:
                raise SceneError(f"{where}.length_mm: the defect spans {(s1 - s0)*1e3:.2f} mm along the "
                                 f"track, more than a quarter of the {self.race} track "
                                 f"({math.pi*track_r/2*1e3:.2f} mm)")
        if self.depth >= section:
            raise SceneError(f"{where}.depth_mm={self.depth*1e3:.4g} is not less than the section "
                             f"under the groove, {sec_txt} = {section*1e3:.4g} mm")
        return self

    def misses_track(self, bearing, delta_max: float, *, clearance: float = 0.0) -> bool:
        """True if no point of the outline can enter the contact at approach <= delta_max.

        The ball passes every angular position on the track centre line, so a point of the
        outline can be reached only if its axial gap to the ball, h(0, z), is below
        ``delta_max``.  Such a defect gives the healthy response.
        """
        g = RaceGeometry.from_bearing(bearing, self.race if self.race != "ball" else "outer",
                                      clearance=clearance)
        zmin = self.min_abs_axial()
        return bool(g.approach(0.0, zmin) >= delta_max)
