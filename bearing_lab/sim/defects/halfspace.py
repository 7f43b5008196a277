"""Elastic half-space contact of a ball with a defected raceway: the "halfspace" model.

Why: over a defect the raceway loses part of the surface that carried the Hertz
pressure.  How much load the contact loses at a given approach is an elastic question:
the material next to the pit is pressed further and carries part of the load the pit
removed.  A local (Winkler) law, where each surface point carries ``~ sqrt(delta - h)``
independently of its neighbours ("area" model), cannot show this; the elastic
half-space can.  This module solves the frictionless normal contact of the ball and the
race, both linear-elastic half-spaces (Boussinesq; Johnson, *Contact Mechanics*, 1985,
sections 3.2 and 5.9), for the exact sphere-in-torus gap with the outline removed, at
a fixed rigid approach.

Method
------
Piecewise-constant pressure on a rectangular grid of cells; the surface displacement of
a uniformly loaded rectangle from Love's (1929) closed form; the convolution over the
grid by FFT with zero padding (DC-FFT: Liu, Wang & Liu, Wear 243, 2000), pruned so that
only the non-zero quarter of the padded array is transformed (:mod:`._transforms`); the complementarity
problem (pressure >= 0, gap >= 0, one of them zero) by the conjugate-gradient method of
Polonsky & Keer (Wear 231, 1999), displacement-controlled (the approach is fixed, so
their load-balance step is omitted), preconditioned on the contact set by a 3 x 3 stencil
of the influence operator's inverse (:func:`preconditioner_stencil`; Vollebregt, J.
Comput. Phys. 257, 2014, preconditions the same method with the whole inverse by FFT):
about 10 iterations a solve instead of 17-20.  A cell whose centre lies inside the
outline carries the floor's gap (the intact gap plus the depth), so a deep pit never touches.
The solver is :mod:`.halfspace_solver`'s (its names re-exported here).

The grid is ball-centred and covers the rigid interpenetration region ``{h < delta}``
(the elastic contact lies inside it, with or without a defect: surface displacements
are >= 0) with ``TABLE_CELLS`` cells.  For a rectangle whose sides run along and across
the track the cell sizes are adjusted so the sides fall on cell boundaries (no
staircase); a rectangle inclined to the track is solved on cells rotated with it and
anchored to its sides (:mod:`.halfspace_skewed`); ellipses and polygons are resolved by
their cells' centres.  Ball positions are
whole numbers of cells along the track (so the outline moves by whole cells), first
every ``COARSE_STEP`` cells, then halved where linear interpolation misses the solved
midpoint by more than ``REFINE_TOL``; positions whose cells see the same part of the
outline are solved once; each round is one batch warm-started from its neighbours.

Accuracy and cost (6308 outer race; ``benchmarks/defect_tables.py``): on the tables'
grids the intact force is within 0.4 % of Hertz (K_o delta^1.5) and the contact
semi-axes from the pressure's second moments within 0.7 % up to 8.4 µm (800 N); the
share of the intact force carried over a centred 1 x 1 mm defect converges to first
order in the cell size (the pressure is singular at the pit's edge), which the
two-grid extrapolation of :mod:`.contact` removes.  One approach node (both grids) costs
about 9 ms of CPU for a rectangle along the track and 30 ms for a skewed one (50 ms off the
track's centre line, where no mirror symmetry halves the ball positions); figures in
``docs/contact-model.md``.

What is neglected: the pit is a pressure-free region of the half-space surface; the
compliance the removed material would add (a flank next to a pit is the edge of a
quarter-space, softer than a half-space) is ignored, as in dent and rough-surface
contact solvers.  So the load lost lies between this figure and the local law's, nearer
this one for pits narrower than the ring section.
"""
from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from .geometry import RaceGeometry, hertz_semi_axes
from .halfspace_solver import (DIRECT_UPDATE_CELLS, ENTER_SCALE, PLAIN, REFRESH_EVERY, SHEARS,  # noqa: F401
                               HalfSpace, love_influence, preconditioner_stencil)
from .model import Defect

#: approach nodes of the "halfspace" table, as fractions of delta_max (the loaded range)
HALFSPACE_NODES = (0.05, 0.1, 0.16, 0.25, 0.35, 0.5, 0.7, 1.0)
#: spacing of the half-space nodes above the loaded range (inside a deep defect), as a fraction of it
ABOVE_NODE_STEP = 0.1
#: cells (across, along the track) over the interpenetration region at each approach
TABLE_CELLS = (32, 24)
#: Polonsky-Keer stopping rule: sum |p - p_previous| / sum p
SOLVE_TOL = 1e-4
#: a position interval is halved while |ratio(mid) - linear interpolation| exceeds this
REFINE_TOL = 1e-3
#: first pass: one ball position every COARSE_STEP cells along the track
COARSE_STEP = 4


def e_star_of(E: float = 208e9, nu: float = 0.3) -> float:
    """Combined modulus of two equal bodies: 1/E* = 2 (1 - nu^2)/E."""
    return E / (2 * (1 - nu * nu))


# ----------------------------------------------------------------------------- grids

@dataclass(frozen=True)
class ContactGrid:
    """Ball-centred cells in track coordinates: centres ``z`` (across), ``s`` (along), m."""

    z: np.ndarray
    s: np.ndarray
    dx: float
    dy: float
    aligned: bool

    @property
    def shape(self) -> tuple[int, int]:
        return self.z.size, self.s.size


def aligned_sides(defect: Defect):
    """(along, across) side lengths if the outline is a rectangle with sides along and
    across the track, else None."""
    if defect.shape != "rectangle":
        return None
    c, s = abs(math.cos(defect.skew)), abs(math.sin(defect.skew))
    if s < 1e-12:
        return defect.length, defect.width
    if c < 1e-12:
        return defect.width, defect.length
    return None


def contact_grid(defect: Defect | None, geom: RaceGeometry, delta: float,
                 cells: tuple[int, int] = TABLE_CELLS) -> ContactGrid:
    """Cells covering the interpenetration region at approach ``delta`` (one cell margin).

    For a rectangle with sides along and across the track the sides fall on cell
    boundaries for every ball position that is a whole number of cells from the defect
    centre (``s`` is symmetric about the ball, ``z`` shifted to the sides)."""
    b_r, a_r = geom.reach(delta)
    dx, dy = 2 * a_r / cells[0], 2 * b_r / cells[1]
    sides = None if defect is None else aligned_sides(defect)
    if sides is None:
        nx, ny = cells[0] + 2, cells[1] + 2
        z = (np.arange(nx) - nx / 2 + 0.5) * dx
        s = (np.arange(ny) - ny / 2 + 0.5) * dy
        return ContactGrid(z, s, dx, dy, False)
    along, across = sides
    n_along = max(1, round(along / dy))
    dy = along / n_along
    n_across = max(1, round(across / dx))
    dx = across / n_across
    ny = math.ceil(2 * b_r / dy) + 2
    if ny % 2 != n_along % 2:
        ny += 1            # sides at +-along/2 from a whole-cell position are boundaries
    s = (np.arange(ny) - (ny - 1) / 2) * dy
    z_side = defect.offset - across / 2
    i_lo = math.floor((-a_r - dx - z_side) / dx)
    i_hi = math.ceil((a_r + dx - z_side) / dx)
    z = z_side + (np.arange(i_lo, i_hi) + 0.5) * dx
    return ContactGrid(z, s, dx, dy, True)


def _gaps(geom: RaceGeometry, grid: ContactGrid, depth: float):
    Z, S = np.meshgrid(grid.z, grid.s, indexing="ij")
    R = geom.track_radius
    g0 = geom.approach(S / R, Z)
    gf = geom.approach(S / R, Z, depth=depth)
    return Z, S, np.where(np.isfinite(g0), g0, 1.0), np.where(np.isfinite(gf), gf, 1.0)


def pressure_semi_axes(p: np.ndarray, Z: np.ndarray, S: np.ndarray, dx: float, dy: float):
    """Contact semi-axes (a across, b along; m) from the pressure's second moments.

    For Hertz's ellipsoidal pressure ``p0 sqrt(1 - z^2/a^2 - s^2/b^2)`` the mean of z^2
    weighted by p is a^2/5 (and s^2: b^2/5); the cells add their own dx^2/12, dy^2/12.
    """
    w = p / p.sum()
    zc = float((w * Z).sum())
    sc = float((w * S).sum())
    z2 = float((w * (Z - zc) ** 2).sum()) + dx * dx / 12
    s2 = float((w * (S - sc) ** 2).sum()) + dy * dy / 12
    return math.sqrt(5 * z2), math.sqrt(5 * s2)


def hertz_start(hs: HalfSpace, geom: RaceGeometry, gap: np.ndarray, Z: np.ndarray, S: np.ndarray,
                delta: float) -> np.ndarray:
    """A start for the intact solve: Hertz's ellipsoidal pressure on the cells (semi-axes of
    :func:`.geometry.hertz_semi_axes`), scaled to the gap in the least-squares sense.  It
    saves about a third of the iterations from a uniform start (33 -> 22 at tol 1e-6)."""
    a, b = hertz_semi_axes(geom, delta)
    q = np.sqrt(np.maximum(1.0 - (Z / a) ** 2 - (S / b) ** 2, 0.0))
    u = hs.displacement(q[None])[0]
    m = q > 0
    den = float((u[m] ** 2).sum())
    return q * (float(((delta - gap)[m] * u[m]).sum()) / den) if den > 0 else q


def intact_contact(geom: RaceGeometry, delta: float, *, cells=TABLE_CELLS,
                   e_star: float | None = None, tol: float = 1e-8, defect: Defect | None = None):
    """Intact half-space contact at approach ``delta`` on the grid the tables use.

    Returns a dict: force (N), a and b (m, from the pressure's moments), p (Pa), grid,
    gaps, solver, iterations.  ``defect`` only sets the grid's alignment.
    """
    e_star = e_star_of() if e_star is None else e_star
    grid = contact_grid(defect, geom, delta, cells)
    Z, S, g0, gf = _gaps(geom, grid, 0.0 if defect is None else defect.depth)
    hs = HalfSpace(*grid.shape, grid.dx, grid.dy, e_star)
    p, it = hs.solve(g0, delta, tol=tol, p0=hertz_start(hs, geom, g0, Z, S, delta))
    a, b = pressure_semi_axes(p, Z, S, grid.dx, grid.dy)
    return {"force": float(p.sum()) * grid.dx * grid.dy, "a": a, "b": b, "p": p, "grid": grid,
            "Z": Z, "S": S, "gap": g0, "gap_floor": gf, "solver": hs, "iterations": it}


# ----------------------------------------------------------------------------- ratio curves

def _symmetry(defect: Defect) -> bool:
    """True if the contact over the defect is even in the ball position."""
    if not defect.outline.symmetric:
        return False
    return defect.offset == 0.0 or defect.skew == 0.0


def ratio_curve(defect: Defect, geom: RaceGeometry, delta: float, *, cells=TABLE_CELLS,
                e_star: float | None = None, tol: float = SOLVE_TOL,
                refine_tol: float = REFINE_TOL, coarse_step: int = COARSE_STEP):
    """Share of the intact half-space force carried over the defect at approach ``delta``.

    Ball positions are whole numbers of cells from the defect centre: every
    ``coarse_step`` cells first, then intervals are halved while the solved midpoint is
    more than ``refine_tol`` from the linear interpolation; each round is solved as one
    batch, warm-started from the nearest solved position.

    Returns ``(s, ratio, info)``: ball positions s (m from the defect centre, sorted)
    with ratio = F(defect) / F(intact) at the same approach (1 where the grid does not
    meet the outline), and info (intact force N, semi-axes m, cells, solves, iterations).
    A rectangle skewed to the track is solved on a grid turned with it,
    :func:`.halfspace_skewed.ratio_curve_skewed` (same arguments and result); here it is refused.
    """
    if defect.shape == "rectangle" and aligned_sides(defect) is None:
        raise ValueError(f"halfspace.ratio_curve: a rectangle skewed to the track (skew {math.degrees(defect.skew):g} "
                         "deg) is solved by halfspace_skewed.ratio_curve_skewed")
    base = intact_contact(geom, delta, cells=cells, e_star=e_star, tol=min(tol, 1e-6),
                          defect=defect)
    grid, hs = base["grid"], base["solver"]
    Z, S, g0, gf = base["Z"], base["S"], base["gap"], base["gap_floor"]
    p_int = base["p"]
    f_int = float(p_int.sum())
    touch = g0 < delta
    dy = grid.dy
    s0, s1, _, _ = defect.track_extent()
    k_lo = math.floor((s0 - grid.s[-1] - dy) / dy)
    k_hi = math.ceil((s1 - grid.s[0] + dy) / dy)
    if _symmetry(defect):
        k_lo = max(k_lo, 0)
    solved: dict[int, tuple[float, np.ndarray]] = {}
    stats = {"solves": 0, "iterations": 0}

    same: dict[bytes, list] = {}     # positions whose cells see the same outline: one solve

    def solve_round(ks, starts):
        todo, gaps, p0 = [], [], []
        # the cells inside the outline for every position of the round at once
        inside = defect.contains(S[None] + (np.asarray(ks) * dy)[:, None, None], Z[None]) & touch
        for k, start, ins in zip(ks, starts, inside):
            if not np.any(ins):
                solved[k] = (1.0, p_int)
                continue
            gap = np.where(ins, gf, g0)
            if np.all(gap >= delta):
                solved[k] = (0.0, np.zeros_like(p_int))
                continue
            key = np.packbits(ins).tobytes()
            if key in same:
                same[key].append(k)
                continue
            same[key] = [k]
            todo.append(k)
            gaps.append(gap)
            p0.append(start)
        if todo:
            p, its = hs.solve_batch(np.array(gaps), delta, tol=tol, p0=np.array(p0))
            stats["solves"] += len(todo)
            stats["iterations"] += int(its.sum())
            for k, pk in zip(todo, p):
                solved[k] = (float(pk.sum()) / f_int, pk)
        for group in same.values():
            for k in group[1:]:
                solved[k] = solved[group[0]]

    _refine(solve_round, solved, p_int, k_lo, k_hi, coarse_step, refine_tol)
    s_nodes, ratio = _curve(solved, dy, defect)
    info = {"intact_force_n": base["force"], "semi_axes_m": (base["a"], base["b"]),
            "cells": grid.shape, "cell_m": (grid.dx, grid.dy), "aligned": grid.aligned, **stats}
    return s_nodes, ratio, info


def _curve(solved, step, defect):
    """(positions m, shares) from the solved ball positions {k: (share, ...)} ``step`` apart, mirrored
    about the defect centre when only one half was solved (:func:`_symmetry`)."""
    ks = np.array(sorted(solved))
    s_nodes = ks * step
    ratio = np.array([solved[k][0] for k in ks])
    if _symmetry(defect) and ks[0] == 0:
        s_nodes = np.concatenate([-s_nodes[:0:-1], s_nodes])
        ratio = np.concatenate([ratio[:0:-1], ratio])
    return s_nodes, ratio


def _refine(solve_round, solved, p_int, k_lo, k_hi, coarse_step, refine_tol):
    """Solve every ``coarse_step`` positions, then halve intervals while the solved
    midpoint misses linear interpolation by more than ``refine_tol`` (``solved`` maps a
    position to (ratio, pressure) and is filled by ``solve_round(ks, starts)``)."""
    coarse = list(range(k_lo, k_hi + 1, coarse_step))
    if coarse[-1] != k_hi:
        coarse.append(k_hi)
    solve_round(coarse, [p_int] * len(coarse))
    # an interval whose neighbourhood is straight on the coarse scale (both second
    # differences below refine_tol) is not checked: e.g. the flat stretch while the
    # contact lies inside a long defect's length
    rc = np.array([solved[k][0] for k in coarse])
    d2 = np.full(rc.size, np.inf)
    d2[1:-1] = np.abs(rc[:-2] - 2 * rc[1:-1] + rc[2:])
    intervals = [(a, b) for i, (a, b) in enumerate(zip(coarse[:-1], coarse[1:]))
                 if b - a >= 2 and max(d2[i], d2[i + 1]) > refine_tol]
    while intervals:
        mids = [(a + b) // 2 for a, b in intervals]
        starts = [solved[a][1] if m - a <= b - m else solved[b][1]
                  for (a, b), m in zip(intervals, mids)]
        solve_round(mids, starts)
        nxt = []
        for (a, b), m in zip(intervals, mids):
            lin = solved[a][0] + (solved[b][0] - solved[a][0]) * (m - a) / (b - a)
            if abs(solved[m][0] - lin) > refine_tol:
                nxt += [(a, m), (m, b)]
        intervals = [(a, b) for a, b in nxt if b - a >= 2]


def halfspace_ratio_nodes(defect: Defect, geom: RaceGeometry, delta_nodes, **kw):
    """:func:`ratio_curve` at each approach in ``delta_nodes``: a list of (s, ratio, info)."""
    return [ratio_curve(defect, geom, float(d), **kw) for d in delta_nodes]
