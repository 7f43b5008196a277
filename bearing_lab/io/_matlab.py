"""MATLAB file access shared by the Testlab, CWRU and MFPT readers.

Why: the three formats are all ``.mat`` files and are told apart only by their
variable names, so sniffing lists variables (cheaply, cached) and reading turns
both v5 (our bounds-checked :mod:`._mat5`) and v7.3 (HDF5, h5py) into the same
plain Python structure: structs -> dict, char arrays -> str, numeric arrays ->
squeezed ndarray.  Field order differs between files, so readers always look
fields up by name.  v5 files are not handed to ``scipy.io.loadmat``: its
compiled reader crashes the process (segmentation fault) on some corrupt files.
"""
from __future__ import annotations

import functools
import struct
import zlib
from pathlib import Path

import numpy as np

from ..errors import RecordingError

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def mat_version(head: bytes) -> str | None:
    """Return "5" (v5/v7, scipy), "7.3" (HDF5) or None from the first bytes."""
    if not head.startswith(b"MATLAB"):
        return None
    if b"MATLAB 7.3" in head[:128] or head[512:520] == HDF5_SIGNATURE:
        return "7.3"
    return "5"


def require_matlab(path, b) -> str:
    """The file's MATLAB version (:func:`mat_version`), or ``b.fail`` naming a file that is not one."""
    with open(path, "rb") as fh:
        version = mat_version(fh.read(1024))
    if version is None:
        b.fail("not a MATLAB file (no 'MATLAB' header)")
    return version


def _h5_names(path: str) -> tuple[str, ...]:
    """Variable names of a v7.3 file (runs in the guarded child)."""
    import h5py  # loads when it reads (every reader is imported to sniff)
    try:
        with h5py.File(path, "r") as f:
            return tuple(k for k in f.keys() if not k.startswith("#"))
    except _ERRORS as exc:
        raise _corrupt(path, exc) from None


def _h5_load(path: str, variable_names) -> dict:
    """Variables of a v7.3 file as plain Python (runs in the guarded child)."""
    import h5py  # loads when it reads (every reader is imported to sniff)
    out = {}
    try:
        with h5py.File(path, "r") as f:
            for k in f.keys():
                if k.startswith("#") or (variable_names and k not in variable_names):
                    continue
                out[k] = _h5_plain(f, f[k])
    except (*_ERRORS, RecursionError) as exc:
        raise _corrupt(path, exc) from None
    return out


@functools.lru_cache(maxsize=64)
def _variables(path: str, mtime: int, size: int, inode: int) -> tuple[str, ...]:
    with open(path, "rb") as fh:
        head = fh.read(1024)
    v = mat_version(head)
    if v == "7.3":  # libhdf5 reads the file in a child process: damage cannot crash us
        from ._guard import guarded  # the child-process guard for a v7.3 file only: io imports this module
        return guarded(path, "HDF5", _h5_names, path)
    if v == "5":
        from . import _mat5  # _mat5 (6 ms) loads for a MATLAB file only: io imports this module
        return tuple(_mat5.variable_names(Path(path).read_bytes()))
    return ()


def _corrupt(path, exc):
    from ._mat5 import Mat5Error  # _mat5 (6 ms) loads for a MATLAB file only: io imports this module
    why = str(exc) if isinstance(exc, Mat5Error) else f"{type(exc).__name__}: {exc}"
    return RecordingError(f"{path}: the MATLAB file is truncated or corrupt ({why}); export or "
                          "download it again")


_ERRORS = (OSError, ValueError, TypeError, KeyError, IndexError, EOFError, AttributeError,
           NotImplementedError, zlib.error, struct.error, UnicodeDecodeError, OverflowError)


def mat_variables(path) -> tuple[str, ...]:
    """Return the variable names of a MATLAB file (empty if it is not one).

    Raises
    ------
    RecordingError
        If the file says it is a MATLAB file but its variable table is unreadable.
    """
    p = Path(path)
    st = p.stat()
    try:
        return _variables(str(p), st.st_mtime_ns, st.st_size, st.st_ino)
    except RecordingError:
        raise
    except _ERRORS as exc:
        raise _corrupt(p, exc) from exc


def _h5_plain(f, obj):
    import h5py  # loads when it reads (every reader is imported to sniff)
    if isinstance(obj, h5py.Group):
        return {k: _h5_plain(f, obj[k]) for k in obj.keys() if not k.startswith("#")}
    cls = obj.attrs.get("MATLAB_class", b"")
    cls = cls.decode() if isinstance(cls, bytes) else str(cls)
    if obj.attrs.get("MATLAB_empty", 0):
        return "" if cls == "char" else np.empty(0)
    data = obj[()]
    if obj.dtype.kind == "O" or obj.dtype == h5py.ref_dtype:
        return [_h5_plain(f, f[r]) for r in np.asarray(data).ravel()]
    if cls == "char":
        arr = np.asarray(data, dtype=np.uint16).T
        if arr.ndim == 2 and min(arr.shape) > 1:
            return ["".join(map(chr, row)).rstrip("\x00") for row in arr]
        return "".join(map(chr, arr.ravel()))
    arr = np.asarray(data)
    if arr.ndim >= 2:
        arr = arr.T
    arr = np.squeeze(arr)
    if cls == "logical":
        arr = arr.astype(bool)
    return arr


def load_mat(path, variable_names=None) -> dict:
    """Load a MATLAB file (v5 or v7.3) as plain Python objects.

    Parameters
    ----------
    path : str or Path
    variable_names : list of str, optional
        Load only these variables.

    Returns
    -------
    dict
        Variable name -> value (structs as dicts, strings as str, arrays squeezed).
    """
    try:
        return _load_mat(path, variable_names)
    except RecordingError:
        raise
    except _ERRORS as exc:
        raise _corrupt(path, exc) from exc


def _load_mat(path, variable_names):
    with open(path, "rb") as fh:
        head = fh.read(1024)
    v = mat_version(head)
    if v == "7.3":
        from ._guard import guarded  # the child-process guard for a v7.3 file only: io imports this module
        names = tuple(variable_names) if variable_names else None
        return guarded(path, "HDF5", _h5_load, str(path), names)
    from . import _mat5  # _mat5 (6 ms) loads for a MATLAB file only: io imports this module
    return _mat5.load(Path(path).read_bytes(), variable_names=variable_names)


def signal_vector(builder, value, name: str) -> np.ndarray:
    """One channel from a MATLAB variable: a real numeric vector, as float64.

    A matrix is refused, not flattened: MATLAB stores an N×2 matrix column by column, and
    ``ravel`` (row-major) would silently interleave its two columns into one channel of 2N
    samples.  Complex values are refused, not cut to their real part.  ``builder`` names
    the file in the message (:meth:`RecordingBuilder.fail`).
    """
    arr = np.asarray(value)
    if arr.dtype.kind == "c":
        builder.fail(f"variable {name!r} holds complex values ({arr.dtype}); a recorded time "
                     "signal is real: not a recording channel")
    if arr.dtype.kind not in "iuf":
        what = "text" if isinstance(value, str) else f"{arr.dtype} values"
        builder.fail(f"variable {name!r} holds {what}, not numbers")
    if arr.ndim > 1:
        dims = "×".join(map(str, arr.shape))
        builder.fail(f"variable {name!r} is a {dims} matrix, not one channel: read as one it "
                     "would interleave its columns; save each channel as a vector of its own")
    return arr.astype(np.float64, copy=False).reshape(-1)
