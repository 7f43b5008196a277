"""WAV files from portable analysers and recorders, with a required calibration.

Why a calibration is required: a WAV file stores numbers relative to the
converter's full scale and nothing about volts or g.  The user says what full
scale means, either physically (``full_scale="50 g"``) or electrically
(``full_scale="5 V"`` plus ``sensitivity="9.91mV/g"``).  Read with
``scipy.io.wavfile`` (no extra dependency); integer samples are scaled by
2**(bits-1) (8-bit: offset 128), float samples are taken as ±1 full scale.
Samples at the converter's limits are reported as clipping.

Length: the RIFF header and the ``data`` chunk declare their sizes; scipy reads a
shorter file with only a warning, so :func:`_declared_frames` checks the chunk
chain first and a shortfall is refused (or kept with ``allow_truncated=True``).
"""
from __future__ import annotations

import struct
import warnings
from pathlib import Path

import numpy as np

from .. import units as _units
from ..errors import RecordingError
from ._base import ENGINES, RecordingBuilder, RecordingReader


def _declared_frames(data: bytes):
    """Return (frames the data chunk declares, problem or None).

    The chunks must tile the RIFF body exactly (a damaged size field would otherwise
    make scipy read fewer frames and ignore the rest as an unknown chunk).
    """
    order = ">" if data[:4] == b"RIFX" else "<"
    if data[:4] == b"RF64" or len(data) < 12:
        return None, None  # 64-bit sizes: left to scipy
    riff_end = struct.unpack_from(order + "I", data, 4)[0] + 8
    problem = None
    if riff_end > len(data):
        problem = f"the RIFF header declares {riff_end} bytes, the file has {len(data)}"
    elif riff_end < len(data) - 1:
        problem = f"{len(data) - riff_end} bytes after the {riff_end} the RIFF header declares"
    pos, align, frames, end = 12, None, None, min(riff_end, len(data))
    while pos + 8 <= end:
        cid, size = data[pos:pos + 4], struct.unpack_from(order + "I", data, pos + 4)[0]
        if cid == b"fmt " and size >= 14 and pos + 22 <= len(data):
            align = struct.unpack_from(order + "H", data, pos + 20)[0]
        if cid == b"data" and align:
            frames = size // align
        pos += 8 + size + (size & 1)
    if problem is None and pos not in (end, end + 1):
        problem = (f"the chunk sizes add up to {pos} bytes, the RIFF header declares {riff_end}: "
                   "a damaged size field")
    return frames, problem


_FORMAT_TAGS = {1: "PCM", 3: "IEEE float", 0xFFFE: "extensible"}


def _format_problem(data: bytes):
    """Check the ``fmt `` chunk's fields against each other; return the problem or None.

    scipy.io.wavfile picks the sample type from ``block_align`` and the channel count, so a
    ``block_align`` that disagrees with channels × bytes per sample would read int16 data as
    int8 or int32 garbage without a word, and 0 channels would end in a ZeroDivisionError: both are
    refused here.
    """
    if data[:4] not in (b"RIFF", b"RIFX") or len(data) < 12:
        return None  # RF64 and non-WAV content: left to scipy
    order = ">" if data[:4] == b"RIFX" else "<"
    pos, align = 12, None
    while pos + 8 <= len(data):
        cid, size = data[pos:pos + 4], struct.unpack_from(order + "I", data, pos + 4)[0]
        if cid == b"data":
            if align is None:
                return "the data chunk comes before the fmt chunk (or there is no fmt chunk)"
            if size % align:
                return f"the data chunk's {size} bytes are not a whole number of {align}-byte frames"
            return None
        if cid == b"fmt " and align is None:
            if size < 16 or pos + 24 > len(data):
                return f"the fmt chunk has {size} bytes, fewer than the 16 of its fields"
            tag, channels, rate, byte_rate, align, bits = struct.unpack_from(order + "HHIIHH", data,
                                                                             pos + 8)
            if tag == 0xFFFE and size >= 40 and pos + 34 <= len(data):
                tag = struct.unpack_from(order + "H", data, pos + 32)[0]  # the sub-format's tag
            if tag not in _FORMAT_TAGS:
                return (f"format tag {tag} is not PCM (1) or IEEE float (3): compressed WAV "
                        "(ADPCM, µ-law ...) is not supported; convert it to PCM")
            if channels == 0:
                return "the fmt chunk declares 0 channels"
            if bits == 0:
                return "the fmt chunk declares 0 bits per sample"
            width = (bits + 7) // 8
            if tag == 3 and bits not in (32, 64):
                return f"{bits}-bit floating-point samples are not supported (32 or 64)"
            if width not in (1, 2, 3, 4, 8):
                return f"{bits} bits per sample ({width}-byte samples) is not a PCM sample size"
            if align != channels * width:
                return (f"block_align is {align} bytes but {channels} channel(s) × {width} bytes "
                        f"({bits}-bit samples) make {channels * width}: the header is damaged "
                        "and the samples would be read with the wrong type")
            align = channels * width
            if rate == 0:
                return "the fmt chunk declares a sampling rate of 0 Hz"
        pos += 8 + size + (size & 1)
    return "no fmt chunk" if align is None else "no data chunk"


class WavReader(RecordingReader):
    """Read PCM/float WAV files with a user calibration."""

    name = "wav"
    description = "WAV (PCM or float) with a calibration: full_scale='5 V' + sensitivity, or '50 g'"
    extensions = (".wav",)
    libraries = ("scipy",)

    def guess_can_open(self, path, head):
        return head[:4] in (b"RIFF", b"RIFX", b"RF64") and head[8:12] == b"WAVE"

    def open_dataset(self, path, *, full_scale=None, sensitivity=None, channels=None,
                     allow_truncated=False, checksum=True):
        """Read a WAV file and calibrate it.

        Parameters
        ----------
        path : str or Path
        full_scale : str
            What digital full scale (1.0, or 2**(bits-1)) means: ``"5 V"`` (then
            ``sensitivity`` is needed) or a physical value such as ``"50 g"``.
        sensitivity : str, optional
            ``"9.91mV/g"`` when ``full_scale`` is a voltage.
        channels : str or list of str, optional
            ``ch1``, ``ch2`` ...
        allow_truncated : bool
            Keep the frames of a file shorter than its header declares (warning).
        checksum : bool

        Returns
        -------
        xarray.Dataset
        """
        import scipy.io.wavfile as wavfile  # loads when it reads (every reader is imported to sniff)

        path = Path(path)
        b = RecordingBuilder(path, self, sensitivity=sensitivity, checksum=checksum)
        if full_scale is None:
            b.fail("a WAV file has no physical unit: pass full_scale='5 V' with "
                   "sensitivity='9.91mV/g', or full_scale='50 g' (CLI --full-scale, --sensitivity)")
        try:
            fs_value, unit = _units.parse_quantity(full_scale)
        except RecordingError as exc:
            b.fail(str(exc))
        if not fs_value > 0:
            b.fail(f"full_scale {full_scale!r} must be positive")
        raw_bytes = path.read_bytes()
        problem = _format_problem(raw_bytes)
        if problem is not None:
            b.fail(f"not a valid WAV file: {problem}")
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                rate, data = wavfile.read(path)
            except (ValueError, EOFError, OSError, IndexError) as exc:
                b.fail(f"not a readable WAV file ({exc})")
            except UnboundLocalError:  # scipy walked the chunks without meeting fmt or data
                b.fail("not a readable WAV file: scipy finds no fmt or no data chunk inside the "
                       "size the RIFF header declares")
        data = np.asarray(data)
        if data.ndim == 1:
            data = data[:, None]
        declared, problem = _declared_frames(raw_bytes)
        if declared is not None and data.shape[0] < declared:
            b.shortfall("WAV data chunk", declared, data.shape[0], allow_truncated, unit="frames")
        elif problem is not None:
            b.shortfall(f"WAV ({problem})", data.shape[0], data.shape[0], allow_truncated,
                        unit="frames")
        for w in caught:
            if "EOF" not in str(w.message):  # a short file is reported above
                b.warn(f"WAV: {w.message}")
        kind = data.dtype.kind
        if kind == "u":
            scale, offset = 2.0 ** (8 * data.dtype.itemsize - 1), 2.0 ** (8 * data.dtype.itemsize - 1)
        elif kind == "i":
            bits = 8 * data.dtype.itemsize
            scale, offset = 2.0 ** (bits - 1), 0.0
        elif kind == "f":
            scale, offset = 1.0, 0.0
        else:
            b.fail(f"sample type {data.dtype} is not supported")
        b.attrs["wav_dtype"] = str(data.dtype)
        b.attrs["full_scale"] = str(full_scale)
        for j in range(data.shape[1]):
            raw = data[:, j]
            if kind in "iu":
                info = np.iinfo(data.dtype)
                n_clip = int(np.count_nonzero((raw == info.max) | (raw == info.min)))
                if n_clip:
                    b.warn(f"channel 'ch{j + 1}': {n_clip} samples at the converter's full scale: "
                           "clipping")
            elif np.any(np.abs(raw) >= 1.0):
                b.warn(f"channel 'ch{j + 1}': samples at or beyond ±1.0 full scale: clipping")
            x = (raw.astype(np.float64) - offset) / scale * (fs_value / unit.factor)
            b.add_channel(f"ch{j + 1}", x, unit.label, attrs={"wav_channel": j + 1})
        return b.build(fs=float(rate), channels=channels)


ENGINES["wav"] = WavReader
