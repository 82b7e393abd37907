"""Brent's bracketing root finder for a scalar function.

The flutter and divergence searches need one bracketing root finder, and importing
``scipy.optimize`` for it costs about 0.3 s of start-up (issue 17). This is Brent's method in
the variant of ``scipy.optimize.brentq`` (inverse quadratic extrapolation, secant
interpolation, bisection as the safeguard), step for step, so the roots are the same to the
last digit; ``tests/test_brent.py`` compares the two on random functions.
"""

from __future__ import annotations

import math
from collections.abc import Callable

#: Smallest relative tolerance accepted (as ``scipy.optimize.brentq``): four machine epsilons.
RTOL_MIN = 4 * 2.220446049250313e-16


class BracketError(ValueError):
    """The function has the same sign at both ends of the interval, or did not converge."""


def brentq(
    f: Callable[..., float],
    a: float,
    b: float,
    args: tuple = (),
    xtol: float = 2e-12,
    rtol: float = RTOL_MIN,
    maxiter: int = 100,
) -> float:
    """Root of ``f`` in ``[a, b]`` by Brent's method.

    Parameters
    ----------
    f : callable
        ``f(x, *args) -> float``; must change sign on the interval.
    a, b : float
        Ends of the bracketing interval (same unit as the root).
    args : tuple
        Extra arguments of ``f``.
    xtol, rtol : float
        The root is returned when it is known to within ``xtol + rtol * |x|``.
    maxiter : int
        Largest number of iterations.

    Returns
    -------
    float
        The root.

    Raises
    ------
    BracketError
        ``f(a)`` and ``f(b)`` have the same sign, a value is not finite, or no convergence.
    """
    if not xtol > 0 or rtol < RTOL_MIN:
        raise ValueError(f"brentq: xtol must be > 0 and rtol >= {RTOL_MIN:g}")
    xpre, xcur = float(a), float(b)
    fpre, fcur = float(f(xpre, *args)), float(f(xcur, *args))
    if not (math.isfinite(fpre) and math.isfinite(fcur)):
        raise BracketError("brentq: the function is not finite at an end of the interval")
    if fpre == 0:
        return xpre
    if fcur == 0:
        return xcur
    if math.copysign(1.0, fpre) == math.copysign(1.0, fcur):
        raise BracketError("brentq: f(a) and f(b) must have different signs")
    xblk = fblk = spre = scur = 0.0
    for _ in range(maxiter):
        if fpre != 0 and fcur != 0 and math.copysign(1.0, fpre) != math.copysign(1.0, fcur):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # secant
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # inverse quadratic
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):
                spre, scur = scur, stry
            else:
                spre = scur = sbis
        else:
            spre = scur = sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0 else -delta)
        fcur = float(f(xcur, *args))
        if not math.isfinite(fcur):
            raise BracketError(f"brentq: the function is not finite at {xcur!r}")
    raise BracketError(f"brentq: no convergence in {maxiter} iterations")
