"""The local (Winkler-type) law against the elastic half-space over one defect: a check of the
"area" model and of the "halfspace" table against a fine-grid half-space solve, used by
``tests/sim/test_defect_contact.py`` and ``benchmarks/defect_tables.py``.  It sits above both the
tables (:mod:`.contact`) and the solver (:mod:`.halfspace`), which import neither it nor each other
for it."""
from __future__ import annotations

import numpy as np

from ...bearings import get_bearing
from .contact import contact_table
from .geometry import RaceGeometry
from .halfspace import HalfSpace, e_star_of, pressure_semi_axes
from .model import Defect

__all__ = ["compare_local_law"]


def compare_local_law(bearing=None, *, load: float = 300.0, k_hertz: float = 3.27e10,
                      s_positions=(0.0, 0.3e-3, 0.5e-3, 0.6e-3), dx: float = 0.0125e-3,
                      dy: float = 0.004e-3) -> dict:
    """6308 outer race: fine-grid half-space against the "area" local law and the
    "halfspace" table over a centred 1 x 1 mm defect.

    At the approach ``(load / k_hertz)^(2/3)`` returns the intact half-space force and
    semi-axes, and for each ball position ``s`` (m from the defect centre) the share of the
    intact force still carried: fine half-space solve, local-law table, half-space table.
    """
    bearing = get_bearing("6308") if bearing is None else bearing
    geom = RaceGeometry.from_bearing(bearing, "outer")
    d = Defect(length=1e-3, width=1e-3, depth=0.5e-3)
    delta = (load / k_hertz) ** (2 / 3)
    intact = race_contact(geom, None, delta, dx=dx, dy=dy)
    tables = {m: contact_table(d, bearing, model=m, delta_max=2 * delta, n_delta=81)
              for m in ("area", "halfspace")}
    out = {"approach": delta, "intact_force": intact["force"], "a": intact["a"], "b": intact["b"],
           "iterations": intact["iterations"], "positions": []}
    for s in s_positions:
        r = race_contact(geom, d, delta, s_ball=s, dx=dx, dy=dy, solver=intact["solver"])
        row = {"s": s, "halfspace": r["force"] / intact["force"]}
        for m, T in tables.items():
            row["local_law" if m == "area" else "table"] = (
                float(T.lookup(s / geom.track_radius, delta)) / delta ** 1.5)
        out["positions"].append(row)
    return out


def race_contact(geom: RaceGeometry, defect: Defect | None, approach: float, *,
                 s_ball: float = 0.0, half_across: float | None = None,
                 half_along: float | None = None, dx: float = 0.0125e-3, dy: float = 0.004e-3,
                 e_star: float | None = None, solver: HalfSpace | None = None):
    """Half-space contact of the ball at track position ``s_ball`` (m from the defect
    centre) and approach ``approach`` on a grid of given cell size (dx across, dy along).

    A fine-grid check, independent of the tables' grids.  Returns a dict with force (N),
    semi-axes a (across) and b (along) of the contact from the pressure's moments (m),
    p (Pa), iterations and the solver (reusable for the same grid)."""
    e_star = e_star_of() if e_star is None else e_star
    if half_across is None or half_along is None:
        b_r, a_r = geom.reach(approach)
        half_across = a_r + dx if half_across is None else half_across
        half_along = b_r + dy if half_along is None else half_along
    nx, ny = int(round(2 * half_across / dx)), int(round(2 * half_along / dy))
    z = (np.arange(nx) - nx / 2 + 0.5) * dx
    s = (np.arange(ny) - ny / 2 + 0.5) * dy
    Z, S = np.meshgrid(z, s, indexing="ij")
    R = geom.track_radius
    gap = geom.approach(S / R, Z)
    if defect is not None:
        ins = defect.contains(S + s_ball, Z)
        gap = np.where(ins, geom.approach(S / R, Z, depth=defect.depth), gap)
    gap = np.where(np.isfinite(gap), gap, 1.0)
    hs = solver if solver is not None else HalfSpace(nx, ny, dx, dy, e_star)
    p, it = hs.solve(gap, approach)
    c = p > 0
    if c.any() and (np.abs(Z[c]).max() > half_across - 2 * dx or np.abs(S[c]).max() > half_along - 2 * dy):
        raise ValueError("the contact reaches the edge of the half-space grid; enlarge it")
    a, b = pressure_semi_axes(p, Z, S, dx, dy) if c.any() else (0.0, 0.0)
    return {"force": float(p.sum() * dx * dy), "a": a, "b": b, "p": p, "iterations": it, "solver": hs}
