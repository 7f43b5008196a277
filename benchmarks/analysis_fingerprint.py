"""``analyze``'s whole result on every mirror recording, to check that a speed-up changes no number.

For each recording channel of the mirror (the records of ``benchmarks/diagnosis_eval.py``) and for the
60 s synthetic record of ``benchmarks/analysis_speed.py``, ``analyze`` runs in three speed modes
(each recording also cropped to the longest length whose real FFT needs no padding, where the
envelope spectra are demodulated from the record's own DFT):
the stored speed (``rpm_source="file"``), the same speed given as a prior (``rpm_source="given"``)
and blind.  The result dicts (diagnosis, verdict, speed, margins, line SNRs, evidence, metrics) are
written as JSON; ``compare`` reports every number that differs by more than a relative 1e-9 and
every other value that differs at all.

Usage::

    python benchmarks/analysis_fingerprint.py dump OUT.json [--mirror DIR]
    python benchmarks/analysis_fingerprint.py compare BEFORE.json AFTER.json
"""
from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def _plain(v):
    if isinstance(v, dict):
        return {str(k): _plain(w) for k, w in v.items()}
    if isinstance(v, (list, tuple)):
        return [_plain(w) for w in v]
    if isinstance(v, np.ndarray):
        return _plain(v.tolist())
    if isinstance(v, (np.floating, float)):
        f = float(v)
        return f if math.isfinite(f) else repr(f)
    if isinstance(v, (np.integer, np.bool_)):
        return v.item()
    return v


def _modes(x, fs, bearing, rpm, channel=""):
    from bearing_lab.analysis import analyze
    out = {}
    runs = {"blind": {}}
    if rpm is not None:
        runs = {"stored": {"rpm": rpm, "rpm_source": "file"}, "prior": {"rpm": rpm}, **runs}
    for mode, kw in runs.items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                out[mode] = _plain(analyze(x, fs, bearing=bearing, channel=channel, **kw))
            except Exception as exc:  # noqa: BLE001 - recorded, compared like a result
                out[mode] = {"error": f"{type(exc).__name__}: {exc}"}
    return out


def _fast_length(n):
    """The longest length <= n whose real FFT needs no padding (a product of 2, 3 and 5)."""
    import scipy.fft
    while scipy.fft.next_fast_len(n, real=True) != n:
        n -= 1
    return n


def dump(path, mirror):
    import analysis_speed
    import diagnosis_eval
    from bearing_lab.io import open_recording
    res = {}
    analysis_speed.SECONDS = 60.0
    res["synthetic 60 s"] = _modes(analysis_speed.make_signal(), analysis_speed.FS, "6308", 60 * analysis_speed.FR)
    cache = {}
    for label, p, opts, channel, bearing, _truth, _group in diagnosis_eval.recordings(mirror):
        if p not in cache:
            cache = {p: open_recording(p, checksum=False, **opts)}
        ds = cache[p]
        x = ds[channel].values.astype(float)
        fs, rpm = float(ds.attrs["sampling_rate_hz"]), ds.attrs.get("shaft_speed_rpm")
        res[label] = _modes(x, fs, bearing, rpm, channel)
        print(label, {m: r.get("diagnosis", r.get("error")) for m, r in res[label].items()}, flush=True)
        n = _fast_length(x.size)
        if n != x.size:  # the record's DFT serves the envelope spectra only at such lengths: test them too
            res[f"{label} [:{n}]"] = _modes(x[:n], fs, bearing, rpm, channel)
    Path(path).write_text(json.dumps(res, indent=1, sort_keys=True))
    print(f"{len(res)} records -> {path}")


def _diff(a, b, where, out, rtol):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                out.append(f"{where}/{k}: only in {'after' if k not in a else 'before'}")
            else:
                _diff(a[k], b[k], f"{where}/{k}", out, rtol)
    elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (u, v) in enumerate(zip(a, b)):
            _diff(u, v, f"{where}[{i}]", out, rtol)
    elif isinstance(a, float) and isinstance(b, (int, float)) or isinstance(b, float) and isinstance(a, int):
        if abs(a - b) > rtol * max(abs(a), abs(b), 1e-300):
            out.append(f"{where}: {a!r} -> {b!r}")
    elif a != b:
        out.append(f"{where}: {str(a)[:80]} -> {str(b)[:80]}")


def compare(before, after, rtol=1e-9):
    a, b = json.loads(Path(before).read_text()), json.loads(Path(after).read_text())
    out = []
    _diff(a, b, "", out, rtol)
    n = sum(len(v) for v in a.values())
    print(f"{len(a)} records, {n} analyses: {len(out)} differences beyond {rtol:g}")
    for line in out[:200]:
        print(" ", line)
    return 1 if out else 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("dump")
    d.add_argument("out")
    d.add_argument("--mirror", default=os.environ.get("BEARING_LAB_MIRROR", "../shared/data"))
    c = sub.add_parser("compare")
    c.add_argument("before")
    c.add_argument("after")
    c.add_argument("--rtol", type=float, default=1e-9)
    args = ap.parse_args(argv)
    if args.cmd == "dump":
        dump(args.out, Path(args.mirror))
        return 0
    return compare(args.before, args.after, args.rtol)


if __name__ == "__main__":
    sys.exit(main())
