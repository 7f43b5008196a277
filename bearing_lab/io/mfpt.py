"""MFPT bearing fault data in MathWorks' packaging (struct ``bearing``: ``gs``, ``sr``, ``rate``, ``load``).

Why a reader of its own: the rate (``sr``, 48 828 Hz for the fault sets) and the
shaft speed (``rate``, Hz) are inside the struct, the acceleration ``gs`` is in
g.  One channel, named ``acc``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ._base import ENGINES, RecordingBuilder, RecordingReader
from ._matlab import load_mat, mat_variables, mat_version, require_matlab, signal_vector


class MfptReader(RecordingReader):
    """Read MFPT ``.mat`` files (MathWorks RollingElementBearingFaultDiagnosis-Data)."""

    name = "mfpt"
    description = "MFPT fault data .mat, struct 'bearing' with gs (g), sr (Hz), rate (shaft Hz)"
    extensions = (".mat",)
    libraries = ("scipy",)

    def guess_can_open(self, path, head):
        return mat_version(head) is not None and "bearing" in mat_variables(path)

    def open_dataset(self, path, *, channels=None, fs=None, units="g", checksum=True):
        """Read the ``bearing.gs`` signal.

        Parameters
        ----------
        path : str or Path
        channels : str or list, optional
            ``"acc"`` (the only channel).
        fs : float, optional
            Sampling rate, Hz (default: ``bearing.sr``).
        units : str
            Unit of ``gs`` (``"g"``).
        checksum : bool
            Compute ``source_sha256``.

        Returns
        -------
        xarray.Dataset
        """
        path = Path(path)
        b = RecordingBuilder(path, self, units=units, checksum=checksum)
        require_matlab(path, b)
        m = load_mat(path)
        s = m.get("bearing")
        if not isinstance(s, dict) or "gs" not in s:
            b.fail(f"no struct 'bearing' with field 'gs' (variables: {', '.join(m) or 'none'}); "
                   "not an MFPT file")
        gs = signal_vector(b, s["gs"], "bearing.gs")
        if fs is None:
            try:
                fs = float(np.ravel(s.get("sr"))[0])
            except (TypeError, ValueError, IndexError):
                b.fail("bearing.sr (sampling rate) is missing or not a number; pass fs=<Hz>")
        rpm = None
        try:
            rpm = float(np.ravel(s.get("rate"))[0]) * 60.0
        except (TypeError, ValueError, IndexError):
            b.warn("bearing.rate (shaft speed) is missing: shaft_speed_rpm unknown")
        load = s.get("load")
        if load is not None:
            try:
                b.attrs["load_lbf"] = float(np.ravel(load)[0])
            except (TypeError, ValueError):
                b.attrs["load_lbf_text"] = str(load)
        for k in ("BPFO", "BPFI", "BSF", "FTF"):
            if k in m:
                try:
                    b.attrs[f"mfpt_{k.lower()}_hz"] = float(np.ravel(m[k])[0])
                except (TypeError, ValueError):
                    pass
        b.add_channel("acc", gs, None, file_name="bearing.gs", inplace=True)
        return b.build(fs=fs, shaft_speed_rpm=rpm, default_channel="acc", channels=channels)


ENGINES["mfpt"] = MfptReader
