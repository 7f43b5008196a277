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

``--startup [SCENE]`` measures instead what a user waits for, the whole process of
``bearing-lab simulate SCENE --duration 1 -o x.nc`` (CPU time of the child, user + system,
``getrusage(RUSAGE_CHILDREN)``): the first run after install (fresh numba and defect-table caches,
``NUMBA_CACHE_DIR`` and ``BEARING_LAB_CACHE`` in new temporary folders; minimum of ``--first``
runs, each with its own) and runs with both caches warm (minimum and median of ``--warm`` runs);
then where a warm run's second goes: the same steps as library calls in a fresh interpreter
(``--warm`` runs, the median of each step, CPU s from ``time.process_time``; without the command
line's ``gc.freeze``, so their sum is a little above the command's own time less its exit): the interpreter's start, the imports (numpy,
xarray with pandas, numba, the rest of ``bearing_lab.sim``), the start equilibrium (with numba's
set-up at the first call of a compiled function), the simulation (defect tables from their cache,
the time loop, the Dataset), the netCDF file (with ``bearing_lab.io``), and which of scipy's
heavy modules the run imported; then, the same way, ``bearing-lab --help`` and
``bearing-lab info FILE`` on each ``--info`` file (default: a CWRU .mat and a UFF 58 file of the
mirror named by ``BEARING_LAB_MIRROR``, when it has them).
"""
import argparse
import importlib.util
import json
import os
from pathlib import Path
import resource
import statistics
import subprocess
import sys
import tempfile

import bearing_lab
from bearing_lab.studies.bench_speed import SPEED_SCENES, all_rows_table, run_speed


def _child_cpu(cmd, env):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def startup(scene="paper-O1", first=2, warm=5):
    """(first-run CPU s, warm CPU s) of ``bearing-lab simulate scene --duration 1 -o x.nc``."""
    exe = str(Path(sys.executable).with_name("bearing-lab"))
    firsts, warms = [], []
    with tempfile.TemporaryDirectory() as tmp:
        out = str(Path(tmp) / "x.nc")
        cmd = [exe, "simulate", scene, "--duration", "1", "-o", out, "--force"]
        for i in range(first):
            env = {**os.environ, "NUMBA_CACHE_DIR": str(Path(tmp) / f"numba{i}"),
                   "BEARING_LAB_CACHE": str(Path(tmp) / f"tables{i}"), "BEARING_LAB_PROGRESS": "0"}
            firsts.append(_child_cpu(cmd, env))
        for _ in range(warm):
            warms.append(_child_cpu(cmd, env))
    print(f"| `bearing-lab simulate {scene} --duration 1 -o x.nc` | CPU s, min | median | all runs |")
    print("|---|---|---|---|")
    print(f"| first run (fresh numba and table caches) | {min(firsts):.2f} | {statistics.median(firsts):.2f} | "
          f"{', '.join(f'{t:.2f}' for t in firsts)} |")
    print(f"| warm caches | {min(warms):.2f} | {statistics.median(warms):.2f} | {', '.join(f'{t:.2f}' for t in warms)} |")
    print(f"\nPython's bytecode cache: {_bytecode_note()}")
    return min(firsts), min(warms)


def _bytecode_note():
    """Whether bearing_lab's modules run from .pyc files or are compiled from source in every process."""
    sources = list(Path(bearing_lab.__file__).parent.rglob("*.py"))
    cached = sum(Path(importlib.util.cache_from_source(str(p))).is_file() for p in sources)
    flag = os.environ.get("PYTHONDONTWRITEBYTECODE")
    return (f"{cached} of {len(sources)} bearing_lab modules have a .pyc; PYTHONDONTWRITEBYTECODE="
            f"{flag or '(unset)'}" + (" (Python writes none: each run compiles the others from source)"
                                      if flag and cached < len(sources) else ""))


#: the steps of ``bearing-lab simulate SCENE --duration 1 -o OUT`` one by one, in a fresh interpreter
_PHASES = r"""
import json, sys, time
T = time.process_time
t = [T()]
import numpy; t.append(T())
import xarray; t.append(T())
import numba; t.append(T())
import bearing_lab.sim as sim; t.append(T())
from bearing_lab.sim.assembly import scene_statics
scene = sim.load_scene(sys.argv[1], **{"output.duration_s": 1.0})
scene_statics(scene); t.append(T())
ds = sim.simulate(scene, progress=False); t.append(T())
from bearing_lab.io.export import to_netcdf
to_netcdf(ds, sys.argv[2]); t.append(T())
heavy = [m for m in ("scipy.linalg", "scipy.optimize", "scipy.fft", "scipy.interpolate", "pandas", "dask",
                     "matplotlib") if type(sys.modules.get(m)).__name__ == "module"]
print(json.dumps({"t": t, "heavy": heavy}))
"""
PHASE_NAMES = ("interpreter start", "import numpy", "import xarray (with pandas)", "import numba",
               "import the rest of bearing_lab.sim", "start equilibrium (with numba's set-up)",
               "simulation (tables from cache, time loop, Dataset)", "netCDF file (with bearing_lab.io)")


def phases(scene="paper-O1", runs=5):
    """Median CPU s of each step of a warm run (PHASE_NAMES), and the heavy modules it imported."""
    env = {**os.environ, "BEARING_LAB_PROGRESS": "0"}
    steps, heavy = [], None
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(runs):
            out = subprocess.run([sys.executable, "-c", _PHASES, scene, str(Path(tmp) / "x.nc")], env=env,
                                 check=True, capture_output=True, text=True).stdout
            rec = json.loads(out.strip().splitlines()[-1])
            steps.append([rec["t"][0]] + [b - a for a, b in zip(rec["t"], rec["t"][1:])])
            heavy = rec["heavy"]
    med = [statistics.median(col) for col in zip(*steps)]
    print(f"\n| a warm run's steps (the library's calls in a fresh interpreter, without the command line's "
          f"gc.freeze; {runs} runs) | CPU s, median |")
    print("|---|---|")
    for name, v in zip(PHASE_NAMES, med):
        print(f"| {name} | {v:.3f} |")
    print(f"| sum (the process's exit not included) | {sum(med):.3f} |")
    print(f"\nheavy modules imported: {', '.join(heavy) or 'none'}")
    return dict(zip(PHASE_NAMES, med)), heavy


#: files ``--startup`` reads with ``bearing-lab info`` (under BEARING_LAB_MIRROR)
INFO_FILES = ("cwru/130_OR007@6_0.mat", "lms/sample_58b_microphone.uff")


def commands(files, runs=5):
    """CPU s (min, median) of ``bearing-lab --help`` and ``bearing-lab info FILE`` for each file."""
    exe = str(Path(sys.executable).with_name("bearing-lab"))
    env = {**os.environ, "BEARING_LAB_PROGRESS": "0"}
    print("\n| command | CPU s, min | median | all runs |")
    print("|---|---|---|---|")
    out = {}
    for label, cmd in [("`bearing-lab --help`", [exe, "--help"])] + [
            (f"`bearing-lab info {Path(f).name}`", [exe, "info", str(f)]) for f in files]:
        ts = sorted(_child_cpu(cmd, env) for _ in range(runs))
        out[label] = (ts[0], statistics.median(ts))
        print(f"| {label} | {ts[0]:.2f} | {statistics.median(ts):.2f} | {', '.join(f'{t:.2f}' for t in ts)} |")
    return out


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--startup", nargs="?", const="paper-O1", default=None, metavar="SCENE",
                    help="whole-process CPU of `bearing-lab simulate SCENE --duration 1 -o x.nc`, first and warm")
    ap.add_argument("--first", type=int, default=2, help="--startup: first runs (fresh caches each)")
    ap.add_argument("--warm", type=int, default=5, help="--startup: runs with warm caches (and of each command)")
    ap.add_argument("--info", action="append", default=None, metavar="FILE",
                    help="--startup: a file to time `bearing-lab info` on (repeatable; default: a CWRU .mat and a "
                         "UFF file of the mirror)")
    ap.add_argument("--duration", type=float, default=0.1, help="simulated s of the equal-accuracy records")
    ap.add_argument("--default-duration", type=float, default=1.0)
    ap.add_argument("--scene", action="append", choices=[s[0] for s in SPEED_SCENES])
    ap.add_argument("--no-scipy", action="store_true")
    ap.add_argument("--json", default=None, help="write every row here")
    args = ap.parse_args()
    if args.startup:
        startup(args.startup, first=args.first, warm=args.warm)
        phases(args.startup, runs=args.warm)
        mirror = Path(os.environ.get("BEARING_LAB_MIRROR", "../shared/data"))
        files = args.info if args.info is not None else [mirror / f for f in INFO_FILES if (mirror / f).is_file()]
        commands(files, runs=args.warm)
        sys.exit(0)
    md, rows, infos, defaults, qrows = run_speed(args.scene, duration=args.duration, default_duration=args.default_duration,
                                          scipy=not args.no_scipy)
    print(md)
    print()
    print(all_rows_table(rows))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"rows": rows, "reference": infos, "default": defaults, "quasi_static": qrows}, fh, indent=1)
