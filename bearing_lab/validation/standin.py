"""Stand-in recordings: what a rig would record, made with the simulator from a hidden defect.

Why: a validation or a defect identification must be tried on a recording whose truth
is known before it is trusted on a real one.  A stand-in is a simulated bearing with
everything a rig adds that the validation model does not contain: the shaft speed
wanders (a random walk of ``jitter`` relative size, one point every 50 ms), the
housing and sensor ring at a resonance (simulated by the scene's own ``[sensor]``
resonator, not by the validation's path filter), the machine adds tones (shaft
harmonics, mains, a fan) and the sensor adds broadband noise.  It is written as a
UFF 58b file or a Simcenter Testlab-style MATLAB export (struct ``Signal``, values
stored in m/s² and labelled g, as Testlab writes them), atomically.

Public API
----------
StandIn                                              -- path, dataset, hidden truth (dict)
make_standin_recording(path, *, scene="paper-O2", overrides=None, rpm=1793.0, duration=2.0, fs=20000.0,
                       jitter=0.005, resonance_hz=4300.0, resonance_damping=0.05, tones=None,
                       noise_g=0.05, seed=0, channel="Acc", rtol=1e-6) -> StandIn
default_tones(rpm)                                   -- the default machine tones [(Hz, amplitude in g)]
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
import tempfile

import numpy as np
import scipy.io
import xarray as xr

from .._version import __version__
from ..datasets import SAMPLE
from ..errors import BearingLabError, RecordingError
from ..io import to_uff58b
from ..units import G
from ..utils._files import atomic_path
from . import simulation

__all__ = ["StandIn", "make_standin_recording", "default_tones", "FORMATS"]

#: file suffix -> written format
FORMATS = {".uff": "UFF 58b", ".unv": "UFF 58b", ".mat": "Testlab MATLAB export"}


@dataclass
class StandIn:
    """A written stand-in recording and the truth it hides."""

    path: Path
    dataset: object
    hidden: dict


def default_tones(rpm: float) -> list:
    """Machine tones of a small motor rig, (frequency Hz, amplitude g): 1x and 2x shaft (unbalance,
    misalignment), 50 and 100 Hz (mains, motor), 315 Hz (a fan's blade pass)."""
    fr = rpm / 60.0
    return [(fr, 0.02), (2 * fr, 0.01), (50.0, 0.03), (100.0, 0.015), (315.0, 0.02)]


def _speed_profile(rpm, duration, jitter, rng):
    t = np.arange(0.0, duration + 0.05, 0.05)
    walk = np.cumsum(rng.standard_normal(t.size))
    walk = walk - walk.mean()
    walk = walk / (np.max(np.abs(walk)) or 1.0)
    return [[float(a), float(rpm * (1 + jitter * w))] for a, w in zip(t, walk)]


def _write_testlab_mat(path, x, fs, channel):
    sig = {"x_values": {"start_value": 0.0, "increment": 1.0 / fs, "number_of_values": x.size,
                        "quantity": {"label": "s"}},
           "y_values": {"values": x.astype(np.float64),
                        "quantity": {"label": "g", "unit_transformation": {"factor": 1.0 / G, "offset": 0.0}}},
           "function_record": {"name": f"1:{channel}", "creation_time": "2026/01/01 00:00:00",
                               "primary_channel": {"label": channel}}}
    scipy.io.savemat(path, {"Signal": sig})


def _dataset(x, fs, channel, hidden):
    t = np.arange(x.size) / fs
    return xr.Dataset({channel: ("time", x, {"units": "m s-2", "quantity": "acceleration", "original_units": "m/s2",
                                             "long_name": "housing acceleration (stand-in)"})},
                      coords={"time": ("time", t, {"units": "s"})},
                      attrs={"sampling_rate_hz": float(fs), "bearing_lab_version": __version__,
                             "source_file": "stand-in", "reader": "simulation",
                             "title": f"stand-in recording of scene {hidden['scene']!r}"})


def make_standin_recording(path, *, scene="paper-O2", overrides=None, rpm=1793.0, duration=2.0, fs=20000.0,
                           jitter=0.005, resonance_hz=4300.0, resonance_damping=0.05, sensor_gain=1.0, tones=None,
                           noise_g=0.05, seed=0, channel="Acc", rtol=1e-6) -> StandIn:
    """Simulate a hidden defect as a rig would record it and write it as UFF 58b or a Testlab .mat.

    Parameters
    ----------
    path : str or Path
        Output file: ``.uff``/``.unv`` (UFF 58b, SI values) or ``.mat`` (Testlab export).
    scene : str
        Built-in scene or scene TOML holding the hidden bearing, load and defect.
    overrides : dict, optional
        Scene keys (``{"defect.offset_mm": 0.3, "load.radial_n": 320}``).
    rpm : float
        Mean shaft speed, r/min.
    duration, fs : float
        Record length (s) and sampling rate (Hz).
    jitter : float
        Relative size of the speed's random walk (0.005 = +-0.5 %).
    resonance_hz, resonance_damping, sensor_gain : float
        The housing/sensor resonance the recording rings at (not in the validation model).
    tones : list of (Hz, g), optional
        Machine tones (default :func:`default_tones`).
    noise_g : float
        RMS of the white sensor noise, g.
    seed : int
        Seed of the speed walk, the tone phases and the noise (same seed, same samples).
    channel : str
        Channel name written to the file.
    rtol : float
        Solver tolerance (unless ``overrides`` gives ``solver.rtol``).  A recording stands in for a
        measurement, so its numerical error must sit far below the misfits it is compared with: at
        the defect auto rule's 1e-4 (stand-in and model alike) the structural path fitted on a
        stand-in came out at 7.1 % damping for its 5 % resonance, at 1e-6 at 5.2 %.

    Returns
    -------
    StandIn
        ``hidden`` holds the truth: scene, overrides, rpm, jitter, resonance, tones, noise.

    See Also
    --------
    new_case_text : a starting case for the file written.
    bearing_lab.io.open_recording : reads it back.

    Examples
    --------
    Fifty milliseconds of a healthy 6308 as a rig's UFF 58b file:

    >>> s = make_standin_recording("rig.uff", scene="paper-healthy", duration=0.05)
    >>> from bearing_lab.io import open_recording
    >>> ds = open_recording("rig.uff")
    >>> ds.sizes["time"], ds.attrs["sampling_rate_hz"], s.hidden["rpm"]     # 0.05 s at 20 kHz
    (1000, 20000.0, 1793.0)
    """
    path = Path(path)
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise RecordingError(f"{path}: a stand-in is written as .uff (UFF 58b) or .mat (Testlab export); "
                             f"got {path.suffix!r}")
    rng = np.random.default_rng(seed)
    ov = dict(overrides or {})
    ov.update({"speed.profile": _speed_profile(rpm, duration, jitter, rng) if jitter > 0 else None,
               "speed_rpm": rpm, "sensor.enabled": True, "sensor.frequency_hz": resonance_hz,
               "sensor.damping_ratio": resonance_damping, "sensor.gain": sensor_gain,
               "solver.rtol": ov.get("solver.rtol", rtol)})
    if ov["speed.profile"] is None:
        ov.pop("speed.profile")
    ds = simulation.run(scene, duration=duration, fs=fs, **ov)
    x = np.asarray(ds[ds.attrs["default_channel"]].values, float)
    t = np.arange(x.size) / fs
    tones = default_tones(rpm) if tones is None else [tuple(map(float, tn)) for tn in tones]
    for f, a_g in tones:
        x = x + a_g * G * np.cos(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
    x = x + rng.normal(0.0, noise_g * G, x.size)
    hidden = {"scene": scene, "overrides": dict(overrides or {}), "rpm": rpm, "jitter": jitter,
              "resonance_hz": resonance_hz, "resonance_damping": resonance_damping, "sensor_gain": sensor_gain,
              "tones": tones, "noise_g": noise_g, "seed": seed, "duration_s": duration, "fs": fs,
              "bearing": ds.attrs["bearing"], "format": fmt}
    out = _dataset(x, fs, channel, hidden)
    _write(path, out, x, fs, channel)
    return StandIn(path, out, hidden)


def _write(path, ds, x, fs, channel):
    try:
        with atomic_path(path) as tmp:
            if path.suffix.lower() == ".mat":
                _write_testlab_mat(tmp, x, fs, channel)
            else:
                to_uff58b(ds, tmp, channels=[channel])
    except OSError as exc:
        raise RecordingError(f"{path}: cannot write ({exc})") from None
    except BearingLabError:
        raise


def make_sample_recording(path) -> Path:
    """Write the project's sample recording: a 1 s stand-in (6308, hidden 3 x 1 mm outer-race defect,
    320 N, 1800 r/min with jitter, a 4.3 kHz resonance, tones, noise) stored as an IEPE accelerometer's
    voltage at 9.91 mV/g in UFF 58b, as a rig's front end would record it.  The file shipped as
    ``bearing_lab/data/sample_recording.uff`` is this function's output (a test regenerates it)."""
    s = SAMPLE
    with tempfile.TemporaryDirectory() as tmp:
        st = make_standin_recording(Path(tmp) / "a.uff", scene=s["scene"], overrides=s["overrides"], rpm=s["rpm"],
                                    duration=s["duration"], fs=s["fs"], seed=s["seed"], channel=s["channel"])
    x = np.asarray(st.dataset[s["channel"]].values, float)
    volts = x / G * s["sensitivity_v_per_g"]
    ds = xr.Dataset({s["channel"]: ("time", volts, {"units": "V", "quantity": "voltage", "original_units": "V",
                                                  "long_name": "accelerometer output, 9.91 mV/g (sample)"})},
                    coords={"time": st.dataset["time"]},
                    attrs={"sampling_rate_hz": s["fs"], "source_file": "bearing_lab sample recording"})
    path = Path(path)
    with atomic_path(path) as t:
        to_uff58b(ds, t, channels=[s["channel"]], id1="bearing_lab sample: 6308 stand-in, 9.91 mV/g",
                  id2="made by bearing_lab.validation.standin.make_sample_recording", id4="1800 r/min")
    return path
