"""Speed at equal accuracy, and the default as users get it (CPU time, one run).

Two measurements behind the simulator's speed figures:

1. **Equal accuracy.**  For each integration method -- ours (dp54, bs32 adaptive; rk4 at a fixed
   step) and scipy's ``solve_ivp`` (LSODA, Radau, BDF, RK45) integrating the SAME compiled
   right-hand side -- every setting runs the same record and is scored against one converged
   reference (dp54, rtol 1e-9, 2 µs step ceiling; its convergence is checked by a second run at
   rtol 1e-10 / 1 µs, whose difference is reported).  The method's figure is its cheapest
   setting within 1 % peak-acceleration and 0.1 % excitation-period error; the ratio of two
   methods' figures is the speed-up at equal accuracy.  scipy's settings run loose to tight and
   stop at the first that meets the tolerance (a tighter tolerance costs more steps).
2. **The default.**  ``simulate(scene)`` exactly as a user calls it (``fidelity = "auto"``,
   ``solver.method = "auto"``), 1 s records, after a first run that compiled the kernels and
   filled the defect-table cache, in a new interpreter that loads the kernels from numba's disk
   cache as a user's process does: the time loop alone, the whole call, and the call's own
   ``wall_time_s`` / ``table_time_s`` attributes.

Cost is CPU time (``time.process_time``) per simulated second, so other jobs on a shared machine
do not inflate it; the minimum over repeats is kept.  scipy gets the same 25 µs step ceiling as
ours (without it, its methods step over a 1 mm defect).
"""
from __future__ import annotations

import json
import math
import subprocess
import sys
import time

import numpy as np

from .. import sim
from ..errors import SolverError
from ..sim import integrate
from ..sim import load_scene
from ..sim.assembly import assemble
from ..sim.auto import resolve
from ..sim.integrate import METHODS, _run, _warm_up
from ..units import G
from .bench_common import bench_scene, measures, rel_err, scipy_acc, within_tolerance


SPEED_SCENES = [
    ("paper-slot", "paper-slot", {}),
    ("paper-O1-H=B/2", "paper-O1", {"defect.offset_mm": 0.5}),
    ("paper-O2-theta=60", "paper-O2", {"defect.skew_deg": 60.0}),
    ("cwru-or007-6", "cwru-or007-6", {}),
]
#: our settings: (method, rtol, fixed step s)
OURS = ([("dp54", r, None) for r in (1e-3, 1e-4, 1e-5, 1e-6)]
        + [("bs32", r, None) for r in (1e-3, 1e-4, 1e-5)]
        + [("rk4", 0.0, h) for h in (2e-5, 1e-5, 5e-6)])
#: scipy's methods, each from loose to tight
SCIPY = {"LSODA": (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8), "RK45": (1e-2, 1e-3, 1e-4, 1e-5, 1e-6),
         "BDF": (1e-3, 1e-4, 1e-5, 1e-6, 1e-7), "Radau": (1e-3, 1e-4, 1e-5, 1e-6, 1e-7)}
MAX_STEP = 2.5e-5


def _cpu(fn, *args, repeats=1, **kw):
    """(result of the last call, smallest CPU seconds over ``repeats`` calls)."""
    best = math.inf
    out = None
    for _ in range(repeats):
        t0 = time.process_time()
        out = fn(*args, **kw)
        best = min(best, time.process_time() - t0)
    return out, best


def equal_accuracy(label, base, ov, *, duration=0.1, scipy=True, repeats=2, progress=None):
    """Rows (one per setting) of ours and scipy's methods against one converged reference."""
    sc = bench_scene(base, ov, duration)
    asm = assemble(sc)
    fs = sc.fs_out

    def ours(method, rtol, step, mx=None):
        return _run(asm, METHODS[method], float(rtol), progress=False, step=step, max_step=mx)

    ref, ref_cpu = _cpu(ours, "dp54", 1e-9, None, 2e-6)
    ref2, _ = _cpu(ours, "dp54", 1e-10, None, 1e-6)
    m_ref = measures(ref["acc"][:, 1], fs, sc)
    m_ref2 = measures(ref2["acc"][:, 1], fs, sc)
    check = {k: rel_err(m_ref2[k], m_ref[k]) for k in ("peak", "period")}
    t_sim = ref["t_end"]
    rows = []

    def add(solver, method, setting, acc, cpu, extra=None):
        m = measures(acc, fs, sc) if acc is not None else {"peak": math.nan, "period": math.nan}
        row = dict(scene=label, solver=solver, method=method, setting=setting, cost=cpu / t_sim,
                   err_peak=rel_err(m["peak"], m_ref["peak"]), err_period=rel_err(m["period"], m_ref["period"]),
                   **(extra or {}))
        row["ok"] = within_tolerance(row, m_ref["period"])
        rows.append(row)
        if progress:
            progress(row)
        return row

    for method, rtol, step in OURS:
        setting = f"h={step:g}" if step else f"rtol={rtol:g}"
        try:
            res, cpu = _cpu(ours, method, rtol, step, repeats=repeats)
        except SolverError:  # a fixed step beyond the stability bound diverges: no figure
            add("bearing_lab", method, setting + " (diverged)", None, math.nan)
            continue
        st = res["stats"]
        add("bearing_lab", method, setting, res["acc"][:, 1], cpu, dict(steps=int(st[0]), rejected=int(st[1])))
    if scipy:
        for method, rtols in SCIPY.items():
            for rtol in rtols:
                acc, cpu = scipy_acc(asm, method, rtol, MAX_STEP)
                if add("scipy", method, f"rtol={rtol:g}", acc, cpu)["ok"]:
                    break
    info = dict(scene=label, duration_s=duration, simulated_s=t_sim, ref_cost=ref_cpu / t_sim,
                ref_peak=m_ref["peak"], ref_period=m_ref["period"], ref_check_peak=check["peak"],
                ref_check_period=check["period"])
    return rows, info


#: quasi-static settings: (method, rtol, step ceiling s) -- massless balls leave the ring modes
#: (3-6 kHz) as the fastest, so the ceiling can rise to 100 µs
QS_SETTINGS = [("bs32", 1e-3, 1e-4), ("bs32", 1e-4, 1e-4), ("dp54", 1e-4, 1e-4), ("dp54", 1e-5, 2.5e-5)]


def quasi_static(label, base, ov, *, duration=0.1, repeats=2):
    """Quasi-static rows: CPU s/s, and the error against the multibody reference (what a user
    gets: model plus numerical error) and against its own converged run (numerical error)."""
    sc_mb = bench_scene(base, ov, duration)
    sc = bench_scene(base, ov, duration, "quasi-static")
    asm = assemble(sc)
    ref_mb = measures(_run(assemble(sc_mb), 0, 1e-9, progress=False, max_step=2e-6)["acc"][:, 1], sc.fs_out, sc_mb)
    ref_qs = measures(_run(asm, 0, 1e-9, progress=False, max_step=2e-6)["acc"][:, 1], sc.fs_out, sc)
    rows = []
    for method, rtol, mx in QS_SETTINGS:
        res, cpu = _cpu(_run, asm, METHODS[method], rtol, progress=False, max_step=mx, repeats=repeats)
        m = measures(res["acc"][:, 1], sc.fs_out, sc)
        row = dict(scene=label, setting=f"{method} rtol={rtol:g} max_step={mx:g}", cost=cpu / res["t_end"],
                   err_peak=rel_err(m["peak"], ref_mb["peak"]), err_period=rel_err(m["period"], ref_mb["period"]),
                   num_err_peak=rel_err(m["peak"], ref_qs["peak"]), steps=int(res["stats"][0]),
                   rejected=int(res["stats"][1]))
        row["ok"] = within_tolerance(row, ref_mb["period"])
        rows.append(row)
    return rows


def quasi_static_table(rows) -> str:
    out = ["| scene | quasi-static setting | CPU s/s | peak err vs multibody | period err | numerical peak err | "
           "steps | rejected | within tolerance |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['scene']} | {r['setting']} | {r['cost']:.3f} | {r['err_peak']:.1e} | {r['err_period']:.1e} | "
                   f"{r['num_err_peak']:.1e} | {r['steps']} | {r['rejected']} | {'yes' if r['ok'] else 'no'} |")
    return "\n".join(out)


def best_per_method(rows):
    """{(scene, solver, method): the cheapest row within tolerance, or None}."""
    out = {}
    for r in rows:
        key = (r["scene"], r["solver"], r["method"])
        cur = out.get(key)
        if r["ok"] and (cur is None or r["cost"] < cur["cost"]):
            out[key] = r
        else:
            out.setdefault(key, None)
    return out


def default_cost(label, base, ov, *, duration=1.0, repeats=3):
    """``simulate`` as users call it (auto), warm caches: CPU of the time loop and the whole call."""
    loop_cpu = []
    orig = integrate._run

    def timed_run(*a, **kw):  # the time loop alone, measured inside the user's call
        t0 = time.process_time()
        try:
            return orig(*a, **kw)
        finally:
            loop_cpu.append(time.process_time() - t0)
    sim.simulate(base, duration=duration, progress=False, **ov)  # compile, build/cache the tables
    best = None
    integrate._run = timed_run
    try:
        for _ in range(repeats):
            loop_cpu.clear()
            t0 = time.process_time()
            ds = sim.simulate(base, duration=duration, progress=False, **ov)
            call = time.process_time() - t0
            row = dict(scene=label, loop_cpu_s_per_s=loop_cpu[0] / duration, call_cpu_s_per_s=call / duration,
                       wall_time_s=float(ds.attrs["wall_time_s"]), table_time_s=float(ds.attrs["table_time_s"]),
                       method=ds.attrs["solver_method"], rtol=float(ds.attrs["solver_rtol"]),
                       fidelity=ds.attrs["fidelity"], steps=int(ds.attrs["solver_steps"]),
                       rejected=int(ds.attrs["solver_rejected_steps"]),
                       peak_g=float(np.max(np.abs(ds.outer_ring_acc_y.values))) / G)
            if best is None or row["loop_cpu_s_per_s"] < best["loop_cpu_s_per_s"]:
                best = row
    finally:
        integrate._run = orig
    return best


def default_costs_as_users_get_them(chosen, *, duration=1.0):
    """:func:`default_cost` of each scene in a new interpreter, which loads the kernels from
    numba's disk cache (warmed by this process) as a user's process does: code compiled in the
    measuring process can differ from what the cache hands out."""
    code = ("import json, sys; from bearing_lab.studies.bench_speed import default_cost; "
            "print(json.dumps([default_cost(l, b, o, duration=float(sys.argv[2])) "
            "for l, b, o in json.loads(sys.argv[1])]))")
    res = subprocess.run([sys.executable, "-c", code, json.dumps([list(c) for c in chosen]), str(duration)],
                         capture_output=True, text=True, check=False)
    if res.returncode != 0:
        raise RuntimeError(f"the default-cost child process failed:\n{res.stderr[-2000:]}")
    return json.loads(res.stdout.strip().splitlines()[-1])


def default_accuracy(label, base, ov, *, duration=0.1):
    """The default's settings on the equal-accuracy record: its error against the reference."""
    sc = bench_scene(base, ov, duration)
    ch = resolve(load_auto(base, ov, duration))
    ref = _run(assemble(sc), METHODS["dp54"], 1e-9, progress=False, max_step=2e-6)
    asm = assemble(bench_scene(base, ov, duration, ch["fidelity"]))
    res = _run(asm, METHODS[ch["method"]], ch["rtol"], progress=False, max_step=ch["max_step_s"],
               step=ch.get("step_s") or None)
    m_ref = measures(ref["acc"][:, 1], sc.fs_out, sc)
    m = measures(res["acc"][:, 1], sc.fs_out, sc)
    return dict(scene=label, err_peak=rel_err(m["peak"], m_ref["peak"]),
                err_period=rel_err(m["period"], m_ref["period"]), method=ch["method"], rtol=ch["rtol"])


def load_auto(base, ov, duration):
    return load_scene(base, **ov, **{"output.duration_s": duration})


def tables(rows, infos, defaults, accs=()) -> str:
    """Markdown: equal-accuracy figure per method and scene, ratios, and the default."""
    best = best_per_method(rows)
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    methods = list(dict.fromkeys((r["solver"], r["method"]) for r in rows))
    heads = " | ".join(f"{'ours' if sv == 'bearing_lab' else sv} {m}" for sv, m in methods)
    out = ["| scene | " + heads + " | scipy's best / ours' best (speed-up) |",
           "|---|" + "---|" * (len(methods) + 1)]
    for s in scenes:
        cells = []
        for solver, m in methods:
            b = best.get((s, solver, m))
            cells.append(f"{b['cost']:.3f} ({b['setting']})" if b else "none within tolerance")
        ours = [best[(s, sv, m)] for sv, m in methods if sv == "bearing_lab" and best.get((s, sv, m))]
        theirs = [best[(s, sv, m)] for sv, m in methods if sv == "scipy" and best.get((s, sv, m))]
        ratio = (f"{min(r['cost'] for r in theirs) / min(r['cost'] for r in ours):.0f}x"
                 if ours and theirs else "-")
        out.append(f"| {s} | " + " | ".join(cells) + f" | {ratio} |")
    out += ["", "| scene | reference: peak (m/s²) | period (ms) | rtol 1e-10 check: peak | period |",
            "|---|---|---|---|---|"]
    for i in infos:
        out.append(f"| {i['scene']} | {i['ref_peak']:.1f} | {1e3 * i['ref_period']:.4f} | "
                   f"{i['ref_check_peak']:.1e} | {i['ref_check_period']:.1e} |")
    if defaults:
        acc = {a["scene"]: a for a in accs}
        out += ["", "| scene | default setting | time loop CPU s/s | whole call CPU s/s | wall_time_s (1 s) | "
                "table_time_s | steps | rejected | peak err | period err |", "|---|" + "---|" * 9]
        for d in defaults:
            a = acc.get(d["scene"], {})
            out.append(f"| {d['scene']} | {d['fidelity']} {d['method']} rtol={d['rtol']:g} | "
                       f"{d['loop_cpu_s_per_s']:.3f} | {d['call_cpu_s_per_s']:.3f} | {d['wall_time_s']:.3f} | "
                       f"{d['table_time_s']:.4f} | {d['steps']} | {d['rejected']} | "
                       f"{a.get('err_peak', math.nan):.1e} | {a.get('err_period', math.nan):.1e} |")
    return "\n".join(out)


def all_rows_table(rows) -> str:
    out = ["| scene | solver | setting | CPU s/s | peak err | period err | steps | rejected | within |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['scene']} | {r['solver']} | {r['method']} {r['setting']} | {r['cost']:.3f} | "
                   f"{r['err_peak']:.1e} | {r['err_period']:.1e} | {r.get('steps', '')} | "
                   f"{r.get('rejected', '')} | {'yes' if r['ok'] else 'no'} |")
    return "\n".join(out)


def run_speed(scenes=None, *, duration=0.1, default_duration=1.0, scipy=True, progress=True, qs=True):
    """Both measurements (and the quasi-static fidelity) on the speed scenes; returns (markdown
    summary, rows, infos, defaults, quasi-static rows)."""
    _warm_up()
    chosen = [s for s in SPEED_SCENES if scenes is None or s[0] in scenes]
    rows, infos, defaults, accs, qrows = [], [], [], [], []
    say = (lambda r: print(f"  {r['scene']} {r['solver']} {r['method']} {r['setting']}: {r['cost']:.3f} s/s, "
                           f"peak {r['err_peak']:.1e}, period {r['err_period']:.1e}", flush=True)) if progress else None
    for label, base, ov in chosen:
        rs, info = equal_accuracy(label, base, ov, duration=duration, scipy=scipy, progress=say)
        rows += rs
        infos.append(info)
        accs.append(default_accuracy(label, base, ov, duration=duration))
        if qs:
            qrows += quasi_static(label, base, ov, duration=duration)
    defaults = default_costs_as_users_get_them(chosen, duration=default_duration)
    md = tables(rows, infos, defaults, accs)
    if qrows:
        md += "\n\n" + quasi_static_table(qrows)
    return md, rows, infos, defaults, qrows
