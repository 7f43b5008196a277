"""Import throughput of bearing_lab's readers against the bare library read of the same file.

Run:  BEARING_LAB_MIRROR=../shared/data .venv/bin/python benchmarks/io_throughput.py [--big-mb 128]

For every public recording in the mirror, and for a synthetic multi-channel UFF
58b of ``--big-mb`` MB, it times (best of ``--repeat``) ``open_recording`` (with
the sha256 provenance, and without it) and the bare read: ``pyuff.UFF(path).
read_sets()`` for UFF, ``scipy.io.loadmat`` for .mat, ``numpy.loadtxt`` for IMS.
Throughput is file size / time.  The ratio column is ours / bare time (lower is
better; the issue asks at most 1.5 for binary formats).  It also times the
58b header scan alone on the big file: the scan seeks past every payload, so it
costs a few milliseconds whatever the file size (data are read once, after).
Prints a Markdown table (paste into benchmarks/README_io.md).
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np


def _map(path):
    """A read-only memory map (the scan works on any buffer; the reader itself reads the file)."""
    import mmap
    with open(path, "rb") as fh:
        return mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ)


def best(fn, repeat):
    t = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        t.append(time.perf_counter() - t0)
    return min(t)


def bare_for(path: Path):
    import pyuff
    import scipy.io
    if path.suffix == ".uff":
        return "pyuff read_sets", lambda: pyuff.UFF(str(path)).read_sets()
    if path.suffix == ".mat":
        return "scipy.io.loadmat", lambda: scipy.io.loadmat(str(path))
    return "numpy.loadtxt", lambda: np.loadtxt(str(path))


def make_big_58b(path: Path, mb: float, nch: int = 4):
    from bearing_lab.io._testing import uff58_block
    n = int(mb * 1e6 / 4 / nch)
    rng = np.random.default_rng(0)
    with open(path, "wb") as fh:
        for k in range(nch):
            x = rng.standard_normal(n).astype(np.float32)
            fh.write(uff58_block(x, binary=True, double=False, ent=f"ch{k}", node=k + 1,
                                 inc="2.00000E-05"))
    return n


def make_big_cwru(path: Path, mb: float):
    import scipy.io
    n = int(mb * 1e6 / 8 / 3)
    rng = np.random.default_rng(1)
    scipy.io.savemat(path, {f"X130_{c}_time": rng.standard_normal((n, 1)) for c in ("DE", "FE", "BA")}
                     | {"X130RPM": np.array([[1796]], dtype=np.uint16)})


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--mirror", default=os.environ.get("BEARING_LAB_MIRROR", "../shared/data"))
    ap.add_argument("--big-mb", type=float, default=128.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    from bearing_lab import open_recording
    from bearing_lab.io import uff58
    from bearing_lab.io._base import RecordingBuilder

    mirror = Path(args.mirror)
    files = [mirror / rel for rel in (
        "lms/mpstd_set001_58b_4ch.uff", "lms/sample_58b_microphone.uff", "lms/sample_58_ascii.uff",
        "lms/testlab_acceler.mat", "cwru/130_OR007@6_0.mat", "cwru/97_Normal_0.mat",
        "mfpt/OuterRaceFault_vload_1.mat", "ims/2004.02.12.10.32.39")]
    rows = []
    tmp = Path(tempfile.mkdtemp(prefix="bl_io_bench_"))
    big = tmp / f"synthetic_4ch_{int(args.big_mb)}MB_58b.uff"
    make_big_58b(big, args.big_mb)
    bigmat = tmp / f"130_synthetic_{int(args.big_mb / 2)}MB.mat"
    make_big_cwru(bigmat, args.big_mb / 2)
    for p in [f for f in files if f.is_file()] + [big, bigmat]:
        size = p.stat().st_size / 1e6
        rep = 2 if p in (big, bigmat) else args.repeat
        opts = {"allow_truncated": True} if "truncated" in p.name else {}
        t_ours = best(lambda: open_recording(p, **opts), rep)
        t_nohash = best(lambda: open_recording(p, checksum=False, **opts), rep)
        label, fn = bare_for(p)
        t_bare = best(fn, rep)
        rows.append((p.name, size, label, size / t_ours, size / t_nohash, size / t_bare,
                     t_ours / t_bare))
    # header-first scan of the big file
    r = uff58.Uff58Reader()
    mm = _map(big)
    b = RecordingBuilder(big, r)
    r._force_bo = None
    t_scan = best(lambda: r._scan(mm, b, False), 3)
    mm.close()
    print(f"| file | MB | bare library | ours MB/s | ours, no sha256 MB/s | bare MB/s | ours/bare time |")
    print("|---|---:|---|---:|---:|---:|---:|")
    for name, size, label, a, c, bb, ratio in rows:
        print(f"| {name} | {size:.2f} | {label} | {a:.0f} | {c:.0f} | {bb:.1f} | {ratio:.2f} |")
    print(f"\nUFF 58b header scan of {big.name} ({big.stat().st_size / 1e6:.0f} MB): "
          f"{t_scan * 1e3:.2f} ms (payloads skipped by offset)")
    print(f"python {sys.version.split()[0]}, numpy {np.__version__}")
    big.unlink()
    bigmat.unlink()
    tmp.rmdir()


if __name__ == "__main__":
    main()
