"""Read the public recordings for the analysis tests.

Uses ``bearing_lab.io.open_recording`` when it can read the file; until then
(and as an independent path) the files are read here with scipy / numpy:

- CWRU: the variable matching ``_DE_time`` (or ``_FE_time`` for fan-end faults)
  in g; fs 12 000 Hz, except record 97 and the ``48k_DE`` folder (48 000 Hz), as
  the Bearing Data Center lists them; the stored ``X###RPM`` is returned
  separately and only the tests that say so use it.
- IMS: tab-separated ASCII, 20 480 rows x 4 channels.  The rate is taken as
  20 480 Hz (one second a file): the nominal "20 kHz" does not fit the fault
  lines, and 20 480 Hz places the bearing-1 BPFO line at the published 236 Hz
  (Qiu et al. 2006).
- MFPT: struct ``bearing`` with ``sr`` (Hz), ``rate`` (shaft Hz), ``gs`` (g).
"""
from __future__ import annotations

import re

import numpy as np
import scipy.io as sio

G = 9.80665
IMS_FS = 20480.0


def cwru(path, channel="DE"):
    """(x in m s-2, fs, rpm_stored) of the drive-end (or fan-end) channel."""
    m = sio.loadmat(str(path))
    key = next(k for k in m if re.search(rf"_{channel}_time$", k))
    rpm_key = next((k for k in m if re.search(r"RPM$", k)), None)
    fs = 48000.0 if (re.match(r"97_", path.name) or path.parent.name == "48k_DE") else 12000.0
    rpm = float(np.ravel(m[rpm_key])[0]) if rpm_key else None
    return np.ravel(m[key]).astype(float) * G, fs, rpm


def ims(path):
    """(x with shape (4, 20480) in m s-2, fs)."""
    data = np.loadtxt(str(path), delimiter="\t")
    return data.T * G, IMS_FS


def mfpt(path):
    """(x in m s-2, fs, shaft_hz_stored)."""
    m = sio.loadmat(str(path), squeeze_me=True)
    b = m["bearing"]
    x = np.ravel(b["gs"].item()).astype(float) * G
    return x, float(b["sr"].item()), float(b["rate"].item())
