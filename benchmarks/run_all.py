"""Regenerate every benchmark figure the docs quote: one command, one results file per run.

    .venv/bin/python benchmarks/run_all.py              # everything (`make bench`; hours)
    .venv/bin/python benchmarks/run_all.py --list       # what would run, and its rough cost
    .venv/bin/python benchmarks/run_all.py --only sim_speed defect_tables-slot   # names as --list prints
    .venv/bin/python benchmarks/run_all.py --quick      # smallest modes, to check the runner
                                                        # (`make bench-quick`; not for quoting)

REGISTRY holds every benchmark script with the exact arguments that give the figures quoted in
README.md, docs/*.md and benchmarks/*.md.  Each entry runs as a child process, one at a time; its
stdout goes to ``benchmarks/results/<name>.txt`` (``<name>`` is the script's name, with
``-<variant>`` when a script has several entries) below a header: date (UTC), git revision (and
whether the tree had uncommitted changes), machine (CPU model, cores, RAM), load average before
and after, Python and the key library versions, the command line, the child's CPU time (user +
system, ``resource.getrusage(RUSAGE_CHILDREN)``, which includes the processes the child waited
for) and its wall time.  A failing entry is reported at the end with its stderr tail (also written
below its output) and the exit status is 1; the other entries still run.  ``--quick`` writes the
same files with "quick: figures not for quoting" in the header: do not commit those.
"""
from __future__ import annotations

import argparse
import datetime
import os
import platform
import resource
import subprocess
import sys
import time
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
LIBRARIES = ("bearing_lab", "numpy", "scipy", "numba", "xarray", "netCDF4", "h5py", "dask", "pyuff")


@dataclass(frozen=True)
class Entry:
    """One benchmark run: ``script`` (in benchmarks/) with ``args``; ``quick`` the arguments of its
    smallest mode (None: the script has none, ``--quick`` runs it in full)."""
    script: str
    args: tuple[str, ...] = ()
    variant: str = ""
    quick: tuple[str, ...] | None = None
    cost: str = "?"            # rough CPU time of the full run (see REGISTRY)
    quick_cost: str = "?"
    mirror_arg: bool = False   # the script takes --mirror (all children also get BEARING_LAB_MIRROR)
    quoted_in: tuple[str, ...] = field(default=())

    @property
    def name(self) -> str:
        return Path(self.script).stem + (f"-{self.variant}" if self.variant else "")

    def argv(self, quick: bool, mirror: str | None) -> list[str]:
        args = list(self.quick if quick and self.quick is not None else self.args)
        if self.mirror_arg and mirror:
            args += ["--mirror", mirror]
        return [sys.executable, str(HERE / self.script), *args]


B, D = "benchmarks/README.md", "docs/"
# cost: rough CPU time of the full run, quick_cost of the quick one, measured with warm numba and table
# caches on the shared 2-core project machine ("~" where a full run was not timed: a guess from its size;
# CPU time, not wall: fuzz_readers and hostile_inputs wait on child processes and time-outs, about 5 min
# of wall time each on the loaded machine)
WP_QUICK = ("--scene", "paper-slot", "--no-scipy", "--no-rates", "--duration", "0.05")
REGISTRY: tuple[Entry, ...] = (
    Entry("work_precision.py", (), quick=WP_QUICK, cost="194 s", quick_cost="40 s",
          quoted_in=("README.md", B, D + "architecture.md")),
    # its own output folder, so that the full study's reports/performance/ stays
    Entry("work_precision.py", ("--scene", "paper-slot", "--no-scipy", "--duration", "0.3", "--no-rates",
                                "-o", "reports/performance-slot"),
          variant="slot", quick=(*WP_QUICK, "-o", "reports/performance-slot"), cost="5 s", quick_cost="3 s",
          quoted_in=(B,)),
    Entry("sim_speed.py", (), quick=("--duration", "0.02", "--default-duration", "0.1", "--scene", "paper-slot",
                                     "--no-scipy"),
          cost="45 s", quick_cost="5 s", quoted_in=("README.md", B)),
    Entry("sim_speed.py", ("--startup", "--first", "1", "--warm", "7"), variant="startup",
          quick=("--startup", "--first", "1", "--warm", "1"), cost="~30 s", quick_cost="11 s",
          quoted_in=("README.md", B)),
    Entry("analysis_speed.py", ("--repeat", "5"), quick=("--repeat", "1", "--seconds", "2"),
          cost="~1 min", quick_cost="2 s", quoted_in=("benchmarks/README_analysis.md",)),
    Entry("analysis_speed.py", ("--seconds", "60"), variant="60s", quick=("--repeat", "1", "--seconds", "2"),
          cost="~2 min", quick_cost="2 s", quoted_in=("README.md",)),
    Entry("defect_models.py", ("1.0",), quick=("0.05",), cost="46 s", quick_cost="12 s",
          quoted_in=(B, D + "contact-model.md")),
    Entry("defect_tables.py", (), quick=("--quick",), cost="2.5 min", quick_cost="42 s",
          quoted_in=(B, D + "contact-model.md", "README.md")),
    Entry("defect_tables.py", ("--slot",), variant="slot", cost="7 s",
          quoted_in=(B, D + "contact-model.md", "README.md")),
    Entry("defect_tables.py", ("--range",), variant="range", cost="14 s", quoted_in=(B,)),
    Entry("defect_tables.py", ("--before", "70e2388"), variant="before-70e2388", cost="54 s",
          quoted_in=(B, D + "contact-model.md")),
    Entry("defect_tables.py", ("--before", "fdecbe8"), variant="before-fdecbe8", cost="41 s",
          quoted_in=(B, D + "contact-model.md")),
    Entry("defect_tables.py", ("--before", "c083eaa"), variant="before-c083eaa", cost="40 s",
          quoted_in=(B, D + "contact-model.md")),
    Entry("defect_tables.py", ("--before", "531c103"), variant="before-531c103", cost="40 s",
          quoted_in=(B, D + "contact-model.md", "README.md")),
    Entry("defect_tables.py", ("--before", "f8262c3"), variant="before-f8262c3", cost="40 s",
          quoted_in=(B, D + "contact-model.md", "README.md")),
    Entry("defect_tables.py", ("--offcentre",), variant="offcentre", cost="25 s",
          quoted_in=(D + "contact-model.md",)),
    Entry("cwru_or021_amplitude.py", (), cost="8 s", quoted_in=(D + "validation.md",)),
    Entry("cwru_ir007_amplitude.py", (), cost="28 s", quoted_in=(D + "validation.md",)),
    Entry("cwru_preload.py", (), quick=("0",), cost="96 s", quick_cost="15 s",
          quoted_in=(B, D + "validation.md")),
    # the preloaded (grazed) columns again at dp54 rtol 1e-8: compared with cwru_preload.txt, they are converged
    Entry("cwru_preload.py", ("125", "188", "250", "--rtol", "1e-8"), variant="converged",
          quick=("250", "--rtol", "1e-6"), cost="35 s", quick_cost="~15 s", quoted_in=(B, D + "validation.md")),
    Entry("bearing3d_cost.py", (), cost="24 s", quoted_in=(B, D + "model.md")),
    # a grazed pit's peak under rounding-level perturbations per solver setting: auto's grazed-defect rule
    Entry("grazed_peak.py", (), quick=("--quick",), cost="52 s", quick_cost="5 s",
          quoted_in=(B, D + "model.md", "bearing_lab/sim/auto.py")),
    Entry("grazed_peak.py", ("--o2",), variant="o2", quick=("--o2", "--perturbations", "1"), cost="22 s",
          quick_cost="6 s", quoted_in=(B,)),
    Entry("diagnosis_eval.py", ("--repeat", "7"), quick=("--quick", "--repeat", "1"), mirror_arg=True,
          cost="19 s", quick_cost="13 s", quoted_in=("benchmarks/README_diagnosis.md", D + "analysis.md")),
    Entry("io_throughput.py", ("--repeat", "7"), quick=("--repeat", "1", "--big-mb", "4"), mirror_arg=True,
          cost="~2 min", quick_cost="1 s", quoted_in=("benchmarks/README_io.md",)),
    Entry("fuzz_readers.py", (), quick=("--total", "200", "--jobs", "1"), cost="72 s", quick_cost="8 s",
          quoted_in=("README.md", D + "reliability.md")),
    Entry("hostile_inputs.py", (), quick=("--kills", "2", "--structured", "10", "--truncations", "1"),
          cost="38 s", quick_cost="20 s", quoted_in=("README.md", D + "reliability.md")),
    Entry("identify_cost.py", (), quick=("--repeat", "1"), cost="~15 s", quick_cost="6 s",
          quoted_in=(D + "identification.md",)),
    Entry("identify_cost.py", ("--walkthrough",), variant="walkthrough", quick=("--walkthrough", "--quick"),
          cost="~3 min", quick_cost="~15 s",
          quoted_in=("README.md", D + "identification.md")),
    Entry("identify_cost.py", ("--phases",), variant="phases", quick=("--phases", "--quick"),
          cost="~2 min", quick_cost="~30 s", quoted_in=(D + "identification.md",)),
    Entry("identify_cost.py", ("--path-fit", "--repeat", "3"), variant="pathfit", quick=("--path-fit", "--repeat", "1"),
          cost="~2 min", quick_cost="~1.5 min", quoted_in=("README.md", D + "identification.md")),
    Entry("identify_selfconsistency.py", (), quick=("--quick",), cost="~1 min", quick_cost="13 s",
          quoted_in=(D + "identification.md",)),
    Entry("sweep_scaling.py", (), quick=("--scenes", "4", "--duration", "0.1", "--rounds", "1"),
          cost="~4 min", quick_cost="14 s", quoted_in=("benchmarks/README_sweep.md",)),
)

# benchmarks/*.py that are not benchmark runs of their own, and why
EXCLUDED = {
    "run_all.py": "this runner",
    "verdicts.py": "the verdict table the tests compare against; `make verdicts` (and `verdicts.py study`) "
                   "rewrite benchmarks/verdicts.csv and verdicts.md",
    "analysis_fingerprint.py": "a check, not a figure: `dump` saves analyze's whole result on every mirror "
                               "recording and `compare` lists what changed between two trees",
}


def _git(*args: str) -> str:
    try:
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""


def revision() -> str:
    rev = _git("rev-parse", "--short=12", "HEAD") or "unknown"
    return rev + (" (dirty: uncommitted changes)" if _git("status", "--porcelain", "--untracked-files=no") else "")


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        ram = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    except (ValueError, OSError, AttributeError):
        ram = float("nan")
    return f"{cpu}, {os.cpu_count()} cores, {ram:.1f} GiB RAM, {platform.system()} {platform.release()}"


def versions() -> str:
    out = [f"Python {platform.python_version()}"]
    for lib in LIBRARIES:
        try:
            out.append(f"{lib} {metadata.version(lib)}")
        except metadata.PackageNotFoundError:
            out.append(f"{lib} (not installed)")
    return ", ".join(out)


def loadavg() -> str:
    try:
        return " ".join(f"{x:.2f}" for x in os.getloadavg()) + f" (1/5/15 min, {os.cpu_count()} cores)"
    except OSError:
        return "unknown"


def header(fields: dict[str, str], quick: bool) -> str:
    """The results file's header: one ``# key: value`` line per field, the quick mark first."""
    lines = ["# quick: figures not for quoting (smallest modes, checking the runner only)"] if quick else []
    lines += [f"# {k}: {v}" for k, v in fields.items()]
    return "\n".join(lines) + "\n\n"


def run_entry(entry: Entry, quick: bool, mirror: str | None, results: Path) -> tuple[int, str, Path]:
    """Run one entry as a child process; write its results file. Returns (status, stderr, path)."""
    argv = entry.argv(quick, mirror)
    env = dict(os.environ)
    if mirror:
        env["BEARING_LAB_MIRROR"] = mirror
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")
    load0 = loadavg()
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(argv, cwd=ROOT, env=env, capture_output=True, text=True, errors="replace")
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    user, system = r1.ru_utime - r0.ru_utime, r1.ru_stime - r0.ru_stime
    fields = {
        "benchmark": entry.name,
        "date": date,
        "git revision": revision(),
        "machine": machine(),
        "load average before": load0,
        "load average after": loadavg(),
        "versions": versions(),
        "command": " ".join([os.path.relpath(argv[0], ROOT) if argv[0].startswith(str(ROOT)) else argv[0],
                             os.path.relpath(argv[1], ROOT), *argv[2:]]),
        "mirror (BEARING_LAB_MIRROR)": mirror or "(none)",
        "child CPU time": f"{user + system:.1f} s (user {user:.1f} + system {system:.1f}; RUSAGE_CHILDREN)",
        "wall time": f"{wall:.1f} s",
        "exit status": str(proc.returncode),
    }
    results.mkdir(parents=True, exist_ok=True)
    path = results / f"{entry.name}.txt"
    failed = ""
    if proc.returncode:
        tail = "".join(f"# {line}\n" for line in proc.stderr.strip().splitlines()[-20:]) or "# (stderr empty)\n"
        failed = f"\n# FAILED (exit status {proc.returncode}); stderr, last lines:\n{tail}"
    path.write_text(header(fields, quick) + proc.stdout + failed)
    return proc.returncode, proc.stderr, path


def select(names: list[str] | None) -> list[Entry]:
    if not names:
        return list(REGISTRY)
    known = [e.name for e in REGISTRY]
    bad = [n for n in names if n not in known]
    if bad:
        raise SystemExit(f"run_all.py: --only: unknown benchmark {', '.join(bad)} (known: {', '.join(known)})")
    return [e for e in REGISTRY if e.name in names]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--list", action="store_true", help="print what would run and its rough cost, run nothing")
    ap.add_argument("--only", nargs="+", metavar="NAME", help="these entries (names as --list prints them)")
    ap.add_argument("--quick", action="store_true", help="each script's smallest mode (figures not for quoting)")
    ap.add_argument("--mirror", default=os.environ.get("BEARING_LAB_MIRROR"),
                    help="the public recordings' folder (default: $BEARING_LAB_MIRROR)")
    ap.add_argument("--results", default=str(HERE / "results"), help="folder of the results files")
    args = ap.parse_args(argv)
    entries = select(args.only)
    if args.list:
        for e in entries:
            quick = "(no quick mode: runs in full)" if e.quick is None else f"quick {e.quick_cost}"
            cmd = " ".join(e.argv(args.quick, args.mirror)[1:]).replace(str(ROOT) + "/", "")
            print(f"{e.name:30s} {e.cost:8s} {quick:32s} {cmd}")
        return 0
    if args.mirror and not Path(args.mirror).is_dir():
        raise SystemExit(f"run_all.py: --mirror {args.mirror}: no such folder")
    failed = []
    for i, e in enumerate(entries, 1):
        print(f"[{i}/{len(entries)}] {e.name} ...", flush=True)
        status, stderr, path = run_entry(e, args.quick, args.mirror, Path(args.results))
        print(f"    -> {path} (exit {status})", flush=True)
        if status:
            failed.append((e.name, status, stderr))
    for name, status, stderr in failed:
        tail = "\n".join(stderr.strip().splitlines()[-15:]) or "(stderr empty: see the script's output)"
        print(f"\nFAILED: {name} (exit status {status}); stderr tail:\n{tail}", file=sys.stderr)
    if failed:
        print(f"\n{len(failed)} of {len(entries)} benchmarks failed: {', '.join(f[0] for f in failed)}",
              file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
