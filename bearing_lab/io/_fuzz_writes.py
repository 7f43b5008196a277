"""Writers killed at random moments must leave a whole file: :func:`kill_writes`.

Why: ``-o`` outputs and exports are replaced atomically (:func:`bearing_lab.utils._files.atomic_path`);
the claim is tested by killing (SIGKILL) a process that writes the same target over and over, at
random moments, and reading what is left: the previous version or the new one, complete, never a
mixture or a stub.  The CI test (``tests/io/test_io_integrity.py``) and the long run
(``benchmarks/hostile_inputs.py``) use this module; the reader fuzzing is in :mod:`._fuzz`.
"""
from __future__ import annotations

from pathlib import Path
import signal
import subprocess
import sys
import time
import warnings

import numpy as np
import xarray as xr

from ..errors import RecordingError
from . import open_recording, to_netcdf, to_uff58b

_WRITE_LOOP = """
import sys
from bearing_lab.io._fuzz_writes import write_version
k = 0
while True:
    k += 1
    write_version(sys.argv[1], sys.argv[2], int(sys.argv[3]), k)
"""


def _version(n: int, k: int):
    t = np.arange(n) / 10000.0
    return xr.Dataset({"acc": ("time", np.sin(t * (1 + k % 2)), {
        "units": "m s-2", "quantity": "acceleration", "original_units": "m/s2"})},
        coords={"time": ("time", t, {"units": "s"})},
        attrs={"sampling_rate_hz": 10000.0, "bearing_lab_version": "0", "source_file": "x",
               "source_sha256": "", "reader": "csv", "warnings": "", "default_channel": "acc"})


def write_version(target, kind: str, n: int, k: int) -> None:
    """Write version ``k`` (two alternating signals) of a test recording to ``target``."""
    (to_netcdf if kind == "netcdf" else to_uff58b)(_version(n, k), target)


def _written_versions(n):
    return [_version(n, k)["acc"].values for k in (1, 2)]


def _wait_for_first_write(target: Path, proc, limit: float = 120.0) -> None:
    t0 = time.perf_counter()
    prefix = f".{target.name}."
    while proc.poll() is None and time.perf_counter() - t0 < limit:
        if any(p.name.startswith(prefix) for p in target.parent.iterdir()):
            return
        time.sleep(0.01)


def kill_writes(target: Path, kills: int, *, kind: str = "netcdf", seed: int = 0,
                n: int = 2_000_000, max_delay: float = 4.0) -> dict:
    """SIGKILL a process that writes ``target`` over and over; after each kill the file must
    open and hold one complete version.  Returns counts: ``intact``, ``destroyed``,
    ``never_written`` (killed before the first write) and ``temporaries`` left behind."""
    target = Path(target)
    rng = np.random.default_rng(seed)
    versions = _written_versions(n)
    write_version(target, kind, n, 0)  # the existing output a killed writer must not destroy
    out = {"kills": kills, "intact": 0, "destroyed": 0, "never_written": 0, "examples": []}
    for _ in range(kills):
        proc = subprocess.Popen([sys.executable, "-c", _WRITE_LOOP, str(target), kind, str(n)],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        _wait_for_first_write(target, proc)  # kill while writing, not while importing
        time.sleep(float(rng.uniform(0.0, max_delay)))
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        if not target.exists():
            out["never_written"] += 1
            continue
        try:
            values = _read_quietly(target).to_array().values[0]
            whole = any(np.array_equal(values, v.astype(np.float64)) for v in versions)
        except RecordingError as exc:
            whole, values = False, str(exc)
        if whole:
            out["intact"] += 1
        else:
            out["destroyed"] += 1
            out["examples"].append(str(values)[:200])
    out["temporaries"] = len([p for p in target.parent.iterdir() if p.name.startswith(f".{target.name}.")])
    return out


def _read_quietly(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with np.errstate(all="ignore"):
            return open_recording(path)
