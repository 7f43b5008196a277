"""What keeps an identification usable while it runs: its cost estimate, its progress and its scene journal.

- :func:`estimate`: the CPU time of the scenes still to simulate, from the contact tables they need (counted
  without building any, cached or not: :func:`bearing_lab.sim.assembly.table_requests`) times a measured
  per-table cost, plus the scenes times a measured per-scene cost (``benchmarks/identify_cost.py``);
- :class:`Progress`: a bar that moves with every scene (from the first), with the count of contact tables
  still to build;
- :class:`Journal`: every scored scene appended to a small JSON-lines file as it finishes, so a run that is
  stopped (Ctrl-C, a kill) resumes where it stopped: a scene found there is read back, not simulated again.
  Each entry holds the sweep's scene hash (:func:`bearing_lab.sweep.scene_hash`: the resolved scene, the
  simulator's version and source) and the file starts with a fingerprint of the comparison (the recording's
  signature, the path, background, amplitude weight and the scoring code); a journal of another comparison
  is set aside, never mixed in.
"""
from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from ..sim.assembly import scene_statics, table_requests
from ..sim.defects.contact import table_is_cached
from ..utils._json import clean

#: CPU s of one contact table built cold, as the simulation builds it (half-space; 6308 stand-in rig):
#: an outline with sides along and across the track, and a skewed one (rotated cells).  Measured with
#: benchmarks/defect_tables.py on the shared 2-core machine: 0.07-0.10 s aligned (the slot 0.28 s),
#: 0.30-0.53 s skewed; bracketed with a wide margin for slower machines
TABLE_CPU_S = {"aligned": (0.05, 1.0), "skewed": (0.2, 3.0)}
#: CPU s per second of record of one scene with its table cached, its signature and score included
#: (0.08-0.10 s for the time loop at rtol 1e-6, 20 kHz; the sweep, the Dataset and the scoring add to it)
SCENE_CPU_S_PER_S = (0.08, 0.8)
#: fewer scenes than the refinement added in any run measured (53-57 on the stand-ins, docs/identification.md);
#: its most is its budget
REFINE_FEWEST = 30
#: the likely figures inside those brackets: the middle of the measured tables (0.07-0.10 s aligned,
#: 0.30-0.53 s skewed), a scene with its scoring (0.065 s for the README walkthrough's 0.65 s scenes), and the
#: refinement's scenes in the runs measured
TABLE_CPU_LIKELY_S = {"aligned": 0.09, "skewed": 0.45}
SCENE_CPU_LIKELY_S_PER_S = 0.12
REFINE_LIKELY = 55
#: the search's budgets (identify.py runs the search; the estimate bounds it from these):
#: the refinement's simplex stops at REFINE_MAX_SCENES scenes; a profile value is the best score over
#: the other parameters found in at most PROFILE_MAX_SCENES scenes; the polish makes at most
#: POLISH_STARTS starts, each a simplex search of at most POLISH_MAX_SCENES scenes
REFINE_MAX_SCENES = 30
PROFILE_MAX_SCENES = 10
#: a profile value whose first PROFILE_CLEAR_SCENES scenes (its start and the first simplex around it) all
#: score more than PROFILE_CLEAR thresholds above the best is excluded there, without the rest of its budget
PROFILE_CLEAR_SCENES = 3
PROFILE_CLEAR = 2.0
POLISH_STARTS = 2
POLISH_MAX_SCENES = 15


def refine_budget(grid) -> int:
    """The most scenes the refinement can add (simplex, probes, walked profiles, polish): a bound, not a guess.
    Nelder-Mead may pass its budget by one shrink step (one scene per parameter) per search."""
    searched = [v for v in grid.values() if len(v) > 1]
    n = len(searched)
    walked = sum(2 * len(v) - 2 for v in searched)          # coarse values and half steps, the best apart
    return (REFINE_MAX_SCENES + n + n + walked * (PROFILE_MAX_SCENES + n)
            + POLISH_STARTS * (POLISH_MAX_SCENES + n))


def _table_cached(defect, bearing, kw) -> bool:
    """Whether the table :func:`contact_table` would return for (defect, kw) is in memory or on disk."""
    return table_is_cached(defect, bearing, **kw)


def table_plan(base, points) -> dict:
    """Contact tables the scenes ``points`` ([{key: value}] over ``base``) need: distinct ones, split into
    cached / to build (aligned or skewed outline), and ``builds``: the indices of the points that build one
    (the first to need each table not cached)."""
    statics = scene_statics(base)
    seen, new, of_point = {}, {"aligned": 0, "skewed": 0}, []
    cached = 0
    for p in points:
        reqs = table_requests(base.replace(**p), statics=statics)
        ids = []
        for d, kw in reqs:
            ident = repr((dataclasses.astuple(dataclasses.replace(d, angle=0.0)), sorted(kw.items())))
            if ident not in seen:
                is_cached = _table_cached(d, base.bearing, kw)
                seen[ident] = is_cached
                if is_cached:
                    cached += 1
                else:
                    new["skewed" if d.skew != 0.0 else "aligned"] += 1
            ids.append(ident)
        of_point.append(tuple(ids))
    first_use = {}
    for k, ids in enumerate(of_point):
        for ident in ids:
            first_use.setdefault(ident, k)
    builds = sorted({k for ident, k in first_use.items() if not seen[ident]})
    return {"tables": len(seen), "cached": cached, "new": new, "builds": builds}


def mirrors(base, keys, combos, done) -> dict:
    """{combo: its mirror image} of the scenes ``combos`` (tuples over ``keys``) not in ``done`` at H = 0 and
    θ < 0 whose mirror (H = 0, -θ) is among ``combos`` or done and gives the same signal: a rectangle or
    ellipse centred on the track whose contact table request is the mirror's with the skew negated (a
    3-D bearing under axial load moves the track off H = 0, and then nothing is mirrored)."""
    if "defect.offset_mm" not in keys or "defect.skew_deg" not in keys:
        return {}
    io, isk = keys.index("defect.offset_mm"), keys.index("defect.skew_deg")
    known = set(combos) | set(done)
    out, statics = {}, None
    for c in combos:
        m = tuple(-x if j == isk else x for j, x in enumerate(c))
        if c in done or c[io] != 0.0 or c[isk] >= 0.0 or m not in known:
            continue
        statics = statics or scene_statics(base)
        a = table_requests(base.replace(**dict(zip(keys, c))), statics=statics)
        b = table_requests(base.replace(**dict(zip(keys, m))), statics=statics)
        if len(a) == len(b) == 1 and a[0][1] == b[0][1] and a[0][0].shape in ("rectangle", "ellipse") \
                and a[0][0].race != "ball" and abs(a[0][0].offset) < 1e-12 \
                and dataclasses.replace(a[0][0], skew=-a[0][0].skew) == b[0][0]:
            out[c] = m
    return out


def estimate(base, grid, *, refine: bool, done=()) -> dict:
    """CPU seconds (low, high) of the scenes of an identification still to run, and the counts they rest on.

    The coarse grid's scenes not in ``done`` (points already scored) are planned exactly (their tables,
    cached or not); the refinement's scenes are counted from :data:`REFINE_FEWEST` to :func:`refine_budget`,
    each with a table of its own to build (skewed unless every searched skew is 0; at the low end only in
    the share of the coarse grid's tables that were not cached)."""
    keys = list(grid)
    done = {tuple(p[k] for k in keys) for p in done}
    coarse = set(itertools.product(*(grid[k] for k in keys)))
    combos = list(itertools.product(*(grid[k] for k in keys)))
    mirrored = mirrors(base, keys, combos, done)         # scored as their mirror images, not simulated
    todo = [dict(zip(keys, c)) for c in combos if c not in done and c not in mirrored]
    plan = table_plan(base, todo)
    sec = float(base.duration)
    skews = grid.get("defect.skew_deg") or [d.skew for d in base.defects]
    kind = "skewed" if any(s != 0.0 for s in skews) else "aligned"
    r_lo, r_hi = (min(REFINE_FEWEST, refine_budget(grid)), refine_budget(grid)) if refine else (0, 0)
    r_lo = max(0, r_lo - len(done - coarse))    # a resumed refinement may find its scenes read back
    lo = hi = 0.0
    for j, (tl, th) in enumerate((TABLE_CPU_S["aligned"], TABLE_CPU_S["skewed"])):
        n = plan["new"]["aligned" if j == 0 else "skewed"]
        lo, hi = lo + n * tl, hi + n * th
    # the refinement's scenes lie off the grid, each with a table of its own: new, unless this grid's tables
    # were cached too (a rerun), which the low end allows for in the same share
    n_new = plan["new"]["aligned"] + plan["new"]["skewed"]
    share = n_new / plan["tables"] if plan["tables"] else 1.0
    lo += len(todo) * SCENE_CPU_S_PER_S[0] * sec + r_lo * (share * TABLE_CPU_S[kind][0] + SCENE_CPU_S_PER_S[0] * sec)
    hi += len(todo) * SCENE_CPU_S_PER_S[1] * sec + r_hi * (TABLE_CPU_S[kind][1] + SCENE_CPU_S_PER_S[1] * sec)
    r_mid = min(REFINE_LIKELY, r_hi) if refine else 0
    likely = (sum(plan["new"][k] * TABLE_CPU_LIKELY_S[k] for k in plan["new"])
              + (len(todo) + r_mid) * SCENE_CPU_LIKELY_S_PER_S * sec + r_mid * share * TABLE_CPU_LIKELY_S[kind])
    return {"cpu_s": (lo, hi), "likely_cpu_s": likely, "refine_likely": r_mid,
            "builds": [tuple(todo[k][q] for q in keys) for k in plan["builds"]], "coarse_scenes": len(todo),
            "mirrored": len(mirrored),
            "coarse_done": len(done & coarse), "refine_scenes": (r_lo, r_hi),
            "tables": plan["tables"], "tables_cached": plan["cached"], "tables_new": plan["new"],
            "record_s": sec}


def estimate_text(est) -> str:
    n_new = est["tables_new"]["aligned"] + est["tables_new"]["skewed"]
    r_lo, r_hi = est["refine_scenes"]
    lo, hi = est["cpu_s"]
    return (f"{est['coarse_scenes']} coarse scenes to simulate"
            + (f" ({est['coarse_done']} of the grid read back from the journal)" if est["coarse_done"] else "")
            + (f" ({est['mirrored']} at H = 0, θ < 0 scored as their mirror images)" if est.get("mirrored") else "")
            + (f" + {r_lo}-{r_hi} in the refinement" if r_hi else "")
            + f", {est['record_s']:g} s each; contact tables of the coarse grid: {n_new} to build "
              f"({est['tables_new']['skewed']} skewed), {est['tables_cached']} cached: about "
              f"{_duration(lo)}-{_duration(hi)} of CPU, likely about {_duration(est['likely_cpu_s'])}"
            + (f" (with the refinement's usual {est['refine_likely']} scenes)" if r_hi else ""))


def _duration(s) -> str:
    s = float(s)
    if s < 90:
        return f"{s:.0f} s"
    if s < 5400:
        return f"{s / 60:.0f} min"
    return f"{s / 3600:.1f} h"


class Progress:
    """A bar over the scenes (its total grows if the refinement passes the estimate), moved by every scene
    as it finishes, with the contact tables still to build; ``callback(event)`` sees the same events
    (a dict: ``scenes``, ``total``, ``tables_left``) and may stop the run by raising."""

    def __init__(self, desc, total, *, bar=True, callback=None):
        self.done, self.total, self.tables_left, self.callback = 0, int(total), 0, callback
        self.builds = set()
        self.bar = None
        if bar:
            # smoothing 0: the mean rate over the run (the first scenes build tables and are slower)
            self.bar = tqdm(total=self.total, unit="scene", desc=desc, leave=False, smoothing=0.0)

    def tables(self, n_new, builds):
        """``n_new`` tables to build, by the scenes ``builds`` (tuples of their grid values)."""
        self.tables_left, self.builds = int(n_new), set(builds)
        self._show()

    def scene(self, built_table=False):
        self.done += 1
        if built_table and self.tables_left:
            self.tables_left -= 1
        if self.done > self.total:
            self.total = self.done
            if self.bar is not None:
                self.bar.total = self.total
        self._show()
        if self.bar is not None:
            self.bar.update(1)
        if self.callback is not None:
            self.callback({"scenes": self.done, "total": self.total, "tables_left": self.tables_left})

    def _show(self):
        if self.bar is not None:
            self.bar.set_postfix_str(f"building contact tables: {self.tables_left} to go" if self.tables_left
                                     else "", refresh=False)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _digest(h, obj, depth=0):
    """Feed ``obj`` (numbers, strings, arrays, dicts, lists, dataclasses, plain objects) into ``h``."""
    if depth > 8:
        return
    if isinstance(obj, np.ndarray):
        h.update(repr((obj.dtype.str, obj.shape)).encode() + np.ascontiguousarray(obj).tobytes())
    elif isinstance(obj, dict):
        for k in sorted(obj, key=str):
            h.update(str(k).encode())
            _digest(h, obj[k], depth + 1)
    elif isinstance(obj, (list, tuple)):
        for v in obj:
            _digest(h, v, depth + 1)
    elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        _digest(h, {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}, depth + 1)
    elif obj is None or isinstance(obj, (bool, int, float, str, np.generic)):
        h.update(repr(obj).encode())
    elif hasattr(obj, "__dict__"):
        _digest(h, {k: v for k, v in vars(obj).items() if not k.startswith("_")}, depth + 1)
    else:
        h.update(repr(obj).encode())


_SOURCE: list = []


def _source_fingerprint() -> str:
    """sha256 of the scoring code's source (validation and analysis), read once per process: the code this
    process runs, even if the files change while it runs."""
    if not _SOURCE:
        root = Path(__file__).resolve().parents[1]
        h = hashlib.sha256()
        for f in sorted([*(root / "validation").glob("*.py"), *(root / "analysis").rglob("*.py")]):
            h.update(f.name.encode() + b"\0" + f.read_bytes())
        _SOURCE.append(h.hexdigest())
    return _SOURCE[0]


def comparison_fingerprint(setting, base) -> str:
    """sha256 of what a scene's score depends on besides the scene: the recording's signature, the
    structural path, the background, the band, period, amplitude weight and tolerance, the path's shape
    residual, the background seed, the scoring code, and the base scene (an amplitude weight given
    explicitly and the same weight by default give the same fingerprint)."""
    h = hashlib.sha256()
    # the score's inputs only: not the notes, the amplitude weight's reason or the split-half misfit (the threshold's)
    fields = {f.name: getattr(setting, f.name) for f in dataclasses.fields(setting)
              if f.name not in ("prep", "notes", "level_reason", "noise_db")}
    _digest(h, fields)
    h.update(b"\0" + _source_fingerprint().encode() + b"\0" + base.to_toml().encode())
    return h.hexdigest()


class Journal:
    """Scored scenes of one comparison, one JSON line each (see the module docstring)."""

    def __init__(self, path, fingerprint):
        self.path, self.fingerprint = Path(path), fingerprint
        self.entries, self.set_aside = {}, None
        if self.path.is_file():
            self._read()
        if not self.path.is_file():
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with open(self.path, "w", encoding="utf-8") as fh:
                fh.write(json.dumps({"journal": "bearing_lab identification", "comparison": fingerprint}) + "\n")

    def _read(self):
        lines = self.path.read_text(encoding="utf-8", errors="replace").splitlines()
        try:
            head = json.loads(lines[0]) if lines else {}
        except json.JSONDecodeError:
            head = {}
        if head.get("comparison") != self.fingerprint:
            old = self.path.with_name(self.path.name + ".old")
            self.path.replace(old)
            self.set_aside = old
            return
        for line in lines[1:]:
            try:
                e = json.loads(line)
                self.entries[e["scene"]] = e
            except (json.JSONDecodeError, KeyError, TypeError):
                continue            # a line cut short by a kill: its scene is simulated again

    def get(self, digest):
        e = self.entries.get(digest)
        return None if e is None else {k: (math.nan if v is None else v) for k, v in e["score"].items()}

    def add(self, digest, point, score):
        e = {"scene": digest, "point": clean(point), "score": clean(score)}
        self.entries[digest] = e
        with open(self.path, "a", encoding="utf-8") as fh:
            fh.write(json.dumps(e, allow_nan=False) + "\n")
            fh.flush()
