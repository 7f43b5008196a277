"""The CWRU cases end to end on the real recordings: kinematics within 1 %, the rig's path identified once on
record 130 and held fixed for 144, 234 and the inner-race record 105, and the failures the model cannot avoid told
apart.

The reports read are those of the run's validation of the default set (tests/conftest.py: ``bearing-lab validate
-o reports`` as the README tour types it, in its order: cwru-105 asks for record 130's path before 130's own case
runs, and the path must be the one 130's report shows)."""
import json

import numpy as np
import pytest

pytestmark = [pytest.mark.data, pytest.mark.xdist_group("validation_cwru")]

CASES = ("cwru-105", "cwru-130", "cwru-144", "cwru-234")


@pytest.fixture(scope="module")
def cwru(datafile, default_validation):
    for f in ("130_OR007@6_0.mat", "144_OR007@3_0.mat", "234_OR021@6_0.mat", "105_IR007_0.mat", "97_Normal_0.mat"):
        datafile(f"cwru/{f}")
    out = default_validation.reports
    sums = {name: json.loads((out / name / "summary.json").read_text()) for name in CASES}
    # the exit status of a run of these four cases alone (runner.exit_status): 1 when one errors or has a row that
    # fails unexplained
    status = int(any(s["verdict"] in ("error", "fail") for s in sums.values()))
    return out, CASES, status, sums


def _rows(s):
    return {r["quantity"]: r for r in s["rows"]}


def test_kinematics_within_1_percent_and_the_contract_files(cwru):
    out, _, status, sums = cwru
    assert status == 0 and {s["status"] for s in sums.values()} <= {"pass", "fail"}
    for name, s in sums.items():
        rows = _rows(s)
        fault, lo, hi = ("bpfi", 161.0, 162.6) if name == "cwru-105" else ("bpfo", 107.0, 108.2)
        for q in (fault, "excitation_period"):
            assert rows[q]["tolerance_pct"] == 1.0 and rows[q]["pass"], (name, rows[q])
        assert lo < rows[fault]["experiment"] < hi
        for r in s["rows"]:
            assert {"quantity", "simulation", "experiment", "difference_pct", "tolerance_pct", "pass"} <= set(r)
        assert "stored in the recording" in s["speed"]["source"]
        for f in ("index.html", "comparison.nc", "summary.json"):
            assert (out / name / f).is_file()


def test_outer_race_records_show_no_bpfi_family_on_either_side(cwru):
    """The outer-race recordings hold a single rig line near BPFI, no family; the model shows none either: the
    row agrees on the absence, on any machine (the line search names no frequency below its detection rule)."""
    _, _, _, sums = cwru
    for name in ("cwru-130", "cwru-144", "cwru-234"):
        r = _rows(sums[name])["bpfi"]
        assert r["simulation"] is None and r["experiment"] is None, (name, r)
        assert r["pass"] and "absence" in r["note"] and "below the detection rule" in r["note"]
    # the inner-race record shows the family on both sides, within the kinematic 1 %
    r = _rows(sums["cwru-105"])["bpfi"]
    assert r["pass"] and r["simulation"] is not None and r["experiment"] is not None


def test_the_path_is_identified_once_on_130_and_held_fixed(cwru):
    _, _, _, sums = cwru
    p130 = sums["cwru-130"]["structural_path"]
    assert p130["status"] == "ok" and p130["fit"]["residual_db"] < p130["fit"]["initial_db"]
    assert 1000 <= p130["resonances"][0]["frequency_hz"] <= 5400
    for name in ("cwru-144", "cwru-234", "cwru-105"):
        p = sums[name]["structural_path"]
        assert "cwru-130" in p["source"]
        assert p["resonances"] == p130["resonances"] and p["gain"] == p130["gain"]
        # amplitudes through a path fitted elsewhere are independent evidence
        assert all(r["independent"] for r in sums[name]["rows"] if not r["quantity"].startswith("healthy"))
    # on 130 itself, the amplitudes the fit used are marked as not independent
    assert not _rows(sums["cwru-130"])["peak"]["independent"]


def test_the_impulse_strength_ratio_fails_as_a_known_limitation(cwru):
    _, _, _, sums = cwru
    r = _rows(sums["cwru-130"])["impulse_strength_ratio"]
    assert r["rule"] == "factor" and not r["pass"] and r["status"] == "known limitation"
    assert r["simulation"] > 100 and 0.5 < r["experiment"] < 2.5
    assert "impulse_strength_ratio" in sums["cwru-130"]["known_limitations"]


def test_the_load_zone_limitation_of_the_3_oclock_pit(cwru):
    _, _, _, sums = cwru
    rows = _rows(sums["cwru-144"])
    for q in ("rms", "impulse_strength"):
        assert not rows[q]["pass"] and rows[q]["status"] == "known limitation"


def test_background_healthy_reference_and_report(cwru):
    out, _, _, sums = cwru
    s = sums["cwru-130"]
    assert "97_Normal_0.mat" in s["background"]["source"]
    assert any(abs(t["frequency_hz"] - 161.7) < 0.5 for t in s["background"]["tones"])  # the rig's line
    dec = {d["signal"]: d for d in s["healthy"]["decomposition"]}
    assert dec["bearing model alone"]["share of the recording's RMS (%)"] < 5
    assert _rows(s)["healthy: shaft_hz"]["pass"]
    from bearing_lab.compare import ComparisonResult
    res = ComparisonResult.load(out / "cwru-130" / "comparison.nc")
    assert list(res.dataset["signal"].values) == ["experiment", "model", "path", "path+background"]
    assert res.dataset.sizes["time"] == 12000
    assert np.isfinite(res.dataset["waveform"].sel(signal="experiment").values).all()
    prov = json.loads(res.dataset.attrs["provenance"])
    assert prov["recording sha256"] == "35a095307d0971477049b343a1b5981dde465a58fb7f233ad89b035068c1717d"
    html = (out / "cwru-130" / "index.html").read_text()
    for part in ("Structural path", "Background model", "known limitation", "How to cite", "130_OR007@6_0.mat"):
        assert part in html, part
    index = (out / "index.html").read_text()
    assert 'href="cwru-144/index.html"' in index


BPFO_ORDER, BPFI_ORDER = 3.5848, 5.4152          # 6205 drive end: fault frequency / shaft frequency


def _record(path):
    import scipy.io
    m = scipy.io.loadmat(str(path))
    return m[next(k for k in m if k.endswith("_DE_time"))].ravel() * 9.80665


def _peaks_by_shaft_angle(x, rpm, order=BPFO_ORDER, bins=8, fs=12000.0):
    """Mean impact peak (2.5-4 kHz band envelope, one per fault period) in ``bins`` shaft-angle bins, and the
    squared-envelope line at the shaft frequency relative to the fault line."""
    import scipy.signal as ss
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    fr = rpm / 60.0
    env = np.abs(ss.hilbert(ss.sosfiltfilt(ss.butter(4, [2500, 4000], "bandpass", fs=fs, output="sos"), x)))
    per = fs / (order * fr)                                    # fault period in samples
    starts = (np.arange(int(x.size // per) - 1) * per).astype(int)
    idx = np.array([s + np.argmax(env[s:s + int(per)]) for s in starts])
    b = np.floor((idx / fs * fr) % 1.0 * bins).astype(int)
    e2 = env ** 2 - np.mean(env ** 2)
    spec, f = np.abs(np.fft.rfft(e2 * np.hanning(e2.size))), np.fft.rfftfreq(e2.size, 1 / fs)

    def line(f0):
        return spec[(f > f0 - 1.0) & (f < f0 + 1.0)].max()
    return np.array([env[idx][b == k].mean() for k in range(bins)]), line(fr) / line(order * fr)


def _impact_peaks_by_shaft_angle(path, rpm, bins=8):
    """Mean impact peak (2.5-4 kHz band envelope, one per BPFO period) in ``bins`` shaft-angle bins of a record."""
    return _peaks_by_shaft_angle(_record(path), rpm, BPFO_ORDER, bins)[0]


def test_the_021_pit_amplitudes_fail_as_a_known_limitation_whose_evidence_holds(cwru, datafile):
    _, _, _, sums = cwru
    s234, s130 = sums["cwru-234"], sums["cwru-130"]
    rows, rows130 = _rows(s234), _rows(s130)
    for q in ("rms", "peak", "impulse_strength"):
        assert not rows[q]["pass"] and rows[q]["status"] == "known limitation", rows[q]
        assert q in s234["known_limitations"]
    assert not s234["unexplained_failures"]
    # the stated reason, model side: through the same fixed path the model's 0.021 in pit gives several times
    # the 0.007 in pit's RMS and peak, while the rig's two records are within a factor 2 of each other
    for q in ("rms", "peak"):
        assert rows[q]["simulation"] / rows130[q]["simulation"] > 4
        assert 0.5 < rows[q]["experiment"] / rows130[q]["experiment"] < 2
    # rig side, straight from the recordings: the 234 impacts change strongly with the shaft angle, 130's much less
    mod234 = _impact_peaks_by_shaft_angle(datafile("cwru/234_OR021@6_0.mat"), 1796.0)
    mod130 = _impact_peaks_by_shaft_angle(datafile("cwru/130_OR007@6_0.mat"), 1796.0)
    assert mod234.max() / mod234.min() > 4 and mod130.max() / mod130.min() < 3, (mod234, mod130)


def _energy_outside_impacts(x, fs, period_s):
    """RMS of ``x`` outside -1..+2 ms of each period's largest sample, and the share of the energy inside."""
    x = np.asarray(x, float)
    x = x[np.isfinite(x)] - np.nanmean(x)
    n, pre, post = int(period_s * fs), int(0.001 * fs), int(0.002 * fs)
    inside, outside, n_out = 0.0, 0.0, 0
    for i in range(1, x.size // n - 1):
        j = i * n + int(np.argmax(np.abs(x[i * n:(i + 1) * n])))
        seg, core = x[j - n // 2: j + n // 2], x[j - pre: j + post]
        inside += float(np.sum(core ** 2))
        outside += float(np.sum(seg ** 2) - np.sum(core ** 2))
        n_out += seg.size - core.size
    return float(np.sqrt(outside / n_out)), inside / (inside + outside)


def test_the_130_kurtosis_passes_with_a_path_that_rings_on_as_the_rig_does(cwru):
    """The path fitted with the recording's background held apart rings on between the impacts as the rig does, and
    the kurtosis, which counts that ringing, passes."""
    import xarray as xr
    out, _, _, sums = cwru
    row = _rows(sums["cwru-130"])["kurtosis"]
    assert row["pass"] and row["status"] == "pass", row
    ds = xr.open_dataset(out / "cwru-130" / "comparison.nc")
    fs, period = float(ds.attrs["sampling_rate_hz"]), 1.0 / float(ds.attrs["bpfo_hz"])
    rms_rec, share_rec = _energy_outside_impacts(ds["waveform"].sel(signal="experiment").values, fs, period)
    rms_sim, share_sim = _energy_outside_impacts(ds["waveform"].sel(signal="path+background").values, fs, period)
    assert rms_sim > 0.5 * rms_rec and share_sim < share_rec + 0.05, (rms_rec, rms_sim, share_rec, share_sim)
    res = json.loads(ds.attrs["structural_path"])["resonances"]
    assert len(res) == 1 and 1.0 / (res[0]["damping_ratio"] * 2 * np.pi * res[0]["frequency_hz"]) > 0.001


def _period_peaks(x, fs, period):
    """The largest 2.5-4 kHz band envelope value in each fault period."""
    import scipy.signal as ss
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    env = np.abs(ss.hilbert(ss.sosfiltfilt(ss.butter(4, [2500, 4000], "bandpass", fs=fs, output="sos"), x)))
    n = int(period * fs)
    return np.array([env[i * n:(i + 1) * n].max() for i in range(x.size // n)]), x - x.mean(), n


def _equalized_shape(x, fs, period):
    """Crest factor and kurtosis of ``x`` with every fault period scaled to the median impact peak."""
    peaks, y, n = _period_peaks(x, fs, period)
    y = np.concatenate([y[i * n:(i + 1) * n] * np.median(peaks) / p for i, p in enumerate(peaks)])
    return float(np.abs(y).max() / y.std()), float(np.mean(y ** 4) / np.mean(y ** 2) ** 2)


def test_the_234_shape_rows_fail_as_a_known_limitation_whose_evidence_holds(cwru):
    """The stated reason: the record's impacts vary many-fold from one period to the next, the model's do not; with the
    record's periods brought to one impact peak its crest factor and kurtosis come within the tolerance."""
    import xarray as xr
    out, _, _, sums = cwru
    rows = _rows(sums["cwru-234"])
    for q in ("crest_factor", "kurtosis"):
        assert not rows[q]["pass"] and rows[q]["status"] == "known limitation", rows[q]
        assert rows[q]["simulation"] < rows[q]["experiment"]
    ds = xr.open_dataset(out / "cwru-234" / "comparison.nc")
    fs, period = float(ds.attrs["sampling_rate_hz"]), 1.0 / float(ds.attrs["bpfo_hz"])
    rec, sim = ds["waveform"].sel(signal="experiment").values, ds["waveform"].sel(signal="path+background").values
    p_rec, p_sim = _period_peaks(rec, fs, period)[0], _period_peaks(sim, fs, period)[0]
    assert p_rec.max() / p_rec.min() > 10 and p_sim.max() / p_sim.min() < 1.2, (p_rec, p_sim)
    crest, kurt = _equalized_shape(rec, fs, period)
    assert 0.5 < rows["crest_factor"]["simulation"] / crest < 2 and 0.5 < rows["kurtosis"]["simulation"] / kurt < 2, \
        (crest, kurt)


def _detection_margin(x, fs, period, band="own"):
    """Median impulse peak over the impulse detector's threshold (4 x the median envelope in ``band``, "own": the
    signal's kurtogram band), the band, and the median impulse spacing."""
    from bearing_lab.analysis._impulse import DETECTION_FACTOR, impulses
    from bearing_lab.analysis._spectral import bandpass, fast_kurtogram, squared_envelope
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if isinstance(band, str):
        band = fast_kurtogram(x, fs, min_bandwidth=min(4 / period, 0.2 * fs)).band
    y = bandpass(x, fs, band=band) if band is not None else x - x.mean()
    thr = DETECTION_FACTOR * float(np.median(np.sqrt(squared_envelope(y, fs))))
    imp = impulses(x, fs, band=band, min_separation=0.5 * period)
    return float(np.median(imp.peak)) / thr, band, float(np.median(np.diff(imp.time)))


def test_the_inner_race_impulse_rows_fail_as_a_known_limitation_whose_evidence_holds(cwru, datafile):
    """The stated reason: the model's inner-race pit is loaded over part of each shaft turn, the rig's over all of it."""
    import xarray as xr
    out, _, _, sums = cwru
    s = sums["cwru-105"]
    rows = _rows(s)
    for q in ("shaft_hz", "bpfi", "excitation_period", "rms", "peak"):
        assert rows[q]["pass"], rows[q]
    for q in ("kurtosis", "impulse_strength", "impulse_duration"):
        assert not rows[q]["pass"] and rows[q]["status"] == "known limitation", rows[q]
    assert not s["unexplained_failures"]
    # the same energy, packed into part of the turn: peak and kurtosis above the record's, the median impact below
    assert rows["peak"]["simulation"] > 1.5 * rows["peak"]["experiment"]
    assert rows["kurtosis"]["simulation"] > 2 * rows["kurtosis"]["experiment"]
    assert rows["impulse_strength"]["simulation"] < 0.5 * rows["impulse_strength"]["experiment"]
    # rig side, the whole record: impacts at every shaft angle (as record 130's pit, which stays in the load zone),
    # a weak shaft line in the squared envelope
    rec, shaft_rec = _peaks_by_shaft_angle(_record(datafile("cwru/105_IR007_0.mat")), 1796.0, BPFI_ORDER)
    assert rec.max() / rec.min() < 3 and shaft_rec < 0.3, (rec, shaft_rec)
    # model side, after the fixed path: impacts over part of the turn only, a shaft line as strong as the BPFI line
    ds = xr.open_dataset(out / "cwru-105" / "comparison.nc")
    fs = float(ds.attrs["sampling_rate_hz"])
    sim, shaft_sim = _peaks_by_shaft_angle(ds["waveform"].sel(signal="path").values, 1796.0, BPFI_ORDER, fs=fs)
    assert np.sum(sim < 0.1 * sim.max()) >= 3 and shaft_sim > 0.8, (sim, shaft_sim)
    # the impulse duration, both in the record's band: the record's impulses barely clear the detector's threshold,
    # the model's clear it by far and ring from one load-zone impact into the next: one impulse a turn, longer than
    # a BPFI period
    period = 1.0 / float(ds.attrs["bpfi_hz"])
    m_rec, band, _ = _detection_margin(ds["waveform"].sel(signal="experiment").values, fs, period)
    m_sim, _, spacing = _detection_margin(ds["waveform"].sel(signal="path+background").values, fs, period, band)
    assert m_rec < 1.5 and m_sim > 3, (m_rec, m_sim)
    assert spacing > 3 * period and rows["impulse_duration"]["simulation"] > period, (spacing, period)
