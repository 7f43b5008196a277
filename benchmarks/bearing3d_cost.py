"""CPU cost of the 3-D bearing against the planar one, per simulated second (whole simulate() call
after a warm-up: tables cached, kernels compiled; best of 3 1 s records), under 300 N axial.

Two ratios: each model at the solver settings ``solver.method = "auto"`` picks for it (the kind of
each is decided on its own contact track, so a defect the 3-D track leaves runs the healthy rule
while the planar run keeps the defect rule), and at equal settings (the planar run repeated at the
3-D run's method and tolerance).  Also the solver's steps (accepted + rejected, settling included).
Usage: python benchmarks/bearing3d_cost.py"""
import time

import numpy as np

from bearing_lab.sim import simulate

AXIAL = {"load.axial_n": 300.0}
SCENES = [("paper-O1", {}), ("paper-O2", {"defect.skew_deg": 60.0}), ("paper-healthy", {}), ("cwru-or007-6", {}),
          # the defect 2.3 mm off the groove bottom: the planar track meets it, the 3-D one leaves it
          ("paper-O1", {"defect.offset_mm": -2.3})]


def cost(name, ov, dur=1.0, repeat=3):
    best = np.inf
    for _ in range(repeat):
        t = time.process_time()
        ds = simulate(name, duration=dur, progress=False, **ov)
        best = min(best, (time.process_time() - t) / dur)
    return best, ds.attrs["solver_steps"] + ds.attrs["solver_rejected_steps"], ds


def main():
    print("| scene | fidelity | planar: setting, CPU s/s | 3-D: setting, CPU s/s | ratio at auto | "
          "planar at the 3-D setting | ratio at equal settings | steps planar / 3-D |")
    print("|---|---|---|---|---:|---:|---:|---:|")
    for name, ov in SCENES:
        for fid in ("multibody", "quasi-static"):
            o = dict(ov, fidelity=fid)
            simulate(name, duration=0.01, progress=False, **o)
            simulate(name, duration=0.01, progress=False, **dict(o, **AXIAL))
            a, sa, da = cost(name, o)
            b, sb, db = cost(name, dict(o, **AXIAL))
            m, r = db.attrs["solver_method"], db.attrs["solver_rtol"]
            same = (da.attrs["solver_method"], da.attrs["solver_rtol"]) == (m, r)
            e = a if same else cost(name, dict(o, method=m, rtol=r))[0]
            print(f"| {name} {ov or ''} | {fid} | {da.attrs['solver_method']} {da.attrs['solver_rtol']:g}, {a:.3f} | "
                  f"{m} {r:g}, {b:.3f} | {b / a:.2f} | {e:.3f} | {b / e:.2f} | {sa} / {sb} |", flush=True)


if __name__ == "__main__":
    main()
