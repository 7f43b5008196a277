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
from . import _stepper as S
from . import _variants as V
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
_KIND_SCENES = {"kinematic": {}, "quasi_static": {"fidelity": "quasi-static"}, "dynamic": {"cage": {"model": "dynamic"}},
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
    keys = [(V.kind_of(asm.p), method)] if asm is not None else [(k, None) for k in V.KINDS]
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
    S.fir_decimate(np.zeros((4, 2)), np.ones(2), 0, 1, np.zeros((2, 2)))
    seconds = _time.perf_counter() - t0
    _COMPILED["seconds"] += seconds
    return seconds


def _loads(kern, out_t, out_state, args, work):
    """Ball loads (Z × samples, inner and outer) at the output samples: written into new
    contiguous blocks, so that one compiled signature serves every chunk."""
    z = work[1].size
    fi, fo = np.empty((z, out_t.size)), np.empty((z, out_t.size))
    kern.loads_at(out_t, out_state, *args, fi, fo, *work)
    return fi, fo


def _run(asm, method, rtol, *, progress, t_end_override=None, step=None, max_step=None,
         defect_steps=40, chunk_s=0.05, loads=True, fixed_method=False):
    """Integrate in chunks and stream the output: nothing finer than the output rate is kept
    beyond one chunk plus the anti-alias filter's length.

    Returns a dict with ``acc`` (n_out, 2: x, y accelerometer signal), ``disp`` (n_out, 4:
    inner x, inner y, outer x, outer y), ``fi``/``fo`` (Z, n_out ball loads, or None),
    ``out_t`` (absolute output times), ``stats`` (steps, rejected, extra RHS) and ``t0``.
    """
    scene = asm.scene
    d = scene.data
    fs = scene.fs_out
    R = int(d["output"]["oversample"])
    taps = anti_alias_taps(fs, R)
    taps_rev = np.ascontiguousarray(taps[::-1])
    half = len(taps) // 2
    dt_f = 1.0 / (fs * R)
    n_out = int(round(scene.duration * fs)) if t_end_override is None else 1
    t0 = scene.settle if t_end_override is None else 0.0
    m_pad = half + 2
    pad = m_pad * dt_f
    t_end = t0 + (n_out - 1) / fs + pad if t_end_override is None else t_end_override
    # fine velocity sample m (m = 0 .. n_fine) at base + (m - 1/2) dt_f; the fine-interval mean
    # acceleration m (between velocity samples m and m+1) sits at base + m dt_f; output k at
    # fine index m_pad + k R
    base = t0 - m_pad * dt_f
    n_fine = m_pad + (n_out - 1) * R + m_pad + 1
    n = asm.y0.size
    z = asm.n_balls
    three_d = asm.p[kernels.P_3D] > 0.5
    zb = int(asm.p[kernels.P_ZOFF])
    vel_idx = np.full((3 if three_d else 2, 2), -1, dtype=np.int64)
    vel_sign = np.ones((3 if three_d else 2, 2))
    vel_idx[0, 0], vel_idx[1, 0] = 6, 7
    if three_d:
        vel_idx[2, 0] = zb + 3      # the outer ring's axial velocity (no sensor model along the axis)
    if d["sensor"]["enabled"]:
        sb = asm.sensor_index
        vel_idx[0, 1], vel_idx[1, 1] = sb + 2, sb + 3
    out_t_all = t0 + np.arange(n_out) / fs
    acc = np.zeros((n_out, 2))
    disp = np.zeros((n_out, 4))
    acc_z = np.zeros(n_out) if three_d else None
    disp_z = np.zeros(n_out) if three_d else None
    angles = np.zeros((2, z, n_out)) if three_d else None
    dyn = d["cage"]["model"] == "dynamic"
    cage_idx = 8 + 5 * z + 1
    cage_speed = np.zeros(n_out) if dyn else None
    fi_all = np.zeros((z, n_out)) if loads else None
    fo_all = np.zeros((z, n_out)) if loads else None
    method = int(method)
    rtol = float(rtol)
    defect_steps = float(defect_steps)
    adaptive = method != METHODS["rk4"]
    hmax = max_step if max_step is not None else (d["solver"]["max_step_s"] or 2.5e-5)
    if not adaptive:
        h = float(step if step is not None else d["solver"]["step_s"])
        hmax = h
    else:
        h = min(1e-6, hmax)
    hmax = float(hmax)
    atol = asm.atol_scale * rtol
    y = asm.y0.copy()
    t = 0.0
    stats = np.zeros(3, dtype=np.int64)
    ctrl = np.array([math.log(1e-4), 0.0])  # step controller memory: log previous error, last step rejected
    m_next = 0                      # next fine velocity index to produce
    o_next = 0                      # next output index whose state is produced
    k_acc = 0                       # next output index whose acceleration is computed
    v_buf = np.zeros((0, vel_idx.shape[0]))  # fine velocities [v_start, m_next)
    v_start = 0
    args = (asm.p, asm.sp_t, asm.sp_w, asm.sp_th, asm.dint, asm.dflt, asm.hbuf, asm.gbuf)
    # the loop compiled for this kind of scene (and with fixed_method, for this method only)
    kern = V.kernels(V.kind_of(asm.p), int(method) if fixed_method else None)
    work = S.work_arrays(n, z)      # the loop's stage derivatives, state vectors and ball loads
    loads_work = (work[1], work[4], work[5])    # a state-size scratch vector and the two ball-load vectors
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
            m_hi = min(int(math.floor((t_stop - base) / dt_f + 0.5)) + 1, n_fine + 1)
            while m_hi > m_next and base + (m_hi - 1 - 0.5) * dt_f > t_stop:
                m_hi -= 1
            fine_t = base + (np.arange(m_next, max(m_hi, m_next)) - 0.5) * dt_f
            fine_out = np.zeros((fine_t.size, vel_idx.shape[0]))
            o_hi = o_next
            while o_hi < n_out and out_t_all[o_hi] <= t_stop:
                o_hi += 1
            out_t = out_t_all[o_next:o_hi]
            out_state = np.zeros((out_t.size, n))
            t_new, h, fpos, opos, status = kern.integrate(
                y, t, t_stop, h, *args, method, rtol, atol, hmax,
                defect_steps, vel_idx, vel_sign, fine_t, fine_out, 0, out_t, out_state, 0, stats, ctrl, *work)
            if status != 0:
                what = "the state became NaN/Inf" if status == 1 else "the step size underflowed"
                raise SolverError(f"scene {scene.name!r}: integration failed at t = {t_new:.6g} s: {what} "
                                  f"(rtol {rtol:g}); the scene may be "
                                  "unphysical, or try solver.method='dp54' with a smaller solver.max_step_s")
            # states at the output samples of this chunk: displacements and ball loads
            if out_t.size:
                disp[o_next:o_hi] = out_state[:, [0, 1, 4, 5]]
                if three_d:
                    disp_z[o_next:o_hi] = out_state[:, zb + 1]
                    S.contact_angles_at(out_t, out_state, asm.p, asm.sp_t, asm.sp_w, asm.sp_th,
                                        angles[:, :, o_next:o_hi])
                if dyn:
                    cage_speed[o_next:o_hi] = out_state[:, cage_idx]
                if loads:
                    fi_all[:, o_next:o_hi], fo_all[:, o_next:o_hi] = _loads(kern, out_t, out_state, args, loads_work)
                o_next = o_hi
            # accelerometer: fine-interval mean acceleration, FIR, decimate; keep the tail
            m_next += fine_t.size
            v_buf = np.concatenate([v_buf, fine_out])
            a_fine = np.diff(v_buf, axis=0) / dt_f          # fine index v_start + i
            # outputs whose whole FIR window is available: centre m_pad + k R + half <= last index
            last = v_start + a_fine.shape[0] - 1
            k_hi = min(n_out, (last - half - m_pad) // R + 1) if last - half - m_pad >= 0 else k_acc
            if k_hi > k_acc:
                s0 = m_pad + k_acc * R - half - v_start
                if three_d:
                    S.fir_decimate3(a_fine, taps_rev, s0, R, acc[k_acc:k_hi], acc_z[k_acc:k_hi])
                else:
                    S.fir_decimate(a_fine, taps_rev, s0, R, acc[k_acc:k_hi])
                k_acc = k_hi
            # drop the velocities no later output needs; v_buf[0] is always fine index v_start
            drop = min(max(m_pad + k_acc * R - half - v_start, 0), v_buf.shape[0])
            v_buf = v_buf[drop:]
            v_start += drop
            if bar is not None:
                bar.update(round(t_new - t, 6))
            t = t_new
    finally:
        if bar is not None:
            bar.close()
    if t_end_override is None and (k_acc != n_out or o_next != n_out):
        raise SolverError(f"scene {scene.name!r}: output incomplete ({k_acc}/{o_next} of {n_out} samples)")
    return dict(acc=acc, disp=disp, fi=fi_all, fo=fo_all, out_t=out_t_all, cage_speed=cage_speed, taps=taps, R=R,
                acc_z=acc_z, disp_z=disp_z, angles=angles,
                m_pad=m_pad, n_out=n_out, stats=stats, dt_f=dt_f, t0=t0, t_end=t_end)


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
    method_name = d["solver"]["method"]
    max_step = d["solver"]["max_step_s"]
    rtol_ = d["solver"]["rtol"]
    step_ = None
    if method_name == "auto":
        method_name = choice["method"]
        max_step = max_step if max_step is not None else choice["max_step_s"]
        rtol_ = rtol_ if rtol_ is not None else choice["rtol"]
        if method_name == "rk4" and choice.get("step_s"):
            step_ = choice["step_s"]
    rtol_ = rtol_ if rtol_ is not None else 1e-5
    max_step = max_step if max_step is not None else 2.5e-5
    compile_s = _warm_up(asm, METHODS[method_name])  # this scene's kind and method only
    res = _run(asm, METHODS[method_name], rtol_, progress=progress, max_step=max_step, step=step_,
               defect_steps=d["solver"]["defect_steps"], loads=d["output"]["ball_loads"], fixed_method=True)
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
        res = _run(asm, METHODS[method_name], rtol_, progress=progress, max_step=max_step, step=step_,
                   defect_steps=d["solver"]["defect_steps"], loads=d["output"]["ball_loads"], fixed_method=True)
    over = _tables_exceeded(asm)
    if over:
        raise SolverError(f"scene {sc.name!r}: the balls' approach on defect table(s) {sorted(over)} "
                          f"kept rising above the table after {TABLE_EXTENSIONS} extensions (reached "
                          + ", ".join(f"{1e6 * asm.dflt[k, kernels.F_REACH]:.3g} um over a "
                                      f"{1e6 * asm.tables[k].delta_max:.3g} um table" for k in sorted(over))
                          + "); the defect is deeper or the load larger than the contact law covers")
    acc = res["acc"]
    if d["sensor"]["enabled"]:
        acc = acc * d["sensor"]["gain"]
    disp = res["disp"]
    z = asm.n_balls
    fi, fo = res["fi"], res["fo"]
    if fi is None:
        fi = fo = np.zeros((z, 0))
    # the time loop alone: the defect tables (built once per defect, then cached) apart
    wall = _time.perf_counter() - t_start - asm.table_time_s - compile_s
    for name, arr in (("acceleration", acc), ("displacements", disp), ("ball loads", fi), ("ball loads", fo)):
        if not np.all(np.isfinite(arr)):
            raise SolverError(f"scene {sc.name!r}: the {name} hold NaN/Inf; the solve diverged")
    time = res["out_t"] - res["t0"]
    coords = {"time": ("time", time, {"units": "s", "long_name": "time from the record start"}),
              "ball": ("ball", np.arange(z), {"long_name": "ball index (cage order)"})}
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
    if d["output"]["ball_loads"]:
        ds["ball_load_outer"] = (("ball", "time"), fo, {"units": "N", "long_name": "ball-outer race normal load",
                                                        "quantity": "force"})
        ds["ball_load_inner"] = (("ball", "time"), fi, {"units": "N", "long_name": "ball-inner race normal load",
                                                        "quantity": "force"})
    stats = res["stats"]
    ds.attrs.update({
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
        "solver_method": method_name,
        "solver_rtol": float(rtol_),
        "solver_max_step_s": float(max_step),
        "fidelity_requested": sc.fidelity,
        "auto_choice": (choice["reason"] + f"; kind {choice['kind']}, decided on the {choice['track']}; expected "
                        f"peak-acceleration error {choice['expected_peak_error']}")
        if "auto" in (sc.fidelity, d["solver"]["method"]) else "",
        "bearing_model": _bearing_model(d, asm.static) if res["angles"] is not None else "planar (no axial load)",
        **({"axial_force_n": float(asm.static["axial_force_n"])} if res["angles"] is not None else {}),
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
    })
    return ds
