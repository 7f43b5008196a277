"""Structure-aware mutants: files whose header fields are set on purpose, read in a worker.

Byte mutants rarely hit a header field with a value chosen on purpose.  These cases build
files whose fields are set on purpose (a WAV block_align, a MAT element's class, dimensions
and compressed streams, a UFF increment or units set, a netCDF attribute), in the layouts
other writers produce (h5py for v7.3, xarray for foreign netCDF).  Every file the reader
accepts is compared with an independent decoder of the same bytes, so a silent change
(a dropped stream, interleaved columns, a real part kept, a scale of 0) is caught by
construction.  Verdicts as in :mod:`._fuzz`, plus ``unverified`` (read, but the independent decoder
cannot decode the file either: nothing to compare with) and ``refcrash`` (the independent
decoder, not bearing_lab, died).

Run by ``tests/io/test_io_fuzz_structured.py`` (a bounded set) and
``benchmarks/hostile_inputs.py --only structured`` (the full set); one case is rebuilt from its
kind, seed and index with :func:`structured_case`.
"""
from __future__ import annotations

import json
import os
from pathlib import Path
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import warnings
import zlib

import lazy_loader as lazy
import numpy as np

from .. import schema
from ..units import G
from . import _fuzz
from ._fuzz import Worker, exception_verdict, limit_address_space, scratch
from ._testing import uff58_block

# the structured mutants' format libraries: loaded when a mutant of that format is made
h5py = lazy.load("h5py")
netCDF4 = lazy.load("netCDF4")
pyuff = lazy.load("pyuff")
scipy_io = lazy.load("scipy.io", suppress_warning=True)

STRUCT_KINDS = ("mat5", "v73", "netcdf", "wav", "uff", "special")
STRUCT_VERDICTS = ("ok", "refused", "unverified", "uncaught", "silent", "invalid", "crash", "hang",
                   "refcrash")


def _field(rng, fields: dict):
    """Nominal values for every field but one (or none), which gets one of its hostile values:
    one change per case, so each outcome is attributed to a field."""
    chosen = rng.choice([*fields, "none"])
    out = {k: v[0] for k, v in fields.items()}
    if chosen != "none":
        hostile = fields[chosen][1]
        out[chosen] = hostile[int(rng.integers(0, len(hostile)))]
    return out, str(chosen)


def _mi(typ, payload: bytes) -> bytes:
    """One MAT v5 data element (tag + payload padded to 8 bytes)."""
    return struct.pack("<II", typ, len(payload)) + payload + b"\0" * (-len(payload) % 8)


def _mat5_array(name: str, cls: int, dims, data_type: int, real: bytes, imag: bytes | None = None,
                logical=False) -> bytes:
    flags = cls | (0x800 if imag is not None else 0) | (0x200 if logical else 0)
    body = (_mi(6, struct.pack("<II", flags, 0)) + _mi(5, struct.pack(f"<{len(dims)}i", *dims))
            + _mi(1, name.encode()) + _mi(data_type, real)
            + (_mi(data_type, imag) if imag is not None else b""))
    return _mi(14, body)


def _mat5_file(elements) -> bytes:
    head = b"MATLAB 5.0 MAT-file, bearing_lab structured fuzz".ljust(116, b" ") + bytes(8)
    return head + b"\x00\x01IM" + b"".join(elements)


_MAT_CLASSES = {"double": (6, 9, "<f8"), "single": (7, 7, "<f4"), "int16": (10, 3, "<i2"),
                "int32": (12, 5, "<i4"), "uint8": (9, 2, "<u1")}


def _case_mat5(rng, tmp: Path, n: int):
    """A CWRU-style file: X130_DE_time (+ X130_FE_time, X130RPM) with fields set on purpose."""
    x = np.round(np.sin(np.arange(n) / 3.7) * 100.0)
    f, chosen = _field(rng, {
        "class": ("double", ["single", "int16", "int32", "uint8", "complex", "logical"]),
        "shape": ((n, 1), [(1, n), (n, 2), (2, n), (n, 1, 1), (0, 1)]),
        "storage": (False, [True]),
        "fe": (True, [False]),
        "rpm": (1797.0, [1e12, 0.0, -5.0, float("nan"), None]),
        "mode": ("plain", ["one stream", "two streams", "junk after", "padded", "bomb"])})
    cls_name, shape = f["class"], f["shape"]
    count = int(np.prod(shape))
    vals = np.resize(x, count)
    desc = [cls_name, "x".join(map(str, shape))]
    if cls_name == "complex":
        el = _mat5_array("X130_DE_time", 6, shape, 9, vals.astype("<f8").tobytes(),
                         (vals / 2).astype("<f8").tobytes())
    elif cls_name == "logical":
        el = _mat5_array("X130_DE_time", 9, shape, 2, (vals > 0).astype("<u1").tobytes(), logical=True)
    else:
        cls, mi, dt = _MAT_CLASSES[cls_name]
        if f["storage"]:  # a storage type narrower than the class (MATLAB does this)
            mi, dt = 3, "<i2"
            desc.append("stored as int16")
        el = _mat5_array("X130_DE_time", cls, shape, mi, vals.astype(dt).tobytes())
    extra = []
    if f["fe"]:
        fe = _mat5_array("X130_FE_time", 6, (n, 1), 9, (2 * x).astype("<f8").tobytes())
        extra.append(fe)
        desc.append("with FE")
    rpm = f["rpm"]
    if rpm is not None:
        extra.append(_mat5_array("X130RPM", 6, (1, 1), 9, np.float64(rpm).astype("<f8").tobytes()))
        desc.append(f"rpm {rpm}")
    mode = f["mode"]
    desc.append(mode)
    desc.insert(0, f"[{chosen}]")
    if mode == "plain":
        elements = [el, *extra]
    elif mode == "one stream":
        elements = [_compressed(zlib.compress(e)) for e in [el, *extra]]
    elif mode == "two streams":  # the second stream holds the fan-end channel
        fe = _mat5_array("X130_FE_time", 6, (n, 1), 9, (2 * x).astype("<f8").tobytes())
        elements = [_compressed(zlib.compress(el) + zlib.compress(fe)), *extra]
    elif mode == "junk after":
        elements = [_compressed(zlib.compress(el) + bytes(rng.integers(0, 256, 16, dtype=np.uint8))),
                    *extra]
    elif mode == "padded":
        elements = [_compressed(zlib.compress(el) + b"\0" * 4), *extra]
    else:  # a small element that inflates to many times its size (zeros)
        big = _mat5_array("X130_DE_time", 6, (4_200_000, 1), 9, bytes(8 * 4_200_000))
        elements = [_compressed(zlib.compress(big, 9)), *extra]
        desc[1] = "4200000x1 zeros"
    p = tmp / "130_fuzz.mat"
    p.write_bytes(_mat5_file(elements))
    return p, {"fs": 12000}, " ".join(desc)


def _compressed(stream: bytes) -> bytes:
    return struct.pack("<II", 15, len(stream)) + stream


def _case_v73(rng, tmp: Path, n: int):
    """A CWRU-style MATLAB v7.3 file written with h5py (MATLAB stores arrays transposed)."""
    x = np.sin(np.arange(n) / 3.7)
    f, chosen = _field(rng, {"shape": ((1, n), [(n,), (n, 1), (2, n), (n, 2)]),
                             "dtype": ("<f8", ["<f4", "<i2", "complex"]),
                             "class": ("double", ["single", "int16", "char", "logical", ""])})
    shape, dtype, cls = f["shape"], f["dtype"], f["class"]
    vals = np.resize(x * 1000.0, int(np.prod(shape))).reshape(shape)
    p = tmp / "130_fuzz73.mat"
    with h5py.File(p, "w", userblock_size=512) as f:
        if dtype == "complex":
            data = np.zeros(shape, dtype=[("real", "<f8"), ("imag", "<f8")])
            data["real"], data["imag"] = vals, vals / 2
        else:
            data = vals.astype(dtype)
        d = f.create_dataset("X130_DE_time", data=data)
        if cls:
            d.attrs["MATLAB_class"] = np.bytes_(cls)
    with open(p, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: bearing_lab structured fuzz "
                 b"HDF5 schema 1.00 .")
    return p, {"fs": 12000}, f"[{chosen}] h5 shape {shape} {dtype} class {cls or 'none'}"


def _case_netcdf(rng, tmp: Path, n: int):
    """A netCDF written by xarray with bearing_lab's attributes set on purpose (or missing)."""
    import xarray as xr  # fuzz workers: memory limit, only what a format needs
    fs = 12000.0
    t = np.arange(n) / fs
    attrs = {"bearing_lab_version": "0", "source_file": "x", "source_sha256": "", "reader": "csv",
             "warnings": "", "default_channel": "acc", "sampling_rate_hz": fs}
    f, chosen = _field(rng, {"rate": (fs, ["12 kHz", float("nan"), 1.0, fs * 1.5, -fs, None]),
                             "rpm": (None, [1797.0, 1e12, 0.0, -1.0, "fast"]),
                             "drop": (None, ["reader", "bearing_lab_version"]),
                             "units": (True, [False]), "nan": (False, [True]),
                             "grid": (False, [True])})
    desc = [f"[{chosen}]"]
    rate = f["rate"]
    if rate is None:
        attrs.pop("sampling_rate_hz")
    else:
        attrs["sampling_rate_hz"] = rate
    desc.append(f"rate {rate!r}")
    rpm = f["rpm"]
    if rpm is not None:
        attrs["shaft_speed_rpm"] = rpm
        desc.append(f"rpm {rpm!r}")
    if f["drop"]:
        attrs.pop(f["drop"])
        desc.append(f"no {f['drop']}")
    vattrs = {"units": "m s-2", "quantity": "acceleration", "original_units": "m/s2"}
    if not f["units"]:
        vattrs.pop("units")
        desc.append("no units")
    values = np.sin(2 * np.pi * 157.0 * t)
    if f["nan"]:
        values[int(rng.integers(0, n))] = np.nan
        desc.append("a NaN")
    ds = xr.Dataset({"acc": ("time", values, vattrs)},
                    coords={"time": ("time", t, {"units": "s"})}, attrs=attrs)
    if f["grid"]:
        ds["grid"] = (("time", "k"), np.zeros((n, 2)), {"units": "m"})
        desc.append("2-D variable")
    p = tmp / "fuzz.nc"
    ds.to_netcdf(p, engine="netcdf4")
    return p, {}, " ".join(desc)


def _case_wav(rng, tmp: Path, n: int):
    """A 16-bit stereo WAV whose fmt fields are set on purpose."""
    x = (np.sin(np.arange(2 * n) / 3.7) * 20000).astype("<i2").reshape(n, 2)
    payload = x.tobytes()
    f, chosen = _field(rng, {"channels": (2, [1, 0, 3, 4]), "bits": (16, [8, 0, 12, 24, 32, 7]),
                             "tag": (1, [3, 2, 0xFFFE, 7]), "align": (4, [1, 2, 3, 8, 0]),
                             "rate": (12000, [0, 1, 2 ** 32 - 1])})
    channels, bits, tag, align, rate = f["channels"], f["bits"], f["tag"], f["align"], f["rate"]
    fmt = b"fmt " + struct.pack("<IHHIIHH", 16, tag, channels, rate, (rate * max(align, 1)) % 2 ** 32,
                                align, bits)
    data = b"data" + struct.pack("<I", len(payload)) + payload
    body = b"WAVE" + fmt + data
    p = tmp / "fuzz.wav"
    p.write_bytes(b"RIFF" + struct.pack("<I", len(body)) + body)
    return p, {"full_scale": "10 g"}, (f"[{chosen}] tag {tag} ch {channels} bits {bits} align "
                                       f"{align} rate {rate}")


_UFF_164 = ("    -1\n   164\n         2mm (milli newton)         2\n"
            "  {0:>25s}  1.00000000000000000D+00  1.00000000000000000D+00\n"
            "  2.73150000000000000D+02\n    -1\n")


def _case_uff(rng, tmp: Path, n: int):
    """A UFF 58b set with its increment, point count, unit label and units set chosen on purpose."""
    x = np.sin(np.arange(n) / 3.7)
    f, chosen = _field(rng, {
        "inc": ("1.00000E-03", ["1.00000E-320", "0.00000E+00", "-1.0000E-03", "1.00000E+300", "NaN",
                                "1.00000E-12"]),
        "num_pts": (n, [n - 1, n + 1, 2 * n, 1, 0]), "unit": ("m/s2", ["NONE", "g"]),
        "164": (None, ["1.00000000000000000D+03", "Infinity", "1.0D-300", "1.0D+200", "NaN", "0.0"]),
        "unit+164": ((None, None), [("NONE", "Infinity"), ("NONE", "1.0D-300"), ("NONE", "1.0D+03")])})
    inc, num, unit, f164 = f["inc"], f["num_pts"], f["unit"], f["164"]
    if f["unit+164"][0]:
        unit, f164 = f["unit+164"]
    body = uff58_block(x, binary=True, inc=inc, num_pts=num, unit=unit)
    if f164 is not None:
        body = _UFF_164.format(f164).encode() + body
    p = tmp / "fuzz.uff"
    p.write_bytes(body)
    return p, {}, f"[{chosen}] inc {inc} num_pts {num}/{n} unit {unit} 164 {f164}"


def _case_special(rng, tmp: Path, n: int):
    """Not a regular file: a FIFO, a device, a pseudo-file, a link loop, a dangling link, a dir."""
    kind = str(rng.choice(["fifo", "/dev/zero", "/dev/urandom", "/dev/null", "/proc/self/status",
                           "loop", "dangling", "directory"]))
    p = tmp / "special.uff"
    if kind == "fifo":
        os.mkfifo(p)
    elif kind == "loop":
        p.symlink_to(p)
    elif kind == "dangling":
        p.symlink_to(tmp / "nothing")
    elif kind == "directory":
        p.mkdir()
    else:
        if not os.path.exists(kind):
            kind = "directory"
            p.mkdir()
        else:
            p = Path(kind)
    return p, {}, kind


_STRUCT_BUILDERS = {"mat5": _case_mat5, "v73": _case_v73, "netcdf": _case_netcdf, "wav": _case_wav,
                    "uff": _case_uff, "special": _case_special}


def structured_case(kind: str, seed: int, index: int, tmp: Path):
    """Case ``index`` of ``kind`` for ``seed`` (always the same file): (path, options, description)."""
    rng = np.random.default_rng([seed, index, sum(map(ord, kind))])
    n = int(rng.choice([600, 1000, 4096]))
    return _STRUCT_BUILDERS[kind](rng, tmp, n)


class NotOneChannel(Exception):
    """The independent decoder finds content no recording channel can hold as read (a matrix,
    complex values, a second zlib stream, format fields that disagree): a reader that accepts
    the file has changed or dropped something."""


def _one_channel(v, name):
    v = np.asarray(v)
    if v.dtype.kind == "c" or v.dtype.names:
        raise NotOneChannel(f"{name} holds complex values")
    if v.ndim > 1 and sorted(v.shape)[-2] > 1:
        raise NotOneChannel(f"{name} is a {'x'.join(map(str, v.shape))} matrix")
    return v


def _mat5_streams(path: Path) -> None:
    """Inflate every compressed element with zlib alone: anything after its first stream is
    content (a second stream, appended bytes) that one stream's reader would drop."""
    data = path.read_bytes()
    pos = 128
    while pos + 8 <= len(data):
        typ, nb = struct.unpack_from("<II", data, pos)
        if typ == 15:
            d = zlib.decompressobj()
            d.decompress(data[pos + 8:pos + 8 + nb])
            if d.unused_data.strip(b"\0"):
                raise NotOneChannel(f"element at byte {pos}: {len(d.unused_data)} bytes after its "
                                    "zlib stream")
        pos += 8 + nb  # top-level elements follow each other without padding


def reference_values(path: Path, kind: str) -> dict | None:
    """What the file holds, decoded without bearing_lab: channel -> values in SI units; None
    when the independent decoder cannot decode the file (nothing to compare with).

    Raises
    ------
    NotOneChannel
        The file holds something no channel can be read as without a change.
    """
    if kind == "mat5":
        _mat5_streams(path)
        m = scipy_io.loadmat(path)  # only reached for files bearing_lab accepted
        out = {}
        for c in ("DE", "FE"):
            v = m.get(f"X130_{c}_time")
            if v is not None:
                v = _one_channel(v, f"X130_{c}_time")
                out[c] = np.asarray(v, dtype=np.float64).ravel(order="F") * G
        return out
    if kind == "v73":
        with h5py.File(path, "r") as f:
            d = f["X130_DE_time"]
            cls = d.attrs.get("MATLAB_class", b"")
            if cls in (b"char", b"logical"):
                raise NotOneChannel(f"X130_DE_time is of class {cls.decode()}, not numbers")
            v = _one_channel(d[()], "X130_DE_time")
            v = np.asarray(v, dtype=np.float64).T
        return {"DE": v.ravel(order="F") * G}
    if kind == "netcdf":
        with netCDF4.Dataset(path) as f:
            out = {k: np.asarray(v[:], dtype=np.float64) for k, v in f.variables.items()
                   if k != "time" and v.dimensions == ("time",)}
            out["__rate__"] = 1.0 / float(np.median(np.diff(np.asarray(f["time"][:], float))))
            stored = getattr(f, "sampling_rate_hz", None)
        if not (isinstance(stored, (int, float, np.number)) and abs(stored / out["__rate__"] - 1) < 1e-6):
            raise NotOneChannel(f"sampling_rate_hz {stored!r} against a {out['__rate__']:g} Hz time axis")
        return out
    if kind == "wav":  # the fmt fields, validated, decide the layout: decode the data chunk
        data = path.read_bytes()
        tag, ch, rate, _, align, bits = struct.unpack_from("<HHIIHH", data, 20)
        width = (bits + 7) // 8
        if ch == 0 or bits == 0 or align != ch * width:
            raise NotOneChannel(f"fmt fields disagree: {ch} channel(s) of {bits} bits in "
                                f"{align}-byte frames")
        if tag != 1 or width not in (1, 2, 4):
            return None  # float, 24-bit, extensible: not decoded here
        size = struct.unpack_from("<I", data, 40)[0]
        if size % align:
            raise NotOneChannel(f"a data chunk of {size} bytes in {align}-byte frames")
        code = {1: "<u1", 2: "<i2", 4: "<i4"}[width]
        raw = np.frombuffer(data, code, count=size // width, offset=44).reshape(-1, ch)
        scale = 2.0 ** (8 * width - 1)
        off = scale if width == 1 else 0.0
        out = {f"ch{j + 1}": (raw[:, j].astype(np.float64) - off) / scale * 10.0 * G
               for j in range(ch)}
        out["__rate__"] = float(rate)
        return out
    if kind == "uff":
        found = pyuff.UFF(str(path)).read_sets()
        found = found if isinstance(found, list) else [found]
        sets = [s for s in found if s.get("type") == 58]
        if len(sets) != 1:
            return None
        h, factor = sets[0], 1.0
        label = str(h.get("ordinate_axis_units_lab", "")).strip()
        units = [s for s in found if s.get("type") == 164]
        if (not label or label.upper() == "NONE") and units:  # SI = file value / length factor
            length = float(units[0].get("length", 1.0))
            factor = 1.0 / length if length else np.inf
            if not (np.isfinite(factor) and 1e-12 <= factor <= 1e12):
                raise NotOneChannel(f"a units set whose length factor {length!r} scales by {factor:g}")
        factor *= G if label == "g" else 1.0
        return {"acc": np.asarray(h["data"], dtype=np.float64) * factor,
                "__rate__": 1.0 / float(h["abscissa_inc"])}
    return None


def structured_verdict(path: Path, options: dict, kind: str) -> tuple[str, str]:
    """Read one structured case and compare what was read with the independent decoder."""
    try:
        ds = _fuzz._open_quietly(path, options)
    except KeyboardInterrupt:
        raise
    except BaseException as exc:  # noqa: BLE001
        return exception_verdict(exc, path)
    try:
        schema.check_dataset(ds, kind="recording" if "reader" in ds.attrs else None)
    except Exception as exc:  # noqa: BLE001
        return "invalid", f"breaks the contract: {exc}"[:300]
    _phase("reference")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ref = reference_values(path, kind)
    except NotOneChannel as exc:
        return "silent", f"read, but the file holds {exc}"[:200]
    except Exception as exc:  # noqa: BLE001 - the independent decoder refuses it
        return "unverified", f"independent decoder: {type(exc).__name__}: {exc}"[:200]
    if ref is None:
        return "unverified", "the independent decoder sees no single channel to compare"
    rate = ref.pop("__rate__", None)
    if rate is not None and not abs(float(ds.attrs["sampling_rate_hz"]) / rate - 1.0) < 1e-6:
        return "silent", f"sampling rate {ds.attrs['sampling_rate_hz']!r} Hz, the file's is {rate:g} Hz"
    for name, want in ref.items():
        if kind == "uff":
            name = next(iter(ds.data_vars))
        if name not in ds:
            return "silent", f"channel {name} of the file is missing from the recording"
        got = ds[name].values
        if got.shape != want.shape or not np.allclose(got, want, rtol=1e-6, atol=0.0):
            return "silent", f"channel {name}: {got.shape} values differ from the file's {want.shape}"
    if kind in ("mat5", "v73") and any(k not in ref for k in ds.data_vars):
        return "silent", "a channel the independent decoder does not see"
    return "ok", ""


def _phase(name: str) -> None:
    """Note what the worker is doing (the parent reads it when the worker dies)."""
    path = os.environ.get("BEARING_LAB_FUZZ_PHASE")
    if path:
        with open(path, "w") as fh:
            fh.write(name)


def structured_worker(kind: str, seed: int) -> None:
    """Serve case indices on stdin; one JSON verdict a line on the original stdout."""
    os.environ.setdefault("BEARING_LAB_READ_TIMEOUT", "5")
    proto = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)
    limit_address_space(2048)
    proto.write(json.dumps({"ready": kind}) + "\n")
    for line in sys.stdin:
        index = int(line)
        tmp = scratch()
        try:
            _phase("read")
            t0 = time.perf_counter()
            p, options, desc = structured_case(kind, seed, index, tmp)
            v, detail = structured_verdict(p, options, kind)
            proto.write(json.dumps({"i": index, "v": v, "op": desc, "detail": detail,
                                     "s": time.perf_counter() - t0}) + "\n")
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


def fuzz_structured(kind: str, n: int, *, seed: int = 0, timeout: float = 30.0) -> dict:
    """Run structured cases ``0 .. n-1`` of ``kind``; return counts, examples and times."""
    counts = {v: 0 for v in STRUCT_VERDICTS}
    examples: dict[str, list] = {}
    ops: dict[str, dict] = {}
    cmd = [sys.executable, "-m", "bearing_lab.io._fuzz_struct", kind, str(seed)]
    fd, phase_file = tempfile.mkstemp(prefix="bearing_lab_fuzz_phase_")
    os.close(fd)
    os.environ["BEARING_LAB_FUZZ_PHASE"] = phase_file

    def start():
        return Worker.__new__(Worker)._boot(cmd, kind)

    w = start()
    t0, slowest = time.perf_counter(), 0.0
    try:
        for i in range(n):
            w.proc.stdin.write(f"{i}\n")
            w.proc.stdin.flush()
            ans = w.answer(timeout)
            if not ans:
                code = w.proc.poll()
                w.stop()
                phase = Path(phase_file).read_text()
                if phase == "reference" and ans is not None:
                    v = "refcrash"
                else:
                    v = "hang" if ans is None else "crash"
                ans = {"i": i, "v": v, "op": "", "detail": f"worker status {code}", "s": timeout}
                w = start()
            counts[ans["v"]] += 1
            slowest = max(slowest, float(ans.get("s", 0.0)))
            ops.setdefault(ans["op"][:60], {}).setdefault(ans["v"], 0)
            ops[ans["op"][:60]][ans["v"]] += 1
            if ans["v"] not in ("ok", "refused") and len(examples.setdefault(ans["v"], [])) < 10:
                examples[ans["v"]].append({k: ans[k] for k in ("i", "op", "detail")})
    finally:
        w.stop()
        os.unlink(phase_file)
    return {"kind": kind, "seed": seed, "cases": n, "counts": counts, "examples": examples,
            "wall_s": time.perf_counter() - t0, "slowest_s": slowest, "by_case": ops}


def truncate_while_reading(target: Path, *, mb: float = 64.0, trials: int = 5, seed: int = 0) -> dict:
    """Write a large UFF 58b, then cut it to 100 kB while `bearing-lab info` reads it.

    Counts how each read ends: ``refused`` (a message), ``ok`` (read before the cut), or
    ``crash`` (a signal such as SIGBUS: the defect a memory-mapped reader had).
    """
    rng = np.random.default_rng(seed)
    n = int(mb * 1e6 / 8)
    x = np.sin(np.arange(n) / 3.7)
    block = uff58_block(x, binary=True)
    out = {"trials": trials, "refused": 0, "ok": 0, "crash": 0, "other": 0, "examples": []}
    for _ in range(trials):
        target.write_bytes(block)
        proc = subprocess.Popen([sys.executable, "-m", "bearing_lab", "info", str(target)],
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        time.sleep(float(rng.uniform(0.3, 1.5)))
        os.truncate(target, 100_000)
        _, err = proc.communicate(timeout=300)
        code = proc.returncode
        if code < 0:
            out["crash"] += 1
            out["examples"].append(f"signal {-code}")
        elif code == 2 and err.count("\n") == 1:
            out["refused"] += 1
            out["examples"].append(err.strip()[-160:])
        elif code == 0:
            out["ok"] += 1
        else:
            out["other"] += 1
            out["examples"].append(f"exit {code}: {err.strip()[-160:]}")
    target.unlink()
    return out


if __name__ == "__main__":  # the worker fuzz_structured starts: ``python -m bearing_lab.io._fuzz_struct KIND SEED``
    structured_worker(sys.argv[1], int(sys.argv[2]))
