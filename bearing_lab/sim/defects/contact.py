"""Ball-race contact over a defect, tabulated once per defect: ``F = K_hertz * G(psi, delta)``.

Why a table: the contact geometry (sphere against a torus with an outline removed) is
exact but costs a 2-D contact solution; the time loop needs the force millions of times.
So the contact is reduced, once per defect and outside the loop, to a function of two
numbers, the ball's angular position over the defect and its approach, and the loop
interpolates.  Tables are kept in memory and on disk (:mod:`._table_cache`), so a sweep,
a validation run or a second session pays for a table once.

Conventions (SI)
----------------
``psi``   angular position (rad) of the BALL CENTRE minus the defect centre's angle, in the
          direction of increasing track coordinate ``s`` (see :mod:`.model`).  The table
          spans the defect's extent along the track plus the reach of the contact at
          ``delta_max`` plus a margin; outside ``[psi_min, psi_max]`` the contact is intact.
          For a ball defect (``against="outer"|"inner"``) psi is the contact point's angle
          ON THE BALL relative to the defect centre (arc ``r_b * psi``), same sense.
``delta`` the ball's approach to the race relative to the INTACT surface (m, >= 0 into the
          race: outward for the outer race, inward for the inner race); uniform grid from 0
          to ``delta_max``.  Negative approach: no contact.
``G``     m^1.5, so that the normal force is ``K_hertz * G``; ``G = delta^1.5`` on intact
          surface, independent of K.
``drop``  the rigid ball's movement allowed at each psi (the approach at which it first
          touches the remaining surface): 0 on intact track, up to ``depth``.

Models
------
``"halfspace"`` (the default)  the load the defected raceway carries at a given approach
    and ball position, from the elastic half-space (Boussinesq/Love influence,
    Polonsky-Keer conjugate gradient on a DC-FFT grid, :mod:`.halfspace`) with the exact
    sphere-in-torus gap and the outline removed, as a share of the intact half-space load
    at the same approach: ``G = share * delta^1.5``.  Solved at ``HALFSPACE_NODES``
    approaches (fractions of ``delta_max``) for ball positions a whole number of cells
    apart (refined where the share curves), interpolated linearly onto the table's psi;
    between approaches ``G^(2/3)`` is interpolated by a monotone cubic through (0, 0) and
    (drop, 0).
    For rectangles the sides fall on cell boundaries (cell sizes adjusted when the sides
    run along and across the track, cells rotated with the outline otherwise), and two
    grids (``TABLE_CELLS`` and half as many cells) are extrapolated to zero cell size
    (Richardson; the error is first order in the cell size).  Accuracy and build time:
    ``docs/contact-model.md``.
``"area"``     2-D loss of contact area by a local (Winkler-type) law over the raceway
    surface, ``dF = K c sqrt(max(delta - h(s, z), 0)) dA`` with ``h`` the exact gap of
    :mod:`.geometry` to the remaining surface, ``c = 3 / (4 pi sqrt(R_x R_y))`` so that the
    paraboloid gives ``K delta^1.5``; the table divides the defected integral by the intact
    one on the same lattice (``G = delta^1.5`` exactly on intact surface).  Its footprint is
    the rigid interpenetration region ``{h < delta}``, about 1.4 times longer and wider than
    the elastic contact, and no load moves to the intact flanks: it removes too much load
    over too long a stretch of track.
``"drop"``     rigid 2-D drop: ``G = max(delta - h2(psi), 0)^1.5`` with ``h2`` the exact 3-D
    drop (:func:`.geometry.drop_profile_2d`); the contact keeps its intact stiffness.
``"profile"``  along-track 1-D: the defect reduced to its intervals on the track centre
    line, each made a full-width slot; ``G = max(delta - h1(psi), 0)^1.5`` with ``h1`` the
    exact drop over the slot's edge lines (:func:`.geometry.drop_profile_1d`).  Blind to
    offset (a defect off the centre line vanishes) and to skew.

How far the cheaper models are from the half-space on the paper's defects, as tables and
in the dynamics, is measured by ``benchmarks/defect_tables.py`` and
``benchmarks/defect_models.py`` (figures in ``benchmarks/README.md``).

Discretisation of "area"
------------------------
(:mod:`.lattice`) A lattice on the track, cells ``ds x dz``; ``ds = psi step * R / m`` with integer ``m`` so
the ball-centred window slides by whole cells; each cell carries the fraction of it inside
the outline (4 x 4 sub-samples), so G is smooth in psi.  The sum over the window is a
correlation evaluated by FFT along the track.

The ``intact_fraction`` is geometric and the same for every model: the share of the intact
Hertz contact ellipse at that approach (semi-axes from :func:`.geometry.hertz_semi_axes`,
0.90 x 0.16 mm at 300 N on the 6308 outer race) that lies outside the outline (1 at
delta = 0).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable
import math
import time

import numpy as np
import xarray as xr

from bearing_lab.errors import SceneError, check_choice

from ...utils.figures import new_figure
from . import _table_cache
from .geometry import RaceGeometry, drop_profile_1d, drop_profile_2d
from .halfspace import ABOVE_NODE_STEP, HALFSPACE_NODES, TABLE_CELLS, aligned_sides, ratio_curve
from .halfspace_skewed import ratio_curve_skewed
from .lattice import track_lattice
from .model import Defect

# CONTACT_MODELS, the registry of models (one entry each), closes this module.
# the "halfspace" model's approach nodes (HALFSPACE_NODES, ABOVE_NODE_STEP) are set in :mod:`.halfspace`;
# the tables are built with this module's names and the cache key is made with them
#: Young's modulus and Poisson ratio the tables assume unless told (52100 steel)
DEFAULT_MATERIAL = (208e9, 0.3)
_CELLS_ALONG = 60   # lattice cells per along-track reach at delta_max ("area")
_CELLS_ACROSS = 60  # lattice cells per across-track reach at delta_max ("area")
_FRACTION_CELLS = 24  # lattice cells per reach for the intact fraction of the other models
_PSI_PER_REACH = 40  # psi grid points per along-track reach at delta_max (auto n_psi)


@dataclass(frozen=True, eq=False)
class ContactTable:
    """Tabulated contact of a ball with a defected race.  See the module docstring.

    Attributes
    ----------
    psi : (n_psi,) rad, uniform; ball-centre angle minus defect-centre angle.
    delta : (n_delta,) m, uniform from 0; approach relative to the intact surface.
    G : (n_psi, n_delta) m^1.5; normal force = K_hertz * G.
    drop : (n_psi,) m; rigid-ball drop allowed at each psi (the model's own geometry).
    intact_fraction : (n_psi, n_delta); share of the intact Hertz contact ellipse at that
        approach that lies outside the outline (geometric, the same for every model).
    model, race : str.
    psi_min, psi_max : float, rad; the table's range (outside it the contact is intact).
    track_radius : m, radius on the defected body: the groove-bottom radius for a race
        defect, the ball radius for a ball defect; the defect spans s = track_radius * psi.
    info : dict of diagnostics (lattice sizes, build time, intact-law ratio).
    """

    psi: np.ndarray
    delta: np.ndarray
    G: np.ndarray
    drop: np.ndarray
    intact_fraction: np.ndarray
    model: str
    race: str
    psi_min: float
    psi_max: float
    track_radius: float
    info: dict = field(default_factory=dict)

    @property
    def delta_max(self) -> float:
        return float(self.delta[-1])

    def lookup(self, psi, delta):
        """G (m^1.5) at (psi, delta), bilinear; intact ``max(delta, 0)^1.5`` outside the psi
        range.  Inside it, an approach above the table's top (``delta_max``) is an error, not
        an extrapolation: build the table with a larger range (``above_drop``, ``delta_top``)."""
        psi = np.asarray(psi, dtype=float)
        delta = np.asarray(delta, dtype=float)
        psi, delta = np.broadcast_arrays(psi, delta)
        shape = psi.shape
        psi, delta = psi.ravel(), delta.ravel()
        out = np.maximum(delta, 0.0) ** 1.5
        n_psi, n_d = self.G.shape
        dpsi = (self.psi_max - self.psi_min) / (n_psi - 1)
        dd = self.delta[-1] / (n_d - 1)
        inside = (psi >= self.psi_min) & (psi <= self.psi_max) & (delta > 0)
        if np.any(inside):
            x = (psi[inside] - self.psi_min) / dpsi
            i = np.clip(np.floor(x).astype(int), 0, n_psi - 2)
            fx = x - i
            dl = delta[inside]
            y = np.minimum(dl, self.delta[-1]) / dd
            j = np.clip(np.floor(y).astype(int), 0, n_d - 2)
            fy = y - j
            G = self.G
            g = ((1 - fx) * ((1 - fy) * G[i, j] + fy * G[i, j + 1])
                 + fx * ((1 - fy) * G[i + 1, j] + fy * G[i + 1, j + 1]))
            above = dl > self.delta[-1] * (1 + 1e-12)
            if np.any(above):
                raise SceneError(f"contact table ({self.model}, {self.race} race): approach "
                                 f"{1e6 * float(dl[above].max()):.3g} um lies above the table's top "
                                 f"{1e6 * self.delta[-1]:.3g} um; build it with a larger range "
                                 "(above_drop or delta_top)")
            out[inside] = g
        return out.reshape(shape)

    def to_dataset(self):
        """The table as an xarray Dataset (SI, ``units`` attributes), e.g. for netCDF."""
        coords = {"psi": ("psi", np.asarray(self.psi), {"units": "rad",
                  "long_name": "ball-centre angle minus defect-centre angle"}),
                  "delta": ("delta", np.asarray(self.delta), {"units": "m",
                  "long_name": "approach relative to the intact surface"})}
        ds = xr.Dataset(
            {"G": (("psi", "delta"), np.asarray(self.G), {"units": "m1.5",
                   "long_name": "normal force / K_hertz"}),
             "drop": ("psi", np.asarray(self.drop), {"units": "m",
                      "long_name": "rigid-ball drop"}),
             "intact_fraction": (("psi", "delta"), np.asarray(self.intact_fraction),
                                 {"units": "1", "long_name": "intact share of the Hertz ellipse"})},
            coords=coords,
            attrs={"model": self.model, "race": self.race, "track_radius_m": self.track_radius,
                   "psi_min": self.psi_min, "psi_max": self.psi_max})
        return ds

    def plot(self, deltas=(4e-6, 8e-6), *, ax=None, s_units: str = "mm"):
        """Plot G / delta^1.5 (carried share of the intact load) and the intact fraction of
        the Hertz ellipse against the ball's track position, at the approaches ``deltas``
        (m).  Returns the figure."""
        scale = {"mm": 1e3, "m": 1.0, "um": 1e6}[s_units]
        if ax is None:
            fig = new_figure(figsize=(6, 3.5))
            ax = fig.subplots()
        else:
            fig = ax.figure
        s = np.asarray(self.psi) * self.track_radius * scale
        for d in deltas:
            k = int(np.argmin(np.abs(self.delta - d)))
            dk = self.delta[k]
            line, = ax.plot(s, self.G[:, k] / dk ** 1.5, label=f"G/δ^1.5, δ = {dk*1e6:.1f} µm")
            ax.plot(s, self.intact_fraction[:, k], "--", color=line.get_color(),
                    label=f"intact ellipse, δ = {dk*1e6:.1f} µm")
        ax.set_xlabel(f"ball position over the defect, s ({s_units})")
        ax.set_ylabel("share of intact")
        ax.set_ylim(-0.05, 1.05)
        ax.set_title(f"{self.race} race, model {self.model!r}")
        ax.legend(fontsize=7)
        return fig

    def kernel_arrays(self):
        """(psi_min, dpsi, ddelta, G) with G C-contiguous float64, for a jitted lookup."""
        n_psi, n_d = self.G.shape
        return (float(self.psi_min), float((self.psi_max - self.psi_min) / (n_psi - 1)),
                float(self.delta[-1] / (n_d - 1)), np.ascontiguousarray(self.G, dtype=np.float64))


def _interacting_s_extent(defect: Defect, a_w: float):
    """s-extent (m) of the outline restricted to the strip |z| <= a_w, or None."""
    s0, s1, z0, z1 = defect.track_extent()
    if z1 < -a_w or z0 > a_w:
        return None
    sb, zb = defect.boundary_track(spacing=max(defect.length, defect.width) / 4000)
    cand = list(sb[np.abs(zb) <= a_w])
    line = np.linspace(s0, s1, 4001)
    for zc in (-a_w, a_w):
        ins = defect.contains(line, np.full_like(line, zc))
        cand.extend(line[ins])
    if not cand:
        return None
    return float(min(cand)), float(max(cand))


def _arguments_and_key(defect, bearing, *, model, clearance=0.0, delta_max, n_psi=None, n_delta=41, against=None,
                       material=None, above_drop=None, delta_top=None):
    """The table's normalised arguments and its cache key, as :func:`contact_table` forms them."""
    material = DEFAULT_MATERIAL if material is None else (float(material[0]), float(material[1]))
    args = dict(model=model, clearance=float(clearance), delta_max=float(delta_max), n_psi=n_psi,
                n_delta=int(n_delta), against=against, material=material)
    if above_drop is not None:
        args["above_drop"] = float(above_drop)
    if delta_top is not None:
        args["delta_top"] = float(delta_top)
    return args, _table_cache.table_key(replace(defect, angle=0.0), bearing, halfspace_nodes=HALFSPACE_NODES,
                                        above_node_step=ABOVE_NODE_STEP, **args)


def table_is_cached(defect: Defect, bearing, **kw) -> bool:
    """Whether :func:`contact_table` with these arguments would read its table back (from memory or the
    disk cache) instead of building it."""
    _, key = _arguments_and_key(defect, bearing, **kw)
    return key in _MEMORY or _table_cache.entry_path(key, kw["model"]).is_file()


def contact_table(defect: Defect, bearing, *, model: str, clearance: float = 0.0,
                  delta_max: float, n_psi: int | None = None, n_delta: int = 41,
                  against: str | None = None, material: tuple[float, float] | None = None,
                  above_drop: float | None = None, delta_top: float | None = None,
                  cache: bool = True) -> ContactTable:
    """Tabulate the contact of a ball with the defected race (see the module docstring).

    Tables are kept in memory (a defect's ``angle`` does not enter the table, so the same
    outline at several positions or speeds is built once) and, with ``cache=True``, on
    disk under :func:`bearing_lab.utils._files.cache_dir` ``("tables")``, keyed by everything
    the table depends on; a damaged disk entry is reported and rebuilt.  The returned
    arrays are read-only; ``info["source"]`` says where the table came from ("built",
    "memory", "disk").

    Parameters
    ----------
    defect : Defect on the "outer" or "inner" race, or on a ball (see ``against``).
    bearing : BearingGeometry.
    model : "halfspace", "area", "drop" or "profile".
    clearance : diametral clearance, m (moves the groove bottoms by clearance/4).
    delta_max : the loaded approach range, m (e.g. 2-3 x the static deflection of the most
        loaded ball; 12e-6 for the 6308 at 480 N): the psi range covers the contact's reach at
        it, and the half-space nodes are densest below it.
    n_psi : psi grid size; default: about 40 points per along-track contact reach.
    n_delta : delta grid points per ``delta_max`` (default 41); a table extended above
        ``delta_max`` keeps that spacing.
    above_drop : approach the table must cover above the deepest rigid drop of its psi range,
        m: the table then reaches ``max(delta_max, max(drop) + above_drop)`` (no extension for
        less than 5 % of delta_max), so a ball that
        falls into the defect and is loaded there reads computed values, never an
        extrapolation (give the loaded range, as the simulation does).
    delta_top : a lower bound of the table's top approach, m (the simulation extends a table
        this way when a run reached above it).
    against : for a ball defect only, the race it strikes, "outer" or "inner" (build one
        table per race).  psi is then measured on the ball: the contact point's angle on the
        ball relative to the defect centre (arc ``ball_radius * psi``), and the outline is
        laid on the contact plane to first order (ball arc = race arc); the floor gap is the
        race's (intact gap + depth to first order).
    material : (Young's modulus Pa, Poisson ratio) of ball and race; default 208 GPa, 0.3.
        G does not depend on it (the half-space share is a ratio); the intact half-space
        force reported in ``info`` does.
    cache : use the on-disk table cache (default True).

    Returns
    -------
    ContactTable
    """
    args, key = _arguments_and_key(defect, bearing, model=model, clearance=clearance, delta_max=delta_max,
                                   n_psi=n_psi, n_delta=n_delta, against=against, material=material,
                                   above_drop=above_drop, delta_top=delta_top)
    _check_arguments(defect, **args)
    hit = _MEMORY.get(key)
    if hit is not None:
        return hit
    fields = _table_cache.load(key, model) if cache else None
    table = ContactTable(**fields) if fields is not None else None
    if table is None:
        table = _build(defect, bearing, **args)
        table.info["source"] = "built"
        if cache:
            _table_cache.store(key, table)
    for name in ("psi", "delta", "G", "drop", "intact_fraction"):
        getattr(table, name).flags.writeable = False
    if len(_MEMORY) >= _MEMORY_SIZE:
        _MEMORY.pop(next(iter(_MEMORY)))
    _MEMORY[key] = table
    return table


_MEMORY: dict = {}
_MEMORY_SIZE = 64


def _check_arguments(defect, *, model, clearance, delta_max, n_psi, n_delta, against, material,
                     above_drop=None, delta_top=None):
    check_choice(model, CONTACT_MODELS, "contact model", SceneError)
    if not (math.isfinite(delta_max) and delta_max > 0):
        raise SceneError(f"{delta_max=} m must be positive and finite")
    for name, v in (("above_drop", above_drop), ("delta_top", delta_top)):
        if v is not None and not (math.isfinite(v) and v > 0):
            raise SceneError(f"{name}={v!r} m must be positive and finite")
    if n_delta < 3:
        raise SceneError(f"{n_delta=} must be at least 3")
    if n_psi is not None and n_psi < 8:
        raise SceneError(f"{n_psi=} must be at least 8")
    E, nu = material
    if not (math.isfinite(E) and E > 0 and 0 <= nu < 0.5):
        raise SceneError(f"material={material!r}: give (Young's modulus in Pa > 0, "
                         "Poisson ratio in [0, 0.5))")
    if defect.race == "ball":
        if against not in ("outer", "inner"):
            raise SceneError(f"a ball defect needs against='outer' or 'inner' (the race it "
                             f"strikes), got {against!r}")
    elif against not in (None, defect.race):
        raise SceneError(f"against={against!r} is only for ball defects "
                         f"(this defect is on the {defect.race} race)")


def _build(defect, bearing, *, model, clearance, delta_max, n_psi, n_delta, against=None,
           material=DEFAULT_MATERIAL, halfspace_settings=None, above_drop=None,
           delta_top=None) -> ContactTable:
    t0 = time.perf_counter()
    c0 = time.process_time()
    _check_arguments(defect, model=model, clearance=clearance, delta_max=delta_max, n_psi=n_psi,
                     n_delta=n_delta, against=against, material=material, above_drop=above_drop,
                     delta_top=delta_top)
    race = defect.race if defect.race != "ball" else against
    geom = RaceGeometry.from_bearing(bearing, race, clearance=clearance)
    # psi is measured on the defected body: the ball for a ball defect
    R = geom.ball_radius if defect.race == "ball" else geom.track_radius
    b_reach, a_reach = geom.reach(delta_max)
    if a_reach >= 0.9 * geom.z_limit:
        raise SceneError(f"{delta_max=} m: the contact would reach the groove's edge; "
                         "give a smaller delta_max")
    ext = _interacting_s_extent(defect, 1.05 * a_reach)
    misses = ext is None
    if misses:
        s0, s1, _, _ = defect.track_extent()
        ext = (s0, s1)
    s_lo = ext[0] - 1.15 * b_reach
    s_hi = ext[1] + 1.15 * b_reach
    if n_psi is None:
        n_psi = int(min(max(math.ceil((s_hi - s_lo) / (b_reach / _PSI_PER_REACH)) + 1, 64), 8001))
    psi = np.linspace(s_lo / R, s_hi / R, n_psi)
    drop2 = drop_profile_2d(defect, geom, psi, psi_radius=R)
    # the approach range: the loaded range, above the deepest drop when asked, and never
    # below delta_top; the grid keeps the loaded range's spacing
    top = delta_max
    if above_drop is not None and float(np.max(drop2)) + above_drop > 1.05 * delta_max:
        # (a drop that would lift the top by under 5 % of the loaded range adds no nodes: the
        # loaded range then still reaches the drop plus 95 % of above_drop)
        top = float(np.max(drop2)) + above_drop
    if delta_top is not None:
        top = max(top, delta_top)
    n_d = n_delta if top <= delta_max * (1 + 1e-12) else int(math.ceil(top / delta_max * (n_delta - 1))) + 1
    delta = np.linspace(0.0, top, n_d)
    spec = CONTACT_MODELS[model]
    drop = drop_profile_1d(defect, geom, psi, psi_radius=R) if spec.along_track_drop else drop2
    cells = (_CELLS_ALONG, _CELLS_ACROSS) if spec.area_law else (_FRACTION_CELLS,) * 2
    lat = track_lattice(defect, geom, psi, R, delta, cells=cells, area_law=spec.area_law)
    info = {"reach_along_m": b_reach, "reach_across_m": a_reach, "misses_track": misses,
            "drop_2d": drop2, "loaded_range_m": float(delta_max), "max_drop_m": float(np.max(drop2)),
            **lat["info"]}
    G = spec.g(dict(defect=defect, geom=geom, psi=psi, R=R, delta=delta, drop=drop, drop2=drop2,
                    lattice=lat, material=material, misses=misses, info=info,
                    halfspace_settings=halfspace_settings))
    G[:, 0] = 0.0
    info["build_time_s"] = time.perf_counter() - t0
    info["build_cpu_s"] = time.process_time() - c0
    label = defect.race if defect.race != "ball" else f"ball/{against}"
    return ContactTable(psi=psi, delta=delta, G=G, drop=drop, intact_fraction=lat["intact_fraction"],
                        model=model, race=label, psi_min=float(psi[0]), psi_max=float(psi[-1]),
                        track_radius=R, info=info)


def _halfspace_G(defect, geom, s_tab, delta, drop, *, e_star, misses, settings=None):
    """G of the "halfspace" model on the table's (s, delta) grid, and diagnostics.

    ``settings`` (for convergence studies) overrides ``nodes`` (fractions of delta_max),
    ``cells``, ``richardson`` and the keywords of :func:`.halfspace.ratio_curve`
    (``tol``, ``refine_tol``, ``coarse_step``)."""
    settings = dict(settings or {})
    n_psi, n_delta = s_tab.size, delta.size
    loaded = settings.pop("loaded_range", delta[-1])
    nodes_d = np.array(settings.pop("nodes", HALFSPACE_NODES)) * loaded
    if delta[-1] > loaded * (1 + 1e-9):
        # above the loaded range (a ball inside a deep defect): nodes a third of it apart
        extra = int(math.ceil((delta[-1] - loaded) / (loaded * ABOVE_NODE_STEP)))
        nodes_d = np.concatenate([nodes_d, loaded + (delta[-1] - loaded) * np.arange(1, extra + 1) / extra])
    cells = tuple(settings.pop("cells", TABLE_CELLS))
    # rectangles: sides on cell boundaries (aligned, or on a grid rotated with the defect)
    richardson = settings.pop("richardson", True) and defect.shape == "rectangle"
    info = {"halfspace_delta_nodes": nodes_d, "halfspace_cells": cells}
    if misses:
        info["halfspace_ratio"] = np.ones((n_psi, nodes_d.size))
        return np.broadcast_to(delta ** 1.5, (n_psi, n_delta)).copy(), info
    coarse = (cells[0] // 2, cells[1] // 2)
    # a rectangle skewed to the track is solved on a grid turned with it
    curve = ratio_curve_skewed if defect.shape == "rectangle" and aligned_sides(defect) is None else ratio_curve
    ratios, forces, axes, solves = [], [], [], 0
    for dn in nodes_d:
        s_f, r_f, inf_f = curve(defect, geom, dn, cells=cells, e_star=e_star, **settings)
        r = np.interp(s_tab, s_f, r_f, left=1.0, right=1.0)
        solves += inf_f["solves"]
        if richardson:
            # first-order error in the cell size h: r = r_h + (r_h - r_2h) h / (h_2h - h)
            s_c, r_c, inf_c = curve(defect, geom, dn, cells=coarse, e_star=e_star, **settings)
            rc = np.interp(s_tab, s_c, r_c, left=1.0, right=1.0)
            h_f, h_c = math.sqrt(math.prod(inf_f["cell_m"])), math.sqrt(math.prod(inf_c["cell_m"]))
            r = r + (r - rc) * h_f / (h_c - h_f)
            solves += inf_c["solves"]
        ratios.append(np.clip(r, 0.0, 1.0))
        forces.append(inf_f["intact_force_n"])
        axes.append(inf_f["semi_axes_m"])
    r = np.column_stack(ratios)
    # G^(2/3) between the nodes by a monotone cubic (Fritsch-Carlson, :func:`pchip_rows`)
    # through (0, 0) and (drop, 0): exact for delta^1.5 scaling and for a rigid drop, and
    # the share curves' bends between nodes cost a quarter of what straight lines did
    g23 = (r ** (2 / 3)) * nodes_d[None, :]
    xd = np.concatenate([[0.0], nodes_d])
    # rows the ball's rigid drop does not touch share one set of nodes: one interpolant
    plain = drop <= 0
    G = np.zeros((n_psi, n_delta))
    if np.any(plain):
        yd = np.column_stack([np.zeros(int(plain.sum())), g23[plain]])
        G[plain] = np.maximum(pchip_rows(np.broadcast_to(xd, yd.shape), yd, delta), 0.0) ** 1.5
    # the other rows: knots 0, the drop and the nodes above it, grouped by how many nodes are above
    above = (xd[None, :] > drop[:, None]).sum(axis=1)
    for n in np.unique(above[~plain & (drop < delta[-1])]):
        rows = np.flatnonzero(~plain & (drop < delta[-1]) & (above == n))
        xj = np.column_stack([np.zeros(rows.size), drop[rows], np.broadcast_to(xd[xd.size - n:], (rows.size, n))])
        yj = np.column_stack([np.zeros((rows.size, 2)), g23[rows, g23.shape[1] - n:]])
        G[rows] = (np.maximum(pchip_rows(xj, yj, delta), 0.0) if n >= 1 else 0.0) ** 1.5
    far = np.all(r == 1.0, axis=1)
    G[far] = delta[None, :] ** 1.5
    info.update({"halfspace_ratio": r, "halfspace_intact_force_n": np.array(forces),
                 "halfspace_semi_axes_m": np.array(axes), "halfspace_richardson": richardson,
                 "halfspace_solves": solves})
    return G, info


def pchip_rows(x: np.ndarray, y: np.ndarray, xq: np.ndarray) -> np.ndarray:
    """Monotone piecewise-cubic interpolation (Fritsch & Carlson; the derivatives of scipy's
    ``PchipInterpolator``) of each row of ``y`` (K, n) over the strictly increasing knots in the
    same row of ``x`` (K, n), at the points ``xq`` (within every row's knots): (K, len(xq)).
    All rows at once, where one interpolant per row cost more than the rest of a table's assembly."""
    h = np.diff(x, axis=1)
    m = np.diff(y, axis=1) / h
    d = np.zeros_like(y)
    if y.shape[1] == 2:
        d[:] = m[:, :1]
    else:
        w1, w2 = 2 * h[:, 1:] + h[:, :-1], h[:, 1:] + 2 * h[:, :-1]
        flat = (np.sign(m[:, 1:]) != np.sign(m[:, :-1])) | (m[:, 1:] == 0) | (m[:, :-1] == 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            d[:, 1:-1] = np.where(flat, 0.0, 1.0 / ((w1 / m[:, :-1] + w2 / m[:, 1:]) / (w1 + w2)))
        for i, (h0, h1, m0, m1) in ((0, (h[:, 0], h[:, 1], m[:, 0], m[:, 1])),
                                    (-1, (h[:, -1], h[:, -2], m[:, -1], m[:, -2]))):
            e = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
            e = np.where(np.sign(e) != np.sign(m0), 0.0,
                         np.where((np.sign(m0) != np.sign(m1)) & (np.abs(e) > 3 * np.abs(m0)), 3 * m0, e))
            d[:, i] = e
    rows = np.arange(x.shape[0])[:, None]
    k = np.clip((x[:, None, :] <= xq[None, :, None]).sum(axis=2) - 1, 0, x.shape[1] - 2)
    t, hk, mk = xq[None, :] - x[rows, k], h[rows, k], m[rows, k]
    d0, d1 = d[rows, k], d[rows, k + 1]
    # scipy's coefficients and sum, operation for operation (so the tables are the same to the bit)
    c = (d0 + d1 - 2 * mk) / hk
    c2, c3 = (mk - d0) / hk - c, c / hk
    return ((y[rows, k] + d0 * t) + c2 * (t * t)) + c3 * ((t * t) * t)


# ---------------------------------------------------------------- the registry
@dataclass(frozen=True)
class ContactModel:
    """One defect-contact model: how its table's G is built and how the time loop reads it.

    ``g(c)`` returns G (n_psi x n_delta, m^1.5) from the build context ``c`` (keys ``defect``,
    ``geom``, ``psi``, ``R``, ``delta``, ``drop``, ``drop2``, ``lattice``, ``material``,
    ``misses``, ``info`` (add diagnostics here), ``halfspace_settings``).  ``tabulated``: the
    time loop interpolates the table's G; otherwise it applies ``max(delta - drop, 0)^1.5`` to
    the table's drop (and G must be that law).  ``along_track_drop``: the table's drop is the
    1-D along-track reduction, not the exact 2-D drop.  ``area_law``: the lattice evaluates the
    local (Winkler-type) law on the fine "area" cells.
    """

    name: str
    g: Callable[[dict], np.ndarray]
    tabulated: bool
    along_track_drop: bool = False
    area_law: bool = False
    summary: str = ""


def _g_halfspace(c):
    E, nu = c["material"]
    settings = dict(c["halfspace_settings"] or {})
    settings.setdefault("loaded_range", c["info"]["loaded_range_m"])
    G, info = _halfspace_G(c["defect"], c["geom"], c["psi"] * c["R"], c["delta"], c["drop2"],
                           e_star=E / (2 * (1 - nu * nu)), misses=c["misses"], settings=settings)
    c["info"].update(info)
    return G


def _g_rigid(c):
    return np.maximum(c["delta"][None, :] - c["drop"][:, None], 0.0) ** 1.5


#: name -> ContactModel, in the order they are listed to users.  Adding a model: one entry here
#: (its ``g``), a section in the module docstring, and its test in tests/sim/test_defect_contact.py;
#: scenes (``defect.contact_model``), ``contact_table`` and the time loop read this table.
CONTACT_MODELS: dict[str, ContactModel] = {m.name: m for m in [
    ContactModel("profile", _g_rigid, tabulated=False, along_track_drop=True,
                 summary="along-track 1-D drop, full-width slot"),
    ContactModel("drop", _g_rigid, tabulated=False, summary="rigid 2-D drop, intact stiffness"),
    ContactModel("area", lambda c: c["lattice"]["G"], tabulated=True, area_law=True,
                 summary="local (Winkler-type) law over the remaining surface"),
    ContactModel("halfspace", _g_halfspace, tabulated=True,
                 summary="elastic half-space share of the intact load (the default)"),
]}

