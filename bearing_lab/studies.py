"""The paper's four parametric studies (section 5) on the 2-D defect model.

``run_paper_studies(out_dir)`` runs size (O1/O2/O3), offset (O1 at H = 0, B/3,
B/2), skew (O2 at θ = 0°, 30°, 60°) and speed (O3 at 900/1800/3600 r/min) and
writes, under ``out_dir``: one PNG per study overlaying the outer-ring
displacement and acceleration pulses of one defect passage (like the paper's
Figs 13, 15, 17, 18), ``mechanism.png`` (the defected ball's outer-race load and
the intact share of its contact through the passage), ``studies.nc`` (tables
and pulses) and ``index.html``.

Measurement (the same everywhere):

- runs are simulated at 100 kHz output (4× internal oversampling before the
  anti-alias filter) so a 0.35 ms passage has 35 samples; 0.1 s is recorded
  after the scene's settling time;
- the passage analysed is the last one in the record whose window fits: the
  window spans ±(L_eff/v + 1 ms) around the instant the ball centre crosses the
  defect centre (L_eff = the defect's extent along the track, v the ball's
  surface speed (reference.md));
- *pulse*: displacement minus its median over the window;
- *peak displacement*: max |pulse| (µm); *peak acceleration*: max |a| in the
  window (g, sampled at 100 kHz); *acceleration peak-to-peak*: max a − min a in
  the window (g);
- *excitation duration*: :func:`bearing_lab.analysis.excitation_duration`
  (width at 10 % of the height) of the displacement pulse's main lobe — the
  stretch between the zero crossings around its peak, so that the ring's
  rebound after the passage (a structural response, not the excitation) is not
  counted.
- *intact share* (mechanism figure): K·G(ψ, δ_s) / (K·δ_s^1.5), the defected
  contact's force over the intact one at the static approach δ_s of the most
  loaded ball, from the defect's contact table: pure geometry, no dynamics.
"""
from __future__ import annotations

import base64
import io
import math
from pathlib import Path
import time

import numpy as np
import xarray as xr

from ._files import savefig, write_text

G0 = 9.80665
STUDY_FS = 100_000.0

# study -> (scene, [(label, overrides)], paper's figure, what the paper reports)
STUDIES = {
    "size": ("paper-O1", [("O1 1x1 mm", {}), ("O2 1x3 mm", {"defect.length_mm": 3.0}),
                          ("O3 1x6 mm", {"defect.length_mm": 6.0})],
             "Fig. 13", "durations T1 < T2 < T3; amplitude grows with size"),
    "offset": ("paper-O1", [("H = 0", {"defect.offset_mm": 0.0}),
                            ("H = B/3", {"defect.offset_mm": 1.0 / 3.0}),
                            ("H = B/2", {"defect.offset_mm": 0.5})],
               "Fig. 15", "peaks 0.0585 / 0.05695 / 0.05545 mm and 28.82 / 22.48 / 15.64 g (ratios 1 : 0.78 : 0.54)"),
    "skew": ("paper-O2", [("θ = 0°", {"defect.skew_deg": 0.0}), ("θ = 30°", {"defect.skew_deg": 30.0}),
                          ("θ = 60°", {"defect.skew_deg": 60.0})],
             "Fig. 17", "duration falls with θ; acceleration amplitude grows with θ; flat section at θ = 0"),
    "speed": ("paper-O3", [("900 r/min", {"speed_rpm": 900.0}), ("1800 r/min", {"speed_rpm": 1800.0}),
                           ("3600 r/min", {"speed_rpm": 3600.0})],
              "Fig. 18", "duration falls and amplitude grows with speed"),
}
PAPER_OFFSET_RATIOS = (1.0, 22.48 / 28.82, 15.64 / 28.82)


def _passage(ds, scene):
    """(centre time in the record, window half-width, ball index) of the last full passage."""
    b = scene.bearing
    rpm = ds.attrs["shaft_speed_rpm"]
    omega = rpm / 60 * 2 * math.pi
    wc = b.frequency_factors()["ftf"] * omega
    d = scene.defects[0]
    z = b.n_balls
    # ball 0 starts at the load-zone centre; the defect sits at angle d.angle from it
    ang = d.angle % (2 * math.pi / z)
    settle = ds.attrs["settle_time_s"]
    v = b.surface_speed(omega)
    s0, s1, _, _ = d.track_extent()
    half = (s1 - s0) / v + 1e-3
    t_rec = ds.time.values
    k = np.arange(0, 1000)
    t_abs = (ang + k * 2 * math.pi / z) / wc
    t_c = t_abs - settle
    ok = (t_c - half >= t_rec[0]) & (t_c + half <= t_rec[-1])
    if not np.any(ok):
        raise RuntimeError("record too short for one full defect passage")
    kk = k[ok][-1]
    # the ball that reaches the defect at passage kk: omega_c t_k + 2 pi j / Z = d.angle (mod 2 pi)
    ball = int(round((d.angle - ang) / (2 * math.pi / z)) - kk) % z
    return float(t_c[ok][-1]), half, ball, (s1 - s0) / v


def _one(scene_name, overrides):
    from .sim import load_scene, simulate
    from .analysis import excitation_duration
    sc = load_scene(scene_name, **overrides)
    ds = simulate(sc, duration=0.1, fs=STUDY_FS, progress=False, **{"output.oversample": 4})
    tc, half, ball, t_cross = _passage(ds, sc)
    w = (ds.time.values >= tc - half) & (ds.time.values <= tc + half)
    t = ds.time.values[w] - tc
    disp = ds.outer_ring_disp_y.values[w]
    pulse = disp - np.median(disp)
    acc = ds.outer_ring_acc_y.values[w]
    ip = int(np.argmax(np.abs(pulse)))
    sgn = np.sign(pulse[ip])
    lo, hi = ip, ip
    while lo > 0 and pulse[lo - 1] * sgn > 0:
        lo -= 1
    while hi < len(pulse) - 1 and pulse[hi + 1] * sgn > 0:
        hi += 1
    lobe = np.concatenate([[0.0], pulse[lo:hi + 1], [0.0]])
    dur = excitation_duration(lobe, STUDY_FS)
    duration = float(np.asarray(dur[0] if isinstance(dur, tuple) else dur))
    load = ds.ball_load_outer.values[ball, w]
    # intact share of the contact along the passage, at the static approach (geometry only)
    from .sim.assembly import assemble
    asm = assemble(sc)
    tab = asm.tables[0]
    q_static = float(np.max(asm.static["ball_loads"]))
    d_s = float((q_static / asm.hertz_outer.stiffness) ** (2 / 3))
    omega = ds.attrs["shaft_speed_rpm"] / 60 * 2 * math.pi
    psi = t * sc.bearing.frequency_factors()["ftf"] * omega
    share = np.asarray(tab.lookup(psi, np.full_like(psi, d_s))) / d_s ** 1.5
    return {
        "t": t, "pulse": pulse, "acc": acc, "load": load, "share": share,
        "peak_disp_um": float(np.max(np.abs(pulse)) * 1e6),
        "peak_acc_g": float(np.max(np.abs(acc)) / G0),
        "p2p_acc_g": float((np.max(acc) - np.min(acc)) / G0),
        "duration_ms": duration * 1e3,
        "crossing_ms": t_cross * 1e3,
        "wall_s": ds.attrs["wall_time_s"],
        "contact_model": ds.attrs["defect_contact_models"],
        "scene": sc,
    }


def run_paper_studies(out_dir="reports/studies", *, progress=True, studies=None) -> xr.Dataset:
    """Run the four studies, write figures, netCDF and HTML under ``out_dir``; return the table."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from tqdm.auto import tqdm
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    names = list(studies or STUDIES)
    jobs = [(s, lab, ov) for s in names for lab, ov in STUDIES[s][1]]
    results = {}
    t0 = time.perf_counter()
    for s, lab, ov in tqdm(jobs, desc="paper studies", disable=not progress):
        results[(s, lab)] = _one(STUDIES[s][0], ov)
    rows = []
    figs = {}
    for s in names:
        fig, ax = plt.subplots(2, 1, figsize=(7.5, 6), sharex=True)
        for lab, _ in STUDIES[s][1]:
            r = results[(s, lab)]
            ax[0].plot(r["t"] * 1e3, r["pulse"] * 1e6, label=lab)
            ax[1].plot(r["t"] * 1e3, r["acc"] / G0, label=lab, lw=0.8)
            rows.append((s, lab, r["peak_disp_um"], r["peak_acc_g"], r["duration_ms"], r["crossing_ms"],
                         r["contact_model"], r["wall_s"], r["p2p_acc_g"]))
        ax[0].set_ylabel("outer-ring displacement Y\nminus baseline (µm)")
        ax[1].set_ylabel("outer-ring acceleration Y (g)")
        ax[1].set_xlabel("time from the ball centre crossing the defect centre (ms)")
        ax[0].legend(fontsize=8)
        ax[0].set_title(f"{s} study ({STUDIES[s][2]} of the paper): one defect passage")
        for a in ax:
            a.grid(alpha=0.3)
        fig.tight_layout()
        savefig(fig, out / f"{s}.png", dpi=110)
        figs[s] = fig
    # mechanism: defected ball's outer-race load through the passage
    fig, ax = plt.subplots(2, len(names), figsize=(4 * len(names), 6), squeeze=False, sharex="col")
    for i, s in enumerate(names):
        for lab, _ in STUDIES[s][1]:
            r = results[(s, lab)]
            ax[0, i].plot(r["t"] * 1e3, r["load"], label=lab)
            ax[1, i].plot(r["t"] * 1e3, r["share"], label=lab)
        ax[0, i].set_title(f"{s}: defected ball", fontsize=10)
        ax[0, i].set_ylabel("outer-race load (N)")
        ax[1, i].set_ylabel("intact share of the contact\nat the static approach")
        ax[1, i].set_xlabel("time (ms)")
        ax[0, i].legend(fontsize=7)
        for a in ax[:, i]:
            a.grid(alpha=0.3)
    fig.tight_layout()
    savefig(fig, out / "mechanism.png", dpi=100)
    figs["mechanism"] = fig
    n = len(rows)
    table = xr.Dataset(
        {"peak_displacement": ("case", [r[2] * 1e-6 for r in rows], {"units": "m"}),
         "peak_acceleration": ("case", [r[3] * G0 for r in rows], {"units": "m s-2"}),
         "acceleration_peak_to_peak": ("case", [r[8] * G0 for r in rows], {"units": "m s-2"}),
         "excitation_duration": ("case", [r[4] * 1e-3 for r in rows], {"units": "s"}),
         "crossing_time": ("case", [r[5] * 1e-3 for r in rows],
                           {"units": "s", "long_name": "defect extent along the track / surface speed"}),
         "wall_time": ("case", [r[7] for r in rows], {"units": "s"})},
        coords={"case": np.arange(n), "study": ("case", [r[0] for r in rows]),
                "label": ("case", [r[1] for r in rows]),
                "contact_model": ("case", [r[6] for r in rows])},
        attrs={"sampling_rate_hz": STUDY_FS, "total_wall_time_s": time.perf_counter() - t0,
               "measurement": __doc__.split("Measurement (the same everywhere):")[1].strip()})
    from .io_netcdf import write_netcdf
    write_netcdf(table, out / "studies.nc")
    _write_html(out, names, rows, figs)
    for f in figs.values():
        plt.close(f)
    return table


def _png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    return base64.b64encode(buf.getvalue()).decode()


def _write_html(out, names, rows, figs):
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>bearing_lab: the paper's "
             "parametric studies</title><style>body{font-family:sans-serif;max-width:1000px;margin:auto}"
             "table{border-collapse:collapse}td,th{border:1px solid #999;padding:3px 8px;text-align:right}"
             "</style></head><body><h1>The paper's section-5 studies on the 2-D defect model</h1>",
             "<p>Peak displacement is the largest deviation of the outer-ring Y displacement from its "
             "median over the passage window; peak acceleration the largest |a| in that window at "
             f"{STUDY_FS/1e3:.0f} kHz; excitation duration the width of the displacement pulse at 10 % of "
             "its height. Crossing time = defect extent along the track / ball surface speed.</p>"]
    for s in names:
        parts.append(f"<h2>{s} ({STUDIES[s][2]}; paper: {STUDIES[s][3]})</h2>")
        parts.append("<table><tr><th>case</th><th>peak displacement (µm)</th><th>peak acceleration (g)"
                     "</th><th>acceleration peak-to-peak (g)</th><th>excitation duration (ms)</th><th>crossing time L/v (ms)</th>"
                     "<th>contact model</th></tr>")
        for r in rows:
            if r[0] == s:
                parts.append(f"<tr><td>{r[1]}</td><td>{r[2]:.4f}</td><td>{r[3]:.2f}</td><td>{r[8]:.2f}</td><td>{r[4]:.3f}</td>"
                             f"<td>{r[5]:.3f}</td><td>{r[6]}</td></tr>")
        parts.append("</table>")
        if s == "offset":
            pk = [r[3] for r in rows if r[0] == "offset"]
            ratios = ", ".join(f"{p / pk[0]:.2f}" for p in pk)
            parts.append(f"<p>Acceleration ratios to H = 0: {ratios} (paper: 1.00, 0.78, 0.54).</p>")
        parts.append(f"<img src='data:image/png;base64,{_png(figs[s])}'>")
    parts.append("<h2>Mechanism</h2>")
    parts.append(f"<img src='data:image/png;base64,{_png(figs['mechanism'])}'>")
    parts.append("</body></html>")
    write_text(out / "index.html", "\n".join(parts))
