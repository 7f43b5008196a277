"""Scene -> flat float64 arrays for the kernels (no numba here).

Also solves the static equilibrium that starts every run (so transients are
small and the load path is explicit) and builds the defect contact tables once,
outside the time loop.
"""
from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from scipy.optimize import brentq, root

from ..errors import SceneError, SolverError
from . import _kernels as K
from .hertz import race_contact, series_stiffness
from .scene import Scene


@dataclass
class Assembly:
    scene: Scene
    p: np.ndarray
    sp_t: np.ndarray
    sp_w: np.ndarray
    sp_th: np.ndarray
    dint: np.ndarray
    dflt: np.ndarray
    hbuf: np.ndarray
    gbuf: np.ndarray
    y0: np.ndarray
    atol_scale: np.ndarray
    n_balls: int
    fidelity: str
    contact_models: tuple
    tables: tuple
    static: dict
    load_zone_angle: float
    hertz_inner: object
    hertz_outer: object

    @property
    def sensor_index(self) -> int:
        return int(self.p[K.P_SENSOFF])


def _unit(angle):
    return np.array([math.cos(angle), math.sin(angle)])


def bearing_force(e, phis, k_eff, pd, exponent=1.5):
    """Force (N, 2-vector) the balls exert on the OUTER ring for relative
    displacement e = inner - outer (quasi-static, massless balls)."""
    c, s = np.cos(phis), np.sin(phis)
    d = e[0] * c + e[1] * s - pd / 2
    q = k_eff * np.maximum(d, 0.0) ** exponent
    return np.array([np.sum(q * c), np.sum(q * s)]), q


def _solve_relative(target, phis, k_eff, pd, z, where):
    """Relative ring displacement e with bearing_force(e) == target (force on the outer ring)."""
    w = float(np.hypot(*target))
    if w < 1e-9:
        return np.zeros(2)
    direction = target / w
    # 1-D search along the load direction, then a 2-D polish (the load zone need not be symmetric)
    def along(a):
        return bearing_force(a * direction, phis, k_eff, pd)[0] @ direction - w
    hi = pd / 2 + (4.37 * w / (z * k_eff)) ** (2 / 3) * 4 + 1e-9
    lo = min(pd / 2, 0.0) - 1e-6
    while along(hi) < 0:
        hi *= 2
        if hi > 1e-2:
            raise SceneError(f"{where}: no static equilibrium (load {w:.3g} N too large for the bearing)")
    a = brentq(along, lo, hi, xtol=1e-16, rtol=1e-14)
    sol = root(lambda e: (bearing_force(e, phis, k_eff, pd)[0] - target) / w, a * direction,
               method="hybr", options={"xtol": 1e-14})
    e = sol.x if sol.success else a * direction
    return e


def static_equilibrium(scene: Scene, phi_c0: float, k_eff: float, *, exponent=1.5) -> dict:
    """Static equilibrium of the rings (quasi-static balls, no defects).

    Returns ring positions, the support springs' rest positions and the
    external forces on each ring (load + weight).
    """
    d = scene.data
    b = scene.bearing
    z = b.n_balls
    m_i, m_o, m_b = scene.masses()
    phis = phi_c0 + 2 * math.pi * np.arange(z) / z
    g = d["gravity"]["g_m_s2"] if d["gravity"]["enabled"] else 0.0
    gvec = np.array([0.0, -g])
    load = d["load"]["radial_n"] * _unit(math.radians(d["load"]["direction_deg"]))
    f_in = m_i * gvec + (load if d["load"]["on"] == "inner" else 0.0)
    f_out = m_o * gvec + (load if d["load"]["on"] == "outer" else 0.0)
    ks = np.array([d["shaft"]["stiffness_x_n_m"], d["shaft"]["stiffness_y_n_m"]])
    km = np.array([d["mount"]["stiffness_x_n_m"], d["mount"]["stiffness_y_n_m"]])
    pd = scene.clearance
    if d["load"]["path"] == "bearing":
        if d["load"]["on"] == "outer":
            e = _solve_relative(-f_out, phis, k_eff, pd, z, "load")
            fb, q = bearing_force(e, phis, k_eff, pd)
            xi = (-fb + f_in) / ks
            xo = xi - e
            rest_i, rest_o = np.zeros(2), xo.copy()
        else:
            e = _solve_relative(f_in, phis, k_eff, pd, z, "load")
            fb, q = bearing_force(e, phis, k_eff, pd)
            xo = (fb + f_out) / km
            xi = xo + e
            rest_i, rest_o = xi.copy(), np.zeros(2)
    else:
        rest_i, rest_o = np.zeros(2), np.zeros(2)

        def resid(x):
            xi, xo = x[:2], x[2:]
            fb, _ = bearing_force(xi - xo, phis, k_eff, pd)
            r_i = -fb + f_in - ks * xi
            r_o = fb + f_out - km * xo
            return np.concatenate([r_i, r_o]) / max(1.0, d["load"]["radial_n"])
        x0 = np.concatenate([f_in / ks, f_out / km])
        sol = root(resid, x0, method="hybr", options={"xtol": 1e-14})
        if not sol.success or np.max(np.abs(resid(sol.x))) > 1e-6:
            raise SolverError(f"scene {scene.name!r}: static equilibrium not found ({sol.message})")
        xi, xo = sol.x[:2], sol.x[2:]
        fb, q = bearing_force(xi - xo, phis, k_eff, pd)
    return {"xi": xi, "xo": xo, "rest_i": rest_i, "rest_o": rest_o, "f_in": f_in, "f_out": f_out,
            "ball_loads": q, "phis": phis, "load_vec": load, "gvec": gvec}


def load_zone_angle(scene: Scene) -> float:
    """Angle (rad) of the load-zone centre: the load direction for a load on the
    inner ring, the opposite direction for a load on the outer ring."""
    d = scene.data["load"]
    beta = math.radians(d["direction_deg"])
    return beta if d["on"] == "inner" else beta + math.pi


def choose_contact_model(defect, requested: str, bearing) -> str:
    """The defect-contact model for this defect.

    "auto" takes "area" (2-D, with loss of contact area) for every defect: measured on the
    paper's scenes (benchmarks/defect_models.py, README), the cheaper models are not exact
    even where one might expect it.  For the full-width slot the along-track "profile" model
    (a rigid ball meeting the slot's edge lines) overstates the peak acceleration by ~70 %,
    because the contact patch is 0.3 mm long along the track against a 1 mm slot; for narrow,
    offset or skewed defects "profile" and "drop" are off by factors.  All three cost the same
    in the time loop (one table lookup); only the table build differs (0.05-1 s).  The cheaper
    models stay selectable with ``contact_model = "profile"`` or ``"drop"``.
    """
    if requested and requested != "auto":
        if requested not in ("profile", "drop", "area", "halfspace"):
            raise SceneError(f"defect.contact_model={requested!r}; allowed values are "
                             "'auto', 'profile', 'drop', 'area' and 'halfspace'")
        return requested
    return "area"


def assemble(scene: Scene, *, fidelity: str | None = None) -> Assembly:
    d = scene.data
    b = scene.bearing
    fid = fidelity or scene.fidelity
    if fid == "auto":
        from .auto import resolve
        fid = resolve(scene)["fidelity"]
    z = b.n_balls
    mat = d["material"]
    E, nu = mat["youngs_modulus_gpa"] * 1e9, mat["poisson_ratio"]
    hi = race_contact(b.ball_diameter, b.pitch_diameter, b.inner_conformity, "inner",
                      contact_angle=b.contact_angle, youngs_modulus=E, poisson_ratio=nu)
    ho = race_contact(b.ball_diameter, b.pitch_diameter, b.outer_conformity, "outer",
                      contact_angle=b.contact_angle, youngs_modulus=E, poisson_ratio=nu)
    k_eff = series_stiffness(hi.stiffness, ho.stiffness)
    m_i, m_o, m_b = scene.masses()
    ftf = b.frequency_factors()["ftf"]
    lz = load_zone_angle(scene)
    # cage angle at t = 0: a ball centred in the load zone (the symmetric start)
    phi_c0 = lz
    st = static_equilibrium(scene, phi_c0, k_eff, exponent=d["contact"]["exponent"])

    # speed profile (rad/s), shaft angle at the nodes
    sp_t, rpm = scene.speed_profile()
    sp_w = rpm * 2 * math.pi / 60
    sp_th = np.zeros_like(sp_t)
    if len(sp_t) > 1:
        sp_th[1:] = np.cumsum(0.5 * (sp_w[1:] + sp_w[:-1]) * np.diff(sp_t))
    # shaft angle is measured from t = 0: shift so that theta(0) = 0
    th0, _ = K.shaft_state(0.0, sp_t, sp_w, sp_th)
    sp_th = sp_th - th0

    # loads and their optional step
    g = d["gravity"]["g_m_s2"] if d["gravity"]["enabled"] else 0.0
    tstep = math.inf
    f_in2, f_out2 = st["f_in"], st["f_out"]
    if d["load"]["step_time_s"] is not None:
        if d["load"]["step_radial_n"] is None:
            raise SceneError("load.step_time_s needs load.step_radial_n")
        tstep = scene.settle + d["load"]["step_time_s"]
        new = d["load"]["step_radial_n"] * _unit(math.radians(d["load"]["direction_deg"]))
        old = st["load_vec"]
        if d["load"]["on"] == "inner":
            f_in2 = st["f_in"] - old + new
        else:
            f_out2 = st["f_out"] - old + new

    # defects -> tables (a ball defect gets one table per race it meets)
    import dataclasses
    from .defects import contact_table
    models, tables = [], []
    entries = []  # (race code, defect used for the table, psi0, ball, model)
    static_max = float(np.max(st["ball_loads"])) if len(st["ball_loads"]) else 0.0
    delta_max = max(3.0 * (max(static_max, 50.0) / ho.stiffness) ** (2 / 3), 5e-6)
    for kk, defect in enumerate(scene.defects):
        req = (d["defect"][kk] or {}).get("contact_model", "auto")
        model = choose_contact_model(defect, req, b)
        models.append(model)
        if defect.race == "ball":
            for code, race in ((2, "outer"), (3, "inner")):
                entries.append((code, dataclasses.replace(defect, race=race, angle=0.0),
                                defect.angle, 0, model))
        else:
            entries.append((0 if defect.race == "outer" else 1, defect, lz + defect.angle, -1, model))
    n_e = max(len(entries), 1)
    dint = np.zeros((n_e, 7), dtype=np.int64)
    dflt = np.zeros((n_e, 7))
    hparts, gparts = [], []
    hoff = goff = 0
    for kk, (code, dfc, psi0, ball, model) in enumerate(entries):
        tab = contact_table(dfc, b, model=model, clearance=scene.clearance, delta_max=delta_max)
        tables.append(tab)
        psi = np.asarray(tab.psi, dtype=float)
        kind = 1 if model in ("area", "halfspace") else 0
        h = np.ascontiguousarray(tab.drop, dtype=float)
        # the kernel interpolates G^(2/3) (see _kernels._interp_g)
        G = np.ascontiguousarray(np.maximum(tab.G, 0.0) ** (2.0 / 3.0), dtype=float)
        scale = b.ball_diameter / 2 / tab.track_radius if code >= 2 else 1.0
        dint[kk] = [code, kind, len(psi), G.shape[1], hoff, goff, ball]
        dflt[kk] = [psi0, psi[0], psi[1] - psi[0], tab.delta[1] - tab.delta[0], psi[0], psi[-1], scale]
        hparts.append(h)
        gparts.append(G.ravel() if kind == 1 else np.zeros(0))
        hoff += len(h)
        goff += gparts[-1].size
    hbuf = np.concatenate(hparts) if hparts else np.zeros(1)
    gbuf = np.concatenate(gparts) if gparts and goff else np.zeros(1)

    p = np.zeros(K.P_SIZE)
    p[K.P_Z] = z
    p[K.P_RP] = b.pitch_diameter / 2
    p[K.P_PD] = scene.clearance
    p[K.P_KI], p[K.P_KO], p[K.P_KEFF] = hi.stiffness, ho.stiffness, k_eff
    p[K.P_CMAX] = d["contact"]["damping_n_s_m"]
    p[K.P_DPEN] = d["contact"]["penetration_um"] * 1e-6
    p[K.P_EXP] = d["contact"]["exponent"]
    p[K.P_MI], p[K.P_MO], p[K.P_MB] = m_i, m_o, m_b
    p[K.P_KSX], p[K.P_KSY] = d["shaft"]["stiffness_x_n_m"], d["shaft"]["stiffness_y_n_m"]
    p[K.P_CSX], p[K.P_CSY] = d["shaft"]["damping_x_n_s_m"], d["shaft"]["damping_y_n_s_m"]
    p[K.P_KMX], p[K.P_KMY] = d["mount"]["stiffness_x_n_m"], d["mount"]["stiffness_y_n_m"]
    p[K.P_CMX], p[K.P_CMY] = d["mount"]["damping_x_n_s_m"], d["mount"]["damping_y_n_s_m"]
    p[K.P_XIR], p[K.P_YIR] = st["rest_i"]
    p[K.P_XOR], p[K.P_YOR] = st["rest_o"]
    p[K.P_FIX], p[K.P_FIY] = st["f_in"]
    p[K.P_FOX], p[K.P_FOY] = st["f_out"]
    p[K.P_TSTEP] = tstep
    p[K.P_FIX2], p[K.P_FIY2] = f_in2
    p[K.P_FOX2], p[K.P_FOY2] = f_out2
    p[K.P_G] = g
    p[K.P_FTF] = ftf
    p[K.P_PHI0] = phi_c0
    sens = d["sensor"]
    p[K.P_SENS] = 1.0 if sens["enabled"] else 0.0
    p[K.P_SW] = 2 * math.pi * sens["frequency_hz"]
    p[K.P_SZ] = sens["damping_ratio"]
    p[K.P_FID] = 1.0 if fid == "quasi-static" else 0.0
    dyn = d["cage"]["model"] == "dynamic"
    if dyn and fid == "quasi-static":
        raise SceneError("cage.model='dynamic' needs fidelity='multibody' (massless balls have no "
                         "orbital dynamics)")
    p[K.P_CAGE] = 1.0 if dyn else 0.0
    cg = d["cage"]
    p[K.P_MU] = cg["traction_coefficient"]
    p[K.P_VREF] = cg["traction_slip_m_s"]
    p[K.P_KPOCK] = cg["pocket_stiffness_n_m"]
    p[K.P_CPOCK] = cg["pocket_clearance_mm"] * 1e-3
    p[K.P_DPOCK] = cg["pocket_damping_n_s_m"]
    m_cage = cg["mass_kg"] or 0.15 * z * m_b
    p[K.P_IC] = m_cage * (b.pitch_diameter / 2) ** 2
    p[K.P_RB] = b.ball_diameter / 2
    p[K.P_CDRAG] = cg["drag_n_m_s"]
    p[K.P_UNB] = d["shaft"]["unbalance_g_mm"] * 1e-6
    p[K.P_IB] = 0.4 * m_b * (b.ball_diameter / 2) ** 2
    p[K.P_NDEF] = len(entries)
    p[K.P_SPIN] = b.frequency_factors()["bsf"]

    # initial state
    n_ball_states = 0 if fid == "quasi-static" else (5 * z + 2 if dyn else 2 * z)
    n = 8 + n_ball_states + (4 if sens["enabled"] else 0)
    p[K.P_SENSOFF] = 8 + n_ball_states
    y0 = np.zeros(n)
    y0[0:2] = st["xi"]
    y0[4:6] = st["xo"]
    xi, xo = st["xi"], st["xo"]
    pd4 = scene.clearance / 4
    omega_c = ftf * sp_w[0]
    if fid != "quasi-static":
        for j, phi in enumerate(st["phis"]):
            c, s = math.cos(phi), math.sin(phi)
            ou = xo[0] * c + xo[1] * s
            iu = xi[0] * c + xi[1] * s
            fc = m_b * (b.pitch_diameter / 2) * omega_c ** 2 - m_b * g * s

            def gq(q):
                di = -q + iu - pd4
                do = q - ou - pd4
                return (hi.stiffness * max(di, 0) ** 1.5 - ho.stiffness * max(do, 0) ** 1.5 + fc)
            lo_q, hi_q = ou + pd4 - 1e-4, iu - pd4 + 1e-4
            y0[8 + j] = brentq(gq, lo_q, hi_q, xtol=1e-16, rtol=1e-14)
        if dyn:
            # balls at the kinematic positions and speeds, rolling without slip; cage alike
            v_c = b.pitch_diameter / 2 * omega_c
            for j, phi in enumerate(st["phis"]):
                y0[8 + 2 * z + j] = phi
                y0[8 + 3 * z + j] = omega_c
                y0[8 + 4 * z + j] = -v_c / (b.ball_diameter / 2)
            y0[8 + 5 * z] = phi_c0
            y0[8 + 5 * z + 1] = omega_c
    # error-control scales: displacement ~ the static deflection, velocity ~ that x 2π·2 kHz
    x_scale = max((max(static_max, 10.0) / k_eff) ** (2 / 3), 1e-7)
    v_scale = x_scale * 2 * math.pi * 2000.0
    atol = np.empty(n)
    pos_idx = [0, 1, 4, 5, *range(8, 8 + z if fid != "quasi-static" else 8)]
    atol[:] = v_scale
    atol[pos_idx] = x_scale
    if dyn:
        # angles: the static deflection over the pitch radius; angular rates: 1 % of the cage speed
        atol[8 + 2 * z:8 + 3 * z] = x_scale / (b.pitch_diameter / 2)
        atol[8 + 3 * z:8 + 4 * z] = 0.01 * max(omega_c, 1.0)
        atol[8 + 4 * z:8 + 5 * z] = 0.01 * max(omega_c, 1.0) * b.pitch_diameter / b.ball_diameter
        atol[8 + 5 * z] = x_scale / (b.pitch_diameter / 2)
        atol[8 + 5 * z + 1] = 0.01 * max(omega_c, 1.0)
    if sens["enabled"]:
        sb = 8 + n_ball_states
        atol[sb:sb + 2] = x_scale
        atol[sb + 2:sb + 4] = v_scale
    return Assembly(scene, p, np.ascontiguousarray(sp_t, dtype=float), np.ascontiguousarray(sp_w),
                    np.ascontiguousarray(sp_th), dint, dflt, hbuf, gbuf, y0, atol, z, fid,
                    tuple(models), tuple(tables), st, lz, hi, ho)
