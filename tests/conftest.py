"""Shared test fixtures.

Real recordings come from the directory named by BEARING_LAB_MIRROR (CI sets it to
../shared/data).  Outside CI a missing mirror skips the data tests with the reason;
in CI (CI=true) a missing file is a failure, never a skip.

The per-user cache (contact tables, sweep results) is pointed at a fresh temporary folder
for the whole session, so no test depends on, or writes to, a user's warm cache.
"""
import os
from pathlib import Path
import tempfile

import pytest

_SESSION_CACHE = tempfile.TemporaryDirectory(prefix="bearing_lab_test_cache_")
os.environ["BEARING_LAB_CACHE"] = _SESSION_CACHE.name

IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")


def _mirror() -> Path | None:
    env = os.environ.get("BEARING_LAB_MIRROR")
    if env:
        return Path(env)
    guess = Path(__file__).resolve().parents[1].parent / "shared" / "data"
    return guess if guess.is_dir() else None


@pytest.fixture(scope="session")
def mirror() -> Path:
    return _mirror()


@pytest.fixture(scope="session")
def datafile(mirror):
    """datafile('cwru/130_OR007@6_0.mat') -> Path; fails in CI if missing."""
    def get(rel: str) -> Path:
        if mirror is None:
            if IN_CI:
                pytest.fail("BEARING_LAB_MIRROR is not set in CI")
            pytest.skip("no BEARING_LAB_MIRROR: public recordings not available")
        p = mirror / rel
        if not p.is_file():
            if IN_CI:
                pytest.fail(f"recording {p} missing from the mirror")
            pytest.skip(f"recording {p} missing from the mirror")
        return p
    return get
