"""Open the recordings a case names: file or registry, channel, calibration, compared segment.

Public API
----------
Recording                               -- dataset, channel, path, x (SI, calibrated, whole record), fs
locate(spec, mirror=None) -> Path|None  -- where a RecordingSpec's file is (registry names via the mirror)
open_spec(spec, case_name, mirror=None) -> Recording
Recording.segment(n)                    -- the compared segment: n samples from the spec's start
Recording.at_rate(fs)                   -- the whole record resampled to ``fs`` (polyphase, anti-aliased)
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

import numpy as np
from scipy.signal import resample_poly

from .. import datasets
from ..errors import BearingLabError, ValidationCaseError
from ..io import open_recording
from ..utils._files import sha256_file

__all__ = ["Recording", "locate", "open_spec", "missing_reason"]


@dataclass
class Recording:
    """One opened recording: the Dataset, the chosen channel and its calibrated SI samples."""

    spec: object
    dataset: object
    channel: str
    path: Path
    x: np.ndarray
    fs: float

    @property
    def sha256(self) -> str:
        if self.dataset.attrs.get("source_sha256"):
            return str(self.dataset.attrs["source_sha256"])
        return sha256_file(self.path)

    @property
    def start(self) -> int:
        return int(round(self.spec.start_s * self.fs))

    def segment(self, n: int) -> np.ndarray:
        return self.x[self.start: self.start + int(n)]

    def at_rate(self, fs: float) -> np.ndarray:
        """The whole record at ``fs`` (identity when equal; polyphase resampling otherwise)."""
        if abs(fs - self.fs) < 1e-9 * fs:
            return self.x
        r = Fraction(float(fs) / self.fs).limit_denominator(1000)
        return resample_poly(self.x, r.numerator, r.denominator)


def locate(spec, mirror=None) -> Path | None:
    if spec.file is not None:
        return spec.file if spec.file.is_file() else None
    return datasets.locate(spec.name, mirror=mirror)


def missing_reason(spec, mirror=None) -> str:
    if spec.file is not None:
        return f"recording file {str(spec.file)!r} not found"
    m = mirror or os.environ.get("BEARING_LAB_MIRROR")
    where = (f"not found in the mirror {m} nor the data directory" if m else
             f"not found: BEARING_LAB_MIRROR is not set (set it to the public recordings' directory, or run "
             f"`bearing-lab data fetch {spec.name}`)")
    return f"recording {spec.name!r} {where}"


def open_spec(spec, case_name, mirror=None) -> Recording:
    """Open the recording of ``spec``: checked file, channel, calibration factor, enough samples.

    Raises
    ------
    ValidationCaseError
        Missing file, a registry copy whose sha256 differs, an unknown channel, a channel that
        is not an acceleration in m s-2, or a record shorter than the compared segment.
    """
    path = locate(spec, mirror)
    if path is None:
        raise ValidationCaseError(f"validation case {case_name!r}: {missing_reason(spec, mirror)}")
    try:
        ds = open_recording(path, **spec.read_options())
    except BearingLabError as exc:
        raise ValidationCaseError(f"validation case {case_name!r}: {exc}") from None
    if spec.name:
        reg = datasets.get(spec.name)
        if reg.sha256 and ds.attrs.get("source_sha256") and ds.attrs["source_sha256"] != reg.sha256:
            raise ValidationCaseError(f"validation case {case_name!r}: {path}: sha256 does not match the "
                                      "registry's; replace the copy")
    ch = spec.channel or ds.attrs.get("default_channel") or next(iter(ds.data_vars))
    if ch not in ds.data_vars:
        raise ValidationCaseError(f"validation case {case_name!r}: {path.name} has no channel {ch!r}; its channels "
                                  f"are {', '.join(ds.data_vars)}")
    units = ds[ch].attrs.get("units")
    if units != "m s-2":
        raise ValidationCaseError(f"validation case {case_name!r}: channel {ch!r} of {path.name} is in {units!r}, "
                                  "not an acceleration (m s-2); for a voltage channel give recording.sensitivity")
    fs = float(ds.attrs["sampling_rate_hz"])
    x = np.asarray(ds[ch].values, float) * spec.scale
    need = int(round((spec.start_s + spec.duration_s) * fs))
    if x.size < need:
        raise ValidationCaseError(f"validation case {case_name!r}: {path.name} lasts {x.size / fs:.3g} s, shorter "
                                  f"than start_s + duration_s = {spec.start_s + spec.duration_s:g} s")
    return Recording(spec, ds, ch, Path(path), x, fs)
