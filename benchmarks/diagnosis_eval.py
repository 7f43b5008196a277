"""Diagnosis on every recording we have and on the simulator's own cases: the table of
benchmarks/README_diagnosis.md.

What it runs (one fixed method, no per-file settings):

- every registered recording present in the mirror (CWRU drive end 12 and 48 kHz, fan
  end 12 kHz, MFPT, IMS set 2), each analysed twice: with the speed stored in the file as
  the prior ("stored") and without any speed ("blind", ``--rpm none``).  The truth is the
  registry's (the file name's) fault class; a *confident wrong label* is a diagnosed
  fault class that differs from it;
- the built-in scenes of the simulator (outer race, inner race, ball, healthy), 2 s
  each: noise-free, with a 1 mg (0.0098 m s-2) sensor floor, and for the fault scenes
  with white noise at 0, -6 and -12 dB of the signal's rms and with interference (50 Hz
  mains and harmonics at the signal's rms, plus random impacts ringing 4 kHz); the
  healthy scenes get interference of fixed size over the sensor floor; both modes;
- the CPU time of :func:`bearing_lab.analysis.analyze` on 10 s at 20 kHz
  (``time.process_time``, best of ``--repeat``, one thread).

Run: ``.venv/bin/python benchmarks/diagnosis_eval.py [--mirror DIR] [--quick] [--out FILE]``
(``--quick`` skips the simulations).  Prints Markdown; exits with 1 when a recording gets a
confident wrong label.
"""
from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

FAULTS = ("outer_race", "inner_race", "ball")
SCENES = {  # name: (built-in scene, overrides, truth)
    "paper-slot": ("paper-slot", {}, "outer_race"),
    "paper-O1": ("paper-O1", {}, "outer_race"),
    "paper-O2": ("paper-O2", {}, "outer_race"),
    "paper-O3": ("paper-O3", {}, "outer_race"),
    "cwru-or007-6": ("cwru-or007-6", {}, "outer_race"),
    "cwru-ir007": ("cwru-ir007", {}, "inner_race"),
    "cwru-ball007": ("cwru-ir007", {"defect.race": "ball"}, "ball"),
    "paper-healthy": ("paper-healthy", {}, "none"),
    "cwru-normal": ("cwru-normal", {}, "none"),
}


def _bearing_name(reg):
    for name in ("6203", "6205", "ZA-2115", "MFPT"):
        if name in reg.bearing:
            return name
    raise ValueError(f"no catalog bearing for {reg.bearing!r}")


def recordings(mirror):
    """[(label, path, open options, channel, bearing, truth)] for the registered files in the mirror."""
    from bearing_lab import datasets
    out = []
    for reg in datasets.load_registry().values():
        if reg.dataset == "lms" or not reg.defect:
            continue
        path = datasets.locate(reg.name, mirror=mirror)
        if path is None:
            continue
        if reg.dataset.startswith("cwru"):
            channel = "FE" if reg.dataset == "cwru-fe-12k" else "DE"
            out.append((reg.name, path, {"fs": reg.fs_hz}, channel, _bearing_name(reg), reg.defect, reg.dataset))
        elif reg.dataset == "mfpt":
            out.append((reg.name, path, {}, "acc", "MFPT", reg.defect, "mfpt"))
        elif reg.dataset == "ims-set2":
            for b in range(1, 5):
                truth = reg.defect if reg.defect_position == f"bearing {b}" else "none"
                out.append((f"{reg.name} b{b}", path, {}, f"b{b}", "ZA-2115", truth, "ims-set2"))
    return out


def _row(label, truth, group, res_stored, res_blind):
    def cell(r):
        band = r["evidence"].get("band") or {}
        return {"diagnosis": r["diagnosis"], "verdict": r["verdict"], "source": r["speed_source"],
                "status": r["speed"]["status"], "shaft_hz": r["shaft_hz"],
                "candidates": r["evidence"]["candidates"], "band_rms": band.get("rms"),
                "band_floor": band.get("floor_rms"),
                "hump": "hump" in r["evidence"]["reason"]}
    return {"label": label, "truth": truth, "group": group, "stored": cell(res_stored), "blind": cell(res_blind)}


def run_recordings(mirror):
    from bearing_lab.analysis import analyze
    from bearing_lab.io import open_recording
    rows = []
    cache = {}
    for label, path, opts, channel, bearing, truth, group in recordings(mirror):
        if path not in cache:
            cache = {path: open_recording(path, checksum=False, **opts)}
        ds = cache[path]
        x = ds[channel].values.astype(float)
        fs = float(ds.attrs["sampling_rate_hz"])
        rpm = ds.attrs.get("shaft_speed_rpm")
        stored = analyze(x, fs, bearing=bearing, rpm=rpm, rpm_source="file", channel=channel)
        blind = analyze(x, fs, bearing=bearing, channel=channel)
        rows.append(_row(label, truth, group, stored, blind))
    return rows


def _interference(n, fs, rng, hum_amp, impact_amp):
    """50 Hz mains with three harmonics and random impacts (7 a second) ringing 4 kHz."""
    t = np.arange(n) / fs
    hum = sum(hum_amp / h * np.sin(2 * np.pi * 50 * h * t + h) for h in range(1, 5))
    spikes = np.zeros(n)
    for t0 in np.sort(rng.uniform(0, t[-1], int(7 * t[-1]))):
        i0 = int(t0 * fs)
        tau = np.arange(min(400, n - i0)) / fs
        spikes[i0:i0 + tau.size] += impact_amp * np.exp(-2000 * tau) * np.sin(2 * np.pi * 4000 * tau)
    return hum + spikes


def _variants(x, fs, rng, healthy):
    """Noise and interference variants of a simulated signal.

    Fault scenes: white noise relative to the signal's rms (0, -6, -12 dB), a 1 mg
    sensor floor, interference at the signal's rms.  Healthy scenes (whose signal is
    the model's tiny ball-entry vibration, rms ~2e-3 m s-2): the 1 mg floor, and
    interference of fixed size (mains 0.1 m s-2, impacts 0.5 m s-2) over it.
    """
    floor = 0.00980665
    out = {"noise-free": x, "1 mg sensor floor": x + rng.normal(0, floor, x.size)}
    if healthy:
        out["mains + random impacts"] = x + _interference(x.size, fs, rng, 0.1, 0.5) + rng.normal(0, floor, x.size)
        return out
    rms = float(np.std(x))
    for snr in (0, -6, -12):
        out[f"white noise {snr} dB"] = x + rng.normal(0, rms * 10 ** (-snr / 20), x.size)
    out["mains + random impacts"] = x + _interference(x.size, fs, rng, rms, 3 * rms) + rng.normal(0, 0.3 * rms, x.size)
    return out


def run_simulations(duration=2.0, seed=0):
    from bearing_lab import simulate
    from bearing_lab.analysis import analyze
    rng = np.random.default_rng(seed)
    rows = []
    for name, (scene, ov, truth) in SCENES.items():
        ds = simulate(scene, duration=duration, progress=False, **ov)
        x = ds["outer_ring_acc_y"].values.astype(float)
        fs = float(ds.attrs["sampling_rate_hz"])
        rpm = float(ds.attrs["shaft_speed_rpm"])
        for variant, xv in _variants(x, fs, rng, healthy=truth == "none").items():
            stored = analyze(xv, fs, bearing=ds.attrs["bearing"], rpm=rpm, rpm_source="file")
            blind = analyze(xv, fs, bearing=ds.attrs["bearing"])
            rows.append(_row(f"{name} ({variant})", truth, variant, stored, blind))
    return rows


def timing(repeat=5):
    """CPU seconds of analyze on 10 s at 20 kHz: a 6308 outer-race record with shaft lines."""
    from bearing_lab import get_bearing
    from bearing_lab.analysis import analyze
    fs, fr = 20000.0, 29.62
    t = np.arange(int(10 * fs)) / fs
    rng = np.random.default_rng(1)
    bpfo = get_bearing("6308").fault_frequencies(fr)["bpfo"] * 0.995
    times = np.cumsum(1 / bpfo * (1 + 0.01 * rng.standard_normal(int(10 * bpfo) + 5)))
    x = np.zeros(t.size)
    for t0 in times[times < t[-1] - 0.005]:
        i0 = int(np.ceil(t0 * fs))
        tau = np.arange(100) / fs + (i0 / fs - t0)
        x[i0:i0 + 100] += np.exp(-1500 * tau) * np.sin(2 * np.pi * 3000 * tau)
    x += 0.3 * sum(np.cos(2 * np.pi * h * fr * t + h) / h for h in range(1, 12)) + rng.normal(0, 0.3, t.size)
    out = {}
    for mode, kw in (("stored speed (the default)", {"rpm": 1800.0, "rpm_source": "file"}), ("blind", {})):
        analyze(x, fs, bearing="6308", **kw)
        best = np.inf
        for _ in range(repeat):
            t0 = time.process_time()
            r = analyze(x, fs, bearing="6308", **kw)
            best = min(best, time.process_time() - t0)
        out[mode] = (best, r["diagnosis"], r["verdict"], r["speed_source"], r["shaft_hz"])
    return out


def _wrong(cell, truth):
    return cell["diagnosis"] in FAULTS and cell["diagnosis"] != truth


def _class_table(rows, groups_title):
    lines = [f"| {groups_title} | truth | n | mode | diagnosed right | uncertain | no fault evidence | "
             "**wrong label** |", "|---|---|---|---|---|---|---|---|"]
    keys = sorted({(r["group"], r["truth"]) for r in rows})
    for group, truth in keys:
        sel = [r for r in rows if r["group"] == group and r["truth"] == truth]
        for mode in ("stored", "blind"):
            c = [r[mode] for r in sel]
            right = sum(x["diagnosis"] == truth and x["verdict"] == "diagnosed" for x in c)
            if truth == "none":
                right = sum(x["verdict"] == "no fault evidence" for x in c)
            unc = sum(x["verdict"] == "uncertain" for x in c)
            nfe = sum(x["verdict"] == "no fault evidence" for x in c) if truth != "none" else "-"
            wrong = sum(_wrong(x, truth) for x in c)
            lines.append(f"| {group} | {truth} | {len(sel)} | {mode} | {right} | {unc} | {nfe} | {wrong} |")
    return "\n".join(lines)


def _fmt(cell):
    d = cell["diagnosis"] if cell["verdict"] != "uncertain" else "uncertain"
    extra = f" ({'/'.join(c.replace('_race', '') for c in cell['candidates'])})" if (
        cell["verdict"] == "uncertain" and cell["candidates"]) else ""
    return f"{d}{extra}"


def _detail_table(rows):
    lines = ["| record | truth | stored: result | speed | blind: result | speed source | blind f_r (Hz) |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        s, b = r["stored"], r["blind"]
        err = ""
        if b["source"] == "estimated" and s["status"] == "confirmed":
            err = f" ({100 * (b['shaft_hz'] / s['shaft_hz'] - 1):+.3f} %)"
        bf = f"{b['shaft_hz']:.3f}{err}" if b["source"] == "estimated" else "-"
        flag = (" **WRONG**" if _wrong(s, r["truth"]) else "") + (" (humps)" if s.get("hump") else "")
        flagb = (" **WRONG**" if _wrong(b, r["truth"]) else "") + (" (humps)" if b.get("hump") else "")
        lines.append(f"| {r['label']} | {r['truth']} | {_fmt(s)}{flag} | {s['status']} | {_fmt(b)}{flagb} | "
                     f"{b['source']} | {bf} |")
    return "\n".join(lines)


def _speed_summary(rows):
    conf = [r for r in rows if r["stored"]["status"] == "confirmed"]
    est = [r for r in conf if r["blind"]["source"] == "estimated"]
    errs = [abs(r["blind"]["shaft_hz"] / r["stored"]["shaft_hz"] - 1) for r in est]
    bad = sum(e > 0.005 for e in errs)
    unres = sum(r["blind"]["source"] == "unresolved" for r in rows)
    return (f"Blind speed: {len(est)} of the {len(conf)} records whose stored speed the signal confirms were "
            f"resolved, largest deviation {100 * max(errs, default=0):.3f} %, {bad} beyond 0.5 %; "
            f"{unres} of {len(rows)} records unresolved (diagnosis `uncertain`).")


def _floor_table(rows):
    """Demodulation band rms per data set (stored speed): in mg, and over the band's floor."""
    lines = ["| data set | n | lowest band rms (mg) | median band rms (mg) | lowest band rms / floor |",
             "|---|---|---|---|---|"]
    for group in sorted({r["group"] for r in rows}):
        sel = [r["stored"] for r in rows if r["group"] == group and r["stored"]["band_rms"] is not None]
        if sel:
            v = [c["band_rms"] / 0.00980665 for c in sel]
            q = min(c["band_rms"] / c["band_floor"] for c in sel)
            lines.append(f"| {group} | {len(v)} | {min(v):.3g} | {float(np.median(v)):.3g} | {q:.3g} |")
    return "\n".join(lines)


def report(rec_rows, sim_rows, times):
    out = [f"Machine: {platform.machine()}, Python {platform.python_version()}, numpy {np.__version__}."]
    if rec_rows:
        out += ["", "## Recordings, per class and mode", "", _class_table(rec_rows, "data set"),
                "", _speed_summary(rec_rows), "", "## Demodulation band level against the floor (1 mg over 10 kHz)", "",
                _floor_table(rec_rows), "", "## Every recording", "", _detail_table(rec_rows)]
    if sim_rows:
        healthy = [r for r in sim_rows if r["truth"] == "none"]
        out += ["", "## Simulations (2 s), per variant", "", _class_table(sim_rows, "variant"),
                "", "Healthy scenes, demodulation band level:", "", _floor_table(healthy).replace("data set", "variant"),
                "", "## Every simulation", "", _detail_table(sim_rows)]
    if times:
        out += ["", "## CPU time of `analyze`, 10 s at 20 kHz (best of repeats, one thread)", "",
                "| mode | CPU s | result |", "|---|---|---|"]
        for mode, (sec, d, v, src, fr) in times.items():
            out.append(f"| {mode} | {sec:.3f} | {v} ({d}), speed {src} {fr:.3f} Hz |")
    return "\n".join(out) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mirror", default=os.environ.get("BEARING_LAB_MIRROR", "../shared/data"))
    ap.add_argument("--quick", action="store_true", help="recordings and timing only")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--out", default=None, help="also write the Markdown here")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    rec = run_recordings(Path(args.mirror))
    sims = [] if args.quick else run_simulations()
    text = report(rec, sims, timing(args.repeat))
    print(text)
    if args.out:
        Path(args.out).write_text(text, encoding="utf-8")
    # the hard goal is on recordings; the simulations' table says what it says
    wrong = sum(_wrong(r[m], r["truth"]) for r in rec for m in ("stored", "blind"))
    return 1 if wrong else 0


if __name__ == "__main__":
    raise SystemExit(main())
