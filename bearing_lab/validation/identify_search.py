"""The identification's search steps after the coarse grid (see :mod:`.identify` and docs/identification.md).

snap(grid, key, x)                     -- a value moved to the refinement's lattice (1 / 16 of a coarse step)
coarse_steps(grid, best)               -- the coarse grid's spacing next to a scene, per parameter
minimise(grid, start, score, keys, max_scenes, first_step)   -- bounded Nelder-Mead on the lattice
probes(grid, best)                     -- the roughness probe's scenes
walk_profiles(...), recheck(...)       -- profiles by minimisation over the other parameters
polish(grid, walked, points, score, thr)   -- searches again from profile points apart from the best
"""
from __future__ import annotations

import lazy_loader as lazy
import numpy as np

from .identify_run import (POLISH_MAX_SCENES, POLISH_STARTS, PROFILE_CLEAR, PROFILE_CLEAR_SCENES,
                           PROFILE_MAX_SCENES)

# the simplex (Nelder-Mead): loaded when a refinement runs
_optimize = lazy.load("scipy.optimize", suppress_warning=True)

__all__ = ["REFINE_XTOL", "REFINE_FIRST_STEP", "REFINE_FTOL_DB", "ROUGHNESS_STEP", "snap", "coarse_steps", "minimise",
           "probes", "profile_value", "walk_profiles", "recheck", "polish"]


#: the refinement stops at REFINE_MAX_SCENES (identify_run.py, with the other budgets), or when its simplex
#: is smaller than REFINE_XTOL of the coarse step in every parameter and its scores differ by less than
#: REFINE_FTOL_DB
REFINE_XTOL = 1.0 / 16.0
#: the refinement's simplex starts with steps of this fraction of the coarse step along each parameter
REFINE_FIRST_STEP = 0.125
REFINE_FTOL_DB = 0.01
#: a profile value's simplex starts with steps of this fraction of the coarse step along each other parameter
PROFILE_FIRST_STEP = 0.25


def snap(grid, key, x) -> float:
    """``x`` moved to the refinement's lattice of parameter ``key``: each gap between neighbouring coarse grid
    values cut into 1 / REFINE_XTOL equal parts (grid values and half steps are lattice points), inside the
    grid's range.  Refinement scenes lie on it, so a search that comes back to a geometry, or a later search
    that passes it, reads its score back instead of simulating it and building its contact table again."""
    v = sorted(grid[key])
    x = min(max(float(x), v[0]), v[-1])
    if len(v) < 2:
        return round(x, 4)
    j = min(int(np.searchsorted(v, x, side="right")) - 1, len(v) - 2)
    n = round(1.0 / REFINE_XTOL)
    i = round((x - v[j]) / (v[j + 1] - v[j]) * n)
    return round(v[j] + i * (v[j + 1] - v[j]) / n, 4)


def coarse_steps(grid, best) -> dict:
    """Per searched parameter: the coarse grid's spacing next to the scene ``best`` (the mean of the gaps
    to the grid values on either side of it)."""
    out = {}
    for k, vals in grid.items():
        v = sorted(vals)
        if len(v) < 2:
            continue
        i = int(np.argmin([abs(x - best[k]) for x in v]))
        gaps = [v[j + 1] - v[j] for j in (i - 1, i) if 0 <= j < len(v) - 1]
        out[k] = float(np.mean(gaps))
    return out


def minimise(grid, start, score, keys, max_scenes, first_step=0.5):
    """Nelder-Mead simplex search (Nelder & Mead, Computer Journal 7, 1965; scipy's bounded
    implementation) over the parameters ``keys`` from the scene ``start`` (the others held at its
    values), inside the coarse grid's range, in units of the coarse step.  A simplex stretches along
    a valley of the misfit that runs diagonally through the parameters (a longer defect further off
    the centre meets the ball over a similar chord), which a search along one parameter at a time
    cannot follow.  ``score(point) -> dB`` simulates one scene (or reads it back)."""
    steps = coarse_steps(grid, start)
    keys = [k for k in keys if k in steps]
    if not keys:
        return
    x0 = np.array([start[k] for k in keys], float)
    s = np.array([steps[k] for k in keys])
    lo = np.array([min(grid[k]) for k in keys])
    hi = np.array([max(grid[k]) for k in keys])
    simplex = [np.zeros(len(keys))]
    for i in range(len(keys)):      # first_step coarse steps along each parameter, into the searched range
        e = np.zeros(len(keys))
        e[i] = first_step if x0[i] + first_step * s[i] <= hi[i] else -first_step
        simplex.append(e)

    def f(z):
        x = x0 + z * s
        return score({**start, **{k: snap(grid, k, v) for k, v in zip(keys, x)}})
    _optimize.minimize(f, np.zeros(len(keys)), method="Nelder-Mead", bounds=list(zip((lo - x0) / s, (hi - x0) / s)),
             options={"initial_simplex": np.array(simplex), "xatol": REFINE_XTOL, "fatol": REFINE_FTOL_DB,
                      "maxfev": max_scenes})


class _Accepted(Exception):
    """A profile value's minimisation found a scene within the threshold: the value is accepted."""


class _Cleared(Exception):
    """A profile value's least score after its first PROFILE_CLEAR_SCENES scenes lies more than PROFILE_CLEAR
    thresholds above the best: the value is excluded without the rest of its budget."""


def profile_value(grid, k, x, best_point, score, points, budget, accept_at, clear_at=None):
    """The profile at ``k`` = ``x``: the least score over the other parameters, found by :func:`minimise`
    (PROFILE_FIRST_STEP of a coarse step first, from the better of the best scene's other values and the best scene
    already simulated at ``x``) in at most ``budget`` scenes; it stops as soon as a scene scores at most
    ``accept_at()`` (the value is then accepted: a lower minimum would not change that), or, given
    ``clear_at``, when its first PROFILE_CLEAR_SCENES scenes all score above ``clear_at()`` (the value is
    then excluded by a wide margin).  Returns (least score found, scenes used, how it stopped: "accepted",
    "cleared" or None)."""
    found = []

    def f(point):
        val = score(point)
        found.append(val)
        if val <= accept_at():
            raise _Accepted
        if clear_at is not None and len(found) == PROFILE_CLEAR_SCENES and min(found) > clear_at():
            raise _Cleared
        return val
    here = [p for p in points if abs(p[k] - x) <= 1e-12]
    start = {**{q: best_point[q] for q in grid}, k: x}
    try:
        if here and min(p["score_db"] for p in here) <= accept_at():
            return min(p["score_db"] for p in here), 0, "accepted"
        if here and min(p["score_db"] for p in here) < f(start):
            start = {q: min(here, key=lambda p: p["score_db"])[q] for q in grid}
        minimise(grid, start, f, [q for q in grid if q != k], budget - len(found), first_step=PROFILE_FIRST_STEP)
    except _Accepted:
        return min(found), len(found), "accepted"
    except _Cleared:
        return min(found), len(found), "cleared"
    return min(found), len(found), None


def walk_profiles(grid, best_point, score, best_score, thr, points, max_scenes=PROFILE_MAX_SCENES,
                   early=None, cleared=None) -> dict:
    """Profiles by optimisation: for each searched parameter, step from the best scene through its coarse
    grid values and the midpoints between them, each way; at each value minimise the score over the *other*
    parameters (:func:`profile_value`) and stop at the first value whose minimum lies more than ``thr``
    above the best (``best_score()``, which may fall while walking).  A value's minimisation stops at the
    first scene within ``thr`` of the best: that accepts it; and after its first PROFILE_CLEAR_SCENES scenes
    if all lie more than PROFILE_CLEAR × ``thr`` above the best: that excludes it with a margin.  ``early``
    (a dict, optional) receives {(key, value): scenes used} of the values so accepted, which :func:`recheck`
    revisits if the best falls; ``cleared`` (a dict, optional) {(key, value): scenes used} of the values so
    excluded.  Returns {key: {value: profile score}}, the best scene's value included."""
    prof = {}
    early = {} if early is None else early
    cleared = {} if cleared is None else cleared
    for k, vals in grid.items():
        if len(vals) < 2:
            continue
        v = sorted(vals)
        v = sorted(set(v) | {round((a + b) / 2, 4) for a, b in zip(v[:-1], v[1:])})   # and the half steps
        prof[k] = {best_point[k]: best_point["score_db"]}
        for side in (-1, 1):
            ahead = [x for x in v if (x - best_point[k]) * side > 1e-12]
            for x in sorted(ahead, key=lambda x: abs(x - best_point[k])):
                val, used, how = profile_value(grid, k, x, best_point, score, points, max_scenes,
                                               lambda: best_score() + thr,
                                               lambda: best_score() + PROFILE_CLEAR * thr)
                prof[k][x] = val
                if how == "accepted":
                    early[(k, x)] = used
                elif how == "cleared":
                    cleared[(k, x)] = used
                if prof[k][x] > best_score() + thr:
                    break
    return prof


def recheck(grid, walked, early, score, points, thr, max_scenes=PROFILE_MAX_SCENES):
    """Values a profile walk accepted early whose score now lies above the threshold (the best fell later):
    their minimisation goes on with the rest of its budget, from the best scene at that value."""
    best = min(points, key=lambda p: p["score_db"])
    for (k, x), used in early.items():
        if walked[k][x] <= best["score_db"] + thr or used >= max_scenes:
            continue
        here = min((p for p in points if abs(p[k] - x) <= 1e-12), key=lambda p: p["score_db"])
        val, _, _ = profile_value(grid, k, x, here, score, points, max_scenes - used,
                                  lambda: best["score_db"] + thr)
        walked[k][x] = min(walked[k][x], val)


def polish(grid, walked, points, score, thr):
    """Search again, all parameters free and with a first step of an eighth of the coarse step, from the
    best scene of every profile value within ``thr`` of the best that lies more than a quarter of a coarse
    step (in some parameter) from the best scene and from the other starts (at most POLISH_STARTS, best
    first): a narrow basin the first search stepped over is found from a start next to it.  Every scene a
    polish reaches within the threshold accepts its values (see :func:`_profile`)."""
    best = min(points, key=lambda p: p["score_db"])
    steps = coarse_steps(grid, best)

    def apart(a, b):
        return any(abs(a[k] - b[k]) > 0.25 * steps[k] for k in steps)
    cands = []
    for k, prof in walked.items():
        for v, sc in prof.items():
            if sc <= best["score_db"] + thr:
                cands.append(min((p for p in points if abs(p[k] - v) <= 1e-12), key=lambda p: p["score_db"]))
    starts = []
    for q in sorted(cands, key=lambda p: p["score_db"]):
        if apart(q, best) and all(apart(q, o) for o in starts):
            starts.append(q)
    for q in starts[:POLISH_STARTS]:
        minimise(grid, {j: q[j] for j in grid}, score, list(grid), POLISH_MAX_SCENES, first_step=0.125)


#: the roughness probe moves each parameter by this fraction of its coarse grid step
ROUGHNESS_STEP = 0.003


def probes(grid, best) -> list:
    """Scenes ROUGHNESS_STEP (0.3 %) of a coarse step from the best one, each parameter alone, one way (up,
    or down at the top of the searched range): geometries no recording can tell apart.  How much their
    scores differ from the best's is the score's roughness at this scale (the contact tables'
    discretisation of the outline, the impact signature's sampling): differences below it carry no
    information.  One scene per parameter, not one each way: each is an outline of its own, whose contact
    table is built for it alone (about 1 s for a skewed outline off the track centre)."""
    out = []
    for k, vals in grid.items():
        v = sorted(vals)
        if len(v) < 2:
            continue
        step = ROUGHNESS_STEP * (v[-1] - v[0]) / (len(v) - 1)
        for sign in (1, -1):
            x = round(best[k] + sign * step, 5)
            if v[0] <= x <= v[-1]:          # inside the searched range (an offset beyond B/2 is another defect)
                out.append({**{q: [best[q]] for q in grid}, k: [x]})
                break
    return out
