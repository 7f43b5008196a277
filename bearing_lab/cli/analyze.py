"""Sub-command ``analyze``: metrics, shaft speed, fault lines and diagnosis of one channel.

Why here: the CLI only reads, picks a channel and prints; the analysis is
:func:`bearing_lab.analysis.analyze`, so the JSON printed here is exactly what a
script gets from Python (contract.md's ``analyze --json`` schema).

``--rpm`` is a nominal speed used as a prior; ``--rpm file`` takes the file's
stored ``shaft_speed_rpm`` (only when asked: stored speeds are nominal).
"""
from __future__ import annotations

from pathlib import Path
import sys

from ..errors import AnalysisError, RecordingError


def register(subparsers):
    p = subparsers.add_parser(
        "analyze", help="metrics, shaft speed, fault frequencies and diagnosis of one channel",
        description="Analyse one channel of a recording or a bearing_lab .nc file: metrics, shaft "
                    "speed (from the signal), bearing fault lines in the squared envelope spectrum "
                    "and a diagnosis (outer_race, inner_race, ball or none).")
    p.add_argument("file", help="a recording (any format bearing-lab import reads) or a .nc")
    p.add_argument("--channel", "-c", default=None,
                   help="variable to analyse (default: the file's default channel, else the first)")
    p.add_argument("--bearing", "-b", default=None,
                   help="catalog bearing, e.g. 6205, 6203, 6308, ZA-2115, MFPT "
                        "(default: from the file's 'bearing' attribute)")
    p.add_argument("--rpm", default=None,
                   help="nominal shaft speed in r/min (a prior for the estimate), or 'file' to use "
                        "the file's stored shaft_speed_rpm")
    p.add_argument("--json", action="store_true", help="print the result as JSON (contract.md)")
    p.add_argument("--plot", metavar="FILE.png", default=None,
                   help="also write a figure: waveform, spectrum, SES with fault-frequency markers")
    p.set_defaults(func=run)
    return p


def _open(path: Path):
    try:
        from ..io import open_recording
    except ImportError:
        open_recording = None
    if not path.is_file():
        raise RecordingError(f"{path}: no such file")
    if open_recording is not None:
        return open_recording(path)
    if path.suffix == ".nc":
        import xarray as xr
        try:
            return xr.open_dataset(path)
        except (OSError, ValueError) as exc:
            raise RecordingError(f"{path}: cannot read as netCDF: {exc}") from None
    raise RecordingError(f"{path}: recording import (bearing_lab.io.open_recording) is not available "
                         "in this installation; give a .nc file")


def _pick_channel(ds, name, path):
    candidates = [v for v, da in ds.data_vars.items() if "time" in da.dims and da.ndim == 1]
    if name is not None:
        if name not in ds.data_vars:
            raise AnalysisError(f"{path}: no channel {name!r}; the file has {', '.join(map(str, ds.data_vars))}")
        if name not in candidates:
            raise AnalysisError(f"{path}: channel {name!r} is not a 1-D time signal "
                                f"(dims {ds[name].dims}); pick one of {', '.join(candidates)}")
        return name
    default = ds.attrs.get("default_channel")
    if default in candidates:
        return default
    for pref in ("outer_ring_acc_y", "outer_ring_acc_x"):
        if pref in candidates:
            return pref
    if not candidates:
        raise AnalysisError(f"{path}: no 1-D time signal to analyse")
    return candidates[0]


def _bearing_name(ds, given, path):
    from ..bearings import CATALOG
    if given is not None:
        return given
    attr = str(ds.attrs.get("bearing", ""))
    if attr in CATALOG:
        return attr
    hits = [k for k in CATALOG if k.lower() in attr.lower()]
    if attr and len(hits) == 1:
        return hits[0]
    reader = str(ds.attrs.get("reader", ""))
    if reader.upper() in CATALOG:
        return reader.upper()
    raise AnalysisError(f"{path}: the file names no catalog bearing (bearing attribute {attr!r}); "
                        f"give --bearing, one of {', '.join(sorted(CATALOG))}")


def _rpm(ds, value, path):
    if value is None:
        return None
    if str(value).lower() == "file":
        if "shaft_speed_rpm" not in ds.attrs:
            raise AnalysisError(f"{path}: --rpm file given but the file stores no shaft_speed_rpm")
        return float(ds.attrs["shaft_speed_rpm"])
    try:
        rpm = float(value)
    except ValueError:
        raise AnalysisError(f"--rpm {value!r} is not a number (r/min) nor 'file'") from None
    if not rpm > 0:
        raise AnalysisError(f"--rpm {value!r} must be a positive speed in r/min")
    return rpm


def run(args) -> int:
    import numpy as np

    from ..analysis import analyze, plot_analysis
    from ..analysis.xr import sampling_rate

    path = Path(args.file)
    ds = _open(path)
    name = _pick_channel(ds, args.channel, path)
    da = ds[name]
    fs = float(ds.attrs["sampling_rate_hz"]) if "sampling_rate_hz" in ds.attrs else sampling_rate(da)
    bearing = _bearing_name(ds, args.bearing, path)
    rpm = _rpm(ds, args.rpm, path)
    x = np.asarray(da.values, dtype=float)
    units = da.attrs.get("units", "1")
    kw = dict(bearing=bearing, rpm=rpm, channel=str(name), units=units)
    import warnings
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # overflow is reported once, below
        if args.plot:
            _, result = plot_analysis(x, fs, path=args.plot, **kw)
        else:
            result = analyze(x, fs, **kw)
    bad = [k for k, v in result.get("metrics", {}).items() if v is None or not np.isfinite(v)]
    if bad:
        print(f"bearing-lab analyze: warning: {path.name} [{name}]: metrics {', '.join(bad)} are not "
              f"finite (the largest |value| is {np.max(np.abs(x)):.3g} {units}): reported as null",
              file=sys.stderr)
    if args.json:
        from .._json import dumps
        print(dumps(result, indent=1))  # no NaN/Infinity tokens: strict parsers read it
        return 0
    ff = result["fault_frequencies"]
    print(f"{path.name} [{name}]  fs {fs:g} Hz  bearing {bearing}  shaft {result['shaft_hz']:.3f} Hz "
          f"({60 * result['shaft_hz']:.1f} r/min)")
    print(f"diagnosis: {result['diagnosis']}"
          + (f"  (excitation period {1e3 * result['excitation_period_s']:.4f} ms)"
             if result["excitation_period_s"] else ""))
    for k in ("bpfo", "bpfi", "bsf", "ftf"):
        r = ff[k]
        meas = "-" if r["measured_hz"] is None else f"{r['measured_hz']:.2f} Hz"
        print(f"  {k.upper():4s} expected {r['expected_hz']:8.2f} Hz  found {meas:>11s}  "
              f"SNR {r['snr_db']:5.1f} dB  harmonics {r['harmonics']}")
    m = result["metrics"]
    print("metrics: " + ", ".join(f"{k} {v:.4g}" for k, v in m.items()) + f"  (rms/peak in {units})")
    if args.plot:
        print(f"figure: {args.plot}")
    return 0
