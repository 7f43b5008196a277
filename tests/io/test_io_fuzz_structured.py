"""Structure-aware mutants: header fields, MAT elements and zlib streams, h5py v7.3 files, foreign
netCDF, WAV format fields, UFF increments and units sets, and files that are not regular files.

Each case changes one field on purpose; every file a reader accepts is compared with an
independent decoder of the same bytes (scipy.io.loadmat, h5py, netCDF4, a numpy decode of the
WAV data chunk under validated fmt fields, pyuff), so a silent change fails by construction.
The rule: no crash, hang, traceback or silent change; each kind reaches both outcomes (read and
equal, refused).  ``benchmarks/hostile_inputs.py --structured`` runs the full set.
"""
import pytest

from bearing_lab.io import _fuzz, _fuzz_struct

SEED = 2026
PLAN = {"mat5": 120, "v73": 30, "netcdf": 24, "wav": 120, "uff": 120, "special": 40}
BAD = ("uncaught", "silent", "invalid", "crash", "hang")


def _report(res):
    lines = [f"{res['kind']}: {res['counts']}"]
    for verdict, examples in res["examples"].items():
        lines += [f"  {verdict} #{e['i']} ({e['op']}): {e['detail']}" for e in examples[:5]]
    return "\n".join(lines)


@pytest.mark.parametrize("kind", sorted(PLAN))
def test_structured_mutants(kind):
    res = _fuzz_struct.fuzz_structured(kind, PLAN[kind], seed=SEED, timeout=60.0)
    c = res["counts"]
    assert not any(c[v] for v in BAD), _report(res)
    assert c["refused"] > 0, _report(res)
    if kind != "special":  # every special file is refused; the others must also be read
        assert c["ok"] > 0, _report(res)


def test_verdict_catches_a_silent_change(tmp_path, monkeypatch):
    """The comparison with the independent decoder sees a value the reader changed."""
    index = next(i for i in range(200) if "[none]" in _fuzz_struct.structured_case("wav", SEED, i, tmp_path)[2])
    p, options, _ = _fuzz_struct.structured_case("wav", SEED, index, tmp_path)  # every field nominal
    assert _fuzz_struct.structured_verdict(p, options, "wav") == ("ok", "")
    real = _fuzz._open_quietly

    def changed(path, opts):
        ds = real(path, opts)
        ds["ch2"].values[5] *= 1.01
        return ds

    monkeypatch.setattr(_fuzz, "_open_quietly", changed)
    verdict, detail = _fuzz_struct.structured_verdict(p, options, "wav")
    assert verdict == "silent" and "ch2" in detail


def test_structured_cases_are_reproducible(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    a = _fuzz_struct.structured_case("mat5", SEED, 7, tmp_path / "a")
    b = _fuzz_struct.structured_case("mat5", SEED, 7, tmp_path / "b")
    assert a[0].read_bytes() == b[0].read_bytes() and a[2] == b[2]
    c = _fuzz_struct.structured_case("mat5", SEED, 8, tmp_path / "b")
    assert (c[0].read_bytes(), c[2]) != (a[0].read_bytes(), a[2])
