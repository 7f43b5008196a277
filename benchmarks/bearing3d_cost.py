"""CPU cost of the 3-D bearing against the planar one, per simulated second (whole simulate() call
after a warm-up: tables cached, kernels compiled; best of 3 1 s records).  Also the solver's steps
(accepted + rejected, settling included: the 3-D bearing settles for at least 0.1 s, the planar
scenes for 0.02 s), which explain most of the difference.
Usage: python benchmarks/bearing3d_cost.py"""
import time

import numpy as np

from bearing_lab.sim import simulate

SCENES = [("paper-O1", {}), ("paper-O2", {"defect.skew_deg": 60.0}), ("paper-healthy", {}), ("cwru-or007-6", {})]


def cost(name, ov, dur=1.0, repeat=3):
    best = np.inf
    for _ in range(repeat):
        t = time.process_time()
        ds = simulate(name, duration=dur, progress=False, **ov)
        best = min(best, (time.process_time() - t) / dur)
    return best, ds.attrs["solver_steps"] + ds.attrs["solver_rejected_steps"]


def main():
    print("| scene | fidelity | planar CPU s/s | 3-D (300 N axial) CPU s/s | ratio | solver steps planar / 3-D |")
    print("|---|---|---:|---:|---:|---:|")
    for name, ov in SCENES:
        for fid in ("multibody", "quasi-static"):
            o = dict(ov, fidelity=fid)
            simulate(name, duration=0.01, progress=False, **o)
            simulate(name, duration=0.01, progress=False, **dict(o, **{"load.axial_n": 300.0}))
            a, sa = cost(name, o)
            b, sb = cost(name, dict(o, **{"load.axial_n": 300.0}))
            print(f"| {name} {ov or ''} | {fid} | {a:.3f} | {b:.3f} | {b / a:.2f} | {sa} / {sb} |", flush=True)


if __name__ == "__main__":
    main()
