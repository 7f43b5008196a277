"""The 3-D bearing: rings that also move axially, and contacts at their real contact angle.

Why: under an axial load (a thrust, or a motor's wave-spring preload) a deep-groove ball bearing
runs at a contact angle.  Each contact then acts along the line through the ball centre and the
groove's curvature centre, its approach is measured along that line, and the contact point moves
across the groove by ``r_g sin(alpha)`` (about 1.1-1.3 mm on the 6308 at 300-500 N, more than the
width of the paper's defects).  The planar model cannot represent any of this, so a scene with an
axial load runs this model; a scene without one runs the planar model, unchanged.

Geometry (exact, rigid rings, Harris & Kotzalas 2007, ch. 1-3): in the plane of ball j (azimuth
``phi_j``), with ``u = x cos(phi_j) + y sin(phi_j)`` a ring's radial displacement there and ``z``
its axial one, the outer groove's curvature centre sits at radius ``d_m/2 + P_d/4 + D_b/2 - r_go
+ u_o``, the inner one's at ``d_m/2 - P_d/4 - D_b/2 + r_gi + u_i``.  A ball whose centre is at
radius ``d_m/2 + q`` and axial position ``w``:

* outer contact: vector from the curvature centre to the ball centre ``(rho_o, zeta_o) = (q - u_o
  - P_d/4 + a_o, w - z_o)`` with ``a_o = r_go - D_b/2``; approach ``|.| - a_o``; contact angle
  ``atan2(zeta_o, rho_o)``;
* inner contact: vector from the ball centre to the curvature centre ``(rho_i, zeta_i) = (u_i - q -
  P_d/4 + a_i, z_i - w)``, ``a_i = r_gi - D_b/2``; approach ``|.| - a_i``.

The load is ``K delta^1.5`` (Hertz, each race's own constant) along the line; a ball with mass
carries its centrifugal force ``m_b (d_m/2 + q) omega_c^2`` radially, so at speed the outer contact
angle is smaller than the inner one (Jones; Harris & Kotzalas 2007, ch. 3).  A massless ball
(quasi-static fidelity) has one line through both curvature centres: ``(rho, zeta) = (a_i + a_o -
P_d/2 + u_i - u_o, z_i - z_o)``, approach ``|.| - (a_i + a_o)``, the same angle at both races.

With ``rho`` along the radius and ``zeta`` along the axis, an axial load reaches zero contact
angle only at zero load: the planar model is this model's limit ``zeta = 0``, which it computes
with fewer operations (and so the planar scenes keep their results to the last bit).

Public API
----------
needs_3d(scene) -> bool                       -- the scene has an axial load or preload
preload_geometry(bearing, clearance, delta)   -- rigid-ring displacement preload: offset, approach, angle
check_axial_keys(scene)                       -- the displacement preload's checks (SceneError)
static_equilibrium_3d(scene, phi_c0, k_in, k_out, *, ball_mass, omega_cage, exponent) -> dict
contact_angles(...)                           -- per ball, from states (see :func:`contact_angles`)
axial_support(section) -> (k, c)             -- a support's axial stiffness and damping (its Y values if unset)
load_zone_angle(scene) -> float               -- the load-zone centre, rad
race_contacts(scene)                          -- the Hertz contacts (inner, outer) of the scene's bearing
static_3d(scene, fid) -> dict                 -- the start of a 3-D run of fidelity fid, kept on the scene
track_offset(defect, st, race, psi0, bearing) -- the defect as the 3-D contact track meets it
"""
from __future__ import annotations

import dataclasses
import math

import lazy_loader as lazy
import numpy as np

from ..errors import SceneError, SolverError
from ._equilibrium_kernel import balls_3d
from .hertz import race_contact
from .limits import MAX_SUPPORT_DEFLECTION
from .numerics import brentq

#: scipy.optimize (Powell's hybrid method, Levenberg-Marquardt) for the 3-D starts: imported the first
#: time a 3-D scene needs it, so a planar run never pays for it (``docs/architecture.md``, "Imports")
_optimize = lazy.load("scipy.optimize", suppress_warning=True)

__all__ = ["needs_3d", "static_equilibrium_3d", "contact_angles", "groove_offsets", "preload_geometry",
           "check_axial_keys", "axial_support", "load_zone_angle", "race_contacts", "static_3d", "track_offset"]


def needs_3d(scene) -> bool:
    """True when the scene loads the bearing axially (``load.axial_n`` not zero, or a displacement
    preload ``load.axial_preload_um`` above zero)."""
    d = scene.data["load"]
    return abs(float(d.get("axial_n") or 0.0)) > 0.0 or float(d.get("axial_preload_um") or 0.0) > 0.0


#: the largest normal approach of a ball's two contacts a displacement preload may ask for, as a
#: fraction of the ball diameter (the limit the scene check puts on a radial preload)
MAX_APPROACH = 0.005


def preload_geometry(bearing, clearance, delta):
    """Rigid rings, centred radially, the loaded one pushed axially by ``delta`` (m) beyond the point
    where the axial play is taken up: ``(axial offset of the curvature centres, normal approach of
    each ball's two contacts, contact angle)`` (m, m, rad).  The centres lie ``A = a_i + a_o`` apart
    at zero load and ``A - P_d/2`` apart radially, so the play is taken up at the axial offset
    ``sqrt(A^2 - (A - P_d/2)^2)`` (the free contact angle, Harris & Kotzalas 2007, sec. 2.2); with a
    negative clearance there is no play and the offset counts from the centred rings."""
    a_i, a_o = groove_offsets(bearing)
    a0 = a_i + a_o
    rho = a0 - clearance / 2
    z = math.sqrt(max(a0 * a0 - rho * rho, 0.0)) + delta
    return z, math.hypot(rho, z) - a0, math.atan2(z, rho)


def check_axial_keys(scene) -> None:
    """``load.axial_preload_um``: not with ``load.axial_n``, grooves that can take a contact angle,
    and no more than :data:`MAX_APPROACH` of the ball diameter pressed into the grooves."""
    d = scene.data["load"]
    pre = float(d.get("axial_preload_um") or 0.0)
    if pre <= 0.0:
        return
    if d["axial_n"]:
        raise SceneError(f"load.axial_preload_um={pre:g} and load.axial_n={d['axial_n']:g} are both given: a "
                         "displacement preload fixes how far the rings are pushed together and the start "
                         "solves for the force that takes, which a force on top would change; give one (a "
                         "preloaded bearing under a further thrust: load.axial_n = the preload's force, "
                         "reported as the attribute axial_force_n, plus the thrust)")
    b = scene.bearing
    a_i, a_o = groove_offsets(b)
    if a_i <= 0 or a_o <= 0:
        raise SceneError(f"load.axial_preload_um={pre:g}: bearing {b.name!r} has groove conformities of 0.5 or "
                         f"less (inner {b.inner_conformity:g}, outer {b.outer_conformity:g}): no contact angle")
    _, approach, alpha = preload_geometry(b, scene.clearance, pre * 1e-6)
    limit = MAX_APPROACH * b.ball_diameter
    if approach > limit:
        rho = a_i + a_o - scene.clearance / 2
        z_max = math.sqrt((a_i + a_o + limit) ** 2 - rho * rho)
        most = z_max - preload_geometry(b, scene.clearance, 0.0)[0]
        raise SceneError(f"load.axial_preload_um={pre:g}: presses each ball {approach * 1e6:.3g} µm into its "
                         f"grooves (contact angle {math.degrees(alpha):.1f} deg), beyond the {limit * 1e6:.0f} µm "
                         f"(0.5 % of the ball diameter) that crushes the balls; at most {most * 1e6:.0f} µm here")


def groove_offsets(bearing):
    """``(a_i, a_o)``: groove curvature radius minus ball radius, inner and outer race (m)."""
    db = bearing.ball_diameter
    return (bearing.inner_conformity - 0.5) * db, (bearing.outer_conformity - 0.5) * db


def _unit(angle):
    return np.array([math.cos(angle), math.sin(angle)])


def _hz(k, d, e):
    return k * max(d, 0.0) ** e


def _ball_multibody(u_i, z_i, u_o, z_o, fc, pd4, a_i, a_o, k_in, k_out, e, guess):
    """Ball centre (q, w) where its two contact forces and its body force ``fc`` (radial) balance."""
    def parts(x):
        q, w = x
        ro, zo = q - u_o - pd4 + a_o, w - z_o
        ri, zi = u_i - q - pd4 + a_i, z_i - w
        lo, li = math.hypot(ro, zo), math.hypot(ri, zi)
        fo, fi = _hz(k_out, lo - a_o, e), _hz(k_in, li - a_i, e)
        return fo, fi, ro, zo, lo, ri, zi, li

    def res(xs):
        fo, fi, ro, zo, lo, ri, zi, li = parts(xs * 1e-6)
        return [(fi * ri / li - fo * ro / lo + fc) / scale, (fi * zi / li - fo * zo / lo) / scale]
    scale = max(abs(fc), 1.0)
    if guess is None:
        # on the line through both curvature centres, the approach split as the two stiffnesses ask
        co = np.array([u_o + pd4 - a_o, z_o])
        ci = np.array([u_i - pd4 + a_i, z_i])
        ln = float(np.hypot(*(ci - co)))
        tot = max(ln - a_i - a_o, 0.0)
        share = 1.0 / (1.0 + (k_out / k_in) ** (1.0 / e))
        guess = co + (ci - co) / ln * (a_o + tot * share)
        if tot * share < (max(fc, 0.0) / k_out) ** (1.0 / e):
            # a ball the rings do not squeeze: its centrifugal force holds it on the outer race
            guess = co + (guess - co) / max(float(np.hypot(*(guess - co))), 1e-30) * (
                a_o + (max(fc, 0.0) / k_out) ** (1.0 / e))
    sol = _optimize.root(res, np.asarray(guess) * 1e6, method="hybr", options={"xtol": 1e-13})
    x = sol.x
    if max(abs(v) for v in res(x)) > 1e-11:
        sol = _optimize.root(res, x, method="lm", options={"xtol": 1e-15, "ftol": 1e-15})
        if max(abs(v) for v in res(sol.x)) < max(abs(v) for v in res(x)):
            x = sol.x
    return x * 1e-6, parts(x * 1e-6)


def _balls_multibody(u, z_i, fc, pd4, a_i, a_o, k_in, k_out, e):
    """(q, w, out) of every ball (:func:`._equilibrium_kernel.balls_3d`, compiled: a scipy root per
    ball cost 25-35 ms of every 3-D multibody start): Newton's method from the line through the
    curvature centres; a ball it leaves unbalanced is solved by :func:`_ball_multibody`."""
    z = u.size
    co = np.stack([np.full(z, pd4 - a_o), np.zeros(z)])
    ci = np.stack([u - pd4 + a_i, np.full(z, float(z_i))])
    ln = np.hypot(*(ci - co))
    tot = np.maximum(ln - a_i - a_o, 0.0)
    share = 1.0 / (1.0 + (k_out / k_in) ** (1.0 / e))
    free = (np.maximum(fc, 0.0) / k_out) ** (1.0 / e)
    reach = np.where(tot * share < free, a_o + free, a_o + tot * share)
    q, w = co + (ci - co) / ln * reach
    out = np.empty((z, 9))
    if balls_3d(np.ascontiguousarray(u, dtype=float), float(z_i), np.ascontiguousarray(fc, dtype=float), pd4, a_i,
                a_o, k_in, k_out, float(e), q, w, out):
        for j in np.flatnonzero(~(out[:, 8] <= 1e-11)):
            (q[j], w[j]), parts = _ball_multibody(u[j], z_i, 0.0, 0.0, fc[j], pd4, a_i, a_o, k_in, k_out, e, None)
            out[j, :8] = parts
    return q, w, out


def ball_forces(e_vec, phis, *, k_in, k_out, pd, a_i, a_o, exponent, ball_mass, omega_cage, g, pitch_radius):
    """Balls between rings displaced by ``e_vec = (inner - outer)`` (x, y, z), outer ring at the origin.

    Returns ``(force on inner ring (3,), force on outer ring (3,), Q_i (Z,), Q_o (Z,), alpha_i, alpha_o
    (Z, rad), q (Z,), w (Z,))``: q, w the ball centres relative to the outer ring (radial, axial)."""
    phis = np.asarray(phis, dtype=float)
    c, s = np.cos(phis), np.sin(phis)
    u = e_vec[0] * c + e_vec[1] * s
    pd4 = pd / 4
    if ball_mass > 0:
        fc = ball_mass * (pitch_radius * omega_cage ** 2 - g * s)
        qq, ww, out = _balls_multibody(u, e_vec[2], fc, pd4, a_i, a_o, k_in, k_out, exponent)
        qo, qi, ro, zo, lo, ri, zi, li = out[:, :8].T
        nri, nzi, nro, nzo = ri / li, zi / li, ro / lo, zo / lo
    else:
        rho, zeta = a_i + a_o - 2 * pd4 + u, np.full_like(u, e_vec[2])
        ln = np.hypot(rho, zeta)
        k_eff = (k_in ** (-1 / exponent) + k_out ** (-1 / exponent)) ** (-exponent)
        qi = qo = k_eff * np.maximum(ln - a_i - a_o, 0.0) ** exponent
        nri = nro = rho / ln
        nzi = nzo = zeta / ln
        qq, ww = u / 2, zeta / 2
    f_i = -np.array([np.sum(qi * nri * c), np.sum(qi * nri * s), np.sum(qi * nzi)])
    f_o = np.array([np.sum(qo * nro * c), np.sum(qo * nro * s), np.sum(qo * nzo)])
    return f_i, f_o, qi, qo, np.arctan2(nzi, nri), np.arctan2(nzo, nro), qq, ww


def static_equilibrium_3d(scene, phi_c0, k_in, k_out, *, ball_mass=0.0, omega_cage=0.0, exponent=1.5) -> dict:
    """Static equilibrium of the 3-D bearing at the start of a run (no defects).

    Load path "bearing": the loaded ring's supports (radial and axial) are preloaded so that they
    carry nothing at the start: the bearing carries the whole load.  Path "springs": every support
    spring is unstressed at the centre.  A displacement preload (``load.axial_preload_um``) fixes
    the rings' relative axial position (:func:`preload_geometry`); the radial balance is solved and
    the axial force the balls then carry is held by the axial supports (see :func:`_ring_positions`).
    Returns the keys of the planar ``static_equilibrium`` (x, y parts) plus ``zi``, ``zo``,
    ``rest_zi``, ``rest_zo``, ``f_inz``, ``f_outz``, the balls' ``q``, ``w`` (absolute, m), contact
    angles ``alpha_i``, ``alpha_o`` (rad) and ``axial_force_n``, the axial force the balls carry.
    """
    d = scene.data
    b = scene.bearing
    z = b.n_balls
    m_i, m_o, _ = scene.masses()
    g = d["gravity"]["g_m_s2"] if d["gravity"]["enabled"] else 0.0
    radial = d["load"]["radial_n"] * _unit(math.radians(d["load"]["direction_deg"]))
    axial = float(d["load"]["axial_n"] or 0.0)
    pre = float(d["load"].get("axial_preload_um") or 0.0) * 1e-6
    on_outer = d["load"]["on"] == "outer"
    load = np.array([radial[0], radial[1], axial])
    grav = np.array([0.0, -g, 0.0])
    f_in = m_i * grav + (0.0 if on_outer else load)
    f_out = m_o * grav + (load if on_outer else 0.0)
    ks = np.array([d["shaft"]["stiffness_x_n_m"], d["shaft"]["stiffness_y_n_m"], axial_support(d["shaft"])[0]])
    km = np.array([d["mount"]["stiffness_x_n_m"], d["mount"]["stiffness_y_n_m"], axial_support(d["mount"])[0]])
    a_i, a_o = groove_offsets(b)
    if a_i <= 0 or a_o <= 0:
        raise SceneError(f"bearing {b.name!r}: an axial load needs groove conformities above 0.5 "
                         f"(inner {b.inner_conformity:g}, outer {b.outer_conformity:g})")
    pd = scene.clearance
    phis = phi_c0 + 2 * math.pi * np.arange(z) / z
    kw = dict(k_in=k_in, k_out=k_out, pd=pd, a_i=a_i, a_o=a_o, exponent=exponent, ball_mass=ball_mass,
              omega_cage=omega_cage, g=g, pitch_radius=b.pitch_diameter / 2)
    k_eff = (k_in ** (-1 / exponent) + k_out ** (-1 / exponent)) ** (-exponent)
    # scale: the deflection of one ball carrying the whole load, plus the clearance
    scale = pd / 2 + (max(float(np.linalg.norm(load)), 1.0) / k_eff) ** (1 / exponent) * 4
    a0 = a_i + a_o
    # start: the axial play taken up (rigid rings, no load) plus a deflection, e = inner - outer
    sgn = -1.0 if on_outer else 1.0
    dr = _unit(math.radians(d["load"]["direction_deg"])) * (0.25 * scale if d["load"]["radial_n"] else 0.0)
    ez = (preload_geometry(b, pd, pre)[0] if pre else
          math.copysign(a0 * math.sin(_axial_angle(abs(axial), z, k_eff, a0, pd, exponent)), axial) if axial else 0.0)
    e0 = sgn * np.array([dr[0], dr[1], ez])
    path = d["load"]["path"]

    def forces(e):
        return ball_forces(e, phis, **kw)

    ax_unit = np.array([0.0, 0.0, 1.0])

    def make_resid(frac):
        # the residual with the axial load scaled by frac (a continuation from the radial solution)
        fi_ext, fo_ext = f_in - (1 - frac) * (0.0 if on_outer else axial) * ax_unit, \
            f_out - (1 - frac) * (axial if on_outer else 0.0) * ax_unit
        if path == "bearing":
            def resid(e):
                fi, fo = forces(e)[:2]
                return ((fo + fo_ext) if on_outer else (fi + fi_ext)) / max(float(np.linalg.norm(load)), 1.0)
        else:
            def resid(e):
                fi, fo = forces(e)[:2]
                xi, xo = (fi + fi_ext) / ks, (fo + fo_ext) / km
                return (xi - xo - e) / scale
        return resid

    if pre:
        e, r, msg, resid = _solve_preload(make_resid(1.0), e0, scale, sgn * 50e-6)
    else:
        # unknowns in units of their expected size (the axial one can be 10-100 times the radial one)
        unit = np.array([scale, scale, max(abs(e0[2]), scale)])
        resid = make_resid(1.0)
        e, r, msg = _root_best(resid, (e0, e0 * np.array([1.0, 1.0, 1.5]), e0 * np.array([2.0, 2.0, 0.8])), unit)
        if (not np.all(np.isfinite(e)) or r > 1e-8) and d["load"]["radial_n"]:
            e, r, msg = _continuation(make_resid, forces, e0, scale, axial * sgn, a0)
    if not np.all(np.isfinite(e)) or r > 1e-8:
        raise SolverError(f"scene {scene.name!r}: 3-D static equilibrium not found ({msg}; "
                          f"residual {r:.3g})" + (_preload_hint(b, pd, pre, k_eff, exponent) if pre else ""))
    fi, fo, q_in, q_out, al_i, al_o, q, w = forces(e)
    xi, xo, rest_i, rest_o = _ring_positions(path, on_outer, e, fi, fo, f_in, f_out, ks, km, bool(pre))
    for sec, x, k in (("shaft", xi[2], ks[2]), ("mount", xo[2], km[2])):
        if abs(x) > MAX_SUPPORT_DEFLECTION:
            raise SceneError(f"{sec}.stiffness_z_n_m={k:g} (unset: the Y stiffness): holding the bearing's axial "
                             f"force of {abs(fo[2]):.3g} N it puts the ring {abs(x):.3g} m off centre; a bearing "
                             f"support gives less than {MAX_SUPPORT_DEFLECTION * 1e3:g} mm")
    return {"xi": xi[:2], "xo": xo[:2], "zi": float(xi[2]), "zo": float(xo[2]),
            "rest_i": rest_i[:2], "rest_o": rest_o[:2], "rest_zi": float(rest_i[2]), "rest_zo": float(rest_o[2]),
            "f_in": f_in[:2], "f_out": f_out[:2], "f_inz": float(f_in[2]), "f_outz": float(f_out[2]),
            "ball_loads": q_out, "ball_loads_inner": q_in, "ball_loads_outer": q_out,
            "phis": phis, "load_vec": radial, "gvec": grav[:2], "alpha_i": al_i, "alpha_o": al_o,
            "q": q + np.array([xo[0] * math.cos(p) + xo[1] * math.sin(p) for p in phis]), "w": w + xo[2],
            "residual": float(np.max(np.abs(resid(e)))), "axial_force_n": float(abs(fo[2]))}


def _preload_hint(bearing, clearance, pre, k_eff, exponent):
    """What a displacement preload that found no start does, rigid rings: for the error message."""
    _, dn, alpha = preload_geometry(bearing, clearance, pre)
    fa = bearing.n_balls * k_eff * max(dn, 0.0) ** exponent * math.sin(alpha)
    return (f"; load.axial_preload_um={pre * 1e6:g} presses each ball {dn * 1e6:.3g} µm into its grooves, about "
            f"{fa:.3g} N axial on rigid rings: a preload this light beside the radial load, the weights or the "
            "balls' centrifugal force leaves balls barely touching; give a larger preload")


def _solve_preload(resid3, e0, scale, firmer):
    """A displacement preload: the relative axial position ``e0[2]`` fixed, the radial balance (the x,
    y parts of the residual) solved.  A small preload beside a radial load, or one the balls'
    centrifugal force lifts them against, leaves balls barely touching and the root search
    stalling: then the rings are first pressed ``firmer`` (m, signed) further together, and the
    displacement brought back to the preload in steps, each started from the last solution.
    Returns (e, max |residual|, message, residual of e)."""
    unit = np.array([scale, scale])

    def at(ez):
        return lambda exy: resid3(np.array([exy[0], exy[1], ez]))[:2]
    ez = e0[2]
    exy, r, msg = _root_best(at(ez), (e0[:2], 2.0 * e0[:2]), unit)
    if not (np.all(np.isfinite(exy)) and r <= 1e-8):
        start = e0[:2]
        for frac in (1.0, 0.5, 0.25, 0.12, 0.06, 0.03, 0.01, 0.0):
            start, r, msg = _root_best(at(ez + frac * firmer), (start, e0[:2]), unit)
        exy = start
    return np.array([exy[0], exy[1], ez]), r, msg, lambda e: at(ez)(e[:2])


def _ring_positions(path, on_outer, e, fi, fo, f_in, f_out, ks, km, preload):
    """(xi, xo, rest_i, rest_o), 3-vectors, for the relative displacement ``e`` and the balls' forces:
    path "bearing" preloads the loaded ring's supports to carry nothing, "springs" leaves every
    support unstressed at the centre.  A displacement preload has no axial force to carry: the
    unloaded ring's axial support is unstressed at the centre and holds the balls' axial force, the
    loaded ring's axial support sits where it pushes that ring against the balls with the same force
    (a locknut, a housing shoulder)."""
    if path == "bearing" and on_outer:
        xi = (fi + f_in) / ks
        xo = xi - e
        rest_i, rest_o = np.zeros(3), xo.copy()
    elif path == "bearing":
        xo = (fo + f_out) / km
        xi = xo + e
        rest_i, rest_o = xi.copy(), np.zeros(3)
    else:
        xi, xo = (fi + f_in) / ks, (fo + f_out) / km
        rest_i, rest_o = np.zeros(3), np.zeros(3)
    if preload:
        if on_outer:
            xi[2], rest_i[2] = (fi[2] + f_in[2]) / ks[2], 0.0
            xo[2] = xi[2] - e[2]
            rest_o[2] = xo[2] - (fo[2] + f_out[2]) / km[2]
        else:
            xo[2], rest_o[2] = (fo[2] + f_out[2]) / km[2], 0.0
            xi[2] = xo[2] + e[2]
            rest_i[2] = xi[2] - (fi[2] + f_in[2]) / ks[2]
    return xi, xo, rest_i, rest_o


def _root_best(resid, starts, unit):
    """(x, max |residual|, message) of the best root from ``starts``; unknowns in units of ``unit``;
    each start by Powell's hybrid method, then polished by Levenberg-Marquardt if not converged."""
    best = None
    for start in starts:
        for method, opts in (("hybr", {"xtol": 1e-15}), ("lm", {"xtol": 1e-15, "ftol": 1e-15})):
            sol = _optimize.root(lambda x: resid(x * unit), start / unit, method=method, options=opts)
            r = np.max(np.abs(resid(sol.x * unit)))
            if best is None or r < best[1]:
                best = (sol.x * unit, r, sol.message)
            if r <= 1e-9:
                return best
            start = best[0]      # polish the best point with the other method
    return best


def _continuation(make_resid, forces, e0, scale, signed_axial, a0):
    """A small axial load beside a large radial one: from the radial solution, raise the axial load
    in steps, each started where a small contact angle puts it (sum Q sin(a) = F_a, sin(a) ~ e_z / a0)."""
    e, r, msg = _root_best(make_resid(0.0), (e0 * np.array([1.0, 1.0, 0.0]),), np.array([scale, scale, scale]))
    for frac in (0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 0.85, 1.0):
        s_q = float(np.sum(forces(e)[3]))
        dz = frac * signed_axial * a0 / s_q if s_q > 0 else 0.0
        start = np.array([e[0], e[1], dz])
        e, r, msg = _root_best(make_resid(frac), (start, e), np.array([scale, scale, max(abs(dz), scale)]))
    return e, r, msg


def _axial_angle(fa, z, k_eff, a0, pd, exponent):
    """Contact angle (rad) of a pure axial load ``fa`` shared by ``z`` massless balls (rigid rings,
    Harris & Kotzalas 2007, sec. 7.2): ``fa = z K (a0 (cos a_f / cos a - 1))^e sin a``, a_f the free
    contact angle of the clearance."""
    cf = 1.0 - pd / (2 * a0)
    a_f = math.acos(max(-1.0, min(1.0, cf)))

    def f(a):
        return z * k_eff * max(a0 * (cf / math.cos(a) - 1.0), 0.0) ** exponent * math.sin(a) - fa
    return brentq(f, a_f + 1e-9, 1.4, xtol=1e-14, where=f"contact angle of a {fa:g} N axial load")


def axial_support(section):
    """(stiffness N/m, damping N s/m) of a support along the axis: its own keys, else its Y values."""
    k = section.get("stiffness_z_n_m")
    c = section.get("damping_z_n_s_m")
    return (section["stiffness_y_n_m"] if k is None else k), (section["damping_y_n_s_m"] if c is None else c)


def contact_angles(state, phis, *, zoff, pd, a_i, a_o, multibody, z):
    """Contact angles (deg) of each ball at the outer and inner race from output states.

    ``state`` (n_out, n_states), ``phis`` (n_out, Z) the balls' azimuths.  Returns (alpha_o, alpha_i)
    as (Z, n_out) arrays."""
    c, s = np.cos(phis), np.sin(phis)
    ui = state[:, [0]] * c + state[:, [1]] * s
    uo = state[:, [4]] * c + state[:, [5]] * s
    zi, zo = state[:, [zoff]], state[:, [zoff + 1]]
    if multibody:
        q = state[:, 8:8 + z]
        w = state[:, zoff + 4:zoff + 4 + z]
        ao = np.degrees(np.arctan2(w - zo, q - uo - pd / 4 + a_o))
        ai = np.degrees(np.arctan2(zi - w, ui - q - pd / 4 + a_i))
    else:
        ao = ai = np.degrees(np.arctan2(np.broadcast_to(zi - zo, ui.shape), a_i + a_o - pd / 2 + ui - uo))
    return ao.T, ai.T


# ---- the start and the contact track, shared by the assembly and the auto choice (below both)
def load_zone_angle(scene) -> float:
    """Angle (rad) of the load-zone centre: the load direction for a load on the
    inner ring, the opposite direction for a load on the outer ring."""
    d = scene.data["load"]
    beta = math.radians(d["direction_deg"])
    return beta if d["on"] == "inner" else beta + math.pi


def track_offset(defect, st, race, psi0, bearing):
    """The defect as the contact meets it in the 3-D bearing: the groove's cross-section turned
    about its curvature centre by the contact angle at the defect's position, so that the table,
    built for a ball at the groove bottom, sees the outline where the contact track really runs.
    The defect's centre at axial offset H (groove angle asin(H / r_g)) moves to r_g sin(asin(H /
    r_g) - alpha), and for an unskewed rectangle or ellipse its axial edges alike (its width then
    grows by about 1 / cos(alpha)); a skewed outline or a polygon only moves.  The along-track
    radius change ((1 - cos alpha) r_g / R, 0.2 % at 10 deg) is neglected."""
    a_i, a_o = groove_offsets(bearing)
    if race == "outer":
        r_g = a_o + bearing.ball_diameter / 2
        alpha = float(np.interp(psi0 % (2 * math.pi), np.sort(st["phis"] % (2 * math.pi)),
                                st["alpha_o"][np.argsort(st["phis"] % (2 * math.pi))], period=2 * math.pi))
    else:
        # a rotating (inner-race) defect: the angle of the most loaded ball
        r_g = a_i + bearing.ball_diameter / 2
        alpha = -float(st["alpha_i"][int(np.argmax(st["ball_loads_inner"]))])
    def turn(zz):
        return r_g * math.sin(math.asin(max(-1.0, min(1.0, zz / r_g))) - alpha)
    if defect.skew == 0.0 and defect.shape in ("rectangle", "ellipse"):
        # the axial edges turned too: a width B at the contact spans B / cos(alpha) of groove arc
        lo, hi = turn(defect.offset - defect.width / 2), turn(defect.offset + defect.width / 2)
        return dataclasses.replace(defect, offset=0.5 * (lo + hi), width=hi - lo), alpha
    return dataclasses.replace(defect, offset=turn(defect.offset)), alpha


def race_contacts(scene):
    """The Hertz contacts (inner, outer) of the scene's bearing and material."""
    b, mat = scene.bearing, scene.data["material"]
    kw = dict(contact_angle=b.contact_angle, youngs_modulus=mat["youngs_modulus_gpa"] * 1e9,
              poisson_ratio=mat["poisson_ratio"])
    return (race_contact(b.ball_diameter, b.pitch_diameter, b.inner_conformity, "inner", **kw),
            race_contact(b.ball_diameter, b.pitch_diameter, b.outer_conformity, "outer", **kw))


def static_3d(scene, fid: str) -> dict:
    """The 3-D bearing's static equilibrium at the start of a run of fidelity ``fid`` (cage with a
    ball at the load-zone centre, at the starting speed): the one :func:`.assembly.assemble` starts from and
    the one ``fidelity``/``solver.method = "auto"`` decide the contact track on.  Solved once per
    scene and fidelity and kept on the scene (a scene is not changed after it is built)."""
    cache = scene.__dict__.setdefault("_static_3d", {})
    if fid not in cache:
        hi, ho = race_contacts(scene)
        _, rpm = scene.speed_profile()
        omega_c0 = scene.bearing.frequency_factors()["ftf"] * rpm[0] * 2 * math.pi / 60
        cache[fid] = static_equilibrium_3d(scene, load_zone_angle(scene), hi.stiffness, ho.stiffness,
                                           ball_mass=0.0 if fid == "quasi-static" else scene.masses()[2],
                                           omega_cage=omega_c0, exponent=scene.data["contact"]["exponent"])
    return cache[fid]
