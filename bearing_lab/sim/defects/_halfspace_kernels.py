"""numba kernels of the half-space solver: the element-wise steps of one conjugate-gradient
iteration (Polonsky & Keer, Wear 231, 1999) for a batch of problems, the groove's gap over
a skewed table's windows (:func:`torus_gap`) and the outline points that hold a rigid ball
(:func:`outline_candidates`).

Why numba: on the tables' small grids (about 34 x 26 cells) the two FFT convolutions of
an iteration cost ~25 µs per problem in single precision, while the dozen numpy
element-wise passes around them (masks, sums, clipping) cost three times that.  One
compiled pass per step does the same arithmetic at memory speed.  And most steps move
only a few cells off the straight step ``p - tau t`` (clipped at zero or entering; 78 %
of the steps of a skewed table move at most 4), so the next ``u(p)`` is
``u(p) - tau u(t)`` plus a direct sum over those cells (:func:`update_displacement`):
one transform per iteration instead of two.  The preconditioner is a 3 x 3 stencil
applied in :func:`cg_direction` (a few multiplications per cell, no transform).

Arrays are (K, nx, ny), float64: K independent problems, each with its own scalars.
``p`` pressure (Pa), ``u`` the displacement ``u(p)``, ``g`` gap (m, ``u(p) + h - approach``),
``t`` search direction, ``r = u(t)``, ``allowed`` cells that can touch (the rigid gap is below the
approach).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def cg_direction(p, u, g, hd, t, allowed, restart, g_old, floor, k00, stalled, exact, stencil, gc, z, shear):
    """The gap ``g = u + hd`` (``u`` the displacement), the new search direction ``t`` in place.

    Preconditioned (:func:`.halfspace_solver.preconditioner_stencil`): ``z = M^-1 g`` with
    ``M^-1`` the symmetric 3 x 3 ``stencil`` (divided by ``k00``: Pa per m of gap), applied
    to ``g`` on the contact set and read there only, so that it acts as its restriction to
    the contact set; ``t = z + beta t``, ``beta = (g.z) / (g.z)_previous``.  A stencil with
    only its centre (1) is the plain method.  Work space: ``gc`` (K, nx + 2, ny + 2 + 2 |shear|)
    with a zero border, ``z`` of ``g``'s shape.

    ``shear`` m: the arrays hold the cells in a sheared layout, index (i, j) being the grid's
    cell (i, j + m i) (:class:`.halfspace_solver.HalfSpace`); the stencil's weights stay those of the
    cells' physical neighbours (offset (di, dj) sits at (di, dj - m di) in the arrays).

    A problem whose contact set is in equilibrium (or empty; ``sum g^2 <= floor``) is
    ``stalled``: its penetrating cells outside the contact enter with the pressure that
    would close their own gap alone (``-g / k00``); with none left it is ``exact``.
    """
    K, nx, ny = p.shape
    sc, sx, sy, sd = stencil[1, 1] / k00, stencil[0, 1] / k00, stencil[1, 0] / k00, stencil[0, 0] / k00
    m = shear
    b = 1 + abs(m)
    for k in range(K):
        G = 0.0
        for i in range(nx):
            for j in range(ny):
                gk = u[k, i, j] + hd[k, i, j]
                g[k, i, j] = gk
                c = gk if p[k, i, j] > 0.0 else 0.0
                gc[k, i + 1, j + b] = c
                G += c * c
        stalled[k] = G <= floor[k]
        exact[k] = False
        if stalled[k]:
            entered = False
            for i in range(nx):
                for j in range(ny):
                    t[k, i, j] = 0.0
                    if p[k, i, j] <= 0.0 and g[k, i, j] < 0.0 and allowed[k, i, j]:
                        p[k, i, j] = -g[k, i, j] / k00
                        entered = True
            exact[k] = not entered
            g_old[k] = G
            continue
        gz = 0.0
        for i in range(nx):
            for j in range(ny):
                if p[k, i, j] <= 0.0:
                    z[k, i, j] = 0.0
                    continue
                jc = j + b
                zz = (sc * gc[k, i + 1, jc] + sx * (gc[k, i, jc + m] + gc[k, i + 2, jc - m])
                      + sy * (gc[k, i + 1, jc - 1] + gc[k, i + 1, jc + 1])
                      + sd * (gc[k, i, jc - 1 + m] + gc[k, i + 2, jc - 1 - m] + gc[k, i, jc + 1 + m]
                              + gc[k, i + 2, jc + 1 - m]))
                z[k, i, j] = zz
                gz += gc[k, i + 1, jc] * zz
        beta = 0.0 if restart[k] or g_old[k] <= 0.0 else gz / g_old[k]
        for i in range(nx):
            for j in range(ny):
                t[k, i, j] = z[k, i, j] + beta * t[k, i, j] if p[k, i, j] > 0.0 else 0.0
        g_old[k] = gz


@njit(cache=True)
def cg_step(p, g, t, r, allowed, stalled, exact, restart, tol, done, tau_out, extra, n_extra, escale):
    """Step ``p`` along ``-t`` (exact line search), clip at zero, let penetrating cells
    outside the contact in (Polonsky & Keer's overlap correction); set ``restart`` and
    ``done`` (small relative change and no cell entering, or nothing left to do).

    For the displacement update (:func:`update_displacement`): the step ``tau_out``, and
    where clipping or entering moved ``p`` off the straight step ``p - tau t``, that
    difference in ``extra`` (zero elsewhere) and the number of such cells in ``n_extra``.
    A cell enters with the pressure ``-tau escale g`` (``escale``: the preconditioner's own
    weight of a cell's gap, 1 for the plain method).  Returns True if any problem is done."""
    K, nx, ny = p.shape
    any_done = False
    for k in range(K):
        den = 0.0
        num = 0.0
        for i in range(nx):
            for j in range(ny):
                den += r[k, i, j] * t[k, i, j]
                num += g[k, i, j] * t[k, i, j]
        tau = num / den if (den > 0.0 and not stalled[k]) else 0.0
        tau_out[k] = tau
        tot = 0.0
        change = 0.0
        entered = False
        n = 0
        for i in range(nx):
            for j in range(ny):
                old = p[k, i, j]
                lin = old - tau * t[k, i, j]
                pn = lin
                if pn < 0.0:
                    pn = 0.0
                if pn == 0.0 and g[k, i, j] < 0.0 and allowed[k, i, j] and not stalled[k]:
                    pn -= tau * escale * g[k, i, j]
                    entered = True
                e = pn - lin
                extra[k, i, j] = e
                if e != 0.0:
                    n += 1
                p[k, i, j] = pn
                tot += pn
                change += abs(pn - old)
        n_extra[k] = n
        restart[k] = entered or stalled[k]
        done[k] = (exact[k] or (not restart[k] and tot > 0.0 and change < tol * tot)
                   or (den <= 0.0 and not stalled[k]))
        any_done = any_done or done[k]
    return any_done


@njit(cache=True)
def update_displacement(u, r, tau, extra, n_extra, kern, stalled, max_cells, refresh, fresh, shear):
    """``u(p)`` after a step, without a transform: ``u - tau u(t) + u(extra)``, the last by
    direct summation over the few cells in ``extra`` (``kern[|di|, |dj|]``: a cell's
    displacement under unit pressure on another, m/Pa; in the sheared layout of
    :func:`cg_direction` the array offset (di, dj) is the grid offset (di, dj + shear di)).  A problem
    that is ``stalled``, has more than ``max_cells`` such cells, or every problem if ``refresh``, is marked
    ``fresh`` and left (its displacement is to be transformed anew).  Returns True if any is."""
    K, nx, ny = u.shape
    any_fresh = False
    for k in range(K):
        fresh[k] = refresh or stalled[k] or n_extra[k] > max_cells
        if fresh[k]:
            any_fresh = True
            continue
        tk = tau[k]
        for i in range(nx):
            for j in range(ny):
                u[k, i, j] -= tk * r[k, i, j]
        if n_extra[k] == 0:
            continue
        for ci in range(nx):
            for cj in range(ny):
                e = extra[k, ci, cj]
                if e == 0.0:
                    continue
                for i in range(nx):
                    di = abs(i - ci)
                    sh = cj - shear * (i - ci)
                    for j in range(ny):
                        u[k, i, j] += e * kern[di, abs(j - sh)]
    return any_fresh


@njit(cache=True)
def torus_gap(S, Z, depth, R, rb, rg, centre, sign, rho0, outer, out):
    """:meth:`.geometry.RaceGeometry.approach` in one compiled pass over flat arrays of track
    positions ``S`` (m along the track from the ball) and ``Z`` (m across), the surface moved
    ``depth`` into the ring; 1.0 (m: never touches) where the ball cannot reach, written to
    ``out``.  Tested against ``approach``."""
    for n in range(S.size):
        out[n] = _gap1(S[n], Z[n], depth, R, rb, rg, centre, sign, rho0, outer)
    return out


@njit(cache=True, inline="always")
def _gap1(s, z, depth, R, rb, rg, centre, sign, rho0, outer):
    dphi = s / R
    r = centre + sign * (math.sqrt(max(rg * rg - z * z, 0.0)) + depth)
    sn = math.sin(dphi)
    cs = math.cos(dphi)
    arg = rb * rb - z * z - (r * sn) ** 2
    if arg >= 0.0 and abs(z) < rg and cs > 0.0:
        rc = r * cs
        return (rc - rho0 if outer else rho0 - rc) - math.sqrt(arg)
    return 1.0


@njit(cache=True)
def window_gaps(xu, xv, du, dv, c, sn, n_u, n_v, delta, depth, R, rb, rg, centre, sign, rho0, outer,
                gap, ins, fu, fv):
    """The gaps of a skewed table's windows (:func:`.halfspace_skewed.windows`, as its ratio curve uses
    them) in one pass: for ball k, ``xu[k], xv[k]`` its position in cells on the defect-anchored grid
    (cells ``du x dv``, the outline ``n_u x n_v`` of them, the window ``gap.shape[1:]``), the window's
    cells at track positions relative to the ball turned by the skew (``c, sn``); ``gap`` the intact
    gap, the floor's (``depth`` into the ring) on cells inside the outline whose intact gap is below
    ``delta``, which are marked in ``ins``; ``fu, fv`` the ball's offsets within a cell.  The
    arithmetic is numpy's in :func:`.halfspace_skewed.windows`, operation for operation (tested), and
    the floor's gap is computed only where it is read.  The windows of a skewed table ask for about
    10^5 gaps per round of ball positions, where numpy's passes cost a tenth of the table."""
    K, nu, nv = gap.shape
    for k in range(K):
        i0 = math.floor(xu[k])
        j0 = math.floor(xv[k])
        fu[k] = xu[k] - i0
        fv[k] = xv[k] - j0
        for a in range(nu):
            dU = (a + 0.5 - nu / 2 - fu[k]) * du
            in_u = 0 <= i0 + a < n_u
            for b in range(nv):
                dV = (b + 0.5 - nv / 2 - fv[k]) * dv
                s = dU * c - dV * sn
                z = dU * sn + dV * c
                g = _gap1(s, z, 0.0, R, rb, rg, centre, sign, rho0, outer)
                inside = in_u and 0 <= j0 + b < n_v and g < delta
                if inside:
                    g = _gap1(s, z, depth, R, rb, rg, centre, sign, rho0, outer)
                gap[k, a, b] = g
                ins[k, a, b] = inside


@njit(cache=True)
def outline_candidates(sa, ca, zz, r, sp, cp, rb2, rho0, outer, margin, cand_j, cand_k):
    """The outline points that may hold a rigid ball (:func:`.geometry.drop_profile_2d`): for each ball
    position j and outline point k the gap of ``approach`` computed cheaply, the angle ``a_k - b_j``
    between them taken from the sines and cosines of both (``sa, ca`` of the points' angles,
    ``sp, cp`` of the balls'), no transcendental per pair; ``zz`` the points' z^2, ``r`` their surface
    radius.  Every pair whose cheap gap is within ``margin`` of its position's lowest goes to
    ``cand_j, cand_k`` (and a few more, within twice the margin: the list of a position is kept in one
    pass, emptied when a gap lower by more than the margin comes).  Returns the number of pairs, or -1
    if they would not fit (the arrays' size).  The cheap gap differs from ``approach`` by rounding
    only (~1e-16 m near the ball), so the point ``approach`` puts lowest is among those within a
    margin of 1e-12 m."""
    n = 0
    cap = cand_j.size
    for j in range(sp.size):
        start = n
        best = math.inf
        for k in range(sa.size):
            sn = sa[k] * cp[j] - ca[k] * sp[j]
            cs = ca[k] * cp[j] + sa[k] * sp[j]
            arg = rb2 - zz[k] - (r[k] * sn) ** 2
            if cs <= 0.0 or arg < 0.0:
                continue
            rc = r[k] * cs
            h = (rc - rho0 if outer else rho0 - rc) - math.sqrt(arg)
            if h < best - margin:
                n = start
            elif h > best + margin:
                continue
            if h < best:
                best = h
            if n >= cap:
                return -1
            cand_j[n] = j
            cand_k[n] = k
            n += 1
    return n


def warm_up():
    """Compile (or load from numba's cache) the kernels on a tiny problem."""
    p = np.ones((1, 2, 2))
    g = np.zeros((1, 2, 2))
    b = np.ones((1, 2, 2), dtype=np.bool_)
    f = np.zeros(1)
    flags = np.zeros(1, dtype=np.bool_)
    cg_direction(p, g.copy(), g, g.copy(), g.copy(), b, flags.copy(), f.copy(), f.copy(), 1.0,
                 flags.copy(), flags.copy(), np.diag([0.0, 1.0, 0.0]), np.zeros((1, 4, 4)),
                 g.copy(), 0)
    n = np.zeros(1, dtype=np.int64)
    cg_step(p, g, g.copy(), g.copy(), b, flags.copy(), flags.copy(), flags.copy(), 1e-4, flags.copy(),
            f.copy(), g.copy(), n, 1.0)
    update_displacement(g, g.copy(), f.copy(), g.copy(), n, np.ones((2, 2)), flags.copy(), 32,
                        False, flags.copy(), 0)
    torus_gap(f.copy(), f.copy(), 0.0, 1.0, 1.0, 1.1, 0.0, 1.0, 0.0, True, f.copy())
    window_gaps(f.copy(), f.copy(), 1.0, 1.0, 1.0, 0.0, 1, 1, 0.1, 0.0, 1.0, 1.0, 1.1, 0.0, 1.0, 0.0, True,
                g.copy(), b.copy(), f.copy(), f.copy())
    outline_candidates(f.copy(), f + 1.0, f.copy(), f + 1.0, f.copy(), f + 1.0, 1.0, 0.0, True, 1e-12,
                       n.copy(), n.copy())
