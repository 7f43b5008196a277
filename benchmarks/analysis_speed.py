"""Speed of the full analysis pipeline beside a straightforward scipy-only pipeline.

Both pipelines get the same signal: 10 s at 20 kHz of outer-race impacts of a
6308 at 1800 r/min (BPFO 92.16 Hz) ringing a 3 kHz mode, shaft harmonics and
white noise.  Both do the same four jobs: band selection by spectral kurtosis
over the same 1/3-binary tree of bands (at least as wide as the highest line
searched), squared envelope spectrum, fault-frequency search, metrics.

- bearing_lab: :func:`bearing_lab.analysis.analyze` (shaft-speed estimate
  included), i.e. an FFT-domain filter bank for the kurtogram.
- scipy-only: for every band a 4th-order Butterworth ``sosfiltfilt`` and
  ``hilbert`` then ``scipy.stats.kurtosis``; the SES of the best band by
  ``hilbert`` + ``rfft``; the largest SES bin within +-2 % of each fault
  frequency; metrics with numpy/scipy.stats.  The shaft speed is given.

Run: ``.venv/bin/python benchmarks/analysis_speed.py`` (prints a Markdown table;
``--repeat N`` sets the runs per pipeline, the best and the median are shown;
``--seconds S`` the record's length, 10 by default).  Times are CPU seconds of the
process (``time.process_time``), so other jobs on a shared machine do not count.
A second table gives ``analyze`` alone in its three speed modes: a stored or given
speed as a prior (``rpm``, as above), the shaft frequency given (``shaft_hz``), and
no speed at all (blind).
Threads are limited to one (OMP/MKL/OpenBLAS) before numpy is imported.
That a faster tree gives the same results: ``benchmarks/analysis_fingerprint.py`` (``dump`` with
each tree, then ``compare``).
"""
from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
import scipy  # noqa: E402
import scipy.fft  # noqa: E402
import scipy.signal as sig  # noqa: E402
import scipy.stats  # noqa: E402

FS = 20000.0
SECONDS = 10.0
FR = 30.0


def make_signal(seed=0):
    from bearing_lab import get_bearing
    rng = np.random.default_rng(seed)
    n = int(FS * SECONDS)
    t = np.arange(n) / FS
    bpfo = get_bearing("6308").fault_frequencies(FR)["bpfo"]
    tau = t % (1 / bpfo)
    x = np.exp(-1500 * tau) * np.sin(2 * np.pi * 3000 * tau)
    x += 0.2 * sum(np.cos(2 * np.pi * h * FR * t + h) / h for h in range(1, 10))
    x += rng.normal(0, 0.5, n)
    return x


def scipy_pipeline(x, fs, shaft_hz, bearing="6308", n_harmonics=5, tol=0.02):
    from bearing_lab import get_bearing
    ff = get_bearing(bearing).fault_frequencies(shaft_hz)
    top = n_harmonics * max(ff["bpfi"], 2 * ff["bsf"]) * (1 + tol) + shaft_hz
    # kurtogram, the straightforward way: filter bank in the time domain
    best = (-np.inf, None)
    layout = [(1,), (2,)] + [(n,) for k in range(1, 12) for n in (3 * 2 ** (k - 1), 2 ** (k + 1))]
    for (nb,) in layout:
        bw = fs / 2 / nb
        if bw < top and nb > 1:
            break
        for i in range(nb):
            lo, hi = i * bw, (i + 1) * bw
            if lo <= 0:
                sos = sig.butter(4, min(hi, 0.999 * fs / 2), "lowpass", fs=fs, output="sos")
            elif hi >= fs / 2:
                sos = sig.butter(4, lo, "highpass", fs=fs, output="sos")
            else:
                sos = sig.butter(4, [lo, hi], "bandpass", fs=fs, output="sos")
            y = sig.sosfiltfilt(sos, x)
            env = np.abs(sig.hilbert(y)) ** 2
            k = scipy.stats.kurtosis(np.sqrt(env), fisher=False)
            if k > best[0]:
                best = (k, sos)
    y = sig.sosfiltfilt(best[1], x)
    se = np.abs(sig.hilbert(y)) ** 2
    spec = np.abs(scipy.fft.rfft((se - se.mean()) * sig.get_window("hann", se.size))) * 2 / se.size
    f = np.fft.rfftfreq(se.size, 1 / fs)
    found = {}
    for key, fe in ff.items():
        m = np.abs(f - fe) <= max(tol * fe, f[1])      # at least the nearest bin on a short record
        found[key] = float(f[m][np.argmax(spec[m])])
    metrics = {"rms": np.sqrt(np.mean(x ** 2)), "kurtosis": scipy.stats.kurtosis(x, fisher=False),
               "peak": np.max(np.abs(x)), "crest_factor": np.max(np.abs(x)) / np.sqrt(np.mean(x ** 2))}
    return found, metrics


def timeit(fn, repeat):
    fn()  # warm-up (imports, FFT plans)
    ts = []
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        ts.append(time.process_time() - t0)
    return min(ts), float(np.median(ts))


def speed_modes(x, repeat):
    """``analyze`` with the speed as a prior, given exactly, and unknown: CPU s and verdict."""
    from bearing_lab.analysis import analyze
    print(f"\n| analyze on {SECONDS:g} s | best of {repeat} (CPU s) | median | speed | diagnosis (verdict) |")
    print("|---|---|---|---|---|")
    for label, kw in (("rpm=1800 (prior)", {"rpm": 60 * FR}), ("shaft_hz=30 (given)", {"shaft_hz": FR}),
                      ("blind (no speed)", {})):
        r = analyze(x, FS, bearing="6308", **kw)
        best, med = timeit(lambda: analyze(x, FS, bearing="6308", **kw), repeat)
        print(f"| {label} | {best:.3f} | {med:.3f} | {r['speed']['status']} | {r['diagnosis']} ({r['verdict']}) |")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--seconds", type=float, default=SECONDS, help="record length, s (default 10)")
    args = ap.parse_args(argv)
    globals()["SECONDS"] = args.seconds
    from bearing_lab.analysis import analyze
    x = make_signal()
    r = analyze(x, FS, bearing="6308", rpm=60 * FR)
    found, _ = scipy_pipeline(x, FS, FR)
    b_best, b_med = timeit(lambda: analyze(x, FS, bearing="6308", rpm=60 * FR), args.repeat)
    s_best, s_med = timeit(lambda: scipy_pipeline(x, FS, FR), args.repeat)
    print(f"signal: {SECONDS:g} s at {FS:g} Hz ({x.size} samples); one thread; "
          f"{platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"numpy {np.__version__}, scipy {scipy.__version__}\n")
    print("| pipeline | best of {0} (CPU s) | median (CPU s) | diagnosis / BPFO found |".format(args.repeat))
    print("|---|---|---|---|")
    bpfo = r["fault_frequencies"]["bpfo"]["measured_hz"]
    print(f"| bearing_lab analyze (kurtogram + SES + speed + fault search + metrics) | {b_best:.3f} | "
          f"{b_med:.3f} | {r['diagnosis']} ({r['verdict']}), "
          f"{'-' if bpfo is None else f'{bpfo:.3f}'} Hz |")
    print(f"| scipy-only (Butterworth filter-bank kurtogram + hilbert SES + argmax + metrics) | "
          f"{s_best:.3f} | {s_med:.3f} | -, {found['bpfo']:.3f} Hz |")
    print(f"\nspeed-up: {s_med / b_med:.1f}x (median); target for analyze: < 0.5 s")
    speed_modes(x, args.repeat)


if __name__ == "__main__":
    main()
