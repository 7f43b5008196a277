"""File primitives shared by every writer and cache: atomic writes, checksums, cache folder.

Why one module: a result file, a sweep-cache entry and a contact-table cache entry must
all survive a crash, a kill or a second process writing the same name.  The rule is the
same everywhere: write a temporary file in the target's directory, flush it to disk,
then rename it over the target in one step (``os.replace`` is atomic on POSIX and on
Windows within one volume).  On any failure the temporary file is removed and the old
target, if any, is left exactly as it was.  A writer killed outright (SIGKILL) leaves its
hidden temporary ``.<name>.<host>-<pid>.*``; the next successful write of the same file
removes it once that process is gone.

atomic_path(path)      -- context manager yielding a temporary path to write by name
                          (netCDF4, savefig, ...); renamed over ``path`` on success
atomic_open(path, mode) -- context manager yielding an open file object ("w", "wb", ...)
write_text(path, text)  -- atomic ``Path.write_text`` (UTF-8)
savefig(fig, path, **kw) -- atomic ``Figure.savefig`` to a file name (format from its suffix)
sha256_file(path)      -- hex digest of a file, read in 1 MiB blocks
sha256_bytes(data)     -- hex digest of bytes
cache_dir(kind)        -- per-user cache folder for ``kind`` ("tables", ...), created on use;
                          ``BEARING_LAB_CACHE`` overrides the root
"""
from __future__ import annotations

from contextlib import contextmanager
import hashlib
import os
from pathlib import Path
import socket
import stat
import tempfile
import threading

__all__ = ["atomic_path", "atomic_open", "write_text", "savefig", "sha256_file", "sha256_bytes",
           "cache_dir"]


_UMASK_LOCK = threading.Lock()
_HOST = "".join(c for c in socket.gethostname() if c.isalnum())[:16] or "host"


def _new_file_mode(path: Path) -> int:
    """The mode a plain ``open(path, "w")`` would give: the old file's, else 0o666 & ~umask.

    (``mkstemp`` creates 0o600 files; a result file must not become private by being
    written atomically.)
    """
    try:
        return stat.S_IMODE(os.stat(path).st_mode)
    except OSError:
        pass
    with _UMASK_LOCK:
        mask = os.umask(0o022)
        os.umask(mask)
    return 0o666 & ~mask


def _fsync_dir(directory: Path) -> None:
    """Flush a directory entry (the rename) to disk where the platform allows it."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


_NAME_MAX = 255  # bytes in one file name (ext4, xfs, btrfs, APFS, NTFS in UTF-16 units)


def _tmp_prefix(name: str, suffix: str) -> str:
    """``.<name>.<host>-<pid>.`` for the temporary of ``name``, short enough that the whole
    temporary name (with mkstemp's 8 random characters and ``suffix``) fits in one file name.

    A long ``name`` (up to the 255-byte limit itself) is cut and given a hash of the whole,
    so two long names that share a beginning never share temporaries; a name that is not
    valid UTF-8 (bytes from another locale) gets the same treatment, so a writer that needs
    UTF-8 names writes the temporary, and the rename gives the file its own name.
    """
    tail = f".{_HOST}-{os.getpid()}."
    # the same cut for every process (pids have at most 7 digits), so _remove_stale finds it
    room = _NAME_MAX - len(os.fsencode(f".{_HOST}-1234567." + suffix)) - 8 - 1
    raw = os.fsencode(name)
    try:
        name.encode("utf-8")
        readable = True
    except UnicodeEncodeError:  # undecodable bytes: libraries such as netCDF-C take UTF-8 names
        readable = False
    if len(raw) > room or not readable:
        digest = hashlib.sha256(raw).hexdigest()[:12]
        cut = raw[:max(room - 13, 0)].decode("utf-8", "ignore")
        name = f"{cut}~{digest}"
    return f".{name}{tail}"


@contextmanager
def atomic_path(path, *, suffix: str | None = None):
    """Yield a temporary path beside ``path``; on normal exit it replaces ``path`` atomically.

    The temporary name keeps ``path``'s suffix (some writers choose the format by it) and
    starts with a dot, so a directory listing does not show half-written files as results.
    If the block raises, the temporary file is removed and ``path`` is untouched.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> with atomic_path(d / "a.txt") as tmp:
    ...     _ = tmp.write_text("new")
    >>> (d / "a.txt").read_text()
    'new'
    """
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    suffix = suffix or path.suffix or ".tmp"
    fd, tmp_name = tempfile.mkstemp(prefix=_tmp_prefix(path.name, suffix), suffix=suffix,
                                    dir=directory)
    try:
        os.fchmod(fd, _new_file_mode(path))
    except (OSError, AttributeError):  # no fchmod (Windows): keep mkstemp's mode
        pass
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        # flush the data before the rename, so a crash cannot leave a renamed empty file
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            tmp.unlink()
        except OSError:
            pass
        raise
    _fsync_dir(directory)
    _remove_stale(directory, path.name, suffix)


def _remove_stale(directory: Path, name: str, suffix: str) -> None:
    """Delete temporaries of ``name`` left by killed writers of this host (their process is gone).

    A writer killed by SIGKILL cannot remove its temporary; the next successful write of the
    same file does, when the temporary's process id no longer runs here.
    """
    own = _tmp_prefix(name, suffix)
    prefix = own[:own.rindex(f".{_HOST}-") + len(_HOST) + 2]
    try:
        entries = [e for e in os.scandir(directory) if e.name.startswith(prefix)]
    except OSError:
        return
    for e in entries:
        pid = e.name[len(prefix):].split(".", 1)[0]
        if not pid.isdigit() or int(pid) == os.getpid() or _alive(int(pid)):
            continue
        try:
            os.unlink(e.path)
        except OSError:
            pass


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True
    return True


@contextmanager
def atomic_open(path, mode: str = "w", **kwargs):
    """Open a temporary file beside ``path`` for writing; it replaces ``path`` on normal exit."""
    if not any(c in mode for c in "wx"):
        raise ValueError(f"atomic_open is for writing; got {mode=}")
    with atomic_path(path) as tmp:
        with open(tmp, mode.replace("x", "w"), **kwargs) as fh:
            yield fh


def write_text(path, text: str, *, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically; return the path."""
    with atomic_open(path, "w", encoding=encoding) as fh:
        fh.write(text)
    return Path(path)


def savefig(fig, path, **kwargs) -> Path:
    """``fig.savefig`` to ``path`` atomically (the temporary name keeps the suffix, so the
    format is still chosen by it); return the path."""
    with atomic_path(path) as tmp:
        fig.savefig(str(tmp), **kwargs)
    return Path(path)


def sha256_file(path, *, block: int = 1 << 20) -> str:
    """Hex sha256 of the file at ``path``."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(block), b""):
            h.update(chunk)
    return h.hexdigest()


def sha256_bytes(data: bytes) -> str:
    """Hex sha256 of ``data``."""
    return hashlib.sha256(data).hexdigest()


def cache_dir(kind: str) -> Path:
    """The per-user cache folder for ``kind`` (created if missing).

    Root: ``$BEARING_LAB_CACHE`` if set, else ``$XDG_CACHE_HOME/bearing_lab`` or
    ``~/.cache/bearing_lab``.  Everything in it can be deleted at any time; it is rebuilt.
    """
    root = os.environ.get("BEARING_LAB_CACHE")
    if not root:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        root = os.path.join(base, "bearing_lab")
    d = Path(root) / kind
    d.mkdir(parents=True, exist_ok=True)
    return d
