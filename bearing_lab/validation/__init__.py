"""Validation: a simulation against a recording (or a paper's figures), quantity by quantity.

A case (TOML; ``docs/case-format.md``) names the recording, the bearing, the speed,
the load and the defect(s), optionally a healthy reference recording of the same rig,
and a tolerance with a reason for each compared quantity.  The structural path from
the outer ring to the sensor is identified once per rig and held fixed; the rig's
measured background can be added to the simulation; every row can fail, and a failing
row says whether it is a known model limitation.

Modules: :mod:`.case` (parsing), :mod:`.quantities` (the table of quantities),
:mod:`.rows` (tolerances, rows, verdicts), :mod:`.speed` (speed sources), :mod:`.simulation`
(scenes and every simulator call); a recording case in layers: :mod:`.recording_case`
(recording and declared scene, measured once), :mod:`.rig` (structural path, background),
:mod:`.evaluate` (rows), :mod:`.candidates` (geometries scored), :mod:`.recording_run` (the case
end to end); :mod:`.paper` (a paper case), :mod:`.figures`, :mod:`.pages` (report,
summary.json), :mod:`.runner`, :mod:`.standin` (stand-in recordings), :mod:`.newcase`
(``bearing-lab case new``).  The names below are served lazily (``lazy_loader.attach``): each module
loads the first time one of its names is used.

Public API
----------
::

    load_case(name_or_path)                        -- a checked ValidationCase
    list_cases()                                   -- {name: title} of the shipped cases
    shipped_cases()                                -- {name: Traversable} (package data bearing_lab/validation/cases)
    check_case(case, mirror=None)                  -- raise if a recording is missing
    default_set(mirror=None)                       -- (cases, skipped) of the default set
    run_case(case, out_dir, ...) / run_validation(specs, out_dir, ...)
    QUANTITIES                                     -- the table of quantities
    Tolerance, make_row                            -- pass rules and rows
    make_standin_recording(path, ...)              -- a simulated recording with a hidden defect, jitter,
                                                      a resonance, tones and noise (UFF58b or Testlab .mat)
    new_case_text(recording_path, ...)             -- the commented starting case `bearing-lab case new` writes
"""
import lazy_loader as _lazy

#: module -> the public names it serves; each module is imported the first time one of its names is
#: used (``lazy_loader.attach``), so ``bearing-lab --help`` (the verdicts of ``validation.rows``) and
#: ``import bearing_lab.validation`` load no simulator, analysis or page code
_PUBLIC = {
    "case": ["DEFAULT_CASE", "RecordingSpec", "ValidationCase", "shipped_cases"],
    "load": ["list_cases", "load_case"],
    "quantities": ["QUANTITIES", "Quantity"],
    "rows": ["Tolerance", "make_row"],
    "runner": ["CaseOutcome", "check_case", "default_set", "run_case", "run_validation"],
    "standin": ["make_standin_recording", "StandIn"],
    "identify": ["identify"],
    "newcase": ["new_case_text"],
}
__getattr__, __dir__, _ = _lazy.attach(__name__, submod_attrs=_PUBLIC)

__all__ = ["load_case", "list_cases", "shipped_cases", "check_case", "default_set", "run_case", "run_validation",
           "CaseOutcome", "ValidationCase", "RecordingSpec", "QUANTITIES", "Quantity", "Tolerance", "make_row",
           "make_standin_recording", "new_case_text", "DEFAULT_CASE"]
