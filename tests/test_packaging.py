"""pyproject.toml says what the package needs: no runtime dependency the package never imports, test
extras that the tests use, and an SPDX license (setuptools >= 77, no deprecation warning on install)."""
import ast
import re
import sys
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
META = tomllib.loads((ROOT / "pyproject.toml").read_text())


def _name(req):
    return re.split(r"[<>=\[; ]", req, 1)[0].lower().replace("_", "-")


def _imported_top_level(folder):
    names = set()
    for p in folder.rglob("*.py"):
        for node in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names |= {a.name.split(".")[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                names.add(node.module.split(".")[0])
            elif (isinstance(node, ast.Call) and getattr(node.func, "attr", None) == "load" and node.args
                  and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)):
                names.add(node.args[0].value.split(".")[0])     # lazy_loader's lazy.load("pkg.sub")
    return {n.lower().replace("_", "-") for n in names}


def test_every_runtime_dependency_is_imported_by_the_package():
    used = _imported_top_level(ROOT / "bearing_lab")
    import_name = {"netcdf4": "netcdf4"}
    deps = [_name(r) for r in META["project"]["dependencies"]]
    assert "pyuff" not in deps
    assert [d for d in deps if import_name.get(d, d) not in used] == []


def test_test_extra_holds_what_the_tests_use_and_not_jupyterlab():
    test = {_name(r) for r in META["project"]["optional-dependencies"]["test"]}
    assert "pyuff" in test and "jupyterlab" not in test
    assert {"nbclient", "ipykernel", "ipywidgets"} <= test       # notebooks run; their progress bars are widgets
    assert 'require("pyuff")' in (ROOT / "tests" / "io" / "test_io_uff58.py").read_text()   # the reference reader
    assert "jupyterlab" in {_name(r) for r in META["project"]["optional-dependencies"]["notebooks"]}


def test_spdx_license_and_the_setuptools_that_reads_it():
    assert META["project"]["license"] == "MIT"
    req = [r for r in META["build-system"]["requires"] if _name(r) == "setuptools"][0]
    assert tuple(int(x) for x in re.search(r">=\s*([\d.]+)", req).group(1).split(".")) >= (77,)
