"""Error and cost of the cheaper defect-contact models against the elastic half-space.

Run:  .venv/bin/python benchmarks/defect_models.py [duration_s]

For each scene (the paper's defects, a ball and an inner-race defect) every contact model
("halfspace", the default and reference; "area", local law; "drop", rigid 2-D drop;
"profile", along-track slot) runs the same record as a user runs it (``simulate`` with
the scene's defaults: fidelity and solver "auto", 20 kHz output, 1 s by default).
Reported: the table's cold build CPU time (one core), the time loop's CPU seconds per
simulated second, the peak acceleration (max |a| of the record) and the excitation period
(squared-envelope line family), and each cheaper model's error against "halfspace".  The
tolerance that ``contact_model = "auto"`` applies: 1 % in peak acceleration and 0.1 % in
period.
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from bearing_lab.analysis import excitation_period
from bearing_lab.sim import load_scene, simulate
from bearing_lab.sim.assembly import assemble
from bearing_lab.sim.defects import contact_table
from bearing_lab.sim.defects._halfspace_kernels import warm_up
from bearing_lab.sim.integrate import _warm_up

MODELS = ("halfspace", "area", "drop", "profile")
CASES = [
    ("paper-slot", {}),
    ("paper-O1", {}),
    ("paper-O1", {"defect.offset_mm": 1 / 3}),
    ("paper-O1", {"defect.offset_mm": 0.5}),
    ("paper-O2", {}),
    ("paper-O2", {"defect.skew_deg": 30.0}),
    ("paper-O2", {"defect.skew_deg": 60.0}),
    ("paper-O3", {}),
    ("paper-O1", {"defect.race": "inner"}),
    ("paper-O1", {"defect.race": "ball"}),
    ("cwru-or007-6", {}),
    ("cwru-or021-6", {}),
    ("cwru-ir007", {}),
]
TOL_PEAK, TOL_PERIOD = 0.01, 0.001


def _scene(name, ov, model, duration):
    sc = load_scene(name, **ov, **{"output.duration_s": duration})
    raw = dict(sc.data)
    raw["defect"] = [dict(d, contact_model=model) for d in raw["defect"]]
    return load_scene(raw)


def _table_cpu(sc):
    """Cold CPU time of the scene's tables (cache off), one core; a ball defect has one
    table per race, built on the race's contact plane as the simulator does."""
    import dataclasses
    from bearing_lab.sim.defects import contact as C
    asm = assemble(sc)
    tables = iter(asm.tables)
    C._MEMORY.clear()
    c = time.process_time()
    for d in sc.defects:
        races = ("outer", "inner") if d.race == "ball" else (d.race,)
        for race in races:
            t = next(tables)
            loaded = t.info["loaded_range_m"]   # the table reaches the deepest drop + this
            contact_table(dataclasses.replace(d, race=race), sc.bearing, model=t.model,
                          clearance=sc.clearance, delta_max=loaded, above_drop=loaded, cache=False)
    return time.process_time() - c


def _period(ds, sc):
    b = sc.bearing
    f = b.fault_frequencies(sc.nominal_rpm / 60)
    race = sc.defects[0].race
    fexp = f["bpfi"] if race == "inner" else (2 * f["bsf"] if race == "ball" else f["bpfo"])
    try:
        return excitation_period(ds.outer_ring_acc_y.values, ds.attrs["sampling_rate_hz"],
                                 frequency_range=(0.9 * fexp, 1.1 * fexp))[0]
    except Exception:           # no line family: reported as NaN
        return math.nan


def run(name, ov, model, duration):
    sc = _scene(name, ov, model, duration)
    build = _table_cpu(sc)
    c = time.process_time()
    ds = simulate(sc, progress=False)
    loop = (time.process_time() - c - ds.attrs["table_time_s"]) / duration
    a = ds.outer_ring_acc_y.values
    return {"build": build, "loop": loop, "peak": float(np.max(np.abs(a))), "period": _period(ds, sc)}


def main(duration=1.0):
    warm_up()
    _warm_up()
    simulate("paper-O1", duration=0.05, progress=False)   # a process's first call pays one-time setup
    print("| scene | model | table build CPU s | loop CPU s / sim s | peak acc (g) | error | period (ms) | error | within tolerance |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, ov in CASES:
        out = {m: run(name, ov, m, duration) for m in MODELS}
        ref = out["halfspace"]
        label = name + "".join(f" {k.split('.')[-1]}={v:.3g}" if isinstance(v, float) else f" {k.split('.')[-1]}={v}"
                               for k, v in ov.items())
        for m, r in out.items():
            ep = (r["peak"] - ref["peak"]) / ref["peak"]
            et = (r["period"] - ref["period"]) / ref["period"]
            ok = "reference" if m == "halfspace" else ("yes" if abs(ep) <= TOL_PEAK and abs(et) <= TOL_PERIOD else "no")
            print(f"| {label} | {m} | {r['build']:.3f} | {r['loop']:.3f} | {r['peak'] / 9.80665:.2f} | {ep:+.1%} "
                  f"| {r['period'] * 1e3:.4f} | {et:+.2e} | {ok} |", flush=True)


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 1.0)
