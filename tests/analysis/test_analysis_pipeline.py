"""analyze(): the JSON layout of docs/analysis.md, plot, and the `bearing-lab analyze` command."""
import json

import numpy as np
import pytest
import xarray as xr

from bearing_lab.analysis import analyze, plot_analysis
from bearing_lab.cli import main
from bearing_lab.errors import AnalysisError

FAULT_KEYS = {"expected_hz", "measured_hz", "snr_db", "harmonics", "sidebands", "detected"}
METRIC_KEYS = {"rms", "peak", "peak_to_peak", "crest_factor", "kurtosis", "impulse_factor",
               "clearance_factor", "shape_factor"}
TOP_KEYS = {"channel", "sampling_rate_hz", "shaft_hz", "diagnosis", "fault_frequencies",
            "excitation_period_s", "metrics", "units", "speed_source", "speed", "verdict", "evidence"}


def _outer_race_signal(fs=12000.0, seconds=10.0, fr=1797 / 60, seed=0):
    t = np.arange(int(fs * seconds)) / fs
    tau = t % (1 / (3.5848 * fr))
    x = np.exp(-900 * tau) * np.sin(2 * np.pi * 3000 * tau)
    x = x + 0.3 * sum(np.cos(2 * np.pi * h * fr * t + h) / h for h in range(1, 12))
    return x + np.random.default_rng(seed).normal(0, 0.3, t.size), fs, fr


def check_schema(r):
    assert set(r) == TOP_KEYS
    assert set(r["fault_frequencies"]) == {"bpfo", "bpfi", "bsf", "ftf"}
    for v in r["fault_frequencies"].values():
        assert set(v) == FAULT_KEYS
        assert isinstance(v["expected_hz"], float) and isinstance(v["snr_db"], float)
        assert v["measured_hz"] is None or isinstance(v["measured_hz"], float)
        assert isinstance(v["harmonics"], int)
    assert set(r["metrics"]) == METRIC_KEYS
    assert all(isinstance(v, float) and np.isfinite(v) for v in r["metrics"].values())
    assert r["diagnosis"] in ("outer_race", "inner_race", "ball", "none", "uncertain")
    assert r["verdict"] in ("diagnosed", "uncertain", "no fault evidence")
    assert r["speed_source"] in ("given", "file", "tacho", "estimated", "unresolved")
    assert r["excitation_period_s"] is None or isinstance(r["excitation_period_s"], float)
    json.dumps(r, allow_nan=False)


def test_analyze_synthetic_outer_race_follows_contract():
    x, fs, fr = _outer_race_signal()
    r = analyze(x, fs, bearing="6205", channel="DE", units="m s-2")
    check_schema(r)
    assert r["diagnosis"] == "outer_race"
    assert r["shaft_hz"] == pytest.approx(fr, abs=2e-3)
    assert r["fault_frequencies"]["bpfo"]["measured_hz"] == pytest.approx(3.5848 * fr, rel=2e-3)
    assert r["excitation_period_s"] == pytest.approx(1 / (3.5848 * fr), rel=1e-5)
    assert r["channel"] == "DE" and r["units"] == "m s-2"


def test_analyze_refuses_bad_input():
    x, fs, _ = _outer_race_signal(seconds=2.0)
    with pytest.raises(AnalysisError, match="bearing"):
        analyze(x, fs, bearing="9999")
    with pytest.raises(AnalysisError, match="NaN"):
        analyze(np.r_[x, np.nan], fs, bearing="6205")
    with pytest.raises(AnalysisError, match="fs"):
        analyze(x, None, bearing="6205")
    with pytest.raises(AnalysisError, match="too low"):
        analyze(x, 1000.0, bearing="6205", shaft_hz=30.0)


def test_plot_writes_png(tmp_path):
    x, fs, _ = _outer_race_signal(seconds=3.0)
    fig, r = plot_analysis(x, fs, bearing="6205", rpm=1797, path=tmp_path / "a.png")
    assert (tmp_path / "a.png").stat().st_size > 10_000
    assert len(fig.axes) == 3
    assert "BPFO" in " ".join(t.get_text() for t in fig.axes[2].get_legend().get_texts())


def _nc(tmp_path, x, fs):
    t = np.arange(x.size) / fs
    ds = xr.Dataset({"acc": ("time", x, {"units": "m s-2"})},
                    coords={"time": ("time", t, {"units": "s"})},
                    attrs={"sampling_rate_hz": fs, "bearing_lab_version": "0.1.0", "bearing": "6205",
                           "shaft_speed_rpm": 1797.0})
    path = tmp_path / "sig.nc"
    ds.to_netcdf(path)
    return path


def test_cli_analyze_json_and_plot(tmp_path, capsys):
    x, fs, fr = _outer_race_signal()
    path = _nc(tmp_path, x, fs)
    png = tmp_path / "fig.png"
    assert main(["analyze", str(path), "--json", "--rpm", "file", "--plot", str(png)]) == 0
    r = json.loads(capsys.readouterr().out)
    check_schema(r)
    assert r["diagnosis"] == "outer_race" and r["channel"] == "acc"
    assert png.is_file()
    # an existing figure is kept unless --force, and refused before any work
    stamp = png.stat().st_mtime_ns
    assert main(["analyze", str(path), "--rpm", "file", "--plot", str(png)]) == 2
    assert "--plot" in capsys.readouterr().err and png.stat().st_mtime_ns == stamp
    assert main(["analyze", str(path), "--rpm", "file", "--plot", str(png), "--force", "-q"]) == 0
    assert png.stat().st_mtime_ns != stamp
    assert main(["analyze", str(path), "--plot", str(tmp_path / "fig.txt")]) == 2
    assert ".png" in capsys.readouterr().err
    assert main(["analyze", str(path), "--bearing", "6205"]) == 0
    out = capsys.readouterr().out
    assert "verdict: diagnosed  diagnosis: outer_race" in out and "BPFO" in out


def test_cli_analyze_bad_input_exits_2(tmp_path, capsys):
    x, fs, _ = _outer_race_signal(seconds=2.0)
    path = _nc(tmp_path, x, fs)
    assert main(["analyze", str(tmp_path / "missing.nc")]) == 2
    assert main(["analyze", str(path), "--channel", "nope"]) == 2
    err = capsys.readouterr().err
    assert "nope" in err and err.count("\n") == 2
    assert main(["analyze", str(path), "--rpm", "fast"]) == 2


@pytest.mark.data
def test_cli_analyze_real_recording(datafile, capsys):
    path = datafile("cwru/130_OR007@6_0.mat")
    assert main(["analyze", str(path), "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    check_schema(r)
    assert r["diagnosis"] == "outer_race" and r["verdict"] == "diagnosed"
    assert r["speed_source"] == "file" and r["speed"]["status"] == "confirmed"
    assert r["units"] == "m s-2"


@pytest.mark.data
def test_cli_fan_end_file_with_fs_channel_and_blind_speed(datafile, capsys):
    """A fan-end 6203 fault, channel FE, rate given (the file stores none), no speed."""
    path = datafile("cwru/12k_FE/OR007@6_0.mat")
    args = ["analyze", str(path), "--fs", "12000", "--channel", "FE", "--bearing", "6203", "--json"]
    assert main(args + ["--rpm", "none"]) == 0
    r = json.loads(capsys.readouterr().out)
    check_schema(r)
    assert r["channel"] == "FE" and r["sampling_rate_hz"] == 12000.0
    assert r["speed_source"] in ("estimated", "unresolved")
    assert r["diagnosis"] in ("outer_race", "uncertain")
    if r["speed_source"] == "estimated":
        assert r["shaft_hz"] == pytest.approx(1797 / 60, rel=0.005)
    assert main(args) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["speed_source"] == "file" and r["diagnosis"] == "outer_race"


def _cwru_like(tmp_path, x, record=999):
    """A CWRU-format file whose record the registry does not know: no rate anywhere."""
    import scipy.io as sio
    path = tmp_path / f"{record}_OR_unknown.mat"
    sio.savemat(path, {f"X{record}_DE_time": (x / 9.80665)[:, None], f"X{record}RPM": np.array([[1797]])})
    return path


def test_cli_fs_for_a_file_without_sampling_rate(tmp_path, capsys):
    x, fs, fr = _outer_race_signal(seconds=5.0)
    path = _cwru_like(tmp_path, x)
    assert main(["analyze", str(path), "--bearing", "6205"]) == 2
    err = capsys.readouterr().err
    assert "fs" in err and err.count("\n") == 1
    assert main(["analyze", str(path), "--fs", "12000", "--channel", "DE", "--bearing", "6205", "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["sampling_rate_hz"] == 12000.0 and r["diagnosis"] == "outer_race"
    assert r["speed_source"] == "file" and r["speed"]["prior_hz"] == pytest.approx(1797 / 60)


def test_cli_fs_overrides_the_rate_of_a_reader_without_an_fs_option(tmp_path, capsys):
    """netCDF files are read as they are (the reader takes no fs): --fs is applied after reading
    and the result says so; another reader's refusal is not taken for this one."""
    x, fs, fr = _outer_race_signal()
    path = _nc(tmp_path, x, fs)
    assert main(["analyze", str(path), "--fs", str(2 * fs), "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["sampling_rate_hz"] == 2 * fs
    assert r["notes"][0] == f"--fs {2 * fs:g} Hz overrides the file's {fs} Hz"


def test_cli_rpm_none_ignores_the_stored_speed(tmp_path, capsys):
    x, fs, fr = _outer_race_signal()
    path = _nc(tmp_path, x, fs)
    assert main(["analyze", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["speed_source"] == "file"
    assert main(["analyze", str(path), "--json", "--rpm", "none"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["speed_source"] in ("estimated", "unresolved") and r["speed"]["prior_hz"] is None
    assert main(["analyze", str(path), "--json", "--rpm", "1790"]) == 0
    assert json.loads(capsys.readouterr().out)["speed_source"] == "given"


def test_cli_uses_a_tacho_channel(tmp_path, capsys):
    x, fs, fr = _outer_race_signal()
    t = np.arange(x.size) / fs
    tacho = ((t * fr) % 1.0 < 0.05).astype(float)
    ds = xr.Dataset({"acc": ("time", x, {"units": "m s-2"}), "tacho": ("time", tacho, {"units": "V"})},
                    coords={"time": ("time", t, {"units": "s"})},
                    attrs={"sampling_rate_hz": fs, "bearing": "6205", "default_channel": "acc",
                           "bearing_lab_version": "0.1.0"})
    path = tmp_path / "with_tacho.nc"
    ds.to_netcdf(path)
    assert main(["analyze", str(path), "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["speed_source"] == "tacho" and r["shaft_hz"] == pytest.approx(fr, rel=2e-4)
    assert r["diagnosis"] == "outer_race"
    assert main(["analyze", str(path), "--json", "--tacho", "none", "--rpm", "none"]) == 0
    assert json.loads(capsys.readouterr().out)["speed_source"] != "tacho"
    assert main(["analyze", str(path)]) == 0
    out = capsys.readouterr().out
    assert "verdict: diagnosed" in out and "tacho channel tacho" in out


def _modulated_impacts(rate, mod_hz, fs=12000.0, seconds=10.0, seed=0):
    """Impacts at `rate` ringing 3 kHz, amplitude-modulated at `mod_hz` (load-zone passage)."""
    t = np.arange(int(fs * seconds)) / fs
    tau = t % (1 / rate)
    k = np.floor(t * rate) / rate  # impact instant of each sample's impulse
    amp = 1 + 0.8 * np.cos(2 * np.pi * mod_hz * k)
    x = amp * np.exp(-900 * tau) * np.sin(2 * np.pi * 3000 * tau)
    return x + np.random.default_rng(seed).normal(0, 0.3, t.size), fs


@pytest.mark.parametrize("kind, expected", [("bpfi", "inner_race"), ("bsf", "ball")])
def test_synthetic_inner_race_and_ball_faults(kind, expected):
    from bearing_lab import get_bearing
    fr = 29.95
    ff = get_bearing("6205").fault_frequencies(fr)
    rate, mod = (ff["bpfi"], fr) if kind == "bpfi" else (2 * ff["bsf"], ff["ftf"])
    x, fs = _modulated_impacts(rate, mod)
    r = analyze(x, fs, bearing="6205", shaft_hz=fr)
    assert r["diagnosis"] == expected
    measured = r["fault_frequencies"][kind]["measured_hz"] * (2 if kind == "bsf" else 1)
    assert measured == pytest.approx(rate, rel=2e-3)


def test_inner_race_shaft_sidebands_are_counted():
    from bearing_lab import get_bearing
    from bearing_lab.analysis import diagnose_ses, squared_envelope_spectrum
    fr = 29.95
    ff = get_bearing("6205").fault_frequencies(fr)
    x, fs = _modulated_impacts(ff["bpfi"], fr)
    f, ses = squared_envelope_spectrum(x, fs, window="hann", band=(2000, 4000), fmax=1000)
    diagnosis, lines = diagnose_ses(f, ses, ff, shaft_hz=fr)
    assert diagnosis == "inner_race"
    assert lines["bpfi"]["sidebands"] >= 4
    assert lines["bpfo"]["sidebands"] == 0  # only counted for the inner race
