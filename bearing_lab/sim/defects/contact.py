"""Ball-race contact over a defect, tabulated once per defect: ``F = K_hertz * G(psi, delta)``.

Why a table: the contact geometry (sphere against a torus with an outline removed) is
exact but costs a 2-D integral; the time loop needs the force millions of times.  So the
geometry is reduced, once per defect and outside the loop, to a function of two numbers,
the ball's angular position over the defect and its approach, and the loop interpolates.

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
``"profile"``  along-track 1-D: the defect reduced to its intervals on the track centre
    line, each made a full-width slot; ``G = max(delta - h1(psi), 0)^1.5`` with ``h1`` the
    exact drop over the slot's edge lines (:func:`.geometry.drop_profile_1d`).  Exact for a
    full-width slot; blind to offset (a defect off the centre line vanishes) and to skew.
``"drop"``     rigid 2-D drop: ``G = max(delta - h2(psi), 0)^1.5`` with ``h2`` the exact 3-D
    drop (:func:`.geometry.drop_profile_2d`); the contact keeps its intact stiffness.
``"area"``     2-D loss of contact area.  A local (Winkler-type) law over the raceway
    surface, ``dF = K c sqrt(max(delta - h(s, z), 0)) dA`` with ``h`` the exact gap of
    :mod:`.geometry` to the remaining surface (intact groove outside the outline, the floor
    inside it).  On the intact paraboloid gap ``s^2/2R_x + z^2/2R_y`` the integral is
    ``(4 pi / 3) sqrt(R_x R_y) delta^1.5``, so ``c = 3 / (4 pi sqrt(R_x R_y))`` gives exactly
    ``K delta^1.5``.  With the exact torus gap the raw law falls below that by 0.12 %/µm
    (outer race; 0.18 %/µm inner): -1.0 % at 8 µm, -2.4 % at 20 µm, because the exact gap
    grows faster than Hertz's paraboloid (``+z^4/8 (1/r_b^3 - 1/r_g^3)`` across the track;
    the half-space solver sees the same effect at a third of the size); the lattice itself
    is exact to 0.5 % on the paraboloid (``info["intact_law_ratio"]``, tests).  The table
    divides the defected integral by the intact one computed on the same lattice, so
    ``G = delta^1.5`` exactly on intact surface (consistent with the simulator's K delta^1.5)
    and discretisation errors cancel to first order.  Edge contact (the ball riding on
    the length edges of a long defect: a flat section of G), the offset effect (part of the
    ellipse left on intact surface) and the gradual entry of a skewed edge all come out of
    ``h``; nothing is special-cased.

``"halfspace"`` the same exact gap, but the load from an elastic half-space solution
    (Boussinesq/Love influence, Polonsky-Keer conjugate gradient, :mod:`.halfspace`)
    computed on coarse nodes: approaches ``HALFSPACE_NODES * delta_max`` and ball positions
    every 2 cells (ball-centred grid of 64 x 48 cells over {h < delta}); the share of the
    intact force is interpolated linearly in psi, and ``G^(2/3)`` linearly in delta through
    (0, 0) and (drop, 0).  The elastic body carries on the intact flanks much of the load a
    local law removes: it is the reference for the other models, at 1-6 s per table
    (the area model: 0.02-0.3 s).  Grid accuracy: about 2-3 % on the carried share.

How far the local law is from the half-space (6308 outer race, centred 1 x 1 mm defect,
share of the intact force still carried; fine half-space grid 0.0125 x 0.004 mm):

=====================  =========  ==========  =========  ==========
ball at s (mm)         4.38 µm (300 N intact)  8 µm (738 N intact)
---------------------  ---------------------  ---------------------
                       local law  half-space  local law  half-space
=====================  =========  ==========  =========  ==========
0 (centred)            0.350      0.553       0.499      0.708
0.3                    0.404      0.618       0.589      0.794
0.5 (edge)             0.676      0.903       0.749      0.930
0.6                    0.823      0.986       0.833      0.977
0.7                    0.947      1.000       0.910      1.000
=====================  =========  ==========  =========  ==========

So the local law removes 1.45 x (300 N) and 1.7 x (8 µm) the load the half-space removes
with the ball centred, and feels the defect over a longer stretch of track (its footprint
is the interpenetration region, sqrt(2) wider than the Hertz ellipse).  At 8 µm and psi =
0 the carried share for O1 at H = 0, B/3, B/2 is 0.499, 0.530, 0.565 (area) and 0.705,
0.724, 0.747 (halfspace); the rigid drop model gives 0.829, 0.980, 1.000.

Discretisation of "area"
------------------------
A lattice on the track, cells ``ds x dz``; ``ds = psi step * R / m`` with integer ``m`` so
the ball-centred window slides by whole cells; each cell carries the fraction of it inside
the outline (4 x 4 sub-samples), so G is smooth in psi.  The sum over the window is a
correlation evaluated as ``2 n_b + 1`` small matrix products.

The ``intact_fraction`` is geometric and the same for every model: the share of the intact
Hertz contact ellipse at that approach (semi-axes from :func:`.geometry.hertz_semi_axes`,
0.90 x 0.16 mm at 300 N on the 6308 outer race) that lies outside the outline (1 at
delta = 0).  ``info["interpenetration_fraction"]`` is the same for the local law's
footprint ``{h_intact < delta}``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
import math
import time

import numpy as np

from bearing_lab.errors import SceneError

from .geometry import RaceGeometry, drop_profile_1d, drop_profile_2d, hertz_semi_axes
from .model import Defect

CONTACT_MODELS = ("profile", "drop", "area", "halfspace")
#: approach nodes of the "halfspace" model, as fractions of delta_max
HALFSPACE_NODES = (0.1, 0.2, 0.35, 0.5, 0.7, 1.0)
_SUB = 4            # sub-samples per cell side for the outline coverage
_CELLS_ALONG = 60   # lattice cells per along-track reach at delta_max
_CELLS_ACROSS = 60  # lattice cells per across-track reach at delta_max
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
        range; above ``delta_max`` G is continued as ``G(delta_max) + 1.5 sqrt(delta_max) *
        (delta - delta_max)`` (the table should be built with a delta_max above any
        approach the simulation reaches)."""
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
            above = dl > self.delta[-1]
            if np.any(above):
                g = g + np.where(above, 1.5 * math.sqrt(self.delta[-1]) * (dl - self.delta[-1]), 0.0)
            out[inside] = g
        return out.reshape(shape)

    def to_dataset(self):
        """The table as an xarray Dataset (SI, ``units`` attributes), e.g. for netCDF."""
        import xarray as xr
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
        import matplotlib.pyplot as plt
        scale = {"mm": 1e3, "m": 1.0, "um": 1e6}[s_units]
        if ax is None:
            fig, ax = plt.subplots(figsize=(6, 3.5))
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


def _coverage(defect: Defect, s_cells: np.ndarray, z_cells: np.ndarray, ds: float, dz: float):
    """Fraction of each cell (len(s_cells) x len(z_cells)) inside the outline."""
    f = np.zeros((s_cells.size, z_cells.size))
    s0, s1, z0, z1 = defect.track_extent()
    ks = np.flatnonzero((s_cells + ds / 2 >= s0) & (s_cells - ds / 2 <= s1))
    ls = np.flatnonzero((z_cells + dz / 2 >= z0) & (z_cells - dz / 2 <= z1))
    if ks.size == 0 or ls.size == 0:
        return f
    off = (np.arange(_SUB) + 0.5) / _SUB - 0.5
    S = (s_cells[ks][:, None] + off[None, :] * ds).ravel()
    Z = (z_cells[ls][:, None] + off[None, :] * dz).ravel()
    inside = defect.contains(S[:, None], Z[None, :])
    cov = inside.reshape(ks.size, _SUB, ls.size, _SUB).mean(axis=(1, 3))
    f[np.ix_(ks, ls)] = cov
    return f


_CACHE: dict = {}
_CACHE_SIZE = 64


def _correlate(f: np.ndarray, kern: np.ndarray, m: int, n_psi: int) -> np.ndarray:
    """out[j, d] = sum_{k, l} f[j m + k, l] kern[k, l, d], by FFT along the track.

    FFT rather than a loop of small matrix products: the products would go to a
    multithreaded BLAS, which on a shared machine spends more time waiting than working.
    """
    from scipy import fft as sfft
    n_glob = f.shape[0]
    cols = np.flatnonzero(f.any(axis=0))          # only the axial cells the outline covers
    n_fft = sfft.next_fast_len(n_glob, real=True)
    Ff = sfft.rfft(f[:, cols], n=n_fft, axis=0)
    Fk = sfft.rfft(kern[:, cols, :], n=n_fft, axis=0)
    # sum_l Ff conj(Fk) = conj(sum_l conj(Ff) Fk): conjugate the small array only
    C = np.einsum("wl,wld->wd", Ff.conj(), Fk).conj()
    c = sfft.irfft(C, n=n_fft, axis=0)
    out = c[0:(n_psi - 1) * m + 1:m]
    # round-off: exact zeros where the window never meets the outline
    touched = np.zeros(n_psi, dtype=bool)
    rows_any = np.flatnonzero(f.any(axis=1))
    if rows_any.size:
        nk = kern.shape[0]
        j = np.arange(n_psi) * m
        touched = (j + nk - 1 >= rows_any[0]) & (j <= rows_any[-1])
    out[~touched] = 0.0
    return out


def contact_table(defect: Defect, bearing, *, model: str, clearance: float = 0.0,
                  delta_max: float, n_psi: int | None = None, n_delta: int = 41,
                  against: str | None = None) -> ContactTable:
    """Tabulate the contact of a ball with the defected race (see the module docstring).

    Tables are cached in-process by their arguments (a defect's ``angle`` does not enter
    the table, so the same outline at several positions or speeds is built once); the
    returned arrays are read-only.

    Parameters
    ----------
    defect : Defect on the "outer" or "inner" race.
    bearing : BearingGeometry.
    model : "profile", "drop", "area" or "halfspace".
    clearance : diametral clearance, m (moves the groove bottoms by clearance/4).
    delta_max : largest approach to tabulate, m (e.g. 2-3 x the static deflection of the
        most loaded ball; 20e-6 for the 6308 at 480 N).
    n_psi : psi grid size; default: about 40 points per along-track contact reach.
    n_delta : delta grid size (default 41).
    against : for a ball defect only, the race it strikes, "outer" or "inner" (build one
        table per race).  psi is then measured on the ball: the contact point's angle on the
        ball relative to the defect centre (arc ``ball_radius * psi``), and the outline is
        laid on the contact plane to first order (ball arc = race arc); the floor gap is the
        race's (intact gap + depth to first order).
    """
    key = (_defect_key(defect), bearing, model, float(clearance), float(delta_max), n_psi, n_delta,
           against)
    try:
        hit = _CACHE.get(key)
    except TypeError:       # unhashable bearing: no cache
        key, hit = None, None
    if hit is not None:
        return hit
    table = _build(defect, bearing, model=model, clearance=clearance, delta_max=delta_max,
                   n_psi=n_psi, n_delta=n_delta, against=against)
    for name in ("psi", "delta", "G", "drop", "intact_fraction"):
        getattr(table, name).flags.writeable = False
    if key is not None:
        if len(_CACHE) >= _CACHE_SIZE:
            _CACHE.pop(next(iter(_CACHE)))
        _CACHE[key] = table
    return table


def _defect_key(defect: Defect):
    from dataclasses import replace
    return replace(defect, angle=0.0)


def _build(defect, bearing, *, model, clearance, delta_max, n_psi, n_delta,
           against=None) -> ContactTable:
    t0 = time.perf_counter()
    c0 = time.process_time()
    if model not in CONTACT_MODELS:
        raise SceneError(f"Invalid value for the 'model' parameter. Allowed values are "
                         f"{', '.join(map(repr, CONTACT_MODELS))}, but got {model!r} instead.")
    if not (math.isfinite(delta_max) and delta_max > 0):
        raise SceneError(f"{delta_max=} m must be positive and finite")
    if n_delta < 3:
        raise SceneError(f"{n_delta=} must be at least 3")
    if n_psi is not None and n_psi < 8:
        raise SceneError(f"{n_psi=} must be at least 8")
    if defect.race == "ball":
        if against not in ("outer", "inner"):
            raise SceneError(f"a ball defect needs against='outer' or 'inner' (the race it "
                             f"strikes), got {against!r}")
        geom = RaceGeometry.from_bearing(bearing, against, clearance=clearance)
        R = geom.ball_radius          # psi is measured on the ball
    else:
        if against not in (None, defect.race):
            raise SceneError(f"against={against!r} is only for ball defects "
                             f"(this defect is on the {defect.race} race)")
        geom = RaceGeometry.from_bearing(bearing, defect.race, clearance=clearance)
        R = geom.track_radius
    Rg = geom.track_radius
    b_reach, a_reach = geom.reach(delta_max)
    if a_reach >= 0.9 * geom.z_limit:
        raise SceneError(f"{delta_max=} m: the contact would reach the groove's edge; "
                         "give a smaller delta_max")
    b_w, a_w = 1.05 * b_reach, 1.05 * a_reach
    ext = _interacting_s_extent(defect, a_w)
    misses = ext is None
    if misses:
        s0, s1, _, _ = defect.track_extent()
        ext = (s0, s1)
    margin = 0.1 * b_reach
    s_lo, s_hi = ext[0] - b_w - margin, ext[1] + b_w + margin
    if n_psi is None:
        n_psi = int(min(max(math.ceil((s_hi - s_lo) / (b_reach / _PSI_PER_REACH)) + 1, 64), 8001))
    psi = np.linspace(s_lo / R, s_hi / R, n_psi)
    dpsi = psi[1] - psi[0]
    delta = np.linspace(0.0, delta_max, n_delta)

    # ---- geometric drops (exact, no lattice)
    drop2 = drop_profile_2d(defect, geom, psi, psi_radius=R)
    if model == "profile":
        drop = drop_profile_1d(defect, geom, psi, psi_radius=R)
    else:
        drop = drop2

    # ---- lattice: coverage and the intact/floor gap over the ball-centred window
    m = max(1, math.ceil(dpsi * R / (b_reach / _CELLS_ALONG)))
    ds = dpsi * R / m
    nb = math.ceil(b_w / ds)
    dz = a_reach / _CELLS_ACROSS
    nzh = math.ceil(a_w / dz)
    z = (np.arange(2 * nzh) - nzh + 0.5) * dz
    srel = np.arange(-nb, nb + 1) * ds
    h0 = geom.approach(srel[:, None] / Rg, z[None, :])
    hf = geom.approach(srel[:, None] / Rg, z[None, :], depth=defect.depth)
    n_glob = (n_psi - 1) * m + 2 * nb + 1
    s_glob = psi[0] * R + (np.arange(n_glob) - nb) * ds
    f = _coverage(defect, s_glob, z, ds, dz)

    d = delta[None, None, :]
    ind0 = (h0[:, :, None] < d).astype(float)              # (2nb+1, nz, n_delta)
    area0 = ind0.sum(axis=(0, 1))
    a_h, b_h = hertz_semi_axes(geom, delta)
    with np.errstate(invalid="ignore", divide="ignore"):
        indh = ((srel[:, None, None] / b_h[None, None, :]) ** 2
                + (z[None, :, None] / a_h[None, None, :]) ** 2 < 1.0).astype(float)
    indh[:, :, delta <= 0] = 0.0
    areah = indh.sum(axis=(0, 1))
    need_area = model == "area"
    if need_area:
        w0 = np.sqrt(np.maximum(d - h0[:, :, None], 0.0))
        wf = np.sqrt(np.maximum(d - hf[:, :, None], 0.0))
        I0 = w0.sum(axis=(0, 1))
        D = w0 - wf
    kernels = [ind0, indh] + ([D] if need_area else [])
    out = _correlate(f, np.concatenate(kernels, axis=2), m, n_psi)
    frac_loss, hertz_loss = out[:, :n_delta], out[:, n_delta:2 * n_delta]
    if need_area:
        loss = out[:, 2 * n_delta:]
    with np.errstate(invalid="ignore", divide="ignore"):
        pen_fraction = np.where(area0 > 0, 1.0 - frac_loss / np.where(area0 > 0, area0, 1.0), 1.0)
        intact_fraction = np.where(areah > 0, 1.0 - hertz_loss / np.where(areah > 0, areah, 1.0), 1.0)
    pen_fraction = np.clip(pen_fraction, 0.0, 1.0)
    intact_fraction = np.clip(intact_fraction, 0.0, 1.0)

    d15 = delta ** 1.5
    if model == "halfspace":
        from .halfspace import halfspace_ratio_nodes
        nodes_d = np.array(HALFSPACE_NODES) * delta_max
        nodes = halfspace_ratio_nodes(defect, geom, nodes_d)
        s_tab = psi * R
        # ratio on the table's psi, then G^(2/3) linear in delta between the nodes, through
        # (0, 0) and (drop, 0): exact for both delta^1.5 scaling and a rigid drop
        r = np.column_stack([np.interp(s_tab, sn, rn, left=1.0, right=1.0) for sn, rn in nodes])
        g23 = (np.clip(r, 0, None) ** (2 / 3)) * nodes_d[None, :]
        G = np.empty((n_psi, n_delta))
        for j in range(n_psi):
            xd = np.concatenate([[0.0], nodes_d])
            yd = np.concatenate([[0.0], g23[j]])
            if 0 < drop2[j] < delta_max:
                keep = xd > drop2[j]
                xd = np.concatenate([[0.0, drop2[j]], xd[keep]])
                yd = np.concatenate([[0.0, 0.0], yd[keep]])
            elif drop2[j] >= delta_max:
                xd, yd = np.array([0.0, delta_max]), np.array([0.0, 0.0])
            G[j] = np.interp(delta, xd, yd) ** 1.5
        far = np.all(r == 1.0, axis=1)
        G[far] = d15[None, :]
        law = None
        info_hs = {"halfspace_delta_nodes": nodes_d, "halfspace_ratio": r}
    elif model == "area":
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = np.where(I0 > 0, (I0 - loss) / np.where(I0 > 0, I0, 1.0), 1.0)
        G = np.clip(ratio, 0.0, None) * d15[None, :]
        c = 3.0 / (4.0 * math.pi * math.sqrt(geom.rx * geom.ry))
        with np.errstate(invalid="ignore", divide="ignore"):
            law = np.where(d15 > 0, c * I0 * ds * dz / np.where(d15 > 0, d15, 1.0), np.nan)
    else:
        G = np.maximum(delta[None, :] - drop[:, None], 0.0) ** 1.5
        law = None
    G[:, 0] = 0.0
    info = {
        "build_time_s": time.perf_counter() - t0, "build_cpu_s": time.process_time() - c0,
        "lattice_ds_m": ds, "lattice_dz_m": dz, "lattice_window": (2 * nb + 1, 2 * nzh),
        "psi_substeps": m, "reach_along_m": b_reach, "reach_across_m": a_reach,
        "misses_track": misses, "drop_2d": drop2, "interpenetration_fraction": pen_fraction,
        "hertz_semi_axes_m": (a_h, b_h),
    }
    if law is not None:
        info["intact_law_ratio"] = law
    if model == "halfspace":
        info.update(info_hs)
    race = defect.race if defect.race != "ball" else f"ball/{against}"
    return ContactTable(psi=psi, delta=delta, G=G, drop=drop, intact_fraction=intact_fraction,
                        model=model, race=race, psi_min=float(psi[0]),
                        psi_max=float(psi[-1]), track_radius=R, info=info)
