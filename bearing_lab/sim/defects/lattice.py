"""The ball-centred lattice of the contact tables: outline coverage of track cells, and the
windowed sums over them by FFT.

Why apart from :mod:`.contact`: the table's steps follow the data, arguments and approach range
(:mod:`.contact`), then the geometric shares on this lattice (the intact fraction of the Hertz
ellipse for every model, the local "area" law's G), then the model's own G.

A lattice on the track, cells ``ds x dz``; ``ds = psi step * R / m`` with integer ``m`` so the
ball-centred window slides by whole cells; each cell carries the fraction of it inside the
outline (4 x 4 sub-samples), so the sums are smooth in psi.  The sum over the window is a
correlation evaluated by FFT along the track.
"""
from __future__ import annotations

import math

import lazy_loader as lazy
import numpy as np

from .geometry import hertz_semi_axes
from .model import Defect

# the table's FFT products: loaded when a table is built
sfft = lazy.load("scipy.fft", suppress_warning=True)

_SUB = 4            # sub-samples per cell side for the outline coverage


def coverage(defect: Defect, s_cells: np.ndarray, z_cells: np.ndarray, ds: float, dz: float):
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


def correlate(f: np.ndarray, kern: np.ndarray, m: int, n_psi: int) -> np.ndarray:
    """out[j, d] = sum_{k, l} f[j m + k, l] kern[k, l, d], by FFT along the track.

    FFT rather than a loop of small matrix products: the products would go to a
    multithreaded BLAS, which on a shared machine spends more time waiting than working.
    """
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


def track_lattice(defect, geom, psi, R, delta, *, cells, area_law):
    """Ball-centred lattice over the track: the intact share of the Hertz ellipse, the
    interpenetration region's, and (``area_law``) the local law's G.  See the module
    docstring and :mod:`.contact`'s.

    Returns ``{"intact_fraction": (n_psi, n_delta), "G": (n_psi, n_delta) or None,
    "info": {...}}``."""
    n_psi, n_delta = psi.size, delta.size
    dpsi = psi[1] - psi[0]
    Rg = geom.track_radius
    b_reach, a_reach = geom.reach(delta[-1])
    b_w, a_w = 1.05 * b_reach, 1.05 * a_reach
    m = max(1, math.ceil(dpsi * R / (b_reach / cells[0])))
    ds = dpsi * R / m
    nb = math.ceil(b_w / ds)
    dz = a_reach / cells[1]
    nzh = math.ceil(a_w / dz)
    z = (np.arange(2 * nzh) - nzh + 0.5) * dz
    srel = np.arange(-nb, nb + 1) * ds
    h0 = geom.approach(srel[:, None] / Rg, z[None, :])
    n_glob = (n_psi - 1) * m + 2 * nb + 1
    s_glob = psi[0] * R + (np.arange(n_glob) - nb) * ds
    f = coverage(defect, s_glob, z, ds, dz)
    d = delta[None, None, :]
    a_h, b_h = hertz_semi_axes(geom, delta)
    with np.errstate(invalid="ignore", divide="ignore"):
        indh = ((srel[:, None, None] / b_h[None, None, :]) ** 2
                + (z[None, :, None] / a_h[None, None, :]) ** 2 < 1.0).astype(float)
    indh[:, :, delta <= 0] = 0.0
    areah = indh.sum(axis=(0, 1))
    kernels = [indh]
    if area_law:
        ind0 = (h0[:, :, None] < d).astype(float)              # (2nb+1, nz, n_delta)
        hf = geom.approach(srel[:, None] / Rg, z[None, :], depth=defect.depth)
        w0 = np.sqrt(np.maximum(d - h0[:, :, None], 0.0))
        wf = np.sqrt(np.maximum(d - hf[:, :, None], 0.0))
        I0 = w0.sum(axis=(0, 1))
        kernels += [ind0, w0 - wf]
    out = correlate(f, np.concatenate(kernels, axis=2), m, n_psi)
    with np.errstate(invalid="ignore", divide="ignore"):
        intact = np.where(areah > 0, 1.0 - out[:, :n_delta] / np.where(areah > 0, areah, 1.0), 1.0)
    res = {"intact_fraction": np.clip(intact, 0.0, 1.0), "G": None,
           "info": {"lattice_ds_m": ds, "lattice_dz_m": dz, "lattice_window": (2 * nb + 1, 2 * nzh),
                    "psi_substeps": m, "hertz_semi_axes_m": (a_h, b_h)}}
    if area_law:
        area0 = ind0.sum(axis=(0, 1))
        loss = out[:, 2 * n_delta:]
        with np.errstate(invalid="ignore", divide="ignore"):
            pen = np.where(area0 > 0, 1.0 - out[:, n_delta:2 * n_delta] / np.where(area0 > 0, area0, 1.0), 1.0)
            ratio = np.where(I0 > 0, (I0 - loss) / np.where(I0 > 0, I0, 1.0), 1.0)
        d15 = delta ** 1.5
        res["G"] = np.clip(ratio, 0.0, None) * d15[None, :]
        c = 3.0 / (4.0 * math.pi * math.sqrt(geom.rx * geom.ry))
        with np.errstate(invalid="ignore", divide="ignore"):
            law = np.where(d15 > 0, c * I0 * ds * dz / np.where(d15 > 0, d15, 1.0), np.nan)
        res["info"]["intact_law_ratio"] = law
        res["info"]["interpenetration_fraction"] = np.clip(pen, 0.0, 1.0)
    return res
