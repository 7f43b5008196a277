"""bearing_lab.run_sweep (the bearing_lab.sweep package): grid Dataset, Dask == serial bit for bit, cache/resume, errors, CLI.

Small scenes (paper-O1, 0.05 s) keep the module well under a minute; the one Dask
test starts a two-process LocalCluster.
"""
import json

import numpy as np
import pytest
import xarray as xr

import bearing_lab
from bearing_lab.errors import SceneError

SCENE = "paper-O1"
PARAMS = {"defect.offset_mm": [0.0, 0.25], "speed_rpm": [900, 1800]}
DUR = 0.05
# differ from run to run (timing) or say where a scene came from
VOLATILE = ["wall_time_s", "cached"]


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("sweep-cache")


@pytest.fixture(scope="module")
def serial(cache):
    return bearing_lab.run_sweep(SCENE, PARAMS, scheduler="serial", cache_dir=cache, progress=False,
                             duration=DUR)


def test_dims_coords_units(serial):
    ds = serial
    assert ds.attrs["sweep_dims"] == "defect_offset_mm speed_rpm"
    assert dict(ds.sizes) == {"defect_offset_mm": 2, "speed_rpm": 2, "time": int(DUR * 20000), "ball": 8}
    assert ds["defect_offset_mm"].values.tolist() == [0.0, 0.25]
    assert ds["speed_rpm"].values.tolist() == [900, 1800]
    assert ds["defect_offset_mm"].attrs["units"] == "mm"
    assert ds["speed_rpm"].attrs["units"] == "rpm"
    # every contract variable stacked, sweep dims first
    assert ds["outer_ring_acc_y"].dims == ("defect_offset_mm", "speed_rpm", "time")
    assert ds["ball_load_outer"].dims == ("defect_offset_mm", "speed_rpm", "ball", "time")
    assert ds["outer_ring_acc_y"].attrs["units"] == "m s-2"
    for name in ("rms", "peak", "crest_factor", "kurtosis", "wall_time_s", "solver_steps"):
        assert ds[name].dims == ("defect_offset_mm", "speed_rpm")
    assert ds["rms"].attrs["units"] == "m s-2" and ds["kurtosis"].attrs["units"] == "1"
    assert np.all(ds["wall_time_s"] > 0)
    assert ds.attrs["sweep_n_scenes"] == 4 and ds.attrs["sweep_computed"] == 4
    assert json.loads(ds.attrs["sweep_params"]) == {"defect.offset_mm": [0.0, 0.25], "speed_rpm": [900, 1800]}
    # the scenes really differ along each dimension
    assert not np.array_equal(ds.outer_ring_acc_y[0, 0], ds.outer_ring_acc_y[0, 1])
    assert not np.array_equal(ds.outer_ring_acc_y[0, 0], ds.outer_ring_acc_y[1, 0])


def test_cell_is_the_simulation_of_that_scene(serial):
    """Grid cell (0.25 mm, 900 rpm) is bit for bit bearing_lab.simulate with those keys; metrics agree."""
    from bearing_lab.analysis import crest_factor, kurtosis, peak, rms
    one = bearing_lab.simulate(SCENE, duration=DUR, progress=False, speed_rpm=900,
                               **{"defect.offset_mm": 0.25})
    cell = serial.sel(defect_offset_mm=0.25, speed_rpm=900)
    for name in one.data_vars:
        np.testing.assert_array_equal(cell[name].values, one[name].values, err_msg=name)
    np.testing.assert_array_equal(serial.time.values, one.time.values)
    y = one.outer_ring_acc_y.values
    for name, f in (("rms", rms), ("peak", peak), ("crest_factor", crest_factor), ("kurtosis", kurtosis)):
        assert float(cell[name]) == float(f(y)), name


def test_dask_equals_serial_bit_for_bit(serial):
    dsk = bearing_lab.run_sweep(SCENE, PARAMS, n_workers=2, cache_dir=False, progress=False, duration=DUR)
    assert dsk.attrs["sweep_scheduler"].startswith("local cluster, 2 worker")
    assert dsk.attrs["sweep_computed"] == 4
    a, b = serial.drop_vars(VOLATILE), dsk.drop_vars(VOLATILE)
    assert set(a.data_vars) == set(b.data_vars)
    for name in a.variables:
        assert a[name].dtype == b[name].dtype, name
        assert np.array_equal(a[name].values, b[name].values), name  # exact, not allclose


def test_resume_from_cache(serial, cache):
    again = bearing_lab.run_sweep(SCENE, PARAMS, scheduler="serial", cache_dir=cache, progress=False,
                              duration=DUR)
    assert again.attrs["sweep_cache_hits"] == 4 and again.attrs["sweep_computed"] == 0
    assert int(again["cached"].sum()) == 4
    xr.testing.assert_equal(again.drop_vars("cached"), serial.drop_vars("cached"))
    # a "stopped" sweep: one scene's file is gone, and the grid grew by one speed
    victim = cache / f"{serial.scene_hash.values[1, 1]}.nc"
    victim.unlink()
    grown = dict(PARAMS, speed_rpm=[900, 1800, 2400])
    res = bearing_lab.run_sweep(SCENE, grown, scheduler="serial", cache_dir=cache, progress=False, duration=DUR)
    assert res.attrs["sweep_cache_hits"] == 3 and res.attrs["sweep_computed"] == 3
    assert res["cached"].values.tolist() == [[1, 1, 0], [1, 0, 0]]
    xr.testing.assert_equal(res.sel(speed_rpm=[900, 1800]).drop_vars(VOLATILE), serial.drop_vars(VOLATILE))
    assert victim.is_file()


def test_code_fingerprint_reads_the_simulator_source():
    """The cache key covers the simulator's code wherever the sweep package sits: the files read
    are bearings.py and the sim/ modules, found from the package root."""
    from pathlib import Path
    from bearing_lab.sweep import _simulator_sources
    root = Path(bearing_lab.__file__).resolve().parent
    names = {str(f.relative_to(root)).replace("\\", "/") for f in _simulator_sources()}
    assert {"bearings.py", "sim/integrate.py", "sim/_kernels.py", "sim/scene.py"} <= names
    assert names == {"bearings.py"} | {str(f.relative_to(root)).replace("\\", "/")
                                       for f in (root / "sim").rglob("*.py")}


def test_hash_depends_on_scene_and_options():
    from bearing_lab.sweep import scene_hash
    toml = bearing_lab.load_scene(SCENE).to_toml()
    assert scene_hash(toml) == scene_hash(toml)
    assert scene_hash(toml) != scene_hash(toml.replace("1800.0", "1801.0"))
    assert scene_hash(toml, {"duration": 0.05}) != scene_hash(toml, {"duration": 0.1})


@pytest.mark.parametrize("params, needle", [
    ({"speed.bogus_rpm": [1, 2]}, "speed.bogus_rpm"),
    ({"defect.bogus_mm": [1, 2]}, "defect.bogus_mm"),
    ({"nonsense": [1, 2]}, "nonsense"),
    ({"speed_rpm": [-5.0, 900]}, "speed_rpm=-5.0"),
    ({"load.radial_n": "480"}, "load.radial_n"),
    ({"load.radial_n": []}, "load.radial_n"),
    ({"load.radial_n": [480, 480]}, "load.radial_n"),
    ({"output.duration_s": [0.05, 0.1]}, "output.duration_s"),
    ({"duration": [0.05, 0.1]}, "duration"),
    ({"fs": [10000, 20000]}, "output.sample_rate_hz"),
    ({"speed_rpm": [900], "speed.rpm": [1800]}, "speed.rpm"),
])
def test_bad_sweep_raises_scene_error_naming_the_key(params, needle, tmp_path):
    with pytest.raises(SceneError, match=None) as info:
        bearing_lab.run_sweep(SCENE, params, scheduler="serial", cache_dir=tmp_path, progress=False, duration=DUR)
    assert needle in str(info.value)
    assert not list(tmp_path.iterdir())  # refused before anything ran


def test_units_in_values_and_one_public_spelling(tmp_path):
    import bearing_lab.sweep  # the package; its function is served at the top as bearing_lab.run_sweep
    assert bearing_lab.run_sweep is bearing_lab.sweep.run_sweep
    from bearing_lab.sweep import _resolve
    keys, values, base, scenes = _resolve(SCENE, {"defect.offset_mm": ["0 mm", "250 um"]}, {"duration": DUR})
    assert values == [[0.0, 0.25]]
    assert scenes[1].data["defect"][0]["offset_mm"] == 0.25
    assert all(s.duration == DUR for s in scenes)


def test_cli_round_trip(serial, cache, tmp_path, capsys):
    from bearing_lab.cli import main
    out = tmp_path / "sweep.nc"
    rc = main(["sweep", SCENE, "--param", "defect.offset_mm=0,0.25", "--param", "speed_rpm=900,1800",
               "--duration", str(DUR), "--scheduler", "serial", "--cache-dir", str(cache), "--json",
               "-o", str(out)])
    assert rc == 0
    assert json.loads(capsys.readouterr().out)["sweep_n_scenes"] == 4
    back = xr.load_dataset(out)
    assert back.attrs["sweep_dims"] == "defect_offset_mm speed_rpm"
    assert back["speed_rpm"].attrs["units"] == "rpm"
    for name in serial.drop_vars(VOLATILE).variables:
        assert np.array_equal(back[name].values, serial[name].values), name


@pytest.mark.parametrize("argv, needle", [
    (["--param", "speed_rpm"], "speed_rpm"),
    (["--param", "speed_rpm=900,,1800"], "speed_rpm"),
    (["--param", "defect.nope_mm=1,2"], "defect.nope_mm"),
    ([], "--param"),
])
def test_cli_errors_are_one_line_exit_2(argv, needle, tmp_path, capsys):
    from bearing_lab.cli import main
    rc = main(["sweep", SCENE, *argv, "--scheduler", "serial", "--cache-dir", str(tmp_path), "-q",
               "-o", str(tmp_path / "x.nc")])
    err = capsys.readouterr().err.strip()
    assert rc == 2
    assert len(err.splitlines()) == 1 and needle in err and err.startswith("bearing-lab sweep: error:")


def test_text_parameter_and_per_scene_attributes():
    """A text key (fidelity) gives a text coordinate without units; attributes that
    differ between scenes (the fidelity used) become per-scene variables."""
    ds = bearing_lab.run_sweep(SCENE, {"fidelity": ["multibody", "quasi-static"]}, scheduler="serial",
                           cache_dir=False, progress=False, duration=DUR)
    assert ds["fidelity"].values.tolist() == ["multibody", "quasi-static"]
    assert "units" not in ds["fidelity"].attrs
    assert ds["scene_fidelity"].values.tolist() == ["multibody", "quasi-static"]
    assert "fidelity" not in ds.attrs and ds.attrs["bearing"] == "6308"
    assert not np.array_equal(ds.outer_ring_acc_y[0], ds.outer_ring_acc_y[1])


@pytest.mark.parametrize("damage", ["nan", "bytes", "no_checksum", "shape"])
def test_damaged_cache_entry_is_recomputed_and_reported(serial, cache, tmp_path, damage):
    """NaN written into a cache file, a flipped byte, a lost checksum file or a wrong shape:
    the scene is computed again (never used), the sweep warns and says how many."""
    import shutil
    from bearing_lab.io.export import checksum_path
    from bearing_lab.sweep import CacheWarning
    from bearing_lab.sweep.store import write_cache
    own = tmp_path / "cache"
    shutil.copytree(cache, own)
    victim = own / f"{serial.scene_hash.values[0, 1]}.nc"
    if damage == "nan":      # re-written consistently (valid checksum), but with a NaN inside
        ds = xr.load_dataset(victim)
        ds["outer_ring_acc_y"][5] = np.nan
        write_cache(ds, victim)
    elif damage == "shape":
        write_cache(xr.load_dataset(victim).isel(time=slice(0, 10)), victim)
    elif damage == "bytes":
        b = bytearray(victim.read_bytes())
        b[len(b) // 2] ^= 0xFF
        victim.write_bytes(bytes(b))
    else:
        checksum_path(victim).unlink()
    with pytest.warns(CacheWarning, match="1 damaged cache entry"):
        res = bearing_lab.run_sweep(SCENE, PARAMS, scheduler="serial", cache_dir=own, progress=False,
                                duration=DUR)
    assert res.attrs["sweep_cache_hits"] == 3 and res.attrs["sweep_computed"] == 1
    assert res.attrs["sweep_cache_rejected"] == 1
    assert np.all(np.isfinite(res["outer_ring_acc_y"].values))
    assert np.all(np.isfinite(res["kurtosis"].values))
    xr.testing.assert_equal(res.drop_vars(VOLATILE), serial.drop_vars(VOLATILE))
    again = bearing_lab.run_sweep(SCENE, PARAMS, scheduler="serial", cache_dir=own, progress=False,
                              duration=DUR)
    assert again.attrs["sweep_cache_hits"] == 4 and again.attrs["sweep_cache_rejected"] == 0


def test_sweep_output_reads_back_through_info(serial, tmp_path, capsys):
    """`bearing-lab info` refused sweep files: per-scene variables had no units."""
    from bearing_lab.cli import main
    from bearing_lab.io import to_netcdf
    p = to_netcdf(serial, tmp_path / "sweep.nc")
    assert main(["info", str(p)]) == 0
    out = capsys.readouterr().out
    assert "sweep of scene 'paper-O1'" in out and "dims (defect_offset_mm, speed_rpm, time)" in out
