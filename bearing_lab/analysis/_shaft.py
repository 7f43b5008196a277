"""Shaft speed for a diagnosis, checked against the bearing's kinematics.

Why: fault frequencies scale with the shaft frequency, and a speed read off the
wrong line family names the wrong fault.  A train of bearing impacts is itself
a comb of lines at BPFO (or BPFI, 2 BSF, FTF), and a comb at ``F`` also scores at
``F/2``, ``F/3``: on the 6308, BPFO = 3.07 f_r, so BPFO/3 sits 2.4 % from f_r,
inside any +-5 % prior window.  The rules below never take such a comb for the
shaft:

1. **1x family.**  A shaft candidate needs at least ``MIN_SHAFT_LINES`` clear
   harmonics (10 dB over the local floor, mains lines masked) in the amplitude
   spectrum; they must not all be multiples of one integer ``d >= 2`` (that is
   a comb at ``d f0``, of which ``f0`` is a sub-multiple); and a family that
   rich must be unlikely by chance (``CHANCE_MAX``): binomial odds from the
   density of clear lines, times the number of candidates a blind search tries.
   A sub-harmonic ``f0/2`` or ``f0/3`` with odd lines of its own is preferred.
2. **With a prior** (a given or stored speed): the best such family within
   +-5 % of the prior refines it (interpolated DFT lines, weighted least
   squares, as in :func:`shaft_frequency`); without one the prior is used as
   given ("unconfirmed").  A fault comb cannot pass: within +-5 % it can only
   appear as a sub-multiple, which rule 1 rejects.  When unconfirmed, the
   blind search below runs too, and a speed it resolves outside the window
   marks the prior "contradicted".
3. **Blind** (no prior): the candidate family ``f0`` could also be the comb of
   a fault frequency of another shaft speed, ``f0 = r_j f_s`` (r_j: BPFO, BPFI,
   2 BSF or FTF ratio, or their halves and thirds, within the slip tolerance),
   and such a speed always lies in the search range.  So the signal names a speed
   only with positive evidence:

   - if some ``f_s`` has a 1x family of its own (rule 1, lines that are not
     harmonics of ``f0``), ``f_s`` is the shaft and ``f0`` its fault comb, and
     ``f_s`` is judged the same way;
   - if a fault family of the bearing is detected at the frequencies ``f0``
     implies (noise rule and decoys, :mod:`._families`) in the squared envelope
     spectrum of the cepstrum-pre-whitened signal, the kinematics confirm ``f0``.
     Only that spectrum counts: pre-whitening removes discrete lines (shaft
     harmonics, a slip-free comb) and keeps the slipping impacts of a fault, and
     the harmonics of ``f0`` are masked there, so a comb at ``f0`` cannot confirm
     ``f0``;
   - if no fault reading of the family is plausible, it is a **plain 1x family**
     and names the speed: its comb ``k f0`` shows in no envelope spectrum
     (pre-whitened or kurtogram band; a fault's impacts modulate the resonances,
     unbalance and misalignment do not), it is not a comb of discrete lines
     reaching the resonances (a slip-free impact train), no other speed's 1x
     family makes it a fault comb, and at least half of the harmonics searched
     are clear lines (a few weak lines, such as a healthy bearing's ball-pass
     lines, are not enough);
   - otherwise the speed is **unresolved**: a shaft and a fault comb would look
     the same.

4. **A stored or given speed is never overridden by its own fault comb**: a
   blind family within the slip tolerance of the prior's BPFO, BPFI, 2 BSF or
   FTF leaves the prior "unconfirmed", not "contradicted".
"""
from __future__ import annotations

import numpy as np
from scipy import fft as _fft
from scipy.stats import binom

from ..errors import AnalysisError
from ._families import SK_MIN, search_families
from ._fault_rule import FUNDAMENTAL_SNR_DB, MIN_HARMONICS
from ._speed import LINE_SNR_DB, SNR_CAP_DB, grid_near_lines, interpolated_peak, line_floor_db

__all__ = ["RawLines", "resolve_speed", "MIN_SHAFT_LINES", "PRIOR_TOLERANCE", "BLIND_RANGE_HZ"]

#: Clear harmonics a 1x family needs before the signal refines or names a speed.
MIN_SHAFT_LINES = 5
#: Half-width of the search window around a given or stored speed (induction-motor slip).
PRIOR_TOLERANCE = 0.05
#: Search range of a blind estimate (300-6000 r/min).
BLIND_RANGE_HZ = (5.0, 100.0)
#: Harmonics in the family score and refinement.
N_SHAFT_HARMONICS = 20
#: A 1x family must be less likely than this to arise by chance in its search range.
CHANCE_MAX = 1e-3
#: A plain 1x family (no fault family to confirm it) has half of its harmonics searched, or all of
#: the first PLAIN_FIRST, as clear lines.
PLAIN_FIRST = 5
#: Harmonics of a candidate examined in the envelope spectra for a fault comb.
COMB_HARMONICS = 5
#: A comb is "discrete" when this fraction of its harmonics up the spectrum are clear lines.
DISCRETE_FRACTION = 0.5


class RawLines:
    """Rectangular-window amplitude spectrum with line SNR, for shaft-line families.

    Parameters
    ----------
    x : ndarray, 1-D
    fs : float
    top_hz : float
        Highest frequency needed.
    mains_hz : sequence of float
        Mains frequencies whose harmonics are masked (within 1.5 bins).
    spectrum : ndarray, optional
        ``rfft(x - x.mean())``, when the caller has it.
    floors : SpectrumFloors, optional
        Of ``spectrum``, for the discrete-comb tests.
    """

    def __init__(self, x, fs, *, top_hz, mains_hz=(50.0, 60.0), spectrum=None, floors=None):
        n = x.size
        self.fs, self.n, self.df = float(fs), n, fs / n
        self.x = x
        top = min(int(np.ceil(top_hz / self.df)) + 64, n // 2)
        # the whole spectrum, for discrete_comb (``spectrum``: the caller's rfft(x - x.mean()))
        self.X_full = _fft.rfft(x - x.mean()) if spectrum is None else spectrum
        self.floors = floors  # a SpectrumFloors of X_full, or None
        self.X = self.X_full[: top + 2]
        amp = floors.amp[: top + 2] if floors is not None and floors.spectrum is self.X_full else np.abs(self.X)
        self.amp = amp
        self.snr = np.clip(line_floor_db(amp, width=max(31, int(round(10.0 / self.df)))), 0.0, SNR_CAP_DB)
        f = np.arange(amp.size) * self.df
        masked = np.zeros(amp.size, bool)
        for fm in mains_hz or ():
            m = np.arange(fm, f[-1] + fm, fm)[:, None]  # |f - m| <= 1.5 df tested on the bins near m
            near = np.clip(np.rint(m / self.df).astype(int) + np.arange(-3, 4), 0, amp.size - 1)
            masked[near[np.abs(f[near] - m) <= 1.5 * self.df]] = True
        self.masked = masked
        local = np.zeros(amp.size, bool)
        local[1:-1] = (amp[1:-1] >= amp[:-2]) & (amp[1:-1] >= amp[2:])
        self.clear = np.where(masked | (self.snr < LINE_SNR_DB) | ~local, 0.0, self.snr)
        # the largest clear-line SNR within +-1 bin of each bin (edges: the bins beside them)
        self.clear3 = self.clear.copy()
        self.clear3[1:-1] = np.maximum(np.maximum(self.clear[:-2], self.clear[1:-1]), self.clear[2:])
        self.top_hz = (amp.size - 3) * self.df

    min_rms = None  # measurability floor of a plain 1x family, in signal units (None: no floor)

    def family_rms(self, fam):
        """rms of a family's clear lines (rectangular-window peak amplitudes 2|X|/N)."""
        amps = []
        for h in fam["harmonics"]:
            k = int(round(h * fam["shaft_hz"] / self.df))
            if 1 <= k < self.amp.size - 1:
                amps.append(2.0 * self.amp[k - 1:k + 2].max() / self.n)
        return float(np.sqrt(0.5 * np.sum(np.square(amps))))

    def n_harmonics(self, hi):
        return int(max(1, min(N_SHAFT_HARMONICS, np.floor(min(self.top_hz, 0.45 * self.fs) / hi))))

    def scan(self, lo, hi):
        """Family score (Hermes-weighted clear-line SNR) of candidates in [lo, hi] (exactly 0 for those
        with no harmonic near a clear line: only the others are computed, when that saves work)."""
        nh = self.n_harmonics(hi)
        step = 0.5 * self.df / nh
        cand = np.arange(lo, hi + step, step)
        h = np.arange(1, nh + 1)
        wts = 0.9 ** (h - 1)
        score = np.zeros(cand.size)
        idx = grid_near_lines(self.clear3, self.df, lo, step, cand.size, h)
        idx = np.arange(cand.size) if idx is None else idx  # a spectrum dense with lines: the whole grid
        for i in range(0, idx.size, 8192):  # blocks that stay in cache, operations in place
            c = cand[idx[i:i + 8192], None] * h
            c /= self.df
            pos = np.rint(c, out=c).astype(np.intp)
            np.clip(pos, 1, self.clear.size - 2, out=pos)
            vals = self.clear3[pos]
            vals *= wts
            score[idx[i:i + 8192]] = vals.sum(axis=1)
        return cand, score

    def candidates(self, lo, hi, count=6):
        """Up to ``count`` distinct local maxima of the family score in [lo, hi], best first."""
        cand, score = self.scan(lo, hi)
        order = np.argsort(-score, kind="stable")
        out = []
        for i in order:
            if score[i] <= 0 or len(out) >= count:
                break
            c = cand[i]
            if all(abs(c / o - 1) > 0.01 for o in out):
                j = i
                while j + 1 < score.size and score[j + 1] >= score[i]:
                    j += 1
                out.append(float(0.5 * (cand[i] + cand[j])))
        return out

    def line_density(self, lo, hi):
        """Fraction of bins in [lo, hi] holding a clear line (the chance that a window of one bin hits one)."""
        a, b = int(lo / self.df), min(int(np.ceil(hi / self.df)) + 1, self.clear.size)
        return float(np.count_nonzero(self.clear[a:b] > 0)) / max(1, b - a)

    def chance(self, fam, lo, hi, tries=None):
        """Probability that a family this rich appears by chance in the search range [lo, hi].

        A harmonic window spans 3 bins, so a random frequency hits a clear line with
        probability ``p = 3 * density``; the number of harmonics hit out of those
        inside the spectrum is binomial.  A blind search tries about
        ``(hi - lo) n_h / df`` independent candidates (Bonferroni, the default);
        a search around a prior asks one question (``tries=1``).
        """
        nh = self.n_harmonics(hi)
        n_in = int(sum(1 for h in range(1, nh + 1) if h * fam["shaft_hz"] < self.top_hz))
        p = min(0.5, 3 * self.line_density(lo, nh * hi))
        if tries is None:
            tries = max(1.0, (hi - lo) * nh / self.df)
        return float(min(1.0, binom.sf(len(fam["harmonics"]) - 1, max(n_in, 1), p) * tries))

    def octave(self, f0, lo, hi):
        """``f0 / d`` (d = 2, 3) when its own odd lines exist (a family of even harmonics
        scores at 2 f_r too): at least 3, and half, of the harmonics of f0/d that are
        not harmonics of f0 must be clear lines; else f0."""
        nh = self.n_harmonics(hi)
        for d in (2, 3):
            sub = f0 / d
            if sub < lo or sub < 4 * self.df:
                continue
            hh = np.array([j for j in range(1, nh + 1) if j % d])
            kk = np.rint(hh * sub / self.df).astype(int)
            kk = kk[(kk >= 1) & (kk < self.clear.size - 1)]
            peak = np.maximum(np.maximum(self.clear[kk - 1], self.clear[kk]), self.clear[kk + 1])
            if np.count_nonzero(peak > 0) >= max(3, 0.5 * hh.size):
                return sub
        return f0

    def family(self, f0, hi=None):
        """Clear harmonics of ``f0`` and the refined frequency.

        Returns
        -------
        dict
            ``shaft_hz`` (refined, or f0), ``harmonics`` (list of h), ``snr_db``
            (list), ``primitive`` (bool), ``supported`` (bool).
        """
        nh = self.n_harmonics(hi or f0)
        est, wts, hs, snrs = [], [], [], []
        for h in range(1, nh + 1):
            k0 = int(round(h * f0 / self.df))
            if k0 < 2 or k0 + 2 >= self.clear.size:
                continue
            win = np.arange(k0 - 1, k0 + 2)
            k = int(win[np.argmax(self.clear[win])])
            if self.clear[k] <= 0:
                continue
            d = interpolated_peak(self.X, k, method="quinn")
            if abs(d) > 1:
                continue
            est.append((k + d) * self.df)
            wts.append(10 ** (self.snr[k] / 10) * h * h)
            hs.append(h)
            snrs.append(float(self.snr[k]))
        fr = float(f0)
        if est:
            est, wts, hsa = np.array(est), np.array(wts), np.array(hs)
            good = np.ones(est.size, bool)
            for _ in range(3):
                fr = float(np.sum(wts[good] * est[good] / hsa[good]) / np.sum(wts[good]))
                new = np.abs(est - hsa * fr) <= 0.5 * self.df
                if not new.any() or np.array_equal(new, good):
                    break
                good = new
            hs = [int(h) for h in hsa[good]]
            snrs = [s for s, g in zip(snrs, good) if g]
        prim = _primitive(hs)
        return {"shaft_hz": fr, "harmonics": hs, "snr_db": snrs, "primitive": prim,
                "supported": bool(prim and len(hs) >= MIN_SHAFT_LINES)}


def _primitive(hs):
    """False when (nearly) every harmonic present is a multiple of one d >= 2."""
    hs = np.asarray(hs, int)
    if hs.size == 0:
        return False
    for d in (2, 3, 4, 5):
        mult = int(np.count_nonzero(hs % d == 0))
        if mult >= 3 and hs.size - mult <= max(1, int(0.2 * hs.size)):
            return False
    return True


def discrete_comb(x, fs, f1, *, max_lines=300, spectrum=None, floors=None):
    """Is the comb ``k f1`` a set of discrete lines of x (a fault without slip)?

    A fault comb without slip (a simulation with a kinematic cage) is a set of
    discrete lines far up the spectrum; a real fault's random slip smears its
    high harmonics into a continuum.  Harmonics ``k = 5 ..`` up to 0.45 fs (at
    most ``max_lines``) count when a line stands ``LINE_SNR_DB`` over the running
    median within +-1 bin of ``k f1``.  The comb is discrete when at least half of
    them count and that many hits are unlikely by chance (binomial, hit rate
    three times the density of clear lines among the bins examined, p < 1e-3).

    ``spectrum``: ``rfft(x - x.mean())`` when the caller has it already; ``floors``: a
    :class:`SpectrumFloors` of it, shared by the tests of several combs.

    Returns
    -------
    (discrete, fraction, harmonics examined)
    """
    n = x.size
    df = fs / n
    k = np.arange(5, int(0.45 * fs // f1) + 1)[:max_lines]
    if k.size < 10:
        return False, 0.0, int(k.size)
    a, b = max(1, int(k[0] * f1 / df) - 200), min(n // 2, int(k[-1] * f1 / df) + 200)
    if floors is not None:
        amp, snr = floors.amp[a:b], floors.snr(a, b, width=max(31, int(round(10.0 / df))))
    else:
        amp = np.abs((_fft.rfft(x - x.mean()) if spectrum is None else spectrum)[a:b])
        snr = line_floor_db(amp, width=max(31, int(round(10.0 / df))))
    local = np.zeros(amp.size, bool)
    local[1:-1] = (amp[1:-1] >= amp[:-2]) & (amp[1:-1] >= amp[2:])
    clear = local & (snr >= LINE_SNR_DB)
    pos = np.rint(k * f1 / df).astype(int) - a
    pos = pos[(pos >= 1) & (pos < amp.size - 1)]
    hits = int(np.count_nonzero(clear[pos - 1] | clear[pos] | clear[pos + 1]))
    p = min(0.5, 3 * float(np.mean(clear)))
    frac = hits / max(1, pos.size)
    return bool(frac >= DISCRETE_FRACTION and binom.sf(hits - 1, pos.size, p) < 1e-3), frac, int(pos.size)


def _summary(fam, note=""):
    return {"shaft_hz": float(fam["shaft_hz"]), "harmonics": len(fam["harmonics"]),
            "snr_db": float(max(fam["snr_db"])) if fam["snr_db"] else 0.0, "note": note}


FAULT_RATIOS = (("BPFO", "bpfo", 1.0), ("BPFI", "bpfi", 1.0), ("2 BSF", "bsf", 2.0), ("FTF", "ftf", 1.0))


def _accept(raw, fam, lo, hi, tries=None):
    """Rule 1 with the chance test: (supported, reason if not)."""
    if not fam["harmonics"]:
        return False, "no clear harmonic"
    if not fam["primitive"]:
        return False, "a sub-multiple of a line comb"
    if len(fam["harmonics"]) < MIN_SHAFT_LINES:
        return False, f"{len(fam['harmonics'])} clear harmonics, fewer than {MIN_SHAFT_LINES}"
    p = raw.chance(fam, lo, hi, tries)
    if p >= CHANCE_MAX:
        return False, f"{len(fam['harmonics'])} harmonics, but a family this rich occurs by chance (p = {p:.2g})"
    return True, ""


def _alternatives(raw, fam, factors, lo, hi, tolerance):
    """Shaft speeds at which the comb ``fam`` is a fault family (or its half or third) and that
    have a 1x family of their own."""
    f0 = fam["shaft_hz"]
    out = []
    for (name, key, mult), d in ((fr, d) for fr in FAULT_RATIOS for d in (1, 2, 3)):
        r = mult * factors[key] / d
        a, b = max(lo, f0 / (r * (1 + tolerance))), min(hi, f0 / (r * (1 - tolerance)))
        if not a < b:
            continue
        name = name if d == 1 else f"{name}/{d}"
        for c in raw.candidates(a, b, count=1):
            alt = raw.family(c, b)
            # lines of the alternative that are harmonics of f0 are f0's, not its own
            own = [h for h in alt["harmonics"]
                   if abs(h * alt["shaft_hz"] / f0 - round(h * alt["shaft_hz"] / f0)) * f0 > raw.df]
            alt = dict(alt, harmonics=own, snr_db=alt["snr_db"][: len(own)], primitive=_primitive(own))
            if _accept(raw, alt, a, b)[0]:
                out.append((name, alt))
    return out


def _spectra(cs, f0):
    """(pre-whitened SES, kurtogram-band SES or None) that ``cs`` gives for f0."""
    if cs is None:
        return None, None
    specs = list(cs(f0)) if callable(cs) else [cs]
    return specs[0], (specs[1] if len(specs) > 1 else None)


def _corroborated(cs, geometry, f0, tolerance):
    """The strongest fault family detected (noise rule and decoys) at the frequencies f0
    implies in the squared envelope spectrum of the cepstrum-pre-whitened signal; None if
    none.  Only that spectrum confirms a speed: pre-whitening removes the discrete lines
    (shaft harmonics, a slip-free comb) and keeps the slipping impacts of a bearing fault,
    and the search masks the harmonics of f0 itself, so a comb at f0 cannot confirm f0.
    The kurtogram band's spectrum is not used: a band chosen for its impulsiveness may
    hold a comb of discrete lines."""
    hits = {}
    for spec in _spectra(cs, f0)[:1]:
        if spec is None:
            continue
        try:
            fams = search_families(spec, geometry.fault_frequencies(f0), shaft_hz=f0, tolerance=tolerance)
        except AnalysisError:
            continue
        for k in ("bpfo", "bpfi", "bsf"):
            if fams[k]["detected"]:
                hits[k] = max(hits.get(k, 0.0), fams[k]["evidence_score"])
    return max(hits, key=hits.get) if hits else None


def _judge(raw, cs, geometry, fam, lo, hi, tolerance, depth=0):
    """Resolve or refuse one candidate 1x family (module docstring, rule 3)."""
    f0 = fam["shaft_hz"]
    factors = geometry.frequency_factors()
    alts = _alternatives(raw, fam, factors, lo, hi, tolerance)
    if alts and depth == 0:
        name, alt = max(alts, key=lambda a: len(a[1]["harmonics"]))
        res = _judge(raw, cs, geometry, alt, lo, hi, tolerance, depth=1)
        note = (f"the {f0:.3f} Hz line family is the {name} comb of a {alt['shaft_hz']:.3f} Hz shaft "
                f"({len(alt['harmonics'])} shaft harmonics of its own)")
        res["candidates"].append(_summary(fam, f"{name} comb, not the shaft"))
        res["note"] = note + ("; " + res["note"] if res["note"] else "")
        return res
    cands = [_summary(a, f"would make {f0:.3f} Hz its {n} comb") for n, a in alts]
    fault = _corroborated(cs, geometry, f0, tolerance)
    if fault is not None:
        return {"resolved": True, "family": fam, "candidates": cands,
                "note": f"{len(fam['harmonics'])} shaft harmonics; the {fault.upper()} family at this speed "
                        "is detected in the envelope spectrum of the pre-whitened signal"}
    comb = _fault_comb(raw, cs, f0, fam["harmonics"])
    hs = set(fam["harmonics"])
    rich = len(hs) >= DISCRETE_FRACTION * raw.n_harmonics(hi) or hs >= set(range(1, PLAIN_FIRST + 1))
    fam_rms = raw.family_rms(fam)
    loud = raw.min_rms is None or fam_rms >= raw.min_rms
    if comb is None and not alts and rich and loud:
        return {"resolved": True, "family": fam, "candidates": cands,
                "note": f"a plain 1x family: {len(fam['harmonics'])} shaft harmonics that are neither an "
                        "envelope comb nor a comb of discrete lines reaching the resonances, so no fault "
                        "reading of them is plausible"}
    readings = ", ".join(f"{n} of a {f0 / (factors[k] * m):.2f} Hz shaft" for n, k, m in FAULT_RATIOS
                         if lo <= f0 / (factors[k] * m) <= hi)
    readings_c = [{"shaft_hz": float(f0 / (factors[k] * m)), "harmonics": 0, "snr_db": 0.0,
                   "note": f"if the {f0:.3f} Hz family is its {n} comb"} for n, k, m in FAULT_RATIOS
                  if lo <= f0 / (factors[k] * m) <= hi]
    cands = cands + readings_c
    why = comb or ("another speed's 1x family makes it a fault comb" if alts else
                   f"{len(fam['harmonics'])} clear harmonics of {raw.n_harmonics(hi)}: too few for a plain 1x "
                   "family without a fault family to confirm it" if not rich else
                   f"its lines carry {fam_rms:.3g} rms, below the measurability floor {raw.min_rms:.3g}: a shaft "
                   "in service vibrates more, a healthy bearing's ball-pass lines can be this small")
    return {"resolved": False, "family": fam, "candidates": [_summary(fam, "1x line family")] + cands,
            "note": f"no fault family at the frequencies {f0:.3f} Hz implies confirms it as the shaft, and "
                    f"its line family could be a fault comb ({why}): {readings or 'of another speed'}"}


def _fault_comb(raw, cs, f0, lines_h=()):
    """Why the line family at f0 could be the comb of a fault's impacts, or None.

    A fault's impacts modulate the structural resonances, so their comb shows in an
    envelope spectrum; a slip-free impact train (a simulation) is also a comb of discrete
    lines reaching the resonances.  Shaft harmonics of unbalance or misalignment are
    neither.  The test: the comb k f0 (k = 1..COMB_HARMONICS, each within one bin) passes the
    noise rule (a fundamental line, MIN_HARMONICS lines) in the pre-whitened envelope spectrum or in that of the
    kurtogram band when the band is
    impulsive (spectral kurtosis at least ``SK_MIN``: a band of a few steady lines has an
    envelope beating at their spacing) and lies above the family's clear lines
    ``lines_h``, or is a discrete comb up to 0.45 fs
    (:func:`discrete_comb`)."""
    for name, spec in zip(("pre-whitened", "kurtogram band's"), _spectra(cs, f0)):
        if spec is None or getattr(spec, "kurtosis", SK_MIN) < SK_MIN:
            continue  # a band without impulsiveness holds no impact comb (its lines beat)
        band = getattr(spec, "band", None)
        if band is not None and band[0] < (max(lines_h, default=0) + 1) * f0:
            continue  # the band holds the family's own lines: its envelope beats at f0 anyway
        k = np.arange(1, COMB_HARMONICS + 1)
        if k[-1] * f0 + 2 * spec.df >= spec.f[-1]:
            continue
        _, snr = spec.best(k * f0, 1)  # lines within one bin: f0 is known to a fraction of a bin
        if snr[0] >= FUNDAMENTAL_SNR_DB and np.count_nonzero(snr > 0) >= MIN_HARMONICS:
            return f"a comb of {np.count_nonzero(snr > 0)} lines in the {name} envelope spectrum"
    if raw.x is not None:
        discrete, frac, count = discrete_comb(raw.x, raw.fs, f0, spectrum=raw.X_full, floors=raw.floors)
        if discrete:
            return f"a comb of discrete lines up to 0.45 fs ({100 * frac:.0f} % of {count} harmonics)"
    if cs is None:
        return "no envelope spectrum to tell"
    return None


def _blind(raw, cs, geometry, tolerance, lo, hi):
    tried = []
    for f0 in raw.candidates(lo, hi, count=6):
        fam = raw.family(raw.octave(f0, lo, hi), hi)
        ok, why = _accept(raw, fam, lo, hi)
        if not ok:
            tried.append(_summary(fam, why))
            continue
        res = _judge(raw, cs, geometry, fam, lo, hi, tolerance)
        res["candidates"] = res["candidates"] + tried
        return res
    return {"resolved": False, "family": None, "candidates": tried,
            "note": f"no 1x line family with at least {MIN_SHAFT_LINES} clear harmonics that chance cannot "
                    f"explain in {lo:g}-{hi:g} Hz"}


def _own_comb(geometry, prior_hz, f_hz, tolerance):
    """Name of the fault family of ``prior_hz`` whose carrier lies at ``f_hz`` within the
    slip tolerance, or None: a stored speed is never overridden by its own fault comb."""
    factors = geometry.frequency_factors()
    for name, key, mult in FAULT_RATIOS:
        if abs(f_hz / (prior_hz * mult * factors[key]) - 1) <= tolerance:
            return name
    return None


def resolve_speed(x, fs, geometry, *, rpm=None, rpm_source="given", cs=None, tolerance=0.02,
                  blind_range_hz=BLIND_RANGE_HZ, min_family_rms=None, spectrum=None, floors=None):
    """Shaft frequency from a prior speed or the signal alone (module docstring).

    Parameters
    ----------
    x : ndarray, 1-D
    fs : float
    geometry : BearingGeometry
    rpm : float, optional
        Prior speed, r/min (None: blind).
    rpm_source : {"given", "file"}
        Where the prior comes from (copied to ``source``).
    cs : CyclicSpectrum or callable, optional
        Cyclic spectrum reaching the fault lines of the fastest candidate, or a
        function of a candidate speed returning a list of spectra (called only when
        a blind search needs them), for the kinematic confirmation of a blind
        candidate; without it no candidate is confirmed that way.
    tolerance : float
        Slip tolerance of fault frequencies.
    blind_range_hz : (float, float)
        Search range without a prior.
    min_family_rms : float, optional
        Measurability floor (signal units, rms) a plain 1x family must reach to name a
        blind speed without a fault family to confirm it.
    spectrum : ndarray, optional
        ``rfft(x - x.mean())``, when the caller has it.
    floors : SpectrumFloors, optional
        Of ``spectrum``, shared with the caller's discrete-comb tests.

    Returns
    -------
    dict
        ``shaft_hz`` (None when a blind search finds no 1x family at all),
        ``source`` ("given", "file", "estimated" or "unresolved"), ``status``
        ("confirmed", "unconfirmed", "contradicted", "resolved", "unresolved"),
        ``prior_hz``, ``harmonics`` and ``snr_db`` of the 1x family used (0 if
        none), ``deviation_pct`` (estimate against the prior), ``candidates``
        (other families considered, with why they were not taken), ``note``.
    """
    lo_b, hi_b = (float(v) for v in blind_range_hz)
    prior = None if rpm is None else float(rpm) / 60.0
    if prior is not None and not (np.isfinite(prior) and 0.0 < prior * (1 + PRIOR_TOLERANCE) < 0.5 * fs):
        # the 1x line must lie below the Nyquist frequency; a wrong speed of 1e12 r/min would
        # otherwise ask the family scan for a candidate grid of hundreds of GiB
        raise AnalysisError(f"a shaft speed of {float(rpm):.6g} r/min ({prior:.6g} Hz) cannot be seen in a "
                            f"record sampled at {fs:.6g} Hz (its lines must lie below {0.5 * fs:.6g} Hz): "
                            "the stored or given speed is wrong; give the speed with --rpm, or --rpm none")
    hi_all = max(hi_b, prior * (1 + PRIOR_TOLERANCE) if prior else 0.0)
    raw = RawLines(x, fs, top_hz=min(0.45 * fs, N_SHAFT_HARMONICS * hi_all * 1.03), spectrum=spectrum,
                   floors=floors)
    raw.min_rms = min_family_rms
    lowest = prior * (1 - PRIOR_TOLERANCE) if prior else lo_b
    if 4 * raw.df > lowest:
        msg = (f"the record lasts {x.size / fs:.3g} s: its 1/T = {raw.df:.3g} Hz bins cannot resolve shaft "
               f"lines at {lowest:.3g} Hz (record at least {4 / lowest:.3g} s, or give the speed)")
        raise AnalysisError(msg)
    out = {"shaft_hz": prior, "source": rpm_source if prior else "unresolved", "status": None,
           "prior_hz": prior, "harmonics": 0, "snr_db": 0.0, "deviation_pct": None, "candidates": [],
           "note": ""}
    if prior is None:
        res = _blind(raw, cs, geometry, tolerance, lo_b, hi_b)
        fam = res["family"]
        out.update(candidates=res["candidates"], note=res["note"])
        if fam is not None:
            s = _summary(fam)
            out.update(shaft_hz=s["shaft_hz"], harmonics=s["harmonics"], snr_db=s["snr_db"])
        out.update(source="estimated" if res["resolved"] else "unresolved",
                   status="resolved" if res["resolved"] else "unresolved")
        return out
    return _with_prior(raw, cs, geometry, out, prior, rpm_source, tolerance, lo_b, hi_b)


def _with_prior(raw, cs, geometry, out, prior, rpm_source, tolerance, lo_b, hi_b):
    """Rules 2 and 4: refine a given or stored speed, or keep it, or mark it contradicted."""
    lo, hi = prior * (1 - PRIOR_TOLERANCE), prior * (1 + PRIOR_TOLERANCE)
    for f0 in raw.candidates(lo, hi, count=3):
        fam = raw.family(f0, hi)
        ok, why = _accept(raw, fam, lo, hi, tries=1)
        if ok and lo <= fam["shaft_hz"] <= hi:
            s = _summary(fam)
            out.update(shaft_hz=s["shaft_hz"], status="confirmed", harmonics=s["harmonics"],
                       snr_db=s["snr_db"], deviation_pct=100 * (s["shaft_hz"] / prior - 1),
                       note=f"{s['harmonics']} shaft harmonics within +-{100 * PRIOR_TOLERANCE:g} % of the "
                            f"{rpm_source} speed refine it")
            return out
        out["candidates"].append(_summary(fam, why or "outside the window"))
    blind = _blind(raw, cs, geometry, tolerance, lo_b, hi_b)
    f_b = blind["family"]["shaft_hz"] if blind["family"] else None
    own = _own_comb(geometry, prior, f_b, tolerance) if blind["resolved"] else None
    if own is not None:
        out.update(status="unconfirmed",
                   note=f"no 1x line family within +-{100 * PRIOR_TOLERANCE:g} % of the {rpm_source} speed; the "
                        f"signal's line family at {f_b:.3f} Hz is the {own} comb of the {rpm_source} speed, which "
                        "is used as it is")
        out["candidates"].append(_summary(blind["family"], f"{own} comb of the {rpm_source} speed"))
    elif blind["resolved"] and not lo <= f_b <= hi:
        out.update(status="contradicted", deviation_pct=100 * (f_b / prior - 1),
                   note=f"no 1x family near the {rpm_source} speed, but the signal's own 1x family is at "
                        f"{f_b:.3f} Hz ({60 * f_b:.1f} r/min): the {rpm_source} speed may be wrong")
        out["candidates"].append(_summary(blind["family"], "1x family of the blind search"))
    else:
        out.update(status="unconfirmed",
                   note=f"no 1x line family with {MIN_SHAFT_LINES} clear harmonics within "
                        f"+-{100 * PRIOR_TOLERANCE:g} %: the {rpm_source} speed is used as it is")
    return out
