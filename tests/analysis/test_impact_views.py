"""The structural-path fit's fast readings of a signal give what the plain definitions give.

The fit reads some 500 signals per identification; it cuts their impact windows from indices worked out once,
takes one Hilbert envelope from a real transform, and filters the simulation through a candidate path from its
transform taken once.  Each must give what the reference does: scipy's analytic signal, the window functions of
:mod:`bearing_lab.analysis.impacts`, a loop over the impacts, and :meth:`StructuralPath.apply`.
"""
import numpy as np
import pytest
from scipy.signal import hilbert

from bearing_lab.analysis import structural_path as sp
from bearing_lab.analysis._impact_views import (CENTROID_HALF_S, ImpactWindows, centred_times, frequency_runs,
                                                hilbert_envelope)
from bearing_lab.analysis.impacts import between_impacts, impact_peaks, mean_envelope, segment_spectrum

FS = 20000.0
PERIOD = 0.0109


def _train(n, seed=0, first=0.0004):
    """Decaying 4.3 kHz bursts every PERIOD (jittered) from ``first`` s, in white noise."""
    rng = np.random.default_rng(seed)
    x = 0.02 * rng.standard_normal(n) + 0.3
    k = np.arange(120)
    burst = np.exp(-k / 15.0) * np.sin(2 * np.pi * 4300.0 * k / FS)
    times, t = [], first
    while t * FS < n:
        i = int(t * FS)
        x[i:i + k.size] += (1 + 0.2 * rng.standard_normal()) * burst[: max(0, min(k.size, n - i))]
        times.append(t)
        t += PERIOD * (1 + 0.01 * rng.standard_normal())
    return x, np.asarray(times)


@pytest.mark.parametrize("n", [40000, 39999, 12007, 8, 7])
def test_hilbert_envelope_is_scipys(n):
    x = _train(n)[0] if n > 100 else np.random.default_rng(1).standard_normal(n)
    ref = np.abs(hilbert(x - np.mean(x)))
    assert np.allclose(hilbert_envelope(x), ref, rtol=1e-12, atol=1e-12 * ref.max())


def test_windows_read_what_the_impact_functions_read():
    """Impacts at both ends of the record: windows that do not fit are left out, peak spans are cut short."""
    x, times = _train(9000, first=0.0002)
    times = np.r_[times, 9000 / FS - 0.0001]
    pre, post = 0.5e-3, 0.6 * PERIOD
    win = ImpactWindows(x.size, FS, times, PERIOD, pre=pre, post=post)
    env = hilbert_envelope(x)
    for shift in (0, 3, -7):
        ref = mean_envelope(x, FS, times + shift / FS, pre=pre, post=post)
        assert np.allclose(win.mean_of(env, shift), ref, rtol=1e-12)
    f, ref = segment_spectrum(x, FS, times, pre=pre, post=post)
    assert np.allclose(win.power(x), ref, rtol=1e-12)
    assert np.allclose(np.sort(win.peaks(x)), np.sort(impact_peaks(x, FS, times, PERIOD)), rtol=1e-12)
    # bins of the spectrum, each a run of its frequencies, summed by one reduceat
    masks = [(f >= lo) & (f < hi) for lo, hi in ((300, 900), (900, 2000), (4000, 6000), (8000, FS / 2 + 1))]
    starts, sizes = frequency_runs(masks)
    got = np.add.reduceat(ref, starts)[::2] / sizes
    assert np.allclose(got, [ref[m].mean() for m in masks], rtol=1e-12)


def test_windows_none_fit():
    win = ImpactWindows(100, FS, [0.0001, 0.0049], PERIOD, pre=0.5e-3, post=0.6 * PERIOD)
    assert win.mean_of(np.ones(100)) is None and win.power(np.ones(100)) is None


def _centroids_loop(x, times):
    """The definition: the centroid of the envelope power above its mean between the impacts, within
    CENTROID_HALF_S of the time, three passes, one impact after another."""
    p = np.abs(hilbert(x - np.mean(x))) ** 2
    p = np.maximum(p - np.mean(p[between_impacts(p.size, FS, times, PERIOD)]), 0.0)
    half = int(round(CENTROID_HALF_S * FS))
    out = []
    for t in times:
        c = t * FS
        for _ in range(3):
            i0, i1 = max(0, int(round(c)) - half), min(p.size, int(round(c)) + half + 1)
            w = p[i0:i1]
            if i1 - i0 < 2 or not w.sum() > 0:
                break
            c = float(np.sum(np.arange(i0, i1) * w) / w.sum())
        out.append(c / FS)
    return np.asarray(out)


def test_centred_times_are_the_loops():
    x, times = _train(12000, first=0.0003)
    times = np.r_[times, 12000 / FS + 0.01]         # one beyond the record: kept as it is
    got = centred_times(x, FS, times, PERIOD)
    assert np.allclose(got, _centroids_loop(x, times), rtol=0, atol=1e-9 / FS)
    assert got[-1] == pytest.approx(times[-1], abs=1e-12)
    # a burst's centroid sits after its onset, near its energy's centre (~0.4 ms for this decay)
    assert np.all((got[1:-2] - times[1:-2] > 0.1e-3) & (got[1:-2] - times[1:-2] < 1.0e-3))


@pytest.mark.parametrize("n_res", [1, 2])
def test_the_fits_path_output_is_apply(n_res):
    x, _ = _train(20000, seed=3)
    rec = sp.StructuralPath((sp.Resonance(4300.0, 0.05),), 2.0).apply(x, FS)
    prob = sp._PathProblem(rec, x, FS, PERIOD, band=None, pre=0.5e-3, post=0.6 * PERIOD, n_resonances=n_res)
    for params in ([4300.0, 0.05, 1.0], [700.0, 0.006, 1.0], [9000.0, 0.45, 1.0]):
        if n_res == 2:
            params = [params[0], 2500.0, params[1], 0.1, 1.0, 0.4]
        x0 = np.log(params)
        ref = prob.path_of(x0).apply(prob.s, FS)
        assert np.allclose(prob.shape_output(x0), ref, rtol=0, atol=1e-11 * np.abs(ref).max())
