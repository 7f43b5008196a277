"""Cost and error of each defect-contact model on the paper's scenes.

Run:  .venv/bin/python benchmarks/defect_models.py

For each scene the three contact models ("profile": along-track 1-D, "drop": rigid
2-D drop, "area": 2-D with loss of contact area) run the same 0.5 s multibody
simulation (dp54, rtol 1e-5).  Reported: compute seconds per simulated second of the
time loop (table build excluded, measured separately), and the peak-acceleration and
peak-displacement-deviation error of each cheaper model against "area" (the model
that is exact for the scene's geometry; "profile" is exact for a full-width slot, where
all three coincide).
"""
from __future__ import annotations

import time

import numpy as np

from bearing_lab.sim import load_scene
from bearing_lab.sim.assembly import assemble
from bearing_lab.sim.integrate import METHODS, _run, _warm_up

CASES = [
    ("paper-slot", {}),
    ("paper-O1", {}),
    ("paper-O1", {"defect.offset_mm": 1 / 3}),
    ("paper-O1", {"defect.offset_mm": 0.5}),
    ("paper-O2", {"defect.skew_deg": 60.0}),
    ("paper-O3", {}),
]


def run(scene, model, duration):
    raw = dict(scene.data)
    raw["defect"] = [dict(d, contact_model=model) for d in raw["defect"]]
    sc = load_scene(raw, **{"output.duration_s": duration})
    t0 = time.perf_counter()
    asm = assemble(sc)
    build = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = _run(asm, METHODS["dp54"], 1e-5, progress=False)
    loop = time.perf_counter() - t0
    acc = res["acc"][:, 1]
    disp = res["disp"][:, 3]
    return loop / res["t_end"], build, np.abs(acc).max(), np.abs(disp - np.median(disp)).max()


def main(duration=0.5):
    _warm_up()
    print("| scene | model | loop s / simulated s | table build s | peak acc (g) | error vs area | peak disp dev (µm) | error vs area |")
    print("|---|---|---|---|---|---|---|---|")
    for name, ov in CASES:
        sc = load_scene(name, **ov)
        out = {m: run(sc, m, duration) for m in ("area", "drop", "profile")}
        a_ref, d_ref = out["area"][2], out["area"][3]
        label = name + "".join(f" {k.split('.')[-1]}={v:.3g}" for k, v in ov.items())
        for m, (cost, build, a, dd) in out.items():
            print(f"| {label} | {m} | {cost:.4f} | {build:.3f} | {a / 9.80665:.2f} | {(a - a_ref) / a_ref:+.1%} "
                  f"| {dd * 1e6:.4f} | {(dd - d_ref) / d_ref:+.1%} |", flush=True)


if __name__ == "__main__":
    main()
