"""Hostile inputs beyond flipped bytes: header fields written on purpose, hand-built MAT
elements and zlib streams, files that are not regular files, files that change while read.

Each test builds the smallest file that shows one problem and checks that the user gets one
clear RecordingError naming the file and the cause (or the right values), never a hang, a
traceback from inside a library, or data changed in silence.
"""
import os
import stat
import struct
import threading
import zlib

import numpy as np
import pytest

from bearing_lab import RecordingError, open_recording
from bearing_lab.cli import main


# ------------------------------------------------------------------ not regular files
def test_fifo_is_refused_without_opening_it(tmp_path):
    fifo = tmp_path / "p.uff"
    os.mkfifo(fifo)
    done = []

    def read():
        try:
            open_recording(fifo)
        except RecordingError as exc:
            done.append(str(exc))

    t = threading.Thread(target=read, daemon=True)
    t.start()
    t.join(10)
    if t.is_alive():  # unblock the reader before failing
        with open(fifo, "wb"):
            pass
        pytest.fail("open_recording blocks on a named pipe")
    assert done and "p.uff: is a named pipe (FIFO), not a regular file" in done[0]


def test_devices_and_pseudo_files_are_named(capsys):
    with pytest.raises(RecordingError, match=r"/dev/zero: is a character device, not a regular "):
        open_recording("/dev/zero")
    if os.path.exists("/proc/self/status"):
        with pytest.raises(RecordingError, match=r"status: reports a size of 0 bytes but has content: "
                                                 "a pseudo-file"):
            open_recording("/proc/self/status")
    assert main(["info", "/dev/urandom"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "character device" in err and "empty" not in err


def test_symlink_loop_and_dangling_link(tmp_path):
    loop = tmp_path / "loop.uff"
    loop.symlink_to(loop)
    with pytest.raises(RecordingError, match=r"loop.uff: symbolic links form a loop"):
        open_recording(loop)
    dangling = tmp_path / "gone.uff"
    dangling.symlink_to(tmp_path / "nothere.uff")
    with pytest.raises(RecordingError, match=r"gone.uff: symbolic link to .*nothere.uff, which does "
                                             "not exist"):
        open_recording(dangling)
    with pytest.raises(RecordingError, match=r"missing.uff: file not found"):
        open_recording(tmp_path / "missing.uff")


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads any file")
def test_unreadable_file(tmp_path):
    p = tmp_path / "secret.uff"
    p.write_bytes(b"    -1\n")
    p.chmod(0)
    try:
        with pytest.raises(RecordingError, match=r"secret.uff: cannot read the file \(Permission"):
            open_recording(p)
    finally:
        p.chmod(stat.S_IRUSR | stat.S_IWUSR)


# ------------------------------------------------------------------ files that change while read
def test_uff_truncated_while_read_is_refused(write, sine, monkeypatch):
    """The file is cut between the size check and the read: a message, never SIGBUS."""
    from bearing_lab.io import _base
    from bearing_lab.io._testing import uff58_block
    p = write("cut.uff", uff58_block(sine, binary=True))
    real_fstat = os.fstat
    calls = []

    def fstat_then_truncate(fd):
        st = real_fstat(fd)
        if not calls:  # another program truncates the file right after it was opened
            os.truncate(p, 1000)
        calls.append(st.st_size)
        return st

    monkeypatch.setattr(_base.os, "fstat", fstat_then_truncate)
    with pytest.raises(RecordingError, match=r"cut.uff: the file changed while it was read \(\d+ "
                                             r"bytes when opened, 1000 read, 1000 now\)"):
        open_recording(p, format="uff58")


def test_uff_reader_does_not_map_the_file(write, sine, monkeypatch):
    """A mapped file truncated by another program kills the process (SIGBUS): no mmap."""
    import mmap
    from bearing_lab.io._testing import uff58_block
    p = write("m.uff", uff58_block(sine, binary=True))

    def no_map(*a, **k):
        raise AssertionError("the reader maps the file")

    monkeypatch.setattr(mmap, "mmap", no_map)
    np.testing.assert_array_equal(open_recording(p)["acc"].values, sine)
