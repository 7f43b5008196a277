"""Testlab text exports, CSV/TSV, WAV; flat line and clipping flags."""
import numpy as np
import pytest
import scipy.io.wavfile

from bearing_lab import RecordingError, open_recording
from bearing_lab.io._testing import check_reader


def _testlab_text(x, *, comma=False, unit="g", encoding="utf-8", time_col=True):
    head = ["Name\tPoint1", "Project\tRig Süd", "Run\tRun 1", "Start\t0", "Increment\t0.0001"]
    names = (["Time"] if time_col else []) + ["Point1", "Point2"]
    units = (["s"] if time_col else []) + [unit, unit]
    rows = []
    for k, v in enumerate(x):
        cells = ([f"{k * 1e-4:.6f}"] if time_col else []) + [f"{v:.9g}", f"{2 * v:.9g}"]
        rows.append("\t".join(c.replace(".", ",") if comma else c for c in cells))
    text = "\n".join(head + ["\t".join(names), "\t".join(units), "\t".join(["Real"] * len(names))]
                     + rows) + "\n"
    return text.encode(encoding)


def test_testlab_text(write, sine, tmp_path):
    p = write("export.txt", _testlab_text(sine))
    ds = check_reader(p, format="testlab_text", tmp_path=tmp_path)
    assert list(ds.data_vars) == ["Point1", "Point2"]
    assert ds.attrs["sampling_rate_hz"] == 10000.0
    np.testing.assert_allclose(ds["Point2"].values, 2 * sine * 9.80665, rtol=1e-8)
    assert ds.attrs["testlab_project"] == "Rig Süd"


def test_testlab_text_decimal_comma_latin1_no_time(write, sine):
    p = write("export_de.txt", _testlab_text(sine, comma=True, encoding="latin-1", time_col=False))
    ds = open_recording(p)
    assert ds.attrs["reader"] == "testlab_text"
    assert ds.attrs["text_encoding"] == "latin-1" and ds.attrs["decimal_comma"] == 1
    assert ds.attrs["sampling_rate_hz"] == 10000.0
    np.testing.assert_allclose(ds["Point1"].values, sine * 9.80665, rtol=1e-8)


def test_testlab_text_unknown_unit(write, sine):
    p = write("unk.txt", _testlab_text(sine, unit="Zorks"))
    with pytest.raises(RecordingError, match=r"unk.txt: channel 'Point1': unknown unit"):
        open_recording(p)


def _csv(x, header="time,DE [g],FE [g]", dt=1e-3, sep=","):
    lines = [header] + [sep.join([f"{k * dt:.6f}", f"{v:.10g}", f"{-v:.10g}"]) for k, v in enumerate(x)]
    return "\n".join(lines) + "\n"


def test_csv_time_column(write, sine, tmp_path):
    p = write("rig.csv", _csv(sine))
    ds = check_reader(p, format="csv", tmp_path=tmp_path)
    assert list(ds.data_vars) == ["DE", "FE"] and ds.attrs["sampling_rate_hz"] == 1000.0
    np.testing.assert_allclose(ds["DE"].values, sine * 9.80665, rtol=1e-9)


def test_tsv_units_row_and_fs(write, sine):
    text = "a\tb\nm/s^2\tV\n" + "\n".join(f"{v:.8f}\t{v / 10:.8f}" for v in sine) + "\n"
    p = write("rig.tsv", text)
    with pytest.raises(RecordingError, match="rig.tsv: no time column.*fs="):
        open_recording(p)
    with pytest.raises(RecordingError, match="rig.tsv: channel 'b' is in V.*sensitivity"):
        open_recording(p, fs=5000)
    ds = open_recording(p, fs=5000, sensitivity={"b": "100 mV/g"})
    np.testing.assert_allclose(ds["b"].values, sine / 10 / 0.1 * 9.80665, rtol=1e-6)


def test_csv_missing_units(write, sine):
    p = write("nounit.csv", _csv(sine, header="time,DE,FE"))
    with pytest.raises(RecordingError, match="nounit.csv: channel 'DE': unknown unit no unit label"):
        open_recording(p)
    ds = open_recording(p, units={"DE": "g", "FE": "g"})
    assert ds["FE"].attrs["original_units"] == "g"
    with pytest.raises(RecordingError, match="nounit.csv: units= names channel"):
        open_recording(p, units={"DE": "g", "FE": "g", "XX": "g"})


def test_csv_non_uniform_time(write, sine):
    text = _csv(sine).splitlines()
    parts = text[500].split(",")
    parts[0] = "0.499700"
    text[500] = ",".join(parts)
    p = write("jitter.csv", "\n".join(text) + "\n")
    with pytest.raises(RecordingError, match="jitter.csv: time column 'time' is not uniformly sampled"):
        open_recording(p)
    ds = open_recording(p, allow_uneven=True)
    assert ds.attrs["uneven_time"] == 1
    ds = open_recording(p, fs=1000)
    assert ds.attrs["sampling_rate_hz"] == 1000.0


def test_csv_corrupt_number_and_ragged(write, sine):
    text = _csv(sine).splitlines()
    text[10] = text[10].replace(".", "#", 1)
    p = write("bad.csv", "\n".join(text) + "\n")
    with pytest.raises(RecordingError, match=r"bad.csv: line 11, column 1: .* is not a number"):
        open_recording(p)
    text = _csv(sine).splitlines()
    text[20] = text[20].rsplit(",", 1)[0]
    p = write("ragged.csv", "\n".join(text) + "\n")
    with pytest.raises(RecordingError, match="ragged.csv: line 21: 2 columns, expected 3"):
        open_recording(p)


def test_csv_nan(write, sine):
    text = _csv(sine).replace(f",{sine[7]:.10g},", ",nan,", 1)
    p = write("gap.csv", text)
    with pytest.raises(RecordingError, match="gap.csv: channel 'DE' holds 1 NaN/Inf"):
        open_recording(p)



def test_text_readers_time_column_steps():
    """The time-column checks both text readers share: the first step that does not increase,
    uniform within 0.1 % of the median step, and the rate snapped to whole Hz within 1 ppm."""
    from bearing_lab.io._text import column_rate, first_non_increasing, is_uniform
    assert first_non_increasing(np.array([0.0, 1.0, 2.0])) is None
    assert first_non_increasing(np.array([0.0, 1.0, 1.0, 2.0])) == 1
    assert first_non_increasing(np.array([0.0, np.nan, 2.0])) == 0
    assert first_non_increasing(np.array([3.0])) == 0  # one value is no time column
    steps = np.full(99, 1e-3)
    assert is_uniform(steps)
    steps[40] *= 1.002  # one step 0.2 % long
    assert not is_uniform(steps)
    rate = column_rate(np.arange(51201) / 51200.0 * (1 + 1e-9))  # 51199.99995 Hz: whole Hz
    assert rate == 51200.0 and isinstance(rate, float)
    assert column_rate(np.arange(1001) / 2999.7) == pytest.approx(2999.7, rel=1e-12)  # not snapped

def test_flat_line_and_clipping_flagged(write, sine):
    clipped = np.clip(3 * sine, -2.0, 2.0)
    flat = np.zeros_like(sine)
    text = "time,clip [g],flat [g]\n" + "\n".join(
        f"{k * 1e-3:.6f},{c:.10g},{f:.10g}" for k, (c, f) in enumerate(zip(clipped, flat))) + "\n"
    ds = open_recording(write("shape.csv", text))
    w = ds.attrs["warnings"]
    assert "'clip'" in w and "probable clipping" in w
    assert "'flat' is a flat line" in w


def test_wav_needs_calibration(tmp_path, sine):
    p = tmp_path / "rec.wav"
    x = (sine / 2 * 32767).astype(np.int16)
    scipy.io.wavfile.write(p, 8000, x)
    with pytest.raises(RecordingError, match="rec.wav: a WAV file has no physical unit"):
        open_recording(p)
    ds = check_reader(p, format="wav", tmp_path=tmp_path, full_scale="5 V", sensitivity="9.91mV/g")
    volts = x / 32768.0 * 5.0
    np.testing.assert_allclose(ds["ch1"].values, volts / 9.91e-3 * 9.80665, rtol=1e-12)
    ds = open_recording(p, full_scale="50 g")
    np.testing.assert_allclose(ds["ch1"].values, x / 32768.0 * 50 * 9.80665, rtol=1e-12)


def test_wav_clipping_and_stereo(tmp_path, sine):
    p = tmp_path / "st.wav"
    x = np.clip(sine * 40000, -32768, 32767).astype(np.int16)
    scipy.io.wavfile.write(p, 8000, np.column_stack([x, x // 2]))
    ds = open_recording(p, full_scale="10 g")
    assert list(ds.data_vars) == ["ch1", "ch2"]
    assert "full scale: clipping" in ds.attrs["warnings"]


def test_wav_truncated(tmp_path, sine):
    p = tmp_path / "cut.wav"
    scipy.io.wavfile.write(p, 8000, (sine * 1000).astype(np.int16))
    p.write_bytes(p.read_bytes()[:30])
    with pytest.raises(RecordingError, match="cut.wav"):
        open_recording(p, full_scale="5 g")
