"""numba kernel of the static equilibrium: each ball's split of its approach between its two
contacts (called a few hundred times while the start state is solved; in numpy each call cost
~0.5 ms of array overhead for 8-20 balls)."""
from __future__ import annotations

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
