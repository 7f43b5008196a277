"""Small numerical routines the simulator's start needs, without scipy.

Why this module: every run starts from Hertz constants (:mod:`.hertz`) and a static equilibrium
(:mod:`.statics`, :mod:`.assembly`), which need the complete elliptic integrals and bracketed
scalar roots.  Importing ``scipy.special`` and ``scipy.optimize`` at the top of those modules for
these cost every ``bearing-lab simulate`` 0.1 s of CPU (the 1 s paper-O1 run spends 0.04 s in its
time loop), so they are written out here:

- :func:`brentq` is Brent's method as scipy's ``brentq`` implements it (same steps, same stopping
  test ``|x - x*| < (xtol + rtol |x|) / 2``), so it returns the same float for the same function;
- :func:`ellipk`, :func:`ellipe` evaluate the Cephes rational approximations scipy uses (peak
  relative error 2.5e-16), as functions of the parameter ``m`` (``k^2``);

Neither falls back on anything: a bracket without a sign change, a NaN, or a search that does
not converge raises :class:`~bearing_lab.errors.SolverError` naming what was searched.
``tests/sim/test_numerics.py`` checks them against scipy and against closed forms.

Public API
----------
brentq(f, a, b, *, xtol=2e-12, rtol=4 eps, maxiter=100, where="root") -> float
ellipk(m), ellipe(m) -> float
"""
from __future__ import annotations

import math

from ..errors import SolverError

__all__ = ["brentq", "ellipk", "ellipe"]

_EPS = 2.220446049250313e-16


def _value(f, x, where):
    v = float(f(x))
    if math.isnan(v):
        raise SolverError(f"{where}: the function is NaN at {x!r}")
    return v


def brentq(f, a: float, b: float, *, xtol: float = 2e-12, rtol: float = 4 * _EPS, maxiter: int = 100,
           where: str = "root") -> float:
    """A root of ``f`` in ``[a, b]`` (``f(a)``, ``f(b)`` of opposite signs) by Brent's method.

    The steps and the stopping test are those of scipy's ``brentq`` (C. Harris's implementation
    of Brent 1973: inverse quadratic interpolation or secant when the step is short enough,
    bisection otherwise); the root is within ``xtol + rtol |x|`` of the true one.

    Raises SolverError when ``f(a)`` and ``f(b)`` have the same sign, ``f`` is NaN, or the root
    is not found within ``maxiter`` iterations; ``where`` names the search in the message.
    """
    if not (xtol > 0) or not (rtol >= 4 * _EPS):
        raise SolverError(f"{where}: xtol={xtol!r} must be > 0 and rtol={rtol!r} >= {4 * _EPS!r}")
    xpre, xcur = float(a), float(b)
    fpre, fcur = _value(f, xpre, where), _value(f, xcur, where)
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    if (fpre < 0.0) == (fcur < 0.0):
        raise SolverError(f"{where}: no sign change between {xpre!r} (f = {fpre:.6g}) and "
                          f"{xcur!r} (f = {fcur:.6g})")
    xblk = fblk = spre = scur = 0.0
    for _ in range(maxiter):
        if fpre != 0.0 and fcur != 0.0 and (fpre < 0.0) != (fcur < 0.0):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:            # interpolate (secant)
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:                       # extrapolate (inverse quadratic)
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):
                spre, scur = scur, stry     # a good short step
            else:
                spre = scur = sbis
        else:
            spre = scur = sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0 else -delta)
        fcur = _value(f, xcur, where)
    raise SolverError(f"{where}: no root within {maxiter} iterations (last {xcur!r}, f = {fcur:.6g}, "
                      f"bracket [{min(xcur, xblk)!r}, {max(xcur, xblk)!r}])")


# Cephes (S. Moshier) rational approximations, in the parameter m1 = 1 - m, as in scipy.special
_K_P = (1.37982864606273237150E-4, 2.28025724005875567385E-3, 7.97404013220415179367E-3,
        9.85821379021226008714E-3, 6.87489687449949877925E-3, 6.18901033637687613229E-3,
        8.79078273952743772254E-3, 1.49380448916805252718E-2, 3.08851465246711995998E-2,
        9.65735902811690126535E-2, 1.38629436111989062502E0)
_K_Q = (2.94078955048598507511E-5, 9.14184723865917226571E-4, 5.94058303753167793257E-3,
        1.54850516649762399335E-2, 2.39089602715924892727E-2, 3.01204715227604046988E-2,
        3.73774314173823228969E-2, 4.88280347570998239232E-2, 7.03124996963957469739E-2,
        1.24999999999870820058E-1, 4.99999999999999999821E-1)
_E_P = (1.53552577301013293365E-4, 2.50888492163602060990E-3, 8.68786816565889628429E-3,
        1.07350949056076193403E-2, 7.77395492516787092951E-3, 7.58395289413514708519E-3,
        1.15688436810574127319E-2, 2.18317996015557253103E-2, 5.68051945617860553470E-2,
        4.43147180560990850618E-1, 1.00000000000000000299E0)
_E_Q = (3.27954898576485872656E-5, 1.00962792679356715133E-3, 6.50609489976927491433E-3,
        1.68862163993311317300E-2, 2.61769742454493659583E-2, 3.34833904888224918614E-2,
        4.27180926518931511717E-2, 5.85936634471101055642E-2, 9.37499997197644278445E-2,
        2.49999999999888314361E-1)
_LOG4 = 1.3862943611198906188E0


def _polevl(x, coef):
    ans = coef[0]
    for c in coef[1:]:
        ans = ans * x + c
    return ans


def _check_m(m, name):
    m = float(m)
    if not (0.0 <= m < 1.0):
        raise SolverError(f"{name}(m={m!r}): the parameter m = k^2 must be in [0, 1)")
    return m


def ellipk(m: float) -> float:
    """Complete elliptic integral of the first kind ``K(m) = int_0^pi/2 dt / sqrt(1 - m sin^2 t)``."""
    x = 1.0 - _check_m(m, "ellipk")
    if x > 1.11022302462515654042E-16:
        return _polevl(x, _K_P) - math.log(x) * _polevl(x, _K_Q)
    return _LOG4 - 0.5 * math.log(x)


def ellipe(m: float) -> float:
    """Complete elliptic integral of the second kind ``E(m) = int_0^pi/2 sqrt(1 - m sin^2 t) dt``."""
    x = 1.0 - _check_m(m, "ellipe")
    return _polevl(x, _E_P) - math.log(x) * (x * _polevl(x, _E_Q))
