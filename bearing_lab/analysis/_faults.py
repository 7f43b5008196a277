"""Fault-frequency search in the squared envelope spectrum, and the diagnosis.

Why one fixed rule: a diagnosis that is tuned per recording proves nothing.
Every threshold below was chosen from the statistics of the squared envelope
spectrum (SES) of Gaussian noise, before looking at any fault recording, and the
same rule is applied to every file:

- Line SNR is ``20 log10(peak / floor)`` where the floor is the running median
  of the SES amplitude over ``floor_width_hz`` (default 10 Hz, at least 21 bins).
  For a noise-only SES the amplitude is roughly Rayleigh distributed, so a bin
  exceeds its median by 10 dB with probability ~1e-3 (``exp(-ln 2 * 10)``).
- The fundamental is searched in ``expected * (1 +- tolerance)`` (default 2 %
  slip).  The largest of the ~40-80 bins in that window exceeds the median by
  about 8 dB in noise; ``FUNDAMENTAL_SNR_DB = 12`` keeps the chance of a false
  fundamental per search below ~1e-3 (checked by simulation, see the tests).
- Harmonic ``h`` of the found line is searched within +-max(2 bins, 0.2 % h f1)
  and counts when its SNR >= ``HARMONIC_SNR_DB = 10`` (~1e-3 per bin in noise,
  so ~1e-2 per harmonic window).
- Integer multiples of the shaft frequency are masked (+-max(1.5 bins, 0.1 %)):
  shaft lines are not bearing-fault evidence, and on some bearings (ZA-2115:
  BPFO = 7.09 f_r) a shaft harmonic falls inside the slip window.
- A fault is *detected* when its fundamental passes and at least two more of
  its first ``n_harmonics`` (5) harmonics do (``MIN_HARMONICS = 3`` lines in
  all; in noise that has a chance below 1e-6).  The count was first set to 2;
  it was raised to 3, for every file alike, after the healthy IMS record
  2004.02.12.10.32.39 channel 3 showed a two-line family near BPFO (15 dB)
  while every diagnosed fault in the proof set shows 3-5 lines.
  For an inner-race fault, shaft sidebands (``h f1 +- f_r``) are reported but
  do not add to the evidence.  The ball fault is searched at ``2 BSF``.
- Diagnosis: the detected fault with the largest evidence (sum of the SNR in dB
  of its counted lines); ``"none"`` when no fault is detected.  Weak evidence
  gives ``"none"``, never a guess.
"""
from __future__ import annotations

import numpy as np

from ..errors import AnalysisError
from ._fault_rule import FUNDAMENTAL_SNR_DB, HARMONIC_SNR_DB, MIN_HARMONICS, shaft_mask
from ._families import CyclicSpectrum, route_verdict, search_families
from ._speed import line_floor_db

__all__ = ["fault_line", "diagnose_ses", "FUNDAMENTAL_SNR_DB", "HARMONIC_SNR_DB", "MIN_HARMONICS"]

FAULT_KEYS = ("bpfo", "bpfi", "bsf", "ftf")
DIAGNOSES = {"bpfo": "outer_race", "bpfi": "inner_race", "bsf": "ball"}


def _parabolic(y, k):
    """Sub-bin peak position from a parabola through log amplitudes."""
    a, b, c = np.log(np.maximum(y[k - 1: k + 2], 1e-300))
    den = a - 2 * b + c
    return 0.0 if den >= 0 else float(np.clip(0.5 * (a - c) / den, -0.5, 0.5))


def _best_peak(snr, lo_k, hi_k, usable):
    """Index of the highest local maximum of snr in [lo_k, hi_k] that is usable, or None."""
    lo_k, hi_k = max(lo_k, 1), min(hi_k, snr.size - 2)
    if hi_k < lo_k:
        return None
    ks = np.arange(lo_k, hi_k + 1)
    loc = (snr[ks] >= snr[ks - 1]) & (snr[ks] >= snr[ks + 1]) & usable[ks]
    if not loc.any():
        return None
    ks = ks[loc]
    return int(ks[np.argmax(snr[ks])])


def fault_line(f, ses, expected_hz, *, shaft_hz=None, tolerance=0.02, n_harmonics=5,
               sidebands=False, floor_width_hz=10.0, snr_db=None):
    """Search a fault frequency and its harmonics in a squared envelope spectrum.

    Parameters
    ----------
    f : ndarray
        Cyclic frequencies of the SES, Hz (uniform, from 0).
    ses : ndarray, 1-D
        SES amplitudes (any unit).
    expected_hz : float
        Kinematic fault frequency, Hz.
    shaft_hz : float, optional
        Shaft frequency, Hz: its harmonics are masked, and the ``+- f_r``
        sidebands are counted when ``sidebands`` is true.
    tolerance : float
        Relative half-width of the search window for the fundamental (slip).
    n_harmonics : int
        Harmonics examined, including the fundamental.
    sidebands : bool
        Count shaft sidebands ``h f1 +- f_r`` (inner-race faults).
    floor_width_hz : float
        Width of the running-median floor, Hz.
    snr_db : ndarray, optional
        Precomputed line SNR of ``ses`` (dB), to share across fault searches.

    Returns
    -------
    dict
        ``expected_hz``, ``measured_hz`` (None when no fundamental passes),
        ``snr_db`` (of the best line in the window, even when it does not pass),
        ``harmonics`` (number of lines found, fundamental included; 0 if none),
        ``sidebands`` (number of shaft sidebands found), ``evidence_score``,
        ``detected`` (bool), ``units`` ("Hz" for frequencies, "dB" for SNR).

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab.analysis import squared_envelope_spectrum, fault_line
    >>> fs = 20000.0; t = np.arange(200000) / fs
    >>> x = np.exp(-900 * (t % (1 / 107.3))) * np.sin(2 * np.pi * 3000 * t)
    >>> x = x + np.random.default_rng(0).normal(0, 0.3, t.size)
    >>> f, ses = squared_envelope_spectrum(x, fs, window="hann", band=(2000, 4000), fmax=1000)
    >>> r = fault_line(f, ses, 106.0)
    >>> r["detected"], round(r["measured_hz"], 1)
    (True, 107.3)
    """
    f = np.asarray(f, float)
    ses = np.asarray(ses, float)
    if ses.ndim != 1 or f.shape != ses.shape or f.size < 8:
        raise AnalysisError(f"fault_line: f and ses must be 1-D of the same length >= 8, got "
                            f"{f.shape} and {ses.shape}")
    if not (np.isfinite(expected_hz) and expected_hz > 0):
        raise AnalysisError(f"fault_line: expected_hz={expected_hz!r} must be a positive frequency")
    df = f[1] - f[0]
    if snr_db is None:
        snr_db = line_floor_db(ses, width=max(21, int(round(floor_width_hz / df))))
    usable = ~shaft_mask(f, shaft_hz, df)
    usable[0] = False
    out = {"expected_hz": float(expected_hz), "measured_hz": None, "snr_db": 0.0, "harmonics": 0,
           "sidebands": 0, "evidence_score": 0.0, "detected": False,
           "units": {"expected_hz": "Hz", "measured_hz": "Hz", "snr_db": "dB",
                     "evidence_score": "1 (sum of line SNRs in dB)"}}
    lo = int(np.floor(expected_hz * (1 - tolerance) / df))
    hi = int(np.ceil(expected_hz * (1 + tolerance) / df))
    if hi >= f.size - 1:
        raise AnalysisError(f"fault_line: the SES reaches {f[-1]:g} Hz, below the search window "
                            f"around {expected_hz:g} Hz (+-{100 * tolerance:g} %)")
    k = _best_peak(snr_db, lo, hi, usable)
    if k is None:
        return out
    out["snr_db"] = float(snr_db[k])
    if snr_db[k] < FUNDAMENTAL_SNR_DB:
        return out
    f1 = (k + _parabolic(ses, k)) * df
    out["measured_hz"] = float(f1)
    count, evidence, nsb = 1, float(snr_db[k]), 0
    for h in range(2, n_harmonics + 1):
        centre = h * f1
        half = max(2 * df, 0.002 * centre)
        kh = _best_peak(snr_db, int(np.floor((centre - half) / df)), int(np.ceil((centre + half) / df)), usable)
        if kh is not None and snr_db[kh] >= HARMONIC_SNR_DB:
            count += 1
            evidence += float(snr_db[kh])
    if sidebands and shaft_hz:
        for h in range(1, n_harmonics + 1):
            for s in (-1, 1):
                centre = h * f1 + s * shaft_hz
                half = max(2 * df, 0.002 * centre)
                ks = _best_peak(snr_db, int(np.floor((centre - half) / df)),
                                int(np.ceil((centre + half) / df)), usable)
                if ks is not None and snr_db[ks] >= HARMONIC_SNR_DB:
                    nsb += 1
    out.update(harmonics=count, sidebands=nsb, evidence_score=evidence,
               detected=bool(count >= MIN_HARMONICS))
    return out


def diagnose_ses(f, ses, fault_hz, *, shaft_hz=None, tolerance=0.02, n_harmonics=5,
                 floor_width_hz=10.0):
    """Search BPFO, BPFI, 2 BSF and FTF families in one SES and name the fault.

    The family rule of :func:`bearing_lab.analysis.analyze` applied to one
    spectrum (harmonics, sidebands, decoys when ``shaft_hz`` is given, and the
    leader against its rivals); ``analyze`` itself combines three such routes.

    Parameters
    ----------
    f, ses : ndarray
        SES from :func:`squared_envelope_spectrum` (1-D).
    fault_hz : dict
        Kinematic frequencies with keys ``bpfo``, ``bpfi``, ``bsf``, ``ftf`` (Hz),
        e.g. ``get_bearing("6205").fault_frequencies(shaft_hz)``.
    shaft_hz : float, optional
        Shaft frequency (masks its harmonics; inner- and outer-race sidebands;
        scale of the decoys, which are skipped without it).
    tolerance, n_harmonics, floor_width_hz
        As in :func:`fault_line`.

    Returns
    -------
    diagnosis : str
        ``"outer_race"``, ``"inner_race"``, ``"ball"``, ``"uncertain"`` (two
        families each on lines of their own, or a ball family without cage
        modulation) or ``"none"``.
    lines : dict
        Per key: ``expected_hz``, ``measured_hz``, ``snr_db``, ``harmonics``,
        ``groups``, ``sidebands``, ``evidence_score``, ``decoy_max_score``, ``detected``,
        ``lines`` and ``units`` (``bsf`` is searched at 2 BSF: its
        ``expected_hz`` and ``measured_hz`` are 2 BSF).

    Examples
    --------
    >>> import numpy as np
    >>> from bearing_lab import get_bearing
    >>> from bearing_lab.analysis import squared_envelope_spectrum, diagnose_ses
    >>> fs = 12000.0; t = np.arange(120000) / fs; fr = 29.95
    >>> bpfo = 3.5848 * fr
    >>> x = np.exp(-900 * (t % (1 / bpfo))) * np.sin(2 * np.pi * 3000 * t)
    >>> x = x + np.random.default_rng(0).normal(0, 0.3, t.size)
    >>> f, ses = squared_envelope_spectrum(x, fs, window="hann", band=(2000, 4000), fmax=1300)
    >>> ff = get_bearing("6205").fault_frequencies(fr)
    >>> diagnose_ses(f, ses, ff, shaft_hz=fr)[0]
    'outer_race'
    """
    missing = [k for k in FAULT_KEYS if k not in fault_hz]
    if missing:
        raise AnalysisError(f"diagnose_ses: fault_hz lacks {missing}; give bpfo, bpfi, bsf and ftf in Hz")
    cs = CyclicSpectrum(f, ses, floor_width_hz=floor_width_hz)
    fams = search_families(cs, fault_hz, shaft_hz=shaft_hz, tolerance=tolerance, n_harmonics=n_harmonics,
                           decoys=shaft_hz is not None)
    verdict = route_verdict(fams, cs.masked(shaft_hz), shaft_hz=shaft_hz, ftf_hz=fault_hz["ftf"],
                            n_harmonics=n_harmonics)
    units = {"expected_hz": "Hz", "measured_hz": "Hz", "snr_db": "dB", "evidence_score": "1 (sum of line SNRs in dB)"}
    return verdict["verdict"], {k: dict(v, units=units) for k, v in fams.items()}
