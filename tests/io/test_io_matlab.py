"""Testlab MATLAB exports (v5 real file, v7.3 and grouped synthetic), CWRU and MFPT .mat files."""
import gc
import warnings

import numpy as np
import pytest

from tests.helpers import require
import scipy.io
import scipy.stats

from bearing_lab import RecordingError, open_recording
from bearing_lab.io._testing import check_reader


# -- Testlab -------------------------------------------------------------------------
def test_testlab_acceler(datafile, tmp_path):
    ds = check_reader(datafile("lms/testlab_acceler.mat"), format="testlab_mat", tmp_path=tmp_path)
    x = ds["Point1"]
    rms = float(np.sqrt(np.mean(x.values ** 2)))
    assert rms == pytest.approx(4.93, abs=0.005)             # m/s²: unit_transformation honoured
    assert rms / 9.80665 == pytest.approx(0.503, abs=0.0005)  # g
    assert ds.time.values[0] == pytest.approx(6.0979e-5, rel=1e-4)
    assert ds.attrs["sampling_rate_hz"] == 12800.0
    assert ds.sizes["time"] == 129024
    assert x.attrs["original_units"] == "g" and x.attrs["units"] == "m s-2"
    assert x.attrs["testlab_name"] == "2:Point1"
    assert ds.attrs["testlab_project_name"] == "Project2"


def _signal(values, *, label="g", factor=1 / 9.80665, inc=1e-4, start=0.0, name="1:Acc"):
    return {"x_values": {"start_value": start, "increment": inc,
                         "number_of_values": np.asarray(values).shape[0],
                         "quantity": {"label": "s"}},
            "y_values": {"values": np.asarray(values),
                         "quantity": {"label": label,
                                      "unit_transformation": {"factor": factor, "offset": 0.0}}},
            "function_record": {"name": name, "creation_time": "2026/01/01 00:00:00"}}


def test_grouped_channels_split(tmp_path, sine):
    vals = np.column_stack([sine, 2 * sine, 3 * sine])
    p = tmp_path / "grouped.mat"
    scipy.io.savemat(p, {"Signal": _signal(vals, name="1:Grp")})
    ds = open_recording(p)
    assert list(ds.data_vars) == ["Grp_1", "Grp_2", "Grp_3"]
    np.testing.assert_array_equal(ds["Grp_3"].values, 3 * sine)


def test_signal_numbered_and_rates(tmp_path, sine):
    p = tmp_path / "two.mat"
    scipy.io.savemat(p, {"Signal_0": _signal(sine, name="1:A"),
                         "Signal_1": _signal(sine[::2], name="2:B", inc=2e-4)})
    with pytest.raises(RecordingError, match="two.mat: signals differ in rate"):
        open_recording(p)
    ds = open_recording(p, channels="B")
    assert ds.attrs["sampling_rate_hz"] == 5000.0


def test_factor_not_matching_label_converted(tmp_path, sine):
    p = tmp_path / "fac.mat"
    scipy.io.savemat(p, {"Signal": _signal(sine, label="g", factor=1.0)})  # stored as g
    ds = open_recording(p)
    np.testing.assert_allclose(ds["Acc"].values, sine * 9.80665)
    assert "does not match" in ds.attrs["warnings"]


def test_v73_hdf5(tmp_path, sine):
    h5py = require("h5py")
    p = tmp_path / "v73.mat"
    with h5py.File(p, "w", userblock_size=512) as f:
        g = f.create_group("Signal")
        g.attrs["MATLAB_class"] = np.bytes_("struct")

        def grp(parent, name):
            x = parent.create_group(name)
            x.attrs["MATLAB_class"] = np.bytes_("struct")
            return x

        def num(parent, name, v):
            d = parent.create_dataset(name, data=np.atleast_2d(np.asarray(v, dtype=float)))
            d.attrs["MATLAB_class"] = np.bytes_("double")

        def txt(parent, name, s):
            d = parent.create_dataset(name, data=np.array([[ord(c)] for c in s], dtype=np.uint16).T)
            d.attrs["MATLAB_class"] = np.bytes_("char")

        xv = grp(g, "x_values")
        num(xv, "start_value", 0.5)
        num(xv, "increment", 1e-4)
        num(xv, "number_of_values", sine.size)
        yv = grp(g, "y_values")
        num(yv, "values", sine[None, :])  # MATLAB column vector as HDF5 stores it
        q = grp(yv, "quantity")
        txt(q, "label", "m/s2")
        ut = grp(q, "unit_transformation")
        num(ut, "factor", 1.0)
        num(ut, "offset", 0.0)
        fr = grp(g, "function_record")
        txt(fr, "name", "3:Rig")
    with open(p, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: test HDF5 schema 1.00 .")
    ds = check_reader(p, format="testlab_mat")
    assert list(ds.data_vars) == ["Rig"]
    np.testing.assert_array_equal(ds["Rig"].values, sine)
    assert ds.time.values[0] == 0.5


def test_mat_without_signal_struct(tmp_path, sine):
    p = tmp_path / "nostruct.mat"
    scipy.io.savemat(p, {"data": sine})
    with pytest.raises(RecordingError, match="nostruct.mat: no reader recognises"):
        open_recording(p)
    with pytest.raises(RecordingError, match=r"nostruct.mat: no 'Signal' struct \(variables: data\)"):
        open_recording(p, format="testlab_mat")


def test_signal_missing_fields(tmp_path):
    p = tmp_path / "bad.mat"
    scipy.io.savemat(p, {"Signal": {"foo": 1}})
    with pytest.raises(RecordingError, match="bad.mat: variable 'Signal' is not a Testlab Signal"):
        open_recording(p)


def test_frf_only(tmp_path, sine):
    p = tmp_path / "frf.mat"
    scipy.io.savemat(p, {"FRF": _signal(sine)})
    with pytest.raises(RecordingError, match="frf.mat: holds FRF but no time signal"):
        open_recording(p)


def test_testlab_unknown_unit(tmp_path, sine):
    p = tmp_path / "unk.mat"
    scipy.io.savemat(p, {"Signal": _signal(sine, label="lbf/in^3", factor=1.0)})
    with pytest.raises(RecordingError, match=r"unk.mat: channel 'Acc': unknown unit 'lbf/in\^3'"):
        open_recording(p)


# -- CWRU ----------------------------------------------------------------------------
@pytest.mark.parametrize("name, lo, hi, fs, nch", [
    ("130_OR007@6_0.mat", 7.6, 8.0, 12000.0, 3),
    ("97_Normal_0.mat", 2.76, 2.96, 48000.0, 2),
])
def test_cwru_kurtosis(datafile, tmp_path, name, lo, hi, fs, nch):
    ds = check_reader(datafile(f"cwru/{name}"), format="cwru", tmp_path=tmp_path)
    k = scipy.stats.kurtosis(ds["DE"].values, fisher=False)
    assert lo < k < hi
    assert ds.attrs["sampling_rate_hz"] == fs
    assert ds.attrs["default_channel"] == "DE"
    assert len(ds.data_vars) == nch
    assert ds.attrs["shaft_speed_rpm"] == 1796.0
    assert ds["DE"].attrs["original_units"] == "g"


@pytest.mark.parametrize("name", ["105_IR007_0.mat", "118_B007_0.mat", "144_OR007@3_0.mat",
                                  "234_OR021@6_0.mat"])
def test_cwru_others(datafile, name):
    ds = open_recording(datafile(f"cwru/{name}"))
    assert ds.attrs["reader"] == "cwru" and ds.attrs["sampling_rate_hz"] == 12000.0
    assert list(ds.data_vars) == ["DE", "FE", "BA"]
    assert ds.attrs["cwru_record"] == int(name.split("_")[0])


def _cwru_file(path, rec_vars, rpm=1797):
    d = {}
    for rec, x in rec_vars.items():
        d[f"X{rec:03d}_DE_time"] = x[:, None]
        d[f"X{rec:03d}_FE_time"] = (0.5 * x)[:, None]
        d[f"X{rec:03d}RPM"] = np.array([[rpm]], dtype=np.uint16)
    scipy.io.savemat(path, d)
    return path


def test_cwru_unregistered_record_needs_fs(tmp_path, sine):
    p = _cwru_file(tmp_path / "9999.mat", {9999: sine})
    with pytest.raises(RecordingError, match=r"9999.mat: CWRU record 9999 is not in the registry.*fs="):
        open_recording(p)
    ds = open_recording(p, fs=12000)
    assert ds.attrs["sampling_rate_hz"] == 12000.0 and ds.attrs["sampling_rate_source"] == "user"


def test_cwru_variables_of_another_record(tmp_path, sine):
    """Channels are found by the _DE_time pattern, not the file's number."""
    p = _cwru_file(tmp_path / "131.mat", {4321: sine})
    ds = open_recording(p)
    assert ds.attrs["cwru_record"] == 4321 and ds.attrs["cwru_file_number"] == 131
    assert ds.attrs["sampling_rate_hz"] == 12000.0  # the file's registered number (131)


def test_cwru_two_records(tmp_path, sine):
    p = _cwru_file(tmp_path / "two.mat", {98: sine, 99: 2 * sine})
    with pytest.raises(RecordingError, match="two.mat: the file holds variables of records 98, 99"):
        open_recording(p)
    ds = open_recording(p, record=99)
    np.testing.assert_allclose(ds["DE"].values, 2 * sine * 9.80665)
    assert ds.attrs["sampling_rate_hz"] == 48000.0


# -- MFPT ----------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["OuterRaceFault_vload_1.mat", "InnerRaceFault_vload_1.mat"])
def test_mfpt(datafile, tmp_path, name):
    ds = check_reader(datafile(f"mfpt/{name}"), format="mfpt", tmp_path=tmp_path)
    assert ds.attrs["sampling_rate_hz"] == 48828.0
    assert ds.attrs["shaft_speed_rpm"] == 1500.0
    assert list(ds.data_vars) == ["acc"] and ds.sizes["time"] == 146484


@pytest.mark.filterwarnings("error::pytest.PytestUnraisableExceptionWarning")
@pytest.mark.parametrize("reader", ["cwru", "mfpt", "testlab_mat"])
def test_a_mat_reader_refuses_a_file_without_the_matlab_header_and_closes_it(tmp_path, reader):
    """Forced onto a file that is not MATLAB, each .mat reader says so by name and leaves no file open."""
    p = tmp_path / "text.mat"
    p.write_bytes(b"time,acc\n" + b"0.0,1.0\n" * 200)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ResourceWarning)
        with pytest.raises(RecordingError, match=r"text.mat: not a MATLAB file"):
            open_recording(p, format=reader)
        gc.collect()
