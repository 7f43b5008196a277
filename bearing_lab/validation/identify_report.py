"""Files of a defect identification: JSON, the misfit landscape as netCDF, figures and a report page.

Public API
----------
landscape(result) -> xarray.Dataset        -- scores on the coarse grid (dims per searched key) + refinement points
figures(result) -> [(Figure, caption)]      -- best fit over the measurement; profiles of the misfit
write_identification(result, out) -> dict   -- DIR/<case>/identification.{json,nc,html}; paths written
add_to_case_report(result, case_dir)        -- the sections added to DIR/<case>/index.html (from report.json)
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import xarray as xr

from .._version import __version__
from ..report import Report
from ..errors import BearingLabError
from ..io.export import to_netcdf
from ..report.html import list_html
from ..sweep import dim_name, key_units
from ..units import G
from ..utils._files import atomic_open
from ..utils._json import clean
from ..utils.figures import new_figure
from .identify import PARAMS

__all__ = ["landscape", "figures", "write_identification", "add_to_case_report"]

_VARS = {"score_db": "misfit score (shape + weight x |level|)",
         "shape_db": "shape misfit (RMS log-envelope difference)",
         "level_db": "level: 20 log10(simulated / measured signature peak)"}


def landscape(result):
    keys = list(result.grid)
    vals = [sorted(result.grid[k]) for k in keys]
    shape = tuple(len(v) for v in vals)
    data = {k: np.full(shape, np.nan) for k in _VARS}
    extra = []
    for p in result.points:
        try:
            idx = tuple(v.index(p[k]) for k, v in zip(keys, vals))
        except ValueError:
            extra.append(p)
            continue
        for k in _VARS:
            data[k][idx] = p[k]
    dims = tuple(dim_name(k) for k in keys)
    coords = {dim_name(k): (dim_name(k), v, {"units": key_units(k) or ""}) for k, v in zip(keys, vals)}
    ds = xr.Dataset({k: (dims, a, {"units": "dB", "long_name": _VARS[k]}) for k, a in data.items()}, coords=coords)
    for k in keys:
        ds[f"refined_{dim_name(k)}"] = ("refined", np.array([p[k] for p in extra], float),
                                        {"units": key_units(k) or ""})
    for k in _VARS:
        ds[f"refined_{k}"] = ("refined", np.array([p[k] for p in extra], float), {"units": "dB"})
    ds.attrs.update({"case": result.case, "threshold_db": result.threshold_db, "noise_db": result.noise_db,
                     "level_weight": result.level_weight, "level_reason": result.level_reason,
                     "best": json.dumps({k: result.best[k] for k in keys}), "n_scenes": result.n_scenes,
                     "bearing_lab_version": __version__,
                     "statements": " | ".join(p["statement"] for p in result.parameters.values())})
    if result.roughness_db is not None:
        ds.attrs["roughness_db"] = result.roughness_db
    return ds


def figures(result) -> list:
    rec, best = result.signatures["recording"], result.signatures["best"]
    out = []
    if best is not None:        # None: a partial result whose best scene was read back from the journal
        out.append(_best_figure(result, rec, best))
    return out + [_profile_figure(result)]


def _best_figure(result, rec, best):
    fig = new_figure(figsize=(10, 3.4), layout="constrained")
    ax = fig.subplots()
    ax.plot(rec.time * 1e3, rec.envelope / G, color="k", lw=1.2, label=f"recording ({rec.n_impacts} impacts)")
    lag = result.best.get("lag_s", 0.0)
    ax.plot((best.time - lag) * 1e3, best.envelope / G, color="tab:red", lw=1.0,
            label="best scene after the fixed path and background")
    ax.set_xlabel("time from the impact (ms)")
    ax.set_ylabel("mean envelope (g)")
    ax.legend(fontsize=8)
    keys = list(result.grid)
    best_txt = ", ".join(f"{k.split('.')[1]} = {result.best[k]:g}" for k in keys)
    return (fig, f"Mean impact envelope ({rec.band_hz[0]:g}-{rec.band_hz[1]:g} Hz) of the recording and of the best "
                 f"scene ({best_txt}; score {result.best['score_db']:.2f} dB).")


def _profile_figure(result):
    keys = list(result.grid)
    fig2 = new_figure(figsize=(10, 2.8), layout="constrained")
    axes = np.atleast_1d(fig2.subplots(1, len(keys)))
    for ax, k in zip(axes, keys):
        p = result.parameters[k]
        v, s = np.array(p["profile"]).T
        opt = np.isin(v, p.get("optimised") or v)
        ax.plot(v[opt], s[opt], "o-", color="k", ms=3)
        if not opt.all():
            ax.plot(v[~opt], s[~opt], ".", color="0.55", ms=3)
        ax.axhline(result.best["score_db"] + result.threshold_db, color="tab:red", lw=0.8, ls="--")
        ax.axvspan(*p["interval"], color="tab:red", alpha=0.12)
        ax.set_xlabel(f"{PARAMS[k][0]} ({p['unit']})")
        ax.set_title(("" if p["identifiable"] else "not identifiable: ") + f"best {p['best']:g}", fontsize=9)
    axes[0].set_ylabel("profile misfit (dB)")
    return ((fig2, f"Misfit profiles: black, the least score found by minimising over the other parameters at "
                      f"each walked value (without the refinement: the best coarse scene at each grid value); grey, "
                      f"other simulated scenes within the threshold; dashed: best + {result.threshold_db:.2f} dB (the "
                      f"interval threshold); shaded: the interval."))


def _add_sections(rep, result):
    """The identification's sections: what was run and the threshold, one statement per parameter, the
    notes, the figures (through the report's templates)."""
    rough = (f"; the score's roughness at the best scene {result.roughness_db:.2f} dB"
             if result.roughness_db is not None else "")
    rep.add_text(f"{result.n_scenes} simulated scenes, {result.cpu_time_s:.0f} s CPU in this process "
                 f"({result.wall_time_s:.0f} s wall). Interval threshold {result.threshold_db:.2f} dB (the "
                 f"recording's split-half misfit {result.noise_db:.2f} dB{rough}).", "Defect identification")
    rep.add_html(list_html([p["statement"] for p in result.parameters.values()]), None)
    if result.notes:
        rep.add_text(list(result.notes), None, note=True)
    rep.add_figures(figures(result), "Defect identification: figures")


def add_to_case_report(result, case_dir):
    case_dir = Path(case_dir)
    rj = case_dir / "report.json"
    rep = Report.load(rj) if rj.is_file() else Report(f"{result.case}: defect identification")
    rep.sections = [s for s in rep.sections if not s["title"].startswith("Defect identification")]
    _add_sections(rep, result)
    rep.save(case_dir / ("index.html" if rj.is_file() else "identification.html"))
    if rj.is_file():
        rep.save(rj)
    return rep


def write_identification(result, out, *, report=False, stem="identification") -> dict:
    d = Path(out) / result.case
    d.mkdir(parents=True, exist_ok=True)
    paths = {ext: d / f"{stem}.{ext}" for ext in ("json", "nc", "html")}
    with atomic_open(paths["json"], "w", encoding="utf-8") as fh:
        json.dump(clean(result.to_dict()), fh, indent=1, allow_nan=False)
    to_netcdf(landscape(result), paths["nc"], error=BearingLabError)
    rep = Report(f"{result.case}: defect identification" + (" (PARTIAL: interrupted)" if result.partial else ""))
    _add_sections(rep, result)
    rep.add_provenance()
    rep.save(paths["html"])
    if report:
        add_to_case_report(result, d)
    return paths
