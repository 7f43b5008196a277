"""IMS/NASA ASCII snapshots."""
import numpy as np
import pytest

from bearing_lab import RecordingError, open_recording
from bearing_lab.io._testing import check_reader


@pytest.mark.parametrize("name", ["2004.02.12.10.32.39", "2004.02.17.07.12.39"])
def test_ims_real(datafile, tmp_path, name):
    ds = check_reader(datafile(f"ims/{name}"), format="ims", tmp_path=tmp_path)
    assert list(ds.data_vars) == ["b1", "b2", "b3", "b4"]
    assert ds.sizes["time"] == 20480
    assert ds.attrs["sampling_rate_hz"] == 20480.0  # the documented choice
    assert "20480" in ds.attrs["sampling_rate_source"]
    assert ds.attrs["shaft_speed_rpm"] == 2000.0
    assert ds.attrs["acquisition_time"].startswith("2004-02-1")


def test_ims_rate_override(datafile):
    ds = open_recording(datafile("ims/2004.02.12.10.32.39"), fs=20000)
    assert ds.attrs["sampling_rate_hz"] == 20000.0 and ds.attrs["sampling_rate_source"] == "user"


def test_ims_eight_columns_and_short(tmp_path):
    """A snapshot with 100 of its 20 480 rows is truncated: refused, or kept when allowed."""
    p = tmp_path / "2003.10.22.12.06.24"
    np.savetxt(p, np.random.default_rng(0).normal(size=(100, 8)), delimiter="\t", fmt="%.3f")
    with pytest.raises(RecordingError, match=r"2003.10.22.12.06.24: IMS snapshot \(rows\): "
                                             r"snapshots hold 20480 rows, 100 present"):
        open_recording(p)
    ds = open_recording(p, allow_truncated=True)
    assert list(ds.data_vars)[:3] == ["b1x", "b1y", "b2x"]
    assert "100 rows present" in ds.attrs["warnings"]
    assert ds.attrs["truncated"] == 1 and ds.attrs["declared_samples"] == 20480


@pytest.mark.parametrize("cut", [1, 3])
def test_ims_cut_inside_the_last_number(datafile, tmp_path, cut):
    """The last value of a cut file ('-0.029' -> '-0.0') must never be read as data."""
    src = datafile("ims/2004.02.12.10.32.39").read_bytes()
    p = tmp_path / "2004.02.12.10.32.39"
    p.write_bytes(src[:-cut])
    with pytest.raises(RecordingError, match="no line break"):
        open_recording(p)
    ds = open_recording(p, allow_truncated=True)
    ref = open_recording(datafile("ims/2004.02.12.10.32.39"))
    assert ds.sizes["time"] == 20479
    for c in ref.data_vars:
        np.testing.assert_array_equal(ds[c].values, ref[c].values[:-1])


def test_ims_ragged(tmp_path):
    p = tmp_path / "2004.02.12.10.42.39"
    p.write_text("0.1\t0.2\t0.3\t0.4\n0.1\t0.2\t0.3\n0.1\t0.2\t0.3\t0.4\n")
    with pytest.raises(RecordingError, match="2004.02.12.10.42.39: row 2 does not have 4 columns"):
        open_recording(p)
