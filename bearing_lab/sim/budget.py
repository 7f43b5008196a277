"""The work a scene implies, estimated before it runs, and the budget it must fit.

Why: a scene is a few numbers, and some innocent-looking ones ask for years of
computing or terabytes of memory (``output.settle_s = 1e9``, an rk4 ``step_s`` of
1e-15 s, ``solver.defect_steps = 1e9``, a 1 GHz sensor resonance that forces a
sub-nanosecond explicit step, ``fs = 1e9``).  Run as given, they hang the process or
end in a MemoryError.  :func:`work_estimate` bounds the work from below without
running anything:

- integration steps >= simulated time / largest allowed step, where the largest step
  is the fixed rk4 step, or the adaptive methods' ceiling, or the explicit stability
  limit of the sensor resonator (|h·λ| <= 2.8 for the Runge-Kutta methods used:
  Hairer, Nørsett & Wanner, *Solving ODEs I*, 1993, fig. IV.2.1; λ the resonator's fastest
  eigenvalue, ω below critical damping and ω(ζ + √(ζ²-1)) above it), whichever is
  smallest; plus ``defect_steps`` per ball crossing of every defect (BPFO crossings a
  second for an outer-race defect, BPFI for an inner-race one, 2·BSF for a ball defect);
- interpolated samples on the fine anti-aliasing grid: oversample × rate × simulated time;
- memory: the output arrays (two accelerations, four displacements, 2·Z ball loads, the
  cage speed) plus one chunk of the fine grid.

:func:`check_budget` refuses a scene over the budget (``[budget]`` keys, defaults below,
raised with ``--set budget.max_steps=...``) with one line that gives the estimate and
the key to change.  The defaults admit the longest scene the schema allows (600 s at
20 kHz) with room to spare.
"""
from __future__ import annotations

import math

from ..errors import SceneError
from .auto import resolve

RK_STABILITY = 2.8       # |h·ω| limit of explicit RK4 / DP5 / BS3 on an undamped oscillator
CHUNK_S = 0.01           # simulated time per streamed chunk (integrate._run)


def _max_step(scene, method: str, step, max_step) -> tuple[float, str]:
    """Largest step the integrator may take, and the key that sets it."""
    d = scene.data
    if method == "rk4":
        h, key = float(step if step is not None else d["solver"]["step_s"]), "solver.step_s"
    else:
        h, key = float(max_step if max_step is not None else (d["solver"]["max_step_s"] or 2.5e-5)), \
            "solver.max_step_s"
    if d["sensor"]["enabled"]:
        zeta = d["sensor"]["damping_ratio"]
        # fastest eigenvalue of the resonator: |λ| = ω below critical damping, ω(ζ + √(ζ²-1))
        # (about 2ζω) above it: a damping ratio of 1e6 is as stiff as a resonance 2e6 times higher
        stiff = 1.0 if zeta <= 1.0 else zeta + math.sqrt(zeta * zeta - 1.0)
        h_stable = RK_STABILITY / (2 * math.pi * d["sensor"]["frequency_hz"] * stiff)
        if h_stable < h:
            h, key = h_stable, "sensor.frequency_hz" if stiff == 1.0 else \
                "sensor.damping_ratio (with sensor.frequency_hz)"
    return h, key


def work_estimate(scene, *, method: str | None = None, step=None, max_step=None) -> dict:
    """Lower bounds of the work of ``scene``: steps, fine samples, memory (bytes).

    ``method``/``step``/``max_step``: the solver settings that will be used (default: the
    scene's, with ``"auto"`` resolved by :func:`bearing_lab.sim.auto.resolve`).
    """
    d = scene.data
    if method is None or method == "auto":
        method = d["solver"]["method"]
        if method == "auto":
            choice = resolve(scene)
            method = choice["method"]
            max_step = max_step if max_step is not None else (d["solver"]["max_step_s"]
                                                              or choice.get("max_step_s"))
            step = step if step is not None else (choice.get("step_s") or None)
    h, h_key = _max_step(scene, method, step, max_step)
    fs, dur = scene.fs_out, scene.duration
    sim_time = scene.settle + dur  # (the anti-alias filter adds a few output periods more)
    shaft_hz = scene.nominal_rpm / 60.0
    z = scene.bearing.n_balls
    ff = scene.bearing.frequency_factors()
    per_rev = {"outer": ff["bpfo"], "inner": ff["bpfi"], "ball": 2 * ff["bsf"]}
    crossings = sum(per_rev.get(getattr(dft, "race", "outer"), ff["bpfi"]) for dft in scene.defects)
    defect_steps = crossings * shaft_hz * sim_time * d["solver"]["defect_steps"]
    oversample = d["output"]["oversample"]
    n_out = round(dur * fs)
    per_sample = 6 + (2 * z if d["output"]["ball_loads"] else 0) + 1
    memory = 8.0 * (n_out * per_sample + 3 * oversample * fs * CHUNK_S * 2)
    return {"steps": sim_time / h + defect_steps, "step_key": h_key, "max_step_s": h,
            "defect_steps": defect_steps, "fine_samples": oversample * fs * sim_time,
            "memory_bytes": memory, "output_samples": n_out, "simulated_s": sim_time}


def check_budget(scene, **solver) -> dict:
    """Raise :class:`SceneError` if the scene's work exceeds its ``[budget]``; return the estimate."""
    w = work_estimate(scene, **solver)
    b = scene.data["budget"]
    name = scene.name
    if w["steps"] > b["max_steps"]:
        why = (f"{w['defect_steps']:.3g} of them in {len(scene.defects)} defect(s) at "
               f"solver.defect_steps={scene.data['solver']['defect_steps']}"
               if w["defect_steps"] > 0.5 * w["steps"] else
               f"{w['simulated_s']:.3g} s simulated (settle + duration) at steps of at most "
               f"{w['max_step_s']:.3g} s, set by {w['step_key']}")
        raise SceneError(f"scene {name!r} needs at least {w['steps']:.3g} integration steps ({why}); "
                         f"the budget is budget.max_steps={b['max_steps']:.3g}: change the scene, or "
                         "raise the budget with --set budget.max_steps=<n>")
    if w["fine_samples"] > b["max_fine_samples"]:
        raise SceneError(f"scene {name!r} interpolates {w['fine_samples']:.3g} samples on the "
                         f"anti-aliasing grid (output.oversample × output.sample_rate_hz × "
                         f"{w['simulated_s']:.3g} s); the budget is budget.max_fine_samples="
                         f"{b['max_fine_samples']:.3g}: lower the rate or the duration, or raise it "
                         "with --set budget.max_fine_samples=<n>")
    if w["memory_bytes"] > b["max_memory_mb"] * 1e6:
        raise SceneError(f"scene {name!r} needs about {w['memory_bytes'] / 1e6:.3g} MB for "
                         f"{w['output_samples']:.3g} output samples; the budget is "
                         f"budget.max_memory_mb={b['max_memory_mb']:g}: lower output.duration_s or "
                         "output.sample_rate_hz, set output.ball_loads=false, or raise it with "
                         "--set budget.max_memory_mb=<MB>")
    return w
