"""Atomic writes: the old file survives any failure; the new one appears whole or not at all."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from bearing_lab.utils._files import atomic_open, atomic_path, cache_dir, sha256_file


def test_atomic_path_replaces_on_success(tmp_path):
    target = tmp_path / "out.nc"
    target.write_text("old")
    with atomic_path(target) as tmp:
        assert tmp.parent == tmp_path and tmp.suffix == ".nc"
        tmp.write_text("new")
        assert target.read_text() == "old"          # not visible before the block ends
    assert target.read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.nc"]


def test_atomic_path_keeps_old_file_on_error(tmp_path):
    target = tmp_path / "keep.nc"
    target.write_text("PRECIOUS")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("partial")
            raise RuntimeError("writer failed")
    assert target.read_text() == "PRECIOUS"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.nc"]


def test_atomic_open_text(tmp_path):
    target = tmp_path / "a.json"
    with atomic_open(target, "w") as fh:
        fh.write("{}")
    assert target.read_text() == "{}"
    with pytest.raises(ValueError):
        with atomic_open(target, "r"):
            pass


def test_killed_writer_leaves_old_file(tmp_path):
    """SIGKILL in the middle of a write: the target keeps its old content."""
    target = tmp_path / "keep.bin"
    target.write_bytes(b"PRECIOUS")
    code = textwrap.dedent(f"""
        import os, signal
        from bearing_lab.utils._files import atomic_path
        with atomic_path({str(target)!r}) as tmp:
            tmp.write_bytes(b"x" * 100000)
            os.kill(os.getpid(), signal.SIGKILL)
    """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True)
    assert r.returncode != 0
    assert target.read_bytes() == b"PRECIOUS"


def test_sha256_and_cache_dir(tmp_path, monkeypatch):
    f = tmp_path / "f"
    f.write_bytes(b"abc")
    # FIPS 180-2 test vector for "abc"
    assert sha256_file(f) == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
    monkeypatch.setenv("BEARING_LAB_CACHE", str(tmp_path / "c"))
    d = cache_dir("tables")
    assert d == tmp_path / "c" / "tables" and d.is_dir() and os.access(d, os.W_OK)


def test_atomic_write_keeps_the_usual_file_mode(tmp_path):
    """A new file gets 0o666 & ~umask like open(); a replaced file keeps its mode."""
    mask = os.umask(0o022)
    os.umask(mask)
    new = tmp_path / "new.txt"
    with atomic_open(new) as fh:
        fh.write("x")
    assert (new.stat().st_mode & 0o777) == 0o666 & ~mask
    old = tmp_path / "old.txt"
    old.write_text("a")
    old.chmod(0o640)
    with atomic_open(old) as fh:
        fh.write("b")
    assert (old.stat().st_mode & 0o777) == 0o640


def test_temporaries_of_killed_writers_are_removed_by_the_next_write(tmp_path):
    """A SIGKILLed writer cannot clean up; the next successful write of the file does."""
    target = tmp_path / "out.nc"
    code = textwrap.dedent(f"""
        import os, signal
        from bearing_lab.utils._files import atomic_path
        with atomic_path({str(target)!r}) as tmp:
            tmp.write_bytes(b"partial")
            os.kill(os.getpid(), signal.SIGKILL)
    """)
    for _ in range(2):
        subprocess.run([sys.executable, "-c", code], capture_output=True)
    assert len([p for p in tmp_path.iterdir() if p.name.startswith(".out.nc.")]) == 2
    with atomic_open(target, "w") as fh:
        fh.write("whole")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.nc"]
