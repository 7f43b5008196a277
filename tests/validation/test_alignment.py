"""The waveform figure's alignment: the simulated impacts are put on the recording's over the whole
train, not on one detected impact (a filter transient at the record's start is the largest envelope
value of a real recording more often than not)."""
import numpy as np

from bearing_lab.compare import align_by_impulse_phase


def _train(n, fs, period, phase, rng, jitter=0.0, f_res=3000.0):
    x = 0.02 * rng.standard_normal(n)
    t = np.arange(n) / fs
    for t0 in np.arange(phase, n / fs, period):
        t0 += jitter * rng.standard_normal()
        tau = t - t0
        on = tau >= 0
        x[on] += np.exp(-800 * tau[on]) * np.sin(2 * np.pi * f_res * tau[on])
    return x


def test_shift_puts_the_train_on_the_recordings_despite_a_start_transient_and_jitter():
    fs, period, n = 12000.0, 1 / 107.3, 12000
    rng = np.random.default_rng(3)
    exp = _train(n, fs, period, 0.66 * period, rng, jitter=4e-4)
    exp[:6] += 8.0 * np.array([1, -1, 1, -1, 1, -1])    # a start transient larger than any impact
    sim = _train(n, fs, period, 0.05 * period, rng)
    k = align_by_impulse_phase(exp, sim, fs, period, band=(2000.0, 4000.0))
    want = (0.66 - 0.05) * period * fs
    assert abs(k - want) < 0.05 * period * fs, (k, want)


def test_a_wrong_phase_is_not_aligned():
    """The same trains a quarter period apart are found a quarter period apart (the check can fail)."""
    fs, period, n = 12000.0, 1 / 107.3, 12000
    rng = np.random.default_rng(4)
    exp = _train(n, fs, period, 0.30 * period, rng)
    sim = _train(n, fs, period, 0.05 * period, rng)
    k = align_by_impulse_phase(exp, sim, fs, period, band=(2000.0, 4000.0))
    assert abs(k - 0.25 * period * fs) < 0.03 * period * fs
