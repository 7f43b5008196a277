"""The product speaks for itself: no development-process wording and no reference to a document
that is not in the repository, in the package (code, templates, shipped cases), the docs, the
README, the benchmarks, the notebooks, the data registry's README or any ``--help`` text.

The pattern is assembled from pieces so that this file does not match it itself."""
import argparse
import re
from pathlib import Path

import pytest

from bearing_lab.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
_DOCS = ["reference", "paper", "contract", "formats", "style"]
PATTERN = re.compile("|".join(
    [r"\bissue" + r" \d"]                                # "issue 5:" and the like
    + [re.escape(d + "." + "md") for d in _DOCS]         # documents outside the repository
    + ["HO" + "OK", "not available" + " yet"]))
TEXT_SUFFIXES = {".py", ".md", ".toml", ".txt", ".csv", ".html", ".css", ".j2", ".ipynb", ".json"}


def _product_files():
    roots = [ROOT / "bearing_lab", ROOT / "docs", ROOT / "benchmarks", ROOT / "notebooks",
             ROOT / "data", ROOT / "validation"]
    files = [ROOT / "README.md"]
    for r in roots:
        files += [p for p in r.rglob("*") if p.is_file() and p.suffix in TEXT_SUFFIXES
                  and "cache" not in p.parts and "__pycache__" not in p.parts
                  and "_build" not in p.parts]     # the built API reference is generated from the sources
    return files


def test_pattern_catches_what_it_should():
    for bad in ["issue" + " 5: tolerance", "see reference" + ".md", "(contract" + ".md)",
                "HO" + "OK: fill later", "is not available" + " yet"]:
        assert PATTERN.search(bad), bad
    for fine in ["scipy/scipy#6072", "Harris & Kotzalas", "an issue of units", "docs/model.md"]:
        assert not PATTERN.search(fine), fine


def test_no_process_language_in_files():
    files = _product_files()
    assert len(files) > 50, "the walk found too few files: the roots moved?"
    hits = []
    for p in files:
        for n, line in enumerate(p.read_text(errors="replace").splitlines(), 1):
            if PATTERN.search(line):
                hits.append(f"{p.relative_to(ROOT)}:{n}: {line.strip()[:100]}")
    assert not hits, "\n".join(hits)


def _all_help(parser: argparse.ArgumentParser, prog="bearing-lab"):
    yield prog, parser.format_help()
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _all_help(sub, f"{prog} {name}")


def test_no_process_language_in_help():
    helps = dict(_all_help(build_parser()))
    assert {"bearing-lab validate", "bearing-lab analyze", "bearing-lab data fetch"} <= set(helps)
    hits = [f"{cmd}: {m.group(0)}" for cmd, text in helps.items()
            for m in [PATTERN.search(text)] if m]
    assert not hits, hits


@pytest.mark.parametrize("cmd", [["--help"], ["analyze", "--help"], ["data", "fetch", "--help"]])
def test_help_walk_matches_the_command_line(cmd, capsys):
    """The walk above reads the same text ``bearing-lab ... --help`` prints."""
    with pytest.raises(SystemExit):
        build_parser().parse_args(cmd)
    printed = capsys.readouterr().out
    helps = dict(_all_help(build_parser()))
    key = " ".join(["bearing-lab"] + cmd[:-1])
    assert printed.split() == helps[key].split()


def test_one_wording_for_allowed_values():
    """Options that take one of a few values are checked by errors.check_choice, so every such
    message reads "<input>: invalid value 'x'; allowed values are ...".  Left: two parameters
    that also take a number or a pair (analysis._impulse: baseline, band) and the spectral-line
    estimators' method/window in analysis._speed."""
    old = re.compile(r"Invalid value for|Allowed values are")
    exceptions = {"_impulse.py": 4, "_speed.py": 4}   # both phrases in each of 2 messages
    found = {}
    for p in (ROOT / "bearing_lab").rglob("*.py"):
        n = len(old.findall(p.read_text()))
        if n:
            found[p.name] = n
    assert found == exceptions, found
