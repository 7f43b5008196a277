"""Sweep scaling: a 200-scene sweep of 1 s scenes on 1 and on 2 Dask workers.

    .venv/bin/python benchmarks/sweep_scaling.py [--scenes 200] [--duration 1.0]
        [--workers 1 2] [--scene paper-slot] [--json out.json]

For each worker count it measures

- end to end: ``bearing_lab.sweep(..., n_workers=N)`` as a user calls it (the
  LocalCluster is started, the workers import bearing_lab and load the numba
  cache, every scene is simulated, written to a fresh cache directory and
  stacked into one Dataset, the cluster is closed);
- steady state: the same sweep on an already started and warmed-up cluster
  (``scheduler=Client``), i.e. the throughput a long sweep approaches.

Scaling efficiency = T(1 worker) / (N × T(N workers)); scenes per minute =
scenes / T × 60.  The grid is speed_rpm × load.radial_n, so every scene differs.
"""
from __future__ import annotations

import argparse
import json
import logging
import os
import platform
import shutil
import tempfile
import time


def _grid(n):
    import numpy as np
    n_speed = 20 if n % 20 == 0 else n
    n_load = n // n_speed
    speeds = [float(x) for x in np.linspace(1200.0, 2400.0, n_speed)]
    loads = [float(x) for x in np.linspace(100.0, 300.0, n_load)]
    return {"speed_rpm": speeds, "load.radial_n": loads}


def _warm(client):
    def w():
        from bearing_lab.sim.integrate import _warm_up
        return _warm_up()
    client.run(w)


def run(scene, n_scenes, duration, workers):
    import bearing_lab
    from dask.distributed import Client, LocalCluster
    params = _grid(n_scenes)
    rows = []
    for n in workers:
        row = {"workers": n}
        # end to end
        cache = tempfile.mkdtemp(prefix="sweep-bench-")
        try:
            t0 = time.perf_counter()
            ds = bearing_lab.sweep(scene, params, n_workers=n, cache_dir=cache, progress=False, duration=duration)
            row["end_to_end_s"] = time.perf_counter() - t0
            row["compute_s_sum"] = float(ds.wall_time_s.sum())
            row["result_mib"] = ds.nbytes / 2**20
            assert ds.attrs["sweep_computed"] == n_scenes
            del ds
        finally:
            shutil.rmtree(cache, ignore_errors=True)
        # steady state: cluster up and warm before the clock starts
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                               silence_logs=logging.ERROR)
        client = Client(cluster)
        cache = tempfile.mkdtemp(prefix="sweep-bench-")
        try:
            _warm(client)
            # one tiny scene per worker loads the defect kernels too
            bearing_lab.sweep(scene, {"speed_rpm": [1000.0 + i for i in range(n)]}, scheduler=client,
                              cache_dir=False, progress=False, duration=0.01)
            t0 = time.perf_counter()
            ds = bearing_lab.sweep(scene, params, scheduler=client, cache_dir=cache, progress=False,
                                   duration=duration)
            row["steady_s"] = time.perf_counter() - t0
            del ds
        finally:
            client.close()
            cluster.close()
            shutil.rmtree(cache, ignore_errors=True)
        for k in ("end_to_end", "steady"):
            row[f"{k}_scenes_per_min"] = n_scenes / row[f"{k}_s"] * 60
        rows.append(row)
        print(json.dumps(row), flush=True)
    base = rows[0]
    for row in rows:
        for k in ("end_to_end", "steady"):
            row[f"{k}_efficiency"] = base[f"{k}_s"] * base["workers"] / (row["workers"] * row[f"{k}_s"])
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="paper-slot")
    ap.add_argument("--scenes", type=int, default=200)
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--json", default=None, help="write the results here")
    args = ap.parse_args(argv)
    from bearing_lab.sweep import code_fingerprint
    info = {"simulator_fingerprint": code_fingerprint()[:16], "scene": args.scene, "scenes": args.scenes, "duration_s": args.duration,
            "cpus": os.cpu_count(), "python": platform.python_version(),
            "load_avg_start": os.getloadavg()}
    rows = run(args.scene, args.scenes, args.duration, args.workers)
    info["load_avg_end"] = os.getloadavg()
    import bearing_lab.sweep as sw
    sw._FINGERPRINT.clear()
    if sw.code_fingerprint()[:16] != info["simulator_fingerprint"]:
        print("WARNING: the simulator source changed during the run; the numbers mix two versions")
        info["simulator_changed_during_run"] = True
    print(f"\n{args.scenes} scenes of {args.scene}, {args.duration:g} s each; simulator "
          f"{info['simulator_fingerprint']}; {info['cpus']} CPUs; "
          f"load average {info['load_avg_start'][0]:.1f} at start, {info['load_avg_end'][0]:.1f} at end")
    print("| workers | end to end (s) | scenes/min | efficiency | steady state (s) | scenes/min | efficiency |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['workers']} | {r['end_to_end_s']:.1f} | {r['end_to_end_scenes_per_min']:.0f} | "
              f"{r['end_to_end_efficiency']:.2f} | {r['steady_s']:.1f} | {r['steady_scenes_per_min']:.0f} | "
              f"{r['steady_efficiency']:.2f} |")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"info": info, "rows": rows}, fh, indent=1)


if __name__ == "__main__":
    main()
