"""The CWRU cases under an axial spring preload: every row at 0 (planar), 125, 188 and 250 N.

The motor's wave spring preloads the bearings axially; SKF's rule for deep-groove ball bearings in
electric motors, F = k d with k = 0.005-0.01 kN/mm and d = 25 mm (6205 bore), gives 125-250 N.  This
script runs the shipped cases cwru-130 (which identifies the rig's structural path), cwru-144,
cwru-234 and cwru-105 with ``load.axial_n`` set on every scene they simulate, and prints one table
per case: each row's simulated value and status per preload.  Usage: python benchmarks/cwru_preload.py [N ...]
[--rtol R] (``--rtol``: every scene at dp54 with that tolerance instead of the ``auto`` rule, to check
the columns converged).
"""
import argparse
import json
import sys
import tempfile
from pathlib import Path

CASES = ["cwru-130", "cwru-144", "cwru-234", "cwru-105"]


def run(preload, out, rtol=None):
    from bearing_lab.validation import run_validation, simulation
    orig = simulation.build_scene

    def build(case, **kw):
        ov = dict(kw.pop("overrides", None) or {})
        if preload:
            ov["load.axial_n"] = float(preload)
        if rtol is not None:
            ov.update({"solver.method": "dp54", "solver.rtol": float(rtol)})
        return orig(case, overrides=ov, **kw)
    simulation.build_scene = build
    try:
        outcomes, _ = run_validation(CASES, out, progress=False)
    finally:
        simulation.build_scene = orig
    return {o.name: json.loads((Path(out) / o.name / "summary.json").read_text()) for o in outcomes}


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("loads", nargs="*", type=float, help="axial preloads, N (default 0 125 188 250)")
    ap.add_argument("--rtol", type=float, help="dp54 at this tolerance on every scene instead of the auto rule")
    a = ap.parse_args(argv)
    if a.rtol is not None and not 0 < a.rtol < 1:
        ap.error(f"--rtol {a.rtol:g}: a relative tolerance between 0 and 1 is needed")
    loads = a.loads or [0.0, 125.0, 188.0, 250.0]
    if a.rtol is not None:
        print(f"every scene at dp54 rtol {a.rtol:g} (not the auto rule)")
    res = {}
    for f in loads:
        with tempfile.TemporaryDirectory() as tmp:
            res[f] = run(f, tmp, a.rtol)
        print(f"preload {f:g} N done", file=sys.stderr, flush=True)
    for case in CASES:
        rows = [r["quantity"] for r in res[loads[0]][case]["rows"]]
        print(f"\n#### {case}\n")
        print("| row | recording | " + " | ".join(f"{f:g} N" for f in loads) + " |")
        print("|---|---:|" + "---:|" * len(loads))
        for q in rows:
            cells, e = [], None
            for f in loads:
                r = next((x for x in res[f][case]["rows"] if x["quantity"] == q), None)
                if r is None:
                    cells.append("-")
                    continue
                e = r["experiment"]
                v = r["simulation"]
                mark = {"pass": "", "known limitation": " (kl)", "fail": " **fail**"}[r["status"]]
                cells.append(("-" if v is None else f"{v:.4g}") + mark)
            print(f"| {q} | {'-' if e is None else f'{e:.4g}'} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main(sys.argv[1:])
