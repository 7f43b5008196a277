"""Validation cases: from a recording (or a paper's figures) and a matching scene to a report.

Why TOML cases: what a validation compares, against what, and how close counts
as agreement are decisions a reviewer must be able to read and argue with.  A
case file names the recording (registry name or path, channel, calibration
factor), the matching scene (built-in or file; speed taken from the recording
- estimated from its shaft line, or the stored rpm - and load and defect as
``--set`` keys), and one tolerance *with a reason* for every quantity it
compares.  A compared quantity without a reason is refused.  Nothing here is
tuned per case: every signal goes through :func:`bearing_lab.compare.measure`.

Case kinds
----------
``paper``      the simulation against figures a paper reports (``validation/paper_reference.toml``);
``recording``  the simulation against a real recording (CWRU records via ``BEARING_LAB_MIRROR``).

Public API
----------
CASE_DIR                         -- the shipped cases (``validation/`` of the project)
list_cases()                     -- {name: path} of the shipped cases
load_case(name_or_path)          -- ValidationCase (checked: keys, tolerances, scenes)
default_set(mirror=None)         -- (cases, skipped) of the embedded default set
check_case(case, mirror=None)    -- raise ValidationCaseError if the recording is missing
run_case(case, out_dir, ...)     -- run one case, write DIR/<case>/{index.html, comparison.nc, summary.json}
run_validation(specs, out_dir, ...) -- several cases + DIR/index.html; returns (outcomes, exit status)
"""
from __future__ import annotations

import copy
import datetime as _dt
import hashlib
import json
import math
import os
import platform
import subprocess
import sys
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .compare import (G0, QUANTITIES, CalibrationResult, Tolerance, calibrate_sensor, compare,
                      impact_times, impulse_strength, make_row, measure)
from .errors import BearingLabError, ValidationCaseError

__all__ = ["CASE_DIR", "ValidationCase", "list_cases", "load_case", "default_set", "check_case",
           "run_case", "run_validation", "CaseOutcome", "PAPER_QUANTITIES", "RECORDING_QUANTITIES"]

CASE_DIR = Path(__file__).resolve().parents[1] / "validation"
DEFAULT_CASE = "paper"

PAPER_QUANTITIES = ("shaft_hz", "bpfo", "bpfi", "excitation_period", "peak", "offset_ratio")
_BASE = ("shaft_hz", "bpfo", "bpfi", "excitation_period", "rms", "peak", "crest_factor", "kurtosis",
         "impulse_duration")
RECORDING_QUANTITIES = _BASE + tuple(f"{q}_calibrated" for q in ("rms", "peak", "crest_factor", "kurtosis",
                                                                 "impulse_duration")) + ("impulse_strength_ratio",)

_TOP_KEYS = {"name", "title", "description", "kind", "default", "bearing", "reference", "run", "recording",
             "scene", "calibration", "ordering", "tolerances", "studies", "numerical_error"}


# ------------------------------------------------------------------ the case
@dataclass
class ValidationCase:
    """A checked case file (``data`` keeps the TOML mapping)."""

    name: str
    title: str
    kind: str
    path: Path
    data: dict
    tolerances: dict = field(default_factory=dict)   # quantity -> Tolerance
    default: bool = False

    @property
    def recording(self) -> dict:
        return self.data.get("recording", {})

    @property
    def recording_names(self) -> list[str]:
        out = []
        if self.kind == "recording":
            out.append(self.recording.get("name") or self.recording.get("path"))
            if self.data.get("ordering"):
                out.append(self.data["ordering"].get("recording"))
        return [o for o in out if o]


def list_cases(case_dir=None) -> dict[str, Path]:
    """Shipped cases: ``{name: path}`` of ``validation/*.toml`` (reference data files excluded)."""
    d = Path(case_dir) if case_dir else CASE_DIR
    if not d.is_dir():
        return {}
    return {p.stem: p for p in sorted(d.glob("*.toml")) if not p.stem.endswith("_reference")}


def _err(case, msg):
    return ValidationCaseError(f"validation case {case!r}: {msg}")


def _tolerances(name, raw, allowed) -> dict:
    if not isinstance(raw, dict) or not raw:
        raise _err(name, "needs a [tolerances] table: one entry per compared quantity, each with a reason")
    out = {}
    for q, spec in raw.items():
        if q not in allowed:
            raise _err(name, f"unknown quantity tolerances.{q}; allowed are {', '.join(allowed)}")
        if not isinstance(spec, dict):
            raise _err(name, f"tolerances.{q} must be a table such as {{pct = 1.0, reason = \"...\"}}")
        bad = set(spec) - {"pct", "factor", "ordering", "reason"}
        if bad:
            raise _err(name, f"unknown key tolerances.{q}.{sorted(bad)[0]}; use pct, factor or ordering, and reason")
        kinds = [k for k in ("pct", "factor", "ordering") if k in spec]
        if len(kinds) != 1:
            raise _err(name, f"tolerances.{q} needs exactly one of pct, factor, ordering")
        if not str(spec.get("reason", "")).strip():
            raise _err(name, f"tolerances.{q} has no reason: every tolerance needs one")
        k = kinds[0]
        try:
            out[q] = Tolerance(k, None if k == "ordering" else float(spec[k]), str(spec["reason"]).strip())
        except (TypeError, ValueError) as exc:
            raise _err(name, f"tolerances.{q}: {exc}") from None
    return out


SCALE_RANGE = (1e-6, 1e6)
"""A calibration factor outside this range is a typo or a unit mix-up, not a sensor's
(a sensitivity error of a million times would be noticed in the recording itself)."""


def _check_scale(name, scale):
    """recording.scale: a finite, positive calibration factor of a plausible size."""
    lo, hi = SCALE_RANGE
    if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not math.isfinite(scale) \
            or not lo <= scale <= hi:
        raise _err(name, f"recording.scale = {scale!r}: the calibration factor on the recording's SI "
                         f"values must be a positive number between {lo:g} and {hi:g} (1.0 when the "
                         "file is calibrated)")


def _check_bounds(name, key, value):
    ok = (isinstance(value, list) and len(value) == 2
          and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                  and v > 0 for v in value) and value[0] < value[1])
    if not ok:
        raise _err(name, f"{key} = {value!r}: give [low, high], two finite positive numbers, low < high")


def _check_scene(name, scene, overrides, where, base: Path):
    from .sim import load_scene
    from .errors import SceneError
    if not isinstance(scene, str) or not scene:
        raise _err(name, f"{where}.scene must be a built-in scene name or a TOML path")
    p = Path(scene)
    if p.suffix == ".toml" and not p.is_absolute():
        p = base / p
        scene = str(p)
    try:
        load_scene(scene, **(overrides or {}))
    except SceneError as exc:
        raise _err(name, f"{where}: {exc}") from None
    return scene


def load_case(spec) -> ValidationCase:
    """Load and check a case: a shipped name (``paper``, ``cwru-130``) or a TOML path.

    Raises
    ------
    ValidationCaseError
        Unknown case, invalid TOML, unknown keys, a tolerance without a reason, an invalid scene
        or ``--set`` key.  (A missing recording is checked by :func:`check_case`.)
    """
    spec = str(spec)
    shipped = list_cases()
    p = Path(spec)
    if spec in shipped:
        path = shipped[spec]
    elif p.suffix == ".toml" or p.exists():
        if not p.is_file():
            raise ValidationCaseError(f"validation case file {spec!r} does not exist")
        path = p
    else:
        raise ValidationCaseError(f"unknown validation case {spec!r}: not a file, and the shipped cases are "
                                  + (", ".join(shipped) or f"none (no {CASE_DIR})"))
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ValidationCaseError(f"validation case {str(path)!r} is not valid TOML: {exc}") from None
    name = str(raw.get("name") or path.stem)
    bad = set(raw) - _TOP_KEYS
    if bad:
        raise _err(name, f"unknown key {sorted(bad)[0]!r}; top-level keys are {', '.join(sorted(_TOP_KEYS))}")
    kind = raw.get("kind", "recording")
    if kind not in ("paper", "recording"):
        raise _err(name, f"invalid kind {kind!r}; allowed are 'paper' and 'recording'")
    base = path.parent
    data = copy.deepcopy(raw)
    if kind == "paper":
        runs = raw.get("run")
        if not isinstance(runs, list) or not runs:
            raise _err(name, "a paper case needs [[run]] tables (label, scene)")
        for i, r in enumerate(runs):
            bad = set(r) - {"label", "scene", "duration_s", "set", "reference"}
            if bad:
                raise _err(name, f"unknown key run[{i}].{sorted(bad)[0]}; run keys are label, scene, duration_s, "
                                 "set, reference")
            if "label" not in r:
                raise _err(name, f"run[{i}] needs a label")
            data["run"][i]["scene"] = _check_scene(name, r.get("scene"), r.get("set"), f"run[{i}]", base)
        ref = raw.get("reference", "paper_reference.toml")
        rp = base / ref
        if not rp.is_file():
            raise _err(name, f"reference data {str(rp)!r} not found")
        data["reference_path"] = str(rp)
        tol = _tolerances(name, raw.get("tolerances"), PAPER_QUANTITIES)
    else:
        rec = raw.get("recording")
        if not isinstance(rec, dict) or not (rec.get("name") or rec.get("path")):
            raise _err(name, "needs [recording] with name (registry) or path")
        bad = set(rec) - {"name", "path", "channel", "scale", "units", "description"}
        if bad:
            raise _err(name, f"unknown key recording.{sorted(bad)[0]}; keys are name, path, channel, scale, units")
        _check_scale(name, rec.get("scale", 1.0))
        sc = raw.get("scene")
        if not isinstance(sc, dict):
            raise _err(name, "needs a [scene] table (scene, speed, duration_s, set)")
        bad = set(sc) - {"scene", "speed", "duration_s", "set"}
        if bad:
            raise _err(name, f"unknown key scene.{sorted(bad)[0]}; keys are scene, speed, duration_s, set")
        speed = sc.get("speed", "estimate")
        if not (speed in ("estimate", "file") or (isinstance(speed, (int, float)) and speed > 0)):
            raise _err(name, f"scene.speed={speed!r}: use 'estimate', 'file' or a speed in r/min")
        data["scene"]["scene"] = _check_scene(name, sc.get("scene"), sc.get("set"), "scene", base)
        if rec.get("path"):
            rp = Path(rec["path"])
            data["recording"]["path"] = str(rp if rp.is_absolute() else base / rp)
        else:
            from . import datasets
            try:
                datasets.get(rec["name"])
            except BearingLabError as exc:
                raise _err(name, str(exc)) from None
        cal = raw.get("calibration", {})
        bad = set(cal) - {"enabled", "frequency_hz", "damping_ratio", "gain"}
        if bad:
            raise _err(name, f"unknown key calibration.{sorted(bad)[0]}")
        for key in ("frequency_hz", "damping_ratio", "gain"):
            if key in cal:
                _check_bounds(name, f"calibration.{key}", cal[key])
        order = raw.get("ordering")
        if order is not None:
            bad = set(order) - {"recording", "scene", "label", "set"}
            if bad or not order.get("recording") or not order.get("scene"):
                raise _err(name, "[ordering] needs recording and scene (and optionally label, set)")
            data["ordering"]["scene"] = _check_scene(name, order["scene"], order.get("set"), "ordering", base)
        tol = _tolerances(name, raw.get("tolerances"), RECORDING_QUANTITIES)
        if "impulse_strength_ratio" in tol and order is None:
            raise _err(name, "tolerances.impulse_strength_ratio needs an [ordering] table")
    st = raw.get("studies")
    if st is not None and not isinstance(st, dict):
        raise _err(name, "[studies] must be a table")
    return ValidationCase(name=name, title=str(raw.get("title", name)), kind=kind, path=path, data=data,
                          tolerances=tol, default=bool(raw.get("default", False)))


def _locate(name_or_path: str, mirror=None) -> Path | None:
    p = Path(name_or_path)
    if p.is_absolute() or p.exists():
        return p if p.is_file() else None
    from . import datasets
    return datasets.locate(name_or_path, mirror=mirror)


def check_case(case: ValidationCase, mirror=None) -> None:
    """Raise ValidationCaseError when a recording the case needs is not available."""
    for rec in case.recording_names:
        if _locate(rec, mirror) is None:
            m = mirror or os.environ.get("BEARING_LAB_MIRROR")
            where = (f"not found in the mirror {m} nor the data directory" if m else
                     f"not found: BEARING_LAB_MIRROR is not set (set it to the public recordings' directory, "
                     f"or run `bearing-lab data fetch {rec}`)")
            raise _err(case.name, f"recording {rec!r} {where}")


def default_set(mirror=None):
    """The embedded default set: the ``paper`` case, and every shipped case marked
    ``default = true`` whose recordings are available.  Returns (cases, skipped) with
    skipped = [(name, title, reason)]."""
    cases, skipped = [], []
    for name in list_cases():
        c = load_case(name)
        if not c.default and name != DEFAULT_CASE:
            continue
        try:
            check_case(c, mirror)
        except ValidationCaseError as exc:
            skipped.append((c.name, c.title, str(exc)))
            continue
        cases.append(c)
    cases.sort(key=lambda c: (c.name != DEFAULT_CASE, c.name))
    return cases, skipped


# ------------------------------------------------------------------ helpers
class _Steps:
    """A tqdm bar over a case's steps (silent when progress is off)."""

    def __init__(self, desc, total, progress, position=1):
        self.bar = None
        if progress:
            from tqdm.auto import tqdm
            self.bar = tqdm(total=total, desc=desc, leave=False, position=position, unit="step")

    def step(self, what):
        if self.bar is not None:
            self.bar.set_postfix_str(what)
            self.bar.update(1)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _versions() -> dict:
    import importlib.metadata as md
    out = {"python": platform.python_version()}
    for pkg in ("bearing_lab", "numpy", "scipy", "numba", "xarray", "netCDF4", "matplotlib"):
        try:
            out[pkg] = md.version(pkg)
        except md.PackageNotFoundError:
            out[pkg] = "?"
    return out


def _git_commit() -> str:
    root = Path(__file__).resolve().parents[1]
    try:
        r = subprocess.run(["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True,
                           text=True, timeout=5)
        return r.stdout.strip() or "?"
    except (OSError, subprocess.SubprocessError):
        return "?"


def _sha256(path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 22), b""):
            h.update(chunk)
    return h.hexdigest()


def _simulate(scene, **kw):
    from .sim import simulate
    return simulate(scene, progress=False, **kw)


def _numerical_error(scene, base_ds, overrides, duration=0.25):
    """Peak difference between the run at the scene's rtol and a rerun at rtol/10 (first ``duration`` s)."""
    rtol = float(base_ds.attrs.get("solver_rtol", 1e-5))
    fine = _simulate(scene, duration=duration, fs=float(base_ds.attrs["sampling_rate_hz"]), rtol=rtol / 10,
                     **overrides)
    a = fine["outer_ring_acc_y"].values
    b = base_ds["outer_ring_acc_y"].values[: a.size]
    d = float(np.max(np.abs(a - b)))
    pk = float(np.max(np.abs(b))) or 1.0
    return {"rtol": rtol, "rtol_check": rtol / 10, "duration_s": duration, "peak_difference_m_s2": d,
            "peak_difference_pct_of_peak": 100.0 * d / pk, "wall_time_fine_s": float(fine.attrs["wall_time_s"])}


def _bounds(b) -> str:
    return f"{b[0]:.4g} to {b[1]:.4g}"


def _clean(v):
    """JSON-safe: NaN/inf -> None, numpy scalars -> Python (one rule for every JSON output)."""
    from ._json import clean
    return clean(v)


@dataclass
class CaseOutcome:
    name: str
    title: str
    status: str                    # pass | fail | error | skip
    rows: list = field(default_factory=list)
    wall_time_s: float = 0.0
    out_dir: Path | None = None
    reason: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def n_pass(self):
        return sum(bool(r["pass"]) for r in self.rows)


# ------------------------------------------------------------------ figures
def _fig(h=3.2, n=1, w=10):
    from matplotlib.figure import Figure
    fig = Figure(figsize=(w, h * n), layout="constrained")
    axes = fig.subplots(n, 1, squeeze=False)[:, 0]
    return fig, axes


def _markers(ax, freqs: dict, fmax, styles=None):
    styles = styles or {}
    for lab, f in freqs.items():
        if f and np.isfinite(f) and f <= fmax:
            c, ls = styles.get(lab, ("k", "--"))
            ax.axvline(f, color=c, ls=ls, lw=0.8, label=lab)


# ------------------------------------------------------------------ paper case
def _paper_reference(case) -> dict:
    with open(case.data["reference_path"], "rb") as fh:
        return tomllib.load(fh)


def _run_paper(case: ValidationCase, out: Path, steps: _Steps, report):
    from .bearings import get_bearing
    from . import analysis as A
    ref = _paper_reference(case)
    rpm = float(ref.get("speed_rpm", 1800.0))
    geom = get_bearing(case.data.get("bearing", "6308"))
    kin = geom.fault_frequencies(rpm / 60.0)
    kin_ref = ref.get("kinematic", {})
    rows, signals, sims, meas, errs = [], {}, {}, {}, {}
    fs = None
    for run in case.data["run"]:
        label = run["label"]
        ov = dict(run.get("set", {}))
        ds = _simulate(run["scene"], duration=float(run.get("duration_s", 1.0)), **ov)
        steps.step(f"simulate {label}")
        fs = float(ds.attrs["sampling_rate_hz"])
        x = ds["outer_ring_acc_y"].values
        sims[label], signals[f"simulation_{label}"] = ds, x
        m = measure(x, fs, bearing=geom, rpm=rpm, shaft_hz=rpm / 60.0)
        meas[label] = m
        errs[label] = _numerical_error(run["scene"], ds, ov)
        steps.step(f"error estimate {label}")
        rr = ref.get(label, {})
        pe, ps = rr.get("experiment", {}), rr.get("simulation", {})
        notes = m["extras"]["notes"]
        for q, kq in (("shaft_hz", "shaft_hz"), ("bpfo", "bpfo"), ("bpfi", "bpfi")):
            if q not in case.tolerances:
                continue
            kv = float(kin_ref.get(kq, kin["shaft" if q == "shaft_hz" else q] if q != "shaft_hz" else rpm / 60.0))
            rows.append(make_row(q, m[q], kv, case.tolerances[q], group=label,
                                 reference=f"kinematic at {rpm:g} r/min", note=notes.get(q, ""),
                                 paper_experiment=pe.get(q), paper_simulation=ps.get(q)))
        if "excitation_period" in case.tolerances and "excitation_period_s" in pe:
            rows.append(make_row("excitation_period", m["excitation_period"], pe["excitation_period_s"],
                                 case.tolerances["excitation_period"], group=label,
                                 reference="paper, measured", note=notes.get("excitation_period", ""),
                                 paper_experiment=pe["excitation_period_s"],
                                 paper_simulation=ps.get("excitation_period_s")))
        if "peak" in case.tolerances and "amplitude_g" in pe:
            rows.append(make_row("peak", m["peak"] / G0, pe["amplitude_g"], case.tolerances["peak"], group=label,
                                 label=f"{label}: waveform amplitude (max |a| over {ds.sizes['time'] / fs:g} s)",
                                 units="g", reference="paper, measured (read from its waveform figure)",
                                 note=("max |a| of the simulated 20 kHz record; the paper gives 'about "
                                       f"±{pe['amplitude_g']:g} g' for experiment and simulation"),
                                 paper_experiment=pe["amplitude_g"], paper_simulation=ps.get("amplitude_g")))
    steps.step("measure")
    n = min(len(v) for v in signals.values())
    result = compare(signals, fs, rows, n=n, ses_fmax=1000.0,
                     attrs={"case": case.name, "bpfo_hz": kin["bpfo"], "bpfi_hz": kin["bpfi"],
                            "shaft_hz": rpm / 60.0, "kind": "paper"})
    # ---- figures: the paper's Figs 8-11 (waveforms and spectra; experiment = the paper's figures)
    figs = []
    for label, amp in (("healthy", ref.get("healthy", {}).get("experiment", {}).get("amplitude_g")),
                       ("slot", ref.get("slot", {}).get("experiment", {}).get("amplitude_g"))):
        if label not in sims:
            continue
        ds = sims[label]
        x = ds["outer_ring_acc_y"].values / G0
        t = ds["time"].values
        fig, (a1, a2) = _fig(n=2)
        sel = t <= 0.1
        a1.plot(t[sel], x[sel], lw=0.6, color="tab:blue", label="bearing_lab simulation")
        if amp:
            a1.axhspan(-amp, amp, color="tab:orange", alpha=0.12,
                       label=f"paper: about ±{amp:g} g (experiment and simulation)")
            a1.axhline(amp, color="tab:orange", lw=0.8)
            a1.axhline(-amp, color="tab:orange", lw=0.8)
        a1.set_xlabel("time (s)")
        a1.set_ylabel("acceleration (g)")
        a1.legend(loc="upper right", fontsize=8)
        a1.set_title(f"{label}: outer-ring acceleration, first 0.1 s (cf. the paper's "
                     f"{'Fig. 8' if label == 'healthy' else 'Fig. 10'}); simulated max |a| = "
                     f"{np.max(np.abs(x)):.3g} g", fontsize=10)
        f, a = A.amplitude_spectrum(x - x.mean(), fs, window="hann")
        s2 = f <= 1000
        a2.semilogy(f[s2], a[s2], lw=0.6, color="tab:blue", label="bearing_lab simulation")
        pe = ref.get(label, {}).get("experiment", {})
        ps = ref.get(label, {}).get("simulation", {})
        _markers(a2, {"kinematic f_i": rpm / 60, "kinematic BPFO": kin["bpfo"], "kinematic BPFI": kin["bpfi"]},
                 1000, {"kinematic f_i": ("0.4", "--"), "kinematic BPFO": ("tab:red", "--"),
                        "kinematic BPFI": ("tab:green", "--")})
        for q, c in (("shaft_hz", "0.4"), ("bpfo", "tab:red"), ("bpfi", "tab:green")):
            if q in pe:
                a2.axvline(pe[q], color=c, ls=":", lw=1.2)
            if q in ps:
                a2.axvline(ps[q], color=c, ls="-.", lw=0.8)
        a2.plot([], [], "k:", label="paper: experiment (Table 2)")
        a2.plot([], [], "k-.", label="paper: simulation (Table 2)")
        a2.set_xlabel("frequency (Hz)")
        a2.set_ylabel("amplitude (g)")
        a2.legend(loc="upper right", fontsize=7, ncol=2)
        a2.set_title(f"{label}: amplitude spectrum (cf. the paper's "
                     f"{'Fig. 9' if label == 'healthy' else 'Fig. 11'})", fontsize=10)
        figs.append((fig, f"{label}: simulated waveform and spectrum. The paper's experimental traces are "
                          "available only as figures: its reported amplitude and Table 2 frequencies are drawn "
                          "as bands and lines."))
    steps.step("figures")
    fig, (ax,) = _fig(h=3.6)
    result.plot_envelope(ax=ax, fmax=600)
    ax.set_title("squared envelope spectra (whole band), kinematic fault frequencies and harmonics", fontsize=10)
    figs.append((fig, "SES of both simulations with kinematic BPFO (red), BPFI (green) and shaft (grey) markers."))
    # ---- HOOK: section-5 trends (2-D defect studies) ---------------------------------
    # `bearing-lab study paper` lives in bearing_lab/studies.py: run_paper_studies(out_dir) returns an
    # xarray Dataset or a dict of tables (the size, offset, skew and speed studies of section 5).
    # When it is importable and the case's [studies] table says enabled = true, its tables are
    # included here; rows it returns in the validation-row format are added to the case table.
    from .report import Report
    side = Report("studies")
    studies = _paper_studies(case, out, ref, side)
    if studies.get("rows"):
        rows.extend(studies["rows"])
        result = compare(signals, fs, rows, n=n, ses_fmax=1000.0, attrs=dict(result.dataset.attrs))
    steps.step("studies")
    report.add_comparison(result, "Comparison table", figures=False, show_paper=True,
                          intro=("Experiment column: the kinematic value (frequencies) or the paper's measured "
                                 "figure (period, amplitude). The paper's own Table 2 numbers are shown beside."))
    report.add_figures(figs, "Waveforms, spectra and SES (Figs 8-11)")
    report.sections.extend(side.sections)
    extra = {"numerical_error": errs,
             "compute": {k: {"wall_time_s": float(v.attrs["wall_time_s"]),
                             "compile_time_s": float(v.attrs.get("compile_time_s", 0.0)),
                             "solver_rtol": float(v.attrs.get("solver_rtol", float("nan"))),
                             "solver_steps": int(v.attrs.get("solver_steps", 0))} for k, v in sims.items()},
             "studies": {"status": studies.get("status", ""), "trends": studies.get("trends", [])}}
    prov = {"experiment": "figures reported by the paper (validation/paper_reference.toml): "
                          + str(ref.get("source", "")),
            "reference file sha256": _sha256(case.data["reference_path"])}
    for k, v in sims.items():
        prov[f"scene ({k})"] = v.attrs.get("scene_toml", "")
    return result, rows, extra, prov


def _paper_studies(case, out: Path, ref: dict, report) -> dict:
    cfg = case.data.get("studies") or {}
    if not cfg.get("enabled", False):
        return {"status": "disabled in the case file"}
    import importlib
    mod_name = cfg.get("module", "bearing_lab.studies")
    fn_name = cfg.get("function", "run_paper_studies")
    try:
        mod = importlib.import_module(mod_name)
        fn = getattr(mod, fn_name)
    except (ImportError, AttributeError):
        msg = (f"{mod_name}.{fn_name} is not available yet: the section-5 trends (size, offset, skew, speed) "
               "are not part of this report. The paper's reported trends are kept in paper_reference.toml.")
        trends = ref.get("section5", {}).get("trends", {})
        report.add_table([{"study": k, "paper reports": v} for k, v in trends.items()],
                         "Section 5 trends (2-D defect studies)", intro=msg)
        return {"status": msg}
    sdir = out / "studies"
    sdir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    try:
        res = fn(sdir, progress=False)
    except TypeError:
        res = fn(sdir)
    took = time.perf_counter() - t0
    rows, trends = [], []
    html_parts = [f'<p>From {mod_name}.{fn_name} ({took:.1f} s); its own page with the pulse figures: '
                  f'<a href="studies/index.html">studies/index.html</a>.</p>']
    import xarray as xr
    if isinstance(res, xr.Dataset) and {"study", "label", "peak_acceleration", "excitation_duration"} <= set(res.variables):
        rows, trends = _study_rows(case, res, ref)
        html_parts.append("<h3>Trends the paper reports, and ours</h3>" + _trend_table(trends))
        tab = res.to_dataframe()
        html_parts.append("<h3>Study table</h3>" + tab.to_html(float_format=lambda v: f"{v:.5g}"))
    else:
        tables = res if isinstance(res, dict) else {"studies": res}
        for name, tab in tables.items():
            if name == "rows" and isinstance(tab, list):
                rows = [r for r in tab if isinstance(r, dict) and {"quantity", "simulation", "experiment", "pass"} <= set(r)]
                continue
            try:
                if isinstance(tab, (xr.Dataset, xr.DataArray)):
                    tab = tab.to_dataframe()
                if hasattr(tab, "to_html"):
                    html_parts.append(f"<h3>{name}</h3>" + tab.to_html(float_format=lambda v: f"{v:.5g}"))
                else:
                    html_parts.append(f"<h3>{name}</h3><pre>{tab!s}</pre>")
            except Exception as exc:  # a table we cannot render is reported, not fatal
                html_parts.append(f"<h3>{name}</h3><p>(could not render: {type(exc).__name__}: {exc})</p>")
    report.add_html("\n".join(html_parts), "Section 5 trends (2-D defect studies)")
    return {"status": f"included ({took:.1f} s)", "rows": rows, "trends": trends}


def _study_rows(case, ds, ref):
    """Rows (offset ratios, where the paper gives numbers) and the trend table from the studies' Dataset."""
    study = [str(s) for s in ds["study"].values]
    label = [str(s) for s in ds["label"].values]
    acc = np.asarray(ds["peak_acceleration"].values, float) / G0
    dur = np.asarray(ds["excitation_duration"].values, float)

    def vals(s, arr):
        return [float(a) for st, a in zip(study, arr) if st == s], [lb for st, lb in zip(study, label) if st == s]

    rows = []
    tol = case.tolerances.get("offset_ratio") or Tolerance(
        "pct", 10.0, "paper.md: the offset study's ratios (not its absolute values, which depend on parameters "
        "the paper does not give) are the comparison to report; 10 % allows for the sampled-peak scatter of "
        "a single short passage (reference.md)")
    s5 = ref.get("section5", {})
    pr = s5.get("offset_acceleration_ratios", [1.0, 0.78, 0.54])
    a, labs = vals("offset", acc)
    if len(a) >= 3 and a[0] > 0:
        for i, h in ((1, "B/3"), (2, "B/2")):
            rows.append(make_row(f"offset_ratio_{h}", a[i] / a[0], pr[i], tol, units="1",
                                 label=f"section 5.2: peak acceleration ratio H = {h} / H = 0",
                                 reference="paper, its section 5.2 (28.82, 22.48, 15.64 g)",
                                 note=f"ours {a[0]:.3g}, {a[1]:.3g}, {a[2]:.3g} g (1 passage, 100 kHz)",
                                 paper_simulation=pr[i]))
    trends = []

    def mono(v, up):
        d = np.diff(v)
        return bool(np.all(d > 0)) if up else bool(np.all(d < 0))

    for s, what, arr, up, paper in (
            ("size", "excitation duration", dur * 1e3, True, "T1 < T2 < T3"),
            ("size", "peak acceleration", acc, True, "amplitude grows with size"),
            ("offset", "peak acceleration", acc, False, "amplitude falls as H grows (28.82, 22.48, 15.64 g)"),
            ("skew", "excitation duration", dur * 1e3, False, "duration falls as θ grows"),
            ("skew", "peak acceleration", acc, True, "amplitude grows with θ"),
            ("speed", "excitation duration", dur * 1e3, False, "duration falls with speed"),
            ("speed", "peak acceleration", acc, True, "amplitude grows with speed")):
        v, labs = vals(s, arr)
        if len(v) < 2:
            continue
        unit = "ms" if "duration" in what else "g"
        trends.append({"study": s, "quantity": what, "paper reports": paper,
                       "ours": ", ".join(f"{lb}: {x:.3g} {unit}" for lb, x in zip(labs, v)),
                       "agrees": mono(v, up)})
    return rows, trends


def _trend_table(trends):
    from .report import esc
    out = ["<table><tr><th class='l'>study</th><th class='l'>quantity</th><th class='l'>paper reports</th>"
           "<th class='l'>ours</th><th>agrees</th></tr>"]
    for t in trends:
        ok = t["agrees"]
        out.append(f"<tr class='{'pass' if ok else 'fail'}'><td class='l'>{esc(t['study'])}</td>"
                   f"<td class='l'>{esc(t['quantity'])}</td><td class='l'>{esc(t['paper reports'])}</td>"
                   f"<td class='l'>{esc(t['ours'])}</td><td class='status'>{'yes' if ok else 'NO'}</td></tr>")
    out.append("</table><p class='note'>A trend counts as reproduced when it is monotonic over the study's "
               "three cases. Durations, the offset trend and the speed trend follow from geometry and "
               "kinematics; the amplitude trends with size and skew depend on how the defect's edges meet "
               "the contact, and the model may honestly disagree with the paper there (paper.md).</p>")
    return "".join(out)


# ------------------------------------------------------------------ recording cases
def _open(case: ValidationCase, rec_name, mirror=None):
    from .io import open_recording
    path = _locate(rec_name, mirror)
    if path is None:
        check_case(case, mirror)
    ds = open_recording(path)
    return path, ds


def _channel(case, ds):
    ch = case.recording.get("channel") or ds.attrs.get("default_channel") or list(ds.data_vars)[0]
    if ch not in ds:
        raise _err(case.name, f"recording has no channel {ch!r}; channels are {', '.join(ds.data_vars)}")
    return ch


def _run_recording(case: ValidationCase, out: Path, steps: _Steps, report, mirror=None):
    from .analysis import amplitude_spectrum
    bearing = case.data.get("bearing", "6205")
    rec = case.recording
    rec_name = rec.get("path") or rec.get("name")
    path, ds_m = _open(case, rec_name, mirror)
    ch = _channel(case, ds_m)
    scale = float(rec.get("scale", 1.0))
    fs = float(ds_m.attrs["sampling_rate_hz"])
    x_full = ds_m[ch].values.astype(float) * scale
    rpm_file = ds_m.attrs.get("shaft_speed_rpm")
    rpm_file = float(rpm_file) if rpm_file else None
    if rec.get("name"):
        from . import datasets
        reg = datasets.get(rec["name"])
        if reg.sha256 and ds_m.attrs.get("source_sha256") and ds_m.attrs["source_sha256"] != reg.sha256:
            raise _err(case.name, f"{path}: sha256 does not match the registry's; replace the copy")
    steps.step("open recording")
    m_full = measure(x_full, fs, bearing=bearing, rpm=rpm_file)
    sc = case.data["scene"]
    speed = sc.get("speed", "estimate")
    if speed == "estimate":
        rpm = 60.0 * m_full["extras"]["shaft_hz_used"]
        speed_src = f"estimated from the recording's shaft line: {rpm:.2f} r/min (file: {rpm_file} r/min)"
    elif speed == "file":
        if rpm_file is None:
            raise _err(case.name, "scene.speed = 'file' but the recording stores no rpm")
        rpm, speed_src = rpm_file, f"stored in the recording: {rpm_file:g} r/min"
    else:
        rpm, speed_src = float(speed), f"given by the case: {float(speed):g} r/min"
    dur = float(sc.get("duration_s", 1.0))
    ov = dict(sc.get("set", {}))
    ov["speed_rpm"] = rpm
    cal_cfg = case.data.get("calibration", {})
    calibrate = bool(cal_cfg.get("enabled", False))
    if calibrate:
        ov["sensor.enabled"] = False     # the fit applies the resonator to the sensor-off run
    ds_s = _simulate(sc["scene"], duration=dur, fs=fs, **ov)
    steps.step("simulate")
    xs = ds_s["outer_ring_acc_y"].values
    n = xs.size
    if n > x_full.size:
        raise _err(case.name, f"the recording ({x_full.size / fs:.2f} s) is shorter than scene.duration_s={dur:g}")
    xe = x_full[:n]
    # frequencies from the full record (finer lines), amplitudes from the same length as the simulation;
    # the simulation's shaft speed is its input (analysis.shaft_frequency can lock onto BPFO/3 on a
    # signal without a shaft line), so its fault lines are searched around that speed
    m_seg = measure(xe, fs, bearing=bearing, rpm=rpm_file, fault=m_full["extras"]["fault"])
    m_sim = measure(xs, fs, bearing=bearing, rpm=rpm, shaft_hz=rpm / 60.0, fault=m_full["extras"]["fault"])
    steps.step("measure")
    err = _numerical_error(sc["scene"], ds_s, {k: v for k, v in ov.items()})
    steps.step("error estimate")
    period_e = m_full["excitation_period"]
    cal: CalibrationResult | None = None
    xc = None
    m_cal = None
    cal_note = ""
    if calibrate and np.isfinite(period_e):
        try:
            cal = calibrate_sensor(x_full, xs, fs, period_e, band=m_full["extras"]["band"],
                                   frequency_bounds=tuple(cal_cfg.get("frequency_hz", (500.0, 0.45 * fs))),
                                   damping_bounds=tuple(cal_cfg.get("damping_ratio", (0.005, 0.5))),
                                   gain_bounds=tuple(cal_cfg.get("gain", (1e-3, 1e3))))
            ds_c = _simulate(sc["scene"], duration=dur, fs=fs, **{**ov, **cal.overrides()})
            xc = ds_c["outer_ring_acc_y"].values
            m_cal = measure(xc, fs, bearing=bearing, rpm=rpm, shaft_hz=rpm / 60.0, fault=m_full["extras"]["fault"])
        except ValidationCaseError as exc:
            cal_note = f"calibration not possible: {exc}"
    elif calibrate:
        cal_note = "calibration not possible: the recording shows no impact train (no fault diagnosed)"
    steps.step("calibrate")
    # ---- ordering of impulse strength against another recording (e.g. @6 against @3)
    order = case.data.get("ordering")
    order_info = {}
    if order is not None:
        opath, ods = _open(case, order["recording"], mirror)
        och = _channel(case, ods)
        xo = ods[och].values.astype(float) * scale
        mo = measure(xo, fs, bearing=bearing, rpm=ods.attrs.get("shaft_speed_rpm"),
                     fault=m_full["extras"]["fault"])
        oov = dict(order.get("set", {}))
        oov.update({"speed_rpm": 60.0 * mo["extras"]["shaft_hz_used"] if speed == "estimate" else rpm})
        if calibrate:
            oov["sensor.enabled"] = False
        dso = _simulate(order["scene"], duration=dur, fs=fs, **oov)
        xso = dso["outer_ring_acc_y"].values
        pe_o = mo["excitation_period"] if np.isfinite(mo["excitation_period"]) else period_e
        ps = m_sim["excitation_period"] if np.isfinite(m_sim["excitation_period"]) else period_e
        s_e, s_eo = impulse_strength(x_full, fs, period_e, band=m_full["extras"]["band"]), \
            impulse_strength(xo, fs, pe_o, band=mo["extras"]["band"])
        s_s, s_so = impulse_strength(xs, fs, ps), impulse_strength(xso, fs, ps)
        order_info = {"label": order.get("label", "this / other"), "other_recording": str(opath),
                      "other_sha256": ods.attrs.get("source_sha256", ""),
                      "experiment_this": s_e, "experiment_other": s_eo, "simulation_this": s_s,
                      "simulation_other": s_so, "other_scene": dso.attrs.get("scene_name", order["scene"])}
        steps.step("ordering")
    # ---- rows
    rows = []
    T = case.tolerances
    fe = m_full["extras"]["notes"]
    fsn = m_sim["extras"]["notes"]

    def note(q, sim_notes, exp_notes):
        parts = []
        if q in sim_notes:
            parts.append("simulation: " + sim_notes[q])
        if q in exp_notes:
            parts.append("recording: " + exp_notes[q])
        return "; ".join(parts)

    for q in ("shaft_hz", "bpfo", "bpfi", "excitation_period"):
        if q in T:
            rows.append(make_row(q, m_sim[q], m_full[q], T[q], reference=f"recording ({x_full.size / fs:.1f} s)",
                                 note=note(q, fsn, fe)))
    for q in ("rms", "peak", "crest_factor", "kurtosis", "impulse_duration"):
        if q in T:
            rows.append(make_row(q, m_sim[q], m_seg[q], T[q], label=QUANTITIES[q][0] + " (uncalibrated)",
                                 reference=f"recording, first {n / fs:g} s",
                                 note=note(q, fsn, m_seg["extras"]["notes"])))
        qc = f"{q}_calibrated"
        if qc in T:
            v = m_cal[q] if m_cal is not None else float("nan")
            rows.append(make_row(qc, v, m_seg[q], T[qc], label=QUANTITIES[q][0] + " (calibrated)",
                                 units=QUANTITIES[q][1], reference=f"recording, first {n / fs:g} s",
                                 note=cal_note or (note(q, m_cal["extras"]["notes"], m_seg["extras"]["notes"])
                                                   if m_cal else "")))
    if "impulse_strength_ratio" in T and order_info:
        oi = order_info
        rs = oi["simulation_this"] / oi["simulation_other"] if oi["simulation_other"] else float("nan")
        re_ = oi["experiment_this"] / oi["experiment_other"] if oi["experiment_other"] else float("nan")
        rows.append(make_row("impulse_strength_ratio", rs, re_, T["impulse_strength_ratio"],
                             label=f"impulse strength ratio {oi['label']} (median impact peak)", units="1",
                             reference=f"recordings {Path(str(path)).name} / {Path(oi['other_recording']).name}",
                             note=(f"median impact peaks, m s-2: recording {oi['experiment_this']:.3g} / "
                                   f"{oi['experiment_other']:.3g}; simulation {oi['simulation_this']:.3g} / "
                                   f"{oi['simulation_other']:.3g} (uncalibrated, same structure for both)")))
    # ---- comparison on one time base, impacts aligned
    shift = 0
    if np.isfinite(period_e):
        te = impact_times(xe, fs, period_e, band=m_seg["extras"]["band"] or m_full["extras"]["band"])
        ts = impact_times(xs, fs, m_sim["excitation_period"] if np.isfinite(m_sim["excitation_period"])
                          else period_e, band=m_sim["extras"]["band"])
        if te.size and ts.size:
            shift = int(round((te[0] - ts[0]) * fs) % round(period_e * fs))
    from .compare import _shift
    sig = {"experiment": xe, "simulation": _shift(xs, shift, n)}
    if xc is not None:
        sig["simulation_calibrated"] = _shift(xc, shift, n)
    ff = m_full["extras"]["analysis"]["fault_frequencies"]
    result = compare(sig, fs, rows, n=n, band=m_full["extras"]["band"], ses_fmax=1000.0,
                     attrs={"case": case.name, "kind": "recording", "alignment_shift_samples": shift,
                            "bpfo_hz": ff["bpfo"]["expected_hz"], "bpfi_hz": ff["bpfi"]["expected_hz"],
                            "shaft_hz": m_full["extras"]["shaft_hz_used"],
                            "calibration": cal.as_dict() if cal else {}, "speed_source": speed_src})
    steps.step("compare")
    # ---- report
    report.add_comparison(result, "Comparison table", figures=False,
                          intro=("Frequencies: the full recording against the simulation; amplitudes: the first "
                                 f"{n / fs:g} s of the recording against the {n / fs:g} s simulation, both at "
                                 f"{fs:g} Hz. 'Uncalibrated': the scene's structure as it is; 'calibrated': "
                                 "with the sensor resonator fitted to this recording."))
    figs = []
    t = np.arange(n) / fs
    win = (t >= 0) & (t <= min(0.1, t[-1]))
    fig, axes = _fig(n=3 if xc is not None else 2, h=2.6)
    axes[0].plot(t[win], xe[win] / G0, lw=0.6, color="k")
    axes[0].set_title(f"recording {Path(str(path)).name} ({ch})", fontsize=10)
    axes[1].plot(t[win], sig["simulation"][win] / G0, lw=0.6, color="tab:blue")
    axes[1].set_title("simulation before calibration (scene structure, no sensor resonator)", fontsize=10)
    if xc is not None:
        axes[2].plot(t[win], xe[win] / G0, lw=0.5, color="0.6", label="recording")
        axes[2].plot(t[win], sig["simulation_calibrated"][win] / G0, lw=0.6, color="tab:red",
                     label="simulation, calibrated")
        axes[2].legend(loc="upper right", fontsize=8)
        axes[2].set_title(f"after calibration: sensor resonance {cal.frequency_hz:.0f} Hz, ζ = {cal.damping_ratio:.3f}, "
                          f"gain {cal.gain:.3g}", fontsize=10)
    for a in axes:
        a.set_ylabel("a (g)")
    axes[-1].set_xlabel("time (s), impacts aligned")
    figs.append((fig, "Waveforms on one time base, the simulation shifted so that its first impact falls on the "
                      f"recording's (shift {shift} samples); cf. the paper's Figs 8 and 10."))
    fig, axes = _fig(n=2, h=3.0)
    for a, (lab, y, c) in zip(axes, (("recording", xe, "k"), ("simulation (calibrated)" if xc is not None else
                                                                "simulation", xc if xc is not None else xs,
                                                                "tab:red"))):
        f, amp = amplitude_spectrum(y - np.mean(y), fs, window="hann")
        a.semilogy(f, amp / G0, lw=0.5, color=c, label=lab)
        if xc is not None and lab != "recording":
            f2, amp2 = amplitude_spectrum(xs - np.mean(xs), fs, window="hann")
            a.semilogy(f2, amp2 / G0, lw=0.4, color="tab:blue", alpha=0.6, label="simulation (uncalibrated)")
        a.set_ylabel("amplitude (g)")
        a.legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("frequency (Hz)")
    figs.append((fig, "Amplitude spectra, recording above and simulation below (cf. the paper's Figs 9 and 11)."))
    fig, (ax,) = _fig(h=3.6)
    result.plot_envelope(ax=ax, fmax=600)
    ax.set_title("squared envelope spectra (demodulation band from the recording's kurtogram)", fontsize=10)
    figs.append((fig, "SES of recording and simulations with the kinematic BPFO (red), BPFI (green) and shaft "
                      "(grey) frequencies and harmonics."))
    report.add_figures(figs, "Waveforms, spectra and SES")
    if cal is not None:
        fig, (ax,) = _fig(h=3.2)
        tt = cal.envelope_time * 1e3
        ax.semilogy(tt, cal.envelope_experiment / G0, "k", lw=1.0, label="recording")
        ax.semilogy(tt, cal.envelope_before / G0, color="tab:blue", lw=0.9, label="simulation before")
        ax.semilogy(tt, cal.envelope_after / G0, color="tab:red", lw=0.9, label="simulation after")
        ax.set_xlabel("time from the impact (ms)")
        ax.set_ylabel("mean envelope (g)")
        ax.legend(fontsize=8)
        ax.set_title("impulse ringing: mean Hilbert envelope around each impact", fontsize=10)
        report.add_figure(fig, "Calibration of the structural path",
                          caption="Mean envelope of the impacts before and after fitting the sensor resonator.")
        report.add_table([{"parameter": "resonance frequency (Hz)", "fitted": cal.frequency_hz,
                           "bounds": _bounds(cal.bounds["frequency_hz"])},
                          {"parameter": "damping ratio", "fitted": cal.damping_ratio,
                           "bounds": _bounds(cal.bounds["damping_ratio"])},
                          {"parameter": "gain", "fitted": cal.gain, "bounds": _bounds(cal.bounds["gain"])},
                          {"parameter": "fit error, RMS of log-amplitude residuals (dB)", "fitted": cal.fit_error_db,
                           "bounds": f"before calibration: {cal.initial_error_db:.1f} dB"},
                          {"parameter": "impacts used (recording / simulation)",
                           "fitted": f"{cal.n_impacts_experiment} / {cal.n_impacts_simulation}", "bounds": ""}],
                         "Calibration: fitted values",
                         intro=("Least squares on the measured impulse ringing (mean envelope), the mean spectrum "
                                "of the impact segments and the SES at five harmonics of the impact rate. "
                                "What limits it: " + cal.limits + "."))
    elif cal_note:
        report.add_html(f"<p>{cal_note}</p>", "Calibration of the structural path")
    extra = {"numerical_error": err, "calibration": cal.as_dict() if cal else {"note": cal_note or "disabled"},
             "compute": {"wall_time_s": float(ds_s.attrs["wall_time_s"]),
                         "compile_time_s": float(ds_s.attrs.get("compile_time_s", 0.0)),
                         "solver_rtol": float(ds_s.attrs.get("solver_rtol", float("nan"))),
                         "solver_steps": int(ds_s.attrs.get("solver_steps", 0))},
             "ordering": order_info, "speed_source": speed_src}
    prov = {"recording file": str(path), "recording sha256": ds_m.attrs.get("source_sha256") or _sha256(path),
            "channel": ch, "reader": ds_m.attrs.get("reader", ""), "calibration factor": scale,
            "speed": speed_src, "scene": ds_s.attrs.get("scene_toml", "")}
    if order_info:
        prov["ordering: other recording"] = f"{order_info['other_recording']} (sha256 {order_info['other_sha256']})"
    return result, rows, extra, prov


# ------------------------------------------------------------------ one case, all cases
def run_case(case: ValidationCase, out_dir, *, progress=True, mirror=None, position=1) -> CaseOutcome:
    """Run one case and write ``out_dir/<case>/{index.html, comparison.nc, summary.json}``."""
    from .report import Report
    t0 = time.perf_counter()
    out = Path(out_dir) / case.name
    out.mkdir(parents=True, exist_ok=True)
    report = Report(f"Validation: {case.name}", subtitle=case.title)
    n_steps = 7 if case.kind == "paper" else 9
    steps = _Steps(case.name, n_steps, progress, position=position)
    try:
        if case.kind == "paper":
            result, rows, extra, prov = _run_paper(case, out, steps, report)
        else:
            result, rows, extra, prov = _run_recording(case, out, steps, report, mirror=mirror)
    finally:
        steps.close()
    wall = time.perf_counter() - t0
    # compute time and numerical error
    ne = extra.get("numerical_error", {})
    ne_rows = []
    items = ne.items() if ne and all(isinstance(v, dict) for v in ne.values()) else [("simulation", ne)]
    for k, v in items:
        if v:
            ne_rows.append({"run": k, "solver rtol": v["rtol"], "check rtol": v["rtol_check"],
                            "checked over (s)": v["duration_s"], "peak difference (m s-2)": v["peak_difference_m_s2"],
                            "peak difference (% of peak)": v["peak_difference_pct_of_peak"]})
    comp = extra.get("compute", {})
    comp_rows = ([{"run": k, **v} for k, v in comp.items()] if comp and all(isinstance(v, dict) for v in comp.values())
                 else [{"run": "simulation", **comp}])
    report.add_table(comp_rows + [{"run": "whole case (simulations, analysis, calibration, figures)",
                                   "wall_time_s": wall}], "Compute time",
                     intro="Simulation wall time excludes numba compilation (compile_time_s).")
    report.add_table(ne_rows, "Estimated numerical error",
                     intro=("Each simulation is rerun with the solver tolerance divided by 10 over its first "
                            "seconds; the peak difference of the outer-ring acceleration estimates the "
                            "integration error."))
    info = {"case": case.name, "case file": str(case.path), "case TOML": case.path.read_text(encoding="utf-8"),
            **prov, "versions": _versions(), "git commit": _git_commit(),
            "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
            "host": f"{platform.system()} {platform.machine()}, {os.cpu_count()} cores"}
    report.add_provenance(info)
    report.add_html('<p>Data of this page: <a href="comparison.nc">comparison.nc</a> (waveforms on one time '
                    'base, spectra, SES and the table; <code>bearing_lab.compare.ComparisonResult.load</code>) and '
                    '<a href="summary.json">summary.json</a>.</p>', "Files")
    result.dataset.attrs["provenance"] = json.dumps(_clean({k: v for k, v in info.items() if k != "case TOML"}),
                                                    default=str)
    result.to_netcdf(out / "comparison.nc")
    report.save(out / "index.html")
    status = "pass" if rows and all(r["pass"] for r in rows) else "fail"
    summary = {"case": case.name,
               "rows": [{k: r[k] for k in ("quantity", "simulation", "experiment", "difference_pct",
                                           "tolerance_pct", "pass")} | {k: r[k] for k in r if k not in (
                   "quantity", "simulation", "experiment", "difference_pct", "tolerance_pct", "pass")}
                        for r in rows],
               "wall_time_s": wall, "status": status, "title": case.title,
               "calibration": extra.get("calibration"), "numerical_error": ne, "compute": comp,
               "ordering": extra.get("ordering"), "studies": extra.get("studies")}
    from ._files import write_text
    write_text(out / "summary.json", json.dumps(_clean(summary), indent=1, default=str, allow_nan=False))
    return CaseOutcome(case.name, case.title, status, rows, wall, out, extra=extra)


def run_validation(specs=None, out_dir="reports", *, strict=False, progress=True, mirror=None):
    """Run cases (default: the embedded default set) and write ``out_dir/index.html``.

    Returns (outcomes, exit status): 0, or 1 with ``strict`` when a row fails or a case errors,
    or 2 when a named case is bad input (unknown case, invalid file or value, missing
    recording): such a case is listed as "error" in the index with its reason, and every
    other case still runs.
    """
    from .report import write_index
    out_dir = Path(out_dir)
    notes = []
    bad_input = []  # cases named by the user that cannot run: listed, the others still run
    if specs:
        cases, skipped = [], []
        for spec in specs:
            try:
                c = load_case(spec)
                check_case(c, mirror)
            except ValidationCaseError as exc:
                bad_input.append(CaseOutcome(str(spec), str(spec), "error", reason=str(exc),
                                             extra={"bad_input": True}))
                continue
            cases.append(c)
    else:
        cases, skipped = default_set(mirror)
        if skipped:
            m = mirror or os.environ.get("BEARING_LAB_MIRROR")
            notes.append(("Recording cases skipped: " + ", ".join(s[0] for s in skipped) + ". "
                          + (f"They need the public recordings in the mirror {m}." if m else
                             "BEARING_LAB_MIRROR is not set: set it to a directory holding the public "
                             "recordings (e.g. ../shared/data) to add the CWRU cases.")))
    out_dir.mkdir(parents=True, exist_ok=True)
    outcomes = []
    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(total=len(cases), desc="validate", unit="case", position=0)
    for c in cases:
        if bar is not None:
            bar.set_postfix_str(c.name)
        try:
            oc = run_case(c, out_dir, progress=progress, mirror=mirror)
        except ValidationCaseError as exc:  # bad input found while running: listed, the rest run
            bad_input.append(CaseOutcome(c.name, c.title, "error", reason=str(exc),
                                         extra={"bad_input": True}))
            if bar is not None:
                bar.update(1)
            continue
        except Exception as exc:  # one broken case must not lose the others' reports: listed as "error"
            msg = f"{type(exc).__name__}: {exc}".splitlines()[0]
            if not isinstance(exc, BearingLabError):
                print(f"bearing-lab validate: case {c.name!r} failed to run: {msg}", file=sys.stderr)
            oc = CaseOutcome(c.name, c.title, "error", reason=msg)
        outcomes.append(oc)
        if bar is not None:
            bar.update(1)
    if bar is not None:
        bar.close()
    outcomes = bad_input + outcomes
    entries = []
    for oc in outcomes:
        entries.append({"case": oc.name, "title": oc.title, "status": oc.status, "n_pass": oc.n_pass,
                        "n_rows": len(oc.rows), "wall_time_s": oc.wall_time_s,
                        "failing": [r.get("label") or r["quantity"] for r in oc.rows if not r["pass"]],
                        "link": f"{oc.name}/index.html" if oc.status in ("pass", "fail") else None,
                        "reason": oc.reason})
    for name, title, reason in skipped:
        entries.append({"case": name, "title": title, "status": "skip", "reason": reason, "link": None})
    write_index(out_dir / "index.html", entries, notes=notes)
    bad = any(o.status in ("fail", "error") for o in outcomes)
    if bad_input:  # after every other case ran and the index was written
        return outcomes, 2
    return outcomes, (1 if strict and bad else 0)
