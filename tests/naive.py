"""Slow, obvious reference implementations that the fast code is tested against.

Nothing here imports bearing_lab's kernels: each function is written from the
textbook formula so that a sign or factor error in the package cannot hide.
"""
from __future__ import annotations

import math

import numpy as np


def hertz_stiffness_harris(sum_rho_per_mm: float, delta_star: float) -> float:
    """Harris & Kotzalas steel constant: K = 2.15e5 Σρ^-1/2 δ*^-3/2 (N/mm^1.5) -> N/m^1.5."""
    k_mm = 2.15e5 * sum_rho_per_mm ** -0.5 * delta_star ** -1.5
    return k_mm * 1e3 ** 1.5


def static_ball_loads(force, angles, k_eff, clearance=0.0, iters=100):
    """Quasi-static ball loads under a radial force (2-vector, N) on the inner ring.

    Newton's method on the inner-ring displacement e with an analytic Jacobian:
    sum_j K (e.u_j - Pd/2)_+^1.5 u_j = F.
    """
    u = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    f = np.asarray(force, float)
    w = np.linalg.norm(f)
    e = f / w * (clearance / 2 + (5 * w / (len(angles) * k_eff)) ** (2 / 3))
    for _ in range(iters):
        d = u @ e - clearance / 2
        dp = np.maximum(d, 0.0)
        q = k_eff * dp ** 1.5
        r = u.T @ q - f
        J = (u * (1.5 * k_eff * np.sqrt(dp))[:, None]).T @ u
        step = np.linalg.solve(J + 1e-3 * np.eye(2) * np.trace(J) * 1e-9, r)
        e = e - step
        if np.linalg.norm(step) < 1e-16:
            break
    d = u @ e - clearance / 2
    return k_eff * np.maximum(d, 0.0) ** 1.5, e


def impulse_times(x, fs, threshold_frac=0.5, dead_time=None):
    """Times of impulses: first upward crossing of threshold_frac * max|x| after a dead time,
    refined by linear interpolation between samples."""
    a = np.abs(np.asarray(x, float))
    thr = threshold_frac * a.max()
    dead = int(round((dead_time or 0.0) * fs))
    times = []
    i = 1
    n = len(a)
    while i < n:
        if a[i] >= thr and a[i - 1] < thr:
            frac = (thr - a[i - 1]) / (a[i] - a[i - 1])
            times.append((i - 1 + frac) / fs)
            i += max(dead, 1)
        else:
            i += 1
    return np.array(times)


def interpolated_peak_frequency(x, fs, f_lo, f_hi, pad=8):
    """Frequency of the largest spectral line in [f_lo, f_hi]: Hann window, zero padding,
    parabolic interpolation of the log magnitude (Gaussian peak fit)."""
    x = np.asarray(x, float) - np.mean(x)
    n = len(x)
    w = np.hanning(n)
    nfft = pad * n
    spec = np.abs(np.fft.rfft(x * w, nfft))
    f = np.fft.rfftfreq(nfft, 1 / fs)
    m = (f >= f_lo) & (f <= f_hi)
    i = np.flatnonzero(m)[np.argmax(spec[m])]
    a, b, c = np.log(spec[i - 1:i + 2])
    p = 0.5 * (a - c) / (a - 2 * b + c)
    return f[i] + p * (f[1] - f[0])


# ----------------------------------------------------------------------------- half-space

def torus_gap(s, z, *, ball_radius, groove_radius, track_radius, depth=0.0):
    """Approach (m) at which a ball centred at s = 0 on the outer race's track centre line
    first touches the groove point (s along the track, z across), the groove moved
    ``depth`` outward.  Written from the geometry: the groove surface lies at radius
    r(z) = R_c + sqrt(r_g^2 - z^2) + depth (R_c = R - r_g); the ball of radius r_b, its centre
    at radius rho on the angle of s = 0, touches a point at angle phi = s / R when
    (r cos phi - rho)^2 + (r sin phi)^2 + z^2 = r_b^2, first for rho = R - r_b + h."""
    r = (track_radius - groove_radius) + np.sqrt(groove_radius ** 2 - z ** 2) + depth
    phi = s / track_radius
    inside = ball_radius ** 2 - z ** 2 - (r * np.sin(phi)) ** 2
    return r * np.cos(phi) - np.sqrt(inside) - (track_radius - ball_radius)


def boussinesq_matrix(iz, js, dz, ds, e_star, order=16):
    """Dense influence matrix (m/Pa) of cells (iz, js) (integer indices on a uniform grid of
    dz x ds cells): displacement at the centre of cell i under unit pressure on cell j.

    Boussinesq's point load, 1/(pi E* r), integrated over the source cell with
    ``order`` x ``order`` Gauss-Legendre points; the cell itself by the closed form at
    the centre of a uniformly loaded 2a x 2b rectangle, (2/(pi E*)) [a asinh(b/a) +
    b asinh(a/b)] (Johnson, Contact Mechanics, 1985, section 3.2)."""
    x, w = np.polynomial.legendre.leggauss(order)
    qz = (x[:, None] * np.ones(order)[None, :]).ravel() * dz / 2
    qs = (np.ones(order)[:, None] * x[None, :]).ravel() * ds / 2
    qw = (w[:, None] * w[None, :]).ravel() * dz * ds / 4
    nz, ns = int(np.ptp(iz)) + 1, int(np.ptp(js)) + 1
    oz = np.arange(nz)[:, None] * dz
    os_ = np.arange(ns)[None, :] * ds
    kern = np.zeros((nz, ns))
    for a_, b_, c_ in zip(qz, qs, qw):
        r = np.hypot(oz - a_, os_ - b_)
        kern += c_ / r
    a, b = dz / 2, ds / 2
    kern[0, 0] = 4 * (a * math.asinh(b / a) + b * math.asinh(a / b))
    kern /= math.pi * e_star
    return kern[np.abs(iz[:, None] - iz[None, :]), np.abs(js[:, None] - js[None, :])]


def contact_nnls(A, gap, approach):
    """Pressures p >= 0 with A p + gap - approach >= 0, complementary (frictionless normal
    contact at a fixed approach).  For a symmetric positive definite A this is the
    minimum of p.A.p/2 - (approach - gap).p over p >= 0; with A = L L^T that is the
    non-negative least-squares problem ||L^T p - L^-1 (approach - gap)|| (Lawson-Hanson,
    scipy.optimize.nnls)."""
    from scipy.linalg import cholesky, solve_triangular
    from scipy.optimize import nnls
    A = 0.5 * (A + A.T)
    L = cholesky(A, lower=True)
    b = solve_triangular(L, approach - gap, lower=True)
    p, _ = nnls(L.T, b, maxiter=50 * gap.size)
    return p


def halfspace_share(geom_radii, approach, *, pit, cell_z, cell_s, half_z, half_s, e_star=114.3e9):
    """F(pit) / F(intact) at the same approach, ball centred at s = 0, brute force.

    ``pit(s, z)`` -> bool (the removed outline, floor never reached); cells centred at
    ((i + 1/2) cell_z, (j + 1/2) cell_s) over |z| < half_z, |s| < half_s (so outline sides
    at multiples of the cell sizes fall on cell boundaries)."""
    nz, ns = round(half_z / cell_z), round(half_s / cell_s)
    I, J = np.meshgrid(np.arange(-nz, nz), np.arange(-ns, ns), indexing="ij")
    Z, S = (I + 0.5) * cell_z, (J + 0.5) * cell_s
    gap = torus_gap(S, Z, **geom_radii)
    keep = np.isfinite(gap) & (gap < approach)
    forces = []
    for removed in (np.zeros_like(keep), pit(S, Z)):
        cells = keep & ~removed
        A = boussinesq_matrix(I[cells], J[cells], cell_z, cell_s, e_star)
        p = contact_nnls(A, gap[cells], approach)
        forces.append(p.sum() * cell_z * cell_s)
    return forces[1] / forces[0], forces[0]


def spectral_coherence_at(x, fs, alpha, nw):
    """Cyclic spectral coherence magnitude at one cyclic frequency, averaged over f (brute force).

    Welch cross-spectrum of x(t) and x(t) exp(-2j pi alpha t) with Hann frames of nw
    samples and half overlap, normalised by the two power spectra (the textbook
    definition, Antoni 2009), magnitude averaged over the interior bins.
    """
    x = np.asarray(x, float) - np.mean(x)
    t = np.arange(x.size) / fs
    y = x * np.exp(-2j * np.pi * alpha * t)
    w = np.hanning(nw + 1)[:-1]
    sxy = np.zeros(nw, complex)
    sxx = np.zeros(nw)
    syy = np.zeros(nw)
    for start in range(0, x.size - nw + 1, nw // 2):
        X = np.fft.fft(w * x[start:start + nw])
        Y = np.fft.fft(w * y[start:start + nw])
        sxy += X * np.conj(Y)
        sxx += np.abs(X) ** 2
        syy += np.abs(Y) ** 2
    coh = np.abs(sxy) / np.sqrt(sxx * syy)
    return float(np.mean(coh[1:nw // 2]))


def resample_at_angle(x, fs, pulse_times, pulses_per_rev=1):
    """Order tracking the slow way: shaft angle by linear interpolation between pulses,
    then linear interpolation of x at each equal-angle instant."""
    p = np.asarray(pulse_times, float)
    revs = np.arange(p.size) / pulses_per_rev
    shaft = revs[-1] / (p[-1] - p[0])
    out = []
    a = revs[0]
    while a <= revs[-1]:
        t = np.interp(a, revs, p)
        if t * fs > x.size - 1:
            break
        out.append(np.interp(t * fs, np.arange(x.size), x))
        a += shaft / fs
    return np.array(out), float(shaft)


def halfspace_share_rotated(geom_radii, approach, *, length, width, offset, skew, s_ball,
                            cell_u, cell_v, half_u, half_v, e_star=114.3e9):
    """F(pit) / F(intact) at the same approach for an L x W rectangular pit (floor never
    reached) centred at axial offset ``offset`` and inclined by ``skew`` (rad) to the track,
    the ball centred at track position ``s_ball`` (m from the pit centre), brute force.

    The cells are cell_u x cell_v along the pit's own axes with boundaries on its sides
    (the influence of a loaded cell depends only on the cells' relative position, so a
    rotated grid serves as well as one along the track); they cover |u - u_ball| < half_u,
    |v - v_ball| < half_v around the ball's position in the pit's axes."""
    c, sn = math.cos(skew), math.sin(skew)
    u_b, v_b = s_ball * c - offset * sn, -s_ball * sn - offset * c
    i = np.arange(math.floor((u_b - half_u + length / 2) / cell_u),
                  math.ceil((u_b + half_u + length / 2) / cell_u))
    j = np.arange(math.floor((v_b - half_v + width / 2) / cell_v),
                  math.ceil((v_b + half_v + width / 2) / cell_v))
    I, J = np.meshgrid(i, j, indexing="ij")
    U, V = -length / 2 + (I + 0.5) * cell_u, -width / 2 + (J + 0.5) * cell_v
    S, Z = U * c - V * sn - s_ball, offset + U * sn + V * c
    with np.errstate(invalid="ignore"):
        gap = torus_gap(S, Z, **geom_radii)
    keep = np.isfinite(gap) & (gap < approach)
    if keep[0].any() or keep[-1].any() or keep[:, 0].any() or keep[:, -1].any():
        raise ValueError("the contact reaches the edge of the brute-force grid")
    pit = (I >= 0) & (I < round(length / cell_u)) & (J >= 0) & (J < round(width / cell_v))
    forces = []
    for removed in (np.zeros_like(keep), pit):
        cells = keep & ~removed
        A = boussinesq_matrix(I[cells], J[cells], cell_u, cell_v, e_star)
        p = contact_nnls(A, gap[cells], approach)
        forces.append(p.sum() * cell_u * cell_v)
    return forces[1] / forces[0], forces[0]
