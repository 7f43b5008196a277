"""bearing_lab.io.summary: the Dataset summary `info` prints, the kind of a Dataset, an RMS that
cannot overflow; and the reader's refusal of an option, with the options named."""
import math

import numpy as np
import pytest
import xarray as xr

from bearing_lab.errors import RecordingError, RecordingOptionError
from bearing_lab.io import open_recording, read_arrays
from bearing_lab.io.summary import channel_rms, dataset_kind, describe


def test_channel_rms_is_the_root_mean_square_without_overflow():
    assert channel_rms([3.0, -3.0, 3.0, -3.0]) == pytest.approx(3.0)
    assert channel_rms(np.array([[1.0, 2.0], [2.0, 4.0]])) == pytest.approx(math.sqrt(25 / 4))
    huge = np.full(10, 1e200)                          # squaring alone would overflow to inf
    assert channel_rms(huge) == pytest.approx(1e200)
    assert channel_rms([0.0, 0.0]) == 0.0
    assert channel_rms([]) is None
    assert channel_rms([1.0, np.nan]) is None
    assert channel_rms([1.0, np.inf]) is None


def _ds(**attrs):
    t = np.arange(4) / 1000.0
    return xr.Dataset({"a": ("time", [1.0, -1.0, 1.0, -1.0], {"units": "m s-2"}),
                       "f": ("time", np.zeros(4), {"units": "N"})},
                      coords={"time": ("time", t, {"units": "s"})}, attrs=attrs)


@pytest.mark.parametrize("attrs, kind", [({"reader": "csv"}, "recording"), ({"fidelity": "multibody"}, "simulation"),
                                         ({"scene_toml": "x", "sweep_n_scenes": 2}, "sweep"), ({}, "dataset")])
def test_dataset_kind(attrs, kind):
    assert dataset_kind(_ds(**attrs)) == kind


def test_describe_a_dataset():
    d = describe(_ds(sampling_rate_hz=1000.0, warnings="one; two", default_channel="a"), "x.nc")
    assert d["file"] == "x.nc" and d["kind"] == "dataset" and d["samples"] == 4
    assert d["duration_s"] == pytest.approx(4 / 1000.0) and d["start_time_s"] == 0.0
    assert d["default_channel"] == "a" and d["warnings"] == ["one", "two"]
    assert d["channels"]["a"]["rms"] == pytest.approx(1.0) and d["channels"]["a"]["quantity"] == "acceleration"
    assert d["channels"]["f"]["quantity"] == "force" and d["channels"]["f"]["dims"] == ["time"]
    assert describe(_ds())["duration_s"] is None          # no rate: no duration, not a division by zero


def test_describe_reads_the_plain_arrays_like_the_dataset(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("time,acc [g]\n0,1\n0.001,-1\n0.002,1\n0.003,-1\n")
    full, arrays = describe(open_recording(p), p), describe(read_arrays(p), p)
    assert full == arrays
    assert full["kind"] == "recording" and full["channels"]["acc"]["rms"] == pytest.approx(9.80665)


def test_an_unknown_option_is_refused_with_the_options_named(tmp_path):
    p = tmp_path / "x.csv"
    p.write_text("time,a [g]\n0,1\n0.001,2\n0.002,3\n")
    with pytest.raises(RecordingOptionError, match="x.csv: the 'csv' reader does not understand option") as info:
        open_recording(p, full_scale="5 V", bogus=1)
    assert isinstance(info.value, RecordingError)
    assert info.value.unknown == ("full_scale", "bogus") and "fs" in info.value.accepted
