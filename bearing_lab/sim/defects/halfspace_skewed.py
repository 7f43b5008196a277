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
to zero smoothly at the contact's edge).  The intact contact is solved on the same cells
at the same position, so the share compares like with like.  The error is then first
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
from .model import Defect


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


def window(defect: Defect, geom: RaceGeometry, g: SkewedGrid, s_ball: float):
    """Intact gap, floor gap (m) and the in-outline mask on the window of cells around the
    ball at track position ``s_ball`` (m from the defect centre); arrays (nu, nv)."""
    c, sn = math.cos(defect.skew), math.sin(defect.skew)
    L, W = defect.length, defect.width
    # the ball centre (s_ball, z = 0) in local coordinates
    u_b = s_ball * c - defect.offset * sn
    v_b = -s_ball * sn - defect.offset * c
    i0 = math.floor((u_b + L / 2) / g.du - g.nu / 2)
    j0 = math.floor((v_b + W / 2) / g.dv - g.nv / 2)
    iu = i0 + np.arange(g.nu)
    jv = j0 + np.arange(g.nv)
    U = -L / 2 + (iu + 0.5) * g.du
    V = -W / 2 + (jv + 0.5) * g.dv
    UU, VV = np.meshgrid(U, V, indexing="ij")
    S = UU * c - VV * sn - s_ball            # along the track, from the ball
    Z = defect.offset + UU * sn + VV * c     # across the track, from its centre line
    R = geom.track_radius
    g0 = geom.approach(S / R, Z)
    gf = geom.approach(S / R, Z, depth=defect.depth)
    ins = ((iu >= 0) & (iu < g.n_u))[:, None] & ((jv >= 0) & (jv < g.n_v))[None, :]
    return (np.where(np.isfinite(g0), g0, 1.0), np.where(np.isfinite(gf), gf, 1.0), ins)


def ratio_curve_skewed(defect: Defect, geom: RaceGeometry, delta: float, *, cells, e_star,
                       tol, refine_tol, coarse_step):
    """:func:`.halfspace.ratio_curve` for a rectangle inclined to the track: the same
    returns, computed on the defect-anchored rotated grid.  Ball positions are whole
    numbers of the track-aligned grid's along-track cells from the defect centre."""
    from .halfspace import HalfSpace, _curve, _refine, _symmetry, e_star_of, intact_contact
    e_star = e_star_of() if e_star is None else e_star
    base = intact_contact(geom, delta, cells=cells, e_star=e_star, tol=min(tol, 1e-6))
    step = base["grid"].dy
    g = skewed_grid(defect, geom, delta, cells)
    hs = HalfSpace(g.nu, g.nv, g.du, g.dv, e_star)
    g0, _, _ = window(defect, geom, g, 0.0)
    p_ref, _ = hs.solve(g0, delta, tol=tol)
    b_r = geom.reach(delta)[0]
    s0, s1, _, _ = defect.track_extent()
    k_lo = math.floor((s0 - 1.05 * b_r) / step) - 1
    k_hi = math.ceil((s1 + 1.05 * b_r) / step) + 1
    if _symmetry(defect):
        k_lo = max(k_lo, 0)
    solved: dict[int, tuple[float, tuple]] = {}
    stats = {"solves": 0, "iterations": 0}

    def solve_round(ks, starts):
        todo, gaps, p0 = [], [], []
        for k, start in zip(ks, starts):
            start_d, start_i = start if isinstance(start, tuple) else (start, start)
            gi, gf, ins = window(defect, geom, g, k * step)
            ins &= gi < delta
            if not np.any(ins):
                solved[k] = (1.0, (start_i, start_i))
                continue
            gap = np.where(ins, gf, gi)
            if np.all(gap >= delta):
                solved[k] = (0.0, (np.zeros_like(p_ref), start_i))
                continue
            todo.append(k)
            gaps += [gap, gi]
            p0 += [start_d, start_i]
        if todo:
            p, its = hs.solve_batch(np.array(gaps), delta, tol=tol, p0=np.array(p0))
            stats["solves"] += len(gaps)
            stats["iterations"] += int(its.sum())
            for n, k in enumerate(todo):
                pd, pi = p[2 * n], p[2 * n + 1]
                solved[k] = (float(pd.sum()) / float(pi.sum()), (pd, pi))

    _refine(solve_round, solved, p_ref, k_lo, k_hi, coarse_step, refine_tol)
    s_nodes, ratio = _curve(solved, step, defect)
    info = {"intact_force_n": base["force"], "semi_axes_m": (base["a"], base["b"]),
            "cells": (g.nu, g.nv), "cell_m": (g.du, g.dv), "aligned": True, "skewed": True,
            **stats}
    return s_nodes, ratio, info
