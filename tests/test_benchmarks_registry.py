"""benchmarks/run_all.py: every benchmark script is registered (or excluded with a reason), every
registered command line parses, the results header carries every field, and one real entry runs
end to end.  No benchmark runs in full here."""
import argparse
import ast
import importlib.util
import os
import runpy
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"
spec = importlib.util.spec_from_file_location("run_all", BENCH / "run_all.py")
run_all = importlib.util.module_from_spec(spec)
sys.modules.setdefault("run_all", run_all)
spec.loader.exec_module(run_all)

FIELDS = ("benchmark", "date", "git revision", "machine", "load average before", "load average after",
          "versions", "command", "mirror (BEARING_LAB_MIRROR)", "child CPU time", "wall time", "exit status")
#: a cheap registered entry in its quick mode (about 5 s of CPU; the analysis_speed entries cost less
#: but their script's 1 s record fails, so the cheapest one is not trusted to stay runnable)
CHEAPEST = "sim_speed"


def test_every_script_registered_or_excluded():
    registered = {e.script for e in run_all.REGISTRY}
    on_disk = {p.name for p in BENCH.glob("*.py")}
    missing = on_disk - registered - set(run_all.EXCLUDED)
    assert not missing, f"benchmarks not in run_all.REGISTRY nor EXCLUDED: {sorted(missing)}"
    assert not (registered | set(run_all.EXCLUDED)) - on_disk, "registered or excluded script not on disk"
    assert not registered & set(run_all.EXCLUDED)
    assert all(len(why) > 10 for why in run_all.EXCLUDED.values())


def test_entry_names_unique_and_docs_named():
    names = [e.name for e in run_all.REGISTRY]
    assert len(names) == len(set(names))
    root = BENCH.parent
    for e in run_all.REGISTRY:
        assert e.quoted_in, e.name
        for page in e.quoted_in:
            assert (root / page).exists(), (e.name, page)


class _Parsed(Exception):
    pass


def _uses_argparse(script: Path) -> bool:
    return "argparse" in script.read_text() or script.name == "work_precision.py"


def _parse_with_script(script: Path, args, monkeypatch):
    """Run the script up to its parse_args (which is stopped right after parsing)."""
    original = argparse.ArgumentParser.parse_args

    def parse_and_stop(self, a=None, namespace=None):
        ns = original(self, a, namespace)
        raise _Parsed(ns)

    monkeypatch.setattr(argparse.ArgumentParser, "parse_args", parse_and_stop)
    monkeypatch.setattr(sys, "argv", [str(script), *args])
    monkeypatch.setattr(sys, "path", list(sys.path))
    environ = dict(os.environ)           # a script may set thread limits before it parses
    try:
        with pytest.raises(_Parsed):
            runpy.run_path(str(script), run_name="__main__")
    finally:
        os.environ.clear()
        os.environ.update(environ)


def _check_argv_script(script: Path, args):
    """A script reading sys.argv by hand: every flag is one it tests for, every other word a number or
    the value after a flag."""
    consts = {n.value for n in ast.walk(ast.parse(script.read_text()))
              if isinstance(n, ast.Constant) and isinstance(n.value, str)}
    assert "sys.argv" in script.read_text() or not args
    for i, a in enumerate(args):
        if a.startswith("--"):
            assert a in consts, f"{script.name} does not know {a}"
        elif not (i and args[i - 1].startswith("--")):
            float(a)   # positional: a number (duration, preload)


@pytest.mark.parametrize("entry", run_all.REGISTRY, ids=lambda e: e.name)
def test_registered_arguments_parse(entry, monkeypatch):
    script = BENCH / entry.script
    assert script.exists()
    for quick in (False, True):
        argv = entry.argv(quick, "/mirror")[2:]
        if _uses_argparse(script):
            _parse_with_script(script, argv, monkeypatch)
        else:
            _check_argv_script(script, argv)


def test_unknown_flag_is_caught(monkeypatch):
    """The parse check can fail: a flag the script does not have."""
    with pytest.raises(SystemExit):
        _parse_with_script(BENCH / "io_throughput.py", ["--no-such-flag"], monkeypatch)
    with pytest.raises(AssertionError):
        _check_argv_script(BENCH / "defect_tables.py", ["--no-such-flag"])


def test_header_has_every_field(tmp_path, monkeypatch):
    """The runner's own command line as a cheap child: one that succeeds, one that fails."""
    ok = run_all.Entry("run_all.py", ("--list",), variant="ok")
    bad = run_all.Entry("run_all.py", ("--no-such-flag",), variant="bad")
    monkeypatch.setattr(run_all, "REGISTRY", (ok, bad))
    status = run_all.main(["--results", str(tmp_path), "--quick"])
    assert status == 1
    for name, code in (("run_all-ok", "0"), ("run_all-bad", "2")):
        text = (tmp_path / f"{name}.txt").read_text()
        assert text.startswith("# quick: figures not for quoting")
        head = dict(line[2:].split(": ", 1) for line in text.split("\n\n")[0].splitlines()[1:])
        assert set(head) == set(FIELDS), set(FIELDS) ^ set(head)
        assert head["exit status"] == code
        assert head["benchmark"] == name
        assert "cores" in head["machine"] and "GiB RAM" in head["machine"]
        assert head["date"].endswith("UTC")
    bad_text = (tmp_path / "run_all-bad.txt").read_text()
    assert "work_precision" not in bad_text
    assert "# FAILED" in bad_text and "unrecognized arguments: --no-such-flag" in bad_text   # stderr tail kept
    assert "work_precision" in (tmp_path / "run_all-ok.txt").read_text()   # the child's stdout follows


def test_only_rejects_unknown_name():
    with pytest.raises(SystemExit, match="unknown benchmark nonesuch"):
        run_all.main(["--only", "nonesuch", "--list"])


def test_cheapest_entry_end_to_end(tmp_path):
    status = run_all.main(["--only", CHEAPEST, "--quick", "--results", str(tmp_path)])
    assert status == 0
    text = (tmp_path / f"{CHEAPEST}.txt").read_text()
    head, _, body = text.partition("\n\n")
    assert "quick: figures not for quoting" in head
    cpu = float(head.split("# child CPU time: ")[1].split(" s")[0])
    assert cpu > 0.1          # the child's CPU time was counted (it imports numpy and compiles)
    assert body.strip()       # the script's own output follows the header


def test_no_quick_results_tracked():
    """Quick-mode files (checking the runner only) are never the committed figures."""
    import shutil
    import subprocess
    if not shutil.which("git") or not (BENCH.parent / ".git").exists():
        pytest.skip("not a git checkout")
    tracked = subprocess.run(["git", "ls-files", "benchmarks/results"], cwd=BENCH.parent,
                             capture_output=True, text=True).stdout.split()
    quick = [f for f in tracked if (BENCH.parent / f).is_file()
             and "quick: figures not for quoting" in (BENCH.parent / f).read_text()[:200]]
    assert not quick, f"quick-mode results in place of full ones: {quick} (git checkout benchmarks/results/)"
