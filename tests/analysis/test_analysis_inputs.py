"""bearing_lab.analysis.inputs: which channel, tacho and bearing of a Dataset are analysed."""
import numpy as np
import pytest
import xarray as xr

from bearing_lab.analysis.inputs import (bearing_name, not_an_acceleration, pick_channel, pick_tacho,
                                         time_channels)
from bearing_lab.errors import AnalysisError


def _ds(names, **attrs):
    t = np.arange(8) / 100.0
    data = {n: ("time", np.zeros(8)) for n in names}
    data["ball_load"] = (("ball", "time"), np.zeros((3, 8)))
    return xr.Dataset(data, coords={"time": t}, attrs=attrs)


def test_time_channels_are_the_1d_signals():
    assert time_channels(_ds(["a", "b"])) == ["a", "b"]


def test_pick_channel_given_default_or_first_non_tacho():
    assert pick_channel(_ds(["tacho", "a", "b"])) == "a"
    assert pick_channel(_ds(["a", "b"], default_channel="b")) == "b"
    assert pick_channel(_ds(["a", "b"], default_channel="gone")) == "a"
    assert pick_channel(_ds(["a", "b"]), "b") == "b"
    with pytest.raises(AnalysisError, match=r"f.nc: no channel 'c'; the file has a, b, ball_load"):
        pick_channel(_ds(["a", "b"]), "c", source="f.nc")
    with pytest.raises(AnalysisError, match=r"f.nc: channel 'ball_load' is not a 1-D time signal"):
        pick_channel(_ds(["a"]), "ball_load", source="f.nc")
    with pytest.raises(AnalysisError, match="f.nc: no 1-D time signal to analyse"):
        pick_channel(_ds(["Keyphasor"]), source="f.nc")


def test_pick_tacho_by_name_given_or_none():
    ds = _ds(["acc", "Tach2", "once_per_rev"])
    assert pick_tacho(ds, channel="acc") == "Tach2"
    assert pick_tacho(ds, channel="Tach2") == "once_per_rev"     # never the channel analysed
    assert pick_tacho(ds, "once_per_rev") == "once_per_rev"
    assert pick_tacho(ds, "None") is None
    assert pick_tacho(_ds(["acc", "speed"]), channel="acc") is None
    with pytest.raises(AnalysisError, match="r.nc: no channel 'tk'"):
        pick_tacho(ds, "tk", source="r.nc")


@pytest.mark.parametrize("attrs, name", [({"bearing": "6205"}, "6205"), ({"bearing": "SKF 6205-2RS JEM"}, "6205"),
                                         ({"reader": "mfpt"}, "MFPT")])
def test_bearing_name_from_the_attributes(attrs, name):
    assert bearing_name(_ds(["a"], **attrs)) == name


def test_bearing_name_given_wins_and_none_is_said():
    assert bearing_name(_ds(["a"], bearing="6205"), "6203") == "6203"
    with pytest.raises(AnalysisError, match=r"x.mat: the file names no catalog bearing \(bearing attribute ''\).*6205"):
        bearing_name(_ds(["a"]), source="x.mat")


def test_a_channel_that_is_not_an_acceleration_is_said():
    acc = xr.DataArray(np.zeros(4), dims="time", attrs={"quantity": "acceleration"})
    assert not_an_acceleration(acc, "a", "m s-2") == "" and not_an_acceleration(acc, "a", "g") == ""
    mic = xr.DataArray(np.zeros(4), dims="time")
    text = not_an_acceleration(mic, "mic", "Pa")
    assert text.startswith("channel 'mic' is a sound pressure (a microphone), not an acceleration") and "in Pa" in text
    odd = xr.DataArray(np.zeros(4), dims="time", attrs={"quantity": "strain"})
    assert "channel 'e' is a strain, not an acceleration" in not_an_acceleration(odd, "e", "1")
    assert not_an_acceleration(mic, "x", "1") == ""          # a bare number says nothing of its quantity


def _nc(tmp_path, fs=1000.0, **attrs):
    from bearing_lab.io.export import to_netcdf
    t = np.arange(64) / fs
    ds = xr.Dataset({"acc": ("time", np.sin(2 * np.pi * 50 * t), {"units": "m s-2"})},
                    coords={"time": ("time", t, {"units": "s"})},
                    attrs={"sampling_rate_hz": fs, "bearing_lab_version": "0", **attrs})
    return to_netcdf(ds, tmp_path / "r.nc")


def test_open_at_rate_passes_fs_to_a_reader_that_takes_it(tmp_path):
    from bearing_lab.analysis.inputs import open_at_rate
    path = tmp_path / "bare.csv"
    path.write_text("acc[g]\n" + "\n".join(str(v) for v in np.arange(40.0)) + "\n")
    ds, fs, note = open_at_rate(path, 2500.0)
    assert (fs, note) == (2500.0, "")
    assert float(ds.attrs["sampling_rate_hz"]) == 2500.0
    assert float(ds["time"].values[1] - ds["time"].values[0]) == pytest.approx(1 / 2500.0)


def test_open_at_rate_overrides_the_rate_of_a_reader_without_an_fs_option(tmp_path):
    from bearing_lab.analysis.inputs import open_at_rate, signal_rate
    path = _nc(tmp_path, fs=1000.0)
    ds, fs, note = open_at_rate(path)
    assert fs is None and note == "" and signal_rate(ds, "acc") == 1000.0
    ds, fs, note = open_at_rate(path, 3000.0, name="--fs")
    assert fs == 3000.0 and float(ds.attrs["sampling_rate_hz"]) == 1000.0
    assert note == "--fs 3000 Hz overrides the file's 1000.0 Hz"
    with pytest.raises(AnalysisError, match=r"^--fs -1.0 must be a positive sampling rate in Hz$"):
        open_at_rate(path, -1.0, name="--fs")
    from bearing_lab.errors import RecordingError
    with pytest.raises(RecordingError, match="missing.nc: no such file"):
        open_at_rate(tmp_path / "missing.nc", 3000.0)


def test_signal_rate_falls_back_on_the_time_axis():
    t = np.arange(10) / 400.0
    ds = xr.Dataset({"acc": ("time", np.zeros(10))}, coords={"time": t})
    from bearing_lab.analysis.inputs import signal_rate
    assert signal_rate(ds, "acc") == 400.0
    assert signal_rate(ds.assign_attrs(sampling_rate_hz=512.0), "acc") == 512.0


def test_shaft_rpm_from_a_value_or_the_file():
    from bearing_lab.analysis.inputs import shaft_rpm
    stored, bare = _ds(["a"], shaft_speed_rpm=1797.0), _ds(["a"])
    assert shaft_rpm(stored) == (1797.0, "file")
    assert shaft_rpm(bare) == (None, "given")
    assert shaft_rpm(stored, "None") == (None, "given")
    assert shaft_rpm(stored, "file") == (1797.0, "file")
    assert shaft_rpm(bare, "1750") == (1750.0, "given")
    with pytest.raises(AnalysisError, match=r"^f.nc: --rpm file given but the file stores no shaft_speed_rpm$"):
        shaft_rpm(bare, "file", source="f.nc", name="--rpm")
    with pytest.raises(AnalysisError, match=r"'fast' is not a number \(r/min\), 'file' nor 'none'"):
        shaft_rpm(bare, "fast")
    with pytest.raises(AnalysisError, match="must be a positive speed"):
        shaft_rpm(bare, "-3")
