"""``fidelity = "auto"`` and ``solver.method = "auto"``: model only what the scene needs.

The rules come from the work-precision study (``bearing-lab bench``, which writes
``reports/performance/auto_rules.toml``; the copy shipped here is the one measured for
this release).  Each rule is the cheapest (fidelity, method, tolerance, step ceiling)
that stayed within 1 % peak-acceleration and 0.1 % period error against a converged
reference on EVERY bench scene of its kind:

- ``healthy``: no defect, or every defect misses the ball track (no defect geometry is
  built then);
- ``defect-slow``: a defect at shaft speeds up to the slow bench scene's (300 r/min);
- ``defect``: any other defect.

A kind may carry rules by output rate (``[[defect.by_rate]]``, from the rate study of
``bearing-lab bench``, ``auto_rate_study.csv``): a higher output rate resolves a sharper
impulse peak, which needs a more accurate integration, so the rule measured at the lowest
studied rate at or above the scene's output rate is used (a 50 kHz scene takes the 100 kHz
rule); above the highest studied rate the highest one is used and the reason says it was not
measured there.  Kinds without rate rules were measured at 20 kHz output.

The choice and its expected error go into the output's attributes.  Without a rule
for a kind the conservative default is used (multibody, dp54, rtol 1e-5).
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path
import tomllib

RULES_FILE = Path(__file__).with_name("auto_rules.toml")
DEFAULT = {"fidelity": "multibody", "method": "dp54", "rtol": 1e-5, "max_step_s": 2.5e-5,
           "expected_peak_error": None}
SLOW_RPM = 300.0


@lru_cache(maxsize=1)
def load_rules() -> dict:
    if not RULES_FILE.is_file():
        return {}
    with open(RULES_FILE, "rb") as fh:
        return tomllib.load(fh)


MISS_DELTA = 20e-6  # an approach no bench scene reaches: beyond it a defect cannot be touched


def scene_kind(scene) -> str:
    if all(d.misses_track(scene.bearing, MISS_DELTA, clearance=scene.clearance) for d in scene.defects):
        return "healthy"
    return "defect-slow" if scene.nominal_rpm <= SLOW_RPM else "defect"


def rate_rule(rule: dict, fs: float) -> tuple[dict, str]:
    """(the rule for output rate ``fs`` Hz, how it was chosen) from a kind's rule and its
    ``by_rate`` bands; the kind's rule itself when it has none."""
    bands = sorted(rule.get("by_rate", ()), key=lambda b: b["max_rate_hz"])
    if not bands:
        return rule, "measured at 20 kHz output"
    for b in bands:
        if fs <= b["max_rate_hz"] * (1 + 1e-9):
            return b, f"measured at {b['max_rate_hz'] / 1e3:g} kHz output (rule for up to it)"
    b = bands[-1]
    return b, (f"measured at up to {b['max_rate_hz'] / 1e3:g} kHz output only: the {fs / 1e3:g} kHz asked for "
               "was not studied")


def resolve(scene) -> dict:
    """The settings auto picks for ``scene``: fidelity, method, rtol, max_step_s, kind, reason."""
    kind = scene_kind(scene)
    rules = load_rules()
    rule = rules.get(kind) or (rules.get("defect") if kind == "defect-slow" else None)
    out = dict(DEFAULT)
    if rule:
        rule, how = rate_rule(rule, float(scene.fs_out))
        out.update({k: rule[k] for k in ("fidelity", "method", "rtol", "max_step_s", "step_s") if k in rule})
        out["expected_peak_error"] = rule.get("expected_peak_error")
        out["reason"] = (f"auto rule '{kind}' from the work-precision study: cheapest setting within 1 % "
                         f"peak acceleration and 0.1 % period on {rule.get('scenes')}, {how}")
    else:
        out["reason"] = f"no measured rule for '{kind}': conservative default"
    out["kind"] = kind
    return out
