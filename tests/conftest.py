"""Shared test fixtures.

Real recordings come from the directory named by BEARING_LAB_MIRROR (CI sets it to
../shared/data).  Outside CI a missing mirror skips the data tests with the reason;
in CI (CI=true) a missing file is a failure, never a skip.

The per-user cache (contact tables, sweep results) is pointed at a fresh temporary folder
for the whole run, so no test depends on, or writes to, a user's warm cache.  The folder is
made once, by the process that starts the run, and handed to the xdist workers through the
environment (BEARING_LAB_TEST_CACHE), so a contact table that two test files need is built
once per run, not once per worker (the cache's writes are atomic, so two workers building
the same table at once both write the same complete file).  BEARING_LAB_TEST_CACHE set
beforehand names a folder to use and keep (a developer's warm runs); the tests that must
build tables cold use their own folder (tests/sim/test_halfspace.py).
"""
import os
from pathlib import Path
import tempfile

import pytest

if not os.environ.get("BEARING_LAB_TEST_CACHE"):
    # the run's first process (xdist's controller, or a plain pytest): its workers inherit this
    _RUN_CACHE = tempfile.TemporaryDirectory(prefix="bearing_lab_test_cache_")
    os.environ["BEARING_LAB_TEST_CACHE"] = _RUN_CACHE.name
os.environ["BEARING_LAB_CACHE"] = os.environ["BEARING_LAB_TEST_CACHE"]

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


@pytest.fixture
def private_table_cache(tmp_path, monkeypatch):
    """An empty cache of this test's own (no table built before it, none shared with other
    workers): for the tests that build tables cold or damage cache entries on purpose."""
    from bearing_lab.sim.defects import contact
    monkeypatch.setenv("BEARING_LAB_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(contact, "_MEMORY", {})
    return tmp_path / "cache"
