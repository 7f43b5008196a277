"""UFF 58 / 58b: the real exports, and the known pitfalls of UFF 58/58b (header fields, binary byte
counts, padding, the closing -1) on synthetic sets."""
import numpy as np
import pytest

from tests.helpers import require

from bearing_lab import RecordingError, open_recording
from bearing_lab.io import RecordingWarning, get_warnings
from bearing_lab.io._testing import check_reader
from bearing_lab.io._testing import uff58_block

pyuff = require("pyuff")


def _map(path):
    """A read-only memory map (the scan works on any buffer; the reader itself reads the file)."""
    import mmap
    with open(path, "rb") as fh:
        return mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ)


def _pyuff_sets(path):
    s = pyuff.UFF(str(path)).read_sets()
    return [s] if isinstance(s, dict) else s


def test_mpstd_four_channels(datafile, tmp_path):
    p = datafile("lms/mpstd_set001_58b_4ch.uff")
    ds = check_reader(p, format="uff58", tmp_path=tmp_path)
    assert list(ds.data_vars) == ["1+Z", "2+Z", "3+Z", "1+Z_2"]  # node/direction 1+Z repeats
    assert ds.attrs["sampling_rate_hz"] == 3200.0
    assert ds.sizes["time"] == 222400
    assert ds["1+Z"].attrs["units"] == "m s-2" and ds["1+Z"].attrs["original_units"] == "m/s2"
    assert ds["1+Z_2"].attrs["id1"] == "MPS set1 Dof4"
    for (name, var), ref in zip(ds.data_vars.items(), _pyuff_sets(p)):
        np.testing.assert_array_equal(var.values, ref["data"])  # same values as pyuff, bit for bit
    assert get_warnings(ds) == []


def test_microphone_rate_snapped(datafile):
    p = datafile("lms/sample_58b_microphone.uff")
    with pytest.warns(RecordingWarning, match="snapped"):
        ds = open_recording(p)
    assert ds.attrs["sampling_rate_hz"] == 65536.0
    assert ds.attrs["file_sampling_rate_hz"] == pytest.approx(65535.953, abs=1e-3)
    assert ds["Mic_01"].attrs["units"] == "Pa"
    assert ds.sizes["time"] == 79292
    assert any("snapped" in w for w in get_warnings(ds))


def test_ascii_equals_binary(datafile):
    a = open_recording(datafile("lms/sample_58_ascii.uff"))
    b = open_recording(datafile("lms/sample_58b_microphone.uff"))
    np.testing.assert_allclose(a["Mic_01"].values, b["Mic_01"].values, rtol=1e-5, atol=1e-9)
    ref = _pyuff_sets(datafile("lms/sample_58_ascii.uff"))[0]["data"]
    np.testing.assert_array_equal(a["Mic_01"].values, ref)


def test_binary_8byte_in_g(datafile, tmp_path):
    p = datafile("lms/binary8byte_g.uff")
    ds = check_reader(p, format="uff58", tmp_path=tmp_path)
    v = ds["sine_5_Hz"]
    assert v.attrs["original_units"] == "g" and v.attrs["units"] == "m s-2"
    np.testing.assert_allclose(v.values, _pyuff_sets(p)[0]["data"] * 9.80665, rtol=1e-15)
    assert ds.attrs["sampling_rate_hz"] == 100.0


def test_catman_utf8_unit_short_line(datafile):
    ds = open_recording(datafile("lms/catman_58_ascii_short.uff"))
    assert ds.sizes["time"] == 13
    assert ds.attrs["sampling_rate_hz"] == 20000.0
    assert ds["ch1"].attrs["original_units"] == "m/s²"


def test_truncated_refused_or_kept(datafile):
    p = datafile("lms/truncated_58_ascii.uff")
    with pytest.raises(RecordingError, match=r"truncated_58_ascii.uff.*2508876 points, 42 present"):
        open_recording(p)
    with pytest.warns(RecordingWarning, match="42 present"):
        ds = open_recording(p, allow_truncated=True)
    assert ds.sizes["time"] == 42
    assert ds.time.values[0] == pytest.approx(1.11858e-05)  # non-zero start kept
    assert ds.attrs["sampling_rate_hz"] == 51200.0
    assert "42 present" in ds.attrs["warnings"]


def test_geometry_only(datafile):
    with pytest.raises(RecordingError, match=r"testlab_geometry_only.uff: no time-history datasets"):
        open_recording(datafile("lms/testlab_geometry_only.uff"))


# -- synthetic -----------------------------------------------------------------------
@pytest.mark.parametrize("bo", [1, 2])
@pytest.mark.parametrize("double", [True, False])
def test_byte_orders_and_precisions(write, sine, bo, double, tmp_path):
    p = write("s.uff", uff58_block(sine, binary=True, bo=bo, double=double))
    ds = check_reader(p, format="uff58")
    ref = sine if double else sine.astype(np.float32).astype(float)
    np.testing.assert_array_equal(ds["acc"].values, ref)
    assert ds.attrs["sampling_rate_hz"] == 1000.0


def test_wrong_byte_order_declared(write, sine):
    """Big-endian bytes declared little-endian: absurd values are caught, not passed on."""
    raw = uff58_block(sine, binary=True, bo=2, double=True).replace(b"58b     2", b"58b     1", 1)
    p = write("wrong_bo.uff", raw)
    with pytest.raises(RecordingError, match="wrong_bo.uff"):
        open_recording(p)


def test_nonzero_start_and_ascii_double(write, sine):
    p = write("a.uff", uff58_block(sine, double=True, t0="2.50000E-01"))
    ds = open_recording(p)
    assert ds.time.values[0] == 0.25
    np.testing.assert_allclose(ds["acc"].values, sine, rtol=1e-10)


def test_header_promises_more_binary(write, sine):
    raw = uff58_block(sine, binary=True)
    p = write("cut.uff", raw[: len(raw) // 2])
    with pytest.raises(RecordingError, match="cut.uff.*header promises 2000 points"):
        open_recording(p)
    ds = open_recording(p, allow_truncated=True)
    assert 0 < ds.sizes["time"] < 2000


def test_truncated_last_set_reported(write, sine):
    two = uff58_block(sine, ent="a") + uff58_block(sine, ent="b")
    p = write("two.uff", two[:-3000])
    with pytest.raises(RecordingError, match="header promises 2000 points"):
        open_recording(p)


def test_nan_in_data(write, sine):
    raw = uff58_block(sine).replace(b"-1.00000E-01", b"         NaN", 1)
    raw = raw if b"NaN" in raw else uff58_block(np.r_[sine[:10], np.nan, sine[11:]])
    p = write("nan.uff", raw)
    with pytest.raises(RecordingError, match=r"nan.uff: channel 'acc' holds 1 NaN/Inf"):
        open_recording(p)


def test_inf_in_binary(write, sine):
    x = sine.copy()
    x[5] = np.inf
    p = write("inf.uff", uff58_block(x, binary=True))
    with pytest.raises(RecordingError, match="NaN/Inf"):
        open_recording(p)


def test_corrupt_number(write, sine):
    raw = bytearray(uff58_block(sine))
    i = raw.index(b"E", raw.index(b"NONE                \n    ") + 400)
    raw[i - 3:i] = b"x#?"
    p = write("corrupt.uff", bytes(raw))
    with pytest.raises(RecordingError, match=r"corrupt.uff: .*corrupt number"):
        open_recording(p)


def test_corrupt_header(write, sine):
    raw = uff58_block(sine).replace(b"      2000         1", b"      2O00         1", 1)
    p = write("hdr.uff", raw)
    with pytest.raises(RecordingError, match="hdr.uff.*record 7"):
        open_recording(p)


def test_uneven_abscissa_kept(write, sine):
    x = np.cumsum(np.r_[0, np.full(1999, 1e-3)])
    x[1000:] += 0.0005
    p = write("uneven.uff", uff58_block(sine, double=True, spacing=0, x=x))
    ds = open_recording(p)
    assert ds.attrs["uneven_time"] == 1
    np.testing.assert_allclose(ds.time.values, x, rtol=1e-9)
    assert "uneven" in ds.attrs["warnings"]


def test_uneven_abscissa_not_increasing_refused(write, sine):
    x = np.arange(2000) * 1e-3
    x[500] = x[498]
    p = write("back.uff", uff58_block(sine, double=True, spacing=0, x=x))
    with pytest.raises(RecordingError, match="back.uff: time values are not strictly increasing"):
        open_recording(p)


def test_different_rates_refused_then_selected(write, sine):
    raw = uff58_block(sine, ent="fast") + uff58_block(sine[::2], ent="slow", inc="2.00000E-03")
    p = write("rates.uff", raw)
    with pytest.raises(RecordingError, match="rates.uff: channels differ in rate.*channels="):
        open_recording(p)
    ds = open_recording(p, channels=["slow"])
    assert list(ds.data_vars) == ["slow"] and ds.attrs["sampling_rate_hz"] == 500.0


def test_dataset_164_units_applied(write, sine):
    u164 = (b"    -1\n   164\n         2mm (milli newton)         2\n"
            b"  1.00000000000000000D+03  1.00000000000000000D+00  1.00000000000000000D+00\n"
            b"  2.73150000000000000D+02\n    -1\n")
    p = write("u164.uff", u164 + uff58_block(sine, unit="NONE"))
    ds = open_recording(p)
    assert ds["acc"].attrs["units"] == "m s-2"
    np.testing.assert_allclose(ds["acc"].values, sine / 1000.0, rtol=1e-10)
    assert ds["acc"].attrs["uff_164_factor"] == pytest.approx(1e-3)


def test_unknown_unit_refused_then_given(write, sine):
    p = write("unit.uff", uff58_block(sine, unit="furlong/ftn2", spec=1))
    with pytest.raises(RecordingError, match=r"unit.uff: channel 'acc': unknown unit 'furlong/ftn2'"):
        open_recording(p)
    ds = open_recording(p, units="g")
    assert ds["acc"].attrs["original_units"] == "g"
    assert ds["acc"].attrs["file_units"] == "furlong/ftn2"


def test_voltage_channel_needs_sensitivity(write, sine):
    p = write("volt.uff", uff58_block(sine, unit="V", spec=1))
    with pytest.raises(RecordingError, match="volt.uff.*sensitivity='9.91mV/g'"):
        open_recording(p)
    ds = open_recording(p, sensitivity="9.91mV/g")
    np.testing.assert_allclose(ds["acc"].values, sine / 9.91e-3 * 9.80665, rtol=1e-9)
    assert ds["acc"].attrs["quantity"] == "acceleration"
    assert ds["acc"].attrs["sensitivity"] == "9.91mV/g"


def test_voltage_clipping_flagged(write):
    x = np.clip(6 * np.sin(np.linspace(0, 20, 2000)), -5.0, 5.0)
    p = write("clip.uff", uff58_block(x, unit="V", spec=1, binary=True))
    ds = open_recording(p, sensitivity="10mV/g")
    text = ds.attrs["warnings"]
    assert "IEPE" in text and "clipping" in text


def test_non_time_sets_dropped(write, sine):
    raw = uff58_block(sine, func_type=4, ent="frf", abscissa_spec=18) + uff58_block(sine, ent="acc")
    ds = open_recording(write("mixed.uff", raw))
    assert list(ds.data_vars) == ["acc"]
    assert "not time responses" in ds.attrs["warnings"]


def test_contradicting_function_type_refused_not_dropped(write, sine):
    """A time abscissa with a non-time function type (one damaged digit) loses no channel."""
    raw = uff58_block(sine, func_type=4, ent="b") + uff58_block(sine, ent="acc")
    with pytest.raises(RecordingError, match=r"odd.uff: set 1: function type 4 with abscissa data "
                                             r"type 17.*damaged"):
        open_recording(write("odd.uff", raw))


@pytest.mark.parametrize("cut", [3, 8])
def test_missing_closing_delimiter_refused_or_declared(write, sine, cut):
    """A file cut inside the last set's closing '-1' (or inside its last number) is truncated."""
    raw = uff58_block(sine, ent="a") + uff58_block(sine, ent="b")
    p = write("cut.uff", raw[:-cut])
    with pytest.raises(RecordingError, match=r"cut.uff: set 2 \('b'\).*(no closing '-1'|2000 points, "
                                             r"1999 present)"):
        open_recording(p)
    one = write("cut1.uff", uff58_block(sine, ent="b")[:-cut])
    ds = open_recording(one, allow_truncated=True)
    assert ds.attrs["truncated"] == 1 and "truncated" in ds.attrs["warnings"]
    np.testing.assert_allclose(ds["b"].values, sine[:ds.sizes["time"]], rtol=1e-5)


def test_unknown_dataset_type_refused(write, sine):
    raw = uff58_block(sine, ent="a", binary=True) + uff58_block(sine, ent="b", binary=True)
    k = raw.index(b"58b", 100)
    with pytest.raises(RecordingError, match=r"bad.uff: set 2 .*(not a Universal File dataset|binary)"):
        open_recording(write("bad.uff", raw[:k] + b"  1" + raw[k + 3:]))


def test_payload_shorter_than_header_is_not_padding(write, sine):
    """Binary data 5 bytes short: the next set's delimiter must not be swallowed as padding."""
    a = uff58_block(sine, ent="a", binary=True)
    k = a.index(b"\n", a.index(b"NONE                 NONE", 800)) + 1 + 400
    raw = a[:k] + a[k + 5:] + uff58_block(sine, ent="b", binary=True)
    with pytest.raises(RecordingError, match=r"short.uff: set 1: .* bytes that are not padding"):
        open_recording(write("short.uff", raw))


def test_padding_and_crlf_after_payload(write, sine):
    raw = uff58_block(sine, binary=True)
    raw = raw[:-7] + b"\x00\x00\x00\x00\r\n    -1\n"
    ds = open_recording(write("pad.uff", raw))
    np.testing.assert_array_equal(ds["acc"].values, sine)
    assert "padding" in ds.attrs["warnings"]


def test_wrong_byte_order_override(write, sine):
    raw = uff58_block(sine, binary=True, bo=2, double=True).replace(b"58b     2", b"58b     1", 1)
    ds = open_recording(write("wrong_bo2.uff", raw), byte_order="big")
    np.testing.assert_array_equal(ds["acc"].values, sine)


def test_big_58b_scanned_header_first(tmp_path):
    """The scan reads headers and seeks past binary payloads, never through them.

    Two files: a 1 GiB set whose payload is a hole (sparse: no disk, no memory), and a 1 MiB set
    whose payload is text that looks like set delimiters and headers (``-1``, ``58b``) — a scanner
    that read through a payload would stop inside it and report another extent or more sets.
    """
    from bearing_lab.io._base import RecordingBuilder
    from bearing_lab.io.uff58 import Uff58Reader
    junk = b"\n    -1\n    -1\n    58b     2     1    11     800     3   800\n"
    for n, fill in ((2 ** 27, None), (2 ** 17, junk)):     # float64 values: 1 GiB, 1 MiB
        p = tmp_path / f"big{n}.uff"
        head = uff58_block(np.zeros(1), binary=True, num_pts=n, nbytes=n * 8)
        head = head[: head.rindex(b"\n", 0, len(head) - 8) + 1]  # header only, up to the payload
        with open(p, "wb") as fh:
            fh.write(head)
            if fill is None:
                fh.seek(len(head) + n * 8)
            else:
                body = fill * (n * 8 // len(fill) + 1)
                fh.write(body[: n * 8])
            fh.write(b"    -1\n")
        r = Uff58Reader()
        r._force_bo = None
        mm = _map(p)
        try:
            sets = r._scan(mm, RecordingBuilder(p, r, checksum=False))
        finally:
            mm.close()
        assert len(sets) == 1 and sets[0].header["num_pts"] == n, p.name
        assert sets[0].data_start == len(head) and sets[0].data_end - sets[0].data_start == n * 8, p.name


def test_line_break_before_payload(write, sine):
    raw = uff58_block(sine, binary=True)
    i = raw.index(b"NONE                 NONE                \n", raw.index(b"Acceleration")) + 42
    i = raw.index(b"\n", raw.index(b"NONE", i)) + 1  # end of the 11th header line
    ds = open_recording(write("crlf.uff", raw[:i] + b"\r\n" + raw[i:]))
    np.testing.assert_array_equal(ds["acc"].values, sine)
    assert "line-break" in ds.attrs["warnings"]


def test_junk_after_a_binary_set_of_another_dataset_is_a_clear_error(write, sine):
    """A 2414b set (not dataset 58: the reader skips its payload) followed by bytes that are not padding:
    the same clear refusal as for a 58b set, not an attribute missing from the skipped set."""
    other = (b"    -1\n" + b"  2414b%6i%6i%12i%12i%6i%6i%12i%12i\n" % (1, 2, 2, 8, 0, 0, 0, 0)
             + b"header line 1\nheader line 2\n" + bytes(range(8)) + b"JUNKJUNK\n    -1\n")
    with pytest.raises(RecordingError, match=r"other.uff: set 1: 9 bytes that are not padding .* 8 bytes its "
                                             r"binary header declares \(dataset 2414b\)"):
        open_recording(write("other.uff", other + uff58_block(sine, ent="b", binary=True)))
    clean = other.replace(b"JUNKJUNK\n", b"")                      # the same set without the junk reads
    ds = open_recording(write("clean.uff", clean + uff58_block(sine, ent="b", binary=True)))
    np.testing.assert_array_equal(ds["b"].values, sine)
