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
import fcntl
import json
import os
from pathlib import Path
from types import SimpleNamespace
import tempfile

import pytest

if not os.environ.get("BEARING_LAB_TEST_CACHE"):
    # the run's first process (xdist's controller, or a plain pytest): its workers inherit this
    _RUN_CACHE = tempfile.TemporaryDirectory(prefix="bearing_lab_test_cache_")
    os.environ["BEARING_LAB_TEST_CACHE"] = _RUN_CACHE.name
os.environ["BEARING_LAB_CACHE"] = os.environ["BEARING_LAB_TEST_CACHE"]
if not os.environ.get("PYTEST_XDIST_WORKER"):
    # this run's own folder for outputs that several test files share (never kept between runs, unlike
    # BEARING_LAB_TEST_CACHE: a result of the code under test is not reused by a later run of other code)
    _RUN_SHARED = tempfile.TemporaryDirectory(prefix="bearing_lab_test_run_")
    os.environ["BEARING_LAB_TEST_RUN_DIR"] = _RUN_SHARED.name

#: test files whose work is longest, started first so that under `make test` (one file per worker, files
#: handed out in this order: --no-loadscope-reorder) no worker is left with a long file at the end: the
#: identification (its module fixture is most of the suite's CPU)
FIRST = ("validation/test_identify.py",)
#: then, on the other worker, the long files that compile no simulation kernel in this process, while the
#: identification compiles its kernels into the numba cache (NUMBA_CACHE_DIR) that later files load instead of
#: compiling them again (a fresh clone's cache is empty: the four sim files test_physics, test_bearing3d,
#: test_axial_preload and test_scene_budget cost 67 s of CPU with it empty, 17 s with it filled)
NO_KERNELS = ("io/test_io_fuzz.py", "test_wheel_install.py", "test_architecture.py",
              "analysis/test_analysis_recordings.py", "analysis/test_analysis_impulse.py",
              "io/test_io_fuzz_structured.py")
#: then the others that cost most, longest first (CPU s of each alone, in a full run on a loaded machine); the
#: ones whose child processes load the kernels (benchmark runner, docs build, notebooks, scene budget) last of
#: these, when more of the kernels are in the cache.  The README tour comes first: it makes the run's shared
#: validation of the default set (DEFAULT_VALIDATION_ARGS below) that the files in LAST read
LONGEST = ("test_readme.py", "sim/test_physics.py", "validation/test_candidate_ranking.py",
           "validation/test_walkthrough.py", "validation/test_perfect_model.py", "validation/test_identify_run.py",
           "validation/test_structural_path.py", "sim/test_halfspace.py", "sim/test_hard_cases.py",
           "sim/test_dynamic_cage.py", "test_sweep.py", "sim/test_bearing3d.py", "io/test_io_integrity.py",
           "sim/test_axial_preload.py", "sim/test_defect_dynamics.py", "test_benchmarks_registry.py",
           "validation/test_validation_notebooks.py", "sim/test_scene_budget.py", "test_api_docs.py")
#: last, after every other file: the files that only read the shared validation, so that the README tour (the first
#: of LONGEST) has made it by then and no worker waits for it
LAST = ("validation/test_cwru_cases.py", "validation/test_verdict_table.py")


def pytest_collection_modifyitems(config, items):
    """Files in FIRST, NO_KERNELS and LONGEST first, in that order, then the others by their number of tests,
    most first (what xdist's default --loadscope-reorder did), then LAST, keeping the order of tests inside a
    file."""
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
    ordered = FIRST + NO_KERNELS + LONGEST
    rank = {f: i for i, f in enumerate(ordered)}
    last = {f: len(ordered) + 1 + i for i, f in enumerate(LAST)}
    items.sort(key=lambda it: (last.get(rel(it), rank.get(rel(it), len(ordered))),
                               -count[rel(it)] if rel(it) not in rank else 0))

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


#: the README tour's validation line: the embedded default set (the paper case and the CWRU cases), run once per
#: test run and read by the tests that check it (tests/test_readme.py's tour, tests/validation/test_verdict_table.py,
#: tests/validation/test_cwru_cases.py).  It starts with no structural path remembered from an earlier test of the
#: same worker, as the fresh process of a user's `bearing-lab validate` does; test_cwru_cases checks that cwru-105,
#: which runs before cwru-130 in the default set's order, is compared through the path cwru-130's own report shows
DEFAULT_VALIDATION_ARGS = ("validate", "-o", "reports")
DEFAULT_SET_RECORDINGS = ("cwru/97_Normal_0.mat", "cwru/105_IR007_0.mat", "cwru/130_OR007@6_0.mat",
                          "cwru/144_OR007@3_0.mat", "cwru/234_OR021@6_0.mat")


def _run_default_validation(where: Path, mirror: Path) -> int:
    """`bearing-lab validate -o reports` as the tour types it: in a fresh folder beside ``shared/data`` (a link
    to the mirror), no progress bars; returns its exit status."""
    from bearing_lab.cli import main
    from bearing_lab.validation import rig
    rig._CACHE.clear()
    clone = where / "clone"
    clone.mkdir(parents=True)
    (where / "shared").mkdir()
    (where / "shared" / "data").symlink_to(Path(mirror).resolve())
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(clone)
        mp.setenv("BEARING_LAB_PROGRESS", "0")
        mp.setenv("BEARING_LAB_MIRROR", str(mirror))
        return main(list(DEFAULT_VALIDATION_ARGS))


@pytest.fixture(scope="session")
def default_validation(datafile, mirror):
    """The default set validated once for the whole run (the first worker that needs it runs it; another waits
    for it and reads the same folder): ``.reports`` (the report folder), ``.status`` (the command's exit
    status), ``.args`` (the command line after ``bearing-lab``)."""
    for rel in DEFAULT_SET_RECORDINGS:
        datafile(rel)                    # fails in CI, skips elsewhere, when a recording is missing
    where = Path(os.environ["BEARING_LAB_TEST_RUN_DIR"]) / "default_validation"
    where.parent.mkdir(parents=True, exist_ok=True)
    done = where.parent / "default_validation.json"
    with open(where.parent / "default_validation.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)          # released when the file closes, also on an error
        if not done.is_file():
            if where.exists():                    # a run that raised: start again, not from its leftovers
                import shutil
                shutil.rmtree(where)
            status = _run_default_validation(where, mirror)
            done.write_text(json.dumps({"status": status}))
    return SimpleNamespace(reports=where / "clone" / "reports", status=json.loads(done.read_text())["status"],
                           args=DEFAULT_VALIDATION_ARGS)
