"""What an identification's scenes cost: the figures ``bearing-lab identify`` estimates its CPU time from.

Run:  .venv/bin/python benchmarks/identify_cost.py [--repeat N]

On paper-O2 (the stand-in rig of docs/identification.md: 6308, 320 N, 1793 r/min) at the comparison's
rtol 1e-6 and 20 kHz, in one process (numba compiled first, its time printed apart), with an empty
table cache of its own:

1. CPU time (``time.process_time``) of a cold contact table as the simulation builds it: an outline with
   sides along and across the track (θ = 0) and skewed ones (θ = 15, 30, 60°), at H = 0 and 0.3 mm;
2. CPU time of one scene of 1 s with its table cached (the time loop, the output Dataset and the
   impact signature's share are not separated: what an identification pays per scene).

The constants in :mod:`bearing_lab.validation.identify_cost` (``TABLE_CPU_S``, ``SCENE_CPU_S_PER_S``)
bracket these with the spread of a shared machine; update them from this output.
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    os.environ["BEARING_LAB_CACHE"] = tempfile.mkdtemp(prefix="identify_cost_")
    from bearing_lab.sim import load_scene, simulate
    from bearing_lab.sim.assembly import table_requests
    from bearing_lab.sim.defects import contact_table
    from bearing_lab.sim.defects import contact
    base = load_scene("paper-O2", **{"load.radial_n": 320.0, "speed_rpm": 1793.0, "solver.rtol": 1e-6,
                                      "output.duration_s": 1.0, "output.sample_rate_hz": 20000.0})
    t = time.process_time()
    simulate(base.replace(**{"output.duration_s": 0.05}))
    print(f"numba compile + first short scene: {time.process_time() - t:.1f} s CPU")
    print("\n| outline | table CPU s (cold) |\n|---|---|")
    for skew in (0.0, 15.0, 30.0, 60.0):
        for offset in (0.0, 0.3):
            for k in range(args.repeat):
                sc = base.replace(**{"defect.skew_deg": skew, "defect.offset_mm": offset,
                                     "defect.length_mm": 3.0 + 0.01 * k})
                (d, kw), = table_requests(sc)
                contact._MEMORY.clear()
                t = time.process_time()
                contact_table(d, sc.bearing, **kw)
                print(f"| 3.{k:02d} x 1 mm, H {offset:g} mm, θ {skew:g}° | {time.process_time() - t:.2f} |")
    print("\n| scene (1 s, table cached) | CPU s |\n|---|---|")
    for skew in (0.0, 30.0):
        sc = base.replace(**{"defect.skew_deg": skew, "defect.offset_mm": 0.3})
        simulate(sc)
        for _ in range(args.repeat):
            t = time.process_time()
            simulate(sc)
            print(f"| θ {skew:g}°, H 0.3 mm | {time.process_time() - t:.2f} |")


if __name__ == "__main__":
    main()
