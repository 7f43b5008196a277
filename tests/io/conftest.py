"""Fixtures and small writers for the recording-import tests.

Synthetic files are written to tmp_path; real recordings come through the
``datafile`` fixture (tests/conftest.py) and are never copied into the repo.
"""
import warnings

import numpy as np
import pytest


@pytest.fixture
def write(tmp_path):
    """write(name, bytes_or_text) -> Path in tmp_path."""
    def _w(name, content):
        p = tmp_path / name
        p.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
        return p
    return _w


@pytest.fixture
def sine():
    t = np.arange(2000) / 1000.0
    return np.sin(2 * np.pi * 50 * t) + 0.1 * np.cos(2 * np.pi * 120 * t)


@pytest.fixture(autouse=True)
def _quiet_recording_warnings():
    from bearing_lab.io import RecordingWarning
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RecordingWarning)
        yield
