"""Hostile scenes, killed writers, `data fetch` through links, structure-aware file mutants,
files cut while read and a decompression bomb: what a user gets, measured.

Run:  BEARING_LAB_MIRROR=../shared/data .venv/bin/python benchmarks/hostile_inputs.py [--kills 20]
      [--structured 300] [--truncations 5] [--only structured]

1. Hostile scenes: each `bearing-lab simulate` below used to hang, crash with a traceback or
   silently simulate something else.  Printed: wall time (the goal: under 10 s), exit status,
   stderr lines (the goal: one), and that line.
2. Killed writers: ``--kills`` SIGKILLs at random moments (seeded) of processes writing one
   output: the netCDF writer and the UFF 58b exporter in a loop, and `bearing-lab import -o`
   over an existing file.  After each kill the output must still open and hold one complete
   version.  Printed: intact / destroyed / never written, and temporary files left behind.
3. `data fetch` into a --dest holding a dangling link and a link to another directory: nothing
   may be written outside --dest.
4. Structure-aware mutants (``bearing_lab.io._fuzz_struct.fuzz_structured``): per kind (MAT v5, v7.3,
   foreign netCDF, WAV, UFF, non-regular files) ``--structured`` cases that each change one
   header field or element on purpose; every file that reads is compared with an independent
   decoder.  Printed: verdicts per kind and per field changed.
5. A 64 MB UFF 58b cut to 100 kB while `bearing-lab info` reads it: refused, or read before the
   cut; never a crash.
6. A 1 MB MAT v5 element inflating to 1 GB of zeros: time and peak memory of the refusal.
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
    from bearing_lab.io._fuzz_writes import kill_writes
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


def structured(cases: int, seed: int) -> int:
    """Structure-aware mutants of every kind, each accepted file checked against an independent
    decoder (bearing_lab.io._fuzz_struct); printed: the verdicts per kind and per changed field."""
    from bearing_lab.io import _fuzz_struct as _fuzz
    print("\n| kind | cases | " + " | ".join(_fuzz.STRUCT_VERDICTS) + " | wall s | slowest case s |")
    print("|---|---|" + "---|" * len(_fuzz.STRUCT_VERDICTS) + "---|---|")
    bad, fields = 0, {}
    for kind in _fuzz.STRUCT_KINDS:
        r = _fuzz.fuzz_structured(kind, cases, seed=seed)
        c = r["counts"]
        bad += sum(c[v] for v in ("uncaught", "silent", "invalid", "crash", "hang"))
        print(f"| {kind} | {cases} | " + " | ".join(str(c[v]) for v in _fuzz.STRUCT_VERDICTS)
              + f" | {r['wall_s']:.0f} | {r['slowest_s']:.2f} |")
        for op, verdicts in r["by_case"].items():
            field = op.split("]")[0].lstrip("[") if op.startswith("[") else op
            agg = fields.setdefault((kind, field), {})
            for v, k in verdicts.items():
                agg[v] = agg.get(v, 0) + k
        for v, examples in r["examples"].items():
            for e in examples:
                print(f"  {kind} {v} #{e['i']} ({e['op']}): {e['detail']}")
    print("\n| kind | field changed | verdicts |")
    print("|---|---|---|")
    for (kind, field), verdicts in sorted(fields.items()):
        print(f"| {kind} | {field} | {', '.join(f'{v} {k}' for v, k in sorted(verdicts.items()))} |")
    print(f"\nstructured cases with a bad verdict: {bad} of {cases * len(_fuzz.STRUCT_KINDS)}")
    return bad


def changing_files(tmp: Path, trials: int, seed: int) -> int:
    """A 64 MB UFF 58b cut to 100 kB while `bearing-lab info` reads it (a mapped file: SIGBUS)."""
    from bearing_lab.io._fuzz_struct import truncate_while_reading
    r = truncate_while_reading(tmp / "big.uff", trials=trials, seed=seed)
    print(f"\nUFF 58b truncated while read, {r['trials']} trials: refused {r['refused']}, read before the "
          f"cut {r['ok']}, crash {r['crash']}, other {r['other']}")
    for e in r["examples"][:3]:
        print(f"  {e}")
    return r["crash"] + r["other"]


def inflate_bomb(tmp: Path) -> int:
    """A 1 MB MAT v5 element inflating to 1 GB of zeros: time and peak memory of the refusal."""
    import resource
    import zlib
    from bearing_lab.io._fuzz_struct import _compressed, _mat5_array, _mat5_file
    n = 125_000_000
    import struct
    z = zlib.compressobj(9)
    empty = _mat5_array("X130_DE_time", 6, (n, 1), 9, b"")  # ends with the (miDOUBLE, 0) tag
    # the array's header with a 1 GB data element, then 1 GB of zeros streamed through deflate
    body = empty[8:-8] + struct.pack("<II", 9, 8 * n)
    tag = struct.pack("<II", 14, len(body) + 8 * n)
    stream = z.compress(tag + body)
    block = bytes(1 << 24)
    for _ in range(8 * n // len(block)):
        stream += z.compress(block)
    stream += z.compress(bytes(8 * n % len(block))) + z.flush()
    p = tmp / "130_bomb.mat"
    p.write_bytes(_mat5_file([_compressed(stream)]))
    code = ("import resource, time, sys\nfrom bearing_lab import open_recording\nt = time.perf_counter()\n"
            "try:\n    open_recording(sys.argv[1], fs=12000)\n    out = 'read'\n"
            "except Exception as e:\n    out = str(e)\n"
            "print(f'{time.perf_counter() - t:.2f} s, peak {resource.getrusage(resource.RUSAGE_SELF)"
            ".ru_maxrss / 1024:.0f} MB: {out}')")
    r = subprocess.run([sys.executable, "-c", code, str(p)], capture_output=True, text=True, timeout=600)
    print(f"\nMAT v5 element of {p.stat().st_size / 1e6:.2f} MB inflating to {8 * n / 1e9:.1f} GB: "
          f"{r.stdout.strip() or r.stderr.strip()[-300:]}")
    return 0 if "inflate ratio" in r.stdout else 1


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kills", type=int, default=20)
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--structured", type=int, default=300, help="structure-aware cases per kind")
    ap.add_argument("--truncations", type=int, default=5, help="UFF files cut while read")
    ap.add_argument("--only", default=None, help="run one part: scenes, kills, fetch, structured, "
                    "changing, bomb")
    args = ap.parse_args(argv)
    mirror = Path(os.environ.get("BEARING_LAB_MIRROR") or
                  Path(__file__).resolve().parents[2] / "shared" / "data")
    parts = {"scenes": lambda tmp: hostile_scenes(tmp),
             "kills": lambda tmp: killed_writers(tmp, args.kills, mirror, args.seed),
             "fetch": lambda tmp: fetch_links(tmp, mirror),
             "structured": lambda tmp: structured(args.structured, args.seed),
             "changing": lambda tmp: changing_files(tmp, args.truncations, args.seed),
             "bomb": lambda tmp: inflate_bomb(tmp)}
    bad = 0
    for name, part in parts.items():
        if args.only in (None, name):
            with tempfile.TemporaryDirectory() as d:
                bad += part(Path(d))
    print(f"\nmachine: {os.cpu_count()} cores, shared with other jobs (wall times scatter)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
