"""The API reference: the docstrings' examples run, every public function of sim, validation and
report has an example and a See Also section, the shared docstring entries are filled in, the public
page names every public name, and the Sphinx build (``make docs``) gives no warning."""
import doctest
import importlib
import inspect
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")

#: the modules whose docstrings hold examples (run here as doctests)
DOCTEST_MODULES = [
    "bearing_lab._docdict", "bearing_lab.bearings",
    "bearing_lab.sim.integrate", "bearing_lab.sim.scene", "bearing_lab.sim.auto",
    "bearing_lab.validation.case", "bearing_lab.validation.load", "bearing_lab.validation.runner", "bearing_lab.validation.rows",
    "bearing_lab.validation.quantities", "bearing_lab.validation.standin",
    "bearing_lab.validation.newcase",
    "bearing_lab.report.html", "bearing_lab.report.page", "bearing_lab.utils.figures",
]
#: the subpackages whose every public function must show an example
EXAMPLED = ["bearing_lab.sim", "bearing_lab.validation", "bearing_lab.report"]


@pytest.mark.parametrize("module", DOCTEST_MODULES)
def test_examples_run(module, tmp_path, monkeypatch):
    """Each module's examples, run as doctests in a scratch folder (they write files there)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    mod = importlib.import_module(module)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    tests = [t for t in finder.find(mod, module) if t.examples]
    assert tests, f"{module} holds no example"
    for t in tests:
        runner.run(t)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples of {module} failed (output above)"


def _public_objects(package):
    mod = importlib.import_module(package)
    return {name: getattr(mod, name) for name in mod.__all__}


@pytest.mark.parametrize("package", EXAMPLED)
def test_every_public_function_has_an_example_and_see_also(package):
    missing = []
    for name, obj in _public_objects(package).items():
        if not (inspect.isfunction(obj) or inspect.isclass(obj)):
            continue                                   # constants (QUANTITIES, DEFAULT_CASE)
        doc = inspect.getdoc(obj) or ""
        if "See Also\n--------" not in doc:
            missing.append(f"{name}: no See Also")
        if inspect.isfunction(obj):
            if "Examples\n--------" not in doc or ">>> " not in doc:
                missing.append(f"{name}: no Examples")
            elif inspect.getmodule(obj).__name__ not in DOCTEST_MODULES:
                missing.append(f"{name}: its module {obj.__module__} is not run in DOCTEST_MODULES")
    assert not missing, missing


def test_placeholders_are_filled_in():
    """No ``%(key)s`` is left in a public docstring (fill_doc was applied where they are used)."""
    left = []
    for package in EXAMPLED:
        for name, obj in _public_objects(package).items():
            if re.search(r"%\(\w+\)s", inspect.getdoc(obj) or ""):
                left.append(f"{package}.{name}")
    assert not left, left


def test_fill_doc_indents_entries_and_names_an_unknown_key():
    from bearing_lab._docdict import docdict, fill_doc

    def f():
        """Summary.

        Parameters
        ----------
        %(fs)s
        x : float
            Ratio, 5 % at most (a % outside a placeholder stays).
        """
    fill_doc(f)
    lines = f.__doc__.splitlines()
    assert lines[4:6] == ["        fs : float", "            Sampling rate, Hz."]
    assert "5 % at most (a % outside" in f.__doc__
    assert all(e.split("\n")[0].count(" : ") <= 1 and not e.endswith("\n") for e in docdict.values())

    def g():
        """%(no_such_key)s"""
    with pytest.raises(KeyError, match="no_such_key"):
        fill_doc(g)


def test_the_public_page_names_every_public_name():
    import bearing_lab
    page = (ROOT / "docs" / "api" / "public.rst").read_text()
    absent = [n for n in bearing_lab.__all__ if n != "__version__" and not re.search(rf"[.\s]{n}\b", page)]
    assert not absent, f"docs/api/public.rst does not list {absent}"


def test_docs_build_without_warnings(tmp_path):
    """``make docs``: Sphinx with warnings as errors (the docs extra; required in CI)."""
    try:
        import myst_parser  # noqa: F401
        import numpydoc  # noqa: F401
        import sphinx  # noqa: F401
    except ImportError as exc:
        if IN_CI:
            pytest.fail(f"the docs extra is not installed ({exc}): pip install -e '.[test,docs]'")
        pytest.skip(f"the docs extra is not installed ({exc})")
    out = tmp_path / "html"
    r = subprocess.run([sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-q",
                        "-d", str(tmp_path / "doctrees"), str(ROOT / "docs"), str(out)],
                       capture_output=True, text=True, cwd=ROOT, env={**os.environ, "MPLBACKEND": "Agg"},
                       timeout=600)
    assert r.returncode == 0, r.stderr[-4000:]
    absent = []
    for package in EXAMPLED:                              # every public name has its entry
        page = (out / "api" / f"{package.split('.')[-1]}.html").read_text(encoding="utf-8")
        absent += [f"{package}.{n}" for n in importlib.import_module(package).__all__
                   if f'id="{package}.{n}"' not in page]
    assert not absent, f"not in the reference: {absent}"
    assert (out / "model.html").is_file()                  # the guide pages are in the same site
