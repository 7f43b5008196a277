"""Exact 3-D geometry of a rigid ball in a toroidal groove with a defect removed.

Why exact rather than paraboloidal: the rigid drops of a 6308 ball into small defects
are fractions of a micrometre (checked against a brute-force grid computation over the
raceway, tests/sim/test_defect_geometry.py), and the outer groove is so conformal (r_o = 0.53 D_b) that small
differences in
the across-track curvature matter.  The exact formulas cost no more than the
approximations once vectorised.

Geometry
--------
The raceway is a surface of revolution about the bearing axis.  In cylindrical
coordinates (r, phi, z) the groove is a torus: its cross-section is a circle of radius
``r_g`` (``f * D_b``) centred at radius ``R_c`` in the plane z = 0, and the groove bottom
(the track centre line) is at radius ``R``:

* outer race: ``R = d_m/2 + D_b/2 + clearance/4``, ``R_c = R - r_g``,
  surface ``r_s(z) = R_c + sqrt(r_g^2 - z^2)`` (concave along and across the track);
* inner race: ``R = d_m/2 - D_b/2 - clearance/4``, ``R_c = R + r_g``,
  surface ``r_s(z) = R_c - sqrt(r_g^2 - z^2)`` (convex along, concave across).

The ball (radius ``r_b = D_b/2``) has its centre in the plane z = 0 at radius ``rho`` and
angle ``phi_b``.  Its *approach* ``delta`` is its radial movement toward the race from
the position where it just touches the intact groove bottom (``rho0 = R - r_b`` outer,
``R + r_b`` inner): outward for the outer race, inward for the inner race.

For a surface point at (r, phi, z) with ``dphi = phi - phi_b``, the approach at which the
ball first touches it is (distance from the centre equal to r_b, first root met)::

    outer:  h = r cos(dphi) - sqrt(r_b^2 - z^2 - r^2 sin^2(dphi)) - rho0
    inner:  h = rho0 - r cos(dphi) - sqrt(r_b^2 - z^2 - r^2 sin^2(dphi))

(``+inf`` where the square root is imaginary: the ball cannot reach the point).  This
``h`` is the gap function of every model in :mod:`.contact`; on the intact surface it is
``~ s^2/(2 R_x) + z^2/(2 R_y)`` with ``1/R_x = 1/r_b -+ 1/R`` and
``1/R_y = 1/r_b - 1/r_g``.

Rigid drop
----------
With a defect removed, the ball at angular position psi (centre over the point
(s = R psi, z = 0)) can move out to the smallest ``h`` over the remaining surface.  If the
point under its centre is intact that is 0.  Otherwise, as ``h`` has a single minimum under
the ball centre and connected sub-level sets, the minimum over the remaining intact surface
lies on the defect outline; the floor (the groove moved by ``depth``) contributes
``depth`` (its minimum, under the ball centre); the radial walls never come first because
``h`` grows with depth below the rim.  So ``drop(psi) = min(min over outline of h, depth)``,
evaluated on an outline sampled every 2 µm or finer (error below 1e-12 m for the
tested cases).  The ball stays on the track centre line (z = 0), so at H = B/2 the drop is
0: a flank at the centre line still holds the ball.
"""
from __future__ import annotations

from dataclasses import dataclass, field
import math

import lazy_loader as lazy
import numpy as np

from bearing_lab.errors import SceneError, check_choice

# ``Defect`` in the annotations is :class:`.model.Defect` (model imports this module, not the reverse)

# only the exact Hertz semi-axes need them (sim/numerics.py serves the simulator's own)
_optimize = lazy.load("scipy.optimize", suppress_warning=True)
_special = lazy.load("scipy.special", suppress_warning=True)


@dataclass(frozen=True)
class RaceGeometry:
    """Groove geometry of one race, SI.  See the module docstring for the formulas."""

    race: str               # "outer" or "inner"
    ball_radius: float      # r_b
    groove_radius: float    # r_g = f * D_b
    track_radius: float     # R, groove-bottom radius
    #: reach() by approach (a cache, not part of the geometry)
    _reach_memo: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    @classmethod
    def from_bearing(cls, bearing, race: str, *, clearance: float = 0.0) -> "RaceGeometry":
        check_choice(race, ("outer", "inner"), "race", SceneError)
        db, dm = bearing.ball_diameter, bearing.pitch_diameter
        # negative: a preload (the groove bottoms move towards the balls by |clearance| / 4)
        if not (math.isfinite(clearance) and abs(clearance) < 0.1 * db):
            raise SceneError(f"radial clearance {clearance * 1e6:g} µm: must be finite and within ± a tenth of "
                             f"the ball diameter (±{0.1 * db * 1e6:.0f} µm; negative is a preload)")
        if race == "outer":
            return cls("outer", db / 2, bearing.outer_conformity * db, dm / 2 + db / 2 + clearance / 4)
        return cls("inner", db / 2, bearing.inner_conformity * db, dm / 2 - db / 2 - clearance / 4)

    @property
    def sign(self) -> float:
        """+1 for the outer race (concave along the track), -1 for the inner race."""
        return 1.0 if self.race == "outer" else -1.0

    @property
    def centre_radius(self) -> float:
        return self.track_radius - self.sign * self.groove_radius

    @property
    def rho0(self) -> float:
        """Ball-centre radius at first contact with the intact groove bottom."""
        return self.track_radius - self.sign * self.ball_radius

    @property
    def rx(self) -> float:
        """Along-track radius of relative curvature, 1/R_x = 1/r_b -+ 1/R (m)."""
        return 1.0 / (1.0 / self.ball_radius - self.sign / self.track_radius)

    @property
    def ry(self) -> float:
        """Across-track radius of relative curvature, 1/R_y = 1/r_b - 1/r_g (m)."""
        return 1.0 / (1.0 / self.ball_radius - 1.0 / self.groove_radius)

    @property
    def z_limit(self) -> float:
        """Largest |z| at which the groove exists and the ball can reach, m."""
        return 0.999 * min(self.ball_radius, self.groove_radius)

    def surface_radius(self, z, depth=0.0):
        """Radius of the groove surface (moved ``depth`` into the ring) at axial z."""
        z = np.asarray(z, dtype=float)
        root = np.sqrt(np.maximum(self.groove_radius ** 2 - z * z, 0.0))
        return self.centre_radius + self.sign * (root + depth)

    def approach(self, dphi, z, depth=0.0):
        """Approach (m) at which the ball first touches the surface point (dphi, z).

        ``dphi``: angle of the point minus the ball-centre angle (rad); ``depth``: the
        point lies on the groove moved that far into the ring.  +inf where unreachable.
        """
        dphi = np.asarray(dphi, dtype=float)
        z = np.asarray(z, dtype=float)
        r = self.surface_radius(z, depth)
        sn = np.sin(dphi)
        arg = self.ball_radius ** 2 - z * z - (r * sn) ** 2
        ok = (arg >= 0) & (np.abs(z) < self.groove_radius) & (np.cos(dphi) > 0)
        root = np.sqrt(np.where(ok, arg, 0.0))
        rc = r * np.cos(dphi)
        if self.race == "outer":
            h = (rc - self.rho0) - root
        else:
            h = (self.rho0 - rc) - root
        return np.where(ok, h, np.inf)

    def reach(self, delta: float) -> tuple[float, float]:
        """(along, across) half-extents (m) of the region where h < delta, exact torus.

        In closed form: along the track (z = 0) with x = R sin(phi) the gap is
        ``+-(sqrt(R^2 - x^2) - rho0) - sqrt(r_b^2 - x^2)`` and across it (phi = 0)
        ``(r_b - r_g) + sqrt(r_g^2 - z^2) - sqrt(r_b^2 - z^2)``: on each axis h = delta fixes the
        sum or difference of the two roots and so their difference of squares fixes the other,
        which gives ``R - U = r_g - U' = delta (2 r_b - delta) / (2 c)`` without cancellation (U,
        U' the outer roots, c their sum or difference).  Bounded by where the ball can reach.
        Remembered per approach: a table asks for the same ones often.
        """
        key = float(delta)
        hit = self._reach_memo.get(key)
        if hit is not None:
            return hit
        d, rb, rg, R = max(key, 0.0), self.ball_radius, self.groove_radius, self.track_radius
        c = d + self.rho0 if self.race == "outer" else self.rho0 - d
        e = d * (2 * rb - d) / (2 * c)                      # R - U
        x = math.sqrt(max(e * (2 * R - e), 0.0))
        along = R * math.asin(min(x, rb) / R)
        e = d * (2 * rb - d) / (2 * (d + rg - rb))          # r_g - U'
        across = min(math.sqrt(max(e * (2 * rg - e), 0.0)), self.z_limit)
        if len(self._reach_memo) < 4096:
            self._reach_memo[key] = (along, across)
        return along, across


def hertz_semi_axes(geom: RaceGeometry, delta) -> tuple[np.ndarray, np.ndarray]:
    """Hertz contact semi-axes (a across the track, b along it), m, at approach ``delta``.

    Independent of the elastic constants: with the curvatures A = 1/(2 R_y) (across) and
    B = 1/(2 R_x) (along), the eccentricity e solves
    ``B/A = ((a/b)^2 E(e) - K(e)) / (K(e) - E(e))`` and ``a^2 = delta (K - E) / (A e^2 K)``,
    ``b = a sqrt(1 - e^2)`` (Johnson, Contact Mechanics, eqs 3.58-3.60; K, E complete
    elliptic integrals of modulus e).  6308 outer race at 4.382 µm (300 N): 0.90 x 0.16 mm.
    """
    A, B = 0.5 / geom.ry, 0.5 / geom.rx
    if B <= A:
        raise ValueError("the along-track curvature must exceed the across-track one")

    def f(m):       # m = e^2
        K, E = _special.ellipk(m), _special.ellipe(m)
        return (E / (1 - m) - K) / (K - E) - B / A
    m = _optimize.brentq(f, 1e-12, 1 - 1e-15, xtol=1e-16, rtol=1e-14, maxiter=500)
    K, E = _special.ellipk(m), _special.ellipe(m)
    delta = np.asarray(delta, dtype=float)
    a = np.sqrt(np.maximum(delta, 0.0) * (K - E) / (A * m * K))
    return a, a * math.sqrt(1 - m)


def _boundary_points(defect: Defect, geom: RaceGeometry, spacing: float | None = None):
    if spacing is None:
        spacing = min(2e-6, min(defect.length, defect.width) / 500)
    s, z = defect.boundary_track(spacing=spacing)
    keep = np.abs(z) < geom.z_limit
    return s[keep], z[keep]


#: ball positions x outline points above which :func:`drop_profile_2d` takes its compiled pass (below,
#: loading the kernel costs more than numpy's pass: e.g. :func:`rigid_drop`'s one position)
_COMPILED_PAIRS = 200_000


def drop_profile_2d(defect: Defect, geom: RaceGeometry, psi, *, chunk: int = 64,
                    psi_radius: float | None = None) -> np.ndarray:
    """Rigid-ball drop (m) at ball positions ``psi`` (rad from the defect centre), 3-D.

    ``drop = 0`` where the point under the ball centre is intact; otherwise the smallest
    approach over the defect outline, capped by the depth (the floor).  ``psi_radius``
    converts psi to arc length on the defected body (default: the groove bottom; the ball
    radius for a ball defect, whose outline is laid on the contact plane).
    """
    psi = np.atleast_1d(np.asarray(psi, dtype=float))
    R = geom.track_radius
    Rp = R if psi_radius is None else psi_radius
    inside = defect.contains(psi * Rp, np.zeros_like(psi))
    out = np.zeros_like(psi)
    if not np.any(inside):
        return out
    sb, zb = _boundary_points(defect, geom)
    if sb.size == 0:
        out[inside] = defect.depth
        return out
    idx = np.flatnonzero(inside)
    if idx.size * sb.size > _COMPILED_PAIRS:
        # the outline points within a rounding margin of the lowest, found by a compiled pass
        # (:func:`._halfspace_kernels.outline_candidates`), and ``approach`` on those only
        from ._halfspace_kernels import outline_candidates
        a, b = sb / R, Rp * psi[idx] / R
        cap = max(4096, 16 * idx.size)
        cj, ck = np.empty(cap, dtype=np.int64), np.empty(cap, dtype=np.int64)
        n = outline_candidates(np.sin(a), np.cos(a), zb * zb, geom.surface_radius(zb), np.sin(b), np.cos(b),
                               geom.ball_radius ** 2, geom.rho0, geom.race == "outer", 1e-12, cj, ck)
        if n >= 0:
            lowest = np.full(idx.size, np.inf)
            j, k = cj[:n], ck[:n]
            np.minimum.at(lowest, j, geom.approach((sb[k] - Rp * psi[idx[j]]) / R, zb[k]))
            out[idx] = np.clip(lowest, 0.0, defect.depth)
            return out
    for i in range(0, idx.size, chunk):
        j = idx[i:i + chunk]
        h = geom.approach((sb[None, :] - Rp * psi[j, None]) / R, zb[None, :])
        out[j] = np.clip(h.min(axis=1), 0.0, defect.depth)
    return out


def drop_profile_1d(defect: Defect, geom: RaceGeometry, psi, *,
                    psi_radius: float | None = None) -> np.ndarray:
    """Drop (m) for the along-track reduction of the defect ("profile" model).

    The defect is replaced by its intervals along the track centre line, each extended to
    a full-width slot; the ball is held by the slot's radial edge lines (minimum of h over
    each edge line, all z) or by the floor.  Exact for a full-width slot.
    """
    psi = np.atleast_1d(np.asarray(psi, dtype=float))
    R = geom.track_radius
    Rp = R if psi_radius is None else psi_radius
    out = np.zeros_like(psi)
    intervals = defect.centreline_intervals()
    if not intervals:
        return out
    s = psi * Rp
    inside = np.zeros(psi.shape, dtype=bool)
    for a, b in intervals:
        inside |= (s >= a) & (s <= b)
    if not np.any(inside):
        return out
    edges = np.array([e for ab in intervals for e in ab])
    j = np.flatnonzero(inside)
    dphi = (edges[None, :, None] - Rp * psi[j, None, None]) / R
    # minimum over each full-width edge line: coarse scan in z, then a fine one around it
    z = np.linspace(-geom.z_limit, geom.z_limit, 401)
    h = geom.approach(dphi, z[None, None, :])
    zc = z[np.argmin(h, axis=2)]                                  # (n, n_edges)
    dz = z[1] - z[0]
    zf = zc[:, :, None] + np.linspace(-dz, dz, 401)[None, None, :]
    hf = geom.approach(dphi, zf)
    out[j] = np.clip(np.minimum(h.min(axis=2), hf.min(axis=2)).min(axis=1), 0.0, defect.depth)
    return out


def rigid_drop(defect: Defect, bearing, *, clearance: float = 0.0,
               against: str | None = None) -> float:
    """How far (m) a rigid ball centred over the defect moves out before it touches.

    The ball centre is at the defect centre's angular position and on the track centre
    line (z = 0), exact sphere in the exact torus groove (see the module docstring).  For
    the 6308 outer race and a 1 x 1 mm, 0.5 mm deep defect this is 0.9413 µm.  A ball defect needs ``against``
    ("outer" or "inner"): the defect
    centre at the contact point, its outline laid on the contact plane (first order).
    """
    if defect.race == "ball":
        if against not in ("outer", "inner"):
            raise SceneError(f"a ball defect needs against='outer' or 'inner', got {against!r}")
        geom = RaceGeometry.from_bearing(bearing, against, clearance=clearance)
    else:
        geom = RaceGeometry.from_bearing(bearing, defect.race, clearance=clearance)
    return float(drop_profile_2d(defect, geom, [0.0])[0])
