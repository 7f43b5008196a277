"""Measurement noise on a simulated accelerometer channel (``bearing-lab simulate --noise-g``).

Why apart from the simulator: the noise is what a sensor and its acquisition add to the
signal, not bearing dynamics; it is added to the finished Dataset, seeded, and recorded in
its attributes, so a noisy record says how it was made and the same seed gives the same samples.
"""
from __future__ import annotations

import numpy as np

from ..errors import SceneError, check_choice
from ..units import G

__all__ = ["add_measurement_noise", "NOISE_COLORS"]

#: power spectral density slope of each colour: PSD ∝ f**-slope
NOISE_COLORS = {"white": 0.0, "pink": 1.0, "brown": 2.0}


def _colored(rng, n, slope):
    w = rng.standard_normal(n)
    if slope == 0.0:
        return w
    spec = np.fft.rfft(w)
    f = np.fft.rfftfreq(n)
    shape = np.ones_like(f)
    shape[1:] = f[1:] ** (-slope / 2.0)
    shape[0] = 0.0                      # no DC offset
    x = np.fft.irfft(spec * shape, n)
    return x / np.sqrt(np.mean(x ** 2))


def add_measurement_noise(ds, noise_g: float, *, seed: int = 0, channel: str | None = None,
                          color: str = "white"):
    """Return a copy of ``ds`` with Gaussian noise of RMS ``noise_g`` (in g) added to ``channel``
    (default: the Dataset's ``default_channel``, the accelerometer signal).

    ``color``: "white" (flat spectrum), "pink" (PSD ∝ 1/f) or "brown" (PSD ∝ 1/f²), each scaled to
    the RMS asked for.  The attributes ``measurement_noise_g``, ``measurement_noise_color``,
    ``measurement_noise_seed`` and ``measurement_noise_channel`` record it (on the Dataset and the
    channel).  ``noise_g = 0`` returns ``ds`` unchanged.
    """
    check_choice(color, NOISE_COLORS, "noise colour", SceneError)
    if not (np.isfinite(noise_g) and noise_g >= 0):
        raise SceneError(f"noise {noise_g!r} g: give the noise RMS as a number of g, 0 or more")
    if noise_g == 0:
        return ds
    channel = channel or ds.attrs.get("default_channel")
    if channel not in ds.data_vars:
        raise SceneError(f"noise: no channel {channel!r} in the Dataset")
    da = ds[channel]
    if da.attrs.get("units") != "m s-2":
        raise SceneError(f"noise: channel {channel!r} is in {da.attrs.get('units')!r}, not an acceleration (m s-2)")
    rng = np.random.default_rng(seed)
    noise = noise_g * G * _colored(rng, da.size, NOISE_COLORS[color]).reshape(da.shape)
    out = ds.copy()
    attrs = {"measurement_noise_g": float(noise_g), "measurement_noise_color": color,
             "measurement_noise_seed": int(seed), "measurement_noise_channel": str(channel)}
    out[channel] = da.copy(data=np.asarray(da.values, float) + noise)
    out[channel].attrs.update({**da.attrs, **{k: v for k, v in attrs.items() if k != "measurement_noise_channel"}})
    out.attrs.update(attrs)
    return out
