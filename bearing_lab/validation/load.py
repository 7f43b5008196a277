"""Loading a validation case: the TOML read, its top-level keys checked, then every section by
:mod:`.case_checks` (which builds on :mod:`.case`), before anything runs.

Public API
----------
load_case(name_or_path)  -- ValidationCase (raises ValidationCaseError naming the problem)
list_cases()             -- {name: title} of the shipped cases
"""
from __future__ import annotations

from dataclasses import replace
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
    """``{name: title}`` of the shipped cases (``bearing-lab validate --list``).

    See Also
    --------
    load_case, bearing_lab.validation.case.shipped_cases, bearing_lab.validation.default_set

    Examples
    --------
    >>> list_cases()["cwru-130"]
    'CWRU record 130: drive end, outer race 0.007 in at 6:00 (load zone), 0 hp, 12 kHz'
    """
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

    Parameters
    ----------
    spec : str or path
        A shipped case's name (:func:`list_cases`) or a case file (``docs/case-format.md``).

    Returns
    -------
    ValidationCase

    Raises
    ------
    ValidationCaseError
        Unknown case, invalid TOML, an unknown key (named), an invalid value, a tolerance
        without a reason, an invalid scene or scene key.  (A missing recording file is
        checked by :func:`bearing_lab.validation.runner.check_case`.)

    See Also
    --------
    list_cases, bearing_lab.validation.check_case, bearing_lab.validation.run_case

    Examples
    --------
    >>> case = load_case("paper")
    >>> case.kind, case.default
    ('paper', True)
    >>> case.tolerances["excitation_period"].text()       # every tolerance carries its reason
    '±0.5 %'
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
    for attr in ("tolerances", "reference_tolerances"):
        setattr(case, attr, {q: replace(t, declared_by=case.author) if t.known_limitation else t
                             for q, t in getattr(case, attr).items()})
    return case
