"""Sub-commands ``import``, ``info`` and ``data`` (``data fetch``, ``data list``).

Why here: the CLI only parses arguments and prints; reading is
:func:`bearing_lab.io.open_recording`, the summary :func:`bearing_lab.io.summary.describe`,
writing :func:`bearing_lab.io.to_netcdf` and fetching :func:`bearing_lab.datasets.fetch`.  Every problem with the input
is a :class:`~bearing_lab.errors.RecordingError`, which the CLI prints as one
line with exit status 2.
"""
from __future__ import annotations

import json
import sys
import warnings
from pathlib import Path

from . import check_output_path
from ..errors import RecordingError
from ..utils._json import dumps


def _options(args) -> dict:
    opts = {}
    if getattr(args, "sensitivity", None):
        opts["sensitivity"] = False if args.sensitivity.lower() in ("none", "off") else args.sensitivity
    if getattr(args, "fs", None) is not None:
        opts["fs"] = args.fs
    if getattr(args, "channels", None):
        opts["channels"] = [c for c in args.channels.split(",") if c]
    if getattr(args, "units", None):
        opts["units"] = args.units
    if getattr(args, "allow_truncated", False):
        opts["allow_truncated"] = True
    if getattr(args, "full_scale", None):
        opts["full_scale"] = args.full_scale
    if getattr(args, "record", None) is not None:
        opts["record"] = args.record
    return opts


def _add_read_options(p):
    p.add_argument("--format", "-f", default=None,
                   help="reader name (default: sniffed from the content); see `bearing-lab info --formats`")
    p.add_argument("--sensitivity", default=None,
                   help="sensor sensitivity for voltage channels, e.g. 9.91mV/g ('none' keeps volts)")
    p.add_argument("--fs", type=float, default=None, help="sampling rate, Hz (overrides the file)")
    p.add_argument("--channels", default=None, help="comma-separated channel names to read")
    p.add_argument("--units", default=None,
                   help="unit of the stored values where the file has none or an unknown one (e.g. g)")
    p.add_argument("--allow-truncated", action="store_true",
                   help="keep what a truncated file holds (UFF, IMS, TDMS, WAV) instead of refusing it; "
                        "the recording then says so in its warnings and attributes")
    p.add_argument("--full-scale", default=None, help="WAV calibration, e.g. '5 V' or '50 g'")
    p.add_argument("--record", type=int, default=None, help="CWRU record number in a multi-record file")


def _open(args, arrays_only=False):
    from ..io import open_recording, read_arrays  # the command's imports load when it runs
    opts = _options(args)
    fmt = args.format
    if fmt is None:
        from ..io import guess_format
        p = Path(args.file)
        if p.is_file() and p.stat().st_size:
            fmt = guess_format(p)
    if fmt is not None:
        from ..io import ENGINES
        if fmt in ENGINES:  # drop CLI options this reader does not take, unless given on purpose
            known = ENGINES[fmt]().option_names()
            dropped = [k for k in opts if k not in known]
            if dropped:
                flags = ", ".join("--" + k.replace("_", "-") for k in dropped)
                raise RecordingError(f"{args.file}: the {fmt!r} reader does not use {flags}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # they are in ds.attrs['warnings'] and printed below
        return (read_arrays if arrays_only else open_recording)(args.file, format=fmt, **opts)


def _cmd_import(args) -> int:
    from ..io import get_warnings, to_netcdf  # the command's imports load when it runs
    from ..io.summary import dataset_kind, describe
    check_output_path(args.output, force=args.force)  # before reading: a bad -o is said at once
    ds = _open(args)
    if args.rpm is not None:
        from ..io import speed_problem
        problem = speed_problem(args.rpm)
        if problem is not None:
            raise RecordingError(f"--rpm {args.rpm:g} {problem}: give the shaft speed as a positive "
                                 "number of r/min")
        old = ds.attrs.get("shaft_speed_rpm")
        ds.attrs["shaft_speed_rpm"] = float(args.rpm)
        ds.attrs["shaft_speed_source"] = "given at import (--rpm)" + (f"; the file stored {old:g}" if old else "")
    to_netcdf(ds, args.output)
    for w in get_warnings(ds):
        print(f"warning: {w}", file=sys.stderr)
    n = ds.sizes["time"]
    fs = ds.attrs["sampling_rate_hz"]
    if args.json:
        print(dumps({**describe(ds, args.file), "output": args.output}, indent=1))
    elif not args.quiet:
        print(f"{args.output}: {len(ds.data_vars)} channel(s) {', '.join(ds.data_vars)}, {n} samples "
              f"at {fs:g} Hz ({n / fs:.4g} s), reader {ds.attrs.get('reader') or 'netcdf (' + dataset_kind(ds) + ')'}")
    return 0


def _fmt(v, spec="", none="-"):
    return none if v is None else format(v, spec)


def _cmd_info(args) -> int:
    if args.formats:
        from ..io import list_engines  # the command's imports load when it runs
        if args.json:
            print(dumps(list_engines(), indent=1))
            return 0
        for name, desc in list_engines().items():
            print(f"{name:14s} {desc}")
        return 0
    if not args.file:
        raise RecordingError("info: give a FILE (or --formats)")
    from ..io.summary import describe
    ds = _open(args, arrays_only=True)  # no Dataset: info prints without importing xarray
    d = describe(ds, args.file)
    if args.json:
        print(dumps(d, indent=1))
        return 0
    if args.quiet:   # the file reads: exit status 0, nothing printed
        return 0
    print(f"file:      {d['file']}")
    what = d["reader"] if d["kind"] == "recording" else \
        f"{d['kind']} of scene {d['scene']!r}" if d["scene"] else d["kind"]
    print(f"reader:    {what}    sha256 {d['sha256'][:16]}…" if d["sha256"] else f"reader:    {what}")
    print(f"rate:      {d['sampling_rate_hz']:g} Hz, {d['samples']} samples, "
          f"{_fmt(d['duration_s'], '.4g')} s from {_fmt(d['start_time_s'], '.6g')} s")
    if d["shaft_speed_rpm"] is not None:
        print(f"shaft:     {d['shaft_speed_rpm']:g} rpm" + (f", bearing {d['bearing']}" if d["bearing"]
                                                          else ""))
    print(f"channels:  (default {_fmt(d['default_channel'])})")
    for k, c in d["channels"].items():
        dims = "" if c["dims"] == ["time"] else f" dims ({', '.join(c['dims'])})"
        print(f"  {k:18s} {_fmt(c['units']):6s} (file: {c['original_units'] or '-'}) "
              f"{_fmt(c['quantity']):13s} rms {_fmt(c['rms'], '.4g')}{dims}")
    print(f"warnings:  {len(d['warnings'])}")
    for w in d["warnings"]:
        print(f"  - {w}")
    return 0


def _cmd_fetch(args) -> int:
    from .. import datasets  # the command's imports load when it runs
    got = {}
    for name in args.names:
        got[name] = str(datasets.fetch(name, mirror=args.mirror, dest=args.dest, download=not args.no_download))
        if not (args.quiet or args.json):
            print(f"{name}: {got[name]}")
    if args.json:
        print(dumps(got, indent=1))
    return 0


def _cmd_sample(args) -> int:
    from importlib import resources  # the command's imports load when it runs
    import shutil
    out = check_output_path(args.output, force=args.force, suffixes=(".uff",))
    src = resources.files("bearing_lab").joinpath("data", "sample_recording.uff")
    with resources.as_file(src) as p:
        shutil.copyfile(p, out)
    if args.json:
        from ..datasets import SAMPLE
        print(dumps({"file": str(out), **SAMPLE}, indent=1))
    elif not args.quiet:
        print(f"{out}: the sample recording (made by bearing_lab: a simulated 6308 with an outer-race defect, "
              f"1 s at 12.8 kHz, stored in volts at 9.91 mV/g; import it with --sensitivity 9.91mV/g)")
    return 0


def _cmd_list(args) -> int:
    from .. import datasets  # the command's imports load when it runs
    rows = []
    for r in datasets.load_registry().values():
        if args.dataset and not r.dataset.startswith(args.dataset):
            continue
        if args.json or args.quiet:
            rows.append({"name": r.name, "dataset": r.dataset, "sha256": r.sha256 or None, "defect": r.defect,
                         "defect_size_in": r.defect_size_in, "defect_position": r.defect_position,
                         "load_hp": r.load_hp, "rpm": r.rpm, "fs_hz": r.fs_hz})
            continue
        cond = ", ".join(x for x in (r.defect, f"{r.defect_size_in} in" if r.defect_size_in else "",
                                     r.defect_position, f"{r.load_hp:g} hp" if r.load_hp is not None
                                     else "", f"{r.rpm:g} rpm" if r.rpm else "",
                                     f"{r.fs_hz:g} Hz" if r.fs_hz else "") if x)
        print(f"{r.name:34s} {'sha256' if r.sha256 else 'no-hash':7s} {cond}")
    if args.json:
        print(dumps(rows, indent=1))
    return 0


def register(subparsers) -> None:
    """Add ``import``, ``info`` and ``data`` to the ``bearing-lab`` parser."""
    p = subparsers.add_parser("import", help="read a rig recording and write it as netCDF4",
                              description="Read a recording (UFF58/58b, Testlab MAT/text, CSV, WAV, "
                              "CWRU/MFPT .mat, IMS, TDMS, MDF4) into SI units and write netCDF4.")
    p.add_argument("file", help="the recording")
    _add_read_options(p)
    p.add_argument("--rpm", type=float, default=None,
                   help="shaft speed, r/min, stored in the output (validation cases read it with speed = \"file\")")
    p.add_argument("-o", "--output", required=True, help="output .nc file")
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p.add_argument("--json", action="store_true", help="print what was written (channels, rate, warnings) as JSON")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors and the file's warnings")
    p.set_defaults(func=_cmd_import)

    p = subparsers.add_parser("info", help="channels, rate, duration, units and warnings of a recording")
    p.add_argument("file", nargs="?", help="a recording or a .nc")
    _add_read_options(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--formats", action="store_true", help="list the readers and exit")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="print nothing: exit status 0 when the file reads, 2 (and the reason) when not")
    p.set_defaults(func=_cmd_info)

    p = subparsers.add_parser("data", help="registered public recordings (fetch, list) and the sample recording")
    sub = p.add_subparsers(dest="data_command", metavar="ACTION")
    f = sub.add_parser("fetch", help="copy (mirror) or download registered recordings, hash-checked")
    f.add_argument("names", nargs="+", metavar="NAME", help="registry name, e.g. cwru/130_OR007@6_0.mat")
    f.add_argument("--mirror", default=None, help="local mirror directory (default $BEARING_LAB_MIRROR)")
    f.add_argument("--dest", default=None, help="target directory (default data/cache or $BEARING_LAB_DATA)")
    f.add_argument("--no-download", action="store_true", help="never use the network")
    f.add_argument("--json", action="store_true", help="print {name: path} as JSON")
    f.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    f.set_defaults(func=_cmd_fetch)
    sm = sub.add_parser("sample", help="write the sample recording bearing_lab ships (a stand-in it made itself)",
                        description="Copy the sample recording shipped with bearing_lab: a simulated 6308 with a "
                                    "hidden 3 x 1 mm outer-race defect at 320 N and 1800 r/min (speed jitter, a "
                                    "4.3 kHz housing resonance, machine tones, sensor noise), 1 s at 12.8 kHz, "
                                    "stored as an accelerometer's voltage at 9.91 mV/g in UFF 58b. Made by "
                                    "bearing_lab.validation.standin.make_sample_recording; no third-party data.")
    sm.add_argument("-o", "--output", default="recording.uff", help="file to write (default recording.uff)")
    sm.add_argument("--force", action="store_true", help="overwrite an existing file")
    sm.add_argument("--json", action="store_true", help="print the file and how it was made as JSON")
    sm.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    sm.set_defaults(func=_cmd_sample)
    ls = sub.add_parser("list", help="list the registry")
    ls.add_argument("--dataset", default=None, help="filter by dataset prefix (cwru, ims, mfpt, lms)")
    ls.add_argument("--json", action="store_true", help="print the registry entries as JSON")
    ls.add_argument("-q", "--quiet", action="store_true", help="print nothing (exit status 0: the registry reads)")
    ls.set_defaults(func=_cmd_list)
    p.set_defaults(func=lambda a: (p.print_help(), 2)[1])
