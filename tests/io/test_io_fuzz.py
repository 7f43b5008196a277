"""Fuzz every reader with seeded mutants of real recordings, each read in a guarded subprocess.

Per source a hundred to about 1 500 mutants (flipped bytes, cut lengths, deleted and
inserted spans, damaged size words, edited text tokens): MATLAB v5 1 450 (CWRU, MFPT,
Testlab), v7.3 300 (HDF5, 30 ms each), UFF 58/58b 5 050 (six real files), IMS text 1 000,
TDMS 1 350, Testlab text 500, CSV 450, MDF4 200, WAV and netCDF 100 each: 10 500 in all.  A worker process reads them under a time and memory limit; the parent survives its
crashes.  The rule, for every mutant: only a RecordingError naming the file may escape; no
crash, hang or runaway memory; what reads has the original's channels and length (a format
that declares its length) and valid values; a pure truncation never reads as changed data.
``benchmarks/fuzz_readers.py`` runs the same harness over more than 20 000 mutants.
"""
import os

import pytest

from bearing_lab.io import _fuzz

# mutants per source, the format totals in the module docstring; the seed changes with nothing (a failure is
# reproducible by index: python -m bearing_lab.io._fuzz repro SOURCE 2026 INDEX).  Each source's count is the
# first mutants that reach every pair (mutation, verdict) and every kind of refusal (the reader's message without
# its numbers and quoted bytes, and the exception it wraps) that the earlier plan of 16 600 (600 to 2 500 a
# source) reached with this seed, plus a quarter, in fifties; the sources whose last new kind came late keep their
# count (IMS, v7.3, Testlab text, the UFF microphone, catman and truncated files).  All 16 600 read without a bad verdict.
# The long run, benchmarks/fuzz_readers.py, reads 21 000 with another seed.
SEED = 2026
PLAN = {"cwru": 150, "cwru_48k": 450, "mfpt": 200, "testlab_v5": 650, "testlab_v73": 300,
        "uff58b_4ch": 450, "uff58b_mic": 1000, "uff58b_g": 1450, "uff58_ascii": 150,
        "uff58_catman": 1000, "uff58_truncated": 1000, "ims": 1000, "tdms": 1350, "wav": 100,
        "netcdf": 100, "csv": 450, "testlab_text": 500, "mdf": 200}


@pytest.fixture(autouse=True)
def _mirror_env(mirror, monkeypatch, datafile):
    datafile("lms/binary8byte_g.uff")  # fails in CI, skips elsewhere, when there is no mirror
    monkeypatch.setenv("BEARING_LAB_MIRROR", str(mirror))


def _report(res):
    lines = [f"{res['source']}: {res['counts']}"]
    for verdict, examples in res["examples"].items():
        for e in examples[:5]:
            lines.append(f"  {verdict} #{e['i']} ({e['op']}): {e['detail']}")
    return "\n".join(lines)


@pytest.mark.parametrize("name", sorted(PLAN))
def test_fuzz_source(name):
    res = _fuzz.fuzz_source(name, PLAN[name], seed=SEED, timeout=60.0)
    bad = {v: res["counts"][v] for v in _fuzz.BAD if res["counts"][v]}
    assert not bad, _report(res)
    # the mutants must reach both outcomes, or the test exercises nothing
    assert res["counts"]["refused"] > 0 and res["counts"]["ok"] + res["counts"]["renamed"] > 0, \
        _report(res)


def test_harness_sees_every_kind_of_failure(monkeypatch):
    """Injected faults: a segfault, a hang, a foreign exception and a silent shortening."""
    monkeypatch.setenv("BEARING_LAB_FUZZ_FAULTS", "crash=2,hang=4,uncaught=6,silent=8")
    res = _fuzz.fuzz_source("uff58b_g", 10, seed=SEED, timeout=4.0)
    c = res["counts"]
    assert (c["crash"], c["hang"], c["uncaught"], c["silent"]) == (1, 1, 1, 1), _report(res)
    assert sum(c.values()) == 10
    assert [e["i"] for e in res["examples"]["crash"]] == [2]


def test_mutants_are_reproducible():
    source = _fuzz.SOURCES["uff58b_g"]
    data = bytes(range(256)) * 8
    hot = _fuzz.hot_spots(data, source.fmt)
    a = _fuzz.mutant(source, data, hot, SEED, 17)
    assert a == _fuzz.mutant(source, data, hot, SEED, 17)
    assert a != _fuzz.mutant(source, data, hot, SEED, 18)


def test_verdicts_judge_against_the_original(tmp_path, datafile):
    """A shortened file that reads is 'silent'; the original itself is 'ok'."""
    import numpy as np
    from bearing_lab.io import open_recording
    src = datafile("lms/binary8byte_g.uff")
    ref = open_recording(src)
    source = _fuzz.SOURCES["uff58b_g"]
    assert _fuzz.verdict(src, source, ref, truncation=False) == ("ok", "")
    short = ref.isel(time=slice(0, 100))

    class Fake:
        name, options, declared_length = "x", {}, True

    verdict, detail = _fuzz.verdict(src, Fake, short, truncation=False)
    assert verdict == "silent" and "250 samples instead of 100" in detail
    assert os.environ.get("BEARING_LAB_MIRROR")
    assert np.isfinite(ref[list(ref.data_vars)[0]].values).all()
