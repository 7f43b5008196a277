"""Why the impulse rows of CWRU record 105 (inner race, 0.007 in pit, 0 hp) fail: the evidence.

Run:  BEARING_LAB_MIRROR=/path/to/mirror python benchmarks/cwru_ir007_amplitude.py

Prints five tables (docs/validation.md, "Record 105: why the impulse rows fail", quotes them):

1. the case's rows (simulation, recording, ratio, status), as shipped and with a radial clearance of
   10 um (the middle of the normal clearance group of a 25 mm bore) set in both the path-fitting case
   cwru-130 and in cwru-105;
2. the impact peaks against the shaft angle (2.5-4 kHz band envelope, one peak a fault period, eight
   angle bins) of records 105 and 130 (whole records) and of the simulation after the path;
3. the squared-envelope lines at f_r and BPFI +- f_r relative to the BPFI line (2.5-4 kHz band);
   the kurtosis inside and outside the simulation's loaded part of the turn;
4. how far the impulses stand above the detection threshold of the impulse duration, and the crossing
   level that leaves (the duration is measured at 10 % of the peak only where that is above the threshold);
5. the rows and the impact peaks by shaft angle with a radial preload of 5 and 10 um in both cases.
"""
from __future__ import annotations

import os
import tempfile
import time
from importlib import resources
from pathlib import Path

import numpy as np
import scipy.io
import scipy.signal as ss
import xarray as xr

from bearing_lab.analysis._impulse import DETECTION_FACTOR, impulses
from bearing_lab.analysis._spectral import bandpass, fast_kurtogram, squared_envelope
from bearing_lab.validation import run_validation

MIRROR = os.environ.get("BEARING_LAB_MIRROR", "../shared/data")
FS, G = 12000.0, 9.80665
FR = 1796.0 / 60.0                 # the records' measured shaft line (29.93 Hz); the files store 1796-1797 r/min
ORDER = {"bpfi": 5.4152, "bpfo": 3.5848}     # 6205 drive end, fault frequency / shaft frequency
ROWS = ("rms", "peak", "crest_factor", "kurtosis", "impulse_strength", "impulse_duration")


def _case_text(name):
    return (resources.files("bearing_lab.validation") / "cases" / f"{name}.toml").read_text()


def _clearance_cases(tmp: Path, clearance_um: float):
    """cwru-130 and cwru-105 with one scene key changed in both (the path is re-fitted on 130 with it)."""
    setting = f'set = {{ "clearance.radial_um" = {clearance_um} }}'
    c130 = _case_text("cwru-130").replace('name = "cwru-130"', 'name = "cwru-130-clearance"')
    c130 = c130.replace('base = "cwru-or007-6"', f'base = "cwru-or007-6"\n{setting}')
    c130 = "\n".join(ln for ln in c130.splitlines() if not ln.startswith("impulse_strength_ratio"))
    c130 = c130.split("[ratio]")[0] + "[tolerances]" + c130.split("[tolerances]")[1]
    c105 = _case_text("cwru-105").replace('name = "cwru-105"', 'name = "cwru-105-clearance"')
    c105 = c105.replace('base = "cwru-ir007"', f'base = "cwru-ir007"\n{setting}')
    c105 = c105.replace('from_case = "cwru-130"', 'from_case = "cwru-130-clearance.toml"')
    (tmp / "cwru-130-clearance.toml").write_text(c130)
    (tmp / "cwru-105-clearance.toml").write_text(c105)
    return str(tmp / "cwru-105-clearance.toml")


def rows(out: Path, names):
    print("\n1. rows: simulation / recording (ratio) status")
    print("   | quantity | " + " | ".join(names) + " |")
    sums = {n: {r["quantity"]: r for r in __import__("json").loads((out / n / "summary.json").read_text())["rows"]}
            for n in names}
    for q in ROWS:
        cells = []
        for n in names:
            r = sums[n][q]
            cells.append(f"{r['simulation']:.4g} / {r['experiment']:.4g} ({r['simulation'] / r['experiment']:.2f}) "
                         f"{r['status']}")
        print(f"   | {q} | " + " | ".join(cells) + " |")


def peaks_by_shaft_angle(x, order, bins=8, band=(2500.0, 4000.0)):
    """Mean impact peak (band envelope, the largest in each fault period) per shaft-angle bin, m/s2."""
    env = np.abs(ss.hilbert(ss.sosfiltfilt(ss.butter(4, band, "bandpass", fs=FS, output="sos"), x)))
    per = FS / (order * FR)
    starts = (np.arange(int(x.size // per) - 1) * per).astype(int)
    idx = np.array([s + np.argmax(env[s:s + int(per)]) for s in starts])
    b = np.floor((idx / FS * FR) % 1.0 * bins).astype(int)
    return np.array([env[idx][b == k].mean() for k in range(bins)]), env


def ses_lines(env, order):
    """Squared-envelope lines at f_r, F - f_r, F + f_r relative to the line at the fault frequency F."""
    e2 = env ** 2 - np.mean(env ** 2)
    spec = np.abs(np.fft.rfft(e2 * np.hanning(e2.size)))
    f = np.fft.rfftfreq(e2.size, 1 / FS)

    def line(f0):
        return spec[(f > f0 - 1.0) & (f < f0 + 1.0)].max()
    F = order * FR
    return line(FR) / line(F), line(F - FR) / line(F), line(F + FR) / line(F)


def detection_margin(x, period, band="own"):
    """Median impulse peak over the detection threshold, and the median crossing level it leaves, in ``band``
    ("own": the signal's kurtogram band, as the row measures the recording; the row measures the simulation
    in the recording's band)."""
    x = x[np.isfinite(x)]
    if isinstance(band, str):
        band = fast_kurtogram(x, FS, min_bandwidth=min(4 / period, 0.2 * FS)).band
    y = bandpass(x, FS, band=band) if band is not None else x - x.mean()
    thr = DETECTION_FACTOR * float(np.median(np.sqrt(squared_envelope(y, FS))))
    imp = impulses(x, FS, band=band, min_separation=0.5 * period)
    level = np.minimum(np.maximum(0.1, thr / imp.peak), 0.999)
    return (band, thr, float(np.median(imp.peak)), float(np.median(level)), float(np.mean(~imp.resolved)),
            float(np.median(imp.duration)), float(np.median(np.diff(imp.time))) if imp.time.size > 1 else float("nan"))


def _kurtosis(v):
    v = v - v.mean()
    return float(np.mean(v ** 4) / np.mean(v ** 2) ** 2)


def _record(name):
    m = scipy.io.loadmat(os.path.join(MIRROR, "cwru", name))
    return m[next(k for k in m if k.endswith("_DE_time"))].ravel() * G


def signals(out: Path):
    ds = xr.open_dataset(out / "cwru-105" / "comparison.nc")
    sim = {s: ds["waveform"].sel(signal=s).values for s in ("experiment", "path", "path+background")}
    recs = {"record 105 (whole)": (_record("105_IR007_0.mat"), "bpfi"),
            "record 105 (compared second)": (sim["experiment"], "bpfi"),
            "simulation 105 after the path": (sim["path"], "bpfi"),
            "simulation 105, path + background": (sim["path+background"], "bpfi"),
            "record 130 (whole, outer race at 6:00)": (_record("130_OR007@6_0.mat"), "bpfo")}
    print("\n2./3. impact peaks by shaft angle (2.5-4 kHz envelope, eight bins, m/s2); squared-envelope lines / "
          "fault line")
    for label, (x, fault) in recs.items():
        x = x[np.isfinite(x)]
        means, env = peaks_by_shaft_angle(x, ORDER[fault])
        f1, lo, hi = ses_lines(env, ORDER[fault])
        print(f"   {label}: {np.round(means, 2)} (max/min {means.max() / means.min():.1f}); "
              f"f_r {f1:.2f}, F - f_r {lo:.2f}, F + f_r {hi:.2f}")
    print("\n   kurtosis and RMS inside the simulation's loaded shaft-angle bins (2-4 of 8) and outside, same samples "
          "of both signals")
    b = np.floor((np.arange(sim["path"].size) / FS * FR) % 1.0 * 8).astype(int)
    for label in ("experiment", "path+background"):
        x = sim[label]
        ok = np.isfinite(x)
        zone = ok & np.isin(b, [2, 3, 4])
        print(f"   {label}: kurtosis all {_kurtosis(x[ok]):.1f}, inside {_kurtosis(x[zone]):.1f}; RMS inside "
              f"{np.sqrt(np.mean(x[zone] ** 2)):.2f}, outside {np.sqrt(np.mean(x[ok & ~zone] ** 2)):.2f} m/s2")
    print("\n4. the impulse duration's detection: median impulse peak against the threshold (4 x median envelope), "
          "median crossing level, share of impulses under two samples, median duration and spacing; the "
          "simulation in the recording's band (as the row) and in its own")
    period = 1.0 / (ORDER["bpfi"] * FR)
    band_rec = detection_margin(sim["experiment"], period)[0]
    for label, band in (("experiment", band_rec), ("path+background", band_rec), ("path+background", "own")):
        band, thr, peak, level, unres, dur, gap = detection_margin(sim[label], period, band)
        print(f"   {label}: band {band}, threshold {thr:.2f}, median peak {peak:.2f} m/s2 ({peak / thr:.2f} x), "
              f"crossing level {level:.2f}, unresolved {unres:.2f}, duration {dur * 1e3:.2f} ms, spacing "
              f"{gap * 1e3:.2f} ms (BPFI period {period * 1e3:.2f} ms)")


def preload(values_um=(-5.0, -10.0)):
    """5. A radial preload (negative clearance) set in both cwru-130 (path re-fitted) and cwru-105: every ball
    loaded all round the turn; the rows and the impact peaks by shaft angle of the simulation after the path."""
    print("\n5. radial preload in both cases")
    for pd in values_um:
        with tempfile.TemporaryDirectory() as tmp:
            variant = _clearance_cases(Path(tmp), pd)
            run_validation([variant], Path(tmp) / "out", progress=False, mirror=MIRROR)
            print(f"   clearance.radial_um = {pd:g}")
            rows(Path(tmp) / "out", ["cwru-105-clearance"])
            ds = xr.open_dataset(Path(tmp) / "out" / "cwru-105-clearance" / "comparison.nc")
            x = ds["waveform"].sel(signal="path").values
            means, env = peaks_by_shaft_angle(x[np.isfinite(x)], ORDER["bpfi"])
            f1, lo, hi = ses_lines(env, ORDER["bpfi"])
            print(f"   simulation after the path: {np.round(means, 2)} (max/min {means.max() / means.min():.1f}); "
                  f"f_r {f1:.2f}, F - f_r {lo:.2f}, F + f_r {hi:.2f}")
            ds.close()


if __name__ == "__main__":
    t0 = time.process_time()
    with tempfile.TemporaryDirectory() as tmp:
        variant = _clearance_cases(Path(tmp), 10.0)
        run_validation(["cwru-105", variant], Path(tmp) / "out", progress=False, mirror=MIRROR)
        rows(Path(tmp) / "out", ["cwru-105", "cwru-105-clearance"])
        signals(Path(tmp) / "out")
    preload()
    print(f"\nCPU {time.process_time() - t0:.1f} s")
