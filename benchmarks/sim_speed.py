"""Simulator core speed: paper-healthy and paper-slot, both fidelities, every solver setting and
scipy's solve_ivp on the same equations -- the issue-2 subset of the work-precision study.

Run:  .venv/bin/python benchmarks/sim_speed.py [--duration 1.0]
(the full study, with the 2-D defect and CWRU scenes, is `bearing-lab bench`).
"""
import argparse

from bearing_lab.bench import run_bench, summary_table

if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("-o", "--output", default="reports/performance-core")
    args = ap.parse_args()
    ds = run_bench(args.output, duration=args.duration, scenes=["paper-healthy", "paper-slot"])
    print(summary_table(ds))
    print(f"all rows: {args.output}/index.html")
