"""compare.py: the resonator filter against the simulator, the calibration fit, the netCDF round trip."""
import numpy as np
import pytest

from bearing_lab.compare import (ComparisonResult, Tolerance, apply_sensor, calibrate_sensor, compare,
                                 impact_times, make_row, measure, sensor_response)


def test_sensor_response_limits():
    f = np.array([0.0, 3000.0, 60000.0])
    h = sensor_response(f, 3000.0, 0.05, 2.0)
    assert abs(h[0]) == pytest.approx(2.0)
    assert abs(h[1]) == pytest.approx(2.0 * np.sqrt(1 + 0.1 ** 2) / 0.1, rel=1e-9)
    assert abs(h[2]) < 0.1


@pytest.mark.slow
def test_offline_resonator_equals_the_simulated_sensor():
    """apply_sensor(sensor-off run) reproduces the simulator's [sensor] channel (same scene)."""
    import bearing_lab as bl
    kw = dict(duration=0.2, progress=False, **{"sensor.frequency_hz": 2800.0, "sensor.damping_ratio": 0.06,
                                                "sensor.gain": 3.0})
    off = bl.simulate("cwru-or007-6", **{**kw, "sensor.enabled": False})
    on = bl.simulate("cwru-or007-6", **{**kw, "sensor.enabled": True})
    fs = off.attrs["sampling_rate_hz"]
    y = apply_sensor(off["outer_ring_acc_y"].values, fs, 2800.0, 0.06, 3.0)
    ref = on["outer_ring_acc_y"].values
    sl = slice(int(0.02 * fs), None)  # the resonator's start-up transient differs (filter starts at rest)
    err = np.sqrt(np.mean((y[sl] - ref[sl]) ** 2)) / np.sqrt(np.mean(ref[sl] ** 2))
    assert err < 0.05, err


def _impacts(fs=12000.0, n=12000, period=1 / 107.3, seed=0):
    """Broadband impacts (a short 5.5 kHz burst each) with 0.5 % random timing jitter."""
    rng = np.random.default_rng(seed)
    x = np.zeros(n)
    t = 0.003
    k = np.arange(40)
    burst = np.exp(-k / 3.0) * np.sin(2 * np.pi * 5500 * k / fs)
    while t * fs + 40 < n:
        i = int(t * fs)
        x[i:i + 40] += burst * (1 + 0.1 * rng.standard_normal())
        t += period * (1 + 0.005 * rng.standard_normal())
    return x


def test_calibration_recovers_a_known_resonator():
    fs, period = 12000.0, 1 / 107.3
    raw = _impacts()
    measured = apply_sensor(_impacts(n=60000, seed=1), fs, 3100.0, 0.04, 25.0)
    measured += np.random.default_rng(2).normal(0, 0.02 * np.std(measured), measured.size)
    cal = calibrate_sensor(measured, raw, fs, period, frequency_bounds=(1000.0, 5400.0))
    assert cal.frequency_hz == pytest.approx(3100.0, rel=0.03)
    assert cal.damping_ratio == pytest.approx(0.04, rel=0.3)
    assert cal.gain == pytest.approx(25.0, rel=0.25)
    assert cal.fit_error_db < cal.initial_error_db
    assert cal.overrides()["sensor.enabled"] is True
    assert set(cal.as_dict()) >= {"frequency_hz", "damping_ratio", "gain", "fit_error_db"}


def test_impact_times_follow_a_jittered_train():
    fs, period = 12000.0, 1 / 107.3
    x = _impacts(n=24000)
    t = impact_times(x, fs, period)
    assert t.size >= 200
    assert np.median(np.diff(t)) == pytest.approx(period, rel=0.01)


def test_measure_finds_the_impact_rate():
    fs, period = 12000.0, 1 / 107.3
    x = _impacts(n=60000) + np.random.default_rng(3).normal(0, 0.05, 60000)
    m = measure(x, fs, bearing="6205", rpm=1796.0, fault="bpfo")
    assert m["excitation_period"] == pytest.approx(period, rel=0.01)
    assert m["bpfo"] == pytest.approx(107.3, rel=0.01)
    assert np.isnan(m["bpfi"]) and "bpfi" in m["extras"]["notes"]
    assert m["kurtosis"] > 3


def test_comparison_round_trip(tmp_path):
    fs = 12000.0
    x = _impacts(n=6000)
    rows = [make_row("bpfo", 107.2, 107.6, Tolerance("pct", 1.0, "because")),
            make_row("rms", float("nan"), 2.0, Tolerance("factor", 2.0, "because"), note="no line"),
            make_row("impulse_strength_ratio", 3.0, 1.2, Tolerance("ordering", None, "why"), units="1")]
    res = compare({"experiment": x, "simulation": np.roll(x, 5)}, fs, rows, band=(2000.0, 5000.0),
                  attrs={"case": "t", "bpfo_hz": 107.3, "calibration": {"gain": 2.0}})
    assert [r["pass"] for r in res.rows] == [True, False, True]
    assert not res.passed
    p = res.to_netcdf(tmp_path / "c.nc")
    back = ComparisonResult.load(p)
    assert back.rows[0]["quantity"] == "bpfo" and back.rows[0]["pass"] is True
    assert np.isnan(back.rows[1]["simulation"]) and back.rows[1]["note"] == "no line"
    assert back.rows[2]["tolerance_pct"] is None
    np.testing.assert_allclose(back.dataset["waveform"].values, res.dataset["waveform"].values)
    np.testing.assert_allclose(back.dataset["ses"].values, res.dataset["ses"].values)
    assert back.dataset.sizes["signal"] == 2
    assert back.dataset["frequency"].size == back.dataset["spectrum"].shape[1]
    # plots draw into given axes and return them
    from matplotlib.figure import Figure
    fig = Figure()
    axes = fig.subplots(3, 1)
    assert back.plot_waveforms(ax=axes[0]) is axes[0]
    assert back.plot_spectra(ax=axes[1]) is axes[1]
    assert back.plot_envelope(ax=axes[2], fmax=600) is axes[2]


def test_a_row_without_two_numbers_never_passes():
    """NaN against NaN counted as PASS ("agreement"): a row that measured nothing is a failure."""
    t = Tolerance("pct", 1.0, "r")
    nan = float("nan")
    row = make_row("bpfi", nan, nan, t)
    assert row["pass"] is False and "neither signal shows this line" in row["note"]
    assert not make_row("excitation_period", nan, nan, Tolerance("factor", 2.0, "r"))["pass"]
    assert not make_row("impulse_strength_ratio", nan, nan, Tolerance("ordering", None, "r"))["pass"]
    assert make_row("bpfi", 162.0, 161.7, t)["pass"]
    assert not make_row("bpfi", nan, 161.7, t)["pass"]
    assert not make_row("bpfi", 162.0, nan, t)["pass"]
    assert not make_row("rms", nan, nan, t)["pass"]  # not a line: a missing number fails
