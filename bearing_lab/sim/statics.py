"""The planar bearing's static equilibrium that starts every run: ball loads from the rings'
relative displacement (Hertz, with each ball's centrifugal force and weight), and the rings'
positions where their supports balance the load (no numba here, no scipy: every solve is
Newton's method or Brent's, :mod:`.numerics`).

Public API
----------
bearing_force(e, phis, k_eff, pd, exponent=1.5)                      -- the balls' total force on a ring
ball_contact_loads(e, phis, k_in, k_out, pd, body_force, exponent=1.5) -- each ball's inner and outer load
static_equilibrium(scene, phi_c0, k_in, k_out, *, ball_mass, omega_cage, exponent, phases) -> dict
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import SceneError, SolverError
from .hertz import series_stiffness
from ._equilibrium_kernel import split_contacts
from .numerics import brentq
from .scene import Scene

__all__ = ["unit_vector", "bearing_force", "ball_contact_loads", "static_equilibrium"]


def unit_vector(angle):
    return np.array([math.cos(angle), math.sin(angle)])


def bearing_force(e, phis, k_eff, pd, exponent=1.5):
    """Force (N, 2-vector) the balls exert on the OUTER ring for relative
    displacement e = inner - outer (quasi-static, massless balls)."""
    c, s = np.cos(phis), np.sin(phis)
    d = e[0] * c + e[1] * s - pd / 2
    q = k_eff * np.maximum(d, 0.0) ** exponent
    return np.array([np.sum(q * c), np.sum(q * s)]), q


def ball_contact_loads(e, phis, k_in, k_out, pd, body_force, exponent=1.5):
    """Inner- and outer-contact loads (N) of each ball for relative ring displacement
    e = inner - outer, each ball in radial equilibrium under ``body_force`` (N, outward;
    the centrifugal force of its orbit minus the outward component of its weight):
    ``Q_o = Q_i + body_force``.  With no body force this is the two contacts in series.

    The ball's total approach ``T = e.u - pd/2`` splits into ``d_i + d_o``; ``d_o`` solves
    ``K_o d_o^n - K_i (T - d_o)^n = body_force`` (increasing in ``d_o``), by Newton's
    method kept inside a bracket.  A ball that cannot touch both races rests on one.
    """
    u = np.stack([np.cos(phis), np.sin(phis)])
    T = np.ascontiguousarray(np.asarray(e, dtype=float) @ u - pd / 2, dtype=float)
    fb = np.ascontiguousarray(np.broadcast_to(np.asarray(body_force, dtype=float), T.shape))
    q_in = np.empty_like(T)
    q_out = np.empty_like(T)
    split_contacts(T, fb, float(k_in), float(k_out), float(exponent), q_in, q_out)
    return q_in, q_out


def _ring_forces(e, phis, k_in, k_out, pd, body_force, exponent=1.5):
    """(force on the inner ring, force on the outer ring, Q_i, Q_o) for displacement e."""
    q_in, q_out = ball_contact_loads(e, phis, k_in, k_out, pd, body_force, exponent)
    c, s = np.cos(phis), np.sin(phis)
    return (-np.array([np.sum(q_in * c), np.sum(q_in * s)]),
            np.array([np.sum(q_out * c), np.sum(q_out * s)]), q_in, q_out)


def _solve_relative(target, force_of, scale, where):
    """Relative ring displacement e with force_of(e) == target (N, 2-vector).

    ``force_of(e)`` grows along e (a bearing pushed further carries more); ``scale`` (m)
    brackets the search: e.g. the displacement that puts the whole load on one ball."""
    w = float(np.hypot(*target))
    direction = target / w if w > 1e-9 else np.array([0.0, -1.0])

    def along(a):
        return force_of(a * direction) @ direction - w
    lo, hi = -abs(scale) - 1e-6, abs(scale) + 1e-9
    while along(lo) > 0:
        lo *= 2
        if lo < -1e-2:
            raise SceneError(f"{where}: no static equilibrium (the balls' own forces cannot be balanced)")
    while along(hi) < 0:
        hi *= 2
        if hi > 1e-2:
            raise SceneError(f"{where}: no static equilibrium (load {w:.3g} N too large for the bearing)")
    a = brentq(along, lo, hi, xtol=1e-16, rtol=1e-14, where=f"{where}: static equilibrium along the load")
    return _newton_2d(lambda e: force_of(e) - target, a * direction, max(w, 1.0), abs(scale), where)


def _newton_2d(residual, e, norm, scale, where, *, tol=1e-10, accept=1e-6, iterations=60):
    """Newton's method with a backtracking line search on a 2-D balance ``residual(e) = 0`` (N, or
    any unit of ``norm``), from ``e`` (m).  The Jacobian by central differences.
    Converged when the residual is below ``tol`` x ``norm``; when the line search stalls first
    (rounding), a residual below ``accept`` x ``norm`` is taken; otherwise a SceneError names
    the unbalance: the start is never taken from an unbalanced solution."""
    r = residual(e)
    h = 1e-7 * max(scale, 1e-9)
    for _ in range(iterations):
        if np.max(np.abs(r)) <= tol * norm:
            return e
        jac = np.column_stack([(residual(e + h * u) - residual(e - h * u)) / (2 * h) for u in np.eye(2)])
        try:
            step = np.linalg.solve(jac, -r)
        except np.linalg.LinAlgError:
            break
        t, size = 1.0, float(np.max(np.abs(r)))
        while t > 1e-6:
            trial = residual(e + t * step)
            if np.all(np.isfinite(trial)) and np.max(np.abs(trial)) < size:
                e, r = e + t * step, trial
                break
            t *= 0.5
        else:
            break
    if np.max(np.abs(r)) <= accept * norm:     # a float's worth from the balance: as good as it gets
        return e
    raise SceneError(f"{where}: static equilibrium not found (unbalanced force {np.max(np.abs(r)):.3g} N of "
                     f"{norm:.3g} N after Newton's method)")


def _loaded_ring_positions(on, phases, z, phi_c0, forces_at, f_in, f_out, ks, km, scale):
    """Ring positions (xi, xo stacked) with the loaded ring's spring unstressed, at
    ``phases`` cage positions across one ball spacing."""
    pos = []
    for k in range(phases):
        _, _, forces = forces_at(phi_c0 + 2 * math.pi * k / (phases * z))
        if on == "outer":
            # the mount unstressed: the balls hold the outer ring's load and weight
            e = _solve_relative(-f_out, lambda e: forces(e)[1], scale, "load")
            xi = (forces(e)[0] + f_in) / ks
            pos.append(np.concatenate([xi, xi - e]))
        else:
            # the shaft spring unstressed: the balls hold the inner ring's load and weight
            e = _solve_relative(f_in, lambda e: -forces(e)[0], scale, "load")
            xo = (forces(e)[1] + f_out) / km
            pos.append(np.concatenate([xo + e, xo]))
    return pos


def static_equilibrium(scene: Scene, phi_c0: float, k_in: float, k_out: float, *,
                       ball_mass: float = 0.0, omega_cage: float = 0.0, exponent: float = 1.5,
                       phases: int = 4) -> dict:
    """Static equilibrium of the rings and balls at the start of a run (no defects).

    Each ball is in radial equilibrium between its two contacts under its centrifugal
    force ``m_b (d_m/2) omega_cage^2`` and weight (``ball_mass = 0``: massless balls, the
    quasi-static fidelity), so the outer contact carries ``Q_o = Q_i + m_b (d_m/2)
    omega_c^2 - m_b g sin(phi_j)``.

    Load path "bearing": the loaded ring's support spring is preloaded so that it carries
    no load on average over a ball spacing: its rest position is the mean of the ring's
    equilibrium positions at ``phases`` cage positions (the ring moves with the number of
    balls in the load zone), and the start (cage at ``phi_c0``) is the exact equilibrium
    with that spring.  Load path "springs": both springs unstressed at the centre.

    Returns ring positions, the springs' rest positions, the external forces on each ring
    (load + weight), the ball loads at both contacts and their body forces.
    """
    d = scene.data
    z = scene.bearing.n_balls
    m_i, m_o, _ = scene.masses()
    g = d["gravity"]["g_m_s2"] if d["gravity"]["enabled"] else 0.0
    gvec = np.array([0.0, -g])
    load = d["load"]["radial_n"] * unit_vector(math.radians(d["load"]["direction_deg"]))
    f_in = m_i * gvec + (load if d["load"]["on"] == "inner" else 0.0)
    f_out = m_o * gvec + (load if d["load"]["on"] == "outer" else 0.0)
    ks = np.array([d["shaft"]["stiffness_x_n_m"], d["shaft"]["stiffness_y_n_m"]])
    km = np.array([d["mount"]["stiffness_x_n_m"], d["mount"]["stiffness_y_n_m"]])
    pd = scene.clearance
    k_eff = series_stiffness(k_in, k_out)
    scale = pd / 2 + (max(float(np.hypot(*load)), 1.0) / k_eff) ** (1 / exponent) * 4

    def forces_at(phi0):
        phis = phi0 + 2 * math.pi * np.arange(z) / z
        body = ball_mass * (scene.bearing.pitch_diameter / 2 * omega_cage ** 2 - g * np.sin(phis))
        return phis, body, lambda e: _ring_forces(e, phis, k_in, k_out, pd, body, exponent)

    rest_i, rest_o = np.zeros(2), np.zeros(2)
    x0 = np.concatenate([f_in / ks, f_out / km])
    if d["load"]["path"] == "bearing":
        pos = _loaded_ring_positions(d["load"]["on"], phases, z, phi_c0, forces_at, f_in, f_out,
                                     ks, km, scale)
        x0 = pos[0]
        if d["load"]["on"] == "outer":
            rest_o = np.mean(pos, axis=0)[2:]
        else:
            rest_i = np.mean(pos, axis=0)[:2]
    phis, body, forces = forces_at(phi_c0)

    def rings(e):
        # each ring where its spring balances the balls' force and its external force
        fi, fo, _, _ = forces(e)
        return rest_i + (fi + f_in) / ks, rest_o + (fo + f_out) / km

    w = max(float(np.hypot(*load)), 1.0)

    def resid(e):
        # the rings' positions against e, as a force: the load times the mismatch in units of scale
        xi, xo = rings(e)
        return (xi - xo - e) / scale * w
    e0 = x0[:2] - x0[2:]
    # the balance to rounding (1e-15 of the load; 2-3 Newton steps from e0): the root Powell's
    # hybrid method (scipy.optimize.root) finds, to one ulp of e
    try:
        e = _newton_2d(resid, e0, w, scale, f"scene {scene.name!r}", tol=1e-15, accept=1e-9)
    except SceneError as exc:
        raise SolverError(str(exc)) from None
    xi, xo = rings(e)
    _, _, q_in, q_out = forces(xi - xo)
    return {"xi": xi, "xo": xo, "rest_i": rest_i, "rest_o": rest_o, "f_in": f_in, "f_out": f_out,
            "ball_loads": q_out, "ball_loads_inner": q_in, "ball_loads_outer": q_out,
            "ball_body_force": body, "phis": phis, "load_vec": load, "gvec": gvec}
