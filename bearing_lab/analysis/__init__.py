"""Signal analysis: spectra, envelope analysis, shaft speed, fault frequencies,
excitation periods, impulses and metrics - one ruler for recordings and simulations.

Pure numpy functions (scipy.signal style: arrays in, tuples out, ``fs`` and
``axis`` keywords, windows passed explicitly); xarray wrappers of the same
names in :mod:`bearing_lab.analysis.xr`; ``da.bearing.<name>()`` accessor
registered on import.

Public API
----------
::

    amplitude_spectrum(x, fs, *, window, axis=-1)           -- (f, peak amplitude in U)
    welch_psd(x, fs, *, window, nperseg, noverlap, axis)    -- (f, PSD in U**2/Hz)
    cepstral_prewhitening(x, *, axis=-1)                    -- whitened signal (dimensionless)
    bandpass(x, fs, *, band, axis=-1)                       -- ideal FFT band-pass
    squared_envelope(x, fs, *, band, prewhiten, axis)       -- |analytic(x)|**2 in U**2
    squared_envelope_spectrum(x, fs, *, window, band, prewhiten, fmax, axis) -- (f, SES in U**2)
    fast_kurtogram(x, fs, *, nlevel, min_bandwidth, fmin)   -- Kurtogram: kurtosis per level and band, the best band
    envelope_band(x, fs, *, frequency_range, min_bandwidth) -- (band, score): band with the strongest SES line family
    interpolated_peak(X, k, *, method)                      -- fractional bin of a DFT line (Quinn, Jacobsen, Hann)
    shaft_frequency(x, fs, *, window, rpm, ...)             -- (shaft Hz, number of harmonics used): strongest 1x family
    shaft_speed(x, fs, *, bearing, rpm, rpm_source)         -- dict: speed checked against the bearing's fault combs
    tacho_pulses(tacho, fs)                                 -- pulse times of a once-per-rev signal, s
    tacho_speed(pulse_times, *, pulses_per_rev)             -- (mean shaft Hz, per-revolution Hz, variation)
    order_track(x, fs, pulse_times, *, pulses_per_rev)      -- (signal at constant shaft angle, mean shaft Hz)
    enhanced_envelope_spectrum(x, fs, *, alpha_max, nw)     -- (alpha, EES): cyclic spectral coherence averaged over f
    fault_line(f, ses, expected_hz, *, shaft_hz, tolerance, ...) -- dict: measured_hz, snr_db, harmonics, sidebands
    diagnose_ses(f, ses, fault_hz, *, shaft_hz, tolerance)  -- (diagnosis, families): the family rule on one SES
    coincidences(fault_hz, shaft_hz, df, *, tolerance, bins)  -- fault lines a shaft or cage harmonic can mimic
    excitation_period(x, fs, *, frequency_range, band, method) -- (period s, lines or impulses used)
    excitation_duration(x, fs, *, level=0.1, baseline="median", axis=-1) -- (duration s, entry s, exit s) of one pulse
    impulses(x, fs, *, band, threshold, min_separation, level) -- Impulses(time, peak, duration, entry, exit, resolved)
    rms, peak, peak_to_peak, crest_factor, kurtosis, impulse_factor, clearance_factor, shape_factor (x, *, axis)
    metrics(x, *, axis=-1, units="1")                       -- dict of the eight metrics + "units"
    METRICS, metric_units(name, signal_units)               -- the metrics' table (name -> Metric) and units
    analyze(x, fs, *, bearing, rpm, rpm_source, tacho, ...) -- dict: speed, verdict, evidence (docs/analysis.md)
    plot_analysis(x, fs, *, bearing, ..., path)             -- (figure, result): waveform, spectrum, SES with markers
    xr                                                      -- xarray wrappers of the above (apply_ufunc, dask-friendly)
"""
from ._spectral import (amplitude_spectrum, bandpass, cepstral_prewhitening, envelope_band,  # noqa: F401
                        fast_kurtogram, Kurtogram, squared_envelope, squared_envelope_spectrum, welch_psd)
from ._speed import interpolated_peak, shaft_frequency  # noqa: F401
from ._faults import diagnose_ses, fault_line  # noqa: F401
from ._diagnosis import coincidences  # noqa: F401
from ._impulse import excitation_duration, excitation_period, impulses, Impulses  # noqa: F401
from ._metrics import (clearance_factor, crest_factor, impulse_factor, kurtosis, metrics,  # noqa: F401
                       metric_units, METRICS, peak, peak_to_peak, rms, shape_factor)
from ._cyclo import enhanced_envelope_spectrum  # noqa: F401
from ._tacho import order_track, tacho_pulses, tacho_speed  # noqa: F401
from .pipeline import analyze, plot_analysis, shaft_speed  # noqa: F401
from . import accessor as _accessor  # noqa: F401  (registers da.bearing)
from . import xr  # noqa: F401

__all__ = ["amplitude_spectrum", "welch_psd", "cepstral_prewhitening", "bandpass", "squared_envelope",
           "squared_envelope_spectrum", "fast_kurtogram", "Kurtogram", "envelope_band",
           "interpolated_peak", "shaft_frequency", "fault_line", "diagnose_ses", "coincidences", "excitation_period",
           "excitation_duration", "impulses", "Impulses", "rms", "peak", "peak_to_peak", "crest_factor",
           "kurtosis", "impulse_factor", "clearance_factor", "shape_factor", "metrics", "METRICS", "metric_units",
           "analyze",
           "plot_analysis", "xr", "shaft_speed", "tacho_pulses", "tacho_speed", "order_track",
           "enhanced_envelope_spectrum"]
