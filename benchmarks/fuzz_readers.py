"""Fuzz every reader with more than 20 000 seeded mutants of the real recordings; print the counts.

Run:  BEARING_LAB_MIRROR=../shared/data .venv/bin/python benchmarks/fuzz_readers.py [--total 21000]
      [--seed 7] [--jobs 2] [--keep DIR] [--json out.json]

The harness is ``bearing_lab.io._fuzz`` (the CI test ``tests/io/test_io_fuzz.py`` runs a smaller
plan with another seed): each source's mutants are read by a worker process under a time and
memory limit, so crashes and hangs are counted, not fatal.  Verdicts are defined in that
module's docstring; the acceptance is 0 uncaught, 0 silent, 0 invalid, 0 crash, 0 hang and 0
memory.  Any bad mutant is listed with its index; ``python -m bearing_lab.io._fuzz repro
SOURCE SEED INDEX`` writes it to a file (and ``--keep DIR`` saves them all).
"""
from __future__ import annotations

import argparse
from concurrent.futures import ThreadPoolExecutor
import json
import os
from pathlib import Path
import sys
import time

from bearing_lab.io import _fuzz

# share of the mutants per source (the slow HDF5 sources get fewer, the formats stay balanced)
WEIGHTS = {"cwru": 3, "cwru_48k": 3, "mfpt": 2, "testlab_v5": 3, "testlab_v73": 1.2,
           "uff58b_4ch": 2, "uff58b_mic": 2, "uff58b_g": 2, "uff58_ascii": 1, "uff58_catman": 1.5,
           "uff58_truncated": 1.5, "ims": 3, "tdms": 3, "wav": 2, "netcdf": 0.8, "csv": 1,
           "testlab_text": 1, "mdf": 2}
FORMATS = {"cwru": "MATLAB v5", "cwru_48k": "MATLAB v5", "mfpt": "MATLAB v5 (compressed)",
           "testlab_v5": "MATLAB v5", "testlab_v73": "MATLAB v7.3 (HDF5)", "uff58b_4ch": "UFF 58b",
           "uff58b_mic": "UFF 58b", "uff58b_g": "UFF 58b", "uff58_ascii": "UFF 58",
           "uff58_catman": "UFF 58", "uff58_truncated": "UFF 58 (allow_truncated)",
           "ims": "IMS text", "tdms": "TDMS", "wav": "WAV", "netcdf": "netCDF4 (bearing_lab)",
           "csv": "CSV", "testlab_text": "Testlab text", "mdf": "MDF4"}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--total", type=int, default=21000, help="mutants in all (default 21000)")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--jobs", type=int, default=2, help="sources fuzzed at once (worker processes)")
    ap.add_argument("--sources", default=",".join(WEIGHTS), help="comma-separated source names")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per mutant before 'hang'")
    ap.add_argument("--keep", default=None, help="directory to save every bad mutant in")
    ap.add_argument("--json", default=None, help="write the full results here")
    args = ap.parse_args(argv)
    if not os.environ.get("BEARING_LAB_MIRROR"):
        os.environ["BEARING_LAB_MIRROR"] = str(Path(__file__).resolve().parents[2] / "shared" / "data")
    names = [n for n in args.sources.split(",") if n]
    weight = sum(WEIGHTS[n] for n in names)
    plan = {n: max(1, round(args.total * WEIGHTS[n] / weight)) for n in names}
    t0 = time.perf_counter()
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {n: pool.submit(_fuzz.fuzz_source, n, plan[n], seed=args.seed,
                                  timeout=args.timeout, keep=Path(args.keep) if args.keep else None)
                   for n in sorted(names, key=lambda n: -plan[n])}
        results = {n: f.result() for n, f in futures.items()}
    wall = time.perf_counter() - t0
    cols = _fuzz.VERDICTS
    print(f"| source | format | mutants | {' | '.join(cols)} | wall s |")
    print("|---|---|---|" + "---|" * len(cols) + "---|")
    total = {c: 0 for c in cols}
    for n in names:
        r = results[n]
        for c in cols:
            total[c] += r["counts"][c]
        print(f"| {n} | {FORMATS[n]} | {r['mutants']} | "
              + " | ".join(str(r["counts"][c]) for c in cols) + f" | {r['wall_s']:.0f} |")
    print(f"| **all** | | **{sum(plan.values())}** | "
          + " | ".join(f"**{total[c]}**" for c in cols) + f" | {wall:.0f} |")
    bad = sum(total[c] for c in _fuzz.BAD)
    print(f"\nseed {args.seed}; bad verdicts ({', '.join(_fuzz.BAD)}): {bad}; wall time {wall:.0f} s "
          f"on {os.cpu_count()} cores (shared machine: wall times scatter)")
    for n in names:
        for v, examples in results[n]["examples"].items():
            for e in examples:
                print(f"  {n} {v} #{e['i']} ({e['op']}): {e['detail']}")
    if args.json:
        Path(args.json).write_text(json.dumps({"plan": plan, "seed": args.seed, "results": results,
                                               "wall_s": wall}, indent=1))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
