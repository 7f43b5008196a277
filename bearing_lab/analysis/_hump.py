"""Ball faults as smeared humps: the 2 BSF family when slip broadens its lines.

Why: a ball with a spall does not strike at a steady rate.  It spins about a
wandering axis, so the spall meets the races irregularly, and the ball's own
slip in and out of the load zone is larger than a race's; the cage carries the
ball through the load zone once per cage turn, so the strikes are modulated at
the cage rate FTF.  In the envelope spectrum the 2 BSF family then shows as
broad humps around ``k 2 BSF`` made of the carrier and its FTF sidebands
smeared together, not as discrete lines: the line search of :mod:`._families`
(a line within two bins) misses it (Randall & Antoni 2011, section 2.3; Smith &
Randall 2015, who find ball faults the hardest class of the CWRU data).

The statistic, per route spectrum: harmonic ``k`` (1..``HUMP_HARMONICS``)
contributes the ratio, in dB, of the mean spectrum in the hump window
``|f - k F| <= 1.5 FTF + slip k F`` (carrier with its first cage sidebands,
widened by a 2 % slip) to the median of the ring around it (out to four
half-widths); shaft harmonics are left out of both.  The ratios are summed.
The same statistic at the decoy carriers of :mod:`._families` (``rho f_r``,
clear of every kinematic ratio) measures what this spectrum gives any
frequency.  A route holds a **clear hump family** when the 2 BSF score beats
every decoy and their mean by ``DECOY_SIGMAS`` standard deviations, and beats the
same statistic at BPFO and BPFI (a race fault's sidebands also raise the 2 BSF
window, notably on the 6203 where 2 BSF lies 1 % from BPFI - f_r).

It is used only where the line families name no race fault (:func:`apply`):
a clear hump family in two or more routes diagnoses ``ball``; in one route it
makes an otherwise silent analysis ``uncertain`` with the candidate ``ball``.
"""
from __future__ import annotations

import numpy as np

from ._families import DECOY_SIGMAS, decoy_ratios

__all__ = ["hump_score", "route_humps", "apply", "HUMP_HARMONICS", "MIN_ROUTES"]

#: Harmonics of 2 BSF whose humps are summed.
HUMP_HARMONICS = 4
#: Relative slip that widens the k-th hump (ball faults slip more than race faults, 1-2 %).
HUMP_SLIP = 0.02
#: Routes that must hold a clear hump family for a ``ball`` diagnosis.
MIN_ROUTES = 2
#: Decoys a route needs before its hump score is judged.
MIN_DECOYS = 8


def hump_score(f, s, carrier_hz, *, shaft_hz, ftf_hz, n_harmonics=HUMP_HARMONICS, slip=HUMP_SLIP):
    """Summed hump-over-ring ratio (dB) of the family ``k carrier_hz``; NaN when the spectrum
    does not reach the last ring."""
    df = float(f[1] - f[0])
    top = f[-1]
    total = 0.0
    for k in range(1, n_harmonics + 1):
        c = k * carrier_hz
        h = 1.5 * ftf_hz + slip * c
        if c + 4 * h >= top or c - 4 * h <= 0:
            return float("nan")
        a, b = int(np.floor((c - 4 * h) / df)), int(np.ceil((c + 4 * h) / df)) + 1
        ff, ss = f[a:b], s[a:b]
        m = np.rint(ff / shaft_hz)  # shaft harmonics are left out (only this window's bins)
        kk = ~((m >= 1) & (np.abs(ff - m * shaft_hz) <= 1.5 * df))
        d = np.abs(ff - c)
        win, ring = kk & (d <= h), kk & (d > h)
        if np.count_nonzero(win) < 3 or np.count_nonzero(ring) < 6:
            return float("nan")
        base = _median(ss[ring])
        if base <= 0:
            return float("nan")
        total += 10.0 * np.log10(max(float(np.mean(ss[win])), 1e-300) / base)
    return float(total)


def _median(v):
    """``np.median`` of a 1-D array: the middle order statistics alone (numpy also places the
    largest, to find NaNs; a NaN here gives NaN as numpy's does)."""
    n, h = v.size, v.size // 2
    if not np.isfinite(v).all():
        return float(np.median(v))
    if n % 2:
        return float(np.partition(v, h)[h])
    p = np.partition(v, (h - 1, h))
    return float((p[h - 1] + p[h]) / 2)


def route_humps(f, s, fault_hz, *, shaft_hz, factors, tolerance=0.02):
    """Hump evidence of one route: 2 BSF against decoys, BPFO and BPFI.

    Returns
    -------
    dict
        ``score_db`` (2 BSF), ``bpfo_db``, ``bpfi_db``, ``decoy_max_score``, ``decoy_threshold_score``,
        ``decoys`` (count), ``clear`` (bool).
    """
    kw = dict(shaft_hz=shaft_hz, ftf_hz=fault_hz["ftf"])
    score = hump_score(f, s, 2 * fault_hz["bsf"], **kw)
    race = {k: hump_score(f, s, fault_hz[k], **kw) for k in ("bpfo", "bpfi")}
    dec = np.array([hump_score(f, s, r * shaft_hz, **kw) for r in decoy_ratios(factors, tolerance=tolerance)])
    dec = dec[np.isfinite(dec)]
    def num(v):
        return float(v) if np.isfinite(v) else None  # NaN: the spectrum does not reach the humps
    out = {"score_db": num(score), "bpfo_db": num(race["bpfo"]), "bpfi_db": num(race["bpfi"]),
           "decoys": int(dec.size),
           "decoy_max_score": float(dec.max()) if dec.size else None, "decoy_threshold_score": None, "clear": False}
    if dec.size < MIN_DECOYS or not np.isfinite(score):
        return out
    thr = float(max(dec.max(), dec.mean() + DECOY_SIGMAS * dec.std()))
    beats_races = all(not np.isfinite(v) or score > v for v in race.values())
    out.update(decoy_threshold_score=thr, clear=bool(score > thr and beats_races))
    return out


def apply(verdict, routes, fault_hz, *, shaft_hz, factors, speed_status, tolerance=0.02):
    """Upgrade a verdict with the hump evidence (module docstring); returns (verdict, humps).

    Only a verdict that names no race fault is changed: a ``ball`` diagnosis when
    ``MIN_ROUTES`` routes hold a clear hump family, ``uncertain`` (candidate ball) from
    ``no fault evidence`` when one does.  A contradicted or unresolved speed changes nothing.
    """
    humps = {n: route_humps(r["f"], r["spectrum"], fault_hz, shaft_hz=shaft_hz, factors=factors,
                            tolerance=tolerance) for n, r in routes.items()}
    clear = [n for n, h in humps.items() if h["clear"]]
    race_named = any(c in ("outer_race", "inner_race") for c in verdict["candidates"]) or \
        verdict["diagnosis"] in ("outer_race", "inner_race")
    if not clear or race_named or speed_status in ("contradicted", "unresolved") or \
            verdict["verdict"] == "diagnosed":
        return verdict, humps
    said = ", ".join(f"{n} (hump score {humps[n]['score_db']:.1f}, decoys up to {humps[n]['decoy_max_score']:.1f})"
                     for n in clear)
    if len(clear) >= MIN_ROUTES:
        return dict(verdict, diagnosis="ball", verdict="diagnosed", decided_by=clear, candidates=["ball"], hump=True,
                    reason=f"a smeared 2 BSF hump family (carrier and cage sidebands broadened by slip) stands "
                           f"above every decoy and above BPFO and BPFI in {said}"), humps
    if verdict["verdict"] == "no fault evidence":
        return dict(verdict, diagnosis="uncertain", verdict="uncertain", candidates=["ball"],
                    reason=f"a smeared 2 BSF hump family in one route only ({said}): not enough to name "
                           "a ball fault"), humps
    return verdict, humps
