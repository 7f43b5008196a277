"""CLI import/info/data, and the generic bad inputs (empty, PNG renamed, unknown options)."""
import json

import numpy as np
import pytest
import xarray as xr

from bearing_lab import RecordingError, open_recording
from bearing_lab.cli import main
from bearing_lab.io import list_engines
from bearing_lab.units import lookup_unit, parse_sensitivity

PNG = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + bytes(200)


def test_empty_file(write):
    with pytest.raises(RecordingError, match=r"empty.uff: file is empty \(0 bytes\)"):
        open_recording(write("empty.uff", b""))


def test_png_renamed(write):
    p = write("picture.uff", PNG)
    with pytest.raises(RecordingError, match=r"picture.uff: no reader recognises this file.*format="):
        open_recording(p)
    with pytest.raises(RecordingError, match=r"picture.uff: expected a '    -1' block delimiter"):
        open_recording(p, format="uff58")


def test_missing_dir_format_option(tmp_path, write, sine):
    with pytest.raises(RecordingError, match="nothere.uff: file not found"):
        open_recording(tmp_path / "nothere.uff")
    with pytest.raises(RecordingError, match="is a directory"):
        open_recording(tmp_path)
    p = write("x.csv", "time,a [g]\n0,1\n0.001,2\n0.002,3\n")
    with pytest.raises(RecordingError, match="format: invalid value 'xls'; allowed values are"):
        open_recording(p, format="xls")
    with pytest.raises(RecordingError, match="x.csv: the 'csv' reader does not understand option"
                                             r"\(s\) full_scale; it accepts"):
        open_recording(p, full_scale="5 V")


def test_units_table():
    for s in ("m/s2", "m/s²", "m/s^2", "m/sÂ²", "[m/s2]", "m s-2"):
        assert lookup_unit(s).si == "m s-2" and lookup_unit(s).factor == 1.0
    assert lookup_unit("g").factor == 9.80665
    with pytest.raises(RecordingError, match="unknown unit 'furlong'"):
        lookup_unit("furlong")
    with pytest.raises(RecordingError, match="ambiguous"):
        lookup_unit("mPa")
    s = parse_sensitivity("9.91mV/g")
    assert s.volts_per_si == pytest.approx(9.91e-3 / 9.80665)
    assert parse_sensitivity("100 mV/(m/s2)").volts_per_si == pytest.approx(0.1)
    for bad in ("9.91", "9.91 g/g", "-1 mV/g", "abc mV/g"):
        with pytest.raises(RecordingError):
            parse_sensitivity(bad)


def test_optional_engines_listed():
    eng = list_engines()
    assert {"uff58", "testlab_mat", "testlab_text", "csv", "wav", "cwru", "ims", "mfpt", "tdms",
            "mdf", "netcdf"} <= set(eng)


def test_tdms_mdf_missing_library_is_clear(write, monkeypatch):
    from bearing_lab.io import ENGINES
    for name, head in (("tdms", b"TDSm" + bytes(40)), ("mdf", b"MDF     4.10    " + bytes(40))):
        monkeypatch.setattr(ENGINES[name], "libraries", ("surely_not_installed_lib",))
        p = write(f"x.{name}", head)
        with pytest.raises(RecordingError, match=f"x.{name}: the '{name}' reader needs the optional "
                                                 "package"):
            open_recording(p)


def test_cli_import_info(datafile, tmp_path, capsys):
    src = datafile("lms/binary8byte_g.uff")
    out = tmp_path / "o.nc"
    assert main(["import", str(src), "-o", str(out)]) == 0
    assert "1 channel(s) sine_5_Hz, 250 samples at 100 Hz" in capsys.readouterr().out
    ds = xr.load_dataset(out)
    assert ds["sine_5_Hz"].attrs["units"] == "m s-2"
    assert main(["info", str(out), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["sampling_rate_hz"] == 100.0 and d["channels"]["sine_5_Hz"]["original_units"] == "g"
    assert main(["info", str(src)]) == 0
    assert "sine_5_Hz" in capsys.readouterr().out


def test_cli_sensitivity(write, tmp_path, sine):
    from bearing_lab.io._testing import uff58_block
    p = write("v.uff", uff58_block(sine, unit="mV", spec=1))
    out = tmp_path / "v.nc"
    assert main(["import", str(p), "--sensitivity", "9.91mV/g", "-o", str(out)]) == 0
    ds = xr.load_dataset(out)
    np.testing.assert_allclose(ds["acc"].values, sine * 1e-3 / 9.91e-3 * 9.80665, rtol=1e-9)


def test_cli_errors_exit_2_one_line(datafile, tmp_path, capsys):
    rc = main(["import", str(datafile("lms/testlab_geometry_only.uff")), "-o", str(tmp_path / "x.nc")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "\n" not in err and "testlab_geometry_only.uff" in err
    rc = main(["info", str(tmp_path / "missing.uff")])
    assert rc == 2 and "file not found" in capsys.readouterr().err
    rc = main(["info", str(datafile("lms/binary8byte_g.uff")), "--record", "3"])
    assert rc == 2 and "--record" in capsys.readouterr().err


def test_cli_data(datafile, mirror, tmp_path, capsys):
    datafile("mfpt/InnerRaceFault_vload_1.mat")
    assert main(["data", "fetch", "mfpt/InnerRaceFault_vload_1.mat", "--mirror", str(mirror),
                 "--dest", str(tmp_path), "--no-download"]) == 0
    assert (tmp_path / "mfpt/InnerRaceFault_vload_1.mat").is_file()
    assert main(["data", "list", "--dataset", "cwru-de"]) == 0
    assert "130_OR007@6_0.mat" in capsys.readouterr().out
    assert main(["data", "fetch", "nothing.mat", "--no-download"]) == 2


def test_import_output_checked_before_reading(tmp_path, capsys, datafile):
    from bearing_lab.cli import main
    src = datafile("lms/binary8byte_g.uff")
    assert main(["import", str(src), "-o", str(tmp_path / "out.txt")]) == 2
    assert main(["import", str(src), "-o", str(tmp_path / "no" / "out.nc")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "must be a netCDF file" in err[0] and "does not exist" in err[1]
