"""``xr.open_dataset(path, engine="bearing_lab")`` gives the same Dataset as open_recording."""
import pytest
import xarray as xr

from bearing_lab.errors import RecordingError
from bearing_lab.io import open_recording


def test_engine_registered():
    assert "bearing_lab" in xr.backends.list_engines()


def test_open_dataset_matches_open_recording(datafile):
    path = datafile("cwru/130_OR007@6_0.mat")
    a = xr.open_dataset(path, engine="bearing_lab")
    b = open_recording(path)
    xr.testing.assert_identical(a, b)
    assert a["DE"].attrs["units"] == "m s-2" and a.attrs["sampling_rate_hz"] == 12000.0


def test_engine_guessed_for_uff_and_options_forwarded(datafile):
    path = datafile("lms/binary8byte_g.uff")
    ds = xr.open_dataset(path)                                   # no engine=: guessed from the suffix
    assert ds.attrs["reader"].startswith("uff58")
    ds2 = xr.open_dataset(path, engine="bearing_lab", fs=200.0)  # a reader option through xarray
    assert ds2.attrs["sampling_rate_hz"] == 200.0
    name = next(iter(ds.data_vars))
    assert name not in xr.open_dataset(path, engine="bearing_lab", drop_variables=[name])


def test_netcdf_not_claimed(tmp_path):
    from bearing_lab.io.xarray_backend import BearingLabBackendEntrypoint
    assert not BearingLabBackendEntrypoint().guess_can_open(str(tmp_path / "x.nc"))


def test_bad_file_one_error(tmp_path):
    bad = tmp_path / "bad.uff"
    bad.write_bytes(b"    -1\n    58\n garbage\n")
    with pytest.raises(RecordingError, match="bad.uff"):
        xr.open_dataset(bad, engine="bearing_lab")


def test_every_reader_keyword_passes_through():
    from bearing_lab.io import ENGINES
    from bearing_lab.io.xarray_backend import READER_OPTIONS
    names = set().union(*(e().option_names() for e in ENGINES.values()))
    assert names == set(READER_OPTIONS)


def test_allow_truncated_as_the_error_message_says(tmp_path, datafile):
    """A truncated UFF is refused with 'pass allow_truncated=True', and that keyword then works."""
    src = datafile("lms/binary8byte_g.uff").read_bytes()
    cut = tmp_path / "cut.uff"
    cut.write_bytes(src[: len(src) - 200])
    with pytest.raises(RecordingError, match="allow_truncated=True"):
        xr.open_dataset(cut, engine="bearing_lab")
    ds = xr.open_dataset(cut, engine="bearing_lab", allow_truncated=True)
    from bearing_lab.io import get_warnings
    assert ds.sizes["time"] > 0 and any("truncat" in w for w in get_warnings(ds)), get_warnings(ds)
    with pytest.raises(RecordingError, match="takes no keyword 'nope'"):
        xr.open_dataset(cut, engine="bearing_lab", nope=1)
