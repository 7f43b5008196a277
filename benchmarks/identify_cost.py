"""What an identification's scenes cost: the figures ``bearing-lab identify`` estimates its CPU time from.

Run:  .venv/bin/python benchmarks/identify_cost.py [--repeat N]

On paper-O2 (the stand-in rig of docs/identification.md: 6308, 320 N, 1793 r/min) at the comparison's
rtol 1e-6 and 20 kHz, in one process (numba compiled first, its time printed apart), with an empty
table cache of its own:

1. CPU time (``time.process_time``) of a cold contact table as the simulation builds it: an outline with
   sides along and across the track (θ = 0) and skewed ones (θ = 15, 30, 60°), at H = 0 and 0.3 mm;
2. CPU time of one scene of 1 s with its table cached (the time loop, the output Dataset and the
   impact signature's share are not separated: what an identification pays per scene).

The constants in :mod:`bearing_lab.validation.identify_run` (``TABLE_CPU_S``, ``SCENE_CPU_S_PER_S``)
bracket these with the spread of a shared machine; update them from this output.

``--walkthrough``: the README walkthrough's identification, as a user runs it (the same commands: ``case
standin``, ``case new``, the TOML additions, ``validate``, then ``identify rig.toml -o reports --report``),
twice: with an empty table cache of its own, then again with the tables cached (the second run with its
journal removed, so that it simulates every scene).  CPU time (user + system, ``RUSAGE_CHILDREN``) of the
``identify`` command alone, its scene count and answer, and whether the estimate it printed before its
scenes ran brackets their CPU time (the command's CPU less its setup).  Then the small grid of 12 scenes
without refinement (``--length-mm 2.5 3 3.6 --offset-mm 0 0.3 --skew-deg 0 30 --no-refine``) on the same
case, with a table cache of its own left empty: CPU time of the whole process (a few minutes in all on
the shared 2-core machine).  ``--grid12``: that grid alone (the case made as above first, ~1 min).

``--path-fit``: the structural path's fit alone (``fit_structural_path``), on the inputs ``identify_path`` gives it:
the README walkthrough's case (made as above) and cwru-130 (its recording from ``BEARING_LAB_MIRROR``).  CPU time
(``time.process_time``) of each of ``--repeat`` fits on the same inputs, and what they found (the fit is
deterministic: every repeat the same).

``--phases``: where the cold walkthrough's CPU time goes, in this process: the same identification (its
table cache a copy of the one ``validate`` left, as in ``--walkthrough``), each scene and each contact table
counted in the step that asked for it (coarse grid, simplex, roughness probe, profiles, polish, recheck),
with the CPU time of the tables built (as each table's build recorded it) and of the step.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: the README's walkthrough: the stand-in recording, the case and what its author adds to it
STANDIN = ["case", "standin", "paper-O2", "--rpm", "1793", "--set", "load.radial_n=320", "--set",
           "defect.offset_mm=0.3", "--set", "defect.skew_deg=30", "-o", "rig.uff"]
CASE_NEW = ["case", "new", "rig.uff", "--bearing", "6308", "--speed", "1793", "-o", "rig.toml"]
ADDED = """
[load]
radial_n = 320.0
on = "inner"

[[defect]]
race = "outer"
length_mm = 3.0
width_mm = 1.0
offset_mm = 0.3
skew_deg = 30.0
"""
HIDDEN = {"defect.length_mm": 3.0, "defect.offset_mm": 0.3, "defect.skew_deg": 30.0}


def _cli(args, cwd, env):
    """Run ``bearing-lab ARGS`` in ``cwd``; returns (CPU s of the child, its stdout)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run([sys.executable, "-c", "import sys; from bearing_lab.cli import main; "
                          "sys.exit(main(sys.argv[1:]))", *args], cwd=cwd, env=env, check=True,
                         capture_output=True, text=True).stdout
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), out


def _walkthrough_case(tmp, env) -> None:
    """The README walkthrough's stand-in, case and validation in ``tmp`` (tables in ``env``'s cache)."""
    for args in (STANDIN, CASE_NEW):
        _cli(args, tmp, env)
    with open(Path(tmp) / "rig.toml", "a", encoding="utf-8") as fh:
        fh.write(ADDED)
    _cli(["validate", "rig.toml", "-o", "reports"], tmp, env)


def walkthrough(quick=False, grid_only=False) -> None:
    """The README walkthrough's identification, cold then warm, and the 12-scene grid cold (see the module
    docstring); ``quick``: one scene at the hidden geometry, no refinement, and no 12-scene grid; ``grid_only``:
    the 12-scene grid alone."""
    with tempfile.TemporaryDirectory(prefix="identify_walkthrough_") as tmp:
        env = {**os.environ, "BEARING_LAB_CACHE": str(Path(tmp) / "cache")}
        _walkthrough_case(tmp, env)
        if grid_only:
            _grid12(tmp)
            return
        print("\n| run (README walkthrough) | scenes | CPU s | length mm | offset H mm | skew θ° | all hidden values "
              "inside their intervals | estimate of the scenes' CPU s (brackets it) |\n|---|---|---|---|---|---|---|---|")
        for label in ("empty table cache", "tables cached"):
            (Path(tmp) / "reports" / "rig" / "identification-journal.jsonl").unlink(missing_ok=True)
            small = ["--length-mm", "3", "--offset-mm", "0.3", "--skew-deg", "30", "--no-refine"] if quick else []
            cpu, out = _cli(["identify", "rig.toml", "-o", "reports", "--report", "--json", "--no-progress", *small],
                            tmp, env)
            r = _row(label, cpu, json.loads(out))
        for k in HIDDEN:
            print(f"- {r['parameters'][k]['statement']}")
        print(f"- threshold {r['threshold_db']:.2f} dB, roughness {r['roughness_db'] or 0:.2f} dB, "
              f"best score {r['best']['score_db']:.2f} dB")
        notes = [n for n in r["notes"] if "interval ends excluded" in n]
        print("".join(f"- {n}\n" for n in notes), end="")
        if not quick:
            _grid12(tmp)


def _grid12(tmp) -> None:
    """The 12-scene grid on the walkthrough's case in ``tmp``, with an empty table cache of its own."""
    print("\n| run (12-scene grid, no refinement) | scenes | CPU s (whole process) | length mm | offset H mm | "
          "skew θ° | all hidden values inside their intervals | estimate of the scenes' CPU s (brackets it) |"
          "\n|---|---|---|---|---|---|---|---|")
    env12 = {**os.environ, "BEARING_LAB_CACHE": str(Path(tmp) / "cache-grid12")}
    cpu, out = _cli(["identify", "rig.toml", "-o", "reports-grid12", "--json", "--no-progress", *GRID12], tmp, env12)
    _row("empty table cache", cpu, json.loads(out))


def path_fit(repeat) -> None:
    """CPU time of the structural path's fit on the walkthrough's case and on cwru-130 (see the module docstring)."""
    with tempfile.TemporaryDirectory(prefix="identify_pathfit_") as tmp:
        env = {**os.environ, "BEARING_LAB_CACHE": str(Path(tmp) / "cache")}
        _walkthrough_case(tmp, env)
        os.environ["BEARING_LAB_CACHE"] = env["BEARING_LAB_CACHE"]
        from bearing_lab.validation import rig
        from bearing_lab.validation.load import load_case
        real, calls = rig.fit_structural_path, []

        def timed(*a, **k):
            for _ in range(repeat):
                t = time.process_time()
                path = real(*a, **k)
                calls[-1][1].append(time.process_time() - t)
            return path
        rig.fit_structural_path = timed
        print("| case | impacts pooled | CPU s per fit (each repeat) | evaluations (last re-fit) | path | status |"
              "\n|---|---|---|---|---|---|")
        for label, ref in (("README walkthrough", str(Path(tmp) / "rig.toml")), ("cwru-130", "cwru-130")):
            calls.append((label, []))
            path = rig.identify_path(load_case(ref))
            cpu = calls[-1][1]
            modes = "".join(f", {r.frequency_hz:.2f} Hz, ζ {r.damping_ratio:.5f}" for r in path.resonances)
            print(f"| {label} | {path.fit.get('n_impacts_simulation', 0)} | {', '.join(f'{c:.2f}' for c in cpu)} | "
                  f"{path.fit.get('evaluations')} | gain {path.gain:.5g}{modes} | {path.status} |", flush=True)


#: the small grid: 3 lengths, 2 offsets, 2 skews, no refinement (12 scenes)
GRID12 = ["--length-mm", "2.5", "3", "3.6", "--offset-mm", "0", "0.3", "--skew-deg", "0", "30", "--no-refine"]


def _row(label, cpu, r) -> dict:
    """Print one table row of an identification's JSON ``r`` that cost ``cpu`` s; returns ``r``."""
    inside = all(r["parameters"][k]["interval"][0] <= v <= r["parameters"][k]["interval"][1] for k, v in HIDDEN.items())
    best = [r["best"][k] for k in HIDDEN]
    lo, hi = r["estimate"]["cpu_s"]
    scenes = r["cpu_time_s"] - r["setup_cpu_s"]
    print(f"| {label} | {r['n_scenes']} | {cpu:.1f} | {best[0]:g} | {best[1]:g} | {best[2]:g} | "
          f"{'yes' if inside else 'NO'} | {lo:.0f}-{hi:.0f} (likely {r['estimate']['likely_cpu_s']:.0f}) for "
          f"{scenes:.1f} ({'yes' if lo <= scenes <= hi else 'NO'}) |", flush=True)
    return r


def phases(quick=False) -> None:
    """Where the cold walkthrough's CPU goes, per step of the search (see the module docstring); ``quick``:
    the 12-scene grid without refinement instead."""
    with tempfile.TemporaryDirectory(prefix="identify_phases_") as tmp:
        env = {**os.environ, "BEARING_LAB_CACHE": str(Path(tmp) / "cache-validate")}
        _walkthrough_case(tmp, env)
        shutil.copytree(Path(tmp) / "cache-validate", Path(tmp) / "cache")
        os.environ["BEARING_LAB_CACHE"] = str(Path(tmp) / "cache")
        t0 = time.process_time()
        import importlib
        from bearing_lab.sim import defects
        idm = importlib.import_module("bearing_lab.validation.identify")
        step = ["setup"]
        rows: dict = {}

        def row():
            return rows.setdefault(step[0], {"scenes": 0, "tables": 0, "table_cpu": 0.0, "cpu": 0.0})
        real_table = defects.contact_table

        def table(*a, **k):
            t = real_table(*a, **k)
            if t.info.get("source") == "built":
                row()["tables"] += 1
                row()["table_cpu"] += float(t.info.get("build_cpu_s", 0.0))
            return t
        defects.contact_table = table
        real_sweep = idm._sweep_scored

        def sweep(setting, base, params, combos, scored, *a, **k):
            c, n = time.process_time(), len(scored)
            real_sweep(setting, base, params, combos, scored, *a, **k)
            row()["scenes"] += len(scored) - n
            row()["cpu"] += time.process_time() - c
        idm._sweep_scored = sweep

        def tagged(name, label, first=False):
            real = getattr(idm, name)

            def run(*a, **k):
                old, step[0] = step[0], label
                try:
                    return real(*a, **k)
                finally:
                    step[0] = label if first else old
            setattr(idm, name, run)
        for name, label in (("minimise", "simplex"), ("walk_profiles", "profiles"), ("polish", "polish"),
                            ("recheck", "recheck")):
            tagged(name, label)
        tagged("probes", "roughness probe", first=True)
        real_setting = idm._setting

        def setting(*a, **k):
            out = real_setting(*a, **k)
            step[0] = "coarse grid"
            return out
        idm._setting = setting
        small = {"defect.length_mm": [2.5, 3.0, 3.6], "defect.offset_mm": [0.0, 0.3], "defect.skew_deg": [0.0, 30.0]}
        r = idm.identify(str(Path(tmp) / "rig.toml"), progress=False, **(dict(grid=small, refine=False) if quick else {}))
        total = time.process_time() - t0
    print(f"\nidentify() in this process, cold: {total:.1f} s CPU (imports included; setup {r.setup_cpu_s:.1f} s), "
          f"{r.n_scenes} scenes ({r.estimate['mirrored']} of them mirrored, not simulated)\n")
    print("| step | scenes simulated | contact tables built | their CPU s | step CPU s |\n|---|---|---|---|---|")
    for label, v in rows.items():
        if label != "setup":
            print(f"| {label} | {v['scenes']} | {v['tables']} | {v['table_cpu']:.1f} | {v['cpu']:.1f} |")
    tot = [sum(v[k] for lab, v in rows.items() if lab != "setup") for k in ("scenes", "tables", "table_cpu", "cpu")]
    print(f"| all | {tot[0]} | {tot[1]} | {tot[2]:.1f} | {tot[3]:.1f} |")
    print("\n" + "\n".join(f"- {p['statement']}" for p in r.parameters.values()))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--walkthrough", action="store_true", help="the README walkthrough's identification instead")
    ap.add_argument("--quick", action="store_true", help="with --walkthrough: one scene, no refinement; with "
                                                        "--phases: the 12-scene grid, no refinement (checks that "
                                                        "they run, not their cost)")
    ap.add_argument("--phases", action="store_true", help="the cold walkthrough's CPU per step of the search")
    ap.add_argument("--grid12", action="store_true", help="the walkthrough's 12-scene grid alone")
    ap.add_argument("--path-fit", action="store_true", help="the structural path's fit alone, on the walkthrough's "
                                                            "case and on cwru-130 (--repeat fits each)")
    args = ap.parse_args()
    if args.walkthrough or args.grid12:
        walkthrough(quick=args.quick, grid_only=args.grid12)
        return
    if args.path_fit:
        path_fit(args.repeat)
        return
    if args.phases:
        phases(quick=args.quick)
        return
    os.environ["BEARING_LAB_CACHE"] = tempfile.mkdtemp(prefix="identify_cost_")
    from bearing_lab.sim import load_scene, simulate
    from bearing_lab.sim.assembly import table_requests
    from bearing_lab.sim.defects import contact_table
    from bearing_lab.sim.defects import contact
    base = load_scene("paper-O2", **{"load.radial_n": 320.0, "speed_rpm": 1793.0, "solver.rtol": 1e-6,
                                      "output.duration_s": 1.0, "output.sample_rate_hz": 20000.0})
    t = time.process_time()
    simulate(base.replace(**{"output.duration_s": 0.05, "defect.length_mm": 2.5}))   # not a table measured below
    print(f"numba compile + first short scene: {time.process_time() - t:.1f} s CPU")
    print("\n| outline | table CPU s (cold) |\n|---|---|")
    for skew in (0.0, 15.0, 30.0, 60.0):
        for offset in (0.0, 0.3):
            for k in range(args.repeat):
                sc = base.replace(**{"defect.skew_deg": skew, "defect.offset_mm": offset,
                                     "defect.length_mm": 3.0 + 0.01 * k})
                (d, kw), = table_requests(sc)
                contact._MEMORY.clear()
                t = time.process_time()
                contact_table(d, sc.bearing, **kw)
                print(f"| 3.{k:02d} x 1 mm, H {offset:g} mm, θ {skew:g}° | {time.process_time() - t:.2f} |")
    print("\n| scene (1 s, table cached) | CPU s |\n|---|---|")
    for skew in (0.0, 30.0):
        sc = base.replace(**{"defect.skew_deg": skew, "defect.offset_mm": 0.3})
        simulate(sc)
        for _ in range(args.repeat):
            t = time.process_time()
            simulate(sc)
            print(f"| θ {skew:g}°, H 0.3 mm | {time.process_time() - t:.2f} |")


if __name__ == "__main__":
    main()
