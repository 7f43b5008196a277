"""Scene -> flat float64 arrays for the kernels (no numba here).

Also starts every run from the static equilibrium (:mod:`.statics`, :mod:`.bearing3d`: so
transients are small and the load path is explicit) and builds the defect contact tables once,
outside the time loop.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
import math
import time

import numpy as np

from ..errors import SceneError, check_choice
from . import _kernels as kernels
from . import scene as _sc
from .auto import resolve
from .bearing3d import (axial_support, groove_offsets, load_zone_angle, needs_3d, race_contacts, static_3d,
                        track_offset)
# defects.contact_table and contact.CONTACT_MODELS are read at call time: a model registered or a
# table builder replaced at run time counts
from . import defects
from .defects import contact
from ._loopargs import Model
from .hertz import series_stiffness
from .numerics import brentq
from .scene import Scene
from .statics import static_equilibrium, unit_vector


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
    table_time_s: float = 0.0

    @property
    def sensor_index(self) -> int:
        return int(self.p[kernels.P_SENSOFF])

    @property
    def model(self) -> Model:
        """The arrays the compiled right-hand side reads, as its :class:`._loopargs.Model` (the
        same arrays, not copies: the run raises the defect tables' reach in ``dflt``)."""
        return Model(self.p, self.sp_t, self.sp_w, self.sp_th, self.dint, self.dflt, self.hbuf, self.gbuf)


def choose_contact_model(defect, requested: str, bearing) -> str:
    """The defect-contact model for this defect.

    "auto" takes "halfspace" (the elastic half-space, the reference) for every defect.
    The cheaper models were measured against it on the paper's scenes
    (``benchmarks/defect_models.py``; ``benchmarks/README.md``) and none stays within 1 %
    of its peak acceleration there; they cost the same in the time loop (one table lookup),
    and the half-space table costs a few tenths of a second once, then comes from the
    cache.  They stay selectable with ``contact_model = "area"``, ``"drop"`` or
    ``"profile"``.
    """
    if requested and requested != "auto":
        return check_choice(requested, ("auto", *contact.CONTACT_MODELS), "defect.contact_model", SceneError)
    return "halfspace"


def _table_entries(scene: Scene, lz: float):
    """(models, entries): each defect's contact model and its table entries (race code, defect used for
    the table, psi0, ball, model); a ball defect gets one entry per race it meets."""
    d, b = scene.data, scene.bearing
    models = []
    entries = []  # (race code, defect used for the table, psi0, ball, model)
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
    return models, entries


def _table_request(scene, entry, delta_max, material, top, st3d):
    """(defect, keywords) of :func:`contact_table` for one table entry (the defect turned to the 3-D
    contact track when ``st3d`` is given)."""
    code, dfc, psi0, _, model = entry
    if st3d is not None and code < 2:
        dfc, _ = track_offset(dfc, st3d, dfc.race, psi0, scene.bearing)
    # the loaded range above the deepest drop: a ball that falls into the defect is
    # loaded there, and reads computed values, not an extrapolation
    return dfc, dict(model=model, clearance=scene.clearance, delta_max=delta_max, material=material,
                     above_drop=delta_max, delta_top=top)


def _defect_tables(scene: Scene, lz: float, delta_max: float, material, delta_top=None, st3d=None):
    """Each defect's contact table, packed for the kernels: a ball defect gets one table per
    race it meets.  Returns (models, tables, entries, dint, dflt, hbuf, gbuf, table_time_s)."""
    b = scene.bearing
    models, entries = _table_entries(scene, lz)
    tables = []
    n_e = max(len(entries), 1)
    dint = np.zeros((n_e, 7), dtype=np.int64)
    dflt = np.zeros((n_e, kernels.N_DFLT))
    hparts, gparts = [], []
    hoff = goff = 0
    t_tables = time.perf_counter()
    for kk, (code, dfc, psi0, ball, model) in enumerate(entries):
        top = None if delta_top is None else delta_top[kk]
        dfc, kw = _table_request(scene, entries[kk], delta_max, material, top, st3d)
        tab = defects.contact_table(dfc, b, **kw)
        tables.append(tab)
        psi = np.asarray(tab.psi, dtype=float)
        kind = 1 if contact.CONTACT_MODELS[model].tabulated else 0
        h = np.ascontiguousarray(tab.drop, dtype=float)
        # the kernel interpolates G^(2/3) (see _kernels._interp_g)
        G = np.ascontiguousarray(np.maximum(tab.G, 0.0) ** (2.0 / 3.0), dtype=float)
        scale = b.ball_diameter / 2 / tab.track_radius if code >= 2 else 1.0
        dint[kk] = [code, kind, len(psi), G.shape[1], hoff, goff, ball]
        dflt[kk, :7] = [psi0, psi[0], psi[1] - psi[0], tab.delta[1] - tab.delta[0], psi[0], psi[-1], scale]
        hparts.append(h)
        gparts.append(G.ravel() if kind == 1 else np.zeros(0))
        hoff += len(h)
        goff += gparts[-1].size
    table_time = time.perf_counter() - t_tables
    hbuf = np.concatenate(hparts) if hparts else np.zeros(1)
    gbuf = np.concatenate(gparts) if gparts and goff else np.zeros(1)
    return models, tables, entries, dint, dflt, hbuf, gbuf, table_time


def _initial_state(scene: Scene, st, p, fid, dyn, hi, ho, k_eff, m_b, g, omega_c, phi_c0, static_max):
    """The state at t = 0 (rings at the static equilibrium, balls at their static radial
    positions, for the dynamic cage at the kinematic positions and speeds) and the absolute
    tolerances of the error control; sets ``p[P_SENSOFF]``."""
    b, z, sens = scene.bearing, scene.bearing.n_balls, scene.data["sensor"]
    n_ball_states = 0 if fid == "quasi-static" else (5 * z + 2 if dyn else 2 * z)
    n = 8 + n_ball_states + (4 if sens["enabled"] else 0)
    p[kernels.P_SENSOFF] = 8 + n_ball_states
    y0 = np.zeros(n)
    y0[0:2] = st["xi"]
    y0[4:6] = st["xo"]
    xi, xo = st["xi"], st["xo"]
    pd4 = scene.clearance / 4
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
            y0[8 + j] = brentq(gq, lo_q, hi_q, xtol=1e-16, rtol=1e-14, where=f"ball {j} start position")
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
    return y0, atol


def _parameters(scene: Scene, fid, st, hi, ho, k_eff, masses, loads, ftf, phi_c0, n_defects):
    """The kernels' parameter vector (indices ``_kernels.P_*``); also whether the cage is dynamic."""
    d, b, z = scene.data, scene.bearing, scene.bearing.n_balls
    m_i, m_o, m_b = masses
    tstep, f_in2, f_out2, g = loads
    p = np.zeros(kernels.P_SIZE + 2 * z)
    p[kernels.P_Z] = z
    # the balls' angular offsets around the cage (cos, sin), read by the right-hand side
    p[kernels.P_TRIG:kernels.P_TRIG + z] = np.cos(2 * np.pi * np.arange(z) / z)
    p[kernels.P_TRIG + z:kernels.P_TRIG + 2 * z] = np.sin(2 * np.pi * np.arange(z) / z)
    p[kernels.P_RP] = b.pitch_diameter / 2
    p[kernels.P_PD] = scene.clearance
    p[kernels.P_KI], p[kernels.P_KO], p[kernels.P_KEFF] = hi.stiffness, ho.stiffness, k_eff
    p[kernels.P_CMAX] = d["contact"]["damping_n_s_m"]
    p[kernels.P_DPEN] = d["contact"]["penetration_um"] * 1e-6
    p[kernels.P_EXP] = d["contact"]["exponent"]
    p[kernels.P_DRATE] = 1.0 if d["contact"]["defect_damping"] == "penetration_rate" else 0.0
    p[kernels.P_MI], p[kernels.P_MO], p[kernels.P_MB] = m_i, m_o, m_b
    p[kernels.P_KSX], p[kernels.P_KSY] = d["shaft"]["stiffness_x_n_m"], d["shaft"]["stiffness_y_n_m"]
    p[kernels.P_CSX], p[kernels.P_CSY] = d["shaft"]["damping_x_n_s_m"], d["shaft"]["damping_y_n_s_m"]
    p[kernels.P_KMX], p[kernels.P_KMY] = d["mount"]["stiffness_x_n_m"], d["mount"]["stiffness_y_n_m"]
    p[kernels.P_CMX], p[kernels.P_CMY] = d["mount"]["damping_x_n_s_m"], d["mount"]["damping_y_n_s_m"]
    p[kernels.P_XIR], p[kernels.P_YIR] = st["rest_i"]
    p[kernels.P_XOR], p[kernels.P_YOR] = st["rest_o"]
    p[kernels.P_FIX], p[kernels.P_FIY] = st["f_in"]
    p[kernels.P_FOX], p[kernels.P_FOY] = st["f_out"]
    p[kernels.P_TSTEP] = tstep
    p[kernels.P_FIX2], p[kernels.P_FIY2] = f_in2
    p[kernels.P_FOX2], p[kernels.P_FOY2] = f_out2
    p[kernels.P_G] = g
    p[kernels.P_FTF] = ftf
    p[kernels.P_PHI0] = phi_c0
    sens = d["sensor"]
    p[kernels.P_SENS] = 1.0 if sens["enabled"] else 0.0
    p[kernels.P_SW] = 2 * math.pi * sens["frequency_hz"]
    p[kernels.P_SZ] = sens["damping_ratio"]
    p[kernels.P_FID] = 1.0 if fid == "quasi-static" else 0.0
    dyn = d["cage"]["model"] == "dynamic"
    if dyn and fid == "quasi-static":
        raise SceneError("cage.model='dynamic' needs fidelity='multibody' (massless balls have no "
                         "orbital dynamics)")
    p[kernels.P_CAGE] = 1.0 if dyn else 0.0
    cg = d["cage"]
    p[kernels.P_MU] = cg["traction_coefficient"]
    p[kernels.P_VREF] = cg["traction_slip_m_s"]
    p[kernels.P_KPOCK] = cg["pocket_stiffness_n_m"]
    p[kernels.P_CPOCK] = cg["pocket_clearance_mm"] * 1e-3
    p[kernels.P_DPOCK] = cg["pocket_damping_n_s_m"]
    m_cage = cg["mass_kg"] or 0.15 * z * m_b
    p[kernels.P_IC] = m_cage * (b.pitch_diameter / 2) ** 2
    p[kernels.P_RB] = b.ball_diameter / 2
    p[kernels.P_CDRAG] = cg["drag_n_m_s"]
    p[kernels.P_UNB] = d["shaft"]["unbalance_g_mm"] * 1e-6
    p[kernels.P_IB] = 0.4 * m_b * (b.ball_diameter / 2) ** 2
    p[kernels.P_NDEF] = n_defects
    p[kernels.P_SPIN] = b.frequency_factors()["bsf"]
    if "zi" in st:
        a_i, a_o = groove_offsets(b)
        p[kernels.P_3D] = 1.0
        p[kernels.P_AGI], p[kernels.P_AGO] = a_i, a_o
        p[kernels.P_KZI], p[kernels.P_CZI] = axial_support(d["shaft"])
        p[kernels.P_KZO], p[kernels.P_CZO] = axial_support(d["mount"])
        p[kernels.P_ZIR], p[kernels.P_ZOR] = st["rest_zi"], st["rest_zo"]
        p[kernels.P_FIZ], p[kernels.P_FOZ] = st["f_inz"], st["f_outz"]
        p[kernels.P_ZSET] = _sc.SETTLE_AXIAL_RATE
        p[kernels.P_TZSET] = max(scene.settle - _sc.SETTLE_FREE_S, 0.0)
    return p, dyn


def _axial_states(scene, st, p, fid, y0, atol):
    """The 3-D bearing's extra states after the planar ones: zi, zo, their rates, then (multibody)
    each ball's axial position and rate; the balls' radial positions from the 3-D equilibrium."""
    z = scene.bearing.n_balls
    zb = y0.size
    p[kernels.P_ZOFF] = zb
    extra = 4 + (2 * z if fid != "quasi-static" else 0)
    y = np.concatenate([y0, np.zeros(extra)])
    a = np.concatenate([atol, np.zeros(extra)])
    y[zb], y[zb + 1] = st["zi"], st["zo"]
    x_scale, v_scale = atol[0], atol[2]
    a[zb:zb + 2] = x_scale
    a[zb + 2:zb + 4] = v_scale
    if fid != "quasi-static":
        y[8:8 + z] = st["q"]
        y[zb + 4:zb + 4 + z] = st["w"]
        a[zb + 4:zb + 4 + z] = x_scale
        a[zb + 4 + z:zb + 4 + 2 * z] = v_scale
    return y, a


def scene_statics(scene: Scene, fidelity=None):
    """(fidelity, inner and outer Hertz contacts, static equilibrium, 3-D or not) of a scene."""
    d, b = scene.data, scene.bearing
    fid = fidelity or scene.fidelity
    if fid == "auto":
        fid = resolve(scene)["fidelity"]
    hi, ho = race_contacts(scene)
    m_b = scene.masses()[2]
    # cage angle at t = 0: a ball centred in the load zone (the symmetric start)
    phi_c0 = load_zone_angle(scene)
    _, rpm0 = scene.speed_profile()
    omega_c0 = b.frequency_factors()["ftf"] * rpm0[0] * 2 * math.pi / 60
    three_d = needs_3d(scene)
    if three_d:
        if d["cage"]["model"] == "dynamic":
            ld = d["load"]
            key = (f"load.axial_n={ld['axial_n']:g}" if ld["axial_n"] else
                   f"load.axial_preload_um={ld['axial_preload_um']:g}")
            raise SceneError(f"{key} with cage.model='dynamic': the 3-D bearing runs with the kinematic cage "
                             "only (its balls' traction and pocket forces are planar). Set cage.model = "
                             "'kinematic' to keep the axial load, or remove the axial load to run the dynamic "
                             "cage in the planar bearing")
        st = static_3d(scene, fid)
    else:
        st = static_equilibrium(scene, phi_c0, hi.stiffness, ho.stiffness,
                                ball_mass=0.0 if fid == "quasi-static" else m_b, omega_cage=omega_c0,
                                exponent=d["contact"]["exponent"])
    return fid, hi, ho, st, three_d


def _table_delta_max(st, ho) -> float:
    """The defect tables' loaded approach range: 3 x the most loaded ball's static deflection."""
    static_max = float(np.max(st["ball_loads"])) if len(st["ball_loads"]) else 0.0
    return max(3.0 * (max(static_max, 50.0) / ho.stiffness) ** (2 / 3), 5e-6)


def table_requests(scene: Scene, *, statics=None) -> list:
    """The contact tables the scene's defects need, without building any: ``[(defect, keywords)]`` as
    :func:`bearing_lab.sim.defects.contact_table` takes them (a cost estimate counts those not cached).
    ``statics``: :func:`scene_statics` of a scene with the same bearing, load and speed, to reuse."""
    _, hi, ho, st, three_d = statics or scene_statics(scene)
    mat = scene.data["material"]
    material = (mat["youngs_modulus_gpa"] * 1e9, mat["poisson_ratio"])
    _, entries = _table_entries(scene, load_zone_angle(scene))
    return [_table_request(scene, e, _table_delta_max(st, ho), material, None, st if three_d else None)
            for e in entries]


def assemble(scene: Scene, *, fidelity: str | None = None, delta_top=None) -> Assembly:
    """The scene's parameters, tables and initial state for the time loop.

    ``delta_top``: per defect-table entry, a lower bound of the table's top approach (m), for a
    re-run after the loop reached above a table."""
    d = scene.data
    b = scene.bearing
    fid, hi, ho, st, three_d = scene_statics(scene, fidelity)
    z = b.n_balls
    mat = d["material"]
    E, nu = mat["youngs_modulus_gpa"] * 1e9, mat["poisson_ratio"]
    k_eff = series_stiffness(hi.stiffness, ho.stiffness)
    m_i, m_o, m_b = scene.masses()
    ftf = b.frequency_factors()["ftf"]
    lz = load_zone_angle(scene)
    # cage angle at t = 0: a ball centred in the load zone (the symmetric start)
    phi_c0 = lz

    # speed profile (rad/s), shaft angle at the nodes
    sp_t, rpm = scene.speed_profile()
    sp_w = rpm * 2 * math.pi / 60
    sp_th = np.zeros_like(sp_t)
    if len(sp_t) > 1:
        sp_th[1:] = np.cumsum(0.5 * (sp_w[1:] + sp_w[:-1]) * np.diff(sp_t))
    # shaft angle is measured from t = 0: shift so that theta(0) = 0
    # (the kernel's Python source: one call does not pay for compiling or loading it)
    th0, _ = kernels.shaft_state.py_func(0.0, sp_t, sp_w, sp_th)
    sp_th = sp_th - th0

    # loads and their optional step
    g = d["gravity"]["g_m_s2"] if d["gravity"]["enabled"] else 0.0
    tstep = math.inf
    f_in2, f_out2 = st["f_in"], st["f_out"]
    if d["load"]["step_time_s"] is not None:
        if d["load"]["step_radial_n"] is None:
            raise SceneError("load.step_time_s needs load.step_radial_n")
        tstep = scene.settle + d["load"]["step_time_s"]
        new = d["load"]["step_radial_n"] * unit_vector(math.radians(d["load"]["direction_deg"]))
        old = st["load_vec"]
        if d["load"]["on"] == "inner":
            f_in2 = st["f_in"] - old + new
        else:
            f_out2 = st["f_out"] - old + new

    # defects -> tables (a ball defect gets one table per race it meets)
    static_max = float(np.max(st["ball_loads"])) if len(st["ball_loads"]) else 0.0
    models, tables, entries, dint, dflt, hbuf, gbuf, table_time = _defect_tables(
        scene, lz, _table_delta_max(st, ho), (E, nu), delta_top, st if three_d else None)

    p, dyn = _parameters(scene, fid, st, hi, ho, k_eff, (m_i, m_o, m_b), (tstep, f_in2, f_out2, g),
                         ftf, phi_c0, len(entries))
    y0, atol = _initial_state(scene, st, p, fid, dyn, hi, ho, k_eff, m_b, g, ftf * sp_w[0], phi_c0,
                              static_max)
    if three_d:
        y0, atol = _axial_states(scene, st, p, fid, y0, atol)
    return Assembly(scene, p, np.ascontiguousarray(sp_t, dtype=float), np.ascontiguousarray(sp_w),
                    np.ascontiguousarray(sp_th), dint, dflt, hbuf, gbuf, y0, atol, z, fid,
                    tuple(models), tuple(tables), st, lz, hi, ho, table_time)
