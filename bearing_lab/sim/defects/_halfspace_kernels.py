"""numba kernels of the half-space solver: the element-wise steps of one conjugate-gradient
iteration (Polonsky & Keer, Wear 231, 1999) for a batch of problems.

Why numba: on the tables' small grids (about 34 x 26 cells) the two FFT convolutions of
an iteration cost ~25 µs per problem in single precision, while the dozen numpy
element-wise passes around them (masks, sums, clipping) cost three times that.  One
compiled pass per step does the same arithmetic at memory speed.  And most steps move
only a few cells off the straight step ``p - tau t`` (clipped at zero or entering; 78 %
of the steps of a skewed table move at most 4), so the next ``u(p)`` is
``u(p) - tau u(t)`` plus a direct sum over those cells (:func:`update_displacement`):
one transform per iteration instead of two.

Arrays are (K, nx, ny), float64: K independent problems, each with its own scalars.
``p`` pressure (Pa), ``g`` gap (m, becomes ``u(p) + h - approach``), ``t`` search
direction, ``r = u(t)``, ``allowed`` cells that can touch (the rigid gap is below the
approach).
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def cg_direction(p, g, hd, t, allowed, restart, g_old, floor, k00, stalled, exact):
    """Finish the gap (``g += hd``), form the new search direction ``t`` in place.

    A problem whose contact set is in equilibrium (or empty; ``sum g^2 <= floor``) is
    ``stalled``: its penetrating cells outside the contact enter with the pressure that
    would close their own gap alone (``-g / k00``); with none left it is ``exact``.
    """
    K, nx, ny = p.shape
    for k in range(K):
        G = 0.0
        for i in range(nx):
            for j in range(ny):
                g[k, i, j] += hd[k, i, j]
                if p[k, i, j] > 0.0:
                    G += g[k, i, j] * g[k, i, j]
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
        beta = 0.0 if restart[k] or g_old[k] <= 0.0 else G / g_old[k]
        for i in range(nx):
            for j in range(ny):
                if p[k, i, j] > 0.0:
                    t[k, i, j] = g[k, i, j] + beta * t[k, i, j]
                else:
                    t[k, i, j] = 0.0
        g_old[k] = G


@njit(cache=True)
def cg_step(p, g, t, r, allowed, stalled, exact, restart, tol, done, tau_out, extra, n_extra):
    """Step ``p`` along ``-t`` (exact line search), clip at zero, let penetrating cells
    outside the contact in (Polonsky & Keer's overlap correction); set ``restart`` and
    ``done`` (small relative change and no cell entering, or nothing left to do).

    For the displacement update (:func:`update_displacement`): the step ``tau_out``, and
    where clipping or entering moved ``p`` off the straight step ``p - tau t``, that
    difference in ``extra`` (zero elsewhere) and the number of such cells in ``n_extra``."""
    K, nx, ny = p.shape
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
                    pn -= tau * g[k, i, j]
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


@njit(cache=True)
def update_displacement(u, r, tau, extra, n_extra, kern, skip):
    """``u(p)`` after a step, without a transform: ``u - tau u(t) + u(extra)``, the last by
    direct summation over the few cells in ``extra`` (``kern[|di|, |dj|]``: a cell's
    displacement under unit pressure on another, m/Pa).  Problems in ``skip`` are left
    (their displacement is transformed anew)."""
    K, nx, ny = u.shape
    for k in range(K):
        if skip[k]:
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
                    for j in range(ny):
                        u[k, i, j] += e * kern[di, abs(j - cj)]


def warm_up():
    """Compile (or load from numba's cache) both kernels on a tiny problem."""
    p = np.ones((1, 2, 2))
    g = np.zeros((1, 2, 2))
    b = np.ones((1, 2, 2), dtype=np.bool_)
    f = np.zeros(1)
    flags = np.zeros(1, dtype=np.bool_)
    cg_direction(p, g, g.copy(), g.copy(), b, flags.copy(), f.copy(), f.copy(), 1.0,
                 flags.copy(), flags.copy())
    n = np.zeros(1, dtype=np.int64)
    cg_step(p, g, g.copy(), g.copy(), b, flags.copy(), flags.copy(), flags.copy(), 1e-4, flags.copy(),
            f.copy(), g.copy(), n)
    update_displacement(g, g.copy(), f.copy(), g.copy(), n, np.ones((2, 2)), flags.copy())
