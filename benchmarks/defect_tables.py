"""Defect contact tables on the paper's defects: build times and what each model predicts.

Run:  .venv/bin/python benchmarks/defect_tables.py [--no-halfspace]

Prints (markdown):
1. the rigid drops against reference.md;
2. per defect and contact model: table build time, the share of the intact load carried
   at the most defected position (minimum over psi of G / delta^1.5) at the ball approach
   delta = 8 µm (the most loaded ball of the 6308 at 480 N), and the stretch of track over
   which more than 1 % of the load is lost;
3. the local law against the elastic half-space (``halfspace.compare_local_law``).
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from bearing_lab.bearings import get_bearing
from bearing_lab.sim.defects import Defect, rigid_drop
from bearing_lab.sim.defects.contact import _build
from bearing_lab.sim.defects.halfspace import compare_local_law

B = get_bearing("6308")
DELTA = 8e-6
DMAX = 25e-6

REFERENCE = [("1x1 H=0", 1, 1, 0, 0, 0.9413), ("1x1 H=B/3", 1, 1, 1 / 3, 0, 0.1043),
             ("1x1 H=B/2", 1, 1, 0.5, 0, 0.0), ("3x1", 3, 1, 0, 0, 0.9413),
             ("6x1", 6, 1, 0, 0, 0.9413), ("3x1 30deg", 3, 1, 0, 30, 1.2275),
             ("3x1 60deg", 3, 1, 0, 60, 3.1287), ("slot 1x23", 1, 23, 0, 0, 13.473)]

SCENES = [("O1 1x1", 1, 1, 0, 0), ("O1 H=B/3", 1, 1, 1 / 3, 0), ("O1 H=B/2", 1, 1, 0.5, 0),
          ("O2 1x3", 3, 1, 0, 0), ("O2 30deg", 3, 1, 0, 30), ("O2 60deg", 3, 1, 0, 60),
          ("O3 1x6", 6, 1, 0, 0), ("slot 1x23", 1, 23, 0, 0)]


def _defect(L, Bw, hf, th, race="outer"):
    return Defect(race=race, length=L * 1e-3, width=Bw * 1e-3, offset=hf * Bw * 1e-3,
                  skew=math.radians(th))


def main(halfspace: bool = True) -> None:
    print("## Rigid drop (µm), 6308 outer race, 0.5 mm deep\n")
    print("| defect | this code | reference.md | error |\n|---|---|---|---|")
    for name, L, Bw, hf, th, ref in REFERENCE:
        v = rigid_drop(_defect(L, Bw, hf, th), B) * 1e6
        print(f"| {name} | {v:.4f} | {ref} | {v - ref:+.4f} |")

    models = ["profile", "drop", "area"] + (["halfspace"] if halfspace else [])
    for race in ("outer", "inner"):
        print(f"\n## {race} race: carried share min_psi G/delta^1.5 at delta = {DELTA*1e6:g} µm, "
              f"loss > 1 % over s (mm); build time (s); delta_max = {DMAX*1e6:g} µm\n")
        print("| defect | " + " | ".join(models) + " |\n" + "|---" * (len(models) + 1) + "|")
        for name, L, Bw, hf, th in SCENES:
            d = _defect(L, Bw, hf, th, race)
            cells = []
            for model in models:
                T = _build(d, B, model=model, clearance=0.0, delta_max=DMAX, n_psi=None, n_delta=51)
                k = int(np.argmin(np.abs(T.delta - DELTA)))
                r = T.G[:, k] / T.delta[k] ** 1.5
                lost = T.psi[r < 0.99] * T.track_radius
                span = float(np.ptp(lost)) * 1e3 if lost.size else 0.0
                cells.append(f"{r.min():.3f}, {span:.2f} mm ({T.info['build_time_s']:.2f} s)")
            print(f"| {name} | " + " | ".join(cells) + " |")

    if halfspace:
        print("\n## Local law vs elastic half-space, centred 1x1 mm (share of intact load)\n")
        for load in (300.0, 3.27e10 * DELTA ** 1.5):
            t = time.perf_counter()
            r = compare_local_law(load=load, s_positions=(0.0, 0.3e-3, 0.5e-3, 0.6e-3, 0.7e-3))
            print(f"approach {r['approach']*1e6:.3f} µm: intact half-space force "
                  f"{r['intact_force']:.2f} N (Hertz {load:.1f} N), semi-axes "
                  f"{r['a']*1e3:.4f} x {r['b']*1e3:.4f} mm ({time.perf_counter() - t:.1f} s)\n")
            print("| s (mm) | local law | half-space |\n|---|---|---|")
            for p in r["positions"]:
                print(f"| {p['s']*1e3:.1f} | {p['local_law']:.3f} | {p['halfspace']:.3f} |")
            print()


if __name__ == "__main__":
    main(halfspace="--no-halfspace" not in sys.argv)
