"""netCDF4 (compressed, bit for bit) and UFF 58b export round trips."""
import numpy as np
import pytest

from tests.helpers import require
import xarray as xr

from bearing_lab import RecordingError, open_recording
from bearing_lab.io import to_netcdf, to_uff58b

pyuff = require("pyuff")


def test_netcdf_bit_for_bit_and_compressed(datafile, tmp_path):
    ds = open_recording(datafile("cwru/130_OR007@6_0.mat"))
    out = to_netcdf(ds, tmp_path / "cwru.nc")
    back = xr.load_dataset(out)
    assert back.identical(ds)
    for name in ds.data_vars:
        assert np.array_equal(back[name].values.view(np.uint64), ds[name].values.view(np.uint64))
    raw = ds.nbytes
    assert out.stat().st_size < 0.9 * raw  # zlib + shuffle actually compress
    again = open_recording(out)  # the .nc reads back through open_recording too
    assert again.identical(ds)


def test_uff58b_roundtrip_through_pyuff(datafile, tmp_path):
    ds = open_recording(datafile("lms/mpstd_set001_58b_4ch.uff"))
    out = to_uff58b(ds, tmp_path / "back.uff")
    sets = pyuff.UFF(str(out)).read_sets()
    types = [s["type"] for s in sets]
    assert types == [164, 58, 58, 58, 58]
    for s, (name, var) in zip(sets[1:], ds.data_vars.items()):
        np.testing.assert_array_equal(s["data"], var.values)  # float64: exact
        assert s["rsp_node"] == var.attrs["uff_rsp_node"] and s["rsp_dir"] == var.attrs["uff_rsp_dir"]
        assert s["ordinate_axis_units_lab"] == "m/s2"
        assert s["num_pts"] == ds.sizes["time"]
        assert s["abscissa_inc"] == pytest.approx(1 / 3200, rel=1e-5)
        assert s["id1"] == var.attrs["id1"]
    back = open_recording(out)
    assert list(back.data_vars) == list(ds.data_vars)
    assert back.attrs["sampling_rate_hz"] == 3200.0
    for name in ds.data_vars:
        np.testing.assert_array_equal(back[name].values, ds[name].values)


def test_uff58b_original_units_and_start(datafile, tmp_path):
    ds = open_recording(datafile("lms/testlab_acceler.mat"))
    out = to_uff58b(ds, tmp_path / "g.uff", units="original")
    s = pyuff.UFF(str(out)).read_sets()[1]
    assert s["ordinate_axis_units_lab"] == "g"
    np.testing.assert_allclose(s["data"] * 9.80665, ds["Point1"].values, rtol=1e-14)
    assert s["abscissa_min"] == pytest.approx(6.0979e-5, rel=1e-5)
    back = open_recording(out)  # snapped back to 12 800 Hz, values in SI again
    assert back.attrs["sampling_rate_hz"] == 12800.0
    np.testing.assert_allclose(back["Point1"].values, ds["Point1"].values, rtol=1e-14)


def test_uff58b_big_endian(tmp_path, sine):
    t = np.arange(sine.size) / 1000.0
    ds = xr.Dataset({"acc_y": ("time", sine, {"units": "m s-2", "quantity": "acceleration"})},
                    coords={"time": ("time", t, {"units": "s"})},
                    attrs={"sampling_rate_hz": 1000.0})
    out = to_uff58b(ds, tmp_path / "be.uff", byte_order="big")
    s = pyuff.UFF(str(out)).read_sets()[1]
    np.testing.assert_array_equal(s["data"], sine)


def test_uff58b_refuses_uneven_and_missing(tmp_path, sine):
    t = np.cumsum(np.r_[0, np.full(sine.size - 1, 1e-3)])
    t[100:] += 1e-4
    ds = xr.Dataset({"a": ("time", sine, {"units": "m s-2"})}, coords={"time": t},
                    attrs={"sampling_rate_hz": 1000.0})
    with pytest.raises(RecordingError, match="uneven"):
        to_uff58b(ds, tmp_path / "u.uff")
    ds2 = ds.assign_coords(time=np.arange(sine.size) / 1000.0)
    with pytest.raises(RecordingError, match="no variable 'b'"):
        to_uff58b(ds2, tmp_path / "u.uff", channels=["b"])
