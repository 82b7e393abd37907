"""The cycles of a judged window: lobes between zero crossings, their extremes and the trend
and scatter of their amplitudes, and period-p patterns of cycles
(:func:`aeroservo.simulate.lco_detect.classify` applies them)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["MAX_SUBHARMONIC", "lobes", "trend", "cycle_frequency", "periodicity", "monotone"]

MAX_SUBHARMONIC = 4
"""Most zero-crossing cycles one LCO period may hold (period-p limit cycles)."""


def lobes(t, x, h):
    """Extremes of the lobes of ``x`` (about zero) cut by zero crossings with hysteresis ``h``.

    A lobe runs between two successive changes of the state (``x > h``: +1, ``x < -h``: -1);
    only full lobes count. Returns the lobes' absolute extremes (refined by a parabola
    through three samples), their times [s] and the upward zero-crossing times [s] (linear
    interpolation across the last sign change before each turn to +1).
    """
    n = x.size
    idx = np.arange(n)
    hit = np.where(x > h, 1, np.where(x < -h, -1, 0)).astype(np.int8)
    last = np.maximum.accumulate(np.where(hit != 0, idx, -1))
    state = np.where(last >= 0, hit[np.maximum(last, 0)], 0)
    flips = np.flatnonzero((state[1:] != state[:-1]) & (state[:-1] != 0)) + 1
    up = flips[state[flips] > 0]
    j = np.maximum.accumulate(np.where(x <= 0, idx, -1))[up]
    t_up = t[j] - x[j] / (x[j + 1] - x[j]) * (t[j + 1] - t[j])
    if flips.size < 2:
        return np.empty(0), np.empty(0), t_up
    lengths = np.diff(flips)
    sign = state[flips[:-1]].astype(float)
    seg = np.repeat(np.arange(sign.size), lengths)
    y = x[flips[0] : flips[-1]] * sign[seg]
    ymax = np.maximum.reduceat(y, flips[:-1] - flips[0])
    at = np.flatnonzero(y == ymax[seg])
    first = np.flatnonzero(np.diff(seg[at], prepend=-1) != 0)
    k = at[first] + flips[0]  # index of each lobe's extreme, 1 <= k <= n - 2
    v0, v1, v2 = x[k - 1] * sign, x[k] * sign, x[k + 1] * sign
    curv = v0 - 2.0 * v1 + v2
    off = np.divide(0.5 * (v0 - v2), curv, out=np.zeros_like(curv), where=curv < 0)
    ext = v1 - 0.25 * (v0 - v2) * off
    t_ext = t[k] + off * 0.5 * (t[k + 1] - t[k - 1])
    return ext, t_ext, t_up


def trend(ts, y, phases):
    """Slope of ``y`` against ``ts`` with one offset per phase (index mod ``phases``).

    Returns the slope and the residual standard deviation (``ts`` all equal: the scatter
    about the phase means).
    """
    ph = np.arange(y.size) % phases
    cnt = np.bincount(ph, minlength=phases)
    dt = ts - (np.bincount(ph, ts, phases) / cnt)[ph]
    dy = y - (np.bincount(ph, y, phases) / cnt)[ph]
    sxx = float(dt @ dt)
    slope = float(dt @ dy) / sxx if sxx > 0 else 0.0
    res = dy - slope * dt
    return slope, math.sqrt(float(res @ res) / max(y.size - phases - 1, 1))


def cycle_frequency(t_ext, p) -> float:
    """Frequency [Hz] of period-``p`` cycles over the most whole ones between lobe extremes."""
    m = (t_ext.size - 1) // (2 * p)
    return m / float(t_ext[2 * p * m] - t_ext[0]) if m > 0 else math.nan


def periodicity(ta, la, periods, cycles, min_cycles, tol):
    """Smallest period-p pattern within ``tol`` (p = 1 if none).

    Returns p, the growth [1/s], the amplitude scatter and the period scatter of that pattern,
    and the larger of the amplitude and period scatters of single cycles (p = 1): what a
    period-p pattern has to explain.
    """
    first = None
    for p in range(1, MAX_SUBHARMONIC + 1):
        if p > 1 and (periods.size < 3 * p or la.size < 6 * p or cycles / p < min_cycles):
            break
        g, a_sc = trend(ta, la, 2 * p)
        p_sc = trend(np.zeros_like(periods), periods, p)[1] / float(periods.mean())
        first = first or (p, g, a_sc, p_sc)
        if max(a_sc, p_sc) <= tol:
            return p, g, a_sc, p_sc, max(first[2:])
    return (*first, max(first[2:]))


def monotone(tw, x, tol, margin):
    """Of a window without cycles that is monotone (at least 3 changes): ``(kind, confidence,
    change, growth)`` from the log-slope of its rate of change (``"decay"``, ``"divergence"``
    or ``"undecided"`` within ``tol``; medium confidence beyond ``margin`` x ``tol``); None if
    it is not monotone."""
    d = np.diff(x)
    if not ((np.all(d >= 0) or np.all(d <= 0)) and np.count_nonzero(d) >= 3):
        return None
    nz = d != 0
    tm = 0.5 * (tw[1:] + tw[:-1])[nz]
    g, _ = trend(tm, np.log(np.abs(d[nz])), 1)
    change = math.expm1(min(g * (tw[-1] - tw[0]), 700.0))
    kind = "decay" if change < -tol else "divergence" if change > tol else "undecided"
    conf = "medium" if abs(change) >= margin * tol and kind != "undecided" else "low"
    return kind, conf, change, g
