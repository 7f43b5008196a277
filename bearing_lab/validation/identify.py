"""Defect identification: along-track length, axial offset H and skew θ (and depth, if asked) from a recording.

Method (docs/identification.md): the recording is prepared once, the rig's structural path
and background are obtained once and held fixed (:mod:`.rig`); a coarse grid of scenes over
the defect's length, offset and skew is simulated with the sweep machinery (Dask or serial,
finished scenes and contact tables cached on disk), each scene :data:`SCENE_PASSAGES` impact periods
long; every scene's impact signature is scored against the recording's (:mod:`.candidates`,
:mod:`.signature`).  The refinement (:mod:`.identify_search`, on a lattice of 1/16 of the coarse
steps): from the best coarse scene a simplex search follows the misfit's valleys; the score's
roughness is probed there; each parameter's *profile* is then walked from the best value through the
coarse values and half steps, minimising over the other parameters at each until a value lies more
than ``threshold_db`` above the best (a value whose first scenes all lie far above it, by
:data:`.identify_run.PROFILE_CLEAR` thresholds, is excluded there, and the notes say which interval ends
were so excluded); and a polish searches again from the profile points that
explain the recording as well but lie apart from the best.
The interval of a parameter spans the accepted values up to the nearest excluded walked value on
each side.  A parameter no walked value excludes is *flat*: not identifiable from this recording.

Public API
----------
Identification                                   -- best scene, per-parameter profiles and intervals, landscape
default_grid(case) -> {key: [values]}            -- the coarse grid around the declared defect
identify(case, *, grid=None, refine=True, scheduler="serial", ...) -> Identification
"""
from __future__ import annotations

from dataclasses import dataclass, field
import itertools
import time

import numpy as np

from ..errors import ValidationCaseError
from ..sweep import dim_name, run_sweep, scene_hash
from . import simulation
from .candidates import candidate_signature, setting_for
from .identify_run import (PROFILE_CLEAR, PROFILE_CLEAR_SCENES, REFINE_MAX_SCENES, Journal, Progress,
                           comparison_fingerprint, estimate, estimate_text, mirrors)
from .identify_search import (REFINE_FIRST_STEP, REFINE_XTOL, ROUGHNESS_STEP, coarse_steps, minimise, polish, probes,
                              recheck, walk_profiles)
from .load import load_case
from .recording import open_spec
from .recording_case import comparison_band, comparison_overrides, prepare
from .rig import background_for, path_for

__all__ = ["Identification", "IdentificationInterrupted", "default_grid", "identify", "PARAMS"]

#: searched scene keys -> (short name, unit)
PARAMS = {"defect.length_mm": ("length", "mm"), "defect.offset_mm": ("offset H", "mm"),
          "defect.skew_deg": ("skew θ", "degree"), "defect.depth_mm": ("depth", "mm")}
#: smallest interval threshold, dB: two halves of one recording share jitter and path, so their
#: misfit understates how much a different noise realisation moves a score
MIN_THRESHOLD_DB = 0.3


@dataclass
class Identification:
    case: str
    points: list                         # [{key: value, ..., "score_db", "shape_db", "level_db"}]
    best: dict
    parameters: dict                     # key -> {best, interval, identifiable, statement, profile}
    threshold_db: float
    noise_db: float
    level_weight: float
    level_reason: str
    grid: dict
    n_scenes: int
    cpu_time_s: float
    wall_time_s: float
    notes: list = field(default_factory=list)
    signatures: dict = field(default_factory=dict)   # "recording", "best" -> Signature
    declared: dict = field(default_factory=dict)
    roughness_db: float | None = None    # score change for ROUGHNESS_STEP of a grid step at the best scene
    partial: bool = False                # stopped before the end: the scenes done only, nothing final
    resumed: int = 0                     # scenes read back from the journal of an earlier run
    estimate: dict = field(default_factory=dict)   # identify_run.estimate() made before the scenes ran
    setup_cpu_s: float = 0.0             # CPU s of preparing the comparison (recording, path, background)
    explains_recording: bool | None = None   # the best scene within the threshold of the recording

    def to_dict(self) -> dict:
        return {"case": self.case, "best": self.best, "parameters": self.parameters,
                "threshold_db": self.threshold_db, "noise_db": self.noise_db, "level_weight": self.level_weight,
                "level_reason": self.level_reason, "grid": self.grid, "n_scenes": self.n_scenes,
                "cpu_time_s": self.cpu_time_s, "wall_time_s": self.wall_time_s, "notes": self.notes,
                "declared": self.declared, "roughness_db": self.roughness_db, "partial": self.partial,
                "resumed": self.resumed, "estimate": self.estimate, "setup_cpu_s": self.setup_cpu_s,
                "explains_recording": self.explains_recording}


class IdentificationInterrupted(KeyboardInterrupt):
    """An identification stopped (Ctrl-C, or SIGTERM through the CLI): ``result`` is the partial
    :class:`Identification` of the scenes done (``partial`` True), or None when no scene had finished.
    Every scene scored before the stop is in the journal, if one was given: a rerun resumes there."""

    def __init__(self, result):
        super().__init__("identification interrupted")
        self.result = result


def _declared(case) -> dict:
    defects = case.data.get("defect", [])
    if len(defects) != 1:
        raise ValidationCaseError(f"validation case {case.name!r}: identification needs exactly one [[defect]] "
                                  f"(its race and shape, and a first guess of its size); the case has {len(defects)}")
    d = defects[0]
    missing = [k for k in ("length_mm", "width_mm") if k not in d]
    if missing:
        raise ValidationCaseError(f"validation case {case.name!r}: [[defect]] needs {', '.join(missing)} "
                                  "(the first guess the search is centred on)")
    return {"defect.length_mm": float(d["length_mm"]), "defect.width_mm": float(d["width_mm"]),
            "defect.offset_mm": float(d.get("offset_mm", 0.0)), "defect.skew_deg": float(d.get("skew_deg", 0.0)),
            "defect.depth_mm": float(d["depth_mm"]) if "depth_mm" in d else None}


def default_grid(case) -> dict:
    """Lengths 0.5, 1 and 2 × the declared one, H = 0, B/4, B/2, θ = -60 ... 60° by 30° (45 scenes)."""
    d = _declared(case)
    b = d["defect.width_mm"]
    return {"defect.length_mm": [round(d["defect.length_mm"] * 2.0 ** k, 4) for k in range(-1, 2)],
            "defect.offset_mm": [round(b * k / 4, 4) for k in range(3)],
            "defect.skew_deg": [-60.0, -30.0, 0.0, 30.0, 60.0]}


def _run_grid(setting, base, grid, *, scheduler, cache_dir, bar, out, keep, journal=None):
    """Simulate ``grid`` (chunked by its first key) and append scored points to ``out`` in the grid's order;
    ``keep`` holds the best simulated scene's signature; ``bar``: a :class:`.identify_run.Progress` (or
    None), moved by each scene as it finishes.  A scene in ``journal`` is read back, one simulated is added
    to it; when the run is stopped the scenes scored so far are still appended."""
    keys = list(grid)
    first, rest = keys[0], keys[1:]
    done = {tuple(p[k] for k in keys) for p in out}
    mirror = mirrors(base, keys, list(itertools.product(*grid.values())), done)
    try:
        for v in grid[first]:
            chunk = [(v, *c) for c in itertools.product(*(grid[k] for k in rest))]
            _run_chunk(setting, base, grid, v, chunk, [c for c in chunk if c not in done and c not in mirror],
                       scheduler=scheduler, cache_dir=cache_dir, bar=bar, out=out, keep=keep, journal=journal)
    finally:
        scored = {tuple(p[k] for k in keys): p for p in out}
        for c, m in mirror.items():
            if m in scored:
                out.append({**{k: scored[m][k] for k in scored[m] if k not in keys}, **dict(zip(keys, c))})
                if bar is not None:
                    bar.scene()


def _run_chunk(setting, base, grid, v, chunk, todo, *, scheduler, cache_dir, bar, out, keep, journal):
    """The scenes ``todo`` of one chunk (the scenes ``chunk`` of the first key's value ``v``): read back from
    the journal or simulated (one sweep over the chunk if none is, else one per scene), appended to ``out``."""
    keys = list(grid)
    first, rest = keys[0], keys[1:]
    if not todo:
        return
    scored = {}
    digests = {c: _digest(base, dict(zip(keys, c))) for c in todo} if journal is not None else {}
    for c in todo:
        hit = journal.get(digests[c]) if journal is not None else None
        if hit is not None:
            scored[c] = hit
            if bar is not None:
                bar.scene()
    try:
        missing = [c for c in todo if c not in scored]
        if len(missing) == len(chunk):
            _sweep_scored(setting, base, {first: [v], **{k: grid[k] for k in rest}}, chunk, scored, digests,
                          scheduler=scheduler, cache_dir=cache_dir, bar=bar, keep=keep, journal=journal)
        else:
            for c in missing:
                _sweep_scored(setting, base, {k: [x] for k, x in zip(keys, c)}, [c], scored, digests,
                              scheduler=scheduler, cache_dir=cache_dir, bar=bar, keep=keep, journal=journal)
    finally:
        out.extend({**dict(zip(keys, c)), **scored[c]} for c in todo if c in scored)


def _digest(base, point) -> str:
    """The sweep's cache key of the scene ``point`` over ``base`` (what the journal is keyed on)."""
    return scene_hash(base.replace(**point).to_toml(), {})


def _sweep_scored(setting, base, params, combos, scored, digests, *, scheduler, cache_dir, bar, keep, journal):
    """One sweep over ``params`` (whose C-order scenes are ``combos``); each scene is scored into ``scored``
    (and the journal) as it finishes."""
    keys = list(params)

    def on_scene(i, ds, cached):
        c = combos[i]
        sig = candidate_signature(setting, np.asarray(ds[ds.attrs["default_channel"]].values, float))
        m = setting.score(sig)
        scored[c] = m
        if journal is not None:
            journal.add(digests.get(c) or _digest(base, dict(zip(keys, c))), dict(zip(keys, c)), m)
        if m["score_db"] < keep.get("score_db", np.inf):
            keep.update(score_db=m["score_db"], signature=sig)
        if bar is not None:
            bar.scene(built_table=c in bar.builds)
    run_sweep(base, params, scheduler=scheduler, cache_dir=cache_dir, progress=False, metrics=False, on_scene=on_scene)


def ds_dim(key):
    return dim_name(key)


def _profile(points, key, threshold, walked=None, span=None):
    """A parameter's profile, interval and statement.

    Without ``walked``: the profile is the best score among ``points`` at each searched value (the coarse
    grid's). With ``walked`` ({value: score minimised over the other parameters},
    :func:`.identify_search.walk_profiles`): only those values can be *excluded* (more than ``threshold``
    above the best); any simulated scene within the threshold *accepts* its value (a geometry that
    explains the recording that well is an answer, whatever the others score).  The interval runs from
    the nearest excluded value below the accepted ones to the nearest above (the profile is known at
    those values only), or to the end of ``span``.
    """
    best = min(points, key=lambda p: p["score_db"])
    top = best["score_db"] + threshold
    if walked:
        known = dict(walked)
        for p in points:
            if p["score_db"] <= top:
                known[p[key]] = min(known.get(p[key], np.inf), p["score_db"])
        decisive = set(walked)
    else:
        known = {}
        for p in points:
            known[p[key]] = min(known.get(p[key], np.inf), p["score_db"])
        decisive = set(known)
    vals = sorted(known)
    span = span or (vals[0], vals[-1])
    ok = [v for v in vals if known[v] <= top]
    out = sorted(v for v in decisive if known[v] > top)
    below, above = [v for v in out if v < min(ok)], [v for v in out if v > max(ok)]
    lo, hi = (below[-1] if below else span[0]), (above[0] if above else span[1])
    flat = not out
    name, unit = PARAMS[key]
    change = max(known[v] for v in decisive) - best["score_db"]
    if len(vals) == 1:
        text = f"{name}: held at {vals[0]:g} {unit} (one value searched)"
    elif flat:
        text = (f"{name}: not identifiable from this recording (the misfit changes by at most "
                f"{change:.2f} dB over {span[0]:g}-{span[1]:g} {unit}, within the {threshold:.2f} dB threshold)")
    else:
        edge = [s for s, hit in (("lower", not below), ("upper", not above)) if hit]
        text = (f"{name}: {best[key]:g} {unit}, interval {lo:g}-{hi:g} {unit}"
                + (f" (reaches the {' and '.join(edge)} end of the searched range: the interval may extend beyond it)"
                   if edge else ""))
    return {"best": best[key], "interval": [lo, hi], "identifiable": not flat, "searched": len(vals) > 1,
            "statement": text, "unit": unit, "profile": [[v, known[v]] for v in vals],
            "optimised": sorted(walked) if walked else []}


def identify(case, *, grid=None, refine=True, scheduler="serial", n_workers=None, cache_dir=False,
             progress=True, level_weight=None, mirror=None, threshold_db=None, journal=None,
             notify=None) -> Identification:
    """Identify the case's defect geometry from its recording (see the module docstring).

    Parameters
    ----------
    case : ValidationCase, shipped name or case TOML path (one ``[[defect]]``: race, shape and a first
        guess of its size; the search is centred on it).
    grid : {scene key: [values]}, optional
        Coarse grid (default :func:`default_grid`); keys among ``defect.length_mm``, ``defect.offset_mm``,
        ``defect.skew_deg``, ``defect.depth_mm``.
    refine : bool
        After the coarse grid: a simplex search from its best scene, the roughness probe there (each
        parameter moved one way by 0.3 % of its grid step; the threshold is at least twice the score change),
        profiles walked by minimisation, and the polish.  False: the grid's scores (profiles are upper bounds).
    scheduler, n_workers, cache_dir : as :func:`bearing_lab.sweep.run_sweep` (default serial, in process, no
        sweep cache: 3.6 MB per scene of 1 s at 20 kHz; contact tables are cached regardless).
    level_weight : float, optional
        Weight of the amplitude in the score (default: 1 when the structural path is independent of this
        recording, else 0; see :func:`bearing_lab.validation.candidates.setting_for`).
    threshold_db : float, optional
        Interval threshold (default: max(3 × the recording's split-half misfit, 0.3 dB, twice the
        score's roughness at the best scene)).
    progress : bool or callable
        True: a progress bar over the scenes; a callable: called after every scene with
        ``{"scenes", "total", "tables_left"}`` (it may stop the run by raising KeyboardInterrupt).
    journal : path, optional
        JSON-lines file of the scored scenes (:class:`.identify_run.Journal`), read back instead of
        simulated and added to as each scene finishes, so a stopped run resumes.
    notify : callable, optional
        ``notify(text)`` receives the cost estimate and the resume count before the scenes run.

    Raises
    ------
    IdentificationInterrupted (a KeyboardInterrupt) when stopped: its ``result`` is the partial
    identification of the scenes done (``partial`` True), or None if none had finished.

    See Also
    --------
    bearing_lab.validation.load_case, bearing_lab.validation.make_standin_recording
    """
    t_cpu, t_wall = time.process_time(), time.perf_counter()
    case = case if hasattr(case, "section") else load_case(case)
    declared = _declared(case)
    grid = {k: [float(x) for x in v] for k, v in (grid or default_grid(case)).items()}
    st, base, setup_cpu, thr, jr, old, est = _prepare(case, grid, refine, mirror, level_weight, threshold_db,
                                                      journal, notify, t_cpu)
    bar = Progress(f"identify {case.name}", int(np.prod([len(v) for v in grid.values()])) + est["refine_likely"],
                   bar=progress is True, callback=progress if callable(progress) else None)
    bar.tables(est["tables_new"]["aligned"] + est["tables_new"]["skewed"], est["builds"])
    client, close = _client(scheduler, n_workers)
    points: list = []
    keep: dict = {}
    walked = roughness = None
    cleared: dict = {}
    try:
        _run_grid(st, base, grid, scheduler=client, cache_dir=cache_dir, bar=bar, out=points, keep=keep, journal=jr)
        bar.tables(0, ())
        if refine:
            run = dict(scheduler="serial", cache_dir=cache_dir, bar=bar, out=points, keep=keep, journal=jr)
            roughness, thr, walked, cleared = _refinement(st, base, grid, points, run, thr, threshold_db is None)
        best = min(points, key=lambda p: p["score_db"])
        if keep.get("score_db") != best["score_db"]:     # the best scene was read back: its signature again
            keep = {}
            _run_grid(st, base, {k: [best[k]] for k in grid}, scheduler="serial", cache_dir=cache_dir, bar=None,
                      out=[], keep=keep)
    except KeyboardInterrupt:
        res = None
        if points:
            res = _stamped(_result(case, st, points, grid, thr, declared, t_cpu, t_wall, keep.get("signature"),
                                   None, None, partial=True), len(jr.entries) if jr else 0, est, setup_cpu)
        raise IdentificationInterrupted(res) from None
    finally:
        bar.close()
        if close:
            client.close()
    res = _stamped(_result(case, st, points, grid, thr, declared, t_cpu, t_wall, keep["signature"], roughness,
                           walked), len(old), est, setup_cpu)
    res.notes += _method_notes(st, base, grid, res, est, refine, cleared)
    return res


def _method_notes(st, base, grid, res, est, refine, cleared=None) -> list:
    """What the search's economies mean for this result: the candidates' length, the mirrored scenes, the
    refinement's lattice (the resolution of the best values) and the profile values excluded by a margin
    after their first scenes (weaker evidence than a whole minimisation)."""
    rec = st.prep.n / st.prep.fs
    out = []
    if base.duration < rec - 1e-9:
        out.append(f"each candidate scene records {base.duration:g} s ({base.duration / st.period_s:.0f} impact "
                   f"periods) of the recording's {rec:g} s: its mean impact envelope settles within that")
    if est.get("mirrored"):
        out.append(f"{est['mirrored']} coarse scenes at H = 0 and θ < 0 were not simulated: they are scored as their "
                   "mirror images (H = 0, -θ), which give the same signal")
    if refine:
        steps = {k: v * REFINE_XTOL for k, v in coarse_steps(grid, res.best).items()}
        out.append(f"refinement scenes lie on a lattice of 1/{round(1 / REFINE_XTOL)} of the coarse grid's steps "
                   "(near the best: "
                   + ", ".join(f"{PARAMS[k][0]} {v:.3g} {PARAMS[k][1]}" for k, v in steps.items())
                   + "): the best values are resolved to it")
    vals = {}
    for k, x in sorted(cleared or ()):      # the interval ends so excluded (a later scene may accept a value)
        p = res.parameters[k]
        if x in p["interval"] and dict(p["profile"]).get(x, -np.inf) > res.best["score_db"] + res.threshold_db:
            vals.setdefault(k, []).append(f"{x:g}")
    if vals:
        out.append(f"interval ends excluded after their first {PROFILE_CLEAR_SCENES} scenes, all more than "
                   f"{PROFILE_CLEAR:g} times the threshold above the best, without the rest of their minimisation: "
                   + "; ".join(f"{PARAMS[k][0]} {', '.join(v)} {PARAMS[k][1]}" for k, v in vals.items())
                   + " (a basin narrower than those scenes' steps could still lie there)")
    return out


def _stamped(res, resumed, est, setup_cpu):
    """``res`` with the scenes read back, the estimate made before the run and the setup's CPU time."""
    res.resumed = resumed
    res.estimate, res.setup_cpu_s = {k: v for k, v in est.items() if k != "builds"}, setup_cpu
    return res


def _prepare(case, grid, refine, mirror, level_weight, threshold_db, journal, notify, t_cpu):
    """Before any scene: the grid checked, the comparison setting and base scene, the threshold from the
    recording's noise, the journal of an earlier run and the cost estimate (said through ``notify``)."""
    bad = [k for k in grid if k not in PARAMS]
    if bad or not grid or any(not v for v in grid.values()):
        raise ValidationCaseError(f"identify: grid keys must be among {', '.join(PARAMS)} with at least one value "
                                  f"each; got {', '.join(bad) or 'an empty grid'}")
    if notify is not None:
        notify("preparing the comparison (the recording, the structural path, the background)")
    st, base = _setting(case, mirror, level_weight)
    setup_cpu = time.process_time() - t_cpu
    thr = float(threshold_db) if threshold_db is not None else max(3 * st.noise_db, MIN_THRESHOLD_DB)
    jr = Journal(journal, comparison_fingerprint(st, base)) if journal else None
    old = [e["point"] for e in (jr.entries.values() if jr else []) if set(e["point"]) == set(grid)]
    est = estimate(base, grid, refine=refine, done=old)
    if notify is not None:
        if jr is not None and jr.set_aside is not None:
            notify(f"the journal {jr.path} was of another comparison: set aside as {jr.set_aside.name}")
        if jr is not None and jr.entries:
            notify(f"resuming: {len(jr.entries)} scored scenes in {jr.path} are read back, not simulated")
        notify(estimate_text(est))
    return st, base, setup_cpu, thr, jr, old, est


def _setting(case, mirror, level_weight):
    """The comparison setting (recording's signature, fixed path, background, score) and the base scene
    of a loaded case."""
    prep = prepare(case, mirror=mirror)
    m = prep.measured["record"]
    path = path_for(case, prep, mirror=mirror)
    reference = open_spec(case.reference, case.name, mirror) if case.reference is not None else None
    bg = background_for(case, prep.recording, m, reference, band=comparison_band(prep.fs))
    st = setting_for(prep, path, bg, level_weight=level_weight)
    return st, base_scene(case, prep, st.period_s)


#: defect passages (impact periods) a candidate scene records, after the scene's own settling
#: (``output.settle_s``); a recording shorter than that is simulated whole.  The score compares *mean*
#: impact envelopes, so the candidate needs enough passages for its mean to settle, not the recording's
#: length: on the README walkthrough's stand-in (183 passages in 2 s) 55 passages moved the scores of
#: 12 geometries by at most 0.03 dB against the full length, 37 by 0.07 dB (docs/identification.md)
SCENE_PASSAGES = 60


def base_scene(case, prep, period_s=None):
    """The scene every candidate is a change of: the case's, at the recording's measured speed and sampling
    rate, with the comparison's solver settings (``prep``: the prepared recording), as long as the
    recording or, given the impact period ``period_s``, :data:`SCENE_PASSAGES` periods if that is shorter."""
    duration = prep.n / prep.fs
    if period_s is not None and period_s > 0:
        duration = min(duration, round(SCENE_PASSAGES * period_s, 4))
    return simulation.build_scene(case, rpm=prep.speed.rpm, fs=prep.fs, duration=duration,
                                  overrides=comparison_overrides(case))


def _scorer(st, base, grid, points, run):
    """``score(point) -> dB``: simulates the scene ``point`` ({key: value} over ``grid``'s keys) and
    appends it to ``points``, or reads back a scene already there."""
    def score(point):
        key = tuple(point[k] for k in grid)
        found = [p for p in points if tuple(p[k] for k in grid) == key]
        if not found:
            _run_grid(st, base, {k: [point[k]] for k in grid}, **run)
            found = points[-1:]
        return found[0]["score_db"]
    return score


def _refinement(st, base, grid, points, run, thr, widen):
    """The steps after the coarse grid (see the module docstring); returns (roughness, threshold, walked
    profiles).  ``run``: keywords of :func:`_run_grid`; ``widen``: raise the threshold to twice the roughness."""
    score = _scorer(st, base, grid, points, run)
    best = min(points, key=lambda p: p["score_db"])
    minimise(grid, {k: best[k] for k in grid}, score, list(grid), REFINE_MAX_SCENES,
             first_step=REFINE_FIRST_STEP)
    best = min(points, key=lambda p: p["score_db"])
    n_before = len(points)
    for probe in probes(grid, best):
        _run_grid(st, base, probe, **run)
    roughness = None
    if len(points) > n_before:
        roughness = max(abs(p["score_db"] - best["score_db"]) for p in points[n_before:])
        if widen:                   # the best and any other scene each move by up to it
            thr = max(thr, 2 * roughness)
    early: dict = {}
    cleared: dict = {}
    walked = walk_profiles(grid, best, score, lambda: min(p["score_db"] for p in points), thr, points,
                           early=early, cleared=cleared)
    polish(grid, walked, points, score, thr)
    recheck(grid, walked, early, score, points, thr)
    return roughness, thr, walked, cleared


def _client(scheduler, n_workers):
    if scheduler in (None, "local"):
        # dask loads when a cluster starts; not a lazy.load stand-in: that would sit in sys.modules as
        # "dask.distributed" without being the package's attribute, so a later `import dask.distributed`
        # in the same process would find no dask.distributed
        from dask.distributed import Client, LocalCluster
        cluster = LocalCluster(n_workers=n_workers or 2, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        return Client(cluster), True
    return scheduler, False


def _result(case, st, points, grid, thr, declared, t_cpu, t_wall, best_signature, roughness=None, walked=None,
            partial=False):
    best = min(points, key=lambda p: p["score_db"])
    walked = walked or {}
    params = {k: _profile(points, k, thr, walked.get(k), (min(grid[k]), max(grid[k]))) for k in grid}
    notes = list(st.notes) + [f"amplitude weight {st.level_weight:g}: {st.level_reason}"]
    if partial:
        n_coarse = int(np.prod([len(v) for v in grid.values()]))
        on_grid = sum(all(p[k] in grid[k] for k in grid) for p in points)
        notes.insert(0, f"PARTIAL: stopped after {len(points)} scenes ({on_grid} of the coarse grid's {n_coarse}"
                        + (", the refinement not finished" if on_grid >= n_coarse else "") + "); the best scene is the "
                        "best so far and each profile is the best scene simulated at each value (an upper bound): "
                        "more scenes can lower any of them, so an interval can widen or move and none is final; "
                        "rerun the same command to resume")
        for k, p in params.items():
            name, unit = PARAMS[k]
            if len(grid[k]) > 1 and len(p["profile"]) < 2:
                p["statement"] = (f"{name}: only {p['best']:g} {unit} simulated so far (of {len(grid[k])} grid "
                                  "values): nothing to conclude yet")
                p["identifiable"] = False
            p["statement"] = "partial, " + p["statement"].replace("from this recording", "from the scenes done so far")
    if roughness is not None:
        notes.append(f"score roughness {roughness:.2f} dB: moving one parameter of the best scene by "
                     f"{100 * ROUGHNESS_STEP:g} % of its grid step changes the score by up to this much"
                     + ("; the interval threshold is raised to twice it (the best scene and any other each move "
                        "by up to it)" if 2 * roughness >= thr - 1e-12 and roughness > 0 else ""))
    explains = _explains(best["score_db"], thr, st.noise_db, partial)
    if not explains[0]:
        notes.insert(1 if partial else 0, explains[1])
    elif not partial and not any(p["identifiable"] for p in params.values()):
        notes.append("no parameter is identifiable: the recording's impact signature does not change with the "
                     "searched geometry more than with its own noise")
    res = Identification(case.name, points, best, params, thr, st.noise_db, st.level_weight, st.level_reason,
                         grid, len(points), time.process_time() - t_cpu, time.perf_counter() - t_wall, notes,
                         {"recording": st.measured, "best": best_signature}, declared, roughness, partial)
    res.explains_recording = explains[0]
    return res


def _explains(best_db, thr, noise_db, partial) -> tuple:
    """(explains, statement): does the best scene explain the recording?  It does when its score lies within
    the threshold (the recording's own noise, its roughness): no geometry can then be told from the truth.
    Above it, the model does not explain the recording, and the intervals describe the nearest geometry of
    a model that misfits, not the defect."""
    if best_db <= thr:
        return True, ""
    ratio = (f", {best_db / noise_db:.1f} times the recording's split-half misfit ({noise_db:.2f} dB)"
             if noise_db > 0 else "")
    return False, ((("so far, " if partial else "") + "the model does not explain this recording: the best scene "
                    f"misfits it by {best_db:.2f} dB, above the threshold of {thr:.2f} dB{ratio}; the intervals "
                    "are those of the nearest geometry of a model that misfits, not the defect's, and a parameter "
                    "called not identifiable may be hidden by the misfit (see the signature figure: the best "
                    "scene's mean impact against the recording's)"))
