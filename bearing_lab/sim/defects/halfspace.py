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

import lazy_loader as lazy
import numpy as np

from ._transforms import convolve, kernel_spectrum
from .geometry import RaceGeometry, hertz_semi_axes
from .model import Defect

# the FFT of the influence coefficients: loaded when a half-space is first solved
sfft = lazy.load("scipy.fft", suppress_warning=True)

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
#: a CG step that moved at most this many cells off the straight step updates the displacement
#: by direct summation over them instead of a transform; every REFRESH_EVERY-th is transformed
DIRECT_UPDATE_CELLS = 32
REFRESH_EVERY = 16
#: shears of the layout a batch may be solved in (:class:`HalfSpace`): a skewed window's contact lies
#: along a diagonal of its cells (measured on paper-O2's pit at 30-60 degrees: shear +-1 halves
#: the transform)
SHEARS = (1, -1, 2, -2)
#: a cell entering the contact starts at this share of the preconditioned step's pressure at it
#: (``-tau g`` times the stencil's centre): a full step overshoots (measured 0.1-1: 0.3 takes
#: 8 % less CPU on a skewed table than 1, the plain method's rule)
ENTER_SCALE = 0.3


def _stable_sum(t, s):
    """t + sqrt(t^2 + s^2) without cancellation for t < 0."""
    r = np.hypot(t, s)
    with np.errstate(divide="ignore", invalid="ignore"):
        neg = s * s / (r - t)
    return np.where(t >= 0, t + r, neg)


def love_influence(nx: int, ny: int, dx: float, dy: float, e_star: float) -> np.ndarray:
    """Normal surface displacement (m per Pa) at cell centres (i dx, j dy), i < nx, j < ny,
    due to unit pressure on the dx x dy cell centred at the origin (both bodies, 1/E*)."""
    # the closed form at the cells' corners (x_i - dx/2, y_j - dy/2), i <= nx, j <= ny: each corner
    # serves the four cells around it, so it is evaluated once
    x = (np.arange(nx + 1)[:, None] - 0.5) * dx
    y = (np.arange(ny + 1)[None, :] - 0.5) * dy
    # x ln(y + r) + y ln(x + r), r = hypot(x, y), stable for any sign
    t = x * np.log(_stable_sum(y, x)) + y * np.log(_stable_sum(x, y))
    u = (t[1:, 1:] - t[1:, :-1]) - (t[:-1, 1:] - t[:-1, :-1])
    return u / (math.pi * e_star)


#: the stencil of the plain (unpreconditioned) method
PLAIN = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]])


def preconditioner_stencil(kern: np.ndarray) -> np.ndarray:
    """The conjugate gradient's preconditioner: a 3 x 3 stencil approximating the inverse of
    the influence operator (in units of ``1 / kern[0, 0]``), from the kernel ``kern[i, j]``
    (a cell's displacement under unit pressure on the cell (i, j) cells away).

    The influence of the cells on each other is a convolution.  Made periodic on a grid of
    the kernel's size it is a circulant matrix, whose inverse is again a convolution; its
    weights fall off fast away from the centre (the Boussinesq operator's symbol is
    ~ 1/|k|, the inverse's ~ |k|: nearly local, like a Laplacian), so its 3 x 3 centre does
    nearly as well as the whole inverse applied by FFT (measured on skewed windows: 9-12
    iterations with either, 18-21 without) at a few multiplications per cell.  The
    stencil's symbol, bilinear in cos(k_x) and cos(k_y), must be positive at the four
    corners of the spectrum (positive definite, so that the method stays a conjugate
    gradient); if it were not, :data:`PLAIN` (the plain method) is returned.
    """
    nx, ny = kern.shape
    ii = np.minimum(np.arange(nx), nx - np.arange(nx))
    jj = np.minimum(np.arange(ny), ny - np.arange(ny))
    spec = np.fft.rfft2(kern[ii][:, jj] / kern[0, 0]).real
    if spec.min() <= 0:
        return PLAIN
    w = np.fft.irfft2(1.0 / spec, s=(nx, ny))
    st = w[np.arange(-1, 2) % nx][:, np.arange(-1, 2) % ny]
    st = 0.5 * (st + st[::-1, ::-1])
    corners = [st[1, 1] + 2 * st[0, 1] * cx + 2 * st[1, 0] * cy + 4 * st[0, 0] * cx * cy
               for cx in (-1.0, 1.0) for cy in (-1.0, 1.0)]
    return st if min(corners) > 0 else PLAIN


class HalfSpace:
    """DC-FFT influence operator on an (nx, ny) grid of cells dx x dy, and its solver.

    ``shear`` m (an integer, default 0): the arrays this solver takes hold the grid's cells in a
    sheared layout, array index (i, j) being the cell (i, j + m i).  The map is one to one
    between the two lattices and the influence of a cell on another still depends only on
    their offset, so the operator stays a convolution (the kernel read at the cell offset
    (di, dj + m di)) and the solution is the same; it serves a contact region that lies along a
    diagonal of the grid (a skewed window), whose bounding box in the sheared layout is about
    half as large (:meth:`solve_batch` picks it)."""

    def __init__(self, nx: int, ny: int, dx: float, dy: float, e_star: float,
                 kern: np.ndarray | None = None, stencil: np.ndarray | None = None, shear: int = 0):
        self.nx, self.ny, self.dx, self.dy, self.e_star = nx, ny, dx, dy, e_star
        self.shear = int(shear)
        # the grid offsets the array offsets reach: |di| < nx, |dj + m di| < ny + |m| (nx - 1)
        need = (nx, ny + abs(self.shear) * (nx - 1))
        if kern is None:
            k = love_influence(*need, dx, dy, e_star)
        elif kern.shape[0] >= need[0] and kern.shape[1] >= need[1]:
            k = kern[:need[0], :need[1]]
        else:
            # a box of a larger grid whose kernel is given (:meth:`solve_batch`): offsets beyond
            # it join a cell outside that grid, which never carries pressure: zero there
            k = np.zeros(need)
            k[:min(need[0], kern.shape[0]), :min(need[1], kern.shape[1])] = kern[:need[0], :need[1]]
        self._crops: dict[tuple[int, int, int], HalfSpace] = {}
        self._sheared: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}
        # the kernel spans offsets -(n-1)..(n-1): a period of 2n - 1 avoids wrap-around
        self.mx = sfft.next_fast_len(2 * nx - 1, real=True)
        self.my = sfft.next_fast_len(2 * ny - 1, real=True)
        full = np.zeros((self.mx, self.my))
        a = np.arange(-(nx - 1), nx)
        b = np.arange(-(ny - 1), ny)
        full[np.ix_(a % self.mx, b % self.my)] = k[np.abs(a)[:, None], np.abs(b[None, :] + self.shear * a[:, None])]
        self.k00 = float(k[0, 0])          # a cell's displacement under its own pressure
        self.kern = k                      # for direct sums over a few cells (m/Pa)
        # single precision in the transforms (~1e-7 relative error in the displacement, far
        # below the solver's tolerance) at a third of the cost; the kernel scaled to order one
        self.kf = kernel_spectrum(full, self.k00)
        self.stencil = preconditioner_stencil(k[:nx, :ny]) if stencil is None else stencil

    def displacement(self, p: np.ndarray) -> np.ndarray:
        """Surface displacement (m) at the cell centres for cell pressures ``p`` (Pa),
        shape (..., nx, ny) (leading axes: independent problems).

        Only the nx x ny corner of the padded array is non-zero and only that corner of
        the result is needed, so the first and last 1-D passes run on nx rows only
        (:func:`._transforms.convolve`).
        """
        return convolve(p, self.kf, self.mx, self.my, self.k00)

    def solve(self, gap: np.ndarray, approach: float, *, tol: float = 1e-8,
              maxiter: int = 3000, p0: np.ndarray | None = None,
              precondition: bool = True) -> tuple[np.ndarray, int]:
        """Pressure (Pa) for rigid approach ``approach`` and initial gap ``gap`` (m).

        Polonsky-Keer conjugate gradient, displacement-controlled, started from ``p0``
        (default: uniform over the interpenetration), preconditioned on the contact set by
        :func:`preconditioner_stencil` (about half the iterations of the plain method,
        ``precondition=False``, to the same tolerance).  Returns (p, iterations).
        """
        p, its = self.solve_batch(np.asarray(gap, dtype=float)[None], approach, tol=tol,
                                  maxiter=maxiter, p0=None if p0 is None else np.asarray(p0)[None],
                                  precondition=precondition)
        return p[0], int(its[0])

    def solve_batch(self, gaps: np.ndarray, approach: float, *, tol: float = 1e-8,
                    maxiter: int = 3000, p0: np.ndarray | None = None, precondition: bool = True):
        """:meth:`solve` for K problems at once: ``gaps`` (K, nx, ny) -> (p, iterations).

        One FFT call serves every problem still iterating (the calls' fixed cost, not the
        arithmetic, dominates on these small grids); each problem keeps its own step
        sizes and stops on its own.  The preconditioner changes the search directions only:
        the contact conditions, the stopping rule (``tol`` on the relative change of the
        pressure, no cell entering) and so the solution are the plain method's.
        """
        h = np.asarray(gaps, dtype=float)
        allowed = h < approach
        # cells that cannot touch carry no pressure and their displacement is never read:
        # the problems are solved on the box of the cells that can (a smaller transform)
        # (its sides rounded up to what the same transform length can take, so that a few
        # boxes, each with its kernel's spectrum, serve a table); a box in a sheared layout
        # (:class:`HalfSpace`) where that transform is smaller by a tenth or more
        cells = allowed.any(axis=0)
        ii, jj = np.nonzero(cells)
        if ii.size == 0:
            return np.zeros_like(h), np.ones(h.shape[0], dtype=int)

        def side(span, n=None):
            m = (sfft.next_fast_len(2 * span - 1, real=True) + 1) // 2
            return m if n is None else min(n, m)

        def cost(a, b):
            return sfft.next_fast_len(2 * a - 1, real=True) * sfft.next_fast_len(2 * b - 1, real=True)
        rows = side(int(ii.max() - ii.min() + 1), self.nx)
        r0 = min(int(ii.min()), self.nx - rows)
        cols = side(int(jj.max() - jj.min() + 1), self.ny)
        best = (0.9 * cost(rows, cols), 0, 0, cols)
        if self.shear == 0:
            for m in SHEARS:
                js = jj - m * ii
                c = side(int(js.max() - js.min() + 1))
                if cost(rows, c) < best[0]:
                    best = (cost(rows, c), m, int(js.min()), c)
        _, m, c0, cols = best
        if m != 0:
            return self._solve_sheared(h, approach, tol, maxiter, p0, precondition, m, r0, rows, c0, cols)
        c0 = min(int(jj.min()), self.ny - cols)
        box = (slice(None), slice(r0, r0 + rows), slice(c0, c0 + cols))
        if (rows, cols) == (self.nx, self.ny):
            return self._iterate(h, approach, tol, maxiter, p0, precondition)
        p, its = self._crop(rows, cols, 0)._iterate(h[box], approach, tol, maxiter,
                                                     None if p0 is None else np.asarray(p0)[box], precondition)
        out = np.zeros_like(h)
        out[box] = p
        return out, its

    def _crop(self, nx, ny, shear):
        key = (nx, ny, shear)
        if key not in self._crops:
            self._crops[key] = HalfSpace(nx, ny, self.dx, self.dy, self.e_star, kern=self.kern,
                                         stencil=self.stencil, shear=shear)
        return self._crops[key]

    def _solve_sheared(self, h, approach, tol, maxiter, p0, precondition, m, r0, rows, c0, cols):
        """:meth:`solve_batch` on the box of ``rows`` x ``cols`` cells in the layout sheared by
        ``m``: array cell (i, j) is this grid's (r0 + i, c0 + j + m (r0 + i)); cells of the box
        outside the grid cannot touch."""
        key = (m, r0, rows, c0, cols)
        if key not in self._sheared:
            # flat indices: the box's cells inside the grid, and those cells in the grid
            ri = r0 + np.arange(rows)
            cj = c0 + np.arange(cols)[None, :] + m * ri[:, None]
            inside = (cj >= 0) & (cj < self.ny)
            self._sheared[key] = (np.flatnonzero(inside),
                                  np.broadcast_to(ri[:, None], inside.shape)[inside] * self.ny + cj[inside])
        box, src = self._sheared[key]
        k = h.shape[0]
        hs, ps = np.full((k, rows, cols), 1.0), None        # 1 m: never touches
        hs.reshape(k, -1)[:, box] = h.reshape(k, -1)[:, src]
        if p0 is not None:
            ps = np.zeros_like(hs)
            ps.reshape(k, -1)[:, box] = np.broadcast_to(p0, h.shape).reshape(k, -1)[:, src]
        p, its = self._crop(rows, cols, m)._iterate(hs, approach, tol, maxiter, ps, precondition)
        out = np.zeros((k, self.nx * self.ny))
        out[:, src] = p.reshape(k, -1)[:, box]
        return out.reshape(h.shape), its

    def _iterate(self, h, approach, tol, maxiter, p0, precondition):
        """:meth:`solve_batch` on this grid's every cell."""
        from ._halfspace_kernels import cg_direction, cg_step, update_displacement  # kernels (7 ms) at the first solve
        stencil = self.stencil if precondition else PLAIN
        allowed = h < approach
        if p0 is None:
            p = np.where(allowed, 1e6, 0.0)
        else:
            p = np.where(allowed, np.maximum(p0, 0.0), 0.0)
            empty = ~np.any(p > 0, axis=(1, 2))
            p[empty] = np.where(allowed[empty], 1e6, 0.0)
        hd = h - approach
        floor = 1e-24 * np.einsum("kij,kij->k", hd, hd)
        out = p.copy()
        iters = np.full(h.shape[0], maxiter)
        act = np.arange(h.shape[0])
        t = np.zeros_like(p)
        g_old = np.ones(act.size)
        restart = np.ones(act.size, dtype=bool)
        stalled, exact, done = (np.zeros(act.size, dtype=bool) for _ in range(3))
        tau, extra = np.zeros(act.size), np.zeros_like(p)
        n_extra = np.zeros(act.size, dtype=np.int64)
        u = np.ascontiguousarray(self.displacement(p))
        g, z, fresh = np.empty_like(p), np.empty_like(p), np.zeros_like(done)
        gc = np.zeros((p.shape[0], self.nx + 2, self.ny + 2 + 2 * abs(self.shear)))
        escale = (ENTER_SCALE * float(stencil[1, 1]) if stencil is not PLAIN else 1.0) / self.k00
        for it in range(1, maxiter + 1):
            cg_direction(p, u, g, hd, t, allowed, restart, g_old, floor, self.k00, stalled, exact,
                         stencil, gc, z, self.shear)
            r = np.ascontiguousarray(self.displacement(t))
            any_done = cg_step(p, g, t, r, allowed, stalled, exact, restart, tol, done, tau, extra,
                               n_extra, escale)
            # u(p) for the next iteration: updated, unless many cells left the straight step
            # (or entered while stalled, or the periodic refresh bounds the drift): transformed
            any_fresh = update_displacement(u, r, tau, extra, n_extra, self.kern, stalled,
                                            DIRECT_UPDATE_CELLS, it % REFRESH_EVERY == 0, fresh, self.shear)
            if any_done:
                out[act[done]] = p[done]
                iters[act[done]] = it
                keep = ~done
                act, p, t, hd, floor = act[keep], p[keep], t[keep], hd[keep], floor[keep]
                allowed, g_old, restart = allowed[keep], g_old[keep], restart[keep]
                stalled, exact, done = stalled[keep], exact[keep], done[keep]
                u, fresh, tau, n_extra = u[keep], fresh[keep], tau[keep], n_extra[keep]
                if act.size == 0:
                    break
                # written whole at every iteration before they are read (gc's border stays zero)
                g, z, extra = np.empty_like(p), np.empty_like(p), np.empty_like(p)
                gc = np.zeros((p.shape[0],) + gc.shape[1:])
                any_fresh = any_fresh and bool(np.any(fresh))
            if any_fresh:
                u[fresh] = self.displacement(p[fresh])
        out[act] = p
        return out, iters


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
