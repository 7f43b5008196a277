"""simulate(scene) -> xarray.Dataset: validate, assemble, integrate, label.

How the output is sampled (as a data-acquisition system would):

1. The integrator steps adaptively (embedded Runge-Kutta, error-controlled) or
   with a fixed step, never stepping over a defect: a step that would carry a
   ball into a defect zone is cut to end at the zone's edge, and inside the zone
   at least ``solver.defect_steps`` steps are taken per crossing.
2. Between steps the solution is interpolated (cubic Hermite, using the
   derivatives at both ends) onto a fine grid at ``oversample × sample_rate``.
3. The accelerometer signal is the mean acceleration over each fine interval,
   computed exactly as the velocity difference across it, then low-pass
   filtered by a linear-phase (zero-delay) Kaiser FIR with −6 dB at the output
   Nyquist frequency, flat (±0.01 dB) to 0.45·fs and ≥ 80 dB down from 0.55·fs,
   and decimated to ``sample_rate``.  So the ball-race resonances at 15–25 kHz
   do not alias into the record.  The fine-interval mean attenuates 0.45·fs by
   under 0.5 % at the default oversampling.
4. Displacements and ball loads are instantaneous samples at the output times
   (they carry no content near the Nyquist frequency worth filtering).
"""
from __future__ import annotations

import dataclasses
import math
import time as _time

import numpy as np
import xarray as xr

from .._docdict import fill_doc
from .._version import __version__
from ..errors import BearingLabError, SolverError
from . import _kernels as kernels
from . import _stepper
from . import _variants
from ._loopargs import Output, Solver, new_work
from .assembly import assemble
from .auto import resolve
from .budget import check_budget
from .scene import load_scene, merge_overrides
from ..schema import DEFAULT_CHANNEL, QUANTITY_OF_UNITS

#: the integration methods (written out in _stepper): Dormand-Prince 5(4) and Bogacki-Shampine
#: 3(2), adaptive with PI step control, and classic RK4 at a fixed step
METHODS = {"dp54": 0, "bs32": 1, "rk4": 2}

_COMPILED = {"kinds": set(), "seconds": 0.0}
#: a scene of each kind of compiled loop (``_variants.KINDS``), for compiling them all at once
_KIND_SCENES = {"kinematic": {}, "quasi_static": {"fidelity": "quasi-static"},
                "dynamic": {"cage": {"model": "dynamic"}},
                "3d_kinematic": {"load": {"axial_n": 20.0}},
                "3d_quasi_static": {"load": {"axial_n": 20.0}, "fidelity": "quasi-static"}}


def anti_alias_taps(fs_out: float, oversample: int) -> np.ndarray:
    """Kaiser low-pass FIR at fs_out·oversample: −6 dB at fs_out/2, 80 dB stop band from 0.55·fs_out.

    ``scipy.signal.firwin(numtaps, fs_out / 2, window=("kaiser", beta), fs=fs_fine)`` with
    ``numtaps, beta = scipy.signal.kaiserord(80, width)`` (numtaps made odd), written out in
    numpy (equal to 1e-15; a test compares them): importing scipy.signal costs every
    simulation a third of a second of CPU.
    """
    fs_fine = fs_out * oversample
    width = 0.1 * fs_out / (fs_fine / 2)
    ripple = 80.0  # dB; Kaiser's formulas (as scipy.signal.kaiserord / kaiser_beta)
    beta = 0.1102 * (ripple - 8.7)
    numtaps = int(math.ceil((ripple - 7.95) / 2.285 / (math.pi * width) + 1)) | 1
    cutoff = (fs_out / 2) / (fs_fine / 2)
    m = np.arange(numtaps) - 0.5 * (numtaps - 1)
    h = cutoff * np.sinc(cutoff * m) * np.kaiser(numtaps, beta)
    return h / np.sum(h)  # unit gain at 0 Hz


def _warm_up(asm=None, method=None):
    """Compile (or load from numba's cache) the loop of ``asm``'s kind for ``method``, or the
    loops of every kind for every method without ``asm`` (the benchmarks), once per process, by
    a 20 µs run; return the seconds it took (reported apart from run time)."""
    keys = [(_variants.kind_of(asm.p), method)] if asm is not None else [(k, None) for k in _variants.KINDS]
    todo = [k for k in keys if k not in _COMPILED["kinds"]]
    if not todo:
        return 0.0
    t0 = _time.perf_counter()
    for kind, m in todo:
        if asm is None:
            scene = load_scene({"output": {"duration_s": 1e-3, "settle_s": 0.0}, **_KIND_SCENES[kind]})
            run_on = assemble(scene, fidelity=scene.data["fidelity"].replace("auto", "multibody"))
        else:  # its own copy of the arrays the loop writes to (the table reach, the buffers)
            run_on = dataclasses.replace(asm, dflt=asm.dflt.copy(), hbuf=asm.hbuf.copy(), gbuf=asm.gbuf.copy())
        _run(run_on, METHODS["dp54"] if m is None else m, 1e-3, progress=False, t_end_override=2e-5,
             step=1e-6, fixed_method=m is not None)
        _COMPILED["kinds"].add((kind, m))
    _stepper.fir_decimate(np.zeros((4, 2)), np.ones(2), 0, 1, np.zeros((2, 2)))
    seconds = _time.perf_counter() - t0
    _COMPILED["seconds"] += seconds
    return seconds


class _Stream:
    """The output grids of one run and its records, filled chunk by chunk: nothing finer than the
    output rate is kept beyond one chunk plus the anti-alias filter's length.

    Fine velocity sample m (m = 0 .. n_fine) sits at base + (m - 1/2) dt_f; the fine-interval mean
    acceleration m (between velocity samples m and m+1) at base + m dt_f; output k at fine index
    m_pad + k R.
    """

    def __init__(self, asm, t_end_override, loads):
        scene, d = asm.scene, asm.scene.data
        fs = scene.fs_out
        self.R = R = int(d["output"]["oversample"])
        self.taps = anti_alias_taps(fs, R)
        self.taps_rev = np.ascontiguousarray(self.taps[::-1])
        self.half = len(self.taps) // 2
        self.dt_f = dt_f = 1.0 / (fs * R)
        self.n_out = n_out = int(round(scene.duration * fs)) if t_end_override is None else 1
        self.t0 = t0 = scene.settle if t_end_override is None else 0.0
        self.m_pad = m_pad = self.half + 2
        self.t_end = t0 + (n_out - 1) / fs + m_pad * dt_f if t_end_override is None else t_end_override
        self.base = t0 - m_pad * dt_f
        self.n_fine = m_pad + (n_out - 1) * R + m_pad + 1
        z = asm.n_balls
        self.three_d = three_d = asm.p[kernels.P_3D] > 0.5
        self.zb = zb = int(asm.p[kernels.P_ZOFF])
        self.vel_idx = np.full((3 if three_d else 2, 2), -1, dtype=np.int64)
        self.vel_sign = np.ones((3 if three_d else 2, 2))
        self.vel_idx[0, 0], self.vel_idx[1, 0] = 6, 7
        if three_d:
            self.vel_idx[2, 0] = zb + 3      # the outer ring's axial velocity (no sensor model along the axis)
        if d["sensor"]["enabled"]:
            sb = asm.sensor_index
            self.vel_idx[0, 1], self.vel_idx[1, 1] = sb + 2, sb + 3
        self.out_t = t0 + np.arange(n_out) / fs
        self.acc, self.disp = np.zeros((n_out, 2)), np.zeros((n_out, 4))
        self.acc_z = np.zeros(n_out) if three_d else None
        self.disp_z = np.zeros(n_out) if three_d else None
        self.angles = np.zeros((2, z, n_out)) if three_d else None
        self.cage_idx = 8 + 5 * z + 1
        self.cage_speed = np.zeros(n_out) if d["cage"]["model"] == "dynamic" else None
        self.fi = np.zeros((z, n_out)) if loads else None
        self.fo = np.zeros((z, n_out)) if loads else None
        self.m_next = 0    # next fine velocity index to produce
        self.o_next = 0    # next output index whose state is produced
        self.k_acc = 0     # next output index whose acceleration is computed
        self.v_buf = np.zeros((0, self.vel_idx.shape[0]))  # fine velocities [v_start, m_next)
        self.v_start = 0

    def grids(self, t_stop, n) -> Output:
        """The fine and output grids of a chunk of the loop ending at t_stop (``n`` states)."""
        dt_f, base = self.dt_f, self.base
        m_hi = min(int(math.floor((t_stop - base) / dt_f + 0.5)) + 1, self.n_fine + 1)
        while m_hi > self.m_next and base + (m_hi - 1 - 0.5) * dt_f > t_stop:
            m_hi -= 1
        fine_t = base + (np.arange(self.m_next, max(m_hi, self.m_next)) - 0.5) * dt_f
        o_hi = self.o_next
        while o_hi < self.n_out and self.out_t[o_hi] <= t_stop:
            o_hi += 1
        out_t = self.out_t[self.o_next:o_hi]
        return Output(self.vel_idx, self.vel_sign, fine_t, np.zeros((fine_t.size, self.vel_idx.shape[0])),
                      out_t, np.zeros((out_t.size, n)))

    def states(self, o: Output, kern, m, w) -> None:
        """Displacements, contact angles, cage speed and ball loads at a chunk's output samples."""
        lo, hi = self.o_next, self.o_next + o.out_t.size
        if lo == hi:
            return
        self.disp[lo:hi] = o.out_state[:, [0, 1, 4, 5]]
        if self.three_d:
            self.disp_z[lo:hi] = o.out_state[:, self.zb + 1]
            _stepper.contact_angles_at(o.out_t, o.out_state, m, self.angles[:, :, lo:hi])
        if self.cage_speed is not None:
            self.cage_speed[lo:hi] = o.out_state[:, self.cage_idx]
        if self.fi is not None:
            # written into new contiguous blocks, so that one compiled signature serves every chunk
            z = w.fi.size
            fi, fo = np.empty((z, hi - lo)), np.empty((z, hi - lo))
            kern.loads_at(o.out_t, o.out_state, m, fi, fo, w.ytmp, w.fi, w.fo)
            self.fi[:, lo:hi], self.fo[:, lo:hi] = fi, fo
        self.o_next = hi

    def accelerations(self, fine_out) -> None:
        """The accelerometer: fine-interval mean acceleration, FIR, decimate; keep the tail."""
        R, half, m_pad = self.R, self.half, self.m_pad
        self.m_next += fine_out.shape[0]
        self.v_buf = np.concatenate([self.v_buf, fine_out])
        a_fine = np.diff(self.v_buf, axis=0) / self.dt_f          # fine index v_start + i
        # outputs whose whole FIR window is available: centre m_pad + k R + half <= last index
        last = self.v_start + a_fine.shape[0] - 1
        k_acc = self.k_acc
        k_hi = min(self.n_out, (last - half - m_pad) // R + 1) if last - half - m_pad >= 0 else k_acc
        if k_hi > k_acc:
            s0 = m_pad + k_acc * R - half - self.v_start
            if self.three_d:
                _stepper.fir_decimate3(a_fine, self.taps_rev, s0, R, self.acc[k_acc:k_hi], self.acc_z[k_acc:k_hi])
            else:
                _stepper.fir_decimate(a_fine, self.taps_rev, s0, R, self.acc[k_acc:k_hi])
            self.k_acc = k_acc = k_hi
        # drop the velocities no later output needs; v_buf[0] is always fine index v_start
        drop = min(max(m_pad + k_acc * R - half - self.v_start, 0), self.v_buf.shape[0])
        self.v_buf = self.v_buf[drop:]
        self.v_start += drop

    def result(self, stats) -> dict:
        return dict(acc=self.acc, disp=self.disp, fi=self.fi, fo=self.fo, out_t=self.out_t,
                    cage_speed=self.cage_speed, taps=self.taps, R=self.R, acc_z=self.acc_z, disp_z=self.disp_z,
                    angles=self.angles, m_pad=self.m_pad, n_out=self.n_out, stats=stats, dt_f=self.dt_f,
                    t0=self.t0, t_end=self.t_end)


def _solver(asm, method, rtol, step, max_step, defect_steps):
    """The loop's :class:`Solver` settings and its first step (s)."""
    d = asm.scene.data
    hmax = max_step if max_step is not None else (d["solver"]["max_step_s"] or 2.5e-5)
    if method == METHODS["rk4"]:
        h = float(step if step is not None else d["solver"]["step_s"])
        hmax = h
    else:
        h = min(1e-6, hmax)
    rtol = float(rtol)
    return Solver(int(method), rtol, asm.atol_scale * rtol, float(hmax), float(defect_steps)), h


def _run(asm, method, rtol, *, progress, t_end_override=None, step=None, max_step=None,
         defect_steps=40, chunk_s=0.05, loads=True, fixed_method=False):
    """Integrate in chunks and stream the output (:class:`_Stream`).

    Returns a dict with ``acc`` (n_out, 2: x, y accelerometer signal), ``disp`` (n_out, 4:
    inner x, inner y, outer x, outer y), ``fi``/``fo`` (Z, n_out ball loads, or None),
    ``out_t`` (absolute output times), ``stats`` (steps, rejected, extra RHS) and ``t0``.
    """
    scene = asm.scene
    out = _Stream(asm, t_end_override, loads)
    sol, h = _solver(asm, int(method), rtol, step, max_step, defect_steps)
    # the loop compiled for this kind of scene (and with fixed_method, for this method only)
    kern = _variants.kernels(_variants.kind_of(asm.p), sol.method if fixed_method else None)
    m = asm.model
    w = new_work(asm.y0, asm.n_balls)
    t, t_end = 0.0, out.t_end
    # the progress bar appears once the run has taken 2 s: a shorter run never imports tqdm (0.05 s)
    bar, wall0 = None, _time.perf_counter()
    bar_at = wall0 + 2.0 if progress else math.inf
    try:
        while t < t_end:
            if bar is None and _time.perf_counter() >= bar_at:
                from tqdm.auto import tqdm  # measured exception: only a run that shows its bar pays for tqdm
                bar = tqdm(total=round(t_end, 6), initial=round(t, 6), unit="s sim", leave=False,
                           desc=f"simulate {scene.name}",
                           bar_format="{l_bar}{bar}| {n:.3f}/{total:.3f} s sim [{elapsed}<{remaining}]")
                bar.start_t -= _time.perf_counter() - wall0   # elapsed counts from the run's start
            t_stop = min(t + chunk_s, t_end)
            o = out.grids(t_stop, asm.y0.size)
            t_new, h, status = kern.integrate(t, t_stop, h, m, sol, w, o)
            if status != 0:
                what = "the state became NaN/Inf" if status == 1 else "the step size underflowed"
                raise SolverError(f"scene {scene.name!r}: integration failed at t = {t_new:.6g} s: {what} "
                                  f"(rtol {sol.rtol:g}); the scene may be "
                                  "unphysical, or try solver.method='dp54' with a smaller solver.max_step_s")
            out.states(o, kern, m, w)
            out.accelerations(o.fine_out)
            if bar is not None:
                bar.update(round(t_new - t, 6))
            t = t_new
    finally:
        if bar is not None:
            bar.close()
    if t_end_override is None and (out.k_acc != out.n_out or out.o_next != out.n_out):
        raise SolverError(f"scene {scene.name!r}: output incomplete ({out.k_acc}/{out.o_next} of {out.n_out} samples)")
    return out.result(w.stats)


def _bearing_model(d, static):
    """The ``bearing_model`` attribute of a 3-D run: what loads the bearing axially."""
    pre = float(d["load"].get("axial_preload_um") or 0.0)
    what = (f"axial displacement preload {pre:g} um ({static['axial_force_n']:.4g} N at the start)" if pre > 0
            else f"axial load {float(d['load']['axial_n']):g} N")
    return f"3-D: {what}, contact angles and axial ring motion"


def _decimate_acc(res):
    """Fine velocity -> fine-interval mean acceleration -> FIR -> output rate (whole record
    in memory; used for outside solvers' dense output in the benchmarks)."""
    v = res["fine_out"]
    a_fine = np.diff(v, axis=0) / res["dt_f"]           # sample m at t0 - m_pad dt_f + m dt_f
    taps = res["taps"]
    half = len(taps) // 2
    s0 = res["m_pad"] - half
    win = np.lib.stride_tricks.sliding_window_view(a_fine, len(taps), axis=0)  # (M', ch, taps)
    return win[s0:s0 + res["R"] * (res["n_out"] - 1) + 1:res["R"]] @ taps[::-1]


#: how many times a run whose balls reached above a defect table is repeated with the table extended
TABLE_EXTENSIONS = 2


def _tables_exceeded(asm) -> set:
    """Table entries (tabulated contact laws) whose forces were taken above the table's top."""
    return {k for k, t in enumerate(asm.tables)
            if asm.dint[k, kernels.D_KIND] == 1 and asm.dflt[k, kernels.F_REACH] > t.delta_max * (1 + 1e-9)}


def _assemble(sc, delta_top=None):
    """assemble(), with a failure to find the static equilibrium said in one line."""
    try:
        with np.errstate(all="ignore"):
            return assemble(sc, delta_top=delta_top)
    except (ValueError, ArithmeticError, RuntimeError) as exc:
        if isinstance(exc, BearingLabError):  # already one clear line (a SceneError, ...)
            raise
        raise SolverError(f"scene {sc.name!r}: no static equilibrium found for the initial state "
                          f"({type(exc).__name__}: {exc}); the load, speed, clearance or support "
                          "stiffness are beyond what the model can start from") from exc


def _solver_settings(sc, choice) -> dict:
    """The scene's solver settings (method name, rtol, max_step, step: RK4's step or None), the
    rule's choice where the method is "auto", the defaults where unset."""
    d = sc.data["solver"]
    method, max_step, rtol, step = d["method"], d["max_step_s"], d["rtol"], None
    if method == "auto":
        method = choice["method"]
        max_step = max_step if max_step is not None else choice["max_step_s"]
        rtol = rtol if rtol is not None else choice["rtol"]
        if method == "rk4" and choice.get("step_s"):
            step = choice["step_s"]
    return dict(method=method, rtol=rtol if rtol is not None else 1e-5,
                max_step=max_step if max_step is not None else 2.5e-5, step=step)


def _run_within_tables(sc, asm, settings, progress):
    """:func:`_run` with the scene's settings; a run whose balls reached above a defect table is
    run again on the extended table (:data:`TABLE_EXTENSIONS` times at most).  Returns (asm, res)."""
    d = sc.data
    kw = dict(progress=progress, max_step=settings["max_step"], step=settings["step"],
              defect_steps=d["solver"]["defect_steps"], loads=d["output"]["ball_loads"], fixed_method=True)
    res = _run(asm, METHODS[settings["method"]], settings["rtol"], **kw)
    for _ in range(TABLE_EXTENSIONS):
        over = _tables_exceeded(asm)
        if not over:
            break
        # a force was taken above a table's top (extrapolated): extend those tables, run again
        top = [max(1.25 * float(asm.dflt[k, kernels.F_REACH]), t.delta_max) if k in over else None
               for k, t in enumerate(asm.tables)]
        table_s = asm.table_time_s
        asm = _assemble(sc, delta_top=top)
        asm.table_time_s += table_s
        res = _run(asm, METHODS[settings["method"]], settings["rtol"], **kw)
    over = _tables_exceeded(asm)
    if over:
        raise SolverError(f"scene {sc.name!r}: the balls' approach on defect table(s) {sorted(over)} "
                          f"kept rising above the table after {TABLE_EXTENSIONS} extensions (reached "
                          + ", ".join(f"{1e6 * asm.dflt[k, kernels.F_REACH]:.3g} um over a "
                                      f"{1e6 * asm.tables[k].delta_max:.3g} um table" for k in sorted(over))
                          + "); the defect is deeper or the load larger than the contact law covers")
    return asm, res


def _dataset(sc, asm, res, acc, fi, fo) -> xr.Dataset:
    """The contract variables of a run (accelerometer signal ``acc``, ball loads ``fi``, ``fo``)."""
    disp = res["disp"]
    time = res["out_t"] - res["t0"]
    coords = {"time": ("time", time, {"units": "s", "long_name": "time from the record start"}),
              "ball": ("ball", np.arange(asm.n_balls), {"long_name": "ball index (cage order)"})}
    def v(data, units, long):
        return (("time",), data, {"units": units, "long_name": long, "quantity": QUANTITY_OF_UNITS[units]})
    ds = xr.Dataset(
        {
            "outer_ring_acc_y": v(acc[:, 1], "m s-2", "outer-ring acceleration Y (accelerometer signal)"),
            "outer_ring_acc_x": v(acc[:, 0], "m s-2", "outer-ring acceleration X (accelerometer signal)"),
            "outer_ring_disp_y": v(disp[:, 3], "m", "outer-ring displacement Y"),
            "outer_ring_disp_x": v(disp[:, 2], "m", "outer-ring displacement X"),
            "inner_ring_disp_y": v(disp[:, 1], "m", "inner-ring displacement Y"),
            "inner_ring_disp_x": v(disp[:, 0], "m", "inner-ring displacement X"),
        },
        coords=coords,
    )
    if res["angles"] is not None:
        ds["outer_ring_acc_z"] = v(res["acc_z"], "m s-2", "outer-ring acceleration Z (along the axis)")
        ds["outer_ring_disp_z"] = v(res["disp_z"], "m", "outer-ring displacement Z (along the axis)")
        for k, race in enumerate(("outer", "inner")):
            ds[f"contact_angle_{race}_deg"] = (("ball", "time"), res["angles"][k], {
                "units": "degree", "quantity": "angle",
                "long_name": f"ball-{race} race contact angle (positive: the load line leans as under a +Z "
                             "force on the outer ring)"})
    if res["cage_speed"] is not None:
        ds["cage_speed"] = (("time",), res["cage_speed"], {"units": "rad s-1", "long_name": "cage angular speed",
                                                           "quantity": "angular velocity"})
    if sc.data["output"]["ball_loads"]:
        ds["ball_load_outer"] = (("ball", "time"), fo, {"units": "N", "long_name": "ball-outer race normal load",
                                                        "quantity": "force"})
        ds["ball_load_inner"] = (("ball", "time"), fi, {"units": "N", "long_name": "ball-inner race normal load",
                                                        "quantity": "force"})
    return ds


def _attrs(sc, asm, res, choice, settings, wall, compile_s) -> dict:
    """The Dataset attributes of a run (``docs/architecture.md``)."""
    d = sc.data
    stats = res["stats"]
    three_d = res["angles"] is not None
    return {
        "title": f"bearing_lab simulation of scene {sc.name!r}",
        "sampling_rate_hz": float(sc.fs_out),
        "bearing_lab_version": __version__,
        "shaft_speed_rpm": float(sc.nominal_rpm),
        "bearing": sc.bearing.name,
        "default_channel": DEFAULT_CHANNEL,
        "fidelity": asm.fidelity,
        "scene_name": sc.name,
        "scene_toml": sc.to_toml(),
        "defect_contact_models": ",".join(asm.contact_models) if asm.contact_models else "none",
        "wall_time_s": float(wall),
        "table_time_s": float(asm.table_time_s),
        "compile_time_s": float(compile_s),
        "solver_method": settings["method"],
        "solver_rtol": float(settings["rtol"]),
        "solver_max_step_s": float(settings["max_step"]),
        "fidelity_requested": sc.fidelity,
        "auto_choice": (choice["reason"] + f"; kind {choice['kind']}, decided on the {choice['track']}; expected "
                        f"peak-acceleration error {choice['expected_peak_error']}")
        if "auto" in (sc.fidelity, d["solver"]["method"]) else "",
        "bearing_model": _bearing_model(d, asm.static) if three_d else "planar (no axial load)",
        **({"axial_force_n": float(asm.static["axial_force_n"])} if three_d else {}),
        "defect_table_top_um": ",".join(f"{1e6 * t.delta_max:.4g}" for t in asm.tables) if asm.tables else "none",
        "defect_table_reach_um": (",".join(f"{1e6 * asm.dflt[k, kernels.F_REACH]:.4g}" for k in range(len(asm.tables)))
                                  if asm.tables else "none"),
        "solver_steps": int(stats[0]),
        "solver_rejected_steps": int(stats[1]),
        "settle_time_s": float(sc.settle),
        "load_zone_angle_deg": float(math.degrees(asm.load_zone_angle) % 360),
        "load_path": d["load"]["path"],
        "anti_alias": f"Kaiser FIR {len(res['taps'])} taps at {d['output']['oversample']}x, -6 dB at fs/2",
        "sensor_resonator": "on" if d["sensor"]["enabled"] else "off",
        "cage_model": d["cage"]["model"],
        "Conventions": "CF-1.8",
    }


@fill_doc
def simulate(scene, *, fidelity: str | None = None, duration: float | None = None,
             fs: float | None = None, rtol: float | None = None, method: str | None = None,
             step: float | None = None, progress: bool = True, **overrides) -> xr.Dataset:
    """Simulate a scene and return the contract Dataset (SI units).

    Parameters
    ----------
    %(scene)s
    fidelity : {"multibody", "quasi-static", "auto"}, optional
        Ball model (default: the scene's ``fidelity``).
    %(duration)s
    fs : float, optional
        Output sampling rate, Hz (``output.sample_rate_hz``; default: the scene's).
    rtol, method, step : optional
        Override the solver settings ``solver.rtol``, ``solver.method`` and ``solver.step_s``.
    progress : bool
        Show a progress bar when a run takes more than 2 s.
    %(overrides)s

    Returns
    -------
    xarray.Dataset
        ``outer_ring_acc_{x,y}`` (m s-2), ``outer_ring_disp_{x,y}``, ``inner_ring_disp_{x,y}`` (m),
        ``ball_load_{outer,inner}`` (N, dims ball x time) and attributes ``bearing``,
        ``fidelity``, ``scene_toml``, ``wall_time_s`` (the run without the defect tables),
        ``table_time_s`` (building or loading the defect contact tables), ``compile_time_s``,
        ``sampling_rate_hz``, ``shaft_speed_rpm`` (``docs/architecture.md``).

    Raises
    ------
    SceneError
        An invalid scene or override, named with its key.
    SolverError
        The integration failed or diverged.

    See Also
    --------
    load_scene : the scene this function runs, without running it.
    list_scenes : the built-in scene names.
    bearing_lab.analysis.analyze : the same analysis a recording gets.
    bearing_lab.io.to_netcdf : write the Dataset.

    Examples
    --------
    Five milliseconds of the healthy 6308 (the compiled solver is cached after the first run):

    >>> from bearing_lab.sim import simulate
    >>> ds = simulate("paper-healthy", duration=0.005, progress=False)
    >>> ds.sizes["time"], ds.attrs["sampling_rate_hz"], ds.attrs["bearing"]
    (100, 20000.0, '6308')
    >>> # the balls carry the 150 N radial load: their contact forces add up to at least that
    >>> bool(ds["ball_load_outer"].sum("ball").min() >= 150.0)
    True
    """
    ov = merge_overrides(overrides, **{"output.duration_s": duration, "output.sample_rate_hz": fs,
                                       "solver.rtol": rtol, "solver.method": method,
                                       "solver.step_s": step, "fidelity": fidelity})
    sc = load_scene(scene, **ov)
    check_budget(sc)  # before any work: a scene that would run for days is refused here
    t_start = _time.perf_counter()
    asm = _assemble(sc)
    d = sc.data
    choice = resolve(sc)
    settings = _solver_settings(sc, choice)
    compile_s = _warm_up(asm, METHODS[settings["method"]])  # this scene's kind and method only
    asm, res = _run_within_tables(sc, asm, settings, progress)
    acc = res["acc"]
    if d["sensor"]["enabled"]:
        acc = acc * d["sensor"]["gain"]
    fi, fo = res["fi"], res["fo"]
    if fi is None:
        fi = fo = np.zeros((asm.n_balls, 0))
    # the time loop alone: the defect tables (built once per defect, then cached) apart
    wall = _time.perf_counter() - t_start - asm.table_time_s - compile_s
    for name, arr in (("acceleration", acc), ("displacements", res["disp"]), ("ball loads", fi), ("ball loads", fo)):
        if not np.all(np.isfinite(arr)):
            raise SolverError(f"scene {sc.name!r}: the {name} hold NaN/Inf; the solve diverged")
    ds = _dataset(sc, asm, res, acc, fi, fo)
    ds.attrs.update(_attrs(sc, asm, res, choice, settings, wall, compile_s))
    return ds
