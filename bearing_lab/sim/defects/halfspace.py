"""Elastic half-space contact solver: the independent check of the "area" local law.

Why: the "area" contact model (:mod:`.contact`) spreads the load over the raceway by a
local law, ``p ~ sqrt(delta - h)``, which ignores that an elastic body carries the load
lost over a defect partly on the neighbouring intact surface.  This module solves the
frictionless normal contact of two elastic half-spaces exactly (to the grid) for the same
exact sphere-torus gap, so the local law can be measured against it.  It is far too slow
for the time loop (one solve is 0.1-1 s) and is run once, in a test and a benchmark.

Method: piecewise-constant pressure on a rectangular grid; surface displacement from
Love's (1929) closed form for a uniformly loaded rectangle; the convolution by FFT with
zero padding (DC-FFT, Liu, Wang & Liu 2000); the complementarity problem by the
conjugate-gradient method of Polonsky & Keer (Wear 231, 1999), displacement-controlled
(the rigid approach is fixed, so the mean-gap/load-balance step is omitted).

Figures (6308 outer race, E = 208 GPa, nu = 0.3, r_o = 0.53 D_b, exact sphere-torus
gap; ``compare_local_law()``, grid 0.0125 x 0.004 mm):

* intact, at the approach 4.382 µm that Hertz (K_o = 3.27e10 N/m^1.5) gives for 300 N:
  force 299.69 N (-0.10 %), contact semi-axes 0.888 x 0.158 mm (reference.md: 0.90 x 0.16;
  the extents are read to one cell, -1.4 % and -1.3 %); at 8 µm 737.8 N (K_o -0.3 %: the
  exact torus gap grows faster than Hertz's paraboloid);
* centred 1 x 1 mm, 0.5 mm deep defect, ball over its centre, same approach: share of the
  intact load still carried 0.553 (half-space) vs 0.350 (local law, "area" table); at 8 µm
  0.708 vs 0.499.  More positions in :mod:`.contact`.

The pit is modelled as a pressure-free region of the half-space surface: the compliance
added by the removed material is ignored.  A flank next to a pit is an edge of a
quarter-space and softer than a half-space, so the true load lost lies between the
half-space figure and the local law's, nearer the half-space for pits narrower than the
ring section (the usual approximation in rough-surface and dent contact solvers).
"""
from __future__ import annotations

import math

import numpy as np

from .geometry import RaceGeometry
from .model import Defect

def _stable_sum(t, s):
    """t + sqrt(t^2 + s^2) without cancellation for t < 0."""
    r = np.hypot(t, s)
    with np.errstate(divide="ignore", invalid="ignore"):
        neg = s * s / (r - t)
    return np.where(t >= 0, t + r, neg)


def love_influence(nx: int, ny: int, dx: float, dy: float, e_star: float) -> np.ndarray:
    """Normal surface displacement (m per Pa) at cell centres (i dx, j dy), i < nx, j < ny,
    due to unit pressure on the dx x dy cell centred at the origin (both bodies, 1/E*)."""
    x = np.arange(nx)[:, None] * dx
    y = np.arange(ny)[None, :] * dy
    a, b = dx / 2, dy / 2

    def term(xx, yy):
        # xx * ln(yy + r) + yy * ln(xx + r), r = hypot(xx, yy), stable for any sign
        return xx * np.log(_stable_sum(yy, xx)) + yy * np.log(_stable_sum(xx, yy))

    u = (term(x + a, y + b) - term(x + a, y - b) - term(x - a, y + b) + term(x - a, y - b))
    return u / (math.pi * e_star)


class HalfSpace:
    """DC-FFT influence operator on an (nx, ny) grid of cells dx x dy."""

    def __init__(self, nx: int, ny: int, dx: float, dy: float, e_star: float):
        self.nx, self.ny, self.dx, self.dy = nx, ny, dx, dy
        k = love_influence(nx, ny, dx, dy, e_star)
        full = np.zeros((2 * nx, 2 * ny))
        full[:nx, :ny] = k
        full[nx + 1:, :ny] = k[:0:-1, :]
        full[:nx, ny + 1:] = k[:, :0:-1]
        full[nx + 1:, ny + 1:] = k[:0:-1, :0:-1]
        self.kf = np.fft.rfft2(full)

    def displacement(self, p: np.ndarray) -> np.ndarray:
        pp = np.zeros((2 * self.nx, 2 * self.ny))
        pp[:self.nx, :self.ny] = p
        return np.fft.irfft2(np.fft.rfft2(pp) * self.kf, s=pp.shape)[:self.nx, :self.ny]

    def solve(self, gap: np.ndarray, approach: float, *, tol: float = 1e-8,
              maxiter: int = 3000, p0: np.ndarray | None = None) -> tuple[np.ndarray, int]:
        """Pressure (Pa) for rigid approach ``approach`` and initial gap ``gap`` (m).

        Polonsky-Keer conjugate gradient, displacement-controlled, started from ``p0``
        (default: uniform over the interpenetration).  Returns (p, iterations).
        """
        h = np.asarray(gap, dtype=float)
        if p0 is None:
            p = np.where(h < approach, 1.0, 0.0) * 1e6
        else:
            p = np.where(h < approach, np.maximum(p0, 0.0), 0.0)
            if not np.any(p > 0):
                p = np.where(h < approach, 1.0, 0.0) * 1e6
        t = np.zeros_like(p)
        g_old = 1.0
        restart = True
        for it in range(1, maxiter + 1):
            g = self.displacement(p) + h - approach
            S = p > 0
            G = float(np.sum(g[S] ** 2))
            if restart:
                t = np.where(S, g, 0.0)
            else:
                t = np.where(S, g + (G / g_old) * t, 0.0)
            g_old = G
            r = self.displacement(t)
            den = float(np.sum(r[S] * t[S]))
            if den == 0:
                break
            tau = float(np.sum(g[S] * t[S])) / den
            p_old = p
            p = p - tau * t
            p[p < 0] = 0.0
            ol = (p == 0) & (g < 0)
            if np.any(ol):
                restart = True
                p[ol] -= tau * g[ol]
            else:
                restart = False
            tot = float(np.sum(p))
            if tot > 0 and float(np.sum(np.abs(p - p_old))) / tot < tol:
                break
        return p, it


def e_star_of(E: float = 208e9, nu: float = 0.3) -> float:
    """Combined modulus of two equal bodies: 1/E* = 2 (1 - nu^2)/E."""
    return E / (2 * (1 - nu * nu))


def race_contact(geom: RaceGeometry, defect: Defect | None, approach: float, *,
                 s_ball: float = 0.0, half_across: float | None = None,
                 half_along: float | None = None, dx: float = 0.0125e-3, dy: float = 0.004e-3,
                 e_star: float | None = None, solver: HalfSpace | None = None):
    """Half-space contact of the ball at track position ``s_ball`` (m from the defect
    centre) and approach ``approach`` with the race, exact sphere-torus gap; cells whose
    centre lies inside the outline carry the floor's gap.  Returns a dict with force (N),
    semi-axes a (across) and b (along) of the contact (m), p (Pa), iterations."""
    e_star = e_star_of() if e_star is None else e_star
    if half_across is None or half_along is None:
        # the elastic contact lies inside the rigid interpenetration region {h < approach}
        # (surface displacements are >= 0), with or without a defect
        b_r, a_r = geom.reach(approach)
        half_across = a_r + dx if half_across is None else half_across
        half_along = b_r + dy if half_along is None else half_along
    nx, ny = int(round(2 * half_across / dx)), int(round(2 * half_along / dy))
    z = (np.arange(nx) - nx / 2 + 0.5) * dx
    s = (np.arange(ny) - ny / 2 + 0.5) * dy
    Z, S = np.meshgrid(z, s, indexing="ij")
    R = geom.track_radius
    gap = geom.approach(S / R, Z)
    if defect is not None:
        ins = defect.contains(S + s_ball, Z)
        gap = np.where(ins, geom.approach(S / R, Z, depth=defect.depth), gap)
    gap = np.where(np.isfinite(gap), gap, 1.0)
    hs = solver if solver is not None else HalfSpace(nx, ny, dx, dy, e_star)
    p, it = hs.solve(gap, approach)
    c = p > 0
    force = float(p.sum() * dx * dy)
    a = float(np.abs(Z[c]).max() + dx / 2) if c.any() else 0.0
    b = float(np.abs(S[c]).max() + dy / 2) if c.any() else 0.0
    if c.any() and (np.abs(Z[c]).max() > half_across - 2 * dx or np.abs(S[c]).max() > half_along - 2 * dy):
        raise ValueError("the contact reaches the edge of the half-space grid; enlarge it")
    return {"force": force, "a": a, "b": b, "p": p, "iterations": it, "solver": hs}


def compare_local_law(bearing=None, *, load: float = 300.0, k_hertz: float = 3.27e10,
                      s_positions=(0.0, 0.3e-3, 0.5e-3, 0.6e-3), dx: float = 0.0125e-3,
                      dy: float = 0.004e-3) -> dict:
    """6308 outer race: half-space vs the "area" local law over a centred 1 x 1 mm defect.

    At the approach ``(load / k_hertz)^(2/3)`` returns the intact half-space force and
    semi-axes, and for each ball position ``s`` (m from the defect centre) the share of the
    intact force still carried by the half-space and by the local-law table.
    """
    from bearing_lab.bearings import get_bearing
    from .contact import contact_table
    bearing = get_bearing("6308") if bearing is None else bearing
    geom = RaceGeometry.from_bearing(bearing, "outer")
    d = Defect(length=1e-3, width=1e-3, depth=0.5e-3)
    delta = (load / k_hertz) ** (2 / 3)
    intact = race_contact(geom, None, delta, dx=dx, dy=dy)
    table = contact_table(d, bearing, model="area", delta_max=2 * delta, n_delta=81)
    out = {"approach": delta, "intact_force": intact["force"], "a": intact["a"], "b": intact["b"],
           "iterations": intact["iterations"], "positions": []}
    for s in s_positions:
        r = race_contact(geom, d, delta, s_ball=s, dx=dx, dy=dy, solver=intact["solver"])
        law = float(table.lookup(s / geom.track_radius, delta)) / delta ** 1.5
        out["positions"].append({"s": s, "halfspace": r["force"] / intact["force"], "local_law": law})
    return out


def _symmetry(defect: Defect) -> bool:
    """True if the contact over the defect is even in psi (G(-psi) = G(psi))."""
    if defect.shape == "polygon":
        return False
    return defect.offset == 0.0 or defect.skew == 0.0


def halfspace_ratio_nodes(defect: Defect, geom: RaceGeometry, delta_nodes, *,
                          cells_across: int = 64, cells_along: int = 48, step_cells: int = 2,
                          e_star: float | None = None, tol: float = 1e-6):
    """Share of the intact half-space force carried over the defect, on coarse nodes.

    For each approach in ``delta_nodes``: a ball-centred grid over the interpenetration
    region {h < delta} (``cells_across x cells_along`` cells; a cell is removed when its
    centre lies inside the outline), the intact force, then the force with the ball at
    track positions s = k * step_cells * dy (only where the grid meets the defect; warm
    started from the neighbouring position).  Returns a list of (s_nodes, ratio) per delta.
    """
    e_star = e_star_of() if e_star is None else e_star
    R = geom.track_radius
    sym = _symmetry(defect)
    s0, s1, z0, z1 = defect.track_extent()
    out = []
    for delta in delta_nodes:
        b_r, a_r = geom.reach(delta)
        dx, dy = 2 * a_r / cells_across, 2 * b_r / cells_along
        nx, ny = cells_across + 2, cells_along + 2
        z = (np.arange(nx) - nx / 2 + 0.5) * dx
        s = (np.arange(ny) - ny / 2 + 0.5) * dy
        Z, S = np.meshgrid(z, s, indexing="ij")
        gap0 = geom.approach(S / R, Z)
        gapf = geom.approach(S / R, Z, depth=defect.depth)
        gap0 = np.where(np.isfinite(gap0), gap0, 1.0)
        gapf = np.where(np.isfinite(gapf), gapf, 1.0)
        hs = HalfSpace(nx, ny, dx, dy, e_star)
        p_int, _ = hs.solve(gap0, delta, tol=tol)
        f_int = float(p_int.sum())
        step = step_cells * dy
        k_lo = math.floor((s0 - b_r - dy) / step)
        k_hi = math.ceil((s1 + b_r + dy) / step)
        if sym:
            k_lo = max(k_lo, 0)
        ks = np.arange(k_lo, k_hi + 1)
        ratio = np.ones(ks.size)
        p_prev = p_int
        for i, k in enumerate(ks):
            ins = defect.contains(S + k * step, Z)
            if not np.any(ins & (gap0 < delta)):
                p_prev = p_int
                continue
            gap = np.where(ins, gapf, gap0)
            if np.all(gap >= delta):
                ratio[i] = 0.0
                continue
            p, _ = hs.solve(gap, delta, tol=tol, p0=p_prev)
            ratio[i] = float(p.sum()) / f_int
            p_prev = p
        s_nodes = ks * step
        if sym:
            s_nodes = np.concatenate([-s_nodes[:0:-1], s_nodes])
            ratio = np.concatenate([ratio[:0:-1], ratio])
        out.append((s_nodes, ratio))
    return out
