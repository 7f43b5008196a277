"""Data registry: conditions, CWRU rates, fetch from a mirror with hash check."""
from pathlib import Path

import pytest

from bearing_lab import RecordingError, datasets


def test_registry_covers_mirror_and_cwru_12k(mirror):
    reg = datasets.load_registry()
    de12 = [r for r in reg.values() if r.dataset == "cwru-de-12k"]
    assert len(de12) == 60 and all(r.fs_hz == 12000 and r.url for r in de12)
    assert {r.defect for r in de12} == {"inner_race", "ball", "outer_race"}
    assert datasets.cwru_sampling_rate(97) == 48000 and datasets.cwru_sampling_rate(130) == 12000
    assert datasets.cwru_sampling_rate(12345) is None
    if mirror is not None:
        files = sorted(str(p.relative_to(mirror)) for p in Path(mirror).glob("*/*") if p.is_file())
        for f in files:
            assert f in reg, f"{f} missing from data/recordings.csv"
            assert len(reg[f].sha256) == 64
    r = datasets.get("130_OR007@6_0.mat")
    assert (r.rpm, r.load_hp, r.defect, r.defect_size_in, r.defect_position) == \
        (1796, 0, "outer_race", 0.007, "@6:00")


def test_fetch_from_mirror(datafile, mirror, tmp_path):
    datafile("cwru/118_B007_0.mat")
    p = datasets.fetch("cwru/118_B007_0.mat", mirror=mirror, dest=tmp_path, download=False)
    assert p == tmp_path / "cwru/118_B007_0.mat" and p.stat().st_size > 0
    assert datasets.fetch("118_B007_0.mat", mirror=mirror, dest=tmp_path) == p  # already there


def test_fetch_hash_mismatch(tmp_path):
    fake = tmp_path / "mirror" / "lms"
    fake.mkdir(parents=True)
    (fake / "binary8byte_g.uff").write_bytes(b"not the file")
    with pytest.raises(RecordingError, match="sha256 .* does not match"):
        datasets.fetch("lms/binary8byte_g.uff", mirror=tmp_path / "mirror", dest=tmp_path / "d")


def test_fetch_missing_without_network(tmp_path, monkeypatch):
    import pooch

    def boom(*a, **k):
        raise ConnectionError("no network")
    monkeypatch.setattr(pooch, "retrieve", boom)
    with pytest.raises(RecordingError, match="download from https://engineering.case.edu.* failed"):
        datasets.fetch("cwru/131_OR007@6_1.mat", mirror=tmp_path, dest=tmp_path / "d")
    with pytest.raises(RecordingError, match="not in mirror"):
        datasets.fetch("cwru/131_OR007@6_1.mat", mirror=tmp_path, dest=tmp_path / "d",
                       download=False)
    with pytest.raises(RecordingError, match="no registered recording 'nope.mat'"):
        datasets.fetch("nope.mat")


def test_pooch_registry():
    reg = datasets.pooch_registry()
    assert reg["cwru/130_OR007@6_0.mat"].startswith("sha256:")
    assert reg["cwru/131_OR007@6_1.mat"] is None
