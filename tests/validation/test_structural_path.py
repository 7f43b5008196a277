"""The structural path: the filter against its closed form and the simulator, the fit recovers a known path,
and a degraded fit says so."""
import numpy as np
import pytest

from bearing_lab.analysis.structural_path import (Resonance, StructuralPath, fit_structural_path,
                                                  transmissibility)
from bearing_lab.errors import AnalysisError

FS, PERIOD = 12000.0, 1 / 107.3


def _impacts(n=12000, seed=0, fs=FS, period=PERIOD):
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


def _path(f=3100.0, z=0.04, g=25.0):
    return StructuralPath((Resonance(f, z),), g)


def test_transmissibility_closed_form():
    """Base-excited single-mode resonator: |T(0)| = 1, |T(f_n)| = sqrt(1 + (2 zeta)^2) / (2 zeta), T -> 0 far above."""
    f = np.array([0.0, 3000.0, 60000.0])
    h = transmissibility(f, 3000.0, 0.05)
    assert abs(h[0]) == pytest.approx(1.0)
    assert abs(h[1]) == pytest.approx(np.sqrt(1 + 0.1 ** 2) / 0.1, rel=1e-9)
    assert abs(h[2]) < 0.1
    p = StructuralPath((Resonance(3000.0, 0.05), Resonance(6000.0, 0.05)), 2.0)
    assert abs(p.response(np.array([0.0]))[0]) == pytest.approx(2.0)


@pytest.mark.slow
def test_the_path_filter_equals_the_simulated_sensor():
    """apply() on a sensor-off run reproduces the simulator's [sensor] channel (same scene)."""
    import bearing_lab as bl
    kw = dict(duration=0.2, progress=False, **{"sensor.frequency_hz": 2800.0, "sensor.damping_ratio": 0.06,
                                                "sensor.gain": 3.0})
    off = bl.simulate("cwru-or007-6", **{**kw, "sensor.enabled": False})
    on = bl.simulate("cwru-or007-6", **{**kw, "sensor.enabled": True})
    fs = off.attrs["sampling_rate_hz"]
    y = StructuralPath((Resonance(2800.0, 0.06),), 3.0).apply(off[off.attrs["default_channel"]].values, fs)
    ref = on[on.attrs["default_channel"]].values
    sl = slice(int(0.02 * fs), None)  # the resonator's start-up transient differs (filter starts at rest)
    err = np.sqrt(np.mean((y[sl] - ref[sl]) ** 2)) / np.sqrt(np.mean(ref[sl] ** 2))
    assert err < 0.05, err


def test_the_fit_recovers_a_known_path_and_reports_it():
    raw = _impacts()
    measured = _path().apply(_impacts(n=60000, seed=1), FS)
    measured += np.random.default_rng(2).normal(0, 0.02 * np.std(measured), measured.size)
    path = fit_structural_path(measured, raw, FS, PERIOD, frequency_bounds=(1000.0, 5400.0))
    r = path.resonances[0]
    assert r.frequency_hz == pytest.approx(3100.0, rel=0.03)
    assert r.damping_ratio == pytest.approx(0.04, rel=0.3)
    assert path.gain == pytest.approx(25.0, rel=0.25)
    assert path.status == "ok" and path.problems == []
    assert path.fit["residual_db"] < path.fit["initial_db"]
    assert path.fit["bounds"]["frequency_hz"] == (1000.0, 5400.0)        # the bounds as given
    assert path.scene_overrides()["sensor.frequency_hz"] == pytest.approx(r.frequency_hz)


def test_bounds_are_never_narrowed_silently_and_a_fit_at_a_bound_is_degraded():
    raw = _impacts()
    measured = _path().apply(_impacts(n=60000, seed=1), FS)
    # the true resonance (3.1 kHz) lies outside the given bounds: the fit must end at a bound and say so
    path = fit_structural_path(measured, raw, FS, PERIOD, frequency_bounds=(3500.0, 9000.0))
    assert path.status == "degraded"
    assert any("bound" in p and "frequency_hz" in p for p in path.problems)
    assert any("lowered to 0.45 fs" in n for n in path.fit["notes"])       # 9000 Hz > 0.45 fs: said, not hidden
    assert path.fit["bounds"]["frequency_hz"] == (3500.0, 0.45 * FS)


def test_a_fit_needs_impacts():
    with pytest.raises(AnalysisError, match="at least 5 impacts"):
        fit_structural_path(_impacts(n=400), _impacts(n=400), FS, PERIOD)
    with pytest.raises(AnalysisError, match="n_resonances"):
        fit_structural_path(_impacts(), _impacts(), FS, PERIOD, n_resonances=3)


@pytest.mark.parametrize("recording, simulation, fs, period, match", [
    (np.array([]), _impacts(), FS, PERIOD, "recording must be one non-empty signal"),
    (np.stack([_impacts(), _impacts()]), _impacts(), FS, PERIOD, r"shape \(2, 12000\)"),
    (np.zeros(12000), _impacts(), FS, PERIOD, "recording is zero throughout"),
    (_impacts(), np.zeros(12000), FS, PERIOD, "simulation is zero throughout"),
    (np.where(np.arange(12000) == 600, np.nan, _impacts()), _impacts(), FS, PERIOD, "1 non-finite samples .* 0.05 s"),
    (_impacts(), np.where(np.arange(12000) == 6, np.inf, _impacts()), FS, PERIOD, "simulation holds 1 non-finite"),
    (_impacts(), _impacts(), -FS, PERIOD, "sampling rate must be positive"),
    (_impacts(), _impacts(), FS, 0.0, "impact period must be positive"),
    (_impacts(), _impacts(), FS, 2.0, "shorter than the recording"),
])
def test_unreadable_signals_are_refused_by_name(recording, simulation, fs, period, match):
    """What the fit cannot read is named (signal, problem, where), not a scipy error from inside the search."""
    with pytest.raises(AnalysisError, match=match):
        fit_structural_path(recording, simulation, fs, period)


def test_two_resonances():
    raw = _impacts()
    true = StructuralPath((Resonance(2500.0, 0.03), Resonance(4500.0, 0.03, 0.7)), 10.0)
    measured = true.apply(_impacts(n=60000, seed=1), FS)
    path = fit_structural_path(measured, raw, FS, PERIOD, n_resonances=2, frequency_bounds=(1000.0, 5400.0))
    got = sorted(r.frequency_hz for r in path.resonances)
    assert got == pytest.approx([2500.0, 4500.0], rel=0.05)
    assert path.fit["residual_db"] < path.fit["initial_db"]


def test_save_load_round_trip_and_invalid_paths(tmp_path):
    p = StructuralPath((Resonance(4300.0, 0.05),), 0.9, "given", fit={"residual_db": 1.0, "problems": []})
    back = StructuralPath.load(p.save(tmp_path / "p.json"))
    assert back.resonances == p.resonances and back.gain == 0.9 and back.status == "ok"
    x = _impacts()
    np.testing.assert_allclose(back.apply(x, FS), p.apply(x, FS))
    for bad in ({"gain": -1.0}, {"gain": 1.0, "resonances": [{"frequency_hz": 1e3, "damping_ratio": 2.0}]},
                {"resonances": []}):
        with pytest.raises(AnalysisError, match="structural path"):
            StructuralPath.from_dict(bad)
    (tmp_path / "bad.json").write_text("{")
    with pytest.raises(AnalysisError, match="bad.json"):
        StructuralPath.load(tmp_path / "bad.json")


def test_the_fit_takes_a_recording_and_a_simulated_dataset():
    import xarray as xr

    def ds(x, fs=FS):
        return xr.Dataset({"acc": ("time", x)}, attrs={"sampling_rate_hz": fs, "default_channel": "acc"})
    measured = _path().apply(_impacts(n=60000, seed=1), FS)
    path = fit_structural_path(ds(measured), ds(_impacts()), None, PERIOD, frequency_bounds=(1000.0, 5400.0))
    assert path.resonances[0].frequency_hz == pytest.approx(3100.0, rel=0.03)
    with pytest.raises(AnalysisError, match="simulate at the recording's rate"):
        fit_structural_path(ds(measured), ds(_impacts(), fs=2 * FS), None, PERIOD)


def test_from_case_file_is_read_beside_the_case(tmp_path, monkeypatch):
    """A relative ``from_case`` file names a case beside the case file, wherever the user runs from."""
    from tests.validation._standins import case_text
    from bearing_lab.validation import rig
    from bearing_lab.validation.load import load_case
    rigdir, elsewhere = tmp_path / "rig", tmp_path / "elsewhere"
    rigdir.mkdir(), elsewhere.mkdir()
    (rigdir / "calib.toml").write_text(case_text("calib", "calib.uff", length_mm=3.0, width_mm=1.0))
    (rigdir / "run2.toml").write_text(case_text("run2", "run2.uff", length_mm=3.0, width_mm=1.0,
                                                path_from="calib.toml"))
    seen = []
    monkeypatch.setattr(rig, "identify_path",
                        lambda other, mirror=None: seen.append(other.name) or StructuralPath.identity())
    monkeypatch.chdir(elsewhere)
    path = rig.path_for(load_case(str(rigdir / "run2.toml")), None)
    assert seen == ["calib"] and "calib" in path.source
