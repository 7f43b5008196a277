"""What a command imports: the lazy public face (lazy_loader.attach) and xarray kept away from
dask until dask is used (bearing_lab._xarray).  Each check runs in a fresh interpreter."""
import json
import os
import subprocess
import sys

import pytest

HEAVY = ("numpy", "xarray", "pandas", "scipy", "numba", "matplotlib", "netCDF4", "h5py", "dask")


def _modules_after(code, env=None):
    """The heavy modules loaded after running ``code`` in a fresh interpreter."""
    probe = code + f"\nimport json, sys; print(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True,
                         env={**os.environ, **(env or {})})
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


def test_import_and_help_load_no_heavy_library():
    assert _modules_after("import bearing_lab") == set()
    code = ("from bearing_lab.cli import main\ntry:\n    main(['--help'])\nexcept SystemExit:\n    pass")
    assert _modules_after(code) == set()


def test_every_public_name_resolves_and_stays_importable():
    """EAGER_IMPORT=1 (lazy_loader) resolves every lazily served name at import."""
    assert "numpy" in _modules_after("import bearing_lab", env={"EAGER_IMPORT": "1"})
    import bearing_lab
    for name in bearing_lab.__all__:
        assert getattr(bearing_lab, name) is not None, name
    for name in ("analysis", "io", "sim", "sweep", "validation", "datasets", "report"):
        assert name in dir(bearing_lab)
    from bearing_lab import (AnalysisError, BearingGeometry, BearingLabError, CATALOG,  # noqa: F401
                             RecordingError, Scene, analyze, check_dataset, get_bearing, identify,
                             list_engines, list_scenes, load_scene, open_recording, run_sweep, simulate,
                             to_netcdf, to_uff58b)
    assert bearing_lab.simulate is bearing_lab.sim.simulate
    assert bearing_lab.run_sweep is bearing_lab.sweep.run_sweep      # the package and its function
    assert bearing_lab.identify.__module__ == "bearing_lab.validation.identify"


def test_info_reads_without_xarray(datafile):
    path = datafile("cwru/12k_FE/IR014_1.mat")
    code = ("import contextlib, io\nfrom bearing_lab.cli import main\n"
            f"with contextlib.redirect_stdout(io.StringIO()):\n    assert main(['info', {str(path)!r}]) == 0")
    loaded = _modules_after(code)
    assert not loaded & {"xarray", "pandas", "dask", "numba", "matplotlib"}, loaded


def test_a_dataset_is_made_and_written_without_dask(tmp_path):
    """A simulation made and written (the ``simulate -o`` path) imports no dask at all (not
    dask.array, not distributed, not dask's core): 0.7 s of CPU that xarray would spend only to
    learn that nothing is dask; and a run shorter than 2 s, which shows no progress bar, no tqdm."""
    code = ("import bearing_lab\nfrom bearing_lab.io import to_netcdf\n"
            "ds = bearing_lab.simulate('paper-healthy', duration=0.005)\n"
            f"to_netcdf(ds, {str(tmp_path / 'a.nc')!r})\n")
    out = subprocess.run([sys.executable, "-c", code + "import sys\n"
                          "print([m for m in ('dask', 'dask.array', 'distributed', 'tqdm') if m in sys.modules])"],
                         capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_the_simulator_imports_scipys_root_finders_only_when_it_solves():
    """``import bearing_lab.sim`` (a scene listed or checked, a sweep's parent process) runs no
    scipy.optimize and no scipy.special: Hertz constants and bracketed roots are the simulator's
    own (bearing_lab.sim.numerics); scipy.optimize (lazy_loader) loads at the first 2-D solve."""
    probe = ("import sys\nimport bearing_lab.sim, bearing_lab.sim.assembly\n"
             "from bearing_lab.sim.hertz import race_contact\nrace_contact(15.081e-3, 65e-3, 0.53, 'outer')\n"
             "print([m for m in ('scipy.optimize._optimize', 'scipy.special._ufuncs') if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_a_planar_simulation_imports_no_scipy_linalg_and_it_still_works_after(tmp_path):
    """A planar run imports neither scipy.optimize (its start is Newton's method) nor scipy.linalg,
    which numba's start asks for its BLAS (bearing_lab.sim._numba answers with the extension
    module alone); afterwards scipy.linalg imports whole, with that module as its cython_blas,
    and numba's np.dot (BLAS) gives the product."""
    probe = ("import sys\nimport bearing_lab\nfrom bearing_lab.io import to_netcdf\n"
             "ds = bearing_lab.simulate('paper-healthy', duration=0.005, progress=False)\n"
             f"to_netcdf(ds, {str(tmp_path / 'a.nc')!r})\n"
             "print([m for m in ('scipy.optimize._optimize', 'scipy.linalg', 'numpy.f2py') if m in sys.modules])\n"
             "blas = sys.modules.get('scipy.linalg.cython_blas')\n"
             "import numpy as np, numba, scipy.linalg, scipy.linalg.cython_blas\n"
             "assert blas is None or scipy.linalg.cython_blas is blas\n"
             "f = numba.njit(lambda a, b: np.dot(a, b))\n"
             "a = np.arange(12.0).reshape(3, 4)\n"
             "assert np.allclose(f(a, a.T), [[14, 38, 62], [38, 126, 214], [62, 214, 366]])\n"
             "assert np.allclose(scipy.linalg.solve(np.diag([2.0, 4.0]), [1.0, 1.0]), [0.5, 0.25])\n"
             "print('ok')")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-2:] == ["[]", "ok"]


def test_dask_still_works_through_xarray_after_the_hooks(tmp_path):
    pytest.importorskip("dask.array")
    import numpy as np
    import xarray as xr
    from bearing_lab import _xarray  # noqa: F401  (the hooks)
    from bearing_lab.io import to_netcdf
    from xarray.namedarray.pycompat import array_type
    ds = xr.Dataset({"a": ("time", np.arange(1000.0))}, coords={"time": np.arange(1000) / 1e3},
                    attrs={"sampling_rate_hz": 1000.0}).chunk({"time": 250})
    assert ds["a"].chunks is not None and isinstance(ds["a"].data, array_type("dask"))
    p = to_netcdf(ds, tmp_path / "chunked.nc")
    back = xr.load_dataset(p)
    np.testing.assert_array_equal(back["a"].values, np.arange(1000.0))


def test_a_lazily_loaded_submodule_stays_reachable_from_its_package():
    """A ``lazy.load("pkg.sub")`` stand-in sits in ``sys.modules`` before ``pkg.sub`` is the package's
    attribute: for a package without a module ``__getattr__`` (dask), a later ``import pkg.sub`` in the
    same process then finds no ``pkg.sub``.  Every dotted name the package loads lazily must stay
    reachable after all of bearing_lab's modules are imported."""
    import ast
    from pathlib import Path
    pkg = Path(__file__).resolve().parents[1] / "bearing_lab"
    names = sorted({n.args[0].value for p in pkg.rglob("*.py") for n in ast.walk(ast.parse(p.read_text()))
                    if isinstance(n, ast.Call) and getattr(n.func, "attr", "") == "load"
                    and getattr(n.func.value, "id", "") == "lazy" and n.args
                    and isinstance(n.args[0], ast.Constant) and "." in str(n.args[0].value)})
    assert "scipy.optimize" in names                        # the scan finds them
    code = ("import importlib, pkgutil, bearing_lab\n"
            "for m in pkgutil.walk_packages(bearing_lab.__path__, 'bearing_lab.'):\n"
            "    if '_fuzz' not in m.name and not m.name.endswith('__main__'):\n"
            "        importlib.import_module(m.name)\n"
            f"for name in {names!r}:\n"
            "    parent, child = name.rsplit('.', 1)\n"
            "    exec(f'import {name}')\n"
            "    assert getattr(importlib.import_module(parent), child) is not None, name\n"
            "import dask\n"
            "import dask.distributed\n"
            "assert dask.distributed.LocalCluster\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
