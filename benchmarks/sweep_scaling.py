"""Sweep scaling: a 200-scene sweep of 1 s scenes on 1 and on 2 Dask workers.

    .venv/bin/python benchmarks/sweep_scaling.py [--scenes 200] [--duration 1.0]
        [--workers 1 2] [--rounds 2] [--scene paper-slot] [--json out.json]

Two ways of timing a sweep, each for every worker count:

- end to end: ``bearing_lab.run_sweep(..., n_workers=N)`` as a user calls it (the
  LocalCluster is started, the workers import bearing_lab and load the numba
  cache, every scene is simulated, written to a fresh cache directory and
  stacked into one Dataset, the cluster is closed);
- steady state: the same sweep on an already started and warmed-up cluster
  (``scheduler=Client``), the throughput a long sweep approaches.

Before the timed runs, one untimed two-scene sweep makes numba's disk cache and the scene's contact
table, which the first timed run would otherwise carry alone.

Scaling efficiency = T(1 worker) / (N × T(N workers)); scenes per minute =
scenes / T × 60.  The grid is speed_rpm × load.radial_n, so every scene differs.

The runs go in ABBA order (1, 2, 2, 1 workers for two rounds) so a change of the
background load does not favour one worker count, and each run records the CPU
time other processes on the machine used meanwhile (``others_cores``: system busy
CPU minus this benchmark's own processes, in cores), and the mean compute time
per scene (simulate's ``wall_time_s``), which grows when the cores are contended.
"""
from __future__ import annotations

import argparse
import json
import logging
import os
import platform
import resource
import shutil
import statistics
import tempfile
import time


def _grid(n):
    import numpy as np
    n_speed = 20 if n % 20 == 0 else n
    n_load = n // n_speed
    speeds = [float(x) for x in np.linspace(1200.0, 2400.0, n_speed)]
    loads = [float(x) for x in np.linspace(100.0, 300.0, n_load)]
    return {"speed_rpm": speeds, "load.radial_n": loads}


def _busy():
    import psutil
    t = psutil.cpu_times()
    return sum(t) - t.idle - getattr(t, "iowait", 0.0)


def _own_cpu():
    s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime


def _worker_cpu(client):
    import psutil
    tot = 0.0
    for pid in client.run(os.getpid).values():
        t = psutil.Process(pid).cpu_times()
        tot += t.user + t.system
    return tot


def _end_to_end(scene, params, n, duration):
    import bearing_lab
    cache = tempfile.mkdtemp(prefix="sweep-bench-")
    try:
        b0, o0, t0 = _busy(), _own_cpu(), time.perf_counter()
        ds = bearing_lab.run_sweep(scene, params, n_workers=n, cache_dir=cache, progress=False, duration=duration)
        el = time.perf_counter() - t0
        # the worker processes were children of this one and have been reaped: RUSAGE_CHILDREN has them
        own, busy = _own_cpu() - o0, _busy() - b0
        out = dict(seconds=el, scene_compute_s=float(ds.wall_time_s.mean()), others_cores=max(busy - own, 0) / el,
                   result_mib=ds.nbytes / 2**20)
        assert ds.attrs["sweep_computed"] == sum(1 for _ in range(ds.attrs["sweep_n_scenes"]))
        return out
    finally:
        shutil.rmtree(cache, ignore_errors=True)


def _steady(scene, params, n, duration):
    import bearing_lab
    from dask.distributed import Client, LocalCluster
    import dask
    with dask.config.set({"distributed.worker.profile.enabled": False}):  # as bearing_lab.run_sweep's own cluster
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                               silence_logs=logging.ERROR)
    client = Client(cluster)
    cache = tempfile.mkdtemp(prefix="sweep-bench-")
    try:
        # warm every worker: compile/cache-load, including the defect kernels
        bearing_lab.run_sweep(scene, {"speed_rpm": [1000.0 + i for i in range(2 * n)]}, scheduler=client,
                          cache_dir=False, progress=False, duration=0.01)
        b0, o0, w0, t0 = _busy(), _own_cpu(), _worker_cpu(client), time.perf_counter()
        ds = bearing_lab.run_sweep(scene, params, scheduler=client, cache_dir=cache, progress=False, duration=duration)
        el = time.perf_counter() - t0
        own = _own_cpu() - o0 + _worker_cpu(client) - w0
        busy = _busy() - b0
        return dict(seconds=el, scene_compute_s=float(ds.wall_time_s.mean()), others_cores=max(busy - own, 0) / el,
                    result_mib=ds.nbytes / 2**20)
    finally:
        client.close()
        cluster.close()
        shutil.rmtree(cache, ignore_errors=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="paper-slot")
    ap.add_argument("--scenes", type=int, default=200)
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--rounds", type=int, default=2, help="ABBA rounds (1: one run per worker count and mode)")
    ap.add_argument("--modes", nargs="+", default=["end_to_end", "steady"], choices=["end_to_end", "steady"])
    ap.add_argument("--json", default=None, help="write the results here")
    args = ap.parse_args(argv)
    import bearing_lab.sweep as sw
    info = {"simulator_fingerprint": sw.code_fingerprint()[:16], "scene": args.scene, "scenes": args.scenes,
            "duration_s": args.duration, "cpus": os.cpu_count(), "python": platform.python_version(),
            "load_avg_start": os.getloadavg(), "started": time.strftime("%Y-%m-%d %H:%M:%S")}
    params = _grid(args.scenes)
    order = []
    for r in range(args.rounds):
        order += args.workers if r % 2 == 0 else args.workers[::-1]
    runs = []
    fn = {"end_to_end": _end_to_end, "steady": _steady}
    # one untimed sweep first: numba's disk cache and the scene's contact table are made here, so that
    # the first timed run does not carry them (a user's sweep after the first simulation of the scene)
    import bearing_lab
    t0 = time.perf_counter()
    bearing_lab.run_sweep(args.scene, {"speed_rpm": [1000.0, 1001.0]}, n_workers=1, cache_dir=False, progress=False,
                          duration=0.01)
    print(f"warm-up (numba cache, contact table; not in the table): {time.perf_counter() - t0:.1f} s", flush=True)
    for n in order:
        for mode in args.modes:
            row = dict(workers=n, mode=mode, **fn[mode](args.scene, params, n, args.duration))
            sw._FINGERPRINT.clear()
            row["simulator"] = sw.code_fingerprint()[:16]
            runs.append(row)
            print(json.dumps(row), flush=True)
    info["load_avg_end"] = os.getloadavg()
    if {r["simulator"] for r in runs} != {info["simulator_fingerprint"]}:
        print("WARNING: the simulator source changed during the run; the numbers mix versions")
        info["simulator_changed_during_run"] = True
    summary = []
    for mode in args.modes:
        best = {}
        for n in args.workers:
            rs = [r for r in runs if r["workers"] == n and r["mode"] == mode]
            best[n] = dict(workers=n, mode=mode, seconds=statistics.median(r["seconds"] for r in rs),
                           scene_compute_s=statistics.median(r["scene_compute_s"] for r in rs),
                           others_cores=statistics.median(r["others_cores"] for r in rs), runs=len(rs))
        base = best[args.workers[0]]
        for n, b in best.items():
            b["scenes_per_min"] = args.scenes / b["seconds"] * 60
            b["efficiency"] = base["seconds"] * base["workers"] / (n * b["seconds"])
            summary.append(b)
    print(f"\n{args.scenes} scenes of {args.scene}, {args.duration:g} s each; simulator "
          f"{info['simulator_fingerprint']}; {info['cpus']} CPUs; load average {info['load_avg_start'][0]:.1f} "
          f"at start, {info['load_avg_end'][0]:.1f} at end; median of {args.rounds} run(s)")
    print("| mode | workers | time (s) | scenes/min | scaling efficiency | compute per scene (s) | other processes (cores) |")
    print("|---|---|---|---|---|---|---|")
    for b in summary:
        print(f"| {b['mode'].replace('_', ' ')} | {b['workers']} | {b['seconds']:.1f} | {b['scenes_per_min']:.0f} | "
              f"{b['efficiency']:.2f} | {b['scene_compute_s']:.3f} | {b['others_cores']:.2f} |")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"info": info, "runs": runs, "summary": summary}, fh, indent=1)


if __name__ == "__main__":
    main()
