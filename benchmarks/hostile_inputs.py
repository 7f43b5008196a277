"""Hostile scenes, killed writers and `data fetch` through links: what a user gets, measured.

Run:  BEARING_LAB_MIRROR=../shared/data .venv/bin/python benchmarks/hostile_inputs.py [--kills 20]

1. Hostile scenes: each `bearing-lab simulate` below used to hang, crash with a traceback or
   silently simulate something else.  Printed: wall time (the goal: under 10 s), exit status,
   stderr lines (the goal: one), and that line.
2. Killed writers: ``--kills`` SIGKILLs at random moments (seeded) of processes writing one
   output: the netCDF writer and the UFF 58b exporter in a loop, and `bearing-lab import -o`
   over an existing file.  After each kill the output must still open and hold one complete
   version.  Printed: intact / destroyed / never written, and temporary files left behind.
3. `data fetch` into a --dest holding a dangling link and a link to another directory: nothing
   may be written outside --dest.
"""
from __future__ import annotations

import argparse
import os
from pathlib import Path
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np

HOSTILE = [
    ["--set", "output.settle_s=1e9"],
    ["--set", "solver.method=rk4", "--set", "solver.step_s=1e-15"],
    ["--set", "solver.max_step_s=1e-15"],
    ["--set", "solver.defect_steps=1e9"],
    ["--set", "sensor.enabled=true", "--set", "sensor.frequency_hz=1e9"],
    ["--set", "speed_rpm=1e9"],
    ["--set", "shaft.stiffness_y_n_m=1e-10", "--set", "load.on=outer"],
    ["--set", "mount.stiffness_x_n_m=1e-10"],
    ["--set", "output.oversample=1"],
    ["--fs", "1e9"],
    ["--set", "fs=1e300"],
    ["--set", "output.duration_s=1e-9"],
    ["--set", "fs=40000", "--set", "duration=0.05"],
    ["--set", "defect.offset_mm=5", "--set", "duration=0.05"],
]


def _cli(*args, timeout=120):
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "bearing_lab", *args], capture_output=True, text=True,
                       timeout=timeout)
    return r, time.perf_counter() - t0


def hostile_scenes(tmp: Path) -> int:
    print("| scene overrides (paper-O1) | wall s | exit | stderr lines | stderr |")
    print("|---|---|---|---|---|")
    late = 0
    for sets in HOSTILE:
        out = tmp / "h.nc"
        r, wall = _cli("simulate", "paper-O1", "-q", "--force", "-o", str(out), *sets)
        lines = r.stderr.strip().splitlines()
        late += wall >= 10.0
        first = lines[0].replace("|", "/") if lines else ""
        print(f"| `{' '.join(sets)}` | {wall:.1f} | {r.returncode} | {len(lines)} | {first[:160]} |")
    print(f"\nscenes over 10 s: {late} of {len(HOSTILE)}")
    return late


def kill_import(tmp: Path, src: Path, kills: int, seed: int) -> dict:
    """SIGKILL `bearing-lab import SRC -o OUT` over an existing OUT at random moments."""
    from bearing_lab.errors import RecordingError
    from bearing_lab.io import open_recording
    out = tmp / "import.nc"
    r, full = _cli("import", str(src), "-o", str(out))
    assert r.returncode == 0, r.stderr
    ref = open_recording(out)
    before = out.read_bytes()
    rng = np.random.default_rng(seed)
    res = {"kills": kills, "intact": 0, "destroyed": 0}
    for _ in range(kills):
        p = subprocess.Popen([sys.executable, "-m", "bearing_lab", "import", str(src), "-o", str(out), "--force"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(float(rng.uniform(0.2, full)))
        p.send_signal(signal.SIGKILL)
        p.wait()
        try:
            same = out.read_bytes() == before or open_recording(out).identical(ref)
        except RecordingError:
            same = False
        res["intact" if same else "destroyed"] += 1
        before = out.read_bytes()
    res["temporaries"] = len([q for q in tmp.iterdir() if q.name.startswith(".import.nc.")])
    res["full_import_s"] = full
    return res


def killed_writers(tmp: Path, kills: int, mirror: Path, seed: int) -> int:
    from bearing_lab.io._fuzz import kill_writes
    n_loop = kills // 4
    runs = {"netCDF writer (loop)": kill_writes(tmp / "loop.nc", kills - 2 * n_loop, kind="netcdf",
                                                seed=seed, n=2_000_000),
            "UFF 58b export (loop)": kill_writes(tmp / "loop.uff", n_loop, kind="uff", seed=seed + 1,
                                                 n=2_000_000),
            "bearing-lab import -o (CWRU 130)": kill_import(tmp, mirror / "cwru" / "130_OR007@6_0.mat",
                                                            n_loop, seed + 2)}
    print("\n| writer | kills | intact | destroyed | never written | temporaries left |")
    print("|---|---|---|---|---|---|")
    destroyed = 0
    for name, r in runs.items():
        destroyed += r["destroyed"]
        print(f"| {name} | {r['kills']} | {r['intact']} | {r['destroyed']} | "
              f"{r.get('never_written', 0)} | {r['temporaries']} |")
    print(f"\ndestroyed outputs: {destroyed} in {kills} kills")
    return destroyed


def fetch_links(tmp: Path, mirror: Path) -> int:
    from bearing_lab import datasets
    from bearing_lab.errors import RecordingError
    name = "lms/binary8byte_g.uff"
    dest, outside = tmp / "dest", tmp / "outside"
    (dest / "lms").mkdir(parents=True)
    outside.mkdir()
    (dest / name).symlink_to(outside / "victim.uff")
    outcomes = []
    for label in ("dangling link to a file outside", "link to a directory outside"):
        try:
            datasets.fetch(name, mirror=mirror, dest=dest, download=False)
            outcomes.append(f"{label}: fetched (!)")
        except RecordingError as exc:
            outcomes.append(f"{label}: refused ({str(exc)[:90]}...)")
        if (dest / "lms").is_dir() and not (dest / "lms").is_symlink():
            (dest / name).unlink()
            (dest / "lms").rmdir()
            (dest / "lms").symlink_to(outside)
    written = list(outside.iterdir())
    print("\n" + "\n".join(outcomes))
    print(f"files written outside --dest: {len(written)}")
    return len(written)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kills", type=int, default=20)
    ap.add_argument("--seed", type=int, default=11)
    args = ap.parse_args(argv)
    mirror = Path(os.environ.get("BEARING_LAB_MIRROR") or
                  Path(__file__).resolve().parents[2] / "shared" / "data")
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        bad = hostile_scenes(tmp)
        bad += killed_writers(tmp, args.kills, mirror, args.seed)
        bad += fetch_links(tmp, mirror)
    print(f"\nmachine: {os.cpu_count()} cores, shared with other jobs (wall times scatter)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
