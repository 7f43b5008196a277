"""Fault-family evidence in one cyclic spectrum, and the verdict of one route.

Why a pattern, not a line: a bearing fault does not show as one line but as a
*family*: harmonics ``k F`` of the fault frequency and, for a fault that moves
through the load zone, sidebands ``k F +- m f_mod`` at the modulating rate
(Randall & Antoni 2011, section 2): the shaft frequency ``f_r`` for an
inner-race fault, the cage frequency FTF for a ball fault; outer-race families
on real rigs often carry ``f_r`` sidebands too (shaft-synchronous load).  Real
squared envelope spectra can be dense (CWRU drive-end records show a line every
2-3 Hz): any window then holds *some* line, so a family is judged as a whole,
against the same search run at frequencies where no bearing fault can be, and
against the competing families.

One family (:func:`family_evidence`):

- the carrier ``F`` is chosen inside the slip window ``expected (1 +- tol)`` by
  the summed line SNR of its first ``n_harmonics`` harmonics (SNR over a running
  median; only local maxima of at least ``HARMONIC_SNR_DB`` count, each capped at
  ``LINE_CAP_DB``); its value is the fundamental line's, interpolated by a
  parabola through the log amplitudes;
- harmonic ``k`` is searched within +-max(2, k/2 + 1) bins of ``k F``: a carrier
  measured to a quarter bin puts its k-th harmonic within k/4 bins, so the window
  grows with ``k`` but stays a few bins wide;
- sidebands ``k F +- m f_mod`` (m = 1, 2) of the family's modulator count as
  evidence (``evidence_score``: capped SNR summed over carrier and sideband lines);
- *detected* when the noise rule passes (the fundamental group, i.e. the carrier
  or one of its first sidebands, holds a line of at least ``FUNDAMENTAL_SNR_DB``;
  at least two carrier harmonics and ``MIN_HARMONICS`` harmonic groups are
  present; the thresholds come from Gaussian-noise statistics, see ``_faults``)
  **and** its evidence exceeds that of every *decoy*, and their mean by
  ``DECOY_SIGMAS`` (2) standard deviations: the same search, with the
  same modulator, run at carriers ``rho f_r`` whose slip windows stay clear of
  those of every kinematic ratio of the bearing, its first and second shaft
  sidebands, halves and doubles (``rho`` at least ``2 tol + 1 %`` from them), and
  of integers.  The decoys measure how much "evidence" this very spectrum hands
  to any frequency.  On spectra holding a strong line every 2 Hz at random, the
  maximum alone lets a chance family of BPFO, BPFI or 2 BSF through for one record
  in four, the maximum and the 2-sigma margin for one in thirty.  No route names a
  fault alone (see ``_diagnosis``), so this per-route rate is not the verdict's.

One route (:func:`route_verdict`): the detected family that explains the most
line energy leads.  Every other detected family is re-judged on its
*exclusive* lines, those more than two bins from the leader's pattern (its
harmonics up to twice the order searched, with shaft and cage sidebands up to
the third order).  A family still detected on its own lines (noise rule and
decoys) is a rival: the route says ``"uncertain"`` and names both.  This matters
on the 6203 (CWRU fan end), where 2 BSF = 3.988 f_r lies 1 % from BPFI - f_r
and 1.6 % from BPFO + f_r, inside the slip window: inner- and outer-race
families always bring a "2 BSF family" with them.  A ball family needs cage
modulation (an FTF sideband or an FTF line family) to be named, since ball
faults are modulated at the cage rate (Smith & Randall 2015); a cage (FTF)
family alone makes the route ``"uncertain"`` with the candidate ``ball``.
"""
from __future__ import annotations

import numpy as np
from scipy.ndimage import maximum_filter1d

from ..errors import AnalysisError
from ._fault_rule import FUNDAMENTAL_SNR_DB, HARMONIC_SNR_DB, MIN_HARMONICS, shaft_mask
from ._speed import line_floor_db

__all__ = ["CyclicSpectrum", "family_evidence", "route_verdict", "search_families", "decoy_ratios",
           "FAMILY_KEYS", "LABELS", "LINE_CAP_DB", "SK_MIN"]

FAMILY_KEYS = ("bpfo", "bpfi", "bsf", "ftf")
LABELS = {"bpfo": "outer_race", "bpfi": "inner_race", "bsf": "ball"}
#: Line SNRs are capped here when summed, so that one huge line cannot carry a family.
LINE_CAP_DB = 60.0
#: Sideband orders counted as evidence (k F +- m f_mod, m = 1..SIDEBAND_ORDERS).
SIDEBAND_ORDERS = 2
#: Orders of the leader's pattern that explain away other families' lines.
EXPLAIN_HARMONIC_FACTOR = 2
EXPLAIN_SIDEBAND_ORDERS = 3
#: Decoy slip windows stay this far (relative) beyond the slip windows of every kinematic
#: ratio and its relatives: decoy ratios keep 2 * tolerance + DECOY_MARGIN away from them.
DECOY_MARGIN = 0.01
#: A family must beat every decoy and their mean by this many standard deviations.
DECOY_SIGMAS = 2.0
#: A band is impulsive when its spectral kurtosis reaches this: for an envelope that is
#: on (constant) a fraction q of the time and off otherwise, SK = 1/q - 2, so SK >= 1 means
#: the band's energy comes in bursts filling at most a third of the time.  Gaussian noise
#: gives 0.04-0.15 for the best band of a kurtogram (records of 1-10 s).
SK_MIN = 1.0


class CyclicSpectrum:
    """A one-sided cyclic spectrum (SES or EES) with its line SNR, shared by the searches.

    Parameters
    ----------
    f : ndarray
        Uniform cyclic-frequency axis from 0, Hz.
    spec : ndarray
        Spectrum amplitudes (any unit).
    floor_width_hz : float
        Width of the running-median floor, Hz.

    Notes
    -----
    :meth:`masked` returns a view whose counted peaks exclude the harmonics of
    a shaft frequency (within +-max(1.5 bins, 0.1 %)): shaft lines are not
    bearing-fault evidence.
    """

    def __init__(self, f, spec, *, floor_width_hz=10.0, _base=None):
        if _base is not None:
            self.__dict__.update(_base.__dict__)
            return
        f = np.asarray(f, float)
        spec = np.asarray(spec, float)
        if spec.ndim != 1 or f.shape != spec.shape or f.size < 16:
            msg = (f"cyclic spectrum: f and spec must be 1-D of the same length >= 16, got {f.shape} "
                   f"and {spec.shape}")
            raise AnalysisError(msg)
        self.f, self.spec = f, spec
        self.df = float(f[1] - f[0])
        self.snr = line_floor_db(spec, width=max(21, int(round(floor_width_hz / self.df))))
        s = self.snr
        local = np.zeros(f.size, bool)
        local[1:-1] = (s[1:-1] >= s[:-2]) & (s[1:-1] >= s[2:])
        local[0] = False
        self._peaks = np.where(local & (s >= HARMONIC_SNR_DB), s, 0.0)
        self.peak_snr = self._peaks
        self.shaft_hz = None

    def masked(self, shaft_hz, cage_hz=None, skip_every=None):
        """A view of this spectrum with the harmonics of ``shaft_hz`` removed from the peaks.

        ``cage_hz``: also remove the cage comb ``n FTF`` (within +-max(1 bin, 0.05 %)),
        except every ``skip_every``-th harmonic (BPFO = Z FTF lies on the comb).
        """
        out = CyclicSpectrum(None, None, _base=self)
        out.shaft_hz = shaft_hz
        mask = shaft_mask(self.f, shaft_hz, self.df)
        if cage_hz:
            n = np.rint(self.f / cage_hz)
            near = (n >= 1) & (np.abs(self.f - n * cage_hz) <= np.maximum(self.df, 5e-4 * self.f))
            if skip_every:
                near &= (n % skip_every) != 0
            mask = mask | near
        out.peak_snr = np.where(mask, 0.0, self._peaks)
        return out

    def best(self, centres_hz, half_bins):
        """Index and SNR of the strongest counted peak within +-half_bins of each centre.

        Returns arrays (index or -1, snr or 0) shaped like ``centres_hz``.
        """
        c = np.asarray(centres_hz, float)
        h = np.broadcast_to(np.asarray(half_bins, int), c.shape)
        hmax = int(h.max()) if h.size else 0
        k0 = np.rint(c / self.df).astype(int)
        offs = np.arange(-hmax, hmax + 1)
        idx = k0[..., None] + offs
        ok = (np.abs(offs) <= h[..., None]) & (idx >= 1) & (idx < self.f.size - 1)
        vals = np.where(ok, self.peak_snr[np.clip(idx, 0, self.f.size - 1)], 0.0)
        j = np.argmax(vals, axis=-1)
        best = np.take_along_axis(vals, j[..., None], -1)[..., 0]
        where = np.take_along_axis(idx, j[..., None], -1)[..., 0]
        return np.where(best > 0, where, -1), best

    def window_max(self, half_bins):
        """The largest counted peak SNR within +-half_bins of every bin (0 beyond the ends): what
        :meth:`best` returns as SNR for a centre on that bin, for many centres at once."""
        of, cache = self.__dict__.get("_window_max", (None, None))
        if of is not self.peak_snr:  # a masked view starts from its base's attributes: its own peaks
            cache = {}
            self._window_max = (self.peak_snr, cache)
        h = int(half_bins)
        if h not in cache:
            cache[h] = maximum_filter1d(self.peak_snr, size=2 * h + 1, mode="constant", cval=0.0)
        return cache[h]


def _half_bins(k):
    return np.maximum(2, np.ceil(np.asarray(k) / 2.0).astype(int) + 1)


def _parabolic_offset(spec, idx):
    """Sub-bin offsets of peaks at bins idx (parabola through log amplitudes), 0 where idx < 1."""
    i = np.clip(idx, 1, spec.size - 2)
    a, b, c = (np.log(np.maximum(spec[i + d], 1e-300)) for d in (-1, 0, 1))
    den = a - 2 * b + c
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(den < 0, 0.5 * (a - c) / np.where(den < 0, den, -1.0), 0.0)
    return np.where(idx >= 1, np.clip(d, -0.5, 0.5), 0.0)


def _batch(cs, expected, modulator, tolerance, n_harmonics):
    """Vectorised family search for M carriers at once (the statistic of family_evidence).

    Returns a dict of arrays: ``f1`` (M,), ``cidx``/``csnr`` (M, K) carrier lines,
    ``sidx``/``ssnr`` (M, 2*SIDEBAND_ORDERS, K) sideband lines (order -2, -1, 1, 2),
    ``evidence`` (M,), ``groups``, ``harmonics``, ``fundamental`` (M,).
    """
    expected = np.atleast_1d(np.asarray(expected, float))
    M, K = expected.size, int(n_harmonics)
    k = np.arange(1, K + 1)
    hb = _half_bins(k)
    lo = np.maximum(1, np.floor(expected * (1 - tolerance) / cs.df)).astype(int)
    hi = np.ceil(expected * (1 + tolerance) / cs.df).astype(int)
    if np.any(hi * K + hb[-1] >= cs.f.size - 1):
        msg = (f"the cyclic spectrum reaches {cs.f[-1]:g} Hz, below harmonic {K} of the slip window "
               f"around {float(expected.max()):g} Hz (+-{100 * tolerance:g} %)")
        raise AnalysisError(msg)
    width = int((hi - lo).max()) + 1
    cand_bins = lo[:, None] + np.arange(width)[None, :]
    valid = cand_bins <= hi[:, None]
    cand = cand_bins * cs.df
    # each carrier's harmonics: the largest peak within +-hb bins (cs.best's SNR, read from the
    # running maxima; the windows of valid carriers lie inside the spectrum, checked above)
    pos = np.clip(np.rint(cand[..., None] * k / cs.df).astype(int), 0, cs.f.size - 1)  # (invalid ones: 0 below)
    snr = np.stack([cs.window_max(hb[q])[pos[..., q]] for q in range(K)], axis=-1)
    fund = cs.peak_snr[np.clip(cand_bins, 0, cs.f.size - 1)]
    score = np.minimum(snr, LINE_CAP_DB).sum(axis=-1) * (fund > 0) * valid
    i = np.argmax(score, axis=1)
    # middle of the plateau holding the maximum: it ends before the first lower score after i
    top = score[np.arange(M), i]
    drop = (np.arange(width) > i[:, None]) & (score < top[:, None])
    j = np.where(drop.any(axis=1), np.argmax(drop, axis=1) - 1, width - 1)
    f1 = 0.5 * (cand[np.arange(M), i] + cand[np.arange(M), j])
    has = top > 0
    # the carrier is its fundamental line, interpolated (parabola through log amplitudes)
    i1, _ = cs.best(f1, 1)
    f1 = np.where(has & (i1 >= 0), (i1 + _parabolic_offset(cs.spec, i1)) * cs.df, f1)
    cidx, csnr = cs.best(f1[:, None] * k, hb)
    cidx, csnr = np.where(has[:, None], cidx, -1), np.where(has[:, None], csnr, 0.0)
    orders = np.array([m for m in range(-SIDEBAND_ORDERS, SIDEBAND_ORDERS + 1) if m])
    sidx = np.full((M, orders.size, K), -1)
    ssnr = np.zeros((M, orders.size, K))
    if modulator is not None:
        mod = np.broadcast_to(np.asarray(modulator, float), (M,))
        centres = f1[:, None, None] * k + orders[None, :, None] * mod[:, None, None]
        sidx, ssnr = cs.best(centres, np.broadcast_to(hb, centres.shape))
        ok = has[:, None, None] & (centres > 0)
        sidx, ssnr = np.where(ok, sidx, -1), np.where(ok, ssnr, 0.0)
    # a line matched twice (a sideband landing on a carrier) counts once
    dup = (sidx[..., None] == cidx[:, None, None, :]) & (sidx[..., None] >= 0)
    ssnr_u = np.where(dup.any(axis=-1), 0.0, ssnr)
    evidence = np.minimum(csnr, LINE_CAP_DB).sum(axis=1) + np.minimum(ssnr_u, LINE_CAP_DB).sum(axis=(1, 2))
    groups = ((cidx >= 0) | (sidx >= 0).any(axis=1)).sum(axis=1)
    first = np.abs(orders) == 1
    fundamental = np.maximum(csnr[:, 0], ssnr[:, first, 0].max(axis=1))
    return {"f1": f1, "has": has, "cidx": cidx, "csnr": csnr, "sidx": sidx, "ssnr": ssnr_u,
            "orders": orders, "evidence": evidence, "groups": groups,
            "harmonics": (cidx >= 0).sum(axis=1), "fundamental": fundamental}


def _noise_rule(b):
    return (b["fundamental"] >= FUNDAMENTAL_SNR_DB) & (b["harmonics"] >= 2) & (b["groups"] >= MIN_HARMONICS)


def decoy_ratios(factors, *, tolerance=0.02, span=(1.5, None), step=0.02):
    """Carrier ratios (carrier / f_r) where no fault of this bearing can show.

    Parameters
    ----------
    factors : dict
        ``BearingGeometry.frequency_factors()`` (per unit shaft frequency).
    tolerance : float
        Slip tolerance of the searches: a decoy's window never overlaps a family's.
    span : (float, float or None)
        Ratio range; the upper end defaults to 1.3 times the largest of BPFO,
        BPFI and 2 BSF.
    step : float
        Logarithmic step (0.02: 2 %).

    Returns
    -------
    ndarray
        Ratios at least ``2 tolerance + DECOY_MARGIN`` (5 %) from every family
        ratio ``r`` (BPFO, BPFI, 2 BSF), from ``r +- 1``, ``r +- 2``, ``r / 2``,
        ``2 r``, and at least 0.05 from an integer.
    """
    fam = [factors["bpfo"], factors["bpfi"], 2 * factors["bsf"]]
    hi = span[1] if span[1] is not None else 1.3 * max(fam)
    rho = np.exp(np.arange(np.log(span[0]), np.log(hi), step))
    near = [r + m for r in fam for m in (-2, -1, 0, 1, 2)] + [r / 2 for r in fam] + [2 * r for r in fam]
    ok = np.abs(rho - np.round(rho)) > 0.05
    for b in near:
        ok &= np.abs(rho / b - 1) > 2 * tolerance + DECOY_MARGIN
    return rho[ok]


def family_evidence(cs, expected_hz, *, modulator_hz=None, tolerance=0.02, n_harmonics=5, decoy_hz=None):
    """Evidence for one fault family in a cyclic spectrum.

    Parameters
    ----------
    cs : CyclicSpectrum
        The spectrum (use ``cs.masked(shaft_hz)`` to keep shaft harmonics out).
    expected_hz : float
        Kinematic frequency of the family's carrier (2 BSF for a ball fault), Hz.
    modulator_hz : float, optional
        Sideband spacing expected for this fault (f_r inner race, FTF ball).
    tolerance : float
        Relative half-width of the slip window for the carrier.
    n_harmonics : int
        Harmonic groups examined.
    decoy_hz : array_like, optional
        Decoy carriers (Hz) searched the same way; without them the decoy test is
        skipped (``decoy_max_score`` None).

    Returns
    -------
    dict
        ``expected_hz``, ``measured_hz`` (None without a carrier line), ``snr_db``
        (fundamental carrier line, else the best line in the slip window),
        ``harmonics`` (carrier lines found), ``groups`` (harmonic groups with a
        carrier or sideband line), ``sidebands`` (sideband lines found),
        ``modulator_hz``, ``evidence_score``, ``decoy_max_score``, ``decoy_threshold_score``,
        ``passes_noise_rule``, ``detected``, ``lines`` (list of ``(frequency Hz, snr
        dB, k, m)``).
    """
    if not (np.isfinite(expected_hz) and expected_hz > 0):
        raise AnalysisError(f"family search: expected_hz={expected_hz!r} must be a positive frequency")
    b = _batch(cs, [expected_hz], modulator_hz, tolerance, n_harmonics)
    out = {"expected_hz": float(expected_hz), "measured_hz": None, "snr_db": 0.0, "harmonics": 0,
           "groups": 0, "sidebands": 0, "modulator_hz": None if modulator_hz is None else float(modulator_hz),
           "evidence_score": 0.0, "decoy_max_score": None, "passes_noise_rule": False, "detected": False,
           "lines": []}
    if not b["has"][0]:
        w = (cs.f >= expected_hz * (1 - tolerance)) & (cs.f <= expected_hz * (1 + tolerance))
        out["snr_db"] = float(max(0.0, cs.snr[w].max())) if w.any() else 0.0
        return out
    lines = []
    for kk in range(n_harmonics):
        i = b["cidx"][0, kk]
        if i >= 0:
            lines.append((float(cs.f[i]), float(b["csnr"][0, kk]), kk + 1, 0))
    for o, m in enumerate(b["orders"]):
        for kk in range(n_harmonics):
            i = b["sidx"][0, o, kk]
            if i >= 0 and b["ssnr"][0, o, kk] > 0:
                lines.append((float(cs.f[i]), float(b["ssnr"][0, o, kk]), kk + 1, int(m)))
    out.update(measured_hz=float(b["f1"][0]), snr_db=float(b["csnr"][0, 0]),
               harmonics=int(b["harmonics"][0]), groups=int(b["groups"][0]),
               sidebands=int(sum(1 for ln in lines if ln[3] != 0)), evidence_score=float(b["evidence"][0]),
               passes_noise_rule=bool(_noise_rule(b)[0]), lines=sorted(lines))
    out["detected"] = out["passes_noise_rule"]
    if decoy_hz is not None and len(decoy_hz):
        d = _batch(cs, decoy_hz, modulator_hz, tolerance, n_harmonics)["evidence"]
        out["decoy_max_score"] = float(d.max())
        out["decoy_threshold_score"] = float(max(d.max(), d.mean() + DECOY_SIGMAS * d.std()))
        out["detected"] = bool(out["passes_noise_rule"] and out["evidence_score"] > out["decoy_threshold_score"])
    return out


def search_families(cs, fault_hz, *, shaft_hz, tolerance=0.02, n_harmonics=5, decoys=True):
    """Search BPFO, BPFI, 2 BSF and FTF families in one spectrum (shaft harmonics masked).

    Parameters
    ----------
    cs : CyclicSpectrum
        Unmasked spectrum.
    fault_hz : dict
        Kinematic frequencies (``bpfo``, ``bpfi``, ``bsf``, ``ftf``), Hz.
    shaft_hz : float
        Shaft frequency (mask, shaft sidebands, decoy scale).
    tolerance, n_harmonics
        As in :func:`family_evidence`.
    decoys : bool
        Run the decoy test (BPFO, BPFI, 2 BSF).

    Returns
    -------
    dict
        :func:`family_evidence` per key (``bsf`` searched at 2 BSF).  When the
        cage (FTF) family is detected, its comb is masked for the other families
        and their decoys (all but every Z-th line, where BPFO = Z FTF lies), the
        ball family's sidebands are searched at the measured cage rate, a BPFO
        family counts only where its lines stand above the comb's neighbouring
        lines, and a 2 BSF carrier lying on a cage harmonic (within max(2, n/10)
        bins of n FTF) is the comb's (both then get ``explained_by`` "ftf").
    """
    cm = cs.masked(shaft_hz)
    if decoys and not shaft_hz:
        raise AnalysisError("family search: decoys need the shaft frequency (shaft_hz)")
    rho = (decoy_ratios({k: v / shaft_hz for k, v in fault_hz.items()}, tolerance=tolerance) if decoys
           else np.array([]))
    top = (cs.f[-1] - (n_harmonics + 8) * cs.df) / ((1 + tolerance) * n_harmonics)
    dec = rho * (shaft_hz or 0.0)
    dec = dec[dec < top]
    out = {"ftf": family_evidence(cm, fault_hz["ftf"], tolerance=tolerance, n_harmonics=n_harmonics)}
    cage = fault_hz["ftf"]
    if out["ftf"]["detected"]:
        # a cage comb explains every line on it: mask it (but not its Z-th harmonics, BPFO's lines)
        cage = out["ftf"]["measured_hz"]
        cm = cs.masked(shaft_hz, cage, skip_every=int(round(fault_hz["bpfo"] / fault_hz["ftf"])))
    mods = {"bpfo": shaft_hz, "bpfi": shaft_hz, "bsf": cage}
    for key in ("bpfo", "bpfi", "bsf"):
        carrier = 2 * fault_hz["bsf"] if key == "bsf" else fault_hz[key]
        out[key] = family_evidence(cm, carrier, modulator_hz=mods[key], tolerance=tolerance,
                                   n_harmonics=n_harmonics, decoy_hz=dec if decoys else None)
    if out["ftf"]["detected"] and out["bpfo"]["detected"]:
        _bpfo_above_cage(cs, out["bpfo"], cage, int(round(fault_hz["bpfo"] / fault_hz["ftf"])))
    if out["ftf"]["detected"] and out["bsf"]["measured_hz"]:
        # a 2 BSF carrier on a cage harmonic (ZA-2115: 2 BSF = 18.94 FTF) is the comb's line
        n = round(out["bsf"]["measured_hz"] / cage)
        if abs(out["bsf"]["measured_hz"] - n * cage) <= max(2.0, 0.1 * n) * cs.df:
            out["bsf"]["detected"] = False
            out["bsf"]["explained_by"] = "ftf"
    return {k: out[k] for k in FAMILY_KEYS}


def _bpfo_above_cage(cs, ev, cage, z):
    """BPFO = Z FTF lies on the cage comb: its lines count only where they stand above the
    comb's neighbouring lines ((Zk +- 1) FTF, (Zk +- 2) FTF); a cage comb alone puts lines at
    Zk FTF no stronger than the others.  At least MIN_HARMONICS carriers must stand out."""
    above = 0
    for f, snr, k, m in ev["lines"]:
        if m != 0:
            continue
        n = int(round(f / cage))
        neigh = cs.best([(n + j) * cage for j in (-2, -1, 1, 2)], 1)[1]
        above += snr > neigh.max()
    if above < MIN_HARMONICS:
        ev["detected"] = False
        ev["explained_by"] = "ftf"


def _pattern(f1, *, shaft_hz, ftf_hz, n_harmonics):
    """Frequencies of a leader's pattern: harmonics with shaft and cage sidebands."""
    k = np.arange(1, EXPLAIN_HARMONIC_FACTOR * n_harmonics + 1)[:, None]
    m = np.arange(-EXPLAIN_SIDEBAND_ORDERS, EXPLAIN_SIDEBAND_ORDERS + 1)[None, :]
    pos = [(k * f1 + m * mod).ravel() for mod in (shaft_hz, ftf_hz) if mod]
    pos = np.concatenate(pos) if pos else (k * f1).ravel()
    return np.sort(pos[pos > 0])


def _exclusive(ev, leader, cs, *, shaft_hz, ftf_hz, n_harmonics):
    """Re-judge family ``ev`` on the lines the leader's pattern does not explain."""
    pat = _pattern(leader["measured_hz"], shaft_hz=shaft_hz, ftf_hz=ftf_hz, n_harmonics=n_harmonics)
    kept = []
    for ln in ev["lines"]:
        j = np.searchsorted(pat, ln[0])
        near = [abs(pat[i] - ln[0]) for i in (j - 1, j) if 0 <= i < pat.size]
        tol = max(2.0, np.ceil(ln[2] / 2.0) + 1) * cs.df
        if not near or min(near) > tol:
            kept.append(ln)
    groups = {ln[2] for ln in kept}
    carriers = [ln for ln in kept if ln[3] == 0]
    fund = max([ln[1] for ln in kept if ln[2] == 1 and abs(ln[3]) <= 1] or [0.0])
    evidence = float(sum(min(s, LINE_CAP_DB) for _, s, _, _ in kept))
    detected = fund >= FUNDAMENTAL_SNR_DB and len(carriers) >= 2 and len(groups) >= MIN_HARMONICS
    if ev.get("decoy_threshold_score") is not None:
        detected = detected and evidence > ev["decoy_threshold_score"]
    return {"lines": kept, "detected": bool(detected), "evidence_score": evidence}


def route_verdict(families, cs, *, shaft_hz, ftf_hz, n_harmonics=5):
    """Verdict of one route from its family evidence.

    Parameters
    ----------
    families : dict
        :func:`search_families` result (modified: rivals get ``exclusive_evidence_score``).
    cs : CyclicSpectrum
        The spectrum they were found in.
    shaft_hz, ftf_hz : float
        Modulating rates with which lines are explained away.
    n_harmonics : int
        As in the search.

    Returns
    -------
    dict
        ``verdict`` ("outer_race", "inner_race", "ball", "none" or "uncertain"),
        ``leader`` (family key or None), ``candidates`` (labels, strongest first),
        ``margin_score`` (leader's evidence minus the next family's; None without a
        leader), ``reason``.
    """
    keys = [k for k in LABELS if families[k]["detected"]]
    if not keys:
        if families["ftf"]["detected"]:
            return {"verdict": "uncertain", "leader": "ftf", "candidates": ["ball"], "margin_score": None,
                    "reason": "a cage-rate (FTF) line family without a 2 BSF family of its own"}
        return {"verdict": "none", "leader": None, "candidates": [], "margin_score": None,
                "reason": "no fault family passes the detection rule"}
    leader = max(keys, key=lambda k: families[k]["evidence_score"])
    runner = max((k for k in LABELS if k != leader), key=lambda k: families[k]["evidence_score"])
    margin = families[leader]["evidence_score"] - families[runner]["evidence_score"]
    rivals = []
    for k in keys:
        if k == leader:
            continue
        ex = _exclusive(families[k], families[leader], cs, shaft_hz=shaft_hz, ftf_hz=ftf_hz,
                        n_harmonics=n_harmonics)
        families[k]["exclusive_evidence_score"] = ex["evidence_score"]
        if ex["detected"]:
            rivals.append(k)
        else:
            families[k]["explained_by"] = leader
    rivals.sort(key=lambda k: -families[k]["evidence_score"])
    cands = [LABELS[leader]] + [LABELS[k] for k in rivals]
    base = {"leader": leader, "candidates": cands, "margin_score": float(margin)}
    if rivals:
        names = " and ".join(k.upper() if k != "bsf" else "2 BSF" for k in [leader] + rivals)
        return {"verdict": "uncertain", **base, "reason": f"{names} families are each detected on lines of their own"}
    if leader == "bsf" and not (families["bsf"]["sidebands"] > 0 or families["ftf"]["detected"]):
        return {"verdict": "uncertain", **base, "reason": "a 2 BSF family without cage (FTF) modulation"}
    return {"verdict": LABELS[leader], **base,
            "reason": f"{'2 BSF' if leader == 'bsf' else leader.upper()} family dominant"}
