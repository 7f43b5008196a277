"""Hertz point contact between a ball and a grooved raceway (Harris & Kotzalas).

Why this module: the paper's printed stiffness equations (its eqs 6 and 8) are
garbled; we use the formulation of Harris & Kotzalas, *Essential Concepts of
Bearing Technology* (5th ed.), section "Contact stress and deformation", which
the paper cites as [28]:

- curvature sum  ``Σρ = 1/r_I1 + 1/r_II1 + 1/r_I2 + 1/r_II2`` and curvature
  difference ``F(ρ) = [(ρ_I1 − ρ_II1) + (ρ_I2 − ρ_II2)] / Σρ``;
- ellipticity κ = a/b solves ``F(ρ) = [(κ²+1)·E − 2·K] / [(κ²−1)·E]`` with
  the complete elliptic integrals K, E of modulus ``e² = 1 − 1/κ²``;
- ``δ* = (2K/π)·(π/(2κ²E))^(1/3)``, ``a* = (2κ²E/π)^(1/3)``,
  ``b* = (2E/(πκ))^(1/3)``;
- ``δ = δ*·(Σρ/2)·(3Q/(E'·Σρ))^(2/3)`` and ``a = a*·(3Q/(E'·Σρ))^(1/3)``
  with ``E' = 2 / [(1−ν₁²)/E₁ + (1−ν₂²)/E₂]``.

Inverting gives ``Q = K_c·δ^1.5``.  For steel (E = 208 GPa, ν = 0.3) this is
Harris's ``K_c = 2.15e5·Σρ^(−1/2)·δ*^(−3/2)`` N/mm^1.5.
"""
from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from ..errors import SceneError
from .numerics import brentq, ellipe, ellipk


@dataclass(frozen=True)
class HertzContact:
    """Hertz constants of one ball-race contact (SI)."""

    curvature_sum: float        # Σρ, 1/m
    curvature_difference: float  # F(ρ)
    ellipticity: float          # κ = a/b
    delta_star: float           # δ*
    a_star: float
    b_star: float
    stiffness: float            # K_c, N/m^1.5
    e_prime: float              # E', Pa
    rx: float                   # effective radius along the rolling direction, m
    ry: float                   # effective radius across the track, m

    def force(self, delta):
        """Elastic force (N) at approach ``delta`` (m); zero when separated."""
        d = np.maximum(np.asarray(delta, dtype=float), 0.0)
        return self.stiffness * d ** 1.5

    def approach(self, force):
        """Approach δ (m) under normal force ``force`` (N)."""
        return (np.asarray(force, dtype=float) / self.stiffness) ** (2.0 / 3.0)

    def semi_axes(self, force):
        """Contact-ellipse semi-axes (a across the track, b along it), m, at ``force`` N."""
        s = (3.0 * np.asarray(force, dtype=float) / (self.e_prime * self.curvature_sum)) ** (1 / 3)
        return self.a_star * s, self.b_star * s


def _kappa_from_f(f_rho: float) -> float:
    if not (0.0 <= f_rho < 1.0):
        raise SceneError(f"curvature difference F(rho)={f_rho} outside [0, 1): impossible groove geometry")
    if f_rho < 1e-9:
        return 1.0

    def g(kappa):
        m = 1.0 - 1.0 / kappa ** 2
        ek, ee = ellipk(m), ellipe(m)
        return ((kappa ** 2 + 1) * ee - 2 * ek) / ((kappa ** 2 - 1) * ee) - f_rho

    return brentq(g, 1.0 + 1e-9, 1e4, xtol=1e-13, rtol=1e-13, maxiter=500,
                  where=f"Hertz ellipticity for F(rho)={f_rho}")


def e_prime(e1: float, nu1: float, e2: float | None = None, nu2: float | None = None) -> float:
    e2 = e1 if e2 is None else e2
    nu2 = nu1 if nu2 is None else nu2
    return 2.0 / ((1 - nu1 ** 2) / e1 + (1 - nu2 ** 2) / e2)


def race_contact(ball_diameter: float, pitch_diameter: float, conformity: float, race: str, *,
                 contact_angle: float = 0.0, youngs_modulus: float = 208e9,
                 poisson_ratio: float = 0.3) -> HertzContact:
    """Hertz constants of the ball–``race`` contact ("inner" or "outer").

    Parameters
    ----------
    ball_diameter, pitch_diameter : m.
    conformity : groove radius over ball diameter (f_i or f_o).
    race : "inner" or "outer".
    contact_angle : rad.
    youngs_modulus : Pa (balls and rings of the same steel).
    poisson_ratio : -.

    Examples
    --------
    >>> c = race_contact(15.081e-3, 65e-3, 0.53, "outer")
    >>> round(c.stiffness / 1e10, 2)   # Harris & Kotzalas's method by hand: 3.27e10 N/m^1.5
    3.27
    """
    if race not in ("inner", "outer"):
        raise SceneError(f"race={race!r} must be 'inner' or 'outer'")
    d = ball_diameter
    gamma = d * math.cos(contact_angle) / pitch_diameter
    rho_ball = 2.0 / d
    if race == "inner":
        rho_i2 = 2.0 / d * gamma / (1 - gamma)
    else:
        rho_i2 = -2.0 / d * gamma / (1 + gamma)
    rho_ii2 = -1.0 / (conformity * d)
    csum = 2 * rho_ball + rho_i2 + rho_ii2
    fr = (rho_i2 - rho_ii2) / csum
    kappa = _kappa_from_f(fr)
    m = 1.0 - 1.0 / kappa ** 2
    ek, ee = float(ellipk(m)), float(ellipe(m))
    dstar = 2 * ek / math.pi * (math.pi / (2 * kappa ** 2 * ee)) ** (1 / 3)
    astar = (2 * kappa ** 2 * ee / math.pi) ** (1 / 3)
    bstar = (2 * ee / (math.pi * kappa)) ** (1 / 3)
    ep = e_prime(youngs_modulus, poisson_ratio)
    # delta = dstar * csum/2 * (3Q/(E' csum))^(2/3)  ->  Q = K delta^1.5
    c = dstar * csum / 2 * (3.0 / (ep * csum)) ** (2.0 / 3.0)
    k = c ** -1.5
    rx = 1.0 / (rho_ball + rho_i2)
    ry = 1.0 / (rho_ball + rho_ii2)
    return HertzContact(csum, fr, kappa, dstar, astar, bstar, k, ep, rx, ry)


def series_stiffness(k_inner: float, k_outer: float) -> float:
    """Stiffness of two Hertz contacts in series: (K_i^(-2/3) + K_o^(-2/3))^(-3/2)."""
    return (k_inner ** (-2 / 3) + k_outer ** (-2 / 3)) ** -1.5
