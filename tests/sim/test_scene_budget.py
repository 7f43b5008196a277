"""Hostile scenes end in seconds with one line; --set aliases and the API never leak tracebacks.

Without its guard, each key below would hang the process (settle time, step sizes, defect steps, a sensor
resonance that forces a sub-nanosecond step), end in a foreign exception (brentq, firwin,
MemoryError, TypeError), or silently simulate something else (a defect off the ball track).
"""
import subprocess
import sys
import resource
import tracemalloc
import warnings

import pytest

from bearing_lab.errors import BearingLabError, SceneError, SolverError
from bearing_lab.sim import load_scene, simulate
from bearing_lab.sim.budget import check_budget, work_estimate
from bearing_lab.sim.limits import SceneWarning
from bearing_lab.sim.scene import merge_overrides, parse_set

HOSTILE = [
    (["output.settle_s=1e9"], "budget.max_steps"),
    (["solver.method=rk4", "solver.step_s=1e-15"], "set by solver.step_s"),
    (["solver.max_step_s=1e-15"], "set by solver.max_step_s"),
    (["solver.defect_steps=1e9"], "solver.defect_steps=1000000000"),
    (["sensor.enabled=true", "sensor.frequency_hz=1e9"], "sensor.frequency_hz"),
    (["speed_rpm=1e9"], "n·d_m"),
    (["shaft.stiffness_y_n_m=1e-10", "load.on=outer"], "shaft.stiffness_y_n_m=1e-10"),
    (["mount.stiffness_x_n_m=1e-10"], "mount.stiffness_x_n_m=1e-10"),
    (["output.oversample=1"], "output.oversample=1"),
    (["fs=1e300"], "output.sample_rate_hz: 1e+300 is beyond any physical value"),
    (["sensor.enabled=true", "sensor.damping_ratio=1e6"], "set by sensor.damping_ratio"),
    (["fs=1e-300"], "below 1 kHz"),
    (["output.duration_s=1e-9"], "0 sample(s)"),
    (["fs=1e9"], "budget.max_"),
]


@pytest.mark.parametrize("sets, needle", HOSTILE, ids=[" ".join(s) for s, _ in HOSTILE])
def test_hostile_scene_refused_in_one_line_within_10_s(tmp_path, sets, needle):
    out = tmp_path / "x.nc"
    cmd = [sys.executable, "-m", "bearing_lab", "simulate", "paper-O1", "-q", "-o", str(out)]
    for s in sets:
        cmd += ["--set", s]
    # the refusal must come before any work: the child's CPU time (not wall clock, which a busy
    # machine stretches) stays far under what the refused scene would take; a hang hits the timeout
    c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    assert (c1.ru_utime + c1.ru_stime) - (c0.ru_utime + c0.ru_stime) < 10.0
    assert r.returncode == 2, r.stderr[-800:]
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], r.stderr
    assert not out.exists()


def test_aliases_in_set_and_flags(tmp_path):
    """`--set fs=` and `--set duration=` (documented aliases) raised TypeError."""
    out = tmp_path / "a.nc"
    r = subprocess.run([sys.executable, "-m", "bearing_lab", "simulate", "paper-healthy", "-q",
                        "--set", "fs=40000", "--set", "duration=0.005", "-o", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    import xarray as xr
    ds = xr.load_dataset(out)
    assert ds.attrs["sampling_rate_hz"] == 40000.0 and ds.sizes["time"] == 200
    with pytest.raises(SceneError, match="output.duration_s is given twice"):
        merge_overrides(parse_set(["duration=0.1"]), **{"output.duration_s": 0.2})
    with pytest.raises(SceneError, match="already given"):
        parse_set(["fs=1000", "output.sample_rate_hz=2000"])
    assert merge_overrides(parse_set(["fs=40000"]), **{"output.sample_rate_hz": 40000.0})


def test_api_refuses_before_allocating():
    """fs=1e9 through the API is refused from its size, before the record is allocated (unguarded: MemoryError after minutes)."""
    with pytest.raises(SceneError, match="budget"):
        simulate("paper-healthy", fs=1e9, progress=False)     # once for the imports tracemalloc would count
    tracemalloc.start()
    try:
        with pytest.raises(SceneError, match="budget"):
            simulate("paper-healthy", fs=1e9, progress=False)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 50_000_000, f"{peak} bytes allocated before the refusal"


def test_budget_is_raised_by_its_key():
    sc = load_scene("paper-O1", **{"solver.defect_steps": 1e8})
    with pytest.raises(SceneError, match=r"needs at least .* --set budget.max_steps"):
        check_budget(sc)
    raised = load_scene("paper-O1", **{"solver.defect_steps": 1e8, "budget.max_steps": 1e12})
    assert check_budget(raised)["steps"] > 5e8


@pytest.mark.parametrize("name, ov", [
    ("paper-healthy", {}),
    ("paper-O1", {"solver.defect_steps": 400}),
    ("paper-O1", {"solver.method": "rk4", "solver.step_s": 1e-6}),
    ("paper-healthy", {"sensor.enabled": True, "sensor.frequency_hz": 2e5}),
])
def test_step_estimate_is_a_tight_lower_bound(name, ov):
    """The estimate never exceeds the accepted steps of a real run, and is within 3x of them."""
    sc = load_scene(name, **ov, **{"output.duration_s": 0.03})
    est = work_estimate(sc)["steps"]
    got = simulate(sc, progress=False).attrs["solver_steps"]
    assert est <= got <= 3 * est, (est, got)


def test_defect_off_the_ball_track_warns():
    """offset_mm=5 on a 1 mm defect (a typo for 0.5) simulated a healthy bearing in silence."""
    with pytest.warns(SceneWarning, match="misses the ball track"):
        load_scene("paper-O1", **{"defect.offset_mm": 5})
    with warnings.catch_warnings():
        warnings.simplefilter("error", SceneWarning)
        load_scene("paper-O1", **{"defect.offset_mm": 0.5})


def test_failed_equilibrium_is_a_solver_error(monkeypatch):
    from bearing_lab.sim import integrate

    def broken(scene, fidelity=None, delta_top=None):
        raise ValueError("f(a) and f(b) must have different signs")

    monkeypatch.setattr(integrate, "assemble", broken)
    with pytest.raises(SolverError, match="no static equilibrium"):
        simulate("paper-healthy", duration=0.005, progress=False)


def test_dask_cluster_that_fails_to_start(monkeypatch):
    import dask.distributed
    from bearing_lab import run_sweep

    class Broken:
        def __init__(self, *a, **k):
            raise RuntimeError("Nanny failed to start")

    monkeypatch.setattr(dask.distributed, "LocalCluster", Broken)
    with pytest.raises(BearingLabError, match=r"local Dask cluster .* did not start .*serial"):
        run_sweep("paper-healthy", {"speed_rpm": [900, 1800]}, cache_dir=False, progress=False,
                  duration=0.005)


def test_overdamped_sensor_counts_the_stiffness_it_implies():
    """sensor.damping_ratio=1e6 ran for 15+ minutes on 0.01 s: the budget saw only the frequency."""
    sc = load_scene("paper-O1", **{"sensor.enabled": True, "sensor.damping_ratio": 1e6,
                                   "output.duration_s": 0.01})
    with pytest.raises(SceneError, match=r"set by sensor.damping_ratio \(with sensor.frequency_hz\)"):
        check_budget(sc)
    light = load_scene("paper-O1", **{"sensor.enabled": True, "output.duration_s": 0.01})
    assert work_estimate(light)["step_key"] == "solver.max_step_s"  # ζ = 0.05: unchanged
    heavy = load_scene("paper-O1", **{"sensor.enabled": True, "sensor.damping_ratio": 1e3,
                                      "output.duration_s": 0.01})
    w = work_estimate(heavy)
    assert w["step_key"].startswith("sensor.damping_ratio")
    assert w["max_step_s"] == pytest.approx(2.8 / (2 * 3.141592653589793 * 5000 * (1e3 + (1e6 - 1) ** 0.5)))


@pytest.mark.parametrize("key", ["bearing_geometry.outer_diameter_mm", "output.oversample",
                                 "material.youngs_modulus_gpa"])
def test_huge_numbers_are_refused_by_key(key):
    """1e308 raised OverflowError deep in the mass or memory estimate."""
    with pytest.raises(SceneError, match=rf"{key}: 1e\+308 is beyond any physical value of this key"):
        load_scene("paper-healthy", **parse_set([f"{key}=1e308"]))


def test_text_and_list_keys_can_be_set():
    """bearing=6205, speed.profile=[[...]] and defect.vertices_mm=[[...]] as the scene keys say."""
    sc = load_scene("paper-healthy", **parse_set(["bearing=6205"]))
    assert sc.data["bearing"] == "6205" and sc.bearing.n_balls == 9
    sc = load_scene("paper-healthy", **parse_set(["speed.profile=[[0, 1000], [0.05, 1800]]"]))
    assert sc.data["speed"]["profile"] == [[0, 1000], [0.05, 1800]]
    sc = load_scene("paper-healthy", **parse_set(["defect.shape=polygon", "defect.depth_mm=0.1",
                                                  "defect.vertices_mm=[[0,0],[1,1],[1,0]]"]))
    assert sc.data["defect"][0]["vertices_mm"] == [[0, 0], [1, 1], [1, 0]]
    with pytest.raises(SceneError, match=r"--set speed.profile: '\[\[0,1000\],' is not a list in TOML"):
        load_scene("paper-healthy", **parse_set(["speed.profile=[[0,1000],"]))
    with pytest.raises(SceneError, match="bearing"):
        load_scene("paper-healthy", **parse_set(["bearing=9999"]))
