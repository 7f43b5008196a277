"""Half-space share curve of a SKEWED rectangle on a grid aligned with its sides.

Why: on the track-aligned grid of :mod:`.halfspace` a rectangle whose sides are inclined to
the track is resolved by its cells' centres: a staircase.  When the outline moves (its
skew or offset changes by a fraction of a cell) whole cells flip between pit and surface
at once, so the share of the load jumps instead of following the geometry, and the
two-grid extrapolation to zero cell size cannot be used (the error is not a power of the
cell size).

How: the Boussinesq influence of a uniformly loaded rectangle depends only on the
relative position of the two cells, whatever the grid's orientation, so the contact can
be solved on cells rotated with the defect (sides along its length and width axes,
Love's rectangle solution as before).  The grid is anchored to the defect: the cell
boundaries fall on the outline's sides, ``L / n_u`` and ``W / n_v`` apart; for each ball
position the window of cells covering the rigid interpenetration region is taken from
that anchored grid, so the outline is always resolved exactly and only the intact
surface's gap is sampled at positions that move with the ball (where the pressure falls
to zero smoothly at the contact's edge).  The intact force is taken on the same cells,
relative to the ball, as the defect's (:class:`IntactForce`), so the share compares like
with like.  The error is then first
order in the cell size, as for the aligned rectangle, and the same Richardson
extrapolation applies.

Cell sizes: the track-aligned grid's cells (``2 a_reach / n_across`` across,
``2 b_reach / n_along`` along) projected on the rotated axes, so the rotated grid resolves
the contact's variation along and across the track as finely as the aligned one
(1/du^2 = cos^2/dy^2 + sin^2/dx^2, and likewise for dv), then rounded so that a whole
number of cells spans the length and the width.
"""
from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from .geometry import RaceGeometry
from .halfspace import (COARSE_STEP, REFINE_TOL, SOLVE_TOL, TABLE_CELLS, HalfSpace, _curve, _refine, _symmetry,
                        contact_grid, e_star_of, hertz_start, pressure_semi_axes)
from .model import Defect

#: odd sizes of the lattice of the ball's sub-cell offsets on which the intact force is solved:
#: on grids of at least the tables' cells, and on the coarser Richardson partner (where the force
#: spreads several times more over the offsets)
INTACT_LATTICE = (3, 5)


@dataclass(frozen=True)
class SkewedGrid:
    """Cells du x dv along the defect's length (u) and width (v) axes; the window is
    nu x nv cells; n_u x n_v cells cover the outline exactly."""

    du: float
    dv: float
    nu: int
    nv: int
    n_u: int
    n_v: int


def skewed_grid(defect: Defect, geom: RaceGeometry, delta: float,
                cells: tuple[int, int]) -> SkewedGrid:
    """The defect-anchored grid for approach ``delta`` (see the module docstring); the
    window covers the interpenetration region ``{h < delta}`` with one cell to spare on
    every side for any ball position (checked on its border at the defect centre)."""
    b_r, a_r = geom.reach(delta)
    dx, dy = 2 * a_r / cells[0], 2 * b_r / cells[1]
    c, sn = abs(math.cos(defect.skew)), abs(math.sin(defect.skew))
    du_t = 1.0 / math.hypot(c / dy, sn / dx)
    dv_t = 1.0 / math.hypot(sn / dy, c / dx)
    n_u = max(1, round(defect.length / du_t))
    n_v = max(1, round(defect.width / dv_t))
    du, dv = defect.length / n_u, defect.width / n_v
    # half-extents of the (near-elliptic) interpenetration region on the rotated axes
    hu = math.hypot(b_r * c, a_r * sn)
    hv = math.hypot(b_r * sn, a_r * c)
    nu = math.ceil(2 * hu / du) + 4
    nv = math.ceil(2 * hv / dv) + 4
    while True:
        g = SkewedGrid(du, dv, nu, nv, n_u, n_v)
        g0 = window(defect, geom, g, 0.0)[0]
        border = np.concatenate([g0[:2].ravel(), g0[-2:].ravel(), g0[:, :2].ravel(), g0[:, -2:].ravel()])
        if np.all(border >= delta):
            return g
        nu, nv = nu + 2, nv + 2


def _anchor(defect: Defect, g: SkewedGrid, s_ball: float):
    """First window cell (i0, j0) on the anchored grid for the ball at track position
    ``s_ball`` (m from the defect centre) and the ball's offset (fu, fv) in cells from the
    window's centre: the window's cells relative to the ball depend only on (fu, fv)."""
    c, sn = math.cos(defect.skew), math.sin(defect.skew)
    # the ball centre (s_ball, z = 0) in local coordinates
    u_b = s_ball * c - defect.offset * sn
    v_b = -s_ball * sn - defect.offset * c
    xu = (u_b + defect.length / 2) / g.du - g.nu / 2
    xv = (v_b + defect.width / 2) / g.dv - g.nv / 2
    i0, j0 = math.floor(xu), math.floor(xv)
    return i0, j0, xu - i0, xv - j0


def _track_coords(skew: float, g: SkewedGrid, fu: float, fv: float):
    """Window cell centres relative to the ball: (S along the track, Z across it) (m)."""
    c, sn = math.cos(skew), math.sin(skew)
    dU = (np.arange(g.nu) + 0.5 - g.nu / 2 - fu) * g.du
    dV = (np.arange(g.nv) + 0.5 - g.nv / 2 - fv) * g.dv
    UU, VV = np.meshgrid(dU, dV, indexing="ij")
    return UU * c - VV * sn, UU * sn + VV * c


def _kernels():
    """The compiled kernels (:mod:`._halfspace_kernels`), loaded at the first solve (7 ms)."""
    from . import _halfspace_kernels
    return _halfspace_kernels


def _groove(geom: RaceGeometry):
    """The groove's numbers the compiled gap takes (``torus_gap``'s arguments after ``depth``)."""
    return (geom.track_radius, geom.ball_radius, geom.groove_radius, geom.centre_radius, geom.sign,
            geom.rho0, geom.race == "outer")


def _gap(geom: RaceGeometry, S, Z, depth=0.0):
    """The intact (or, ``depth`` into the ring, the floor's) gap (m) at track positions S, Z
    relative to the ball; 1.0 where the ball cannot reach (compiled ``geom.approach``)."""
    S, Z = np.broadcast_arrays(np.asarray(S, dtype=float), np.asarray(Z, dtype=float))
    out = np.empty(S.shape)
    _kernels().torus_gap(np.ascontiguousarray(S).ravel(), np.ascontiguousarray(Z).ravel(), float(depth),
                         *_groove(geom), out.reshape(-1))
    return out


def window(defect: Defect, geom: RaceGeometry, g: SkewedGrid, s_ball: float):
    """Intact gap, floor gap (m; inside the outline, the intact gap elsewhere) and the
    in-outline mask on the window of cells around the ball at track position ``s_ball``
    (m from the defect centre); arrays (nu, nv)."""
    gi, gf, ins, _ = windows(defect, geom, g, np.array([s_ball]))
    return gi[0], gf[0], ins[0]


def windows(defect: Defect, geom: RaceGeometry, g: SkewedGrid, s_balls: np.ndarray):
    """:func:`window` for K ball positions at once (one pass of the gap formula; the floor's
    gap inside the outline only, the intact gap elsewhere): arrays (K, nu, nv), and the ball's sub-cell offsets
    (fu, fv) (each (K,), see :func:`_anchor`)."""
    c, sn = math.cos(defect.skew), math.sin(defect.skew)
    s_balls = np.asarray(s_balls, dtype=float)
    xu = ((s_balls * c - defect.offset * sn) + defect.length / 2) / g.du - g.nu / 2
    xv = ((-s_balls * sn - defect.offset * c) + defect.width / 2) / g.dv - g.nv / 2
    i0, j0 = np.floor(xu), np.floor(xv)
    fu, fv = xu - i0, xv - j0
    dU = (np.arange(g.nu)[None, :] + 0.5 - g.nu / 2 - fu[:, None]) * g.du
    dV = (np.arange(g.nv)[None, :] + 0.5 - g.nv / 2 - fv[:, None]) * g.dv
    UU, VV = dU[:, :, None], dV[:, None, :]
    S, Z = UU * c - VV * sn, UU * sn + VV * c
    iu = i0[:, None] + np.arange(g.nu)[None, :]
    jv = j0[:, None] + np.arange(g.nv)[None, :]
    ins = ((iu >= 0) & (iu < g.n_u))[:, :, None] & ((jv >= 0) & (jv < g.n_v))[:, None, :]
    S, Z = np.broadcast_arrays(S, Z)
    gi = _gap(geom, S, Z)
    gf = gi.copy()          # the floor's gap is read inside the outline only
    gf[ins] = _gap(geom, S[ins], Z[ins], defect.depth)
    return gi, gf, ins, (fu, fv)


def window_gaps(defect: Defect, geom: RaceGeometry, g: SkewedGrid, s_balls: np.ndarray, delta: float):
    """The windows of :func:`windows` as a ratio curve reads them at approach ``delta``, in one compiled
    pass (:func:`._halfspace_kernels.window_gaps`): the gap (the floor's on the cells inside the
    outline whose intact gap is below ``delta``, the intact one elsewhere), those cells, (K, nu, nv),
    and the ball's sub-cell offsets (fu, fv)."""
    c, sn = math.cos(defect.skew), math.sin(defect.skew)
    s_balls = np.asarray(s_balls, dtype=float)
    xu = ((s_balls * c - defect.offset * sn) + defect.length / 2) / g.du - g.nu / 2
    xv = ((-s_balls * sn - defect.offset * c) + defect.width / 2) / g.dv - g.nv / 2
    gap = np.empty((s_balls.size, g.nu, g.nv))
    ins = np.empty(gap.shape, dtype=bool)
    fu, fv = np.empty(s_balls.size), np.empty(s_balls.size)
    _kernels().window_gaps(xu, xv, g.du, g.dv, c, sn, g.n_u, g.n_v, float(delta), float(defect.depth),
                           *_groove(geom), gap, ins, fu, fv)
    return gap, ins, (fu, fv)


class IntactForce:
    """The intact contact's force on the window as a function of the ball's sub-cell offset.

    The window's cells relative to the ball depend only on its offset (fu, fv) in [0, 1)^2
    (:func:`_anchor`), and a whole cell's shift gives the same contact, so the intact force
    is periodic in both, and even (the offsets (fu, fv) and (-fu, -fv) see the same contact
    turned by 180 degrees: forces within 4e-8).  It is solved on an m x m lattice of offsets
    (one of each even pair, (m^2 + 1) / 2 solves in one batch, started from the intact
    pressure ``p0`` at another offset) and read between them by trigonometric interpolation, instead of one intact
    solve per ball position (which
    doubled a table's solves).  On the tables' grids the force spreads by 0.03 % (fine) to
    0.17 % (coarse) over the offsets (up to 0.3 % on paper-O2's coarse grids); the lattice
    (:data:`INTACT_LATTICE`: 3 x 3 on the fine grid, whose solves cost three times the coarse
    grid's, 5 x 5 on the coarse one) reads it within 1.5e-4 (fine) and 4.6e-4 (coarse) of a
    solve at the ball's own offset (paper-O2 at 30 and 60 degrees, 5-150 % of the loaded
    range)."""

    def __init__(self, hs, geom: RaceGeometry, skew: float, g: SkewedGrid, delta: float,
                 m: int, tol: float, p0: np.ndarray):
        if m % 2 == 0:
            raise ValueError(f"the intact-force lattice needs an odd size, got {m}")
        # the intact gap is even in (s, z) together, and so is the force in (fu, fv): the
        # offsets (a, b) and (-a, -b) (mod 1) see the same contact, mirrored; one is solved
        half = [(a, b) for a in range(m) for b in range(m) if (a, b) <= ((-a) % m, (-b) % m)]
        gaps = np.array([_gap(geom, *_track_coords(skew, g, a / m, b / m)) for a, b in half])
        p, its = hs.solve_batch(gaps, delta, tol=tol, p0=np.broadcast_to(p0, gaps.shape))
        self.solves, self.iterations = len(half), int(its.sum())
        force = np.empty((m, m))
        for (a, b), fk in zip(half, p.sum(axis=(1, 2))):
            force[a, b] = force[(-a) % m, (-b) % m] = fk
        self.coef = np.fft.fft2(force) / (m * m)
        self.k = np.fft.fftfreq(m, 1.0 / m)      # m odd: no Nyquist term

    def __call__(self, fu, fv):
        """The force at the offsets (fu, fv): a float, or an array for arrays of offsets."""
        if np.ndim(fu) == 0:
            eu = np.exp(2j * np.pi * self.k * fu)
            ev = np.exp(2j * np.pi * self.k * fv)
            return float((eu @ self.coef @ ev).real)
        eu = np.exp(2j * np.pi * self.k[None, :] * np.asarray(fu)[:, None])
        ev = np.exp(2j * np.pi * self.k[None, :] * np.asarray(fv)[:, None])
        return np.einsum("ka,ab,kb->k", eu, self.coef, ev).real


def _intact_diagnostics(defect: Defect, g: SkewedGrid, p: np.ndarray):
    """Intact force (N) and semi-axes (a across, b along the track; m, from the pressure's
    moments) of the intact pressure ``p`` on the window of the ball at the defect centre."""
    fu, fv = _anchor(defect, g, 0.0)[2:]
    S, Z = _track_coords(defect.skew, g, fu, fv)
    c, sn = math.cos(defect.skew), math.sin(defect.skew)
    # a rotated cell's own second moments across and along the track
    dz, ds = math.hypot(sn * g.du, c * g.dv), math.hypot(c * g.du, sn * g.dv)
    return float(p.sum()) * g.du * g.dv, pressure_semi_axes(p, Z, S, dz, ds)


def ratio_curve_skewed(defect: Defect, geom: RaceGeometry, delta: float, *, cells=TABLE_CELLS,
                       e_star: float | None = None, tol: float = SOLVE_TOL, refine_tol: float = REFINE_TOL,
                       coarse_step: int = COARSE_STEP):
    """:func:`.halfspace.ratio_curve` for a rectangle inclined to the track: the same
    returns, computed on the defect-anchored rotated grid.  Ball positions are whole
    numbers of the track-aligned grid's along-track cells from the defect centre."""
    e_star = e_star_of() if e_star is None else e_star
    step = contact_grid(None, geom, delta, cells).dy
    g = skewed_grid(defect, geom, delta, cells)
    hs = HalfSpace(g.nu, g.nv, g.du, g.dv, e_star)
    g0, _, _ = window(defect, geom, g, 0.0)
    S0, Z0 = _track_coords(defect.skew, g, *_anchor(defect, g, 0.0)[2:])
    p_ref, _ = hs.solve(g0, delta, tol=tol, p0=hertz_start(hs, geom, g0, Z0, S0, delta))
    force, axes = _intact_diagnostics(defect, g, p_ref)
    b_r = geom.reach(delta)[0]
    s0, s1, _, _ = defect.track_extent()
    k_lo = math.floor((s0 - 1.05 * b_r) / step) - 1
    k_hi = math.ceil((s1 + 1.05 * b_r) / step) + 1
    if _symmetry(defect):
        k_lo = max(k_lo, 0)
    solved: dict[int, tuple[float, np.ndarray]] = {}
    m = INTACT_LATTICE[0] if cells[0] >= TABLE_CELLS[0] else INTACT_LATTICE[1]
    intact = IntactForce(hs, geom, defect.skew, g, delta, m, tol, p_ref)
    stats = {"solves": intact.solves, "iterations": intact.iterations}

    def solve_round(ks, starts):
        gap, ins, (fu, fv) = window_gaps(defect, geom, g, np.asarray(ks) * step, delta)
        meets = ins.any(axis=(1, 2))
        touches = (gap < delta).any(axis=(1, 2))
        todo = np.flatnonzero(meets & touches)
        for i in np.flatnonzero(~meets):
            solved[ks[i]] = (1.0, p_ref)
        for i in np.flatnonzero(meets & ~touches):
            solved[ks[i]] = (0.0, np.zeros_like(p_ref))
        if todo.size:
            p, its = hs.solve_batch(gap[todo], delta, tol=tol, p0=np.array([starts[i] for i in todo]))
            stats["solves"] += todo.size
            stats["iterations"] += int(its.sum())
            for i, pk, fk in zip(todo, p, intact(fu[todo], fv[todo])):
                solved[ks[i]] = (float(pk.sum()) / fk, pk)

    _refine(solve_round, solved, p_ref, k_lo, k_hi, coarse_step, refine_tol)
    s_nodes, ratio = _curve(solved, step, defect)
    info = {"intact_force_n": force, "semi_axes_m": axes,
            "cells": (g.nu, g.nv), "cell_m": (g.du, g.dv), "aligned": True, "skewed": True,
            **stats}
    return s_nodes, ratio, info
