"""Hostile inputs beyond flipped bytes: header fields written on purpose, hand-built MAT
elements and zlib streams, files that are not regular files, files that change while read.

Each test builds the smallest file that shows one problem and checks that the user gets one
clear RecordingError naming the file and the cause (or the right values), never a hang, a
traceback from inside a library, or data changed in silence.
"""
import os
import stat
import struct
import threading
import zlib

import numpy as np
import pytest

from bearing_lab import RecordingError, open_recording
from bearing_lab.cli import main


# ------------------------------------------------------------------ not regular files
def test_fifo_is_refused_without_opening_it(tmp_path):
    fifo = tmp_path / "p.uff"
    os.mkfifo(fifo)
    done = []

    def read():
        try:
            open_recording(fifo)
        except RecordingError as exc:
            done.append(str(exc))

    t = threading.Thread(target=read, daemon=True)
    t.start()
    t.join(10)
    if t.is_alive():  # unblock the reader before failing
        with open(fifo, "wb"):
            pass
        pytest.fail("open_recording blocks on a named pipe")
    assert done and "p.uff: is a named pipe (FIFO), not a regular file" in done[0]


def test_devices_and_pseudo_files_are_named(capsys):
    with pytest.raises(RecordingError, match=r"/dev/zero: is a character device, not a regular "):
        open_recording("/dev/zero")
    if os.path.exists("/proc/self/status"):
        with pytest.raises(RecordingError, match=r"status: reports a size of 0 bytes but has content: "
                                                 "a pseudo-file"):
            open_recording("/proc/self/status")
    assert main(["info", "/dev/urandom"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "character device" in err and "empty" not in err


def test_symlink_loop_and_dangling_link(tmp_path):
    loop = tmp_path / "loop.uff"
    loop.symlink_to(loop)
    with pytest.raises(RecordingError, match=r"loop.uff: symbolic links form a loop"):
        open_recording(loop)
    dangling = tmp_path / "gone.uff"
    dangling.symlink_to(tmp_path / "nothere.uff")
    with pytest.raises(RecordingError, match=r"gone.uff: symbolic link to .*nothere.uff, which does "
                                             "not exist"):
        open_recording(dangling)
    with pytest.raises(RecordingError, match=r"missing.uff: file not found"):
        open_recording(tmp_path / "missing.uff")


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads any file")
def test_unreadable_file(tmp_path):
    p = tmp_path / "secret.uff"
    p.write_bytes(b"    -1\n")
    p.chmod(0)
    try:
        with pytest.raises(RecordingError, match=r"secret.uff: cannot read the file \(Permission"):
            open_recording(p)
    finally:
        p.chmod(stat.S_IRUSR | stat.S_IWUSR)


# ------------------------------------------------------------------ files that change while read
def test_uff_truncated_while_read_is_refused(write, sine, monkeypatch):
    """The file is cut between the size check and the read: a message, never SIGBUS."""
    from bearing_lab.io import _base
    from bearing_lab.io._testing import uff58_block
    p = write("cut.uff", uff58_block(sine, binary=True))
    real_fstat = os.fstat
    calls = []

    def fstat_then_truncate(fd):
        st = real_fstat(fd)
        if not calls:  # another program truncates the file right after it was opened
            os.truncate(p, 1000)
        calls.append(st.st_size)
        return st

    monkeypatch.setattr(_base.os, "fstat", fstat_then_truncate)
    with pytest.raises(RecordingError, match=r"cut.uff: the file changed while it was read \(\d+ "
                                             r"bytes when opened, 1000 read, 1000 now\)"):
        open_recording(p, format="uff58")


def test_uff_reader_does_not_map_the_file(write, sine, monkeypatch):
    """A mapped file truncated by another program kills the process (SIGBUS): no mmap."""
    import mmap
    from bearing_lab.io._testing import uff58_block
    p = write("m.uff", uff58_block(sine, binary=True))

    def no_map(*a, **k):
        raise AssertionError("the reader maps the file")

    monkeypatch.setattr(mmap, "mmap", no_map)
    np.testing.assert_array_equal(open_recording(p)["acc"].values, sine)


# ------------------------------------------------------------------ netCDF attributes
def _nc(tmp_path, name="r.nc", *, n=1200, fs=12000.0, reader="csv", **attrs):
    """A small bearing_lab netCDF (a recording, or with reader=None a simulation-like output)."""
    import xarray as xr
    from bearing_lab.io import to_netcdf
    t = np.arange(n) / fs
    acc = np.sin(2 * np.pi * 157.0 * t)
    base = {"sampling_rate_hz": fs, "bearing_lab_version": "0", "default_channel": "acc"}
    if reader:
        base.update(source_file="x", source_sha256="", reader=reader, warnings="")
    else:
        base.update(scene_toml="", fidelity="fast", scene_name="paper-slot")
    base.update(attrs)
    ds = xr.Dataset({"acc": ("time", acc, {"units": "m s-2", "quantity": "acceleration",
                                           "original_units": "m/s2"})},
                    coords={"time": ("time", t, {"units": "s"})}, attrs=base)
    return to_netcdf(ds, tmp_path / name)


def test_import_of_a_netcdf_without_reader_attribute(tmp_path, capsys):
    """A simulation output has no `reader`: importing it is a copy, not a KeyError."""
    src = _nc(tmp_path, "sim.nc", reader=None)
    out = tmp_path / "copy.nc"
    assert main(["import", str(src), "-o", str(out)]) == 0
    assert "1200 samples at 12000 Hz (0.1 s), reader netcdf (simulation)" in capsys.readouterr().out
    np.testing.assert_array_equal(open_recording(out)["acc"].values, open_recording(src)["acc"].values)


@pytest.mark.parametrize("value, why", [
    ("12 kHz", r"attribute sampling_rate_hz is '12 kHz', not a number of Hz"),
    (float("nan"), r"attribute sampling_rate_hz = nan Hz is not a rate of a vibration recording"),
    (1.0, r"attribute sampling_rate_hz = 1 Hz disagrees with the time coordinate \(12000 Hz\)"),
    (12000.5, r"attribute sampling_rate_hz = 12000.5 Hz disagrees with the time coordinate"),
])
def test_netcdf_rate_must_be_a_number_that_matches_time(tmp_path, capsys, value, why):
    p = _nc(tmp_path, sampling_rate_hz=value)
    with pytest.raises(RecordingError, match=r"r.nc: " + why):
        open_recording(p)
    assert main(["info", str(p)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "sampling_rate_hz" in err


@pytest.mark.parametrize("rpm, why", [(1e12, "is faster than any rolling bearing turns"),
                                      (0.0, "is not positive"), (-1797.0, "is not positive"),
                                      ("fast", "is not a number")])
def test_netcdf_stored_speed_must_be_plausible(tmp_path, rpm, why):
    with pytest.raises(RecordingError, match=rf"r.nc: attribute shaft_speed_rpm = .* {why}"):
        open_recording(_nc(tmp_path, shaft_speed_rpm=rpm))


def test_rig_file_with_absurd_speed_keeps_data_drops_speed(tmp_path):
    """A reader that finds an absurd stored speed keeps the signal and says it dropped the speed."""
    from bearing_lab.io import get_warnings
    from bearing_lab.io._base import RecordingBuilder
    from bearing_lab.io.csv import CsvReader
    for rpm in (1e12, 0.0, -5.0, float("nan")):
        b = RecordingBuilder(tmp_path / "f.csv", CsvReader(), checksum=False)
        b.add_channel("acc", np.sin(np.arange(100.0)), "m/s2")
        ds = b.build(fs=1000.0, shaft_speed_rpm=rpm)
        assert "shaft_speed_rpm" not in ds.attrs
        assert any("stored shaft speed" in w and "not used" in w for w in get_warnings(ds)), rpm


def test_analysis_refuses_a_speed_above_nyquist_at_once(tmp_path, capsys):
    """--rpm 1e12 is refused before a candidate grid is allocated (unguarded: hundreds of GiB)."""
    import tracemalloc
    p = _nc(tmp_path, n=24000)
    assert main(["analyze", str(p), "--bearing", "6205", "--rpm", "1e12"]) == 2   # the imports, untraced
    capsys.readouterr()
    tracemalloc.start()
    try:
        assert main(["analyze", str(p), "--bearing", "6205", "--rpm", "1e12"]) == 2
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 50_000_000, f"{peak} bytes allocated before the refusal"
    err = capsys.readouterr().err
    assert "shaft speed of 1e+12 r/min" in err and "below 6000 Hz" in err
    from bearing_lab.analysis import shaft_speed
    from bearing_lab.errors import AnalysisError
    with pytest.raises(AnalysisError, match="cannot be seen in a record sampled at 1000 Hz"):
        shaft_speed(np.random.default_rng(0).normal(size=4000), 1000.0, bearing="6205", rpm=60 * 600)


def test_import_rpm_option_is_bounded(tmp_path, capsys):
    src = _nc(tmp_path)
    assert main(["import", str(src), "--rpm", "1e12", "-o", str(tmp_path / "o.nc")]) == 2
    assert "--rpm 1e+12 is faster than any rolling bearing turns" in capsys.readouterr().err


# ------------------------------------------------------------------ MATLAB v5 / v7.3, hand-built
def _savemat(path, variables, compress=True):
    import scipy.io
    scipy.io.savemat(path, variables, do_compression=compress, oned_as="column")
    return path


def _compressed_element(payload: bytes) -> bytes:
    """A top-level miCOMPRESSED element around ``payload`` (already deflated)."""
    return struct.pack("<II", 15, len(payload)) + payload


def _matrix_bytes(path_of_one_var_file) -> bytes:
    """The inflated miMATRIX element of the only variable of a compressed v5 file."""
    raw = path_of_one_var_file.read_bytes()
    typ, nb = struct.unpack_from("<II", raw, 128)
    assert typ == 15
    return zlib.decompress(raw[136:136 + nb])


def test_mat5_two_zlib_streams_in_one_element_refused(tmp_path):
    """The second stream (here the fan-end channel) is read too, not dropped without a word."""
    x = np.sin(np.arange(4000) / 7.0)
    de = _matrix_bytes(_savemat(tmp_path / "de.mat", {"X130_DE_time": x}))
    fe = _matrix_bytes(_savemat(tmp_path / "fe.mat", {"X130_FE_time": 2 * x}))
    head = (tmp_path / "de.mat").read_bytes()[:128]
    p = tmp_path / "130_two.mat"
    p.write_bytes(head + _compressed_element(zlib.compress(de) + zlib.compress(fe)))
    with pytest.raises(RecordingError, match=r"130_two.mat: .*compressed variable at byte 128: \d+ "
                                             r"bytes follow the end of the compressed stream"):
        open_recording(p, fs=12000)
    junk = tmp_path / "130_junk.mat"
    junk.write_bytes(head + _compressed_element(zlib.compress(de) + b"JUNK" * 8))
    with pytest.raises(RecordingError, match=r"130_junk.mat: .*32 bytes follow the end"):
        open_recording(junk, fs=12000)
    ok = tmp_path / "130_ok.mat"  # one stream per element, as MATLAB writes: both channels read
    ok.write_bytes(head + _compressed_element(zlib.compress(de)) + _compressed_element(zlib.compress(fe)))
    ds = open_recording(ok, fs=12000)
    np.testing.assert_array_equal(ds["FE"].values, 2 * x * 9.80665)


@pytest.mark.parametrize("compress", [False, True])
def test_cwru_n_by_2_matrix_refused_not_interleaved(tmp_path, compress):
    x = np.stack([np.arange(3000.0), -np.arange(3000.0)], axis=1)  # N×2
    p = _savemat(tmp_path / "130_m.mat", {"X130_DE_time": x}, compress)
    with pytest.raises(RecordingError, match=r"130_m.mat: variable 'X130_DE_time' is a 3000×2 matrix, "
                                             "not one channel"):
        open_recording(p, fs=12000)


def test_mfpt_n_by_2_matrix_refused(tmp_path):
    gs = np.stack([np.arange(3000.0), -np.arange(3000.0)], axis=1)
    p = _savemat(tmp_path / "mfpt.mat", {"bearing": {"gs": gs, "sr": 48828.0, "rate": 25.0}})
    with pytest.raises(RecordingError, match=r"mfpt.mat: variable 'bearing.gs' is a 3000×2 matrix"):
        open_recording(p)


def test_v73_n_by_2_matrix_refused(tmp_path):
    """v7.3 (HDF5): MATLAB's N×2 is stored as a 2×N dataset; still one clear refusal."""
    h5py = pytest.importorskip("h5py")
    p = tmp_path / "130_v73.mat"
    with h5py.File(p, "w", userblock_size=512) as f:
        d = f.create_dataset("X130_DE_time", data=np.stack([np.arange(3000.0), -np.arange(3000.0)]))
        d.attrs["MATLAB_class"] = np.bytes_("double")
    with open(p, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: test HDF5 schema 1.00 .")
    with pytest.raises(RecordingError, match=r"130_v73.mat: variable 'X130_DE_time' is a 3000×2 matrix"):
        open_recording(p, fs=12000)


def test_complex_channel_refused_not_cut_to_real(tmp_path):
    z = np.exp(1j * np.arange(3000) / 5.0)
    p = _savemat(tmp_path / "130_c.mat", {"X130_DE_time": z})
    with pytest.raises(RecordingError, match=r"130_c.mat: variable 'X130_DE_time' holds complex values"):
        open_recording(p, fs=12000)


def test_mat5_inflate_bomb_refused_before_allocating(tmp_path, monkeypatch):
    """A few kB that inflate to 80 MB of zeros: refused from the declared size, before inflating."""
    import tracemalloc
    zeros = np.zeros((10_000_000, 1))
    p = _savemat(tmp_path / "130_bomb.mat", {"X130_DE_time": zeros})
    size = p.stat().st_size
    assert size < 200_000
    with pytest.raises(RecordingError, match="inflate ratio"):
        open_recording(p, fs=12000)          # once for the reader's imports, which tracemalloc would count
    tracemalloc.start()
    try:
        with pytest.raises(RecordingError, match=r"130_bomb.mat: .*declares 80000\d+ bytes inside \(inflate "
                                                 r"ratio \d+, more than the 100 .*BEARING_LAB_MAX_INFLATE_RATIO"):
            open_recording(p, fs=12000)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 8_000_000, f"{peak} bytes allocated before the refusal (the payload inflates to 80 MB)"
    monkeypatch.setenv("BEARING_LAB_MAX_INFLATE_RATIO", "1e6")  # the user says it is genuine
    ds = open_recording(p, fs=12000)
    assert ds.sizes["time"] == 10_000_000 and not ds["DE"].values.any()


# ------------------------------------------------------------------ WAV format fields
def wav_bytes(samples, *, channels=None, bits=16, align=None, tag=1, rate=12000, fmt_first=True):
    """A RIFF/WAVE file with format fields as given (independent of scipy's writer)."""
    samples = np.asarray(samples)
    channels = samples.shape[1] if channels is None else channels
    align = channels * ((bits + 7) // 8) if align is None else align
    payload = samples.astype("<i2" if bits == 16 else "<f4").tobytes()
    fmt = b"fmt " + struct.pack("<IHHIIHH", 16, tag, channels, rate, rate * align, align, bits)
    data = b"data" + struct.pack("<I", len(payload)) + payload + b"\0" * (len(payload) & 1)
    body = b"WAVE" + (fmt + data if fmt_first else data + fmt)
    return b"RIFF" + struct.pack("<I", len(body)) + body


@pytest.mark.parametrize("fields, why", [
    ({"align": 1}, r"block_align is 1 bytes but 2 channel\(s\) × 2 bytes \(16-bit samples\) make 4"),
    ({"align": 8}, r"block_align is 8 bytes but 2 channel\(s\) × 2 bytes"),
    ({"channels": 0, "align": 4}, r"the fmt chunk declares 0 channels"),
    ({"bits": 0, "align": 4}, r"the fmt chunk declares 0 bits per sample"),
    ({"tag": 2}, r"format tag 2 is not PCM \(1\) or IEEE float \(3\)"),
    ({"rate": 0}, r"the fmt chunk declares a sampling rate of 0 Hz"),
    ({"fmt_first": False}, r"the data chunk comes before the fmt chunk"),
])
def test_wav_format_fields_checked_before_decoding(write, fields, why):
    """scipy picks the sample type from block_align: a wrong one read int16 data as int8/int32."""
    x = (np.arange(400).reshape(200, 2) - 200) * 50
    p = write("f.wav", wav_bytes(x, **fields))
    with pytest.raises(RecordingError, match=r"f.wav: not a valid WAV file: " + why):
        open_recording(p, full_scale="10 g")


def test_wav_with_consistent_fields_reads_the_samples(write):
    x = (np.arange(400).reshape(200, 2) - 200) * 50
    ds = open_recording(write("ok.wav", wav_bytes(x)), full_scale="10 g")
    np.testing.assert_allclose(ds["ch2"].values, x[:, 1] / 32768 * 10 * 9.80665, rtol=1e-12)
    assert ds.attrs["wav_dtype"] == "int16"


# ------------------------------------------------------------------ UFF header fields
def _u164(length: str, force: str = "1.00000000000000000D+00") -> bytes:
    return (b"    -1\n   164\n         2mm (milli newton)         2\n"
            + f"  {length:>25s}  {force:>25s}  1.00000000000000000D+00\n".encode()
            + b"  2.73150000000000000D+02\n    -1\n")


@pytest.mark.parametrize("length, scale", [("Infinity", "0"), ("1.0D-300", "1e+300"),
                                           ("1.0D+200", "1e-200"), ("NaN", "nan")])
def test_uff_164_factor_that_is_no_unit_refused(write, sine, length, scale):
    """An infinite length factor multiplied every sample by 0; 1e-300 scaled them by 1e300."""
    from bearing_lab.io._testing import uff58_block
    import re
    p = write("u.uff", _u164(length) + uff58_block(sine, unit="NONE", binary=True))
    with pytest.raises(RecordingError, match=rf"u.uff: set \d+: the unit factors of dataset 164 .* "
                                             rf"would scale every value by {re.escape(scale)}: not a unit "
                                             "conversion.*units="):
        open_recording(p)
    ds = open_recording(p, units="m/s2")  # the user's unit replaces the damaged units set
    np.testing.assert_array_equal(ds["acc"].values, sine)


def test_uff_164_ignored_when_every_channel_has_a_label(write, sine):
    from bearing_lab.io import get_warnings
    from bearing_lab.io._testing import uff58_block
    ds = open_recording(write("u.uff", _u164("Infinity") + uff58_block(sine, unit="m/s2", binary=True)))
    np.testing.assert_array_equal(ds["acc"].values, sine)
    assert any("which are not unit factors" in w for w in get_warnings(ds))


@pytest.mark.parametrize("inc", ["1.00000E-320", "1.00000E-12"])
def test_uff_increment_that_means_no_rate_refused(write, sine, inc):
    """1e-320 made round(fs) raise OverflowError inside the rate snapping."""
    from bearing_lab.io._testing import uff58_block
    p = write("inc.uff", uff58_block(sine, inc=inc))
    with pytest.raises(RecordingError, match=rf"inc.uff: abscissa increment '{inc}' s means a sampling "
                                             r"rate of .* Hz, outside 0.001 Hz .. 1e\+09 Hz"):
        open_recording(p)


# ------------------------------------------------------------------ outputs: names and disks
def test_long_output_name_up_to_the_limit(tmp_path, datafile, capsys):
    """A 240-byte -o name failed: the temporary name added ~22 bytes past the 255-byte limit."""
    src = datafile("lms/binary8byte_g.uff")
    for length in (233, 240, 255):
        out = tmp_path / ("a" * (length - 3) + ".nc")
        assert main(["import", str(src), "-o", str(out)]) == 0, capsys.readouterr().err
        assert out.is_file() and len(os.listdir(tmp_path)) == 1  # no temporary left
        out.unlink()
    too_long = tmp_path / ("a" * 253 + ".nc")
    assert main(["import", str(src), "-o", str(too_long)]) == 2
    assert "the file name has 256 bytes; a file name has at most 255" in capsys.readouterr().err


def test_stale_temporaries_of_long_names_are_found(tmp_path):
    """The cut-and-hashed temporary prefix is the same in every process, so a killed writer's
    temporary of a long name is removed by the next write."""
    from bearing_lab.utils import _files
    name = "b" * 250 + ".nc"
    stale = tmp_path / (_files._tmp_prefix(name, ".nc").replace(f"-{os.getpid()}.", "-4194303.")
                        + "zzzzzzzz.nc")
    assert len(os.fsencode(stale.name)) <= 255
    stale.write_bytes(b"half")
    _files.write_text(tmp_path / name, "x")
    assert sorted(os.listdir(tmp_path)) == [name]


def test_output_name_that_is_not_utf8(tmp_path, datafile, capsys):
    """An -o name in another locale's bytes raised UnicodeEncodeError inside netCDF-C."""
    src = datafile("lms/binary8byte_g.uff")
    out = os.path.join(os.fsdecode(bytes(tmp_path)), os.fsdecode(b"caf\xe9.nc"))
    assert main(["import", str(src), "-o", out]) == 0, capsys.readouterr().err
    assert os.listdir(bytes(tmp_path)) == [b"caf\xe9.nc"]
    assert open_recording(out)["sine_5_Hz"].size == 250


def test_full_disk_is_named_as_such(tmp_path, monkeypatch):
    """netCDF-C reports a full disk as 'Permission denied' or 'HDF error'."""
    import shutil
    import xarray as xr
    from bearing_lab.errors import BearingLabError
    from bearing_lab.io import to_netcdf

    def denied(self, path, **kw):
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(xr.Dataset, "to_netcdf", denied)
    ds = xr.Dataset({"a": ("time", np.zeros(100_000))}, coords={"time": np.arange(100_000.0)})
    real = shutil.disk_usage
    monkeypatch.setattr(shutil, "disk_usage", lambda p: real(p)._replace(free=4096))
    with pytest.raises(BearingLabError, match=r"o.nc: cannot write netCDF4 \(no space left on the "
                                              r"device: 0.0041 MB free in .*, the data take up to 1.6 MB\)"):
        to_netcdf(ds, tmp_path / "o.nc")
    monkeypatch.setattr(shutil, "disk_usage", real)  # space enough: the library's own words
    with pytest.raises(BearingLabError, match=r"PermissionError: \[Errno 13\] Permission denied"):
        to_netcdf(ds, tmp_path / "o.nc")


def test_column_name_that_netcdf_refuses_is_cleaned_at_read(write, tmp_path, capsys):
    """'../../etc [g]' failed at write time, naming the output file, not the input column."""
    p = write("c.csv", "time [s],../../etc [g],.hidden [g],-x [g]\n0,1,2,3\n0.001,2,3,1\n0.002,3,1,2\n")
    ds = open_recording(p)
    assert list(ds.data_vars) == ["etc", "hidden", "x"]
    assert main(["import", str(p), "-o", str(tmp_path / "c.nc")]) == 0, capsys.readouterr().err


# ------------------------------------------------------------------ the guarded child
def test_script_without_main_guard_reads_a_netcdf(tmp_path):
    """The fork-server child re-ran a script that has no `if __name__ == "__main__":`, which
    opened the file again and was reported as netCDF-C crashing on a damaged file."""
    import subprocess
    import sys
    nc = _nc(tmp_path)
    script = tmp_path / "user_script.py"
    script.write_text("import sys\nfrom bearing_lab.io import open_recording\nprint('RUN')\n"
                      "print('OK', open_recording(sys.argv[1]).sizes['time'])\n")
    r = subprocess.run([sys.executable, str(script), str(nc)], capture_output=True, text=True,
                       timeout=120, env={**os.environ, "BEARING_LAB_NO_GUARD": ""})
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.split() == ["RUN", "OK", "1200"]  # the script ran once


def test_child_that_exits_is_not_blamed_on_the_file(tmp_path):
    from bearing_lab.io._guard import guarded
    with pytest.raises(RecordingError, match=r"x.nc: the process reading the file with netCDF-C ended "
                                             r"with exit status 3 before it answered \(not a crash"):
        guarded(tmp_path / "x.nc", "netCDF-C", os._exit, 3)


def test_mat5_values_that_do_not_fit_their_class_refused(tmp_path):
    """A uint8 array stored as int16 with negative values wrapped around without a word."""
    from bearing_lab.io._fuzz_struct import _mat5_array, _mat5_file
    v = np.arange(-50, 250).astype("<i2")
    p = tmp_path / "130_wrap.mat"
    p.write_bytes(_mat5_file([_mat5_array("X130_DE_time", 9, (300, 1), 3, v.tobytes())]))
    with pytest.raises(RecordingError, match=r"130_wrap.mat: .*values -50 .. 249 do not fit the array's "
                                             r"class uint8 \(they would wrap around\)"):
        open_recording(p, fs=12000)
    ok = tmp_path / "130_fits.mat"
    ok.write_bytes(_mat5_file([_mat5_array("X130_DE_time", 9, (300, 1), 3, np.abs(v).tobytes())]))
    np.testing.assert_array_equal(open_recording(ok, fs=12000)["DE"].values, np.abs(v) * 9.80665)


def test_wav_without_data_chunk(write):
    """scipy raised UnboundLocalError (caught only by the catch-all) for a WAV with no data chunk."""
    x = (np.arange(400).reshape(200, 2) - 200) * 50
    full = wav_bytes(x)
    body = full[12:12 + 24]  # the fmt chunk only
    p = write("nodata.wav", b"RIFF" + struct.pack("<I", 4 + len(body)) + b"WAVE" + body)
    with pytest.raises(RecordingError, match=r"nodata.wav: not a valid WAV file: no data chunk"):
        open_recording(p, full_scale="10 g")
    short = bytearray(full)  # a RIFF size that ends before the data chunk: scipy never sees it
    short[4:8] = struct.pack("<I", 4 + 24)
    with pytest.raises(RecordingError, match=r"f.wav: not a (valid|readable) WAV file") as exc:
        open_recording(write("f.wav", bytes(short)), full_scale="10 g")
    assert "UnboundLocalError" not in str(exc.value)
