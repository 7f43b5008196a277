"""Run a native-library reader in a child process, so a damaged file cannot crash or hang us.

Why: netCDF-C and HDF5 are C libraries that trust the metadata of the file they
open.  A few corrupted bytes in a netCDF4 file make netCDF-C loop for ever while
opening it (found by fuzzing bearing_lab's own outputs), and damaged HDF5
metadata has crashed libhdf5 in other projects.  Neither can be interrupted from
Python.  So the readers that hand a user's file to those libraries (bearing_lab
netCDF files, MATLAB v7.3 files) call :func:`guarded`: the work runs in a child
process; the parent waits with a time limit and gets the result through a pipe.  A
child that dies, or runs past the limit, becomes one
:class:`~bearing_lab.errors.RecordingError` naming the file.

Cost: on Linux the children come from multiprocessing's fork server, which is started
once (about a second, with the readers' modules imported) and then forks a clean
single-threaded child in milliseconds; elsewhere each read spawns an interpreter.
``BEARING_LAB_NO_GUARD=1`` reads in-process (unguarded), e.g. for debugging.
"""
from __future__ import annotations

import contextlib
import faulthandler
import os
import threading

from ..errors import BearingLabError, RecordingError

DEFAULT_TIMEOUT_S = 20.0
"""Base time limit (``BEARING_LAB_READ_TIMEOUT`` overrides it); one more second is allowed per
10 MB of file.  Reading a healthy file takes a fraction of it."""


def _child(conn, func, args):
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


_PRELOAD = ["bearing_lab.io.netcdf", "bearing_lab.io._matlab", "xarray", "netCDF4", "h5py"]


def _context():
    """A fresh single-threaded process for each read: a child of the fork server (Linux),
    else a spawned interpreter.  Never a plain fork of this process: other threads of it
    (Dask, tqdm, a notebook) may hold locks, which the copy would inherit held."""
    import multiprocessing  # 8 ms that a read without a child process does not pay
    if "forkserver" in multiprocessing.get_all_start_methods():
        ctx = multiprocessing.get_context("forkserver")
        ctx.set_forkserver_preload(_PRELOAD)  # once the server runs, children start in ms
        return ctx
    return multiprocessing.get_context("spawn")


_START_LOCK = threading.Lock()


@contextlib.contextmanager
def _without_main():
    """Start children that do not import the caller's ``__main__``.

    multiprocessing tells a fork-server or spawned child to run the parent's main script
    again (as ``__mp_main__``) so that functions defined there can be unpickled.  The
    function run here lives in bearing_lab, so the child never needs the script; and a
    script without ``if __name__ == "__main__":`` would run itself once more in the child,
    open its file again, and make the read look like a crash of the C library.  The
    preparation data therefore leave the main module out (for this start only, under a lock).
    """
    from multiprocessing import spawn  # 8 ms that a read without a child process does not pay
    with _START_LOCK:
        original = spawn.get_preparation_data

        def prepared(name):
            data = original(name)
            data.pop("init_main_from_path", None)
            data.pop("init_main_from_name", None)
            return data

        spawn.get_preparation_data = prepared
        try:
            yield
        finally:
            spawn.get_preparation_data = original


def guarded(path, what: str, func, *args, timeout: float | None = None):
    """Return ``func(*args)`` computed in a child process; errors name ``path``.

    Parameters
    ----------
    path : the file being read (named in every message).
    what : the library doing the work, for messages ("netCDF-C", "HDF5").
    func, args : a module-level function and its (picklable) arguments.
    timeout : seconds (default :data:`DEFAULT_TIMEOUT_S` plus 1 s per 10 MB).
    """
    if os.environ.get("BEARING_LAB_NO_GUARD", "") not in ("", "0"):
        return func(*args)
    if timeout is None:
        try:
            size = os.path.getsize(path)
        except OSError:
            size = 0
        base = float(os.environ.get("BEARING_LAB_READ_TIMEOUT", "") or DEFAULT_TIMEOUT_S)
        timeout = base + size / 10e6
    ctx = _context()
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(child, func, args), daemon=True)
    with _without_main():
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
            if code is not None and code < 0:
                raise RecordingError(f"{path}: {what} crashed while reading the file (signal "
                                     f"{-code}): the file is damaged") from None
            raise RecordingError(f"{path}: the process reading the file with {what} ended with exit "
                                 f"status {code} before it answered (not a crash on the file); if "
                                 "a script of yours runs this, put its top-level code under "
                                 "if __name__ == '__main__':") from None
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
