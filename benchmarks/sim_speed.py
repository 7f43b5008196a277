"""Simulator speed against error, with scipy's solve_ivp on the same equations.

Run:  .venv/bin/python benchmarks/sim_speed.py [--duration 0.1]

For each scene (paper-healthy, paper-slot) and fidelity (multibody,
quasi-static) it measures compute seconds per simulated second and the error
of the peak outer-ring Y acceleration (max |a| of the 20 kHz record) against a
converged reference: dp54 at rtol 1e-9 with a 2 µs step ceiling, checked by
comparing it with rtol 1e-10 (the difference is printed as the reference's own
error).  scipy's LSODA and Radau (rtol 1e-8) integrate the same numba
right-hand side (called from Python) with the same 25 µs step ceiling — without
it they step over a 1 mm defect — and their dense output goes through the same
anti-alias stage.  One process, one core, same run.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.integrate import solve_ivp

from bearing_lab.sim import _kernels as K
from bearing_lab.sim.assembly import assemble
from bearing_lab.sim.integrate import METHODS, _decimate_acc, _run, _warm_up
from bearing_lab.sim.scene import load_scene


def ours(asm, method, rtol, duration, *, step=None, max_step=None):
    t0 = time.perf_counter()
    res = _run(asm, METHODS[method], float(rtol), progress=False, step=step, max_step=max_step)
    wall = time.perf_counter() - t0
    acc = res["acc"][:, 1]
    sim_s = res["t_end"]
    return acc, wall / sim_s, int(res["stats"][0])


def scipy_run(asm, method, rtol, max_step):
    """Same equations through solve_ivp; returns (acc, s per simulated s, n_rhs)."""
    res0 = _run(asm, METHODS["dp54"], 1e-3, progress=False, t_end_override=1e-9)  # grids only
    scene = asm.scene
    fs = scene.fs_out
    R = int(scene.data["output"]["oversample"])
    # rebuild the grids exactly as _run does
    from bearing_lab.sim.integrate import anti_alias_taps
    taps = anti_alias_taps(fs, R)
    half = len(taps) // 2
    dt_f = 1 / (fs * R)
    n_out = int(round(scene.duration * fs))
    t0 = scene.settle
    m_pad = half + 2
    n_fine = m_pad + (n_out - 1) * R + m_pad + 1
    fine_t = t0 - m_pad * dt_f + (np.arange(n_fine + 1) - 0.5) * dt_f
    t_end = fine_t[-1] + 1e-9
    z = asm.n_balls
    fi, fo = np.empty(z), np.empty(z)
    args = (asm.p, asm.sp_t, asm.sp_w, asm.sp_th, asm.dint, asm.dflt, asm.hbuf, asm.gbuf)
    count = [0]

    def f(t, y):
        dy = np.empty_like(y)
        K.rhs(t, y, *args, dy, fi, fo)
        count[0] += 1
        return dy
    atol = asm.atol_scale * rtol
    tic = time.perf_counter()
    sol = solve_ivp(f, (0.0, t_end), asm.y0.copy(), method=method, rtol=rtol, atol=atol,
                    max_step=max_step, dense_output=True)
    wall = time.perf_counter() - tic
    if not sol.success:
        return None, wall / t_end, count[0]
    v = sol.sol(fine_t)[[6, 7]].T
    res = dict(fine_out=v, dt_f=dt_f, taps=taps, m_pad=m_pad, R=R, n_out=n_out)
    return _decimate_acc(res)[:, 1], wall / t_end, count[0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--duration", type=float, default=1.0, help="simulated seconds for our solvers")
    ap.add_argument("--scipy-duration", type=float, default=0.03, help="simulated seconds for scipy")
    ap.add_argument("--no-scipy", action="store_true")
    args = ap.parse_args()
    _warm_up()
    rows = []
    for name in ("paper-healthy", "paper-slot"):
        for fid in ("multibody", "quasi-static"):
            sc = load_scene(name, fidelity=fid, **{"output.duration_s": args.duration})
            asm = assemble(sc)
            ref, _, _ = ours(asm, "dp54", 1e-9, args.duration, max_step=2e-6)
            ref2, _, _ = ours(asm, "dp54", 1e-10, args.duration, max_step=1e-6)
            pk = np.max(np.abs(ref))
            ref_err = abs(np.max(np.abs(ref2)) - pk) / pk
            settings = [("dp54", dict(rtol=r)) for r in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7)]
            settings += [("bs32", dict(rtol=r)) for r in (1e-3, 1e-4, 1e-5)]
            settings += [("rk4", dict(rtol=0, step=h)) for h in (1e-5, 5e-6, 2e-6)]
            for method, kw in settings:
                acc, cost, steps = ours(asm, method, kw["rtol"], args.duration, step=kw.get("step"))
                err = abs(np.max(np.abs(acc)) - pk) / pk
                rms_err = abs(np.std(acc) - np.std(ref)) / np.std(ref)
                label = f"{method} " + (f"h={kw['step']:g}" if "step" in kw else f"rtol={kw['rtol']:g}")
                rows.append((name, fid, label, cost, err, rms_err, steps))
            print(f"# {name} {fid}: reference peak {pk:.4f} m/s2, reference self-check {ref_err:.1e}",
                  flush=True)
            if not args.no_scipy:
                sc_s = load_scene(name, fidelity=fid, **{"output.duration_s": args.scipy_duration})
                asm_s = assemble(sc_s)
                ref_s, _, _ = ours(asm_s, "dp54", 1e-9, args.scipy_duration, max_step=2e-6)
                pk_s = np.max(np.abs(ref_s))
                fast, cost_fast, _ = ours(asm_s, "dp54", 1e-5, args.scipy_duration)
                rows.append((name, fid, f"(ours dp54 rtol=1e-05 on the scipy window)", cost_fast,
                             abs(np.max(np.abs(fast)) - pk_s) / pk_s, np.nan, 0))
                for method, rtol in (("LSODA", 1e-6), ("LSODA", 1e-8), ("Radau", 1e-8)):
                    acc, cost, nf = scipy_run(asm_s, method, rtol, 2.5e-5)
                    pk, ref = pk_s, ref_s
                    if acc is None:
                        rows.append((name, fid, f"scipy {method} rtol={rtol:g}", cost, np.nan, np.nan, nf))
                        continue
                    err = abs(np.max(np.abs(acc)) - pk) / pk
                    rms_err = abs(np.std(acc) - np.std(ref)) / np.std(ref)
                    rows.append((name, fid, f"scipy {method} rtol={rtol:g}", cost, err, rms_err, nf))
    print("| scene | fidelity | setting | compute s / simulated s | peak-acc error | RMS error | steps (ours) / RHS calls (scipy) |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]:.4f} | {r[4]:.2e} | {r[5]:.2e} | {r[6]} |")


if __name__ == "__main__":
    main()
