"""Simulator physics against independent numbers (closed-form kinematics and Hertz theory after
Harris & Kotzalas, *Rolling Bearing Analysis*; the 6308 of Liu et al., Table 1).

Each test states what fixes the expected value; none compares with numbers the
simulator printed before.
"""
import math

import numpy as np
import pytest
import xarray as xr

from bearing_lab import get_bearing, simulate
from bearing_lab.io import to_netcdf
from bearing_lab.schema import check_dataset
from bearing_lab.sim.hertz import race_contact, series_stiffness
from tests.naive import impulse_times, interpolated_peak_frequency, static_ball_loads

BPFO_1800 = 92.158          # BPFO = Z f_r/2 (1 - D_b/d_m), 6308 at 1800 r/min, by hand
PERIOD_1800 = 0.0108509     # 1 / BPFO_1800


@pytest.fixture(scope="module")
def slot_half_second():
    return simulate("paper-slot", duration=0.5, progress=False)


def test_contract_and_attributes(slot_half_second):
    ds = slot_half_second
    check_dataset(ds, kind="simulation")
    assert ds.attrs["fidelity"] == "multibody"
    assert ds.attrs["defect_contact_models"] == "halfspace"
    assert ds.attrs["wall_time_s"] > 0 and ds.attrs["compile_time_s"] >= 0


def test_static_load_distribution_against_newton():
    """6308, 480 N on the inner ring, zero clearance, gravity off, cage creeping at 6 r/min:
    each ball's load against an independent Newton solve of the quasi-static equilibrium."""
    ds = simulate("paper-healthy", progress=False, duration=0.2, speed_rpm=6.0,
                  **{"load.on": "inner", "load.radial_n": 480.0, "gravity.enabled": False,
                     "output.settle_s": 0.03, "output.sample_rate_hz": 2000.0})
    b = get_bearing("6308")
    k_eff = series_stiffness(race_contact(b.ball_diameter, b.pitch_diameter, 0.52, "inner").stiffness,
                             race_contact(b.ball_diameter, b.pitch_diameter, 0.53, "outer").stiffness)
    t_abs = ds.attrs["settle_time_s"] + float(ds.time[-1])
    shaft_angle = 6.0 / 60 * 2 * math.pi * t_abs
    lz = math.radians(ds.attrs["load_zone_angle_deg"])
    angles = lz + b.frequency_factors()["ftf"] * shaft_angle + 2 * math.pi * np.arange(8) / 8
    force = 480.0 * np.array([0.0, -1.0])
    q_ref, _ = static_ball_loads(force, angles, k_eff)
    q_sim = ds.ball_load_inner.isel(time=-1).values
    q_out = ds.ball_load_outer.isel(time=-1).values
    loaded = q_ref > 0.02 * q_ref.max()
    np.testing.assert_allclose(q_sim[loaded], q_ref[loaded], rtol=0.02)
    np.testing.assert_allclose(q_out[loaded], q_ref[loaded], rtol=0.02)
    assert np.all(q_sim[~loaded] < 0.02 * q_ref.max())
    # the loads balance the applied load (the preloaded shaft spring, whose rest position is the
    # equilibrium at t = 0, takes the small change as the balls move: ~0.5 % here)
    u = np.stack([np.cos(angles), np.sin(angles)], 1)
    np.testing.assert_allclose(u.T @ q_sim, force, atol=0.01 * 480)
    # Stribeck: Q_max ~ 4.37 F_r / Z for zero clearance (infinitely many balls).  With Z = 8 and a
    # ball near the load line the exact factor is Z / sum(cos^2.5) = 4.35: within 2 % of 4.37.
    assert q_sim.max() == pytest.approx(4.37 * 480 / 8, rel=0.02)


def test_healthy_bpfo_line_10s():
    """Varying compliance: the outer-ring Y acceleration of a healthy bearing has a line at BPFO."""
    ds = simulate("paper-healthy", duration=10.0, progress=False)
    f = interpolated_peak_frequency(ds.outer_ring_acc_y.values, ds.attrs["sampling_rate_hz"], 80, 105)
    assert f == pytest.approx(BPFO_1800, rel=1e-3)


def test_slot_excitation_period(slot_half_second):
    ds = slot_half_second
    t = impulse_times(ds.outer_ring_acc_y.values, ds.attrs["sampling_rate_hz"], 0.5, dead_time=0.005)
    assert len(t) >= 40
    period = np.polyfit(np.arange(len(t)), t, 1)[0]
    assert period == pytest.approx(PERIOD_1800, rel=1e-3)


def test_slot_impulses_stronger_than_healthy(slot_half_second):
    healthy = simulate("paper-healthy", duration=0.2, progress=False)
    assert np.abs(slot_half_second.outer_ring_acc_y).max() > 20 * np.abs(healthy.outer_ring_acc_y).max()


def test_convergence_peak_acceleration():
    """Tightening the tolerance changes the paper-slot peak acceleration by < 1 %."""
    peaks = {}
    for rtol in (1e-4, 1e-5, 1e-6, 1e-7):
        ds = simulate("paper-slot", duration=0.1, rtol=rtol, progress=False)
        peaks[rtol] = float(np.abs(ds.outer_ring_acc_y).max())
    seq = ", ".join(f"rtol {k:g}: {v:.4f} m/s2" for k, v in peaks.items())
    ref = peaks[1e-7]
    assert abs(peaks[1e-5] - ref) / ref < 0.01, seq
    assert abs(peaks[1e-6] - ref) / ref < 0.01, seq
    # fixed-step RK4: halving the step converges to the same peak
    a = float(np.abs(simulate("paper-slot", duration=0.1, method="rk4", step=2e-6, progress=False)
                     .outer_ring_acc_y).max())
    b = float(np.abs(simulate("paper-slot", duration=0.1, method="rk4", step=1e-6, progress=False)
                     .outer_ring_acc_y).max())
    assert abs(a - b) / b < 0.01 and abs(b - ref) / ref < 0.01, (a, b, seq)


def test_deterministic_and_lossless_netcdf(tmp_path):
    a = simulate("paper-slot", duration=0.05, progress=False)
    b = simulate("paper-slot", duration=0.05, progress=False)
    for name in a.data_vars:
        assert np.array_equal(a[name].values, b[name].values), name
    p = to_netcdf(a, tmp_path / "s.nc")
    with xr.open_dataset(p) as back:
        for name in a.data_vars:
            assert np.array_equal(back[name].values, a[name].values), name
        assert back.attrs["scene_toml"] == a.attrs["scene_toml"]


def test_quasi_static_agrees_with_multibody_when_slow():
    """At low speed ball inertia is negligible: both fidelities give the same ring deflection."""
    kw = dict(duration=0.05, progress=False, speed_rpm=300.0)
    mb = simulate("paper-healthy", fidelity="multibody", **kw)
    qs = simulate("paper-healthy", fidelity="quasi-static", **kw)
    assert qs.attrs["fidelity"] == "quasi-static"
    rel = abs(float(mb.inner_ring_disp_y.mean() - mb.outer_ring_disp_y.mean())
              / float(qs.inner_ring_disp_y.mean() - qs.outer_ring_disp_y.mean()) - 1)
    assert rel < 0.01


def test_no_aliasing_of_ball_resonance():
    """The ball-race resonance (15-25 kHz) must not fold into the 20 kHz record: the spectrum above
    0.55 fs_out of a 160 kHz run, folded, must match what the 20 kHz record shows below Nyquist."""
    fine = simulate("paper-slot", duration=0.05, fs=160000.0, progress=False)
    coarse = simulate("paper-slot", duration=0.05, fs=20000.0, progress=False)
    xf = fine.outer_ring_acc_y.values
    xc = coarse.outer_ring_acc_y.values
    # energy below 9 kHz agrees; the coarse record holds no more energy than the band-limited fine one
    def band_energy(x, fs, lo, hi):
        s = np.abs(np.fft.rfft(x)) ** 2
        f = np.fft.rfftfreq(len(x), 1 / fs)
        return s[(f >= lo) & (f < hi)].sum() / len(x) ** 2
    e_f = band_energy(xf, 160000.0, 0, 9000)
    e_c = band_energy(xc, 20000.0, 0, 9000)
    assert e_c == pytest.approx(e_f, rel=0.05)


@pytest.mark.parametrize("fs_out,oversample", [(20000.0, 8), (12000.0, 4), (48000.0, 16), (25600.0, 6)])
def test_anti_alias_taps_are_scipys_kaiser_firwin(fs_out, oversample):
    """The numpy-written anti-alias filter is scipy.signal's kaiserord + firwin design."""
    from scipy import signal
    from bearing_lab.sim.integrate import anti_alias_taps
    fs_fine = fs_out * oversample
    numtaps, beta = signal.kaiserord(80.0, 0.1 * fs_out / (fs_fine / 2))
    ref = signal.firwin(numtaps | 1, fs_out / 2, window=("kaiser", beta), fs=fs_fine)
    taps = anti_alias_taps(fs_out, oversample)
    assert taps.shape == ref.shape
    np.testing.assert_allclose(taps, ref, rtol=0, atol=1e-15)


def test_streaming_output_equals_whole_record_and_scipy():
    """The chunked, streaming anti-alias stage gives what the whole-record pipeline gives, and
    an independent integrator (scipy's LSODA on the same right-hand side) lands on the same
    accelerometer signal."""
    from scipy.integrate import solve_ivp
    from bearing_lab.sim import _kernels as K, load_scene
    from bearing_lab.sim.assembly import assemble
    from bearing_lab.sim.integrate import METHODS, _decimate_acc, _run, anti_alias_taps
    sc = load_scene("paper-O1", fidelity="multibody", **{"defect.offset_mm": 0.5, "output.duration_s": 0.03})
    asm = assemble(sc)
    chunked = _run(asm, METHODS["dp54"], 1e-8, progress=False, max_step=2e-6, chunk_s=0.003)["acc"][:, 1]
    whole = _run(asm, METHODS["dp54"], 1e-8, progress=False, max_step=2e-6, chunk_s=1.0)["acc"][:, 1]
    # chunk boundaries restart the step sequence: differences at the solver tolerance only
    np.testing.assert_allclose(chunked, whole, atol=1e-4 * np.abs(whole).max())
    # scipy: same equations, its own stepping and dense output, our decimation on top
    taps = anti_alias_taps(sc.fs_out, 8)
    half = len(taps) // 2
    dt_f = 1 / (sc.fs_out * 8)
    n_out = len(whole)
    m_pad = half + 2
    fine_t = sc.settle - m_pad * dt_f + (np.arange(m_pad + (n_out - 1) * 8 + m_pad + 2) - 0.5) * dt_f
    model = asm.model
    fi, fo = np.empty(8), np.empty(8)

    def f(t, y):
        dy = np.empty_like(y)
        K.rhs(t, y, model, dy, fi, fo)
        return dy
    sol = solve_ivp(f, (0, fine_t[-1] + 1e-9), asm.y0.copy(), method="LSODA", rtol=1e-8,
                    atol=asm.atol_scale * 1e-8, max_step=2.5e-5, dense_output=True)
    v = sol.sol(fine_t)[[6, 7]].T
    ref = _decimate_acc(dict(fine_out=v, dt_f=dt_f, taps=taps, m_pad=m_pad, R=8, n_out=n_out))[:, 1]
    assert np.abs(whole).max() == pytest.approx(np.abs(ref).max(), rel=2e-3)
    assert np.abs(whole - ref).max() < 0.01 * np.abs(ref).max()
