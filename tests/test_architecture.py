"""The package's shape: every module imports on its own (no import circle), no module reaches for
another module's private names, and the public face serves exactly what ``__all__`` says."""
import ast
import fnmatch
import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "bearing_lab"

#: private names a module may import from another module, and why (at most five entries);
#: patterns are ``fnmatch`` patterns over the importing module and the imported dotted name (``|``: either)
EXCEPTIONS = {
    ("bearing_lab.studies.bench*", "bearing_lab.sim.integrate._*"):
        "the work-precision benchmark times the solver's own time loop, below simulate()",
    ("bearing_lab.studies.bench_common", "bearing_lab.sim._kernels|bearing_lab.sim._loopargs.Model"):
        "scipy's solve_ivp is benchmarked on the same compiled right-hand side (the kernels and their argument tuple)",
    ("bearing_lab.sim.scene", "bearing_lab.sim.scene_keys._NUM"):
        "the table of scene keys' number type, which scene.py checks values against",
    ("bearing_lab.sim.defects.halfspace_skewed", "bearing_lab.sim.defects.halfspace._*"):
        "one half-space solver in two modules (the size limit): the skewed defect reuses its steps",
}
#: imports still to make public; an entry that no longer occurs must be removed from here
TO_FIX: set[str] = set()


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = [_module_name(p) for p in sorted(PKG.rglob("*.py")) if p.name != "__main__.py"]


def _is_module(dotted: str) -> bool:
    p = ROOT.joinpath(*dotted.split("."))
    return p.with_suffix(".py").is_file() or (p / "__init__.py").is_file()


#: the shared base's helper modules: every module of the package may import them (the folder
#: layout names them: ``utils/_files.py``, ``utils/_json.py``); users import ``utils.figures``
SHARED_PRIVATE = "bearing_lab.utils"


def _private_owner(dotted: str) -> str | None:
    """The package that owns the first private (underscore) module on ``dotted``'s path, or None."""
    parts = dotted.split(".")
    for i in range(1, len(parts)):
        if parts[i].startswith("_") and not parts[i].startswith("__") and _is_module(".".join(parts[: i + 1])):
            return ".".join(parts[:i])
    return None


def _inside(pkg: str, owner: str) -> bool:
    return pkg == owner or pkg.startswith(owner + ".") or owner == SHARED_PRIVATE


def private_imports() -> list[str]:
    """``"importer: bearing_lab.module._name"`` for every import of a private name of another module,
    and ``"importer: bearing_lab.pkg._module.name"`` for every name taken from another package's private
    module.  A package's private submodule (``from . import _kernels`` inside ``sim``, ``from
    ._spectral import bandpass`` inside ``analysis``) may be imported by the modules of that package."""
    out = []
    for path in sorted(PKG.rglob("*.py")):
        mod = _module_name(path)
        is_pkg = path.name == "__init__.py"
        pkg = mod if is_pkg else mod.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    owner = _private_owner(alias.name) if alias.name.startswith("bearing_lab.") else None
                    if owner is not None and not _inside(pkg, owner):
                        out.append(f"{mod}: {alias.name}")
                continue
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level:
                base = pkg.split(".")[: len(pkg.split(".")) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            if source.split(".")[0] != "bearing_lab":
                continue
            owner = _private_owner(source)
            for alias in node.names:
                full = f"{source}.{alias.name}"
                if owner is not None and not _inside(pkg, owner):
                    out.append(f"{mod}: {full}")
                    continue
                if not alias.name.startswith("_") or alias.name.startswith("__"):
                    continue
                if _is_module(full) and _inside(pkg, source):
                    continue
                out.append(f"{mod}: {full}")
    return out


def _excepted(entry: str) -> bool:
    importer, name = entry.split(": ")
    return any(fnmatch.fnmatchcase(importer, a) and any(fnmatch.fnmatchcase(name, x) for x in b.split("|"))
               for a, b in EXCEPTIONS)


def test_no_module_imports_another_modules_private_names():
    assert len(EXCEPTIONS) <= 5
    found = private_imports()
    new = sorted({e for e in found if not _excepted(e)} - TO_FIX)
    assert not new, "private names imported from another module (make them public there):\n" + "\n".join(new)
    gone = sorted(TO_FIX - set(found))
    assert not gone, "fixed, remove from TO_FIX:\n" + "\n".join(gone)


def test_the_exceptions_cover_only_what_they_name():
    assert not [e for e in private_imports() if e.startswith("bearing_lab.sim.assembly:")]
    assert _excepted("bearing_lab.studies.bench_speed: bearing_lab.sim.integrate._run")
    assert not _excepted("bearing_lab.sweep: bearing_lab.sim.integrate._run")
    assert not _excepted("bearing_lab.studies.bench_common: bearing_lab.sim._loopargs.Work")


def test_the_private_module_check_can_fail():
    """A name taken from another package's private module is found, whatever its own spelling."""
    assert _private_owner("bearing_lab.analysis._diagnosis.coincidences") == "bearing_lab.analysis"
    assert _private_owner("bearing_lab.analysis.pipeline.analyze") is None
    assert _private_owner("bearing_lab._version.__version__") == "bearing_lab"
    assert not _inside("bearing_lab.validation", "bearing_lab.analysis")
    assert _inside("bearing_lab.analysis", "bearing_lab.analysis") and _inside("bearing_lab.sim.defects", "bearing_lab.sim")


def imported_modules(module: str) -> set:
    """The bearing_lab modules ``module`` imports anywhere in its file (function-level imports too)."""
    path = ROOT.joinpath(*module.split("."))
    path = path / "__init__.py" if path.is_dir() else path.with_suffix(".py")
    pkg = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg.split(".")[: len(pkg.split(".")) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            names = [f"{source}.{a.name}" for a in node.names] + [source]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        for name in names:
            while name.startswith("bearing_lab") and not _is_module(name):
                name = name.rpartition(".")[0]
            if name.startswith("bearing_lab") and name != module:
                out.add(name)
                break
    return out


#: the folders in data-flow order: a module imports from its own rank or a lower one
RANKS = {"_version": 0, "_docdict": 0, "errors": 0, "units": 0, "utils": 0, "schema": 0, "bearings": 0, "_xarray": 0,
         "io": 1, "datasets": 1, "sim": 1, "analysis": 2, "_accessor": 2, "compare": 3, "sweep": 3, "report": 3,
         "validation": 4, "studies": 4, "cli": 5}
#: imports against that order, and why (at most two)
UPWARD = {("bearing_lab.io", "bearing_lab._accessor"): "every recording carries the da.bearing accessor",
          ("bearing_lab.sim", "bearing_lab._accessor"): "every simulation carries the da.bearing accessor"}
#: validation's recording-case layers, in order: a module imports only from its layer or an earlier one
VALIDATION_LAYERS = [
    ("quantities", "rows", "recording", "speed", "simulation", "signature"),
    ("case", "case_checks", "load", "standin", "newcase"),
    ("recording_case", "rig"),
    ("evaluate", "candidates", "identify", "identify_run", "identify_search", "identify_report"),
    ("recording_run", "paper", "figures"),
    ("pages", "runner"),
]


def test_folders_import_along_the_data_flow():
    assert {m.split(".")[1] for m in MODULES if "." in m} <= set(RANKS) | {"__main__"}
    up = {}
    for m in MODULES:
        if "." not in m:
            continue
        for t in imported_modules(m):
            if "." in t and RANKS[t.split(".")[1]] > RANKS[m.split(".")[1]]:
                up[(m, t)] = True
    assert set(up) <= set(UPWARD), f"imports against the data flow: {sorted(set(up) - set(UPWARD))}"
    assert len(UPWARD) <= 2


def test_validation_modules_import_only_their_layer_or_earlier():
    layer = {f"bearing_lab.validation.{m}": i for i, ms in enumerate(VALIDATION_LAYERS) for m in ms}
    assert set(layer) | {"bearing_lab.validation"} >= {m for m in MODULES if m.startswith("bearing_lab.validation")}
    wrong = sorted(f"{m} -> {t}" for m in layer for t in imported_modules(m) if layer.get(t, -1) > layer[m])
    assert not wrong, "validation imports a later layer:\n" + "\n".join(wrong)


def import_circles(graph: dict) -> list:
    """The strongly connected components of more than one module of ``graph`` (module -> the modules it
    imports), each sorted: the import circles, whether their imports sit at a module's top or in a function."""
    index, low, stack, on_stack, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while not comp or comp[-1] != v:
                comp.append(stack.pop())
                on_stack.discard(comp[-1])
            if len(comp) > 1:
                out.append(sorted(comp))
    for m in sorted(graph):
        if m not in index:
            visit(m)
    return out


def test_no_import_circle_even_through_function_level_imports():
    """A circle closed by an import inside a function imports alone (the check below cannot see it), so
    the module graph itself, every import counted, must have none."""
    circles = import_circles({m: imported_modules(m) for m in MODULES})
    assert not circles, "import circles:\n" + "\n".join(" <-> ".join(c) for c in circles)


def test_the_circle_check_can_fail():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set(), "e": {"e2"}, "e2": {"e"}}
    assert import_circles(graph) == [["a", "b", "c"], ["e", "e2"]]
    assert import_circles({"a": {"b"}, "b": set()}) == []


def test_the_layer_checks_can_fail():
    assert "bearing_lab.validation.recording_case" in imported_modules("bearing_lab.validation.rig")
    assert "bearing_lab.validation.rig" in imported_modules("bearing_lab.validation.recording_run")


#: the function-level imports left in each module (all others sit at the module top), each for the
#: reason on its line (docs/architecture.md, "Imports"): an import circle, a CLI handler's command
#: library (the parser imports no numpy), a library a light path must not pay for, a registry read
#: at call time.  A module not listed has none.
FUNCTION_LEVEL_IMPORTS = {
    "_accessor.py": 3, "_xarray.py": 3, "compare.py": 1,
    "cli/analyze.py": 3, "cli/bench.py": 2, "cli/case.py": 4, "cli/identify.py": 6, "cli/recording.py": 13,
    "cli/simulate.py": 5, "cli/study.py": 1, "cli/sweep.py": 5, "cli/validate.py": 4,
    "io/__init__.py": 1, "io/_base.py": 2, "io/_fuzz.py": 2, "io/_fuzz_struct.py": 1, "io/_guard.py": 2,
    "io/_matlab.py": 8, "io/cwru.py": 2, "io/export.py": 1, "io/mdf.py": 1, "io/netcdf.py": 3, "io/tdms.py": 1,
    "io/wav.py": 1,
    "sim/defects/geometry.py": 1, "sim/defects/halfspace_skewed.py": 1, "sim/defects/halfspace_solver.py": 1,
    "sim/integrate.py": 1,
    "studies/bench.py": 2, "studies/paper.py": 1, "sweep/__init__.py": 5, "sweep/store.py": 1,
    "utils/figures.py": 2, "validation/identify.py": 1,
}


def function_level_imports(source: str) -> list[int]:
    """Line numbers of the ``import`` statements inside a function (or lambda) of ``source``."""
    out = []

    def walk(node, in_function):
        for child in ast.iter_child_nodes(node):
            if in_function and isinstance(child, (ast.Import, ast.ImportFrom)):
                out.append(child.lineno)
            walk(child, in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)))
    walk(ast.parse(source), False)
    return out


def test_function_level_imports_do_not_creep_back():
    over = []
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG).as_posix()
        found = function_level_imports(path.read_text(encoding="utf-8"))
        if len(found) > FUNCTION_LEVEL_IMPORTS.get(rel, 0):
            over.append(f"{rel}: {len(found)} function-level imports (lines {found}), "
                        f"at most {FUNCTION_LEVEL_IMPORTS.get(rel, 0)}: move them to the module top")
    assert not over, "\n".join(over)
    assert all((PKG / rel).is_file() for rel in FUNCTION_LEVEL_IMPORTS), "a listed module is gone"


def test_the_function_level_import_count_can_fail():
    src = ("import os\nfrom . import a\n\ndef f():\n    import json\n    g = lambda: __import__('x')\n"
           "    class C:\n        from . import b\n    return json\n\nclass D:\n    def m(self):\n"
           "        from .c import d\n")
    assert function_level_imports(src) == [5, 8, 13]


#: third-party libraries loaded once by the import server before it forks one child per module: a
#: child then pays only for bearing_lab's own modules.  Only libraries whose submodules load on
#: attribute access (or are named here) are preloaded, so a module that uses ``scipy.signal`` or
#: ``matplotlib.pyplot`` without importing it still fails in its child as it would alone.
PRELOAD = ("numpy", "scipy", "scipy.signal", "scipy.optimize", "scipy.stats", "scipy.fft", "scipy.io",
           "scipy.interpolate", "pandas", "xarray", "numba", "netCDF4", "matplotlib")

_SERVER = r"""
import importlib, json, os, sys, warnings
warnings.simplefilter("ignore")
preload, modules = json.loads(sys.argv[1]), json.loads(sys.argv[2])
for lib in preload:
    try:
        importlib.import_module(lib)
    except ImportError:
        pass
assert not [m for m in sys.modules if m.split(".")[0] == "bearing_lab"], "bearing_lab preloaded"
out = []
for m in modules:
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(r)
        try:
            importlib.import_module(m)
            msg, code = b"", 0
        except BaseException as e:
            msg, code = f"{type(e).__name__}: {e}".encode()[:4000], 1
        os.write(w, msg)
        os._exit(code)
    os.close(w)
    with os.fdopen(r, "rb") as f:
        msg = f.read().decode(errors="replace")
    _, status = os.waitpid(pid, 0)
    out.append([m, os.waitstatus_to_exitcode(status), msg])
print(json.dumps(out))
"""


def _import_alone(modules: list) -> list:
    """``(module, exit code, last error line)`` for each module, each imported first and alone: in a
    child forked from a fresh interpreter that has loaded only the third-party :data:`PRELOAD`."""
    r = subprocess.run([sys.executable, "-c", _SERVER, json.dumps(PRELOAD), json.dumps(modules)],
                       capture_output=True, text=True, cwd=ROOT, timeout=600,
                       env={**os.environ, "PYTHONWARNINGS": "ignore"})
    assert r.returncode == 0, r.stderr[-2000:]
    return [tuple(x) for x in json.loads(r.stdout.strip().splitlines()[-1])]


@pytest.mark.skipif(not hasattr(os, "fork"), reason="the import server forks")
def test_the_import_check_catches_a_circle_and_a_missing_submodule_import(tmp_path):
    """Break it: a two-module import circle, entered from either side, and a module that uses
    ``scipy.ndimage``/``matplotlib.pyplot`` without importing them, fail in the server as alone."""
    pkg = tmp_path / "circ"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from .b import g\ndef f():\n    return 1\n")
    (pkg / "b.py").write_text("from .a import f\ndef g():\n    return 2\n")
    (pkg / "c.py").write_text("import matplotlib\nmatplotlib.pyplot.figure\n")
    (pkg / "d.py").write_text("import numpy\n")
    code = (f"import sys; sys.path.insert(0, {str(tmp_path)!r});"
            + "exec(" + repr(_SERVER) + ")")
    r = subprocess.run([sys.executable, "-c", code, json.dumps(PRELOAD),
                        json.dumps(["circ.a", "circ.b", "circ.c", "circ.d"])],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    got = {m: rc for m, rc, _ in json.loads(r.stdout.strip().splitlines()[-1])}
    assert got == {"circ.a": 1, "circ.b": 1, "circ.c": 1, "circ.d": 0}, got


@pytest.mark.slow
def test_every_module_imports_alone_in_a_fresh_interpreter():
    """An import circle shows only when a module is the first of its circle to be imported: each
    module is imported first, alone, in its own child of a fresh interpreter (two servers, half the
    modules each)."""
    assert len(MODULES) > 100
    halves = [MODULES[0::2], MODULES[1::2]]
    with ThreadPoolExecutor(2) as pool:
        results = [x for part in pool.map(_import_alone, halves) for x in part]
    assert [m for m, _, _ in results] == MODULES[0::2] + MODULES[1::2]
    failed = [f"{m}: {err}" for m, rc, err in results if rc != 0]
    assert not failed, "\n".join(failed)


def _docstring_public_names(doc: str) -> set:
    sec = doc.split("Public API\n----------\n")[1].split("\n\n", 2)[1]
    names = set()
    for line in sec.splitlines():
        head = line.split("--")[0].strip()
        names.update(n.strip() for n in head.split(",") if n.strip())
    return names


def test_the_public_face_serves_what_all_says():
    code = ("import json, bearing_lab as b; ns = {}; exec('from bearing_lab import *', ns);"
            "print(json.dumps([b.__all__, dir(b), sorted(k for k in ns if k != '__builtins__'),"
            " b.__doc__, b._SUBPACKAGES]))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    all_, dir_, star, doc, subpackages = json.loads(out.stdout)
    assert len(set(all_)) == len(all_)
    assert sorted(star) == sorted(all_)                       # import * gives __all__, no subpackage
    assert dir_ == sorted(all_ + subpackages)                 # dir() lists the names and the subpackages
    assert _docstring_public_names(doc) == set(all_)          # the docstring lists every public name
    import bearing_lab
    for name in all_:
        assert getattr(bearing_lab, name) is not None, name
    with pytest.raises(AttributeError):
        bearing_lab.no_such_name  # noqa: B018


def test_the_version_is_written_once_and_read_from_version_py():
    """``__version__`` is imported from ``_version.py`` (never the package root), pyproject reads it there,
    and the pages' provenance reports that version, not whatever an installed package's metadata says."""
    import re
    import tomllib
    from bearing_lab.report.provenance import software_versions
    written = re.search(r'__version__ = "([^"]+)"', (PKG / "_version.py").read_text()).group(1)
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert pyproject["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "bearing_lab._version.__version__"}
    assert software_versions()["bearing_lab"] == written
    wrong = []
    for path in sorted(PKG.rglob("*.py")) + [ROOT / "docs" / "conf.py"]:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and any(a.name == "__version__" for a in node.names) \
                    and not (node.module or "").endswith("_version"):
                wrong.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert not wrong, "__version__ imported from elsewhere than _version.py: " + ", ".join(wrong)


#: the longest line a module may hold
LINE_LIMIT = 120
#: modules with longer lines still (to wrap; an entry whose module fits must be removed from here)
LONG_LINES_TO_FIX = set()


def test_lines_fit_the_limit():
    over, fitting = [], []
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG).as_posix()
        long = [i for i, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1) if len(line) > LINE_LIMIT]
        if long and rel not in LONG_LINES_TO_FIX:
            over.append(f"{rel}: lines {long} are over {LINE_LIMIT} characters")
        if not long and rel in LONG_LINES_TO_FIX:
            fitting.append(rel)
    assert not over, "\n".join(over)
    assert not fitting, f"these fit now, remove them from LONG_LINES_TO_FIX: {fitting}"


def test_every_top_level_file_is_in_the_architecture_page():
    """A loose module at the top level shows: the page's list of top-level files is the folder's."""
    import re
    page = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    table = page[page.index("<!-- top level:"):].split("\n\n", 1)[0]
    listed = set(re.findall(r"^\s*\| `([\w.]+\.py)` \|", table, flags=re.M))
    assert len(listed) > 10 and listed == {p.name for p in PKG.glob("*.py")}
