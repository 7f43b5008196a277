"""Where a result came from: software versions, source revision, machine, date; and how to cite it.

Public API
----------
software_versions()   -- {package: version} of bearing_lab and the libraries its numbers depend on
source_revision()     -- the git commit of the source tree, or "" for an installed package
environment()         -- versions, revision, host, date (UTC)
citation()            -- {"software": str, "paper": str}: the "how to cite" block
"""
from __future__ import annotations

import datetime as _dt
import importlib.metadata as md
import os
import platform
import subprocess
from pathlib import Path

from .._version import __version__

__all__ = ["software_versions", "source_revision", "environment", "citation", "PAPER_CITATION"]

#: the paper whose model and experiment the project reproduces
PAPER_CITATION = ("Liu, Xu, Wang, Xu, Tang: Influence of the local defect distribution on vibration "
                  "characteristics of ball bearings. Eksploatacja i Niezawodność (Maintenance and Reliability).")


def software_versions() -> dict:
    """``{package: version}``: Python, bearing_lab (its ``_version.py``, the one place the version is
    written) and the installed libraries its numbers depend on ("not installed" for one that is not)."""
    out = {"python": platform.python_version(), "bearing_lab": __version__}
    for pkg in ("numpy", "scipy", "numba", "xarray", "netCDF4", "matplotlib"):
        try:
            out[pkg] = md.version(pkg)
        except md.PackageNotFoundError:
            out[pkg] = "not installed"
    return out


def source_revision() -> str:
    """Short git commit of the source tree (with "+changes" when it differs from the commit), or ""."""
    root = Path(__file__).resolve().parents[2]
    if not (root / ".git").exists():
        return ""
    try:
        head = subprocess.run(["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, timeout=5).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=5).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""
    return head + ("+changes" if head and dirty else "")


def environment() -> dict:
    """The page's provenance: :func:`software_versions`, :func:`source_revision`, the date (UTC) and the host."""
    return {"versions": software_versions(), "source revision": source_revision() or "installed package",
            "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
            "host": f"{platform.system()} {platform.machine()}, {os.cpu_count()} cores"}


def citation() -> dict:
    """How to cite a result: ``{"software": bearing_lab's version and source revision, "paper": the reference}``."""
    rev = source_revision()
    software = (f"bearing_lab {__version__}" + (f" (source revision {rev})" if rev else "")
                + ": rolling-bearing simulation, analysis and validation toolkit.")
    return {"software": software, "paper": PAPER_CITATION}
