"""Every shipped validation case's row verdicts and margins in one table, and how they move.

Why: a verdict that flips when the machine changes (thread counts, CPU-specific code, library
versions, the last bit of a recording) is not a result.  This script runs every shipped case and
writes one row per table row: its status and its *margin*, how far the compared number lies
inside (+) or outside (-) its tolerance, as a share of the tolerance:

- ``pct`` rule: ``1 - |sim - exp| / (tol |exp|)``;
- ``factor`` rule: ``1 - |ln(sim / exp)| / ln(factor)``;
- a line-family row where neither signal shows the family: no margin; its note gives each side's
  family evidence score over the decoy threshold (a sum of line SNRs in dB: a score; the detection's
  own margin).

Usage::

    python benchmarks/verdicts.py table [-o benchmarks/verdicts.csv] [--perturb-recording 1e-12]
    python benchmarks/verdicts.py study [--python PATH ...]     # the perturbation study -> verdicts.md

``table`` is what the test suite compares against (``tests/validation/test_verdict_table.py``):
a changed verdict shows as a diff with the row's note, its cause.  ``study`` runs ``table`` in
fresh processes under each perturbation and writes ``benchmarks/verdicts.md``.
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
FIELDS = ("case", "quantity", "status", "simulation", "experiment", "rule", "tolerance", "margin", "note")


def margin(row) -> float:
    """How far inside (+) or outside (-) its tolerance a row's number lies, as a share of it (NaN: no number)."""
    s, e = row["simulation"], row["experiment"]
    if s is None or e is None or not (math.isfinite(s) and math.isfinite(e)):
        return float("nan")
    if row["rule"] == "pct":
        return 1.0 - abs(s - e) / (row["tolerance_pct"] / 100.0 * abs(e)) if e else float("nan")
    f = 1.0 + row["tolerance_pct"] / 100.0
    if s * e <= 0:
        return -math.inf
    return 1.0 - abs(math.log(s / e)) / math.log(f)


def shipped_names():
    from bearing_lab.validation.case import shipped_cases
    from bearing_lab.validation.load import load_case
    return [n for n in shipped_cases() if load_case(n).default or n == "paper"]


def _perturb_recordings(eps):
    """Scale every opened recording by (1 + eps): the smallest change a different decoder could make."""
    import dataclasses

    from bearing_lab.validation import recording, recording_case, recording_run, rig
    orig = recording.open_spec

    def open_spec(*a, **k):
        rec = orig(*a, **k)
        return dataclasses.replace(rec, x=rec.x * (1.0 + eps))
    for mod in (recording, recording_case, recording_run, rig):
        if hasattr(mod, "open_spec"):
            mod.open_spec = open_spec


def report_rows(reports, cases):
    """The table's rows of the cases ``(name, status)`` from their summaries in the report folder ``reports``
    (a case that wrote none: one error row with its status)."""
    rows = []
    for name, status in cases:
        f = Path(reports) / name / "summary.json"
        if not f.is_file():
            rows.append({"case": name, "quantity": "(case)", "status": "error", "note": str(status)})
            continue
        for r in json.loads(f.read_text())["rows"]:
            rows.append({"case": name, "quantity": r["quantity"], "status": r["status"],
                         "simulation": r["simulation"], "experiment": r["experiment"], "rule": r["rule"],
                         "tolerance": r["tolerance"], "margin": margin(r), "note": r["note"]})
    return rows


def table(out, *, perturb_recording=0.0, mirror=None):
    """Run the shipped cases; write their rows (FIELDS) to ``out`` (CSV) and return them."""
    if perturb_recording:
        _perturb_recordings(perturb_recording)
    from bearing_lab.validation import run_validation
    with tempfile.TemporaryDirectory() as tmp:
        outcomes, _ = run_validation(shipped_names(), tmp, progress=False, mirror=mirror)
        rows = report_rows(tmp, [(o.name, o.status) for o in outcomes])
    with open(out, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS, lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else ("" if v is None else v))
                        for k, v in ((k, r.get(k)) for k in FIELDS)})
    return rows


def read(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


PERTURBATIONS = {
    "baseline": {},
    "one BLAS/FFT thread": {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
                            "NUMBA_NUM_THREADS": "1"},
    "NUMBA_CPU_NAME=generic (fresh cache)": {"NUMBA_CPU_NAME": "generic", "NUMBA_CACHE_DIR": "{tmp}/numba"},
    "recording x (1 + 1e-12)": {"--perturb-recording": "1e-12"},
}


def study(pythons, mirror):
    runs = {}
    t0 = time.time()
    with tempfile.TemporaryDirectory() as tmp:
        jobs = [(name, sys.executable, env) for name, env in PERTURBATIONS.items()]
        jobs += [(f"versions of {p}", p, {"NUMBA_CACHE_DIR": "{tmp}/numba-%d" % i}) for i, p in enumerate(pythons)]
        for name, py, env in jobs:
            e = dict(os.environ)
            args = [py, str(Path(__file__)), "table", "-o", f"{tmp}/{len(runs)}.csv"]
            for k, v in env.items():
                if k.startswith("--"):
                    args += [k, v]
                else:
                    e[k] = v.format(tmp=tmp)
            if mirror:
                args += ["--mirror", mirror]
            ver = subprocess.run([py, "-c", "import numpy, scipy, numba; print(numpy.__version__, scipy.__version__, "
                                  "numba.__version__)"], capture_output=True, text=True).stdout.strip()
            print(f"[{time.time() - t0:6.0f} s] {name} (numpy, scipy, numba = {ver})", flush=True)
            subprocess.run(args, env=e, check=True)
            runs[f"{name} ({ver})"] = read(f"{tmp}/{len(runs)}.csv")
    base_name, base = next(iter(runs.items()))
    lines = ["# Verdicts of the shipped validation cases under machine-like perturbations", "",
             "Regenerate: `python benchmarks/verdicts.py study --python <lowest-versions venv python>` "
             "(one run per perturbation, each in a fresh process).", "",
             "Margin: how far inside (+) or outside (-) its tolerance a row's number lies, as a share of the "
             "tolerance (1 = exact agreement, 0 = on the limit). 'moved' lists perturbations that change the status; "
             "'largest margin change' is over all perturbations.", "",
             "Runs: " + "; ".join(runs), "",
             "| case | row | status | margin | largest margin change | moved under |",
             "|---|---|---|---:|---:|---|"]
    for i, r in enumerate(base):
        moved, dm = [], 0.0
        for name, rows in list(runs.items())[1:]:
            o = rows[i] if i < len(rows) else {}
            if (o.get("case"), o.get("quantity")) != (r["case"], r["quantity"]) or o.get("status") != r["status"]:
                moved.append(name)
            try:
                dm = max(dm, abs(float(o["margin"]) - float(r["margin"])))
            except (KeyError, ValueError):
                pass
        m = r["margin"] if r["margin"] not in ("", "nan") else "-"
        lines.append(f"| {r['case']} | {r['quantity']} | {r['status']} | {m} | {dm:.2g} | "
                     f"{', '.join(moved) or 'none'} |")
    (HERE / "verdicts.md").write_text("\n".join(lines) + "\n")
    print(f"wrote {HERE / 'verdicts.md'} ({time.time() - t0:.0f} s)")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("table", help="run the shipped cases and write the verdict table (CSV)")
    t.add_argument("-o", "--output", default=str(HERE / "verdicts.csv"))
    t.add_argument("--perturb-recording", type=float, default=0.0)
    t.add_argument("--mirror", default=None)
    s = sub.add_parser("study", help="the table under each perturbation, in fresh processes -> verdicts.md")
    s.add_argument("--python", action="append", default=[], help="another interpreter (e.g. lowest versions)")
    s.add_argument("--mirror", default=None)
    a = ap.parse_args(argv)
    if a.cmd == "table":
        rows = table(a.output, perturb_recording=a.perturb_recording, mirror=a.mirror)
        print(f"{len(rows)} rows -> {a.output}")
    else:
        study(a.python, a.mirror)


if __name__ == "__main__":
    main()
