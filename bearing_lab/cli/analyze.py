"""Sub-command ``analyze``: metrics, shaft speed, fault families and a graded diagnosis of one channel.

Why here: the CLI only reads, picks a channel and the speed prior, and prints;
the analysis is :func:`bearing_lab.analysis.analyze`, so the JSON printed here is
exactly what a script gets from Python (``docs/analysis.md`` describes it).

Speed: by default the file's stored speed (``shaft_speed_rpm``: CWRU ``X###RPM``,
MFPT ``rate``, simulations) is the prior (``speed_source`` "file"); ``--rpm R``
gives one ("given"); ``--rpm none`` ignores any stored speed (blind); a tacho
channel, named with ``--tacho`` or found by its name (tacho, tach, keyphasor,
once-per-rev), is used first.
"""
from __future__ import annotations

import sys
from pathlib import Path
import warnings

from . import check_output_path
from ..utils._json import dumps


def register(subparsers):
    p = subparsers.add_parser(
        "analyze", help="metrics, shaft speed, fault families and a graded diagnosis of one channel",
        description="Analyse one channel of a recording or a bearing_lab .nc file: metrics, shaft speed "
                    "(stored, given, from a tacho or from the signal), bearing fault families in three "
                    "envelope spectra, and a verdict: diagnosed (outer_race, inner_race or ball), "
                    "uncertain (with the candidates and the evidence) or no fault evidence.")
    p.add_argument("file", help="a recording (any format bearing-lab import reads) or a .nc")
    p.add_argument("--channel", "-c", default=None,
                   help="variable to analyse (default: the file's default channel, else the first)")
    p.add_argument("--bearing", "-b", default=None,
                   help="catalog bearing, e.g. 6205, 6203, 6308, ZA-2115, MFPT "
                        "(default: from the file's 'bearing' attribute)")
    p.add_argument("--fs", type=float, default=None, metavar="HZ",
                   help="sampling rate in Hz, for files that store none (CWRU records outside the "
                        "registry, bare text); overrides a stored rate")
    p.add_argument("--rpm", default=None,
                   help="shaft speed in r/min used as a prior; 'none' ignores a stored speed (blind "
                        "estimate); 'file' requires the stored one (default: the stored speed if the "
                        "file has one, else blind)")
    p.add_argument("--tacho", default=None, metavar="CHANNEL",
                   help="tacho channel (once-per-rev pulses) giving the speed; 'none' ignores one "
                        "(default: a channel named tacho, tach, keyphasor or once-per-rev)")
    p.add_argument("--pulses-per-rev", type=int, default=1, help="tacho pulses per revolution (default 1)")
    p.add_argument("--json", action="store_true",
                   help="print the result as JSON (fields described in the analysis documentation, docs/analysis.md)")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="print nothing but warnings and errors (--json and --plot still write their output)")
    p.add_argument("--plot", metavar="FILE.png", default=None,
                   help="also write a figure: waveform, spectrum, envelope spectrum with fault markers "
                        "(.png, .svg or .pdf)")
    p.add_argument("--force", action="store_true", help="overwrite an existing --plot file")
    p.set_defaults(func=run)
    return p


PLOT_SUFFIXES = (".png", ".svg", ".pdf")


def run(args) -> int:
    import numpy as np  # the command's imports load when it runs

    from ..analysis import analyze, plot_analysis
    from ..analysis.inputs import (bearing_name, not_an_acceleration, open_at_rate, pick_channel, pick_tacho,
                                   shaft_rpm, signal_rate)

    path = Path(args.file)
    if args.plot:  # before reading: a bad or existing figure path is said at once
        check_output_path(args.plot, force=args.force, suffixes=PLOT_SUFFIXES, flag="--plot")
    ds, fs, note = open_at_rate(path, args.fs, name="--fs")
    name = pick_channel(ds, args.channel, source=path)
    da = ds[name]
    fs = signal_rate(ds, name) if fs is None else fs
    bearing = bearing_name(ds, args.bearing, source=path)
    rpm, rpm_source = shaft_rpm(ds, args.rpm, source=path, name="--rpm")
    tacho_name = pick_tacho(ds, args.tacho, channel=name, source=path)
    x = np.asarray(da.values, dtype=float)
    units = da.attrs.get("units", "1")
    kw = dict(bearing=bearing, rpm=rpm, rpm_source=rpm_source, channel=str(name), units=units,
              pulses_per_rev=args.pulses_per_rev,
              tacho=None if tacho_name is None else np.asarray(ds[tacho_name].values, float))
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # overflow is reported once, below
        if args.plot:
            _, result = plot_analysis(x, fs, path=args.plot, **kw)
        else:
            result = analyze(x, fs, **kw)
    if note:
        result["notes"] = [note]
    not_acc = not_an_acceleration(da, name, units)
    if not_acc:
        result.setdefault("notes", []).append(not_acc)
        print(f"bearing-lab analyze: warning: {path.name} [{name}]: {not_acc}", file=sys.stderr)
    bad = [k for k, v in result.get("metrics", {}).items()
           if not isinstance(v, (int, float)) or not np.isfinite(v)]
    if bad:
        print(f"bearing-lab analyze: warning: {path.name} [{name}]: metrics {', '.join(bad)} are not "
              f"finite (the largest |value| is {np.max(np.abs(x)):.3g} {units}): reported as null",
              file=sys.stderr)
    if args.json:
        print(dumps(result, indent=1))  # no NaN/Infinity tokens: strict parsers read it
        return 0
    if args.quiet:
        return 0
    print(f"{path.name} [{name}]  fs {fs:g} Hz  bearing {bearing}" + (f"  ({note})" if note else ""))
    _print(result, units, tacho_name, args.plot)
    return 0


def _print(result, units, tacho_name, plot):
    """The result in words, after the line naming the file, channel, rate and bearing."""
    sp = result["speed"]
    ev = result["evidence"]
    if result["speed_source"] == "unresolved":
        print(f"shaft speed unresolved (speed_source unresolved): {sp['note']}")
    else:
        print(f"shaft {result['shaft_hz']:.3f} Hz ({60 * result['shaft_hz']:.1f} r/min), speed_source "
              f"{result['speed_source']}" + (f" (tacho channel {tacho_name})" if tacho_name else "")
              + f", {sp['status']}: {sp['note']}")
    head = f"verdict: {result['verdict']}  diagnosis: {result['diagnosis']}"
    if result["excitation_period_s"]:
        head += f"  (excitation period {1e3 * result['excitation_period_s']:.4f} ms)"
    print(head)
    if ev.get("candidates") and result["verdict"] != "diagnosed":
        print(f"  candidates: {', '.join(ev['candidates'])}")
    if ev.get("runner_up"):
        a, b = ev.get("leader_lines") or {}, ev.get("runner_up_lines") or {}

        def _lines(s):
            return f"{s['n_lines']} at a mean {s['mean_line_snr_db']:.1f} dB" if s.get("n_lines") else "none"
        print(f"  runner-up: {ev['runner_up']} (envelope-spectrum lines over the floor: {_lines(b)}; the "
              f"leader's: {_lines(a)}; evidence score {ev['margin_score']:.0f} lower)")
    print(f"  why: {ev['reason']}")
    if ev.get("band") and ev["band"]["low_hz"] is not None:
        b = ev["band"]
        print(f"  demodulation band {b['low_hz']:.0f}-{b['high_hz']:.0f} Hz, spectral kurtosis "
              f"{b['spectral_kurtosis']:.2f}{'' if b['impulsive'] else ' (not impulsive)'}"
              + (f", {b['rms']:.3g} {units} rms" if b.get("rms") is not None else "")
              + (f" (measurability floor {b['floor_rms']:.3g})" if b.get("floor_rms") else ""))
    for route, r in ev.get("routes", {}).items():
        print(f"  route {route}: {r['verdict']} ({r['reason']})")
    for r in ev.get("interpretations", []):
        print(f"  could be {r['diagnosis']} with the shaft at {r['shaft_hz']:.2f} Hz ({r['rpm']:.0f} r/min)")
    ff = result["fault_frequencies"]
    for k in ("bpfo", "bpfi", "bsf", "ftf"):
        r = ff[k]
        meas = "-" if r["measured_hz"] is None else f"{r['measured_hz']:.2f} Hz"
        print(f"  {k.upper():4s} expected {r['expected_hz']:8.2f} Hz  found {meas:>11s}  "
              f"SNR {r['snr_db']:5.1f} dB  harmonics {r['harmonics']}  sidebands {r['sidebands']}"
              + ("  detected" if r["detected"] else ""))
    for flag in ev.get("flags", []):
        print(f"  note: {flag}")
    m = result["metrics"]
    print("metrics: " + ", ".join(f"{k} {v:.4g}" for k, v in m.items()) + f"  (rms/peak in {units})")
    if plot:
        print(f"figure: {plot}")
