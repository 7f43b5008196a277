"""Run a native-library reader in a child process, so a damaged file cannot crash or hang us.

Why: netCDF-C and HDF5 are C libraries that trust the metadata of the file they
open.  A few corrupted bytes in a netCDF4 file make netCDF-C loop for ever while
opening it (found by fuzzing bearing_lab's own outputs), and damaged HDF5
metadata has crashed libhdf5 in other projects.  Neither can be interrupted from
Python.  So the readers that hand a user's file to those libraries (bearing_lab
netCDF files, MATLAB v7.3 files) call :func:`guarded`: the work runs in a forked
child; the parent waits with a time limit and gets the result through a pipe.  A
child that dies, or runs past the limit, becomes one
:class:`~bearing_lab.errors.RecordingError` naming the file.

Cost: a fork and a pickle of the result (milliseconds for a recording).  Where
``fork`` is unavailable (Windows, macOS spawn default) or other Python threads run
(a fork could inherit a held lock), the work runs in-process, unguarded.
"""
from __future__ import annotations

import os
import threading

from ..errors import BearingLabError, RecordingError

DEFAULT_TIMEOUT_S = 20.0
"""Base time limit (``BEARING_LAB_READ_TIMEOUT`` overrides it); one more second is allowed per
10 MB of file.  Reading a healthy file takes a fraction of it."""


def _child(conn, func, args):
    import faulthandler
    faulthandler.disable()  # a crash is reported once, by the parent, as a RecordingError
    try:
        result = ("ok", func(*args))
    except BearingLabError as exc:
        result = ("error", type(exc).__name__, str(exc))
    except BaseException as exc:  # noqa: BLE001 - everything goes back to the parent
        result = ("error", type(exc).__name__, f"{type(exc).__name__}: {exc}")
    try:
        conn.send(result)
    except Exception as exc:  # noqa: BLE001 - an unpicklable result
        conn.send(("error", "RecordingError", f"result could not be sent back ({exc})"))
    finally:
        conn.close()


def _can_fork() -> bool:
    import multiprocessing
    return "fork" in multiprocessing.get_all_start_methods() and threading.active_count() == 1 \
        and os.environ.get("BEARING_LAB_NO_GUARD", "") in ("", "0")


def guarded(path, what: str, func, *args, timeout: float | None = None):
    """Return ``func(*args)`` computed in a child process; errors name ``path``.

    Parameters
    ----------
    path : the file being read (named in every message).
    what : the library doing the work, for messages ("netCDF-C", "HDF5").
    func, args : a module-level function and its (picklable) arguments.
    timeout : seconds (default :data:`DEFAULT_TIMEOUT_S` plus 1 s per 10 MB).
    """
    if not _can_fork():
        return func(*args)
    import multiprocessing
    if timeout is None:
        try:
            size = os.path.getsize(path)
        except OSError:
            size = 0
        base = float(os.environ.get("BEARING_LAB_READ_TIMEOUT", "") or DEFAULT_TIMEOUT_S)
        timeout = base + size / 10e6
    ctx = multiprocessing.get_context("fork")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(child, func, args), daemon=True)
    proc.start()
    child.close()
    try:
        if not parent.poll(timeout):
            proc.kill()
            raise RecordingError(f"{path}: {what} did not finish reading the file in {timeout:.0f} s "
                                 "and was stopped: its metadata are probably damaged")
        try:
            result = parent.recv()
        except (EOFError, OSError):
            proc.join(5)
            code = proc.exitcode
            how = f"signal {-code}" if code is not None and code < 0 else f"exit status {code}"
            raise RecordingError(f"{path}: {what} crashed while reading the file ({how}): the file "
                                 "is damaged") from None
    finally:
        parent.close()
        if proc.is_alive():
            proc.kill()
        proc.join(5)
    if result[0] == "ok":
        return result[1]
    _, kind, message = result
    if kind == "MemoryError":
        raise RecordingError(f"{path}: damaged sizes in the file ask for more memory than there is")
    if str(path) in message or os.path.basename(str(path)) in message:
        raise RecordingError(message)
    raise RecordingError(f"{path}: {message}")
