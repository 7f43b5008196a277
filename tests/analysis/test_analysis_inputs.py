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
