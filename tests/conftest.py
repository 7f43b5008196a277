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

#: test files whose work is longest, started first so that under `make test` (one file per worker, files
#: handed out in this order: --no-loadscope-reorder) no worker is left with a long file at the end: the
#: identification (its module fixture is most of the suite's CPU); the other files follow by their number of
#: tests, as xdist's default ordering had them
FIRST = ("validation/test_identify.py",)


def pytest_collection_modifyitems(config, items):
    """Files in FIRST first, then the others by their number of tests, most first (what xdist's
    default --loadscope-reorder did), keeping the order of tests inside a file."""
    if not hasattr(config, "workerinput"):
        return                      # a plain (serial) run keeps the collection order
    root = Path(__file__).resolve().parent

    def rel(item):
        try:
            return Path(str(item.path)).resolve().relative_to(root).as_posix()
        except ValueError:
            return str(item.path)
    count = {}
    for it in items:
        count[rel(it)] = count.get(rel(it), 0) + 1
    rank = {f: i for i, f in enumerate(FIRST)}
    items.sort(key=lambda it: (rank.get(rel(it), len(FIRST)), -count[rel(it)] if rel(it) not in rank else 0))

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
