"""The scene keys: every section and key of a scene, its default, type, check and meaning.

``SCHEMA[section][key] = (default, type, check, doc)``; ``check`` is "pos", "nonneg", "any",
"frac", a tuple of allowed strings, or None.  :mod:`.scene` validates scenes against this table;
the defaults where the paper is silent are explained in the :mod:`.scene` docstring.
"""
from __future__ import annotations

from ..units import G

STEEL_DENSITY = 7850.0    # kg/m^3, AISI 52100
# section -> key -> (default, type, check, doc).  check: "pos", "nonneg", "any", "frac",
# a tuple of allowed strings, or None.
_NUM = (int, float)
SCHEMA: dict[str, dict[str, tuple]] = {
    "": {
        "name": ("custom", str, None, "scene name"),
        "description": ("", str, None, "one line shown by `bearing-lab scenes`"),
        "bearing": ("6308", str, None, "catalog bearing (6308, 6205, 6203) or see [bearing_geometry]"),
        "fidelity": ("auto", str, ("multibody", "quasi-static", "auto"),
                     "multibody: each ball a body with radial inertia; quasi-static: massless balls; "
                     "auto: the cheapest measured within half of the 1 % peak acceleration it promises (sim/auto.py)"),
    },
    "bearing_geometry": {
        "n_balls": (None, int, "pos", "override Z"),
        "ball_diameter_mm": (None, _NUM, "pos", "override D_b"),
        "pitch_diameter_mm": (None, _NUM, "pos", "override d_m"),
        "bore_mm": (None, _NUM, "pos", "override bore"),
        "outer_diameter_mm": (None, _NUM, "pos", "override outer diameter"),
        "width_mm": (None, _NUM, "pos", "override ring width"),
        "inner_conformity": (None, _NUM, "pos", "groove radius / D_b, inner (default 0.52)"),
        "outer_conformity": (None, _NUM, "pos", "groove radius / D_b, outer (default 0.53)"),
    },
    "material": {
        "youngs_modulus_gpa": (208.0, _NUM, "pos", "E of balls and rings (52100 steel)"),
        "poisson_ratio": (0.3, _NUM, "frac", "nu"),
        "density_kg_m3": (STEEL_DENSITY, _NUM, "pos", "steel density"),
    },
    "clearance": {
        "radial_um": (0.0, _NUM, "any", "radial internal clearance P_d (total radial play); negative = preload"),
    },
    "mass": {
        "inner_ring_kg": (None, _NUM, "pos", "default: steel ring from bore to inner raceway shoulder"),
        "outer_ring_kg": (None, _NUM, "pos", "default: steel ring from outer raceway shoulder to OD"),
        "ball_kg": (None, _NUM, "pos", "default: steel sphere of D_b"),
    },
    "shaft": {
        "stiffness_x_n_m": (1e8, _NUM, "pos", "inner ring to ground, X"),
        "stiffness_y_n_m": (1e8, _NUM, "pos", "inner ring to ground, Y"),
        "damping_x_n_s_m": (1e3, _NUM, "nonneg", "inner ring to ground, X"),
        "damping_y_n_s_m": (1e3, _NUM, "nonneg", "inner ring to ground, Y"),
        "stiffness_z_n_m": (None, _NUM, "pos", "inner ring to ground along the axis (3-D bearing only); "
                            "default: the Y value"),
        "damping_z_n_s_m": (None, _NUM, "nonneg", "inner ring to ground along the axis; default: the Y value"),
        "unbalance_g_mm": (130.0, _NUM, "nonneg",
                           "residual unbalance U = m e turning with the shaft (a force U omega^2 on the inner "
                           "ring): 130 g mm is ISO 21940-11 grade G2.5 for a 10 kg rotor share at 1800 r/min "
                           "(4.6 N); it gives the shaft-frequency line every rig shows, and BPFI sidebands"),
    },
    "mount": {
        "stiffness_x_n_m": (1e8, _NUM, "pos", "outer-ring bushing to ground, X"),
        "stiffness_y_n_m": (1e8, _NUM, "pos", "outer-ring bushing to ground, Y"),
        "damping_x_n_s_m": (1e3, _NUM, "nonneg", "outer-ring bushing, X"),
        "damping_y_n_s_m": (1e3, _NUM, "nonneg", "outer-ring bushing, Y"),
        "stiffness_z_n_m": (None, _NUM, "pos", "outer-ring bushing along the axis (3-D bearing only); "
                            "default: the Y value"),
        "damping_z_n_s_m": (None, _NUM, "nonneg", "outer-ring bushing along the axis; default: the Y value"),
    },
    "speed": {
        "rpm": (1800.0, _NUM, "nonneg", "constant shaft (inner ring) speed"),
        "profile": (None, list, None, "[[t_s, rpm], ...] piecewise-linear speed; overrides rpm"),
    },
    "load": {
        "radial_n": (150.0, _NUM, "nonneg", "radial load magnitude"),
        "axial_n": (0.0, _NUM, "any", "constant axial force on the loaded ring, N, along +Z (a thrust or a "
                    "spring preload); non-zero runs the 3-D bearing (contact angles, axial ring motion)"),
        "axial_preload_um": (None, _NUM, "nonneg", "displacement preload instead of a force: the loaded ring pushed "
                             "along +Z relative to the other by this much beyond the point where the axial play "
                             "is taken up (the balls just touching both grooves); the start solves for the axial "
                             "force it takes, held by the axial supports (docs/model.md); at most the 0.5 % of "
                             "D_b normal approach the clearance check allows; not together with axial_n; 0 = none"),
        "direction_deg": (270.0, _NUM, "any", "direction of the force on the ring (270 = -Y, downward)"),
        "on": ("outer", str, ("inner", "outer"), "ring the load is applied to"),
        "path": ("bearing", str, ("bearing", "springs"), "see module docs: who carries the static load"),
        "step_time_s": (None, _NUM, "nonneg", "optional load step: time (from the record start)"),
        "step_radial_n": (None, _NUM, "nonneg", "optional load step: new magnitude"),
    },
    "gravity": {
        "enabled": (True, bool, None, "ring and ball weights along -Y"),
        "g_m_s2": (G, _NUM, "nonneg", "standard gravity"),
    },
    "contact": {
        "damping_n_s_m": (350.0, _NUM, "nonneg", "IMPACT c_max (paper: 350 N s/m)"),
        "penetration_um": (1.0, _NUM, "pos", "IMPACT d: penetration at which full damping applies"),
        "exponent": (1.5, _NUM, "pos", "IMPACT exponent e (Hertz point contact: 1.5)"),
        "defect_damping": ("approach", str, ("approach", "penetration_rate"),
                           "rate the IMPACT damping multiplies over a defect: approach = the bodies' "
                           "approach rate (as Adams' IMPACT); penetration_rate = the rate of the defect "
                           "law's equivalent penetration, which adds its change as the ball rolls over "
                           "the outline (docs/contact-model.md)"),
    },
    "cage": {
        "model": ("kinematic", str, ("kinematic", "dynamic"),
                  "kinematic: balls spaced at the cage speed (FTF); dynamic: cage and ball orbital/spin "
                  "motion from traction and pocket contact (slip possible)"),
        "mass_kg": (None, _NUM, "pos", "cage mass (default: 15 % of the balls' mass, a pressed-steel cage)"),
        "pocket_clearance_mm": (0.15, _NUM, "nonneg", "circumferential ball-pocket play, each side"),
        "pocket_stiffness_n_m": (1e7, _NUM, "pos", "ball-pocket contact stiffness (steel cage web)"),
        "pocket_damping_n_s_m": (20.0, _NUM, "nonneg", "ball-pocket contact damping"),
        "traction_coefficient": (0.08, _NUM, "pos", "ball-race traction coefficient at full slip (EHL: 0.05-0.1)"),
        "traction_slip_m_s": (0.05, _NUM, "pos", "slip speed at which traction saturates (regularised Coulomb)"),
        "drag_n_m_s": (1e-5, _NUM, "nonneg", "viscous drag on the cage (torque / angular speed): ~1e-3 N m at a "
                       "6308's cage speed at 1800 r/min, the order of a lubricated cage's churning loss"),
    },
    "sensor": {
        "enabled": (False, bool, None, "accelerometer/housing resonator between outer ring and sensor"),
        "frequency_hz": (5000.0, _NUM, "pos", "resonance frequency"),
        "damping_ratio": (0.05, _NUM, "pos", "resonance damping ratio"),
        "gain": (1.0, _NUM, "pos", "sensor gain"),
    },
    "output": {
        "duration_s": (1.0, _NUM, "pos", "recorded duration"),
        "sample_rate_hz": (20000.0, _NUM, "pos", "output rate (as the DAQ: anti-alias filtered)"),
        "settle_s": (0.02, _NUM, "nonneg", "simulated and discarded before the record starts (the 3-D bearing: "
                     "at least 0.03 s, its balls' axial motion damped until 0.01 s before the record; "
                     "docs/model.md)"),
        "oversample": (8, int, "pos", "internal fine grid = oversample x sample_rate before the anti-alias FIR"),
        "ball_loads": (True, bool, None, "store per-ball contact loads"),
    },
    "solver": {
        "method": ("auto", str, ("auto", "dp54", "bs32", "rk4"),
                   "dp54/bs32: adaptive embedded RK; rk4: fixed step; auto: from the measured rules"),
        "rtol": (None, _NUM, "pos", "relative tolerance of the adaptive methods (default: the rule's, or 1e-5)"),
        "step_s": (2e-6, _NUM, "pos", "fixed step (rk4)"),
        "max_step_s": (None, _NUM, "pos", "largest step of the adaptive methods (default: the rule's, or 25 µs)"),
        "defect_steps": (40, int, "pos", "at least this many steps while a ball crosses a defect"),
    },
    "budget": {
        "max_steps": (5e8, _NUM, "pos", "refuse a scene that needs more integration steps (estimated "
                      "before it runs, see sim/budget.py): ~20 min of computing"),
        "max_fine_samples": (1e9, _NUM, "pos", "refuse more samples on the anti-aliasing grid"),
        "max_memory_mb": (4000.0, _NUM, "pos", "refuse a scene whose output needs more memory, MB"),
    },
}
DEFECT_KEYS = {"race", "shape", "length_mm", "width_mm", "depth_mm", "offset_mm", "skew_deg",
               "angle_deg", "vertices_mm", "diameter_mm", "contact_model"}

#: the keys of one ``[[defect]]`` table: default and meaning (validated by the defect model)
DEFECT_DOCS = {
    "race": ("outer", "'outer', 'inner' or 'ball'"),
    "shape": ("rectangle", "'rectangle', 'ellipse' or 'polygon'"),
    "length_mm": (None, "extent along the track (required unless polygon or diameter_mm)"),
    "width_mm": (None, "extent across the track (required unless polygon or diameter_mm)"),
    "diameter_mm": (None, "a circular ellipse: sets length and width"),
    "depth_mm": (0.5, "depth below the intact surface"),
    "offset_mm": (0.0, "axial offset H of the centre from the raceway centre line"),
    "skew_deg": (0.0, "rotation of the outline on the raceway"),
    "angle_deg": (0.0, "position around the ring, from the load-zone centre"),
    "vertices_mm": (None, "polygon: [[along, across], ...] about the centre"),
    "contact_model": ("auto", "'auto', or a defect-contact model (sim/defects/contact.py CONTACT_MODELS)"),
}


def _cell(v) -> str:
    if v is None:
        return "—"
    if v == "":
        return '`""`'
    if isinstance(v, (list, tuple)):
        return ", ".join(f"`{x}`" for x in v)
    return f"`{v}`"


def keys_markdown() -> str:
    """docs/scene-keys.md: every scene key with its default, check and meaning."""
    checks = {"pos": "> 0", "nonneg": ">= 0", "frac": "in [0, 0.5)", "any": "any number", None: ""}
    out = ["# Scene keys", "",
           "Every key a scene (TOML file, dict or `--set KEY=VALUE`) accepts, with its default, the",
           "check applied when the scene loads, and its meaning. Keys carry their unit in the name; a",
           "value may also be a string with a unit (`\"1 mm\"`, `\"1800 rpm\"`). Generated from",
           "`bearing_lab/sim/scene_keys.py` (the test suite keeps this page in step with it).", ""]
    for sec, keys in SCHEMA.items():
        out += [f"## {'top level' if sec == '' else '[' + sec + ']'}", "",
                "| key | default | allowed | meaning |", "|---|---|---|---|"]
        for k, (default, _typ, check, doc) in keys.items():
            allowed = _cell(check) if isinstance(check, tuple) else checks.get(check, "")
            out.append(f"| `{k}` | {_cell(default)} | {allowed} | {doc.replace('|', '/')} |")
        out.append("")
    out += ["## [[defect]] (one table per defect; none: a healthy bearing)", "",
            "| key | default | meaning |", "|---|---|---|"]
    out += [f"| `{k}` | {_cell(d)} | {doc} |" for k, (d, doc) in DEFECT_DOCS.items()]
    return "\n".join(out) + "\n"
