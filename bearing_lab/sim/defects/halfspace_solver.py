"""The half-space contact solver of :mod:`.halfspace`: Love's influence of a uniformly loaded cell, the
conjugate gradient's preconditioner and :class:`HalfSpace`, the influence operator on a grid of cells
and its batched solver (Polonsky & Keer's conjugate gradient, the steps compiled in
:mod:`._halfspace_kernels`, the convolution in :mod:`._transforms`).

Apart from the tables' discretisation (:mod:`.halfspace`) so that each module stays readable; the
names are re-exported there.
"""
from __future__ import annotations

import math

import lazy_loader as lazy
import numpy as np

from ._transforms import convolve, kernel_spectrum

# the FFT lengths of the padded grids: loaded when a half-space is first solved
sfft = lazy.load("scipy.fft", suppress_warning=True)

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
#: a batch whose start is known is first solved on the box of the cells the start presses, widened by
#: this many cells (:meth:`HalfSpace._iterate_near`), or by NEAR_CELLS_LOST for a problem whose start
#: loses more than NEAR_LOST of its load on cells that cannot touch (its load moves outward; measured
#: with a margin of one cell on a skewed table off the track's centre line: 14 of 4140 problems
#: below that share needed a second solve, 1034 of 1996 above it)
NEAR_CELLS = 1
NEAR_CELLS_LOST = 3
NEAR_LOST = 0.1
#: ... on boxes of at least this many cells: on smaller ones (the coarse Richardson grid's, about 330
#: cells) the extra batches' fixed costs outweigh the smaller transforms (measured: off the track's
#: centre line 2 % more CPU with them, and paper-O1's aligned table 5-10 % more)
NEAR_MIN_CELLS = 800


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
            return self._iterate_near(h, approach, tol, maxiter, p0, precondition)
        p, its = self._crop(rows, cols, 0)._iterate_near(h[box], approach, tol, maxiter,
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
        p, its = self._crop(rows, cols, m)._iterate_near(hs, approach, tol, maxiter, ps, precondition)
        out = np.zeros((k, self.nx * self.ny))
        out[:, src] = p.reshape(k, -1)[:, box]
        return out.reshape(h.shape), its

    def _iterate_near(self, h, approach, tol, maxiter, p0, precondition):
        """:meth:`_iterate`, on a smaller box where the start says where the contact will be.

        The elastic contact covers about half of the cells that can touch (the rigid
        interpenetration region, whose box this grid is), and a solve started from a neighbouring
        position's pressure ends with its edge a cell or so from the start's.  So the problems are
        first solved on the box of the cells the start presses, widened by :data:`NEAR_CELLS`
        (:data:`NEAR_CELLS_LOST` for a problem whose start loses more than :data:`NEAR_LOST` of its
        load on cells that cannot touch here, over a pit: its load moves outward), when this grid has
        :data:`NEAR_MIN_CELLS` cells or more and that box's transform is smaller by a tenth or more.
        Each result is then checked on every cell of this grid that can touch (one transform at this
        grid's size): a problem where such a cell
        outside the box would penetrate is solved again from that pressure, those cells added, on
        the box around them, and if that fails too, on this whole grid.  So the solution is this
        grid's problem's, to the solver's tolerance; only the transforms are smaller."""
        if p0 is None or self.nx * self.ny < NEAR_MIN_CELLS:
            return self._iterate(h, approach, tol, maxiter, p0, precondition)
        p0 = np.broadcast_to(p0, h.shape)
        allowed = h < approach
        lost = np.where(allowed, 0.0, p0).sum(axis=(1, 2)) > NEAR_LOST * p0.sum(axis=(1, 2))
        p, its = np.zeros(h.shape), np.zeros(h.shape[0], dtype=int)
        # first the two groups, each on its box; then the problems that failed the check, together, on
        # the box around their grown contact; then those that failed again, on this whole grid
        stages = [[(np.flatnonzero(~lost), NEAR_CELLS), (np.flatnonzero(lost), NEAR_CELLS_LOST)], []]
        start = p0
        for stage in stages:
            failed, fstart = [], []
            for idx, r in stage:
                if idx.size == 0:
                    continue
                p[idx], it, bad, st = self._on_box(h[idx], approach, tol, maxiter, start[idx], precondition, r)
                its[idx] += it
                failed.append(idx[bad])
                fstart.append(st)
            failed = np.concatenate(failed) if failed else np.zeros(0, dtype=int)
            if failed.size == 0:
                return p, its
            start = p.copy()
            start[failed] = np.concatenate(fstart)
            if stage is stages[0]:
                stages[1].append((failed, NEAR_CELLS))
        pb, ib = self._iterate(h[failed], approach, tol, maxiter, start[failed], precondition)
        p[failed] = pb
        its[failed] += ib
        return p, its

    def _on_box(self, h, approach, tol, maxiter, p0, precondition, r):
        """One stage of :meth:`_iterate_near`: the problems solved on the box of the cells ``p0``
        presses widened by ``r`` cells (or on this whole grid if that box's transform is not smaller by
        a tenth), and checked.  Returns (p, iterations, the problems that failed the check, their
        starts for the next stage: p with the penetrating cells at the pressure that closes their own
        gap)."""
        allowed = h < approach
        ii, jj = np.nonzero(np.any((p0 > 0) & allowed, axis=0))
        none = np.zeros(h.shape[0], dtype=bool)
        if ii.size == 0:
            ii, jj = np.array([0, self.nx - 1]), np.array([0, self.ny - 1])
        i0, i1 = max(int(ii.min()) - r, 0), min(int(ii.max()) + r + 1, self.nx)
        j0, j1 = max(int(jj.min()) - r, 0), min(int(jj.max()) + r + 1, self.ny)
        # sides rounded up to what the same transform length takes: fewer boxes, each with its spectrum
        rows = min(self.nx, (sfft.next_fast_len(2 * (i1 - i0) - 1, real=True) + 1) // 2)
        cols = min(self.ny, (sfft.next_fast_len(2 * (j1 - j0) - 1, real=True) + 1) // 2)
        i0, j0 = min(i0, self.nx - rows), min(j0, self.ny - cols)
        i1, j1 = i0 + rows, j0 + cols
        if (sfft.next_fast_len(2 * rows - 1, real=True) * sfft.next_fast_len(2 * cols - 1, real=True)
                > 0.9 * self.mx * self.my):
            p, its = self._iterate(h, approach, tol, maxiter, p0, precondition)
            return p, its, none, p[:0]
        sub = (slice(None), slice(i0, i1), slice(j0, j1))
        p = np.zeros(h.shape)
        p[sub], its = self._crop(rows, cols, self.shear)._iterate(h[sub], approach, tol, maxiter, p0[sub],
                                                                  precondition)
        outside = allowed.copy()
        outside[sub] = False
        chk = np.flatnonzero(outside.any(axis=(1, 2)))
        if chk.size == 0:
            return p, its, none, p[:0]
        g = self.displacement(p[chk]) + (h[chk] - approach)
        pen = (g < 0) & outside[chk]
        sel = np.any(pen, axis=(1, 2))
        bad = none.copy()
        bad[chk[sel]] = True
        return p, its, bad, np.where(pen[sel], -g[sel] / self.k00, p[chk[sel]])

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
