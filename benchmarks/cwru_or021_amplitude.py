"""Why the amplitudes of CWRU record 234 (outer race, 0.021 in pit at 6:00, 0 hp) fail: the evidence.

Run:  BEARING_LAB_MIRROR=/path/to/mirror python benchmarks/cwru_or021_amplitude.py

Prints four tables (docs/validation.md, "Record 234: why the amplitudes fail", quotes them):

1. the share of the intact load the most loaded ball keeps over each pit (elastic half-space
   contact at that ball's static approach, three grids), and the Hertz contact ellipse;
2. the model's record-234 signal against its record-130 signal through the SAME fixed path (the one
   case cwru-130 fits), for constant radial loads of 75-1200 N, and for a through-width slot;
3. the same ratio in the two recordings, overall and per frequency band;
4. the impact peaks of both recordings against the shaft angle (2.5-4 kHz band envelope, one peak a
   BPFO period, eight angle bins) and the squared-envelope lines at f_r and BPFO +- f_r.
"""
from __future__ import annotations

import os
import time

import numpy as np
import scipy.io
import scipy.signal as ss

from bearing_lab.bearings import get_bearing
from bearing_lab.sim.defects.geometry import RaceGeometry
from bearing_lab.sim.defects.halfspace import ratio_curve
from bearing_lab.sim.defects.model import Defect
from bearing_lab.sim.hertz import race_contact
from bearing_lab.validation import simulation
from bearing_lab.validation.load import load_case
from bearing_lab.validation.rig import identify_path

MIRROR = os.environ.get("BEARING_LAB_MIRROR", "../shared/data")
FS, RPM, G = 12000.0, 1796.0, 9.80665
PITS_MM = {"0.007 in (record 130)": 0.1778, "0.021 in (record 234)": 0.5334}
BANDS = [(0, 1000), (1000, 2000), (2000, 2500), (2500, 3000), (3000, 3500), (3500, 4000), (4000, 5000), (5000, 6000)]


def contact_shares():
    b = get_bearing("6205")
    q_max = 4.37 * 150.0 / 9                          # Stribeck, zero clearance, 150 N radial
    hz = race_contact(b.ball_diameter, b.pitch_diameter, b.outer_conformity, "outer")
    a, bb = hz.semi_axes(q_max)
    delta = float(hz.approach(q_max))
    print(f"\n1. most loaded ball {q_max:.1f} N: approach {delta * 1e6:.2f} um, contact ellipse "
          f"{2 * a * 1e3:.2f} mm across x {2 * bb * 1e3:.2f} mm along the track")
    geom = RaceGeometry.from_bearing(b, "outer")
    for label, d in PITS_MM.items():
        pit = Defect("outer", "ellipse", d * 1e-3, d * 1e-3, 0.2794e-3)
        shares = [ratio_curve(pit, geom, delta, cells=c)[1].min() for c in ((32, 24), (64, 48), (128, 96))]
        print(f"   {label}: share of the intact load kept, pit under the ball: "
              + " / ".join(f"{s:.3f}" for s in shares) + " (32x24 / 64x48 / 128x96 cells)")


def _through_path(case, path, overrides):
    scene = simulation.build_scene(case, rpm=RPM, fs=FS, duration=0.5, overrides={**simulation.SENSOR_OFF, **overrides})
    y = path.apply(simulation.signal(simulation.run(scene)), FS)[int(0.1 * FS):]
    return np.sqrt(np.mean(y ** 2)), np.abs(y).max()


def model_ratios():
    c130, c234 = load_case("cwru-130"), load_case("cwru-234")
    path = identify_path(c130, mirror=MIRROR)
    print(f"\n2. model through the path fitted on record 130 ({path.describe()}), 0.4 s after 0.1 s settling")
    print("   | radial load (N) | 130 RMS / peak (m/s2) | 234 RMS / peak (m/s2) | 234/130 RMS | 234/130 peak |")
    for load in (75.0, 150.0, 300.0, 600.0, 1200.0):
        r1, p1 = _through_path(c130, path, {"load.radial_n": load})
        r2, p2 = _through_path(c234, path, {"load.radial_n": load})
        print(f"   | {load:g} | {r1:.2f} / {p1:.1f} | {r2:.2f} / {p2:.1f} | {r2 / r1:.2f} | {p2 / p1:.2f} |")
    r, p = _through_path(c234, path, {"defect.shape": "rectangle", "defect.width_mm": 15.0})
    print(f"   through-width slot 0.533 mm x 15 mm at 150 N: RMS {r:.1f}, peak {p:.0f} m/s2")


def _record(name):
    m = scipy.io.loadmat(os.path.join(MIRROR, "cwru", name))
    return m[next(k for k in m if k.endswith("_DE_time"))].ravel() * G


def _band_rms(x):
    f, p = ss.welch(x, FS, nperseg=1024)
    return np.array([np.sqrt(np.trapezoid(p[(f >= lo) & (f < hi)], f[(f >= lo) & (f < hi)])) for lo, hi in BANDS])


def _modulation(x):
    fr = RPM / 60.0
    env = np.abs(ss.hilbert(ss.sosfiltfilt(ss.butter(4, [2500, 4000], "bandpass", fs=FS, output="sos"), x)))
    per = FS / (3.5848 * fr)
    idx = np.array([s + np.argmax(env[s:s + int(per)]) for s in (np.arange(int(x.size // per) - 1) * per).astype(int)])
    bins = np.floor((idx / FS * fr) % 1.0 * 8).astype(int)
    means = np.array([env[idx][bins == k].mean() for k in range(8)])
    e2 = env ** 2 - np.mean(env ** 2)
    spec = np.abs(np.fft.rfft(e2 * np.hanning(e2.size)))
    freq = np.fft.rfftfreq(e2.size, 1 / FS)

    def line(f0):
        return spec[(freq > f0 - 1.0) & (freq < f0 + 1.0)].max()
    bpfo = 3.5848 * fr
    return means, line(fr) / line(bpfo), (line(bpfo - fr) + line(bpfo + fr)) / 2 / line(bpfo)


def recordings():
    x130, x234 = _record("130_OR007@6_0.mat"), _record("234_OR021@6_0.mat")
    n = int(FS)
    print("\n3. recordings, first 1 s: RMS 130 {:.2f}, 234 {:.2f} m/s2 (ratio {:.2f}); peak 130 {:.1f}, 234 {:.1f} "
          "(ratio {:.2f})".format(np.sqrt(np.mean(x130[:n] ** 2)), np.sqrt(np.mean(x234[:n] ** 2)),
                                  np.sqrt(np.mean(x234[:n] ** 2) / np.mean(x130[:n] ** 2)),
                                  np.abs(x130[:n]).max(), np.abs(x234[:n]).max(),
                                  np.abs(x234[:n]).max() / np.abs(x130[:n]).max()))
    b130, b234 = _band_rms(x130), _band_rms(x234)
    for name, x in (("130", x130), ("234", x234)):
        f, p = ss.welch(x, FS, nperseg=512)
        print(f"   {name}: spectrum peak at {f[np.argmax(p)]:.0f} Hz ({f[1]:.1f} Hz bins)")
    print("   | band (Hz) | 130 RMS | 234 RMS | 234/130 |")
    for (lo, hi), u, v in zip(BANDS, b130, b234):
        print(f"   | {lo}-{hi} | {u:.2f} | {v:.2f} | {v / u:.2f} |")
    print("\n4. impact peaks (2.5-4 kHz envelope) by shaft angle, eight bins, m/s2; squared-envelope lines")
    for name, x in (("130", x130), ("234", x234)):
        means, f1, sb = _modulation(x)
        print(f"   {name}: {np.round(means, 1)} (max/min {means.max() / means.min():.1f}); "
              f"line at f_r / BPFO line {f1:.2f}; mean of BPFO +- f_r / BPFO line {sb:.2f}")


if __name__ == "__main__":
    t0 = time.process_time()
    contact_shares()
    model_ratios()
    recordings()
    print(f"\nCPU {time.process_time() - t0:.1f} s")
