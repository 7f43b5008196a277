"""Simcenter (LMS) Testlab MATLAB export: struct ``Signal`` (``Signal_0``, ``Signal_1`` ... grouped).

Why this reader is careful with units: Testlab stores the values in SI (MKS;
``quantity.info`` says "Data saved by Testlab in MKS") and labels the *display*
unit, with ``unit_transformation.factor/.offset`` converting stored -> display.
The real sample is stored in m/s² and labelled ``g`` with factor 1/9.80665:
taking the values as g would make them 9.81× too large.  We check that the
label and the factor agree (factor × g-in-SI ≈ 1) and keep the stored values;
when they disagree the values are converted through the factor and the label
(display = stored·factor + offset, then label -> SI) and a warning says so.

v5 files are read with scipy.io, v7.3 with h5py; fields are read by name
(their order differs between files).  ``y_values.values`` of shape N×C (a
grouped export) is split into C channels.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .. import units as _units
from ..errors import RecordingError
from ._base import ENGINES, RecordingBuilder, RecordingReader, clean_name
from ._matlab import load_mat, mat_variables, mat_version, require_matlab

_SIGNAL = re.compile(r"^Signal(_\d+)?$")
_OTHER = re.compile(r"^(FRF|PSD|Spectrum|Autopower|Crosspower|Order|Octave)\w*$", re.I)


def _get(d, *keys, default=None):
    for k in keys:
        if not isinstance(d, dict) or k not in d:
            return default
        d = d[k]
    return d


class TestlabMatReader(RecordingReader):
    """Read Testlab MATLAB exports of time signals."""

    name = "testlab_mat"
    description = "Simcenter/LMS Testlab MATLAB export, struct 'Signal' (v5 or v7.3 .mat)"
    extensions = (".mat",)
    libraries = ("scipy", "h5py")

    def guess_can_open(self, path, head):
        if mat_version(head) is None:
            return False
        names = mat_variables(path)
        return any(_SIGNAL.match(n) for n in names) or \
            (any(_OTHER.match(n) for n in names) and not any(n.startswith("X") for n in names))

    def open_dataset(self, path, *, channels=None, units=None, sensitivity=None, checksum=True):
        """Read the ``Signal`` variables of a Testlab MATLAB export.

        Parameters
        ----------
        path : str or Path
        channels : str or list of str, optional
            Channel names (Testlab point names, e.g. ``Point1``) to keep.
        units : str or dict, optional
            Display-unit label(s) replacing the file's (for unknown labels).
        sensitivity : str, dict or False, optional
            For channels stored in volts.
        checksum : bool
            Compute ``source_sha256``.

        Returns
        -------
        xarray.Dataset
        """
        path = Path(path)
        b = RecordingBuilder(path, self, units=units, sensitivity=sensitivity, checksum=checksum)
        require_matlab(path, b)
        names = mat_variables(path)
        sigs = sorted((n for n in names if _SIGNAL.match(n)),
                      key=lambda n: int(n[7:]) if "_" in n else -1)
        if not sigs:
            others = [n for n in names if _OTHER.match(n)]
            if others:
                b.fail(f"holds {', '.join(others)} but no time signal ('Signal' struct); export "
                       "the time history from Testlab")
            b.fail(f"no 'Signal' struct (variables: {', '.join(names) or 'none'}); not a Testlab "
                   "time-signal export (for CWRU or MFPT files use format='cwru' or 'mfpt')")
        m = load_mat(path, variable_names=sigs)
        chan_rt = {}
        for var in sigs:
            _add_signal(b, var, m.get(var), units, chan_rt)
        fs, t0 = _common_rate(b, chan_rt, channels)
        ann = _get(m[sigs[0]], "function_record", "TL_export_properties_annotation", default={})
        if isinstance(ann, dict):
            for k in ("project_name", "section_name", "run_name", "absolute_time"):
                if isinstance(ann.get(k), str):
                    b.attrs[f"testlab_{k}"] = ann[k]
        return b.build(fs=fs, t0=t0, channels=channels)


def _signal_values(b, var, s):
    """(start s, increment s, values N x C) of one ``Signal`` struct, checked."""
    if not isinstance(s, dict) or "y_values" not in s or "x_values" not in s:
        b.fail(f"variable {var!r} is not a Testlab Signal struct (needs fields x_values "
               f"and y_values; has {', '.join(s) if isinstance(s, dict) else type(s).__name__})")
    xv, yv = s["x_values"], s["y_values"]
    try:
        start = float(_get(xv, "start_value", default=0.0))
        inc = float(_get(xv, "increment"))
        nval = int(_get(xv, "number_of_values", default=-1))
    except (TypeError, ValueError):
        b.fail(f"{var}.x_values has no usable start_value/increment/number_of_values")
    if not (np.isfinite(inc) and inc > 0):
        b.fail(f"{var}.x_values.increment is {inc!r}; expected a positive time step")
    vals = np.asarray(_get(yv, "values"))
    if vals.dtype.kind not in "iuf" or vals.size == 0:
        b.fail(f"{var}.y_values.values is missing or not numeric")
    if vals.ndim == 1:
        vals = vals[:, None]
    if vals.ndim != 2:
        b.fail(f"{var}.y_values.values has shape {vals.shape}; expected N or N×C")
    if nval >= 0 and vals.shape[0] != nval:
        if vals.shape[1] == nval:
            vals = vals.T
        else:
            b.fail(f"{var}: x_values.number_of_values is {nval} but y_values.values has "
                   f"{vals.shape[0]} rows: truncated or corrupt export")
    return start, inc, vals


def _add_signal(b, var, s, units, chan_rt):
    """Add the channels of one ``Signal`` struct; ``chan_rt[name] = (rate, start, var)``."""
    start, inc, vals = _signal_values(b, var, s)
    yv, fr = s["y_values"], s.get("function_record", {}) or {}
    label = _get(yv, "quantity", "label", default="")
    factor = float(_get(yv, "quantity", "unit_transformation", "factor", default=1.0))
    offset = float(_get(yv, "quantity", "unit_transformation", "offset", default=0.0))
    point = _get(fr, "name", default="") or var
    point = point if isinstance(point, str) else ", ".join(map(str, point))
    base = clean_name(point.split(":", 1)[-1] if ":" in point else point, var)
    attrs = {"testlab_variable": var, "testlab_name": point,
             "testlab_creation_time": _get(fr, "creation_time"),
             "testlab_primary_channel": _get(fr, "primary_channel", "label"),
             "testlab_unit_factor": factor, "testlab_unit_offset": offset}
    ann = _get(fr, "TL_export_properties_annotation", default={}) or {}
    for k in ("project_name", "section_name", "run_name", "absolute_time", "channel_group"):
        if isinstance(ann, dict) and isinstance(ann.get(k), str):
            attrs[f"testlab_{k}"] = ann[k]
    ncol = vals.shape[1]
    for j in range(ncol):
        cname = base if ncol == 1 else f"{base}_{j + 1}"
        y = vals[:, j].astype(np.float64)
        stored_si = True
        try:
            u = _units.lookup_unit(units if isinstance(units, str) else
                                   (units or {}).get(cname, label), what="")
            stored_si = offset == 0.0 and abs(factor * u.factor - 1.0) < 1e-9
        except RecordingError:
            u = None  # add_channel reports the unknown label
        if not stored_si and u is not None:
            b.warn(f"{var}: unit_transformation (factor {factor:g}, offset {offset:g}) "
                   f"does not match the label {label!r}: values converted through it")
            y = y * factor + offset
        got = b.add_channel(cname, y, label, already_si=stored_si, attrs=attrs,
                            file_name=cname)
        chan_rt[got] = (1.0 / inc, start, var)


def _common_rate(b, chan_rt, channels):
    """(fs, t0) shared by the selected channels (refused when they differ)."""
    sel = list(chan_rt) if channels is None else \
        [c for c in ([channels] if isinstance(channels, str) else channels) if c in chan_rt]
    if len({(round(chan_rt[c][0], 9), chan_rt[c][1]) for c in sel}) > 1:
        desc = ", ".join(f"{c} ({chan_rt[c][2]}): {chan_rt[c][0]:g} Hz from {chan_rt[c][1]:g} s"
                         for c in sel)
        b.fail(f"signals differ in rate or start ({desc}); read them one at a time with "
               "channels=[...]")
    fs, t0 = chan_rt[sel[0]][:2] if sel else (1.0, 0.0)
    if abs(fs - round(fs)) < 1e-6 * fs:
        fs = float(round(fs))
    return fs, t0


ENGINES["testlab_mat"] = TestlabMatReader
