"""The figures of a validation report, built as matplotlib ``Figure`` objects (no backend switching).

Each function returns ``(figure, caption)``; accelerations are drawn in g.
"""
from __future__ import annotations

import numpy as np
from scipy.signal import welch

from ..analysis import amplitude_spectrum
from ..compare import SIGNAL_COLORS
from ..units import G
from ..utils.figures import new_figure

__all__ = ["waveforms", "spectra", "envelope_spectra", "structural_path", "psd_overlay", "paper_run"]


def _fig(h=3.2, n=1, w=10):
    fig = new_figure(figsize=(w, h * n), layout="constrained")
    return fig, fig.subplots(n, 1, squeeze=False)[:, 0]


def waveforms(signals: dict, fs, *, recording_label, window_s=0.1, shift=0):
    """Recording above; the simulation as the model gives it; the compared simulation over the recording."""
    names = [k for k in ("model", "path+background") if k in signals]
    fig, axes = _fig(n=1 + len(names), h=2.4)
    xe = signals["experiment"]
    t = np.arange(xe.size) / fs
    win = t <= min(window_s, t[-1])
    axes[0].plot(t[win], xe[win] / G, lw=0.6, color="k")
    axes[0].set_title(f"recording {recording_label}", fontsize=10)
    titles = {"model": "simulation: the bearing model alone (outer ring, no path, no background)",
              "path+background": "simulation after the fixed structural path (and background), over the recording"}
    for ax, k in zip(axes[1:], names):
        if k != "model":
            ax.plot(t[win], xe[win] / G, lw=0.5, color="0.65", label="recording")
        ax.plot(t[win], signals[k][win] / G, lw=0.6, color=SIGNAL_COLORS.get(k, "tab:red"),
                label="simulation")
        ax.set_title(titles[k], fontsize=10)
        ax.legend(loc="upper right", fontsize=8)
    for a in axes:
        a.set_ylabel("a (g)")
    axes[-1].set_xlabel("time (s), simulated impacts aligned with the recording's")
    return fig, (f"Waveforms on one time base: the simulation is shifted by {shift} samples so that its first "
                 "impact falls on the recording's.")


def spectra(signals: dict, fs):
    """Amplitude spectra: recording, and each simulated signal."""
    fig, (ax,) = _fig(h=3.6)
    colors = SIGNAL_COLORS
    for k, y in signals.items():
        y = np.nan_to_num(np.asarray(y, float))
        f, a = amplitude_spectrum(y - y.mean(), fs, window="hann")
        ax.semilogy(f, np.maximum(a / G, 1e-12), lw=0.5, color=colors.get(k, "0.5"),
                    label="recording" if k == "experiment" else f"simulation: {k}")
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("amplitude (g)")
    ax.legend(loc="upper right", fontsize=8)
    return fig, "Amplitude spectra of the compared segment (Hann window, peak amplitude)."


def envelope_spectra(result, fmax=600):
    fig, (ax,) = _fig(h=3.6)
    result.plot_envelope(ax=ax, fmax=fmax)
    ax.set_title("squared envelope spectra, with the kinematic fault frequencies and harmonics", fontsize=10)
    return fig, "Squared envelope spectra with BPFO (red), BPFI (green) and shaft (grey) markers."


def structural_path(path, fs):
    """The fit's pooled impulse envelopes (before/after) and the path's frequency response."""
    fig, (a1, a2) = _fig(n=2, h=3.0)
    c = path.curves
    if c:
        tt = c["time_s"] * 1e3
        a1.semilogy(tt, c["recording"] / G, "k", lw=1.0, label="recording")
        a1.semilogy(tt, c["before"] / G, color="tab:blue", lw=0.9, label="simulation, no path")
        a1.semilogy(tt, c["after"] / G, color="tab:red", lw=0.9, label="simulation through the fitted path")
        a1.set_xlabel("time from the impact (ms)")
        a1.set_ylabel("mean envelope (g)")
        a1.legend(fontsize=8)
        a1.set_title("impulse response pooled over all impacts (mean Hilbert envelope)", fontsize=10)
    f = np.linspace(0, fs / 2, 2000)
    a2.semilogy(f, np.abs(path.response(f)), color="tab:red")
    a2.set_xlabel("frequency (Hz)")
    a2.set_ylabel("|H| (outer ring to sensor)")
    a2.set_title(f"structural path: {path.describe()}", fontsize=10)
    return fig, ("The structural path, identified once on the pooled impulse responses and then held fixed for "
                 "every compared simulation of this rig.")


def psd_overlay(curves: dict, fs, title):
    """Welch PSDs (g²/Hz) of several signals on one axis."""
    fig, (ax,) = _fig(h=3.4)
    for label, y in curves.items():
        y = np.nan_to_num(np.asarray(y, float))
        f, p = welch(y - y.mean(), fs, window="hann", nperseg=min(y.size, 1024))
        ax.semilogy(f, np.maximum(p / G ** 2, 1e-20), lw=0.8, label=label)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("PSD (g²/Hz)")
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    return fig, title


def paper_run(label, x, fs, *, kinematic: dict, measured: dict, paper_simulation: dict, amplitude_g=None):
    """One run of the paper case: waveform against the reported amplitude, spectrum with the reported lines."""
    fig, (a1, a2) = _fig(n=2)
    t = np.arange(x.size) / fs
    sel = t <= 0.1
    a1.plot(t[sel], x[sel] / G, lw=0.6, color="tab:blue", label="bearing_lab simulation")
    if amplitude_g:
        a1.axhspan(-amplitude_g, amplitude_g, color="tab:orange", alpha=0.12,
                   label=f"paper: about ±{amplitude_g:g} g")
    a1.set_xlabel("time (s)")
    a1.set_ylabel("acceleration (g)")
    a1.legend(loc="upper right", fontsize=8)
    a1.set_title(f"{label}: outer-ring acceleration, first 0.1 s; simulated max |a| = "
                 f"{np.max(np.abs(x)) / G:.3g} g", fontsize=10)
    f, a = amplitude_spectrum(x - x.mean(), fs, window="hann")
    s2 = f <= 1000
    a2.semilogy(f[s2], np.maximum(a[s2] / G, 1e-12), lw=0.6, color="tab:blue", label="bearing_lab simulation")
    for q, c in (("shaft_hz", "0.4"), ("bpfo", "tab:red"), ("bpfi", "tab:green")):
        if q in kinematic:
            a2.axvline(kinematic[q], color=c, ls="--", lw=0.8)
        if q in measured:
            a2.axvline(measured[q], color=c, ls=":", lw=1.4)
        if q in paper_simulation:
            a2.axvline(paper_simulation[q], color=c, ls="-.", lw=0.7)
    a2.plot([], [], "k--", label="kinematic (reference)")
    a2.plot([], [], "k:", label="paper: measured")
    a2.plot([], [], "k-.", label="paper: its simulation")
    a2.set_xlabel("frequency (Hz)")
    a2.set_ylabel("amplitude (g)")
    a2.legend(loc="upper right", fontsize=7, ncol=3)
    return fig, (f"{label}: simulated waveform and spectrum. The paper's traces exist only as figures: its "
                 "reported amplitude and lines (f_i grey, BPFO red, BPFI green) are drawn as bands and lines.")
