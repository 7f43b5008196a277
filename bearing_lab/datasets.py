"""Registry of the public recordings used by tests and validation.

Why: recordings are never committed (their publishers' terms, and their size);
the project keeps only their names, sha256, publisher addresses and test
conditions in ``bearing_lab/data/recordings.csv`` (one row per file, path relative to a
mirror root such as ``../shared/data``).  A file is brought in from a local
mirror (``--mirror DIR`` or ``BEARING_LAB_MIRROR``) with a hash check, or
downloaded with pooch where a network allows.  The CWRU reader asks this module
for a record's sampling rate, because CWRU files do not store it (record 97 is
48 kHz, the 12k drive-end set 12 kHz).

Public API
----------
load_registry()                     -- {name: Recording} from bearing_lab/data/recordings.csv
get(name)                           -- one Recording (name, or a unique suffix such as "130_OR007@6_0.mat")
cwru_record(number)                 -- the Recording of a CWRU record number, or None
cwru_sampling_rate(number)          -- its rate in Hz, or None if unknown
fetch(name, mirror=None, dest=None) -- Path of a hash-checked local copy (never deletes, never
                                       writes outside dest or through a symbolic link)
locate(name, mirror=None)           -- Path in a mirror or the cache, without copying, or None
pooch_registry()                    -- {name: "sha256:..."} for pooch.create
data_dir()                          -- where fetch puts files by default
SAMPLE                              -- how the shipped sample recording (bearing_lab/data/sample_recording.uff)
                                       is made (:func:`bearing_lab.validation.standin.make_sample_recording`)
"""
from __future__ import annotations

import csv
import functools
import importlib.resources
import os
import shutil
import tempfile
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import lazy_loader as lazy

from .errors import RecordingError
from .utils._files import atomic_path, sha256_file

# the download library, loaded when a recording is fetched or the cache folder is asked
pooch = lazy.load("pooch")

# package data: present in a wheel install as in a checkout (data/README.md documents it)
#: the sample recording shipped as package data (``bearing-lab data sample``): how it is made, here so that
#: ``data sample --json`` says it without importing the simulator that makes it
SAMPLE = {"scene": "paper-O2", "overrides": {"load.radial_n": 320.0}, "rpm": 1800.0, "duration": 1.0,
          "fs": 12800.0, "seed": 7, "sensitivity_v_per_g": 9.91e-3, "channel": "Acc"}
REGISTRY_FILE = importlib.resources.files("bearing_lab") / "data" / "recordings.csv"
# a checkout's git-ignored download folder (absent in a wheel install)
_CHECKOUT_DATA = Path(__file__).resolve().parents[1] / "data"


@dataclass(frozen=True)
class Recording:
    """One registered public recording (a row of bearing_lab/data/recordings.csv)."""

    name: str
    sha256: str
    url: str
    page: str
    publisher: str
    dataset: str
    record: int | None
    fs_hz: float | None
    rpm: float | None
    load_hp: float | None
    defect: str
    defect_size_in: float | None
    defect_position: str
    bearing: str
    channels: tuple[str, ...] = field(default_factory=tuple)
    note: str = ""


def _num(text, kind=float):
    text = (text or "").strip()
    return kind(text) if text else None


@functools.lru_cache(maxsize=4)
def _load(path) -> dict:
    out = {}
    with path.open("r", newline="", encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            rec = Recording(
                name=row["name"], sha256=row["sha256"].strip().lower(), url=row["url"].strip(),
                page=row.get("page", ""), publisher=row["publisher"], dataset=row["dataset"],
                record=_num(row["record"], int), fs_hz=_num(row["fs_hz"]), rpm=_num(row["rpm"]),
                load_hp=_num(row["load_hp"]), defect=row["defect"],
                defect_size_in=_num(row["defect_size_in"]), defect_position=row["defect_position"],
                bearing=row["bearing"], channels=tuple(row["channels"].split()), note=row["note"])
            out[rec.name] = rec
    return out


def load_registry(path=None) -> dict[str, Recording]:
    """Return ``{name: Recording}`` from the package's ``data/recordings.csv`` (or ``path``).

    Raises
    ------
    RecordingError
        If the registry file is missing.
    """
    p = Path(path) if path else REGISTRY_FILE
    if not p.is_file():
        why = "" if path else ": bearing_lab's package data is missing, the install is broken; reinstall it"
        raise RecordingError(f"data registry {p} not found{why}")
    return dict(_load(p))


def get(name: str) -> Recording:
    """Return the registered recording ``name`` (full name or a unique file-name suffix)."""
    reg = load_registry()
    if name in reg:
        return reg[name]
    hits = [r for n, r in reg.items() if n.endswith("/" + name) or Path(n).name == name]
    if len(hits) == 1:
        return hits[0]
    if len(hits) > 1:
        raise RecordingError(f"recording name {name!r} is ambiguous: {', '.join(h.name for h in hits)}")
    close = [n for n in reg if name.split("/")[-1].split("_")[0] in n][:5]
    hint = f"; similar: {', '.join(close)}" if close else ""
    raise RecordingError(f"no registered recording {name!r} (see `bearing-lab data list`){hint}")


def cwru_record(number: int) -> Recording | None:
    """Return the registered CWRU recording with this record number, or None."""
    for r in load_registry().values():
        if r.dataset.startswith("cwru") and r.record == int(number):
            return r
    return None


def cwru_sampling_rate(number: int) -> float | None:
    """Return the sampling rate (Hz) of CWRU record ``number``, or None if not registered."""
    r = cwru_record(number)
    return r.fs_hz if r else None


def pooch_registry() -> dict[str, str | None]:
    """Return ``{name: "sha256:<hex>" or None}`` for ``pooch.create(registry=...)``."""
    return {n: (f"sha256:{r.sha256}" if r.sha256 else None) for n, r in load_registry().items()}


def data_dir() -> Path:
    """Return where fetched recordings go: ``BEARING_LAB_DATA``, else ``data/cache`` of the
    project checkout (git-ignored), else (an installed package) pooch's user cache."""
    env = os.environ.get("BEARING_LAB_DATA")
    if env:
        return Path(env)
    proj = _CHECKOUT_DATA
    if (proj / "README.md").is_file() and os.access(proj, os.W_OK):
        return proj / "cache"
    return Path(pooch.os_cache("bearing_lab"))


def _sha256(path: Path) -> str:
    return sha256_file(path)


def _mirror_dir(mirror) -> Path | None:
    m = mirror if mirror is not None else os.environ.get("BEARING_LAB_MIRROR")
    return Path(m) if m else None


def _check(rec: Recording, path: Path, where: str) -> None:
    if not rec.sha256:
        return
    got = _sha256(path)
    if got != rec.sha256:
        msg = (f"{path}: sha256 {got} does not match the registry's {rec.sha256} for "
               f"{rec.name!r} ({where}); the copy is corrupt or a different file: replace it")
        raise RecordingError(msg)


def locate(name: str, mirror=None) -> Path | None:
    """Return the path of ``name`` in the mirror or the data directory (no copy), or None."""
    rec = get(name)
    m = _mirror_dir(mirror)
    for root in ([m] if m else []) + [data_dir()]:
        p = root / rec.name
        if p.is_file():
            return p
    return None


class UnverifiedWarning(UserWarning):
    """A recording was fetched that the registry has no checksum for: it could not be verified."""


def _safe_target(dest: Path, rec: Recording) -> Path:
    """``dest/<name>``, refusing any path that would write outside ``dest`` or through a link."""
    target = dest / rec.name
    root = dest.resolve()
    parts = Path(rec.name).parts
    if Path(rec.name).is_absolute() or ".." in parts:
        raise RecordingError(f"registry name {rec.name!r} is not a relative path inside --dest")
    p = dest
    for part in parts:
        p = p / part
        if not p.is_symlink():
            continue
        where = os.readlink(p)
        if not p.exists():
            raise RecordingError(f"{p}: is a dangling symbolic link (to {where}); refusing to write "
                                 "through it: remove it, or fetch into another --dest")
        if not p.resolve().is_relative_to(root):
            raise RecordingError(f"{p}: is a symbolic link to {where}, outside --dest {dest}; "
                                 "refusing to write there")
    if not target.resolve().is_relative_to(root):
        raise RecordingError(f"{target}: resolves outside --dest {dest}; refusing to write there")
    return target


def _install(src_copy, target: Path, rec: Recording, verify: bool, where: str) -> Path:
    """Copy ``src_copy`` (a path) to ``target`` atomically after checking its hash."""
    if verify and rec.sha256:
        _check(rec, Path(src_copy), where)
    elif verify:
        warnings.warn(f"{rec.name}: the registry has no sha256 for this recording, so the copy "
                      f"from {where} is not verified", UnverifiedWarning, stacklevel=3)
    target.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(target) as tmp:  # the old file, good or bad, stays until this succeeds
        shutil.copyfile(src_copy, tmp)
        if verify and rec.sha256:
            _check(rec, tmp, f"copy of {where}")
    return target


def fetch(name: str, mirror=None, dest=None, *, download: bool = True, verify: bool = True) -> Path:
    """Bring a registered recording into ``dest`` (default :func:`data_dir`), hash-checked.

    Parameters
    ----------
    name : str
        Registry name (``cwru/130_OR007@6_0.mat``) or a unique file name (``130_OR007@6_0.mat``).
    mirror : str or Path, optional
        A local directory laid out like the registry (default: ``BEARING_LAB_MIRROR``).
    dest : str or Path, optional
        Target directory; the file goes to ``dest/<name>``.
    download : bool
        Try the publisher's URL (pooch) when no mirror holds the file.
    verify : bool
        Check the sha256; a recording without a registered checksum is copied with an
        :class:`UnverifiedWarning`.

    Returns
    -------
    Path
        The local, verified copy.

    Raises
    ------
    RecordingError
        Unknown name, checksum mismatch, a path that would leave ``dest`` or pass through a
        symbolic link, or the file is neither in a mirror nor downloadable.

    Notes
    -----
    Nothing is deleted: a new copy replaces the target in one rename once it is complete
    and verified, and an existing copy that fails its check stays where it is until a
    verified one replaces it.
    """
    rec = get(name)
    dest = Path(dest) if dest else data_dir()
    target = _safe_target(dest, rec)
    stale = None
    if target.is_file():
        try:
            if verify:
                _check(rec, target, "existing copy")
            return target
        except RecordingError as exc:
            stale = exc  # replaced below if a verified copy can be had; never deleted
    m = _mirror_dir(mirror)
    if m is not None:
        src = m / rec.name
        if src.is_file():
            if src.resolve() == target.resolve():
                if verify:
                    _check(rec, src, f"mirror {m}")
                return target
            return _install(src, target, rec, verify, f"mirror {m}")
    if not download or not rec.url:
        where = (f"is not in the mirror {m}" if m else
                 "is not cached and no mirror is set (pass --mirror DIR or set BEARING_LAB_MIRROR)")
        how = f"download it from {rec.page or rec.url}" if (rec.page or rec.url) else "get it"
        msg = (f"recording {rec.name!r} {where}"
               + ("" if rec.url else " and has no direct download URL")
               + f"; {how} and place it under <mirror>/{rec.name}")
        if stale is not None:
            msg = f"{stale}; the existing copy is left in place, and no replacement: {msg}"
        raise RecordingError(msg)
    return _download(rec, target, verify, stale)


def _download(rec: Recording, target: Path, verify: bool, stale) -> Path:
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=target.parent, prefix=".fetch-") as tmp:
        try:
            got = pooch.retrieve(rec.url, known_hash=f"sha256:{rec.sha256}" if rec.sha256 else None,
                                 fname=Path(rec.name).name, path=tmp, progressbar=False)
        except Exception as exc:  # network down, 404, hash mismatch
            msg = (f"recording {rec.name!r}: download from {rec.url} failed ({type(exc).__name__}: "
                   f"{exc}); without network, copy it from a mirror with --mirror DIR")
            if stale is not None:
                msg = f"{stale}; the existing copy is left in place: {msg}"
            raise RecordingError(msg) from exc
        return _install(got, target, rec, verify, rec.url)
