"""Optional readers: NI TDMS (npTDMS) and ASAM MDF (asammdf); skipped when not installed."""
import numpy as np
import pytest

from tests.helpers import require

from bearing_lab import RecordingError, open_recording
from bearing_lab.io._testing import check_reader


def test_tdms(tmp_path, sine):
    nptdms = require("nptdms")
    p = tmp_path / "rig.tdms"
    props = {"wf_increment": 1e-3, "wf_start_offset": 0.5, "unit_string": "g"}
    with nptdms.TdmsWriter(p) as w:
        w.write_segment([nptdms.ChannelObject("Vib", "DE", sine, properties=props),
                         nptdms.ChannelObject("Vib", "FE", 2 * sine, properties=props)])
    ds = check_reader(p, format="tdms", tmp_path=tmp_path)
    assert list(ds.data_vars) == ["DE", "FE"]
    assert ds.attrs["sampling_rate_hz"] == 1000.0 and ds.time.values[0] == 0.5
    np.testing.assert_allclose(ds["FE"].values, 2 * sine * 9.80665)


def test_tdms_different_rates(tmp_path, sine):
    nptdms = require("nptdms")
    p = tmp_path / "rates.tdms"
    with nptdms.TdmsWriter(p) as w:
        w.write_segment([
            nptdms.ChannelObject("G", "a", sine, properties={"wf_increment": 1e-3, "unit_string": "g"}),
            nptdms.ChannelObject("G", "b", sine[::2], properties={"wf_increment": 2e-3,
                                                                  "unit_string": "g"})])
    with pytest.raises(RecordingError, match="rates.tdms: channels differ in rate"):
        open_recording(p)
    assert open_recording(p, channels=["b"]).attrs["sampling_rate_hz"] == 500.0


def test_tdms_corrupt(tmp_path):
    require("nptdms")
    p = tmp_path / "bad.tdms"
    p.write_bytes(b"TDSm" + bytes(range(200)))
    with pytest.raises(RecordingError, match="bad.tdms"):
        open_recording(p)


def test_mdf(tmp_path, sine):
    asammdf = require("asammdf")
    p = tmp_path / "rig.mf4"
    t = np.arange(sine.size) / 1000.0
    m = asammdf.MDF(version="4.10")
    m.append([asammdf.Signal(sine, t, name="DE", unit="g")])
    m.save(p, overwrite=True)
    ds = check_reader(p, format="mdf", tmp_path=tmp_path)
    assert ds.attrs["sampling_rate_hz"] == pytest.approx(1000.0)
    np.testing.assert_allclose(ds["DE"].values, sine * 9.80665)


def test_tdms_fuzz(tmp_path, sine):
    nptdms = require("nptdms")
    from hypothesis import HealthCheck, given, settings, strategies as st
    src = tmp_path / "src.tdms"
    with nptdms.TdmsWriter(src) as w:
        w.write_segment([nptdms.ChannelObject("G", "a", sine[:300], properties={
            "wf_increment": 1e-3, "unit_string": "g"})])
    data = src.read_bytes()

    @settings(max_examples=15, deadline=None, derandomize=True,
              suppress_health_check=[HealthCheck.function_scoped_fixture])
    @given(cut=st.floats(0, 1), flips=st.lists(st.tuples(st.floats(0, 1), st.integers(0, 255)),
                                               max_size=5))
    def run(cut, flips):
        b = bytearray(data[:max(1, int(len(data) * cut))])
        for pos, val in flips:
            b[int(pos * (len(b) - 1))] = val
        p = tmp_path / "fz.tdms"
        p.write_bytes(bytes(b))
        try:
            ds = open_recording(p, format="tdms")
        except RecordingError as exc:
            assert "fz.tdms" in str(exc)
        else:  # what opens must still be a valid recording
            from bearing_lab.schema import check_dataset
            check_dataset(ds, kind="recording")

    run()


def test_engine_alias(datafile):
    ds = open_recording(datafile("lms/binary8byte_g.uff"), engine="uff58")
    assert ds.attrs["reader"] == "uff58"


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_mdf_two_rasters_and_corrupt(tmp_path, sine):
    asammdf = require("asammdf")
    p = tmp_path / "rasters.mf4"
    m = asammdf.MDF(version="4.10")
    m.append([asammdf.Signal(sine, np.arange(sine.size) / 1000.0, name="DE", unit="g")])
    m.append([asammdf.Signal(sine[::2], np.arange(sine.size // 2) / 500.0, name="FE", unit="g")])
    m.save(p, overwrite=True)
    with pytest.raises(RecordingError, match="rasters.mf4: channels 'DE' and 'FE' have different"):
        open_recording(p)
    assert open_recording(p, channels=["FE"]).attrs["sampling_rate_hz"] == pytest.approx(500.0)
    bad = tmp_path / "bad.mf4"
    bad.write_bytes(p.read_bytes()[:300])
    with pytest.raises(RecordingError, match="bad.mf4"):
        open_recording(bad)
    import gc
    gc.collect()  # asammdf's __del__ of the half-built object complains here, not later
