"""Loading a validation case: the TOML read, its top-level keys checked, then every section by
:mod:`.case_checks` (which builds on :mod:`.case`), before anything runs.

Public API
----------
load_case(name_or_path)  -- ValidationCase (raises ValidationCaseError naming the problem)
list_cases()             -- {name: title} of the shipped cases
"""
from __future__ import annotations

import tomllib
from functools import partial
from pathlib import Path

from ..errors import ValidationCaseError, check_choice
from .case import ValidationCase, case_dir, case_error, shipped_cases
from .case_checks import check_paper, check_recording

__all__ = ["load_case", "list_cases"]

_TOP_RECORDING = {"name", "title", "description", "kind", "default", "bearing", "speed", "recording", "reference",
                  "load", "defect", "scene", "structural_path", "background", "ratio", "numerical_error",
                  "tolerances"}
_TOP_PAPER = {"name", "title", "description", "kind", "default", "bearing", "reference", "run", "tolerances",
              "studies", "numerical_error"}


def list_cases() -> dict:
    """``{name: title}`` of the shipped cases."""
    return {n: load_case(n).title for n in shipped_cases()}


def _read(spec):
    """(name guess, source text, base dir, raw text) for a shipped name or a file path."""
    spec = str(spec)
    shipped = shipped_cases()
    if spec in shipped:
        return spec, f"shipped case {spec}", case_dir(), shipped[spec].read_text(encoding="utf-8")
    p = Path(spec).expanduser()
    if p.suffix == ".toml" or p.exists():
        if not p.is_file():
            raise ValidationCaseError(f"validation case file {spec!r} does not exist")
        return p.stem, str(p), p.resolve().parent, p.read_text(encoding="utf-8")
    raise ValidationCaseError(f"unknown validation case {spec!r}: not a file, and the shipped cases are "
                              + ", ".join(shipped))


def load_case(spec) -> ValidationCase:
    """Load and check a case: a shipped name (``paper``, ``cwru-130``) or a TOML path.

    Raises
    ------
    ValidationCaseError
        Unknown case, invalid TOML, an unknown key (named), an invalid value, a tolerance
        without a reason, an invalid scene or scene key.  (A missing recording file is
        checked by :func:`bearing_lab.validation.runner.check_case`.)
    """
    stem, source, base_dir, text = _read(spec)
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValidationCaseError(f"validation case {source!r} is not valid TOML: {exc}") from None
    name = str(raw.get("name") or stem)
    kind = raw.get("kind", "recording")
    check_choice(kind, ("recording", "paper"), "kind", partial(case_error, name))
    top = _TOP_PAPER if kind == "paper" else _TOP_RECORDING
    bad = sorted(set(raw) - top)
    if bad:
        hint = (" ([[run]] tables belong to paper cases; a healthy recording of the same rig goes in "
                "[reference])" if bad[0] == "run" else "")
        raise case_error(name, f"unknown key {bad[0]!r}{hint}; allowed top-level keys are {', '.join(sorted(top))}")
    case = ValidationCase(name=name, title=str(raw.get("title", name)), kind=kind, source=source, text=text,
                          data=raw, base_dir=base_dir, default=bool(raw.get("default", False)))
    (check_paper if kind == "paper" else check_recording)(case)
    from dataclasses import replace
    for attr in ("tolerances", "reference_tolerances"):
        setattr(case, attr, {q: replace(t, declared_by=case.author) if t.known_limitation else t
                             for q, t in getattr(case, attr).items()})
    return case
