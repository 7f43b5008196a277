"""Speed against error: the work-precision study behind ``bearing-lab bench``.

What it measures: :data:`MEASURED` (the text its page opens with).

Outputs (``reports/performance/``): ``index.html`` (table and figures),
``work_precision_<scene>.png`` (log cost against log error), ``performance.nc``
(every row) and ``auto_rules.toml`` (the cheapest setting within the default
tolerance per kind of scene, which ``fidelity = "auto"`` reads when it is copied to
``bearing_lab/sim/auto_rules.toml``).
"""
from __future__ import annotations

import csv
import math
from pathlib import Path
import time

import numpy as np
import xarray as xr

from .._version import __version__
from ..errors import BearingLabError
from ..io.export import to_netcdf
from ..report import Report
from ..sim.assembly import assemble
from ..sim.integrate import METHODS, _run, _warm_up, anti_alias_taps
from ..utils._files import savefig, write_text
from ..utils.figures import new_figure
from .bench_common import RULE_MARGIN, TOL_PEAK, TOL_PERIOD, bench_scene, measures, rel_err, within_tolerance
from .bench_speed import all_rows_table, equal_accuracy, tables

#: the defect-contact model of the reference and of the solver rows (the default); the
#: cheaper models run once each at dp54 rtol 1e-5
REF_CONTACT = "halfspace"
CHEAP_CONTACTS = ("area", "drop", "profile")

SCENES = [
    ("paper-healthy", "paper-healthy", {}, "healthy"),
    ("paper-slot", "paper-slot", {}, "defect"),
    ("paper-O1-H=B/2", "paper-O1", {"defect.offset_mm": 0.5}, "defect"),
    ("paper-O2-theta=60", "paper-O2", {"defect.skew_deg": 60.0}, "defect"),
    ("cwru-or007-6", "cwru-or007-6", {}, "defect"),
    ("paper-slot-300rpm", "paper-slot", {"speed_rpm": 300.0}, "defect-slow"),
]

#: output rates of the auto-rule study (``run_rate_study``): a setting is scored at each, since a
#: higher output rate resolves a sharper impulse peak, which needs a more accurate integration
RATES_HZ = (20_000.0, 100_000.0, 200_000.0)
#: the paper's scenes at every size, offset and skew its studies use, the slot, and the bench's
#: CWRU defect scene (so the lowest band covers every defect scene the kind rule was made on)
RATE_SCENES = [
    ("paper-O1-H=0", "paper-O1", {}),
    ("paper-O1-H=B/3", "paper-O1", {"defect.offset_mm": 1.0 / 3.0}),
    ("paper-O1-H=B/2", "paper-O1", {"defect.offset_mm": 0.5}),
    ("paper-O2-theta=0", "paper-O2", {}),
    ("paper-O2-theta=30", "paper-O2", {"defect.skew_deg": 30.0}),
    ("paper-O2-theta=60", "paper-O2", {"defect.skew_deg": 60.0}),
    ("paper-O3", "paper-O3", {}),
    ("paper-slot", "paper-slot", {}),
    ("cwru-or007-6", "cwru-or007-6", {}),
]
#: the candidates of the rate study: the adaptive multibody settings (fixed steps and the
#: quasi-static fidelity are no candidates, see ``_rules``), with one tighter dp54 tolerance
RATE_SETTINGS = ([("dp54", r) for r in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7)]
                 + [("bs32", r) for r in (1e-3, 1e-4, 1e-5)])
RATE_KIND = "defect"

MB_SETTINGS = ([("dp54", r, None, None) for r in (1e-3, 1e-4, 1e-5, 1e-6)]
               + [("bs32", r, None, None) for r in (1e-3, 1e-4, 1e-5)]
               + [("rk4", 0.0, h, None) for h in (1e-5, 5e-6, 2e-6)])
QS_SETTINGS = ([("dp54", r, None, m) for r in (1e-4, 1e-5) for m in (2.5e-5, 1e-4)]
               + [("bs32", r, None, m) for r in (1e-3, 1e-4) for m in (2.5e-5, 1e-4)])

#: what the study measures (its page opens with it)
MEASURED = """\
For each benchmark scene every solver setting (fixed steps, adaptive tolerances),
every fidelity (quasi-static balls, ball inertia, ball inertia with a dynamic
cage) and every defect-contact model
(along-track profile, rigid 2-D drop, 2-D local law, elastic half-space) runs the same record; each
is scored by its compute seconds per simulated second and its error in peak
acceleration, RMS, excitation period and impulse duration against ONE converged
reference per scene: the most complete model (multibody, "halfspace" contact) with dp54 at
rtol 1e-9 and a 2 µs step ceiling.  Convergence of that reference is established by
a second run at rtol 1e-10 with a 1 µs ceiling; their difference is reported as the
reference's own error.  Cost is CPU time (time.process_time) per simulated second.
Speed at equal accuracy (bearing_lab.studies.bench_speed): each of our methods and scipy's
solve_ivp (LSODA, RK45, BDF, Radau on the same compiled right-hand side) at its cheapest
setting within the tolerance, on a 0.1 s record with its own converged reference.
"""
#: how a setting is scored (the page's second paragraph)
SCORED = (f"Tolerance: {TOL_PEAK:.0%} in peak acceleration, {TOL_PERIOD:.1%} in excitation period. Cost: CPU "
          "seconds (process time) per simulated second, one core, including the settling time.")


def _timed(asm, method, rtol, step, max_step):
    """(result, CPU seconds per simulated second): process time, so other jobs do not count."""
    t0 = time.process_time()
    res = _run(asm, METHODS[method], float(rtol), progress=False, step=step, max_step=max_step)
    return res, (time.process_time() - t0) / res["t_end"]


def _t_end(asm):
    fs = asm.scene.fs_out
    R = int(asm.scene.data["output"]["oversample"])
    half = len(anti_alias_taps(fs, R)) // 2
    dt_f = 1 / (fs * R)
    n_out = int(round(asm.scene.duration * fs))
    m_pad = half + 2
    return asm.scene.settle - m_pad * dt_f + (m_pad + (n_out - 1) * R + m_pad + 0.5) * dt_f + 1e-9


def run_rate_study(out_dir="reports/performance", *, duration=1.0, rates=RATES_HZ, scenes=None,
                   progress=True) -> list:
    """Every candidate setting (``RATE_SETTINGS``) on every ``RATE_SCENES`` scene at every output
    rate, against a converged reference at that rate (dp54 rtol 1e-9, 2 µs ceiling; checked by
    rtol 1e-10, 1 µs).  Writes ``auto_rate_study.csv`` (one row per scene, rate and setting) and
    returns the rows."""
    from tqdm.auto import tqdm  # tqdm only when the bar is shown
    _warm_up()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    chosen = [s for s in RATE_SCENES if scenes is None or s[0] in scenes]
    rows = []
    jobs = [(fs, sc) for fs in rates for sc in chosen]
    for fs, (label, base, ov) in tqdm(jobs, desc="rate study", disable=not progress):
        sc = bench_scene(base, {**ov, "output.sample_rate_hz": float(fs)}, duration, "multibody", REF_CONTACT)
        asm = assemble(sc)
        ref, ref_cost = _timed(asm, "dp54", 1e-9, None, 2e-6)
        ref2, _ = _timed(asm, "dp54", 1e-10, None, 1e-6)
        m_ref = measures(ref["acc"][:, 1], fs, sc)
        m_ref2 = measures(ref2["acc"][:, 1], fs, sc)
        for method, rtol in RATE_SETTINGS:
            res, cost = _timed(asm, method, rtol, None, None)
            m = measures(res["acc"][:, 1], fs, sc)
            rows.append(dict(kind=RATE_KIND, scene=label, rate_hz=float(fs), method=method, rtol=float(rtol),
                             max_step=2.5e-5, cost=cost, peak=m["peak"], ref_peak=m_ref["peak"],
                             ref_period=m_ref["period"], err_peak=rel_err(m["peak"], m_ref["peak"]),
                             err_period=rel_err(m["period"], m_ref["period"]),
                             ref_check_peak=rel_err(m_ref2["peak"], m_ref["peak"]),
                             ref_check_period=rel_err(m_ref2["period"], m_ref["period"]), duration_s=duration))
    if not rows:
        return rows
    with open(out / "auto_rate_study.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    return rows


def read_rate_study(path) -> list:
    """The rows of an ``auto_rate_study.csv`` (numbers as floats)."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        for k in r:
            if k not in ("kind", "scene", "method"):
                r[k] = float(r[k]) if r[k] not in ("", "nan") else math.nan
    return rows


def rate_choices(rows) -> dict:
    """Per (kind, output rate): the cheapest setting (mean cost over the scenes) within
    :data:`~.bench_common.RULE_MARGIN` of the tolerance on EVERY scene the study ran at that rate, as
    ``(method, rtol, worst peak error, mean cost, scenes)``; None where no candidate held."""
    out = {}
    for kind in sorted({r["kind"] for r in rows}):
        for fs in sorted({r["rate_hz"] for r in rows if r["kind"] == kind}):
            rs = [r for r in rows if r["kind"] == kind and r["rate_hz"] == fs]
            scenes = sorted({r["scene"] for r in rs})
            best = None
            for key in dict.fromkeys((r["method"], r["rtol"]) for r in rs):
                sel = [r for r in rs if (r["method"], r["rtol"]) == key]
                if len(sel) != len(scenes) or not all(_accurate(r, RULE_MARGIN) for r in sel):
                    continue
                cost = float(np.mean([r["cost"] for r in sel]))
                if best is None or cost < best[3]:
                    best = (key[0], key[1], max(r["err_peak"] for r in sel), cost, scenes)
            out[(kind, fs)] = best
    return out


def _rate_rules(rows) -> str:
    """``[[<kind>.by_rate]]`` tables: the rule for output rates up to ``max_rate_hz`` (and above
    the band below it) is the cheapest setting the rate study found within the rule margin at that rate."""
    lines = ["", f"# by output rate: the cheapest setting within {RULE_MARGIN * TOL_PEAK:.2%} peak and "
             f"{RULE_MARGIN * TOL_PERIOD:.3%} period error ({RULE_MARGIN:g} of the {TOL_PEAK:.0%} and "
             f"{TOL_PERIOD:.1%} promised) on every scene of the rate study at that rate (auto_rate_study.csv); "
             "a rule covers the rates above the band below it up to max_rate_hz", ""]
    for (kind, fs), best in rate_choices(rows).items():
        if best is None:
            lines += [f"# {kind} at {fs:g} Hz: no candidate held within the rule margin on every scene", ""]
            continue
        method, rtol, worst, cost, scenes = best
        lines += [f"[[{kind}.by_rate]]", f"max_rate_hz = {fs!r}", 'fidelity = "multibody"', f'method = "{method}"',
                  f"rtol = {rtol!r}", "step_s = 0.0", f"max_step_s = {2.5e-5!r}", f"expected_peak_error = {worst!r}",
                  f"cost_s_per_s = {cost!r}", f"scenes = {scenes!r}".replace("'", '"'), ""]
    return "\n".join(lines)


def _accurate(row, fraction=1.0) -> bool:
    """The row within ``fraction`` of the tolerance of its scene's reference (its ``ref_period`` says
    whether that has a period)."""
    return within_tolerance(row, row.get("ref_period", math.nan), fraction)


def _worst(values) -> str:
    v = [x for x in values if math.isfinite(x)]
    return f"{max(v):.1e}" if v else "-"


def rate_table(rows) -> str:
    """Markdown: per output rate and setting, the worst peak and period errors over the scenes,
    the scene where the peak error is worst, the mean cost, and whether it held on every scene within
    the tolerance and within the rule margin (the fraction of it a rule must keep)."""
    lines = ["| output | setting | worst peak err | at | worst period err | mean CPU s/s | within on every scene "
             f"| within {RULE_MARGIN:g} of it |", "|---|---|---|---|---|---|---|---|"]
    choice = rate_choices(rows)
    for fs in sorted({r["rate_hz"] for r in rows}):
        for key in dict.fromkeys((r["method"], r["rtol"]) for r in rows if r["rate_hz"] == fs):
            sel = [r for r in rows if r["rate_hz"] == fs and (r["method"], r["rtol"]) == key]
            w = max(sel, key=lambda r: r["err_peak"])
            picked = any(c is not None and c[:2] == key and f == fs for (_, f), c in choice.items())
            lines.append(f"| {fs / 1e3:g} kHz | {key[0]} rtol={key[1]:g} | {w['err_peak']:.1e} | {w['scene']} | "
                         f"{_worst(r['err_period'] for r in sel)} | {np.mean([r['cost'] for r in sel]):.3f} | "
                         f"{'yes' if all(_accurate(r) for r in sel) else 'no'} | "
                         f"{'yes' if all(_accurate(r, RULE_MARGIN) for r in sel) else 'no'}"
                         f"{' (auto)' if picked else ''} |")
    return "\n".join(lines)


def run_bench(out_dir="reports/performance", *, duration=0.3, scipy_duration=0.1, scenes=None,
              progress=True, scipy=True, rates=True, rate_duration=1.0) -> xr.Dataset:
    """Run the work-precision study; write HTML, PNG, netCDF and rules under ``out_dir``.

    With ``rates`` the rate study (:func:`run_rate_study`, ``rate_duration`` simulated seconds per
    run) also runs, and its per-rate rules join ``auto_rules.toml``."""
    from tqdm.auto import tqdm  # tqdm only when the bar is shown
    _warm_up()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    chosen = [s for s in SCENES if scenes is None or s[0] in scenes]
    rows = []
    notes = {}
    speed_rows, speed_infos = [], []
    for label, base, ov, kind in tqdm(chosen, desc="bench scenes", disable=not progress):
        sc_ref = bench_scene(base, ov, duration, "multibody", REF_CONTACT if kind != "healthy" else None)
        asm = assemble(sc_ref)
        fs = sc_ref.fs_out
        ref, _ = _timed(asm, "dp54", 1e-9, None, 2e-6)
        ref2, _ = _timed(asm, "dp54", 1e-10, None, 1e-6)
        m_ref = measures(ref["acc"][:, 1], fs, sc_ref)
        m_ref2 = measures(ref2["acc"][:, 1], fs, sc_ref)
        notes[label] = {k: rel_err(m_ref2[k], m_ref[k]) for k in m_ref}
        jobs = [("multibody", REF_CONTACT, *s) for s in MB_SETTINGS]
        jobs += [("quasi-static", REF_CONTACT, *s) for s in QS_SETTINGS]
        jobs += [("multibody+dynamic cage", REF_CONTACT, m, r, None, None)
                 for m, r in (("dp54", 1e-5), ("bs32", 1e-4), ("bs32", 1e-3))]
        if kind != "healthy":
            jobs += [("multibody", m, "dp54", 1e-5, None, None) for m in CHEAP_CONTACTS]
        for fid, model, method, rtol, step, mx in jobs:
            cage = "dynamic" if fid.endswith("dynamic cage") else "kinematic"
            sc = bench_scene(base, ov, duration, fid.split("+")[0], model if kind != "healthy" else None, cage)
            asm_j = assemble(sc)
            res, cost = _timed(asm_j, method, rtol, step, mx)
            m = measures(res["acc"][:, 1], fs, sc)
            setting = (f"{method} " + (f"h={step:g}" if step else f"rtol={rtol:g}")
                       + (f" max_step={mx:g}" if mx else ""))
            rows.append(dict(scene=label, kind=kind, fidelity=fid, contact=model if kind != "healthy" else "none",
                             setting=setting, method=method, rtol=rtol, step=step or 0.0, max_step=mx or 0.0,
                             solver="bearing_lab", cost=cost, ref_period=m_ref["period"],
                             **{f"err_{k}": rel_err(m[k], m_ref[k]) for k in m_ref}))
        if scipy:
            rs, info = equal_accuracy(label, base, ov, duration=scipy_duration)
            speed_rows += rs
            speed_infos.append(info)
    keys = list(rows[0])
    ds = xr.Dataset({k: ("row", [r[k] for r in rows]) for k in keys})
    ds["cost"].attrs["units"] = "s per simulated s"
    for k in ("err_peak", "err_rms", "err_period", "err_duration"):
        ds[k].attrs["units"] = "1"
    ds.attrs.update({"duration_s": duration, "scipy_duration_s": scipy_duration,
                     "reference": f"multibody + {REF_CONTACT} contact, dp54 rtol 1e-9, max step 2e-6 s",
                     "reference_self_check": repr(notes), "tolerance_peak": TOL_PEAK,
                     "tolerance_period": TOL_PERIOD, "sampling_rate_hz": 0.0,
                     "bearing_lab_version": __version__})
    to_netcdf(ds, out / "performance.nc", error=BearingLabError)
    rules = _rules(rows)
    if rates:
        rate_rows = run_rate_study(out, duration=rate_duration, scenes=scenes, progress=progress)
        if rate_rows:
            rules += _rate_rules(rate_rows)
            ds.attrs["rate_table_md"] = rate_table(rate_rows)
    write_text(out / "auto_rules.toml", rules)
    speed_md = ""
    if scipy:
        speed_md = tables(speed_rows, speed_infos, []) + "\n\n" + all_rows_table(speed_rows)
        write_text(out / "equal_accuracy.md", speed_md + "\n")
    ds.attrs["equal_accuracy_md"] = speed_md
    _report(out, rows, notes, speed_md)
    return ds


def fastest_within_tolerance(rows, scene):
    cands = [r for r in rows if r["scene"] == scene and r["solver"] == "bearing_lab" and _accurate(r)]
    return min(cands, key=lambda r: r["cost"]) if cands else None


def _rules(rows) -> str:
    """Per kind of scene: the cheapest setting whose error stayed within
    :data:`~.bench_common.RULE_MARGIN` of the tolerance on EVERY scene of that kind (the promise is
    the whole tolerance; the rest is room for the rounding-level spread the study does not sample).

    Only adaptive settings are candidates: a fixed step that held on the bench scenes is no
    safe default for scenes the bench did not cover (a 1e12 N/m mount rings at 300 kHz).
    Cost is the mean over the kind's scenes (single timings on a shared machine are noisy).
    """
    lines = ["# written by `bearing-lab bench`: the cheapest setting within "
             f"{RULE_MARGIN * TOL_PEAK:.2%} peak-acceleration and {RULE_MARGIN * TOL_PERIOD:.3%} period error "
             f"on every bench scene of the kind: {RULE_MARGIN:g} of the {TOL_PEAK:.0%} and {TOL_PERIOD:.1%} "
             "promised, so that the promise holds under rounding-level perturbations of a run", ""]
    kinds = sorted({r["kind"] for r in rows})
    for kind in kinds:
        scenes = sorted({r["scene"] for r in rows if r["kind"] == kind})
        settings = {}
        for r in rows:
            if (r["kind"] != kind or r["solver"] != "bearing_lab" or r["contact"] not in (REF_CONTACT, "none")
                    or r["method"] == "rk4" or "cage" in r["fidelity"]):
                continue
            settings.setdefault((r["fidelity"], r["method"], r["rtol"], r["step"], r["max_step"]), []).append(r)
        best = None
        for key, rs in settings.items():
            if len(rs) == len(scenes) and all(_accurate(r, RULE_MARGIN) for r in rs):
                cost = float(np.mean([r["cost"] for r in rs]))
                worst = max(r["err_peak"] for r in rs)
                if best is None or cost < best[1]:
                    best = (key, cost, worst)
        if best is None:
            continue
        (fid, method, rtol, step, mx), cost, worst = best
        lines += [f"[{kind}]", f'fidelity = "{fid}"', f'method = "{method}"', f"rtol = {rtol!r}",
                  f"step_s = {step!r}", f"max_step_s = {mx or 2.5e-5!r}",
                  f"expected_peak_error = {worst!r}", f"cost_s_per_s = {cost!r}",
                  f"scenes = {scenes!r}".replace("'", '"'), ""]
    return "\n".join(lines)


def _work_precision_figure(sc, rs):
    """Log cost against log peak-acceleration error of one scene's rows."""
    fig = new_figure(figsize=(6.5, 4.2))
    ax = fig.subplots()
    groups = [(f"{fid} ({solver})", mk, col,
               lambda r, fid=fid, solver=solver: (r["fidelity"] == fid and r["solver"] == solver
                                                  and r["contact"] in (REF_CONTACT, "none")))
              for fid, mk in (("multibody", "o"), ("quasi-static", "s"), ("multibody+dynamic cage", "^"))
              for solver, col in (("bearing_lab", None), ("scipy", "k"))]
    groups.append((f"multibody, cheaper contact ({', '.join(CHEAP_CONTACTS)})", "x", "r",
                   lambda r: r["contact"] in CHEAP_CONTACTS))
    for label, mk, col, keep in groups:
        sel = [r for r in rs if keep(r) and math.isfinite(r["err_peak"])]
        if sel:
            ax.scatter([max(r["err_peak"], 1e-9) for r in sel], [r["cost"] for r in sel], marker=mk,
                       c=col, label=label, alpha=0.8)
            for r in sel:
                text = r["setting"].replace(" (short window)", "")
                if r["contact"] in CHEAP_CONTACTS:
                    text = f"{r['contact']} contact"
                ax.annotate(text, (max(r["err_peak"], 1e-9), r["cost"]), fontsize=5, alpha=0.7)
    ax.axvline(TOL_PEAK, color="r", ls="--", lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("relative error in peak acceleration")
    ax.set_ylabel("compute s per simulated s")
    ax.set_title(f"work-precision: {sc}")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    return fig


def _report(out, rows, notes, speed_md=""):
    """The benchmark's page through the report layer: per scene the reference's self-check, the
    fastest setting within tolerance, the work-precision figure and every row."""
    rep = Report("Speed against error", verdict=False)
    rep.add_text([MEASURED, SCORED], "What is measured")
    for sc in dict.fromkeys(r["scene"] for r in rows):
        rs = [r for r in rows if r["scene"] == sc]
        fig = _work_precision_figure(sc, rs)
        savefig(fig, out / f"work_precision_{sc.replace('/', '_').replace('=', '')}.png", dpi=100)
        rep.add_text("reference self-check (rtol 1e-10 vs 1e-9): "
                     + ", ".join(f"{k} {v:.1e}" for k, v in notes[sc].items()), sc)
        best = fastest_within_tolerance(rows, sc)
        if best:
            rep.add_text(f"{best['fidelity']}, {best['contact']}, {best['setting']}: {best['cost']:.4f} s/s, "
                         f"peak error {best['err_peak']:.2e}", None, lead="Fastest within tolerance:")
        rep.add_figure(fig, None, alt=f"work-precision: {sc}", dpi=90)
        rep.add_table([{"fidelity": r["fidelity"], "contact": r["contact"], "setting": r["setting"],
                        "s/s": r["cost"], "peak err": r["err_peak"], "RMS err": r["err_rms"],
                        "period err": r["err_period"], "duration err": r["err_duration"]}
                       for r in sorted(rs, key=lambda r: r["cost"])], None)
    if speed_md:
        rep.add_text(speed_md, "Speed at equal accuracy (CPU s per simulated s; cheapest "
                     f"setting within {TOL_PEAK:.0%} peak and {TOL_PERIOD:.1%} period error)", preformatted=True)
    rep.save(out / "index.html")


def rows_of(ds: xr.Dataset) -> list:
    return [{k: ds[k].values[i].item() for k in ds.data_vars} for i in range(ds.sizes["row"])]


def summary_table(ds: xr.Dataset) -> str:
    """Markdown: per scene, the fastest setting within tolerance (the comparison with scipy at
    equal accuracy is ``ds.attrs["equal_accuracy_md"]``)."""
    rows = rows_of(ds)
    lines = ["| scene | fastest within tolerance | CPU s / simulated s | peak error |", "|---|---|---|---|"]
    for sc in dict.fromkeys(r["scene"] for r in rows):
        best = fastest_within_tolerance(rows, sc)
        if best:
            lines.append(f"| {sc} | {best['fidelity']}, {best['contact']}, {best['setting']} | {best['cost']:.4f} | "
                         f"{best['err_peak']:.1e} |")
        else:
            lines.append(f"| {sc} | none within tolerance | | |")
    return "\n".join(lines)
