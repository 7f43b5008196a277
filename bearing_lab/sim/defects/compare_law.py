"""The local (Winkler-type) law against the elastic half-space over one defect: a check of the
"area" model and of the "halfspace" table against a fine-grid half-space solve, used by
``tests/sim/test_defect_contact.py`` and ``benchmarks/defect_tables.py``.  It sits above both the
tables (:mod:`.contact`) and the solver (:mod:`.halfspace`), which import neither it nor each other
for it."""
from __future__ import annotations

from ...bearings import get_bearing
from .contact import contact_table
from .geometry import RaceGeometry
from .halfspace import race_contact
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
