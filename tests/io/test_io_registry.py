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
            assert f in reg, f"{f} missing from bearing_lab/data/recordings.csv"
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
    with pytest.raises(RecordingError, match="is not in the mirror"):
        datasets.fetch("cwru/131_OR007@6_1.mat", mirror=tmp_path, dest=tmp_path / "d",
                       download=False)
    monkeypatch.delenv("BEARING_LAB_MIRROR", raising=False)
    with pytest.raises(RecordingError) as info:
        datasets.fetch("cwru/131_OR007@6_1.mat", dest=tmp_path / "d", download=False)
    assert "is not cached and no mirror is set" in str(info.value) and "no mirror (" not in str(info.value)
    with pytest.raises(RecordingError, match="no registered recording 'nope.mat'"):
        datasets.fetch("nope.mat")


def test_pooch_registry():
    reg = datasets.pooch_registry()
    assert reg["cwru/130_OR007@6_0.mat"].startswith("sha256:")
    assert reg["cwru/131_OR007@6_1.mat"] is None


def test_every_mirrored_registry_file_has_its_true_sha256(mirror):
    """A registry row without a checksum lets a mirror serve anything: every row whose file is in
    the mirror must carry the sha256 of that file."""
    from bearing_lab.utils._files import sha256_file
    if mirror is None:
        pytest.skip("no mirror")
    checked = 0
    for name, rec in datasets.load_registry().items():
        p = Path(mirror) / name
        if p.is_file():
            assert rec.sha256 == sha256_file(p), name
            checked += 1
    assert checked >= 18


def _fake_mirror(tmp_path, content=None):
    src = Path(__file__)  # any bytes; the registry row's hash is patched to match
    m = tmp_path / "mirror" / "lms"
    m.mkdir(parents=True)
    (m / "binary8byte_g.uff").write_bytes(content if content is not None else src.read_bytes())
    return tmp_path / "mirror"


@pytest.fixture
def patched_hash(monkeypatch):
    """The lms/binary8byte_g.uff row with the sha256 of this test file (no mirror needed)."""
    from dataclasses import replace
    from bearing_lab.utils._files import sha256_file
    reg = dict(datasets.load_registry())
    name = "lms/binary8byte_g.uff"
    reg[name] = replace(reg[name], sha256=sha256_file(Path(__file__)))
    monkeypatch.setattr(datasets, "load_registry", lambda path=None: reg)
    return name


def test_fetch_never_deletes_what_it_cannot_replace(tmp_path, patched_hash):
    """A copy failing its check was deleted even when nothing could replace it."""
    dest = tmp_path / "d"
    (dest / "lms").mkdir(parents=True)
    old = dest / patched_hash
    old.write_bytes(b"my local edit")
    with pytest.raises(RecordingError, match="does not match.*left in place"):
        datasets.fetch(patched_hash, mirror=tmp_path / "empty", dest=dest, download=False)
    assert old.read_bytes() == b"my local edit"
    # a verified copy replaces it, in one step
    p = datasets.fetch(patched_hash, mirror=_fake_mirror(tmp_path), dest=dest, download=False)
    assert p == old and p.read_bytes() == Path(__file__).read_bytes()
    assert sorted(x.name for x in (dest / "lms").iterdir()) == ["binary8byte_g.uff"]


def test_fetch_refuses_links_that_leave_dest(tmp_path, patched_hash):
    """A dangling link in --dest made fetch write a file outside it."""
    dest = tmp_path / "d"
    (dest / "lms").mkdir(parents=True)
    outside = tmp_path / "outside.uff"
    (dest / patched_hash).symlink_to(outside)
    mirror = _fake_mirror(tmp_path)
    with pytest.raises(RecordingError, match="dangling symbolic link .*refusing to write"):
        datasets.fetch(patched_hash, mirror=mirror, dest=dest, download=False)
    assert not outside.exists()
    (dest / patched_hash).unlink()
    (dest / "lms").rmdir()
    other = tmp_path / "elsewhere"
    other.mkdir()
    (dest / "lms").symlink_to(other)
    with pytest.raises(RecordingError, match="outside --dest"):
        datasets.fetch(patched_hash, mirror=mirror, dest=dest, download=False)
    assert not any(other.iterdir())


def test_fetch_download_is_checked_before_it_lands(tmp_path, patched_hash, monkeypatch):
    import pooch

    def fake_retrieve(url, known_hash, fname, path, progressbar):
        p = Path(path) / fname
        p.write_bytes(b"tampered")
        return str(p)

    monkeypatch.setattr(pooch, "retrieve", fake_retrieve)
    dest = tmp_path / "d"
    with pytest.raises(RecordingError, match="does not match"):
        datasets.fetch(patched_hash, mirror=tmp_path / "none", dest=dest)
    assert not (dest / patched_hash).exists()
    assert [p.name for p in (dest / "lms").iterdir()] == []  # no temporary left behind


def test_fetch_of_an_unhashed_row_warns(tmp_path, monkeypatch):
    from dataclasses import replace
    reg = dict(datasets.load_registry())
    name = "lms/binary8byte_g.uff"
    reg[name] = replace(reg[name], sha256="")
    monkeypatch.setattr(datasets, "load_registry", lambda path=None: reg)
    with pytest.warns(datasets.UnverifiedWarning, match="not verified"):
        datasets.fetch(name, mirror=_fake_mirror(tmp_path), dest=tmp_path / "d", download=False)


def test_cwru_files_open_with_their_registered_rate_by_content(datafile, tmp_path):
    """Every 48 kHz drive-end file opens at 48 kHz without fs=, also IR014_0 whose variables
    carry record 173 while the data centre lists it as 174, and also under another name: the
    registry is found by the file's sha256.  Breaking it: without the content lookup, IR014_0
    asks for fs= (record 173 is not registered)."""
    import shutil
    import warnings

    from bearing_lab.io import open_recording
    for name in ("B007_0", "IR007_0", "IR014_0"):
        src = datafile(f"cwru/48k_DE/{name}.mat")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = open_recording(src, checksum=False)
            assert ds.attrs["sampling_rate_hz"] == 48000.0, name
            renamed = tmp_path / f"renamed_{name}.mat"
            shutil.copyfile(src, renamed)
            ds2 = open_recording(renamed, checksum=False)
        assert ds2.attrs["sampling_rate_hz"] == 48000.0 and "sha256" in ds2.attrs["sampling_rate_source"]
        assert ds2.attrs["registry_name"] == f"cwru/48k_DE/{name}.mat"


def test_registry_documentation_lists_its_columns():
    """data/README.md documents the package's registry: every CSV column, and no other."""
    import csv
    import re
    from pathlib import Path
    with datasets.REGISTRY_FILE.open(newline="", encoding="utf-8") as fh:
        header = next(csv.reader(fh))
    readme = (Path(__file__).resolve().parents[2] / "data" / "README.md").read_text()
    rows = [line.split("|")[1] for line in readme.splitlines() if line.startswith("| `")]
    documented = {c for cell in rows for c in re.findall(r"`([a-z_0-9]+)`", cell)}
    assert documented == set(header), (documented ^ set(header))
