"""Simulator speed: every integration method at equal accuracy, and the default as users get it.

For paper-slot, paper-O1 (H = B/2), paper-O2 (theta = 60 deg) and cwru-or007-6:

- each method -- ours (dp54, bs32, rk4) and scipy's solve_ivp (LSODA, RK45, BDF, Radau) on the
  same compiled right-hand side -- at its cheapest setting within 1 % peak-acceleration and
  0.1 % period error of a converged reference (dp54 rtol 1e-9 / 2 us, checked against
  rtol 1e-10 / 1 us), and the ratio ours / scipy's best, all in one run;
- the quasi-static fidelity (massless balls) at a few settings: its cost and its error against
  the multibody reference;
- ``simulate(scene)`` with the defaults (fidelity and solver "auto") on 1 s records with warm
  numba and defect-table caches: the time loop, the whole call, wall_time_s and table_time_s,
  and the default's own error on the equal-accuracy record.

Cost is CPU time (time.process_time) per simulated second, minimum of repeats.
Run:  .venv/bin/python benchmarks/sim_speed.py [--duration 0.1] [--scene paper-slot] [--no-scipy]
"""
import argparse
import json

from bearing_lab.bench_speed import SPEED_SCENES, all_rows_table, run_speed

if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--duration", type=float, default=0.1, help="simulated s of the equal-accuracy records")
    ap.add_argument("--default-duration", type=float, default=1.0)
    ap.add_argument("--scene", action="append", choices=[s[0] for s in SPEED_SCENES])
    ap.add_argument("--no-scipy", action="store_true")
    ap.add_argument("--json", default=None, help="write every row here")
    args = ap.parse_args()
    md, rows, infos, defaults, qrows = run_speed(args.scene, duration=args.duration, default_duration=args.default_duration,
                                          scipy=not args.no_scipy)
    print(md)
    print()
    print(all_rows_table(rows))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"rows": rows, "reference": infos, "default": defaults, "quasi_static": qrows}, fh, indent=1)
