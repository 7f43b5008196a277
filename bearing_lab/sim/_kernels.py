"""numba kernels of the bearing model: contact laws and the right-hand side (the integrator is in ``_stepper``).

Why numba: the model is a small ODE system (rings, balls, sensor) whose
right-hand side is evaluated millions of times per simulated second because
ball-race Hertz contacts ring at 15-25 kHz.  Calling a Python function per
evaluation (as scipy's ``solve_ivp`` does) costs more than the physics, so the
right-hand side and the integrator loop are compiled together here.

Conventions the kernels rely on (assembled by :mod:`bearing_lab.sim.assembly`):

- SI units; angles in rad, counter-clockwise positive; the shaft turns
  counter-clockwise; Y is up.
- ``p``: float64 parameter vector, indices ``P_*`` below; the kernels get it with the speed
  profile and the defect tables as one :class:`._loopargs.Model` ``m``.
- state ``y``: inner ring (x, y, vx, vy), outer ring (x, y, vx, vy), then for the
  multibody fidelity each ball's radial coordinate q_j = r_j − d_m/2 and its
  rate, then the sensor's relative displacements and rates (x, y).
- ball j sits at angle φ_j = φ_c(t) + 2πj/Z with the cage angle
  φ_c = φ_c0 + FTF/f_r · θ_s(t) (kinematic cage), θ_s the shaft angle.
- contact deflections are linearised in the ring displacements (µm against
  rings of tens of mm: the neglected terms are ~1e-10 m).
- a defect is a table over ψ (ball-centre angle relative to the defect centre):
  kind 0: drop h(ψ) (elastic force K·max(δ − h, 0)^e); kind 1: G(ψ, δ) with
  force K·G (2-D contact-area tables; G = δ^1.5 on intact surface).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._loopargs import Cage

# ---- parameter vector layout
P_Z, P_RP, P_PD, P_KI, P_KO, P_KEFF, P_CMAX, P_DPEN, P_EXP = 0, 1, 2, 3, 4, 5, 6, 7, 8
P_MI, P_MO, P_MB = 9, 10, 11
P_KSX, P_KSY, P_CSX, P_CSY, P_KMX, P_KMY, P_CMX, P_CMY = 12, 13, 14, 15, 16, 17, 18, 19
P_XIR, P_YIR, P_XOR, P_YOR = 20, 21, 22, 23
P_FIX, P_FIY, P_FOX, P_FOY = 24, 25, 26, 27
P_G, P_FTF, P_PHI0 = 28, 29, 30
P_SENS, P_SW, P_SZ = 31, 32, 33
P_FID = 34
P_TSTEP, P_FIX2, P_FIY2, P_FOX2, P_FOY2 = 35, 36, 37, 38, 39
P_NDEF = 40
P_SPIN = 41
# dynamic cage: flag, traction coefficient, slip speed of full traction, pocket stiffness,
# pocket clearance (arc, each side), pocket damping, cage polar inertia, ball polar inertia,
# ball radius, sensor state offset
P_CAGE, P_MU, P_VREF, P_KPOCK, P_CPOCK, P_DPOCK, P_IC, P_IB, P_RB, P_SENSOFF = 42, 43, 44, 45, 46, 47, 48, 49, 50, 51
P_CDRAG = 52
P_UNB = 53      # shaft unbalance U = m e (kg m): a force U omega^2 turning with the shaft on the inner ring
P_DRATE = 54    # damping rate over a defect: 0 the bodies' approach rate, 1 the rate of the
                # contact law's equivalent penetration (including the rolling term)
# the 3-D bearing (an axial load or preload): flag; index of the axial states (zi, zo, vzi, vzo,
# then for multibody balls each ball's axial position and rate); groove curvature radius minus
# ball radius, inner and outer (m); axial support stiffness and damping, inner and outer; the
# axial springs' rest positions; the constant axial forces on the rings
P_3D, P_ZOFF, P_AGI, P_AGO = 55, 56, 57, 58
P_KZI, P_CZI, P_KZO, P_CZO, P_ZIR, P_ZOR, P_FIZ, P_FOZ = 59, 60, 61, 62, 63, 64, 65, 66
P_ZSET, P_TZSET = 67, 68  # settling only: damping rate (1/s) of the balls' axial motion, until this time
P_SIZE = 69
# after P_SIZE: cos(2 pi j / Z) for j < Z, then sin(2 pi j / Z) (ball offsets around the cage,
# so the right-hand side rotates them with 4 products instead of calling cos/sin per ball)
P_TRIG = P_SIZE

# ---- defect table layout: dint[k] = race, kind, npsi, ndelta, h_off, g_off, ball
#   race 0: outer race, 1: inner race, 2: ball defect meeting the outer race,
#   3: ball defect meeting the inner race (a ball defect has one table per race);
#                            dflt[k] = psi0, psi_first, dpsi, ddelta, zone_lo, zone_hi, scale
#   scale (ball defects): ball radius / track radius, mapping the defect's arc on the ball
#   to the equivalent angle on the race table (to the Hertz paraboloid order the gap
#   depends on the relative curvature only, so a pit on the ball meeting the race at the
#   contact point is the same pit on the race meeting the ball).
D_RACE, D_KIND, D_NPSI, D_NDEL, D_HOFF, D_GOFF, D_BALL = 0, 1, 2, 3, 4, 5, 6
F_PSI0, F_PSIF, F_DPSI, F_DDEL, F_ZLO, F_ZHI, F_SCALE = 0, 1, 2, 3, 4, 5, 6
# the largest approach (m) a force was evaluated at inside the table's psi range, written by
# the time loop: a run that reached above the table's top is extended and re-run, never
# trusted on an extrapolated force
F_REACH = 7
N_DFLT = 8

TWO_PI = 2.0 * math.pi

# The kernels that are not inlined are compiled without numba's reference counting
# (``_nrt=False``): they allocate nothing, and with it the right-hand side took a reference to
# each of its 13 array arguments on entry and dropped it on exit (26 atomic operations, about
# half the cost of an evaluation: 275 -> 135 ns per call for 8 balls, CPU time of 10^6 calls).
# The option is numba's own (a jit flag since its runtime appeared); should a numba version not
# have it, the kernels compile with reference counting: slower, same results.


try:
    from numba.core.cpu import CPUTargetOptions
except ImportError:          # a numba without it: reference counting stays on
    CPUTargetOptions = None


def _no_refcount() -> dict:
    if CPUTargetOptions is None:
        return {}
    return {"_nrt": False} if hasattr(CPUTargetOptions, "_nrt") else {}


NO_REFCOUNT = _no_refcount()


@njit(cache=True, error_model="numpy", inline="always")
def shaft_state(t, sp_t, sp_w, sp_th):
    """Shaft angle (rad) and speed (rad/s) at t for a piecewise-linear speed."""
    n = sp_t.shape[0]
    if n == 1 or t <= sp_t[0]:
        return sp_w[0] * (t - sp_t[0]) + sp_th[0], sp_w[0]
    if t >= sp_t[n - 1]:
        return sp_th[n - 1] + sp_w[n - 1] * (t - sp_t[n - 1]), sp_w[n - 1]
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if sp_t[mid] <= t:
            lo = mid
        else:
            hi = mid
    dt = t - sp_t[lo]
    slope = (sp_w[hi] - sp_w[lo]) / (sp_t[hi] - sp_t[lo])
    return sp_th[lo] + sp_w[lo] * dt + 0.5 * slope * dt * dt, sp_w[lo] + slope * dt


@njit(cache=True, error_model="numpy", inline="always")
def cage_at(t, m):
    """The shaft and a kinematic cage at time t (:class:`Cage`) for :class:`Model` ``m``."""
    p = m.p
    theta_s, omega_s = shaft_state(t, m.sp_t, m.sp_w, m.sp_th)
    phic = p[P_PHI0] + p[P_FTF] * theta_s
    return Cage(int(p[P_Z]), phic, math.cos(phic), math.sin(phic), p[P_FTF] * omega_s, theta_s, omega_s)


@njit(cache=True, error_model="numpy", inline="always")
def wrap(a):
    """Angle wrapped to [-pi, pi) (floor, not fmod: fmod costs tens of ns)."""
    return a - TWO_PI * math.floor((a + math.pi) / TWO_PI)


@njit(cache=True, error_model="numpy", inline="always")
def step_fn(x, x0, h0, x1, h1):
    """Adams STEP: cubic from (x0, h0) to (x1, h1), constant outside."""
    if x <= x0:
        return h0
    if x >= x1:
        return h1
    s = (x - x0) / (x1 - x0)
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)


@njit(cache=True, error_model="numpy", inline="always")
def impact(pen, pen_rate, k, e, cmax, dpen):
    """Adams IMPACT force for penetration ``pen`` >= 0 (clipped at zero: no pull)."""
    if pen <= 0.0:
        return 0.0
    if e == 1.5:
        f = k * pen * math.sqrt(pen)
    else:
        f = k * pen ** e
    if pen >= dpen:
        f += cmax * pen_rate
    else:
        sr = pen / dpen
        f += cmax * sr * sr * (3.0 - 2.0 * sr) * pen_rate
    return f if f > 0.0 else 0.0


@njit(cache=True, error_model="numpy", inline="always")
def _interp_h(k, psi, dint, dflt, hbuf):
    """Drop h (m) and dh/dpsi at relative angle psi for defect k (linear)."""
    n = dint[k, D_NPSI]
    off = dint[k, D_HOFF]
    x = (psi - dflt[k, F_PSIF]) / dflt[k, F_DPSI]
    if x <= 0.0 or x >= n - 1:
        return 0.0, 0.0
    i = int(x)
    fr = x - i
    h0 = hbuf[off + i]
    h1 = hbuf[off + i + 1]
    return h0 + fr * (h1 - h0), (h1 - h0) / dflt[k, F_DPSI]


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def _interp_g23(k, psi, delta, dint, dflt, gbuf):
    """Equivalent penetration g = G^(2/3) (m) of defect k at (psi, delta), and its partial
    derivatives dg/ddelta and dg/dpsi.

    The table holds G^(2/3) (an approach-like quantity, m), interpolated bilinearly: exact
    on intact surface (g = delta) and for a rigid drop (max(delta - h, 0)), where
    interpolating G itself would overstate the convex delta^1.5 between grid nodes.
    Linear extrapolation above the grid's delta range, for trial evaluations only: a force
    the run keeps is noted by :func:`_note_reach`, and a run that reached above the table is
    extended and repeated (see ``integrate.simulate``).
    """
    npsi = dint[k, D_NPSI]
    nd = dint[k, D_NDEL]
    off = dint[k, D_GOFF]
    dd = dflt[k, F_DDEL]
    x = (psi - dflt[k, F_PSIF]) / dflt[k, F_DPSI]
    if delta <= 0.0:
        return 0.0, 0.0, 0.0
    if x <= 0.0 or x >= npsi - 1:
        return delta, 1.0, 0.0
    i = int(x)
    fx = x - i
    yv = delta / dd
    if yv >= nd - 1:
        j = nd - 2
    else:
        j = int(yv)
    fy = yv - j
    a00 = gbuf[off + i * nd + j]
    a01 = gbuf[off + i * nd + j + 1]
    a10 = gbuf[off + (i + 1) * nd + j]
    a11 = gbuf[off + (i + 1) * nd + j + 1]
    g0 = a00 + fy * (a01 - a00)
    g1 = a10 + fy * (a11 - a10)
    g = g0 + fx * (g1 - g0)
    dg_dd = ((1.0 - fx) * (a01 - a00) + fx * (a11 - a10)) / dd
    dg_dpsi = (g1 - g0) / dflt[k, F_DPSI]
    return g, dg_dd, dg_dpsi


@njit(cache=True, error_model="numpy", inline="always")
def _note_reach(k, psi, delta, dflt):
    """Remember the largest approach a defect force was taken at inside the table's psi range."""
    if dflt[k, F_ZLO] < psi < dflt[k, F_ZHI] and delta > dflt[k, F_REACH]:
        dflt[k, F_REACH] = delta


@njit(cache=True, error_model="numpy", inline="always")
def _interp_g(k, psi, delta, dint, dflt, gbuf):
    """G(psi, delta) (m^1.5) of defect k: the equivalent penetration raised to 1.5."""
    g, _, _ = _interp_g23(k, psi, delta, dint, dflt, gbuf)
    return g * math.sqrt(g) if g > 0.0 else 0.0


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def defect_force(kk, rel, reld, delta, delta_rate, k, p, dint, dflt, hbuf, gbuf):
    """Normal force of a ball at relative angle ``rel`` inside the zone of defect kk (the
    contact's own damping coefficient); see :func:`contact_force`."""
    return contact_force(kk, rel, reld, delta, delta_rate, k, p[P_CMAX], p, dint, dflt, hbuf, gbuf)


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def contact_force(kk, rel, reld, delta, delta_rate, k, cmax, p, dint, dflt, hbuf, gbuf):
    """Normal force of a contact at relative angle ``rel`` inside the zone of defect kk, with
    stiffness ``k`` and damping coefficient ``cmax`` (one ball-race contact, or for a drop
    profile the quasi-static ball's two contacts in series).

    Elastic part from the defect's law at the approach ``delta``; IMPACT damping
    ``STEP(pen, 0, 0, d, c_max) * rate`` with ``pen`` the law's own penetration (``delta
    - h`` for a drop profile, ``G^(2/3)`` for a 2-D table) and ``rate`` the bodies'
    approach rate ``delta_rate`` (``p[P_DRATE] == 0``, the default) or the rate of
    ``pen`` itself, which adds the change of the contact as the ball rolls over the
    outline (``p[P_DRATE] == 1``).  See docs/contact-model.md for the choice.
    """
    rolling = p[P_DRATE] > 0.5
    if dint[kk, D_KIND] == 0:
        h, dh = _interp_h(kk, rel, dint, dflt, hbuf)
        pen = delta - h
        if pen <= 0.0:
            return 0.0
        rate = delta_rate - dh * reld if rolling else delta_rate
        return impact(pen, rate, k, p[P_EXP], cmax, p[P_DPEN])
    g, dg_dd, dg_dpsi = _interp_g23(kk, rel, delta, dint, dflt, gbuf)
    _note_reach(kk, rel, delta, dflt)
    if g <= 0.0:
        return 0.0
    rate = dg_dd * delta_rate + dg_dpsi * reld if rolling else delta_rate
    f = k * g * math.sqrt(g) + step_fn(g, 0.0, 0.0, p[P_DPEN], cmax) * rate
    return f if f > 0.0 else 0.0


@njit(cache=True, error_model="numpy", inline="always")
def rel_angle(kk, j, phi, phidot, theta_s, omega_s, spin, dint, dflt):
    """Relative angle (on the defect's table) and its rate for ball j and defect kk."""
    race = dint[kk, D_RACE]
    if race == 0:
        return wrap(phi - dflt[kk, F_PSI0]), phidot
    if race == 1:
        return wrap(phi - dflt[kk, F_PSI0] - theta_s), phidot - omega_s
    # ball defect: spin angle of the defect on ball D_BALL, 0 facing the outer race
    if j != dint[kk, D_BALL]:
        return 10.0, 0.0
    theta_b = dflt[kk, F_PSI0] + spin * theta_s
    if race == 3:
        theta_b -= math.pi
    sc = dflt[kk, F_SCALE]
    return wrap(theta_b) * sc, spin * omega_s * sc


@njit(cache=True, error_model="numpy", inline="always")
def find_zone(contact, j, phi, phidot, theta_s, omega_s, spin, ndef, dint, dflt):
    """(defect index or -1, relative angle, rate) for ball j's ``contact`` (0 outer, 1 inner)."""
    for kk in range(ndef):
        if dint[kk, D_RACE] % 2 != contact:
            continue
        rel, reld = rel_angle(kk, j, phi, phidot, theta_s, omega_s, spin, dint, dflt)
        if dflt[kk, F_ZLO] <= rel <= dflt[kk, F_ZHI]:
            return kk, rel, reld
    return -1, 0.0, 0.0


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def _qs_ball(kk, rel, reld, dtot, dtot_rate, p, dint, dflt, hbuf, gbuf):
    """Quasi-static (massless) ball whose contact kk has a defect: load through the two
    contacts in series."""
    e = p[P_EXP]
    cser = 0.5 * p[P_CMAX]  # two equal dampers in series
    dpen = p[P_DPEN]
    rolling = p[P_DRATE] > 0.5
    h, dh = _interp_h(kk, rel, dint, dflt, hbuf)
    pen = dtot - h
    if pen <= 0.0:
        return 0.0
    if dint[kk, D_KIND] == 0:  # a drop: the two contacts in series as one law
        return contact_force(kk, rel, reld, dtot, dtot_rate, p[P_KEFF], cser, p, dint, dflt, hbuf, gbuf)
    # 2-D table on one contact, Hertz on the other: split the approach by bisection
    outer = dint[kk, D_RACE] % 2 == 0
    k_def = p[P_KO] if outer else p[P_KI]
    k_oth = p[P_KI] if outer else p[P_KO]
    # split the approach: f(x) = K_def G(x) - K_oth (dtot - x)^1.5 rises from f(0) <= 0 to
    # f(dtot) >= 0; Illinois (regula falsi with halving) converges in a few iterations
    lo = 0.0
    hi = dtot
    f_lo = -k_oth * dtot * math.sqrt(dtot)
    f_hi = k_def * _interp_g(kk, rel, dtot, dint, dflt, gbuf)
    x = 0.5 * dtot
    side = 0
    for _ in range(60):
        if f_hi - f_lo == 0.0:
            break
        x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        rem = dtot - x
        fx = k_def * _interp_g(kk, rel, x, dint, dflt, gbuf) - k_oth * rem * math.sqrt(rem)
        if fx > 0.0:
            hi = x
            f_hi = fx
            if side == 1:
                f_lo *= 0.5
            side = 1
        else:
            lo = x
            f_lo = fx
            if side == -1:
                f_hi *= 0.5
            side = -1
        if hi - lo < 1e-7 * dtot or abs(fx) < 1e-9 * k_oth * dtot * math.sqrt(dtot):
            break
    rem = dtot - x
    q = k_oth * rem * math.sqrt(rem)
    # damping on the pair's equivalent penetration: the table's G^(2/3) at the split plus
    # the other contact's penetration (dtot on intact surface, as for a healthy ball)
    g, dg_dd, dg_dpsi = _interp_g23(kk, rel, x, dint, dflt, gbuf)
    _note_reach(kk, rel, x, dflt)
    rate = dtot_rate
    if rolling:
        # d/dt (g + dtot - x), the split x following the series balance
        # K_def g^1.5 = K_oth (dtot - x)^1.5 (implicit differentiation)
        c_def = 1.5 * k_def * math.sqrt(max(g, 0.0))
        w_oth = 1.5 * k_oth * math.sqrt(rem)
        den = c_def * dg_dd + w_oth
        x_rate = (w_oth * dtot_rate - c_def * dg_dpsi * reld) / den if den > 0.0 else 0.0
        rate = dtot_rate + (dg_dd - 1.0) * x_rate + dg_dpsi * reld
    f = q + step_fn(g + rem, 0.0, 0.0, dpen, cser) * rate
    return f if f > 0.0 else 0.0


@njit(cache=True, error_model="numpy", inline="always")
def _ball_dir(p, z, j, c0, s0):
    """cos, sin of ball j's angle for a kinematic cage: the cage angle rotated by the ball's
    tabulated offset 2 pi j / Z."""
    cj = p[P_TRIG + j]
    sj = p[P_TRIG + z + j]
    return c0 * cj - s0 * sj, s0 * cj + c0 * sj


@njit(cache=True, error_model="numpy", inline="always")
def _zone_candidates(kk, z, phic, theta_s, dint, dflt):
    """Balls that may sit in defect kk's zone (kinematic cage), found in O(1): (first, second,
    count); count == z means every ball must be checked (a zone wider than the ball spacing)."""
    race = dint[kk, D_RACE]
    if race >= 2:  # a ball defect: its own ball
        return dint[kk, D_BALL], -1, 1
    sp = TWO_PI / z
    zlo = dflt[kk, F_ZLO]
    if dflt[kk, F_ZHI] - zlo >= sp:
        return 0, 0, z
    u = phic - dflt[kk, F_PSI0] - (theta_s if race == 1 else 0.0) - zlo
    # ball j sits u + j sp past the zone's start: j = -floor(u / sp) is the one within a ball
    # spacing past it; its predecessor, in case rounding put the boundary on the other side
    ja = (-int(math.floor(u / sp))) % z
    return ja, (ja - 1) % z, 2


@njit(cache=True, error_model="numpy", inline="always")
def _approaches(y, z, j, c, s, phidot, pd4):
    """Ball j's outer and inner contact approaches (m) and their rates (multibody)."""
    qj = y[8 + j]
    qd = y[8 + z + j]
    d_o = qj - (y[4] * c + y[5] * s) - pd4
    d_or = qd - (y[6] * c + y[7] * s) - (y[4] * (-s) + y[5] * c) * phidot
    d_i = -qj + (y[0] * c + y[1] * s) - pd4
    d_ir = -qd + (y[2] * c + y[3] * s) + (y[0] * (-s) + y[1] * c) * phidot
    return d_o, d_or, d_i, d_ir


@njit(cache=True, error_model="numpy", inline="always")
def _balls_kinematic(y, m, cg, dy, fi_out, fo_out):
    """Ball loads and ball equations for multibody balls in a kinematic cage.

    Every contact as intact first (one loop without branches on defects), then for each defect
    the O(1) candidate balls in its zone get the defect's law, with the ball's equation and the
    ring sums corrected (the lowest-numbered defect wins where zones overlap).  Returns the
    ball forces on the inner and outer ring (x, y)."""
    p, dint, dflt = m.p, m.dint, m.dflt
    z, phic, c0, s0, phidot, theta_s, omega_s = cg
    xi, yi, vxi, vyi = y[0], y[1], y[2], y[3]
    xo, yo, vxo, vyo = y[4], y[5], y[6], y[7]
    pd4 = 0.25 * p[P_PD]
    ko = p[P_KO]
    ki = p[P_KI]
    e = p[P_EXP]
    cmax = p[P_CMAX]
    dpen = p[P_DPEN]
    inv_mb = 1.0 / p[P_MB]
    rp = p[P_RP]
    g = p[P_G]
    w2 = phidot * phidot
    fix = fiy = fox = foy = 0.0
    for j in range(z):
        c, s = _ball_dir(p, z, j, c0, s0)
        qj = y[8 + j]
        qd = y[8 + z + j]
        d_o = qj - (xo * c + yo * s) - pd4
        d_or = qd - (vxo * c + vyo * s) - (xo * (-s) + yo * c) * phidot
        d_i = -qj + (xi * c + yi * s) - pd4
        d_ir = -qd + (vxi * c + vyi * s) + (xi * (-s) + yi * c) * phidot
        fo = impact(d_o, d_or, ko, e, cmax, dpen)
        fi = impact(d_i, d_ir, ki, e, cmax, dpen)
        fo_out[j] = fo
        fi_out[j] = fi
        dy[8 + j] = qd
        dy[8 + z + j] = (fi - fo) * inv_mb + (rp + qj) * w2 - g * s
        fix -= fi * c
        fiy -= fi * s
        fox += fo * c
        foy += fo * s
    ndef = int(p[P_NDEF])
    if ndef == 0:
        return fix, fiy, fox, foy
    sp = TWO_PI / z
    spin = p[P_SPIN]
    for im in range(ndef):
        kk = ndef - 1 - im
        ja, jb, cnt = _zone_candidates(kk, z, phic, theta_s, dint, dflt)
        outer = dint[kk, D_RACE] % 2 == 0
        for q in range(cnt):
            j = q if cnt == z else (ja if q == 0 else jb)
            rel, reld = rel_angle(kk, j, phic + sp * j, phidot, theta_s, omega_s, spin, dint, dflt)
            if not (dflt[kk, F_ZLO] <= rel <= dflt[kk, F_ZHI]):
                continue
            c, s = _ball_dir(p, z, j, c0, s0)
            d_o, d_or, d_i, d_ir = _approaches(y, z, j, c, s, phidot, pd4)
            if outer:
                f = contact_force(kk, rel, reld, d_o, d_or, ko, cmax, p, dint, dflt, m.hbuf, m.gbuf)
                df = f - fo_out[j]
                fo_out[j] = f
                fox += df * c
                foy += df * s
            else:
                f = contact_force(kk, rel, reld, d_i, d_ir, ki, cmax, p, dint, dflt, m.hbuf, m.gbuf)
                df = f - fi_out[j]
                fi_out[j] = f
                fix -= df * c
                fiy -= df * s
            dy[8 + z + j] = (fi_out[j] - fo_out[j]) * inv_mb + (rp + y[8 + j]) * w2 - g * s
    return fix, fiy, fox, foy


@njit(cache=True, error_model="numpy", inline="always")
def _balls_quasi_static(y, m, cg, fi_out, fo_out):
    """Ball loads of massless (quasi-static) balls: the two contacts of a ball in series, the
    same load on both.  Intact first, then the O(1) candidate balls of each defect zone (an
    outer-race defect wins over an inner-race one, the lowest-numbered over the others).
    Returns the ball forces on the inner and outer ring (x, y)."""
    p, dint, dflt = m.p, m.dint, m.dflt
    z, phic, c0, s0, phidot, theta_s, omega_s = cg
    pd4 = 0.25 * p[P_PD]
    keff = p[P_KEFF]
    e = p[P_EXP]
    cser = 0.5 * p[P_CMAX]  # two equal dampers in series
    dpen = p[P_DPEN]
    dx = y[0] - y[4]
    dyy = y[1] - y[5]
    dvx = y[2] - y[6]
    dvy = y[3] - y[7]
    for j in range(z):
        c, s = _ball_dir(p, z, j, c0, s0)
        dtot = dx * c + dyy * s - 2.0 * pd4
        drate = dvx * c + dvy * s + (dx * (-s) + dyy * c) * phidot
        q = impact(dtot, drate, keff, e, cser, dpen)
        fi_out[j] = q
        fo_out[j] = q
    ndef = int(p[P_NDEF])
    sp = TWO_PI / z
    spin = p[P_SPIN]
    for im in range(2 * ndef):
        # inner-race defects first, then outer-race ones, each from the last to the first
        kk = ndef - 1 - (im % ndef)
        if dint[kk, D_RACE] % 2 != (1 if im < ndef else 0):
            continue
        ja, jb, cnt = _zone_candidates(kk, z, phic, theta_s, dint, dflt)
        for q in range(cnt):
            j = q if cnt == z else (ja if q == 0 else jb)
            rel, reld = rel_angle(kk, j, phic + sp * j, phidot, theta_s, omega_s, spin, dint, dflt)
            if not (dflt[kk, F_ZLO] <= rel <= dflt[kk, F_ZHI]):
                continue
            c, s = _ball_dir(p, z, j, c0, s0)
            dtot = dx * c + dyy * s - 2.0 * pd4
            drate = dvx * c + dvy * s + (dx * (-s) + dyy * c) * phidot
            qd = _qs_ball(kk, rel, reld, dtot, drate, p, dint, dflt, m.hbuf, m.gbuf)
            fi_out[j] = qd
            fo_out[j] = qd
    fix = fiy = fox = foy = 0.0
    for j in range(z):
        c, s = _ball_dir(p, z, j, c0, s0)
        fix -= fi_out[j] * c
        fiy -= fi_out[j] * s
        fox += fo_out[j] * c
        foy += fo_out[j] * s
    return fix, fiy, fox, foy


@njit(cache=True, error_model="numpy", inline="always")
def _balls_dynamic(y, m, cg, dy, fi_out, fo_out):
    """Multibody balls in a dynamic cage: each ball's orbital angle, speed and spin are states;
    traction at both contacts (regularised Coulomb), cage pockets.  Returns the ball forces on
    the inner and outer ring (x, y) and the pockets' torque on the cage."""
    p, dint, dflt = m.p, m.dint, m.dflt
    z, _, _, _, _, theta_s, omega_s = cg
    xi, yi, vxi, vyi = y[0], y[1], y[2], y[3]
    xo, yo, vxo, vyo = y[4], y[5], y[6], y[7]
    pd4 = 0.25 * p[P_PD]
    mb = p[P_MB]
    ndef = int(p[P_NDEF])
    spin = p[P_SPIN]
    base = 8
    fix = fiy = fox = foy = 0.0
    pocket_torque = 0.0
    for j in range(z):
        phi = y[base + 2 * z + j]
        phidot = y[base + 3 * z + j]
        c = math.cos(phi)
        s = math.sin(phi)
        qj = y[base + j]
        qd = y[base + z + j]
        d_o, d_or, d_i, d_ir = _approaches(y, z, j, c, s, phidot, pd4)
        ko = -1
        ki = -1
        if ndef > 0:
            ko, relo, reldo = find_zone(0, j, phi, phidot, theta_s, omega_s, spin, ndef, dint, dflt)
            ki, reli, reldi = find_zone(1, j, phi, phidot, theta_s, omega_s, spin, ndef, dint, dflt)
        if ko >= 0:
            fo = defect_force(ko, relo, reldo, d_o, d_or, p[P_KO], p, dint, dflt, m.hbuf, m.gbuf)
        else:
            fo = impact(d_o, d_or, p[P_KO], p[P_EXP], p[P_CMAX], p[P_DPEN])
        if ki >= 0:
            fi = defect_force(ki, reli, reldi, d_i, d_ir, p[P_KI], p, dint, dflt, m.hbuf, m.gbuf)
        else:
            fi = impact(d_i, d_ir, p[P_KI], p[P_EXP], p[P_CMAX], p[P_DPEN])
        dy[base + j] = qd
        dy[base + z + j] = (fi - fo) / mb + (p[P_RP] + qj) * phidot * phidot - p[P_G] * s
        r = p[P_RP] + qj
        om_b = y[base + 4 * z + j]
        rb = p[P_RB]
        vt_o = r * phidot - (vxo * (-s) + vyo * c)
        vt_i = r * phidot - (vxi * (-s) + vyi * c)
        slip_o = vt_o + rb * om_b
        slip_i = vt_i - rb * om_b - omega_s * (p[P_RP] - rb)
        ft_o = -p[P_MU] * fo * math.tanh(slip_o / p[P_VREF])
        ft_i = -p[P_MU] * fi * math.tanh(slip_i / p[P_VREF])
        gap = r * wrap(phi - y[base + 5 * z] - TWO_PI * j / z)
        gap_rate = r * (phidot - y[base + 5 * z + 1])
        fp = 0.0
        cp = p[P_CPOCK]
        if gap > cp:
            fp = -(p[P_KPOCK] * (gap - cp) + p[P_DPOCK] * gap_rate)
            if fp > 0.0:
                fp = 0.0
        elif gap < -cp:
            fp = -(p[P_KPOCK] * (gap + cp) + p[P_DPOCK] * gap_rate)
            if fp < 0.0:
                fp = 0.0
        pocket_torque -= fp * r
        dy[base + 2 * z + j] = phidot
        dy[base + 3 * z + j] = (ft_o + ft_i + fp - mb * p[P_G] * c - 2.0 * mb * qd * phidot) / (mb * r)
        dy[base + 4 * z + j] = rb * (ft_o - ft_i) / p[P_IB]
        # reactions of the traction on the rings (tangential direction -s, c)
        fix += -ft_i * (-s)
        fiy += -ft_i * c
        fox += -ft_o * (-s)
        foy += -ft_o * c
        fix -= fi * c
        fiy -= fi * s
        fox += fo * c
        foy += fo * s
        fi_out[j] = fi
        fo_out[j] = fo
    return fix, fiy, fox, foy, pocket_torque


@njit(cache=True, error_model="numpy", inline="always")
def _geom_outer(y, zb, j, z, c, s, phidot, pd4, ago):
    """Ball j's outer contact in 3-D: the vector from the outer groove's curvature centre to the
    ball centre (radial, axial), its length, and their rates (multibody balls)."""
    ro = y[8 + j] - (y[4] * c + y[5] * s) - pd4 + ago
    ro_r = y[8 + z + j] - (y[6] * c + y[7] * s) - (y[4] * (-s) + y[5] * c) * phidot
    wb = zb + 4
    zo = y[wb + j] - y[zb + 1]
    zo_r = y[wb + z + j] - y[zb + 3]
    return ro, zo, math.sqrt(ro * ro + zo * zo), ro_r, zo_r


@njit(cache=True, error_model="numpy", inline="always")
def _geom_inner(y, zb, j, z, c, s, phidot, pd4, agi):
    """Ball j's inner contact in 3-D: the vector from the ball centre to the inner groove's
    curvature centre (radial, axial), its length, and their rates (multibody balls)."""
    ri = (y[0] * c + y[1] * s) - y[8 + j] - pd4 + agi
    ri_r = (y[2] * c + y[3] * s) + (y[0] * (-s) + y[1] * c) * phidot - y[8 + z + j]
    wb = zb + 4
    zi = y[zb] - y[wb + j]
    zi_r = y[zb + 2] - y[wb + z + j]
    return ri, zi, math.sqrt(ri * ri + zi * zi), ri_r, zi_r


@njit(cache=True, error_model="numpy", inline="always")
def _balls_kinematic_3d(y, m, cg, dy, fi_out, fo_out):
    """Multibody balls in a kinematic cage, in 3-D: each ball has a radial and an axial position;
    each contact acts along the line through the ball centre and its groove's curvature centre
    (the contact angle), its approach measured along it.  Returns the ball forces on the inner
    and outer ring (x, y, z)."""
    p, dint, dflt = m.p, m.dint, m.dflt
    z, phic, c0, s0, phidot, theta_s, omega_s = cg
    pd4 = 0.25 * p[P_PD]
    ko = p[P_KO]
    ki = p[P_KI]
    e = p[P_EXP]
    cmax = p[P_CMAX]
    dpen = p[P_DPEN]
    inv_mb = 1.0 / p[P_MB]
    rp = p[P_RP]
    g = p[P_G]
    agi = p[P_AGI]
    ago = p[P_AGO]
    zb = int(p[P_ZOFF])
    wb = zb + 4
    w2 = phidot * phidot
    fix = fiy = fiz = fox = foy = foz = 0.0
    for j in range(z):
        c, s = _ball_dir(p, z, j, c0, s0)
        ro, zo, lo, ro_r, zo_r = _geom_outer(y, zb, j, z, c, s, phidot, pd4, ago)
        ri, zi, li, ri_r, zi_r = _geom_inner(y, zb, j, z, c, s, phidot, pd4, agi)
        ilo = 1.0 / lo
        ili = 1.0 / li
        fo = impact(lo - ago, (ro * ro_r + zo * zo_r) * ilo, ko, e, cmax, dpen)
        fi = impact(li - agi, (ri * ri_r + zi * zi_r) * ili, ki, e, cmax, dpen)
        fo_out[j] = fo
        fi_out[j] = fi
        # force components: on the outer ring (+) and on the ball (-) from the outer contact,
        # on the ball (+) and on the inner ring (-) from the inner contact
        for_ = fo * ro * ilo
        foz_ = fo * zo * ilo
        fir_ = fi * ri * ili
        fiz_ = fi * zi * ili
        dy[8 + j] = y[8 + z + j]
        dy[8 + z + j] = (fir_ - for_) * inv_mb + (rp + y[8 + j]) * w2 - g * s
        dy[wb + j] = y[wb + z + j]
        dy[wb + z + j] = (fiz_ - foz_) * inv_mb
        fix -= fir_ * c
        fiy -= fir_ * s
        fiz -= fiz_
        fox += for_ * c
        foy += for_ * s
        foz += foz_
    ndef = int(p[P_NDEF])
    if ndef == 0:
        return fix, fiy, fiz, fox, foy, foz
    sp = TWO_PI / z
    spin = p[P_SPIN]
    for im in range(ndef):
        kk = ndef - 1 - im
        ja, jb, cnt = _zone_candidates(kk, z, phic, theta_s, dint, dflt)
        outer = dint[kk, D_RACE] % 2 == 0
        for q in range(cnt):
            j = q if cnt == z else (ja if q == 0 else jb)
            rel, reld = rel_angle(kk, j, phic + sp * j, phidot, theta_s, omega_s, spin, dint, dflt)
            if not (dflt[kk, F_ZLO] <= rel <= dflt[kk, F_ZHI]):
                continue
            c, s = _ball_dir(p, z, j, c0, s0)
            if outer:
                ro, zo, lo, ro_r, zo_r = _geom_outer(y, zb, j, z, c, s, phidot, pd4, ago)
                f = contact_force(kk, rel, reld, lo - ago, (ro * ro_r + zo * zo_r) / lo, ko, cmax, p, dint, dflt,
                                  m.hbuf, m.gbuf)
                df = f - fo_out[j]
                fo_out[j] = f
                fox += df * ro / lo * c
                foy += df * ro / lo * s
                foz += df * zo / lo
                dy[8 + z + j] -= df * ro / lo * inv_mb
                dy[wb + z + j] -= df * zo / lo * inv_mb
            else:
                ri, zi, li, ri_r, zi_r = _geom_inner(y, zb, j, z, c, s, phidot, pd4, agi)
                f = contact_force(kk, rel, reld, li - agi, (ri * ri_r + zi * zi_r) / li, ki, cmax, p, dint, dflt,
                                  m.hbuf, m.gbuf)
                df = f - fi_out[j]
                fi_out[j] = f
                fix -= df * ri / li * c
                fiy -= df * ri / li * s
                fiz -= df * zi / li
                dy[8 + z + j] += df * ri / li * inv_mb
                dy[wb + z + j] += df * zi / li * inv_mb
    return fix, fiy, fiz, fox, foy, foz


@njit(cache=True, error_model="numpy", inline="always")
def _qs_geom(y, zb, c, s, phidot, pd4, a0):
    """Massless ball in 3-D: the vector between the two grooves' curvature centres (radial,
    axial), its length and their rates."""
    rho = a0 - 2.0 * pd4 + (y[0] - y[4]) * c + (y[1] - y[5]) * s
    rho_r = (y[2] - y[6]) * c + (y[3] - y[7]) * s + ((y[0] - y[4]) * (-s) + (y[1] - y[5]) * c) * phidot
    zeta = y[zb] - y[zb + 1]
    zeta_r = y[zb + 2] - y[zb + 3]
    return rho, zeta, math.sqrt(rho * rho + zeta * zeta), rho_r, zeta_r


@njit(cache=True, error_model="numpy", inline="always")
def _balls_quasi_static_3d(y, m, cg, fi_out, fo_out):
    """Massless balls in 3-D: the two contacts in series along the line through both grooves'
    curvature centres (one contact angle per ball).  Returns the forces on the rings (x, y, z)."""
    p, dint, dflt = m.p, m.dint, m.dflt
    z, phic, c0, s0, phidot, theta_s, omega_s = cg
    pd4 = 0.25 * p[P_PD]
    keff = p[P_KEFF]
    e = p[P_EXP]
    cser = 0.5 * p[P_CMAX]
    dpen = p[P_DPEN]
    a0 = p[P_AGI] + p[P_AGO]
    zb = int(p[P_ZOFF])
    for j in range(z):
        c, s = _ball_dir(p, z, j, c0, s0)
        rho, zeta, ln, rho_r, zeta_r = _qs_geom(y, zb, c, s, phidot, pd4, a0)
        q = impact(ln - a0, (rho * rho_r + zeta * zeta_r) / ln, keff, e, cser, dpen)
        fi_out[j] = q
        fo_out[j] = q
    ndef = int(p[P_NDEF])
    sp = TWO_PI / z
    spin = p[P_SPIN]
    for im in range(2 * ndef):
        kk = ndef - 1 - (im % ndef)
        if dint[kk, D_RACE] % 2 != (1 if im < ndef else 0):
            continue
        ja, jb, cnt = _zone_candidates(kk, z, phic, theta_s, dint, dflt)
        for q in range(cnt):
            j = q if cnt == z else (ja if q == 0 else jb)
            rel, reld = rel_angle(kk, j, phic + sp * j, phidot, theta_s, omega_s, spin, dint, dflt)
            if not (dflt[kk, F_ZLO] <= rel <= dflt[kk, F_ZHI]):
                continue
            c, s = _ball_dir(p, z, j, c0, s0)
            rho, zeta, ln, rho_r, zeta_r = _qs_geom(y, zb, c, s, phidot, pd4, a0)
            qd = _qs_ball(kk, rel, reld, ln - a0, (rho * rho_r + zeta * zeta_r) / ln, p, dint, dflt, m.hbuf,
                          m.gbuf)
            fi_out[j] = qd
            fo_out[j] = qd
    fix = fiy = fiz = fox = foy = foz = 0.0
    for j in range(z):
        c, s = _ball_dir(p, z, j, c0, s0)
        rho, zeta, ln, _, _ = _qs_geom(y, zb, c, s, phidot, pd4, a0)
        fr = rho / ln
        fz = zeta / ln
        fix -= fi_out[j] * fr * c
        fiy -= fi_out[j] * fr * s
        fiz -= fi_out[j] * fz
        fox += fo_out[j] * fr * c
        foy += fo_out[j] * fr * s
        foz += fo_out[j] * fz
    return fix, fiy, fiz, fox, foy, foz


@njit(cache=True, error_model="numpy", inline="always")
def _rhs_3d(t, y, m, dy, fi_out, fo_out):
    """dy/dt of the 3-D bearing (rings with an axial translation, contact angles)."""
    p = m.p
    xi, yi, vxi, vyi = y[0], y[1], y[2], y[3]
    xo, yo, vxo, vyo = y[4], y[5], y[6], y[7]
    zb = int(p[P_ZOFF])
    cg = cage_at(t, m)
    z, theta_s, omega_s = cg.z, cg.theta_s, cg.omega_s
    if p[P_FID] > 0.5:
        fix, fiy, fiz, fox, foy, foz = _balls_quasi_static_3d(y, m, cg, fi_out, fo_out)
    else:
        fix, fiy, fiz, fox, foy, foz = _balls_kinematic_3d(y, m, cg, dy, fi_out, fo_out)
        if t < p[P_TZSET]:  # start transient of the nearly undamped axial ball modes (scene.settle)
            for j in range(zb + 4 + z, zb + 4 + 2 * z):
                dy[j] -= p[P_ZSET] * (y[j] - 0.5 * (y[zb + 2] + y[zb + 3]))
    if t >= p[P_TSTEP]:
        lix, liy, lox, loy = p[P_FIX2], p[P_FIY2], p[P_FOX2], p[P_FOY2]
    else:
        lix, liy, lox, loy = p[P_FIX], p[P_FIY], p[P_FOX], p[P_FOY]
    if p[P_UNB] > 0.0:
        fu = p[P_UNB] * omega_s * omega_s
        lix += fu * math.cos(theta_s)
        liy += fu * math.sin(theta_s)
    axo = (fox - p[P_KMX] * (xo - p[P_XOR]) - p[P_CMX] * vxo + lox) / p[P_MO]
    ayo = (foy - p[P_KMY] * (yo - p[P_YOR]) - p[P_CMY] * vyo + loy) / p[P_MO]
    dy[0] = vxi
    dy[1] = vyi
    dy[2] = (fix - p[P_KSX] * (xi - p[P_XIR]) - p[P_CSX] * vxi + lix) / p[P_MI]
    dy[3] = (fiy - p[P_KSY] * (yi - p[P_YIR]) - p[P_CSY] * vyi + liy) / p[P_MI]
    dy[4] = vxo
    dy[5] = vyo
    dy[6] = axo
    dy[7] = ayo
    dy[zb] = y[zb + 2]
    dy[zb + 1] = y[zb + 3]
    dy[zb + 2] = (fiz - p[P_KZI] * (y[zb] - p[P_ZIR]) - p[P_CZI] * y[zb + 2] + p[P_FIZ]) / p[P_MI]
    dy[zb + 3] = (foz - p[P_KZO] * (y[zb + 1] - p[P_ZOR]) - p[P_CZO] * y[zb + 3] + p[P_FOZ]) / p[P_MO]
    if p[P_SENS] > 0.5:
        sb = int(p[P_SENSOFF])
        w = p[P_SW]
        zt = p[P_SZ]
        dy[sb] = y[sb + 2]
        dy[sb + 1] = y[sb + 3]
        dy[sb + 2] = -2.0 * zt * w * y[sb + 2] - w * w * y[sb] - axo
        dy[sb + 3] = -2.0 * zt * w * y[sb + 3] - w * w * y[sb + 1] - ayo


@njit(cache=True, error_model="numpy", **NO_REFCOUNT)
def rhs(t, y, m, dy, fi_out, fo_out):
    """dy/dt of the bearing model :class:`Model` ``m`` at time t, state y (into dy); also writes
    the ball loads (N) into fi_out/fo_out."""
    p = m.p
    if p[P_3D] > 0.5:
        _rhs_3d(t, y, m, dy, fi_out, fo_out)
        return
    xi, yi, vxi, vyi = y[0], y[1], y[2], y[3]
    xo, yo, vxo, vyo = y[4], y[5], y[6], y[7]
    cg = cage_at(t, m)
    z, theta_s, omega_s = cg.z, cg.theta_s, cg.omega_s
    qs = p[P_FID] > 0.5
    dyn = p[P_CAGE] > 0.5
    pocket_torque = 0.0
    if dyn and not qs:
        fix, fiy, fox, foy, pocket_torque = _balls_dynamic(y, m, cg, dy, fi_out, fo_out)
    elif qs:
        fix, fiy, fox, foy = _balls_quasi_static(y, m, cg, fi_out, fo_out)
    else:
        fix, fiy, fox, foy = _balls_kinematic(y, m, cg, dy, fi_out, fo_out)
    if t >= p[P_TSTEP]:
        lix, liy, lox, loy = p[P_FIX2], p[P_FIY2], p[P_FOX2], p[P_FOY2]
    else:
        lix, liy, lox, loy = p[P_FIX], p[P_FIY], p[P_FOX], p[P_FOY]
    if p[P_UNB] > 0.0:
        fu = p[P_UNB] * omega_s * omega_s
        lix += fu * math.cos(theta_s)
        liy += fu * math.sin(theta_s)
    axi = (fix - p[P_KSX] * (xi - p[P_XIR]) - p[P_CSX] * vxi + lix) / p[P_MI]
    ayi = (fiy - p[P_KSY] * (yi - p[P_YIR]) - p[P_CSY] * vyi + liy) / p[P_MI]
    axo = (fox - p[P_KMX] * (xo - p[P_XOR]) - p[P_CMX] * vxo + lox) / p[P_MO]
    ayo = (foy - p[P_KMY] * (yo - p[P_YOR]) - p[P_CMY] * vyo + loy) / p[P_MO]
    dy[0] = vxi
    dy[1] = vyi
    dy[2] = axi
    dy[3] = ayi
    dy[4] = vxo
    dy[5] = vyo
    dy[6] = axo
    dy[7] = ayo
    if dyn and not qs:
        dy[8 + 5 * z] = y[8 + 5 * z + 1]
        dy[8 + 5 * z + 1] = (pocket_torque - p[P_CDRAG] * y[8 + 5 * z + 1]) / p[P_IC]
    if p[P_SENS] > 0.5:
        sb = int(p[P_SENSOFF])
        w = p[P_SW]
        zt = p[P_SZ]
        dy[sb] = y[sb + 2]
        dy[sb + 1] = y[sb + 3]
        dy[sb + 2] = -2.0 * zt * w * y[sb + 2] - w * w * y[sb] - axo
        dy[sb + 3] = -2.0 * zt * w * y[sb + 3] - w * w * y[sb + 1] - ayo

