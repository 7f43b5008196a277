"""numba kernels of the static equilibrium: each ball's split of its approach between its two
contacts (called a few hundred times while the start state is solved; in numpy each call cost
~0.5 ms of array overhead for 8-20 balls), and in the 3-D bearing each multibody ball's position
between its grooves (:func:`balls_3d`)."""
from __future__ import annotations

import math

from numba import njit


@njit(cache=True, error_model="numpy")
def split_contacts(T, fb, k_in, k_out, n, q_in, q_out):
    """Inner and outer contact loads (N) of balls with total approach ``T`` (m) and outward
    body force ``fb`` (N) in radial equilibrium ``Q_o = Q_i + fb``: ``d_o`` solves
    ``K_o d_o^n - K_i (T - d_o)^n = fb`` by Newton's method kept inside a bracket; a ball that
    cannot touch both races rests on one (or carries nothing with a negative approach)."""
    for j in range(T.shape[0]):
        t = T[j]
        f_b = fb[j]
        lo = (max(f_b, 0.0) / k_out) ** (1.0 / n)       # Q_i = 0: on the outer race only
        hi = t - (max(-f_b, 0.0) / k_in) ** (1.0 / n)   # Q_o = 0: on the inner race only
        if hi > lo:
            x = 0.5 * (lo + hi)
            lo_b = lo
            hi_b = hi
            for _ in range(60):
                di = max(t - x, 0.0)
                do = max(x, 0.0)
                f = k_out * do ** n - k_in * di ** n - f_b
                df = n * (k_out * do ** (n - 1.0) + k_in * di ** (n - 1.0))
                if f < 0.0:
                    lo_b = x
                if f > 0.0:
                    hi_b = x
                xn = x - (f / df if df > 0.0 else 0.0)
                if xn <= lo_b or xn >= hi_b:
                    xn = 0.5 * (lo_b + hi_b)
                done = abs(xn - x) <= 1e-15 + 1e-13 * abs(x)
                x = xn
                if done:
                    break
            q_in[j] = k_in * max(t - x, 0.0) ** n
            q_out[j] = k_out * max(x, 0.0) ** n
        else:
            q_in[j] = max(-f_b, 0.0) if t > 0.0 else 0.0
            q_out[j] = max(f_b, 0.0)
            if f_b < 0.0 and t <= 0.0:
                q_in[j] = 0.0


@njit(cache=True, error_model="numpy")
def _ball_state(q, w, ro0, ri0, z_i, fc, a_i, a_o, k_in, k_out, n):
    """Ball (q, w): its energy (each contact's ``K d^(n+1) / (n+1)`` minus the work of the body
    force ``fc``), the net force on it (radial, axial) and the contacts' loads and lines."""
    ro, zo = q + ro0, w
    ri, zi = ri0 - q, z_i - w
    lo = math.hypot(ro, zo)
    li = math.hypot(ri, zi)
    do = max(lo - a_o, 0.0)
    di = max(li - a_i, 0.0)
    fo = k_out * do ** n
    fi = k_in * di ** n
    energy = (fo * do + fi * di) / (n + 1.0) - fc * q
    return energy, fi * ri / li - fo * ro / lo + fc, fi * zi / li - fo * zo / lo, fo, fi, ro, zo, lo, ri, zi, li


@njit(cache=True, error_model="numpy")
def _hessian_part(f, df, x, zz, ln):
    """One contact's part of the ball energy's Hessian: stiffness ``df`` along the contact line
    (unit vector ``(x, zz) / ln``), ``f / ln`` across it (the line turns as the ball moves)."""
    nx, nz = x / ln, zz / ln
    t = f / ln
    return df * nx * nx + t * (1.0 - nx * nx), (df - t) * nx * nz, df * nz * nz + t * (1.0 - nz * nz)


@njit(cache=True, error_model="numpy")
def balls_3d(u, z_i, fc, pd4, a_i, a_o, k_in, k_out, n, q, w, out):
    """Multibody balls between an outer ring at the origin and an inner ring displaced by ``u``
    (radially, per ball) and ``z_i`` (axially), each ball at the ``(q, w)`` (radial, axial,
    relative to the outer ring; in: the start, out: the solution) where its two Hertz contacts
    and its radial body force ``fc`` balance.

    The balance is the minimum of the ball's energy (each contact's ``K d^(n+1) / (n+1)``, ``d``
    the distance to the groove's curvature centre less ``a``, minus ``fc q``): a convex
    function, so Newton's method with the step halved until the energy falls converges from any
    start where a contact is loaded.  ``out[j]``: (Q_o, Q_i, rho_o, zeta_o, l_o, rho_i, zeta_i,
    l_i, |residual| / max(|fc|, Q_o, Q_i, 1 N)).  Returns the number of balls whose residual stayed above
    1e-11 (the caller solves those another way)."""
    bad = 0
    for j in range(u.shape[0]):
        ro0 = -pd4 + a_o              # rho_o = q + ro0, zeta_o = w
        ri0 = u[j] - pd4 + a_i        # rho_i = ri0 - q, zeta_i = z_i - w
        scale = max(abs(fc[j]), 1.0)
        qj = q[j]
        wj = w[j]
        for _ in range(100):
            e0, r1, r2, fo, fi, ro, zo, lo, ri, zi, li = _ball_state(qj, wj, ro0, ri0, z_i, fc[j], a_i, a_o, k_in,
                                                                     k_out, n)
            res = math.hypot(r1, r2)
            if res < 1e-14 * max(scale, fo, fi):
                break
            do = lo - a_o
            di = li - a_i
            a11, a12, a22 = _hessian_part(fo, n * k_out * do ** (n - 1.0) if do > 0.0 else 0.0, ro, zo, lo)
            b11, b12, b22 = _hessian_part(fi, n * k_in * di ** (n - 1.0) if di > 0.0 else 0.0, ri, zi, li)
            h11, h12, h22 = a11 + b11, a12 + b12, a22 + b22
            det = h11 * h22 - h12 * h12
            if not det > 0.0:
                break
            sq = (h22 * r1 - h12 * r2) / det
            sw = (h11 * r2 - h12 * r1) / det
            # the step halved until the energy falls or, near the minimum where the energy's
            # change is below its rounding, the net force does
            lam = 1.0
            for _ in range(60):
                e1, s1, s2, _, _, _, _, _, _, _, _ = _ball_state(qj + lam * sq, wj + lam * sw, ro0, ri0, z_i, fc[j],
                                                                 a_i, a_o, k_in, k_out, n)
                if e1 < e0 or math.hypot(s1, s2) < res:
                    break
                lam *= 0.5
            else:
                break
            qj += lam * sq
            wj += lam * sw
        q[j] = qj
        w[j] = wj
        _, r1, r2, fo, fi, ro, zo, lo, ri, zi, li = _ball_state(qj, wj, ro0, ri0, z_i, fc[j], a_i, a_o, k_in, k_out,
                                                                n)
        # relative to the largest force on the ball (the root search of the rings tries
        # displacements where the contacts carry 1e7 N: there 1e-11 N cannot be resolved)
        res = math.hypot(r1, r2) / max(scale, fo, fi)
        out[j, 0], out[j, 1], out[j, 2], out[j, 3], out[j, 4] = fo, fi, ro, zo, lo
        out[j, 5], out[j, 6], out[j, 7], out[j, 8] = ri, zi, li, res
        if not res <= 1e-11:
            bad += 1
    return bad
