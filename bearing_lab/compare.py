"""Measured against simulated on one time base: the ComparisonResult and its plots.

Why a module of its own: what a validation shows a reviewer (waveforms on one time
base with the impacts aligned, spectra, squared envelope spectra with the fault
markers, and the table) must be one object that plots and saves itself, and that
loads back from ``comparison.nc``.  The measurements it tabulates live in
:mod:`bearing_lab.analysis.measurement` and :mod:`bearing_lab.analysis.impacts`, the
structural-path fit in :mod:`bearing_lab.analysis.structural_path`, the rows and
their tolerances in :mod:`bearing_lab.validation.rows`.

Public API
----------
compare(signals, fs, rows, *, n, band, ses_fmax, attrs) -> ComparisonResult
ComparisonResult                    -- .dataset, .rows, .passed, plot_waveforms/plot_spectra/plot_envelope(ax=None),
                                       to_netcdf(path), load(path)
align_by_impulse_phase(exp, sim, fs, period, *, band) -- samples that put the simulation's impacts on the experiment's
shift(x, shift, n)                  -- x delayed by ``shift`` samples into n samples (NaN before)
table_dataset(rows)                 -- the rows as Dataset variables along ``quantity``
SIGNAL_COLORS                       -- one colour per compared signal in every figure
"""
from __future__ import annotations

import json

import numpy as np
import xarray as xr

from .analysis import amplitude_spectrum, squared_envelope_spectrum
from .analysis.impacts import impact_times
from .errors import BearingLabError
from .io.export import to_netcdf
from .units import G

__all__ = ["compare", "ComparisonResult", "align_by_impulse_phase", "shift", "table_dataset", "SIGNAL_COLORS"]

_TEXT_KEYS = ("quantity", "label", "units", "tolerance", "rule", "reason", "known_limitation", "declared_by",
              "note", "reference_label", "simulated_signal", "experiment_span", "status")
_FLOAT_KEYS = ("simulation", "experiment", "reference_value", "difference", "difference_pct", "tolerance_pct",
               "paper_simulation")
_BOOL_KEYS = ("pass", "independent")

#: one colour per compared signal in every figure, none of them a fault marker's (BPFO red, BPFI green)
SIGNAL_COLORS = {"experiment": "k", "recording": "k", "model": "tab:blue", "path": "tab:orange",
                 "path+background": "tab:purple"}


def _float_or_nan(v) -> float:
    try:
        return float(v) if v is not None else float("nan")
    except (TypeError, ValueError):
        return float("nan")


def align_by_impulse_phase(experiment, simulation, fs, period, *, band=None, periods=10):
    """Samples to delay ``simulation`` by so that its impacts fall on the experiment's.

    Both signals at the same rate ``fs``.  Each signal's impact phase is the circular mean of
    its impact times modulo ``period`` over its first ``periods`` impacts, skipping the first
    half period, where the band-pass filter's start transient can make the envelope's largest
    value (so one early, wrong impact cannot set the shift; slip jitter averages out).
    Returns ``shift`` in [0, period*fs): the aligned simulation is ``sim[n - shift]``.
    """
    phases = []
    for x in (experiment, simulation):
        t = impact_times(x, fs, period, band=band)
        t = t[t >= 0.5 * period][:periods]
        if t.size == 0:
            return 0
        phases.append(np.angle(np.mean(np.exp(2j * np.pi * t / period))) / (2 * np.pi) * period)
    return int(round(((phases[0] - phases[1]) * fs) % (period * fs))) % max(int(round(period * fs)), 1)


def shift(x, shift, n):
    """``x`` delayed by ``shift`` samples into an array of ``n`` (NaN where it has no data)."""
    out = np.full(n, np.nan)
    x = np.asarray(x, float)
    m = min(n - shift, len(x))
    if m > 0:
        out[shift: shift + m] = x[:m]
    return out


def _spectrum(x, fs, n):
    x = np.asarray(x, float)[:n]
    return amplitude_spectrum(x - np.mean(x), fs, window="hann")


def _ses(x, fs, n, band, fmax):
    return squared_envelope_spectrum(np.asarray(x, float)[:n], fs, window="hann", band=band, fmax=fmax)


class ComparisonResult:
    """Measured against simulated: a Dataset (waveforms, spectra, SES, table) and its plots.

    ``dataset`` dims: ``signal`` (e.g. "experiment", "simulation", "simulation_calibrated"),
    ``time`` (one time base, impacts aligned), ``frequency``, ``cyclic_frequency``,
    ``quantity`` (table rows).  Table variables: ``simulation``, ``experiment``,
    ``difference``, ``difference_pct``, ``tolerance_pct``, ``pass`` (+ labels, units,
    reasons).  Attributes hold the case name, fault frequencies and provenance (JSON).
    """

    def __init__(self, dataset: xr.Dataset):
        self.dataset = dataset

    # ---- table
    @property
    def rows(self) -> list[dict]:
        ds = self.dataset
        if "quantity" not in ds.dims:
            return []
        out = []
        for i in range(ds.sizes["quantity"]):
            row = {}
            for k in _TEXT_KEYS:
                row[k] = str(ds[k].values[i]) if k in ds else ""
            for k in _FLOAT_KEYS:
                row[k] = float(ds[k].values[i]) if k in ds else float("nan")
            if not np.isfinite(row["tolerance_pct"]):
                row["tolerance_pct"] = None
            for k in _BOOL_KEYS:
                row[k] = bool(ds[k].values[i]) if k in ds else True
            out.append(row)
        return out

    @property
    def passed(self) -> bool:
        return all(r["pass"] for r in self.rows)

    # ---- plots
    def _ax(self, ax, figsize=(9, 3.2)):
        if ax is None:
            import matplotlib.pyplot as plt  # lazy.load would import matplotlib (0.075 s) with this module
            _, ax = plt.subplots(figsize=figsize, layout="constrained")
        return ax

    def plot_waveforms(self, ax=None, *, signals=None, window_s=None, acceleration_units="g"):
        """Waveforms on the common time base (impacts aligned); ``window_s`` (start, stop)."""
        ax = self._ax(ax)
        ds = self.dataset
        scale = G if acceleration_units == "g" else 1.0
        t = ds["time"].values
        sel = slice(None)
        if window_s is not None:
            sel = (t >= window_s[0]) & (t <= window_s[1])
        for s in signals or list(ds["signal"].values):
            if s not in list(ds["signal"].values):
                continue
            y = ds["waveform"].sel(signal=s).values / scale
            ax.plot(t[sel], y[sel], lw=0.7, label=str(s).replace("_", " "))
        ax.set_xlabel("time (s)")
        ax.set_ylabel(f"acceleration ({acceleration_units})")
        ax.legend(loc="upper right", fontsize=8)
        return ax

    def plot_spectra(self, ax=None, *, signals=None, fmax=None, acceleration_units="g", log=True):
        """Amplitude spectra on the common frequency axis."""
        ax = self._ax(ax)
        ds = self.dataset
        scale = G if acceleration_units == "g" else 1.0
        f = ds["frequency"].values
        sel = f <= (fmax or f[-1])
        for s in signals or list(ds["signal"].values):
            if s not in list(ds["signal"].values):
                continue
            y = ds["spectrum"].sel(signal=s).values / scale
            ax.plot(f[sel], y[sel], lw=0.6, label=str(s).replace("_", " "))
        if log:
            ax.set_yscale("log")
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel(f"amplitude ({acceleration_units})")
        ax.legend(loc="upper right", fontsize=8)
        return ax

    def plot_envelope(self, ax=None, *, signals=None, frequency_units="Hz", fmax=None, normalize=True,
                      markers=("bpfo", "bpfi", "shaft")):
        """Squared envelope spectra with fault-frequency markers (harmonics 1-5)."""
        ax = self._ax(ax)
        ds = self.dataset
        f = ds["cyclic_frequency"].values
        fscale = {"Hz": 1.0, "kHz": 1e3}.get(frequency_units, 1.0)
        sel = f <= (fmax or f[-1])
        for s in signals or list(ds["signal"].values):
            if s not in list(ds["signal"].values):
                continue
            y = ds["ses"].sel(signal=s).values.astype(float)
            if normalize:
                pos = y[sel & (f > 5)]
                y = y / (np.nanmax(pos) if pos.size and np.nanmax(pos) > 0 else 1.0)
            ax.plot(f[sel] / fscale, y[sel], lw=0.7, label=str(s).replace("_", " "), color=SIGNAL_COLORS.get(str(s)))
        colors = {"bpfo": "tab:red", "bpfi": "tab:green", "shaft": "0.5"}
        for m in markers:
            fm = ds.attrs.get(f"{m}_hz")
            if not fm:
                continue
            for h in range(1, 6):
                if h * fm <= f[sel][-1]:
                    ax.axvline(h * fm / fscale, color=colors.get(m, "k"), ls="--", lw=0.6,
                               label=m.upper() if h == 1 else None)
        ax.set_xlabel(f"cyclic frequency ({frequency_units})")
        ax.set_ylabel("SES (normalised)" if normalize else "SES")
        ax.legend(loc="upper right", fontsize=8)
        return ax

    # ---- save / load
    def to_netcdf(self, path):
        """Write the Dataset (atomically: a crash leaves the old file or none)."""
        return to_netcdf(self.dataset, path, error=BearingLabError)

    @classmethod
    def load(cls, path) -> "ComparisonResult":
        with xr.open_dataset(path) as ds:
            ds = ds.load()
        for k in _BOOL_KEYS:
            if k in ds:
                ds[k] = ds[k].astype(bool)
        return cls(ds)

    def __repr__(self):
        n = len(self.rows)
        ok = sum(r["pass"] for r in self.rows)
        return f"<ComparisonResult {self.dataset.attrs.get('case', '')!r}: {ok}/{n} rows pass>"


def table_dataset(rows: list[dict]) -> xr.Dataset:
    """The rows as Dataset variables along ``quantity``."""
    q = [r["quantity"] for r in rows]
    data = {}
    for k in _TEXT_KEYS[1:]:
        data[k] = ("quantity", np.array([str(r.get(k, "")) for r in rows], dtype=object))
    for k in _FLOAT_KEYS:
        data[k] = ("quantity", np.array([_float_or_nan(r.get(k)) for r in rows], dtype=float))
    for k in _BOOL_KEYS:
        data[k] = ("quantity", np.array([bool(r.get(k, True)) for r in rows], dtype=bool))
    return xr.Dataset(data, coords={"quantity": ("quantity", np.array(q, dtype=object))})


def compare(signals: dict, fs: float, rows: list[dict], *, n=None, band=None, ses_fmax=1000.0,
            attrs=None) -> ComparisonResult:
    """Assemble a :class:`ComparisonResult` from signals already on one time base.

    Parameters
    ----------
    signals : {name: 1-D array} sampled at ``fs`` and aligned (NaN where a shifted signal has no data).
    rows : table rows from :func:`make_row`.
    n : samples kept (default: the shortest signal).
    band : demodulation band of the SES (the same for every signal), or None.
    """
    names = list(signals)
    n = n or min(len(v) for v in signals.values())
    wave = np.stack([np.asarray(signals[k], float)[:n] for k in names])
    spec, ses = [], []
    for k in names:
        y = np.nan_to_num(wave[names.index(k)], nan=0.0)
        f, a = _spectrum(y, fs, n)
        fc, sv = _ses(y, fs, n, band, ses_fmax)
        spec.append(a)
        ses.append(sv)
    ds = xr.Dataset(
        {"waveform": (("signal", "time"), wave, {"units": "m s-2", "long_name": "acceleration"}),
         "spectrum": (("signal", "frequency"), np.stack(spec),
                      {"units": "m s-2", "long_name": "amplitude spectrum (Hann, peak amplitude)"}),
         "ses": (("signal", "cyclic_frequency"), np.stack(ses),
                 {"units": "m2 s-4", "long_name": "squared envelope spectrum"})},
        coords={"signal": ("signal", np.array(names, dtype=object)),
                "time": ("time", np.arange(n) / fs, {"units": "s"}),
                "frequency": ("frequency", f, {"units": "Hz"}),
                "cyclic_frequency": ("cyclic_frequency", fc, {"units": "Hz"})})
    if rows:
        ds = ds.merge(table_dataset(rows))
    ds.attrs.update({"sampling_rate_hz": float(fs), "ses_band": json.dumps(band and list(map(float, band)))})
    for k, v in (attrs or {}).items():
        ds.attrs[k] = v if isinstance(v, (str, int, float)) else json.dumps(v, default=str)
    return ComparisonResult(ds)
