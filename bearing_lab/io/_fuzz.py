"""Fuzzing the readers with seeded mutants of real recordings, each read in a guarded subprocess.

(The structure-aware cases, whose header fields are set on purpose, are in :mod:`._fuzz_struct`;
writers killed at random moments, which must leave a whole file, in :mod:`._fuzz_writes`.)

Why in the package: the CI test (``tests/io/test_io_fuzz.py``) and the long run
(``benchmarks/fuzz_readers.py``) use the same corpus, mutations and verdicts, and a
user can rerun one mutant from its seed and index (``python -m bearing_lab.io._fuzz
repro SOURCE SEED INDEX``).

How: a worker process opens the original file once (its channels, length and values
are the reference), then reads mutants by index: mutant ``i`` of source ``s`` with
seed ``k`` is always the same bytes.  The parent feeds indices, waits for each answer
under a time limit and restarts the worker when it dies, so a segmentation fault, a
hang or a runaway allocation is counted, not fatal.  The worker runs under an address
space limit.  Verdicts, one per mutant:

``ok``         read, same channels and length as the original;
``renamed``    read, as many channels and samples, but a name differs (a flipped byte
               in a name field is a change of content, like a flipped digit in a value);
``refused``    :class:`~bearing_lab.errors.RecordingError` naming the file;
``uncaught``   any other exception (or a RecordingError that does not name the file);
``silent``     read, but channels or length differ from the original without an error
               (with ``allow_truncated`` a shortfall counts only when the recording
               does not say so in its warnings and ``truncated_samples`` attribute),
               or a pure truncation read with values that differ from the original's;
``invalid``    read, but NaN/Inf values or a Dataset that breaks the recording contract;
``crash``      the worker died (signal or exit); ``hang``: no answer within the limit;
``memory``     the worker's peak memory grew by more than its limit on this mutant.
"""
from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
import re
import resource
import select
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import warnings

import lazy_loader as lazy
import numpy as np

from .. import schema
from ..errors import RecordingError
from ..units import G
from . import open_recording, to_netcdf
from ._matlab import load_mat

# the corpus builders' format libraries (optional ones included): loaded when a builder runs
asammdf = lazy.load("asammdf")
h5py = lazy.load("h5py")
nptdms = lazy.load("nptdms")

VERDICTS = ("ok", "renamed", "refused", "uncaught", "silent", "invalid", "crash", "hang", "memory")
BAD = ("uncaught", "silent", "invalid", "crash", "hang", "memory")


# ------------------------------------------------------------------ the corpus
def _mirror_file(rel):
    def build(mirror: Path, tmp: Path) -> Path:
        p = mirror / rel
        if not p.is_file():
            raise FileNotFoundError(f"{p} (set BEARING_LAB_MIRROR to the public recordings)")
        return p
    return build


def _ims_channels(mirror):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = open_recording(mirror / "ims" / "2004.02.17.07.12.39")
    return ds


def _build_tdms(mirror: Path, tmp: Path) -> Path:
    """Two channels of a real IMS snapshot, 20 000 samples, streamed in two segments."""
    ds = _ims_channels(mirror)
    p = tmp / "ims_b1_b2.tdms"
    props = {"wf_increment": 1.0 / ds.attrs["sampling_rate_hz"], "wf_start_offset": 0.0,
             "unit_string": "m/s^2"}
    with nptdms.TdmsWriter(p) as w:
        for part in (slice(0, 10000), slice(10000, 20000)):
            w.write_segment([nptdms.ChannelObject("Vibration", c, ds[c].values[part], properties=props)
                             for c in ("b1", "b2")])
    return p


def _build_v73(mirror: Path, tmp: Path) -> Path:
    """The real Testlab export re-saved as a MATLAB v7.3 (HDF5) file, values deflated."""
    sig = load_mat(mirror / "lms" / "testlab_acceler.mat")["Signal"]
    p = tmp / "testlab_acceler_v73.mat"

    def put(group, name, value):
        if isinstance(value, dict):
            g = group.create_group(name)
            g.attrs["MATLAB_class"] = np.bytes_("struct")
            for k, v in value.items():
                put(g, k, v)
        elif isinstance(value, str):
            d = group.create_dataset(name, data=np.array([[ord(c) for c in value or " "]],
                                                         dtype=np.uint16).T)
            d.attrs["MATLAB_class"] = np.bytes_("char")
        elif isinstance(value, (int, float, np.ndarray)):
            arr = np.atleast_2d(np.asarray(value, dtype=float))
            kw = {"compression": "gzip", "chunks": True} if arr.size > 1000 else {}
            d = group.create_dataset(name, data=arr, **kw)
            d.attrs["MATLAB_class"] = np.bytes_("double")

    with h5py.File(p, "w", userblock_size=512) as f:
        put(f, "Signal", {k: sig[k] for k in ("x_values", "y_values", "function_record")})
    with open(p, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: bearing_lab fuzz corpus "
                 b"HDF5 schema 1.00 .")
    return p


def _build_wav(mirror: Path, tmp: Path) -> Path:
    """CWRU drive-end and fan-end signals as a 16-bit stereo WAV (full scale 10 g)."""
    import scipy.io.wavfile  # lazy.load imports scipy.io at once (workers: memory limit)
    ds = open_recording(mirror / "cwru" / "130_OR007@6_0.mat")
    x = np.stack([ds["DE"].values, ds["FE"].values], axis=1)[:40000] / G / 10.0
    p = tmp / "cwru130_de_fe.wav"
    scipy.io.wavfile.write(p, 12000, np.round(np.clip(x, -1, 1) * 32767).astype(np.int16))
    return p


def _build_nc(mirror: Path, tmp: Path) -> Path:
    """A bearing_lab netCDF4 file: a real IMS snapshot imported."""
    ds = _ims_channels(mirror)
    p = tmp / "ims_import.nc"
    to_netcdf(ds, p)
    return p


def _build_csv(mirror: Path, tmp: Path) -> Path:
    ds = _ims_channels(mirror)
    p = tmp / "ims_b1_b2.csv"
    t = ds["time"].values[:3000]
    rows = "\n".join(f"{a:.8f},{b:.6f},{c:.6f}" for a, b, c in
                     zip(t, ds["b1"].values[:3000], ds["b2"].values[:3000]))
    p.write_text("time [s],b1 [m/s2],b2 [m/s2]\n" + rows + "\n")
    return p


def _build_testlab_text(mirror: Path, tmp: Path) -> Path:
    ds = _ims_channels(mirror)
    head = ("Name\tRun 1\nProject\tIMS set 2\nSection\tSection1\nIncrement\t"
            f"{1.0 / ds.attrs['sampling_rate_hz']:.10g}\n" + "b1\tb2\ng\tg\nReal\tReal\n")
    rows = "\n".join(f"{a:.6f}\t{b:.6f}".replace(".", ",") for a, b in
                     zip(ds["b1"].values[:3000] / G, ds["b2"].values[:3000] / G))
    p = tmp / "ims_export.txt"
    p.write_bytes((head + rows + "\n").encode("latin-1"))
    return p


def _build_mdf(mirror: Path, tmp: Path) -> Path:
    ds = _ims_channels(mirror)
    t = ds["time"].values[:5000]
    m = asammdf.MDF(version="4.10")
    m.append([asammdf.Signal(ds[c].values[:5000], t, name=c, unit="m/s^2") for c in ("b1", "b2")])
    p = tmp / "ims_b1_b2.mf4"
    m.save(p, overwrite=True)
    m.close()
    return p


class Source:
    """One fuzzing source: how to get the file, reader options, what the format declares."""

    def __init__(self, name, build, *, options=None, declared_length=True, text=False,
                 fmt="mat5"):
        self.name, self.build, self.options = name, build, dict(options or {})
        self.declared_length, self.text, self.fmt = declared_length, text, fmt


SOURCES = {s.name: s for s in [
    Source("cwru", _mirror_file("cwru/130_OR007@6_0.mat")),
    Source("cwru_48k", _mirror_file("cwru/48k_DE/IR014_0.mat"), options={"fs": 48000}),
    Source("mfpt", _mirror_file("mfpt/OuterRaceFault_vload_1.mat")),
    Source("testlab_v5", _mirror_file("lms/testlab_acceler.mat")),
    Source("testlab_v73", _build_v73, fmt="hdf5"),
    Source("uff58b_4ch", _mirror_file("lms/mpstd_set001_58b_4ch.uff"), fmt="uff"),
    Source("uff58b_mic", _mirror_file("lms/sample_58b_microphone.uff"), fmt="uff"),
    Source("uff58b_g", _mirror_file("lms/binary8byte_g.uff"), fmt="uff"),
    Source("uff58_ascii", _mirror_file("lms/sample_58_ascii.uff"), text=True, fmt="uff"),
    Source("uff58_catman", _mirror_file("lms/catman_58_ascii_short.uff"), text=True, fmt="uff"),
    Source("uff58_truncated", _mirror_file("lms/truncated_58_ascii.uff"), text=True, fmt="uff",
           options={"allow_truncated": True}),
    Source("ims", _mirror_file("ims/2004.02.12.10.32.39"), text=True, fmt="text"),
    Source("tdms", _build_tdms, fmt="tdms"),
    Source("wav", _build_wav, options={"full_scale": "10 g"}, fmt="wav"),
    Source("netcdf", _build_nc, fmt="hdf5"),
    # a CSV declares no length: a cut between rows cannot be told from a shorter file
    Source("csv", _build_csv, text=True, declared_length=False, fmt="text"),
    Source("testlab_text", _build_testlab_text, text=True, declared_length=False, fmt="text"),
    Source("mdf", _build_mdf, fmt="mdf"),
]}


# ------------------------------------------------------------------ mutations
_INTERESTING = [0, 1, 2, 7, 8, 9, 0x7F, 0x80, 0xFF, 0x7FFF, 0xFFFF, 0x7FFFFFFF, 0x80000000,
                0xFFFFFFFF, 0x19]
_TOKENS = [b"0", b"-1", b"1", b"nan", b"inf", b"1e309", b"-0", b"", b" ", b"\t", b"\n", b"9" * 12,
           b"1.5", b"58", b"58b", b"E", b"D+01", b",", b"x"]


def hot_spots(data: bytes, fmt: str) -> np.ndarray:
    """Byte positions in the file's structure (headers, tags, lead-ins) rather than bulk data."""
    size = len(data)
    spots = []
    if fmt == "uff":  # the text lines (headers, delimiters), not the binary payloads
        for m in re.finditer(rb"(?m)^[ -~]{1,80}\r?$", data[:1 << 22]):
            spots.extend(range(m.start(), m.end() + 1))
            if len(spots) > 200000:
                break
    elif fmt == "mat5" and size > 136:
        pos = 128
        while pos + 8 <= size and len(spots) < 1 << 16:
            spots.extend(range(pos, min(pos + 96, size)))
            pos += 8 + struct.unpack_from("<I", data, pos + 4)[0]
    elif fmt == "tdms":
        pos = 0
        while pos + 28 <= size and data[pos:pos + 4] == b"TDSm":
            nxt, raw = struct.unpack_from("<QQ", data, pos + 12)
            spots.extend(range(pos, min(pos + 28 + raw, size)))
            pos += 28 + nxt
    elif fmt == "wav":
        spots.extend(range(0, min(64, size)))
    if not spots or fmt in ("hdf5",):
        spots.extend(range(0, min(size, 8192)))
    return np.asarray(spots, dtype=np.int64)


def mutate(data: bytes, hot: np.ndarray, text: bool, rng) -> tuple[bytes, str, bool]:
    """Return (mutant, description, is_pure_truncation); ``hot``: see :func:`hot_spots`."""
    size = len(data)
    op = rng.choice(["flip", "flip_hot", "truncate", "truncate_end", "delete", "insert",
                     "word", "token" if text else "flip_hot"])
    b = bytearray(data)

    def where(want_hot):
        pos = int(hot[rng.integers(0, hot.size)]) if want_hot else int(rng.integers(0, size))
        return min(max(pos, 0), size - 1)

    if op in ("flip", "flip_hot"):
        k = int(rng.integers(1, 5))
        spots = [where(op == "flip_hot") for _ in range(k)]
        for p in spots:
            b[p] = int(rng.integers(0, 256))
        return bytes(b), f"{op} at {spots}", False
    if op == "truncate":
        cut = int(rng.integers(0, size))
        return bytes(b[:cut]), f"truncate to {cut} of {size} bytes", True
    if op == "truncate_end":
        cut = max(size - int(rng.integers(1, 64)), 0)
        return bytes(b[:cut]), f"truncate to {cut} of {size} bytes", True
    if op == "delete":
        p, n = where(rng.random() < 0.5), int(rng.integers(1, 65))
        del b[p:p + n]
        return bytes(b), f"delete {n} bytes at {p}", False
    if op == "insert":
        p, n = where(rng.random() < 0.5), int(rng.integers(1, 17))
        b[p:p] = bytes(rng.integers(0, 256, n, dtype=np.uint8))
        return bytes(b), f"insert {n} bytes at {p}", False
    if op == "word":
        p = where(True) & ~3
        v = int(rng.choice(_INTERESTING)) if rng.random() < 0.7 else int(rng.integers(0, 1 << 32))
        order = "little" if rng.random() < 0.8 else "big"
        b[p:p + 4] = v.to_bytes(4, order)
        return bytes(b[:size]), f"word {v:#x} ({order}) at {p}", False
    # token: replace one whitespace-separated token of a text file
    p = where(rng.random() < 0.5)
    lo = p
    while lo > 0 and data[lo - 1:lo] not in (b" ", b"\t", b"\n", b"\r"):
        lo -= 1
    hi = p
    while hi < size and data[hi:hi + 1] not in (b" ", b"\t", b"\n", b"\r"):
        hi += 1
    tok = _TOKENS[int(rng.integers(0, len(_TOKENS)))]
    b[lo:hi] = tok
    return bytes(b), f"token {data[lo:hi][:20]!r} -> {tok!r} at {lo}", False


def mutant(source: Source, data: bytes, hot: np.ndarray, seed: int, index: int):
    """Mutant ``index`` of ``source`` for ``seed``: always the same bytes."""
    rng = np.random.default_rng([seed, index, sum(map(ord, source.name))])
    return mutate(data, hot, source.text, rng)


# ------------------------------------------------------------------ the worker (one source)
def _summary(ds) -> dict:
    return {"channels": list(ds.data_vars), "n": int(ds.sizes.get("time", 0))}


def _open_quietly(path, options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with np.errstate(all="ignore"):
            return open_recording(path, **options)


def exception_verdict(exc, path: Path) -> tuple[str, str]:
    if isinstance(exc, RecordingError):
        if path.name not in str(exc):
            return "uncaught", f"RecordingError without the file name: {exc}"
        return "refused", str(exc).replace(str(path.parent), "")[:300]
    return "uncaught", f"{type(exc).__name__}: {exc}"[:300]


def verdict(path: Path, source: Source, ref, truncation: bool) -> tuple[str, str]:
    """Read one mutant and judge it against the original's Dataset ``ref``."""
    try:
        ds = _open_quietly(path, source.options)
    except KeyboardInterrupt:
        raise
    except BaseException as exc:  # noqa: BLE001 - the point is to count them
        return exception_verdict(exc, path)
    got, want = _summary(ds), _summary(ref)
    if len(got["channels"]) != len(want["channels"]):
        return "silent", f"channels {got['channels']} instead of {want['channels']}"
    if got["n"] != want["n"] and source.declared_length:
        declared = int(ds.attrs.get("declared_samples", 0) or 0)
        said = "truncat" in str(ds.attrs.get("warnings", "")).lower()
        if not (source.options.get("allow_truncated") and declared > got["n"] and said):
            return "silent", f"{got['n']} samples instead of {want['n']}"
    try:
        schema.check_dataset(ds, kind="recording")
    except Exception as exc:  # noqa: BLE001
        return "invalid", f"breaks the recording contract: {exc}"[:300]
    for name, var in ds.data_vars.items():
        if not np.all(np.isfinite(var.values)):
            return "invalid", f"channel {name} holds NaN/Inf"
    if truncation and source.declared_length:  # a prefix gives the original values, or fewer, said
        n = min(got["n"], want["n"])
        for name, orig in zip(got["channels"], want["channels"]):
            a, r = ds[name].values[:n], ref[orig].values[:n]
            if not np.array_equal(a, r):
                k = int(np.flatnonzero(a != r)[0])
                return "silent", f"truncated file read with channel {name} changed at sample {k}"
    if got["channels"] != want["channels"]:
        return "renamed", f"channels {got['channels']} instead of {want['channels']}"
    return "ok", ""


def _peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def limit_address_space(extra_mb: int) -> None:
    try:
        with open("/proc/self/status") as fh:
            vm = next(int(ln.split()[1]) for ln in fh if ln.startswith("VmSize")) * 1024
        limit = vm + extra_mb * 1024 * 1024
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    except (OSError, ValueError, StopIteration):  # not Linux: no limit, the RSS check remains
        pass


def scratch() -> Path:
    base = "/dev/shm" if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK) else None
    return Path(tempfile.mkdtemp(prefix="bearing_lab_fuzz_", dir=base))


def worker(name: str, seed: int, mem_mb: int) -> None:
    """Serve mutant indices on stdin, one JSON verdict a line on the original stdout."""
    os.environ.setdefault("BEARING_LAB_READ_TIMEOUT", "5")  # guarded readers give up first
    proto = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)  # anything a library prints goes to stderr, never into the protocol
    source = SOURCES[name]
    mirror = Path(os.environ.get("BEARING_LAB_MIRROR", "../shared/data"))
    tmp = scratch()
    try:
        original = source.build(mirror, tmp)
        data = original.read_bytes()
        hot = hot_spots(data, source.fmt)
        ref = _open_quietly(original, source.options)
        ref.load()
        limit_address_space(max(3 * mem_mb, 2048))
        base = _peak_rss_mb()
        proto.write(json.dumps({"ready": _summary(ref), "bytes": len(data)}) + "\n")
        faults = _injected_faults()
        for line in sys.stdin:
            index = int(line)
            blob, desc, trunc = mutant(source, data, hot, seed, index)
            d = tmp / str(index)
            d.mkdir()
            p = d / original.name
            p.write_bytes(blob)
            try:
                if index in faults:  # the harness's own test: it must see each of these
                    v, detail = _inject(faults[index], p)
                else:
                    v, detail = verdict(p, source, ref, trunc)
            finally:
                shutil.rmtree(d, ignore_errors=True)
            grown = _peak_rss_mb() - base
            if grown > mem_mb:
                v, detail = "memory", f"peak memory grew by {grown:.0f} MB ({detail})"
            proto.write(json.dumps({"i": index, "v": v, "op": desc, "detail": detail}) + "\n")
            if v == "memory":
                return  # a fresh worker gets a fresh peak
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _injected_faults() -> dict[int, str]:
    """``BEARING_LAB_FUZZ_FAULTS="crash=3,hang=5,uncaught=7,silent=9"``: faults to inject."""
    out = {}
    for item in filter(None, os.environ.get("BEARING_LAB_FUZZ_FAULTS", "").split(",")):
        kind, index = item.split("=")
        out[int(index)] = kind
    return out


def _inject(kind: str, path: Path) -> tuple[str, str]:
    if kind == "crash":
        os.kill(os.getpid(), signal.SIGSEGV)
    if kind == "hang":
        time.sleep(3600)
    if kind == "uncaught":
        return exception_verdict(TypeError("injected"), path)
    return "silent", "injected"


# ------------------------------------------------------------------ the parent
class Worker:
    def __init__(self, name, seed, mem_mb, startup_s=120.0):
        cmd = [sys.executable, "-m", "bearing_lab.io._fuzz", "worker", name, str(seed), str(mem_mb)]
        self._boot(cmd, name, startup_s)

    def _boot(self, cmd, name, startup_s=120.0):
        self._select = select.select
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, text=True, bufsize=1)
        first = self.answer(startup_s)
        if first is None or "ready" not in first:
            self.stop()
            raise RuntimeError(f"fuzz worker for {name!r} did not start (is the mirror set?)")
        self.ready = first
        return self

    def answer(self, timeout):
        ready, _, _ = self._select([self.proc.stdout], [], [], timeout)
        if not ready:
            return None
        line = self.proc.stdout.readline()
        return json.loads(line) if line else {}

    def stop(self):
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()


def fuzz_source(name: str, n: int, *, seed: int = 0, start: int = 0, timeout: float = 20.0,
                mem_mb: int = 512, keep: Path | None = None) -> dict:
    """Run mutants ``start .. start+n-1`` of one source; return counts and examples."""
    counts = {v: 0 for v in VERDICTS}
    examples: dict[str, list] = {}
    w = Worker(name, seed, mem_mb)
    t0 = time.perf_counter()
    try:
        for i in range(start, start + n):
            w.proc.stdin.write(f"{i}\n")
            w.proc.stdin.flush()
            ans = w.answer(timeout)
            if ans is None or not ans:
                if ans is None:
                    v, detail = "hang", f"no answer within {timeout:g} s"
                else:
                    w.stop()
                    v, detail = "crash", f"worker died with status {w.proc.returncode}"
                w.stop()
                ans = {"i": i, "v": v, "detail": detail, "op": _describe(name, seed, i)}
                w = Worker(name, seed, mem_mb)
            elif ans["v"] == "memory":
                w.stop()
                w = Worker(name, seed, mem_mb)
            counts[ans["v"]] += 1
            if ans["v"] in BAD:
                examples.setdefault(ans["v"], [])
                if len(examples[ans["v"]]) < 10:
                    examples[ans["v"]].append({k: ans[k] for k in ("i", "op", "detail")})
                if keep is not None:
                    _save(name, seed, i, Path(keep))
    finally:
        w.stop()
    return {"source": name, "seed": seed, "mutants": n, "counts": counts, "examples": examples,
            "cpu_note": "wall time; the machine may be shared", "wall_s": time.perf_counter() - t0}


def _source_bytes(name):
    source = SOURCES[name]
    mirror = Path(os.environ.get("BEARING_LAB_MIRROR", "../shared/data"))
    tmp = scratch()
    try:
        p = source.build(mirror, tmp)
        return source, p.name, p.read_bytes()
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _describe(name, seed, index):
    source, _, data = _source_bytes(name)
    return mutant(source, data, hot_spots(data, source.fmt), seed, index)[1]


def _save(name, seed, index, keep: Path) -> Path:
    source, fname, data = _source_bytes(name)
    blob = mutant(source, data, hot_spots(data, source.fmt), seed, index)[0]
    d = keep / f"{name}-{seed}-{index}"
    d.mkdir(parents=True, exist_ok=True)
    (d / fname).write_bytes(blob)
    return d / fname


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bearing_lab.io._fuzz")
    sub = ap.add_subparsers(dest="cmd", required=True)
    w = sub.add_parser("worker")
    w.add_argument("name")
    w.add_argument("seed", type=int)
    w.add_argument("mem_mb", type=int)
    r = sub.add_parser("repro", help="write one mutant and say what reading it gives")
    r.add_argument("name", choices=sorted(SOURCES))
    r.add_argument("seed", type=int)
    r.add_argument("index", type=int)
    r.add_argument("-o", "--out", default=".", help="directory for the mutant file")
    args = ap.parse_args(argv)
    if args.cmd == "worker":
        worker(args.name, args.seed, args.mem_mb)
        return 0
    p = _save(args.name, args.seed, args.index, Path(args.out))
    print(f"{p}: {_describe(args.name, args.seed, args.index)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
