"""The closed-form motion of one linear region and where it meets the edges of its pieces.

On a region the plant is ``x' = A_r x + B u + g_r``; with ``A_r = V diag(lambda) V^-1`` and the
input held, the modal coordinates are ``y(t) = exp(lambda t) y0 + (exp(lambda t) - 1)/lambda
gamma`` (:func:`modal_path`). A rotation ``w y(t)`` reaches an edge where a scalar function
changes sign: :func:`crossing_time` finds it by Newton's method kept in its bracket, to rounding.
:func:`leaves` decides from the ends of a sample whether the exact march is needed there (the
rotation ends beyond an edge, or its cubic interpolant comes near one); :func:`quick_bracket`,
:func:`exits` and :func:`graze_index` bracket the first crossing (``docs/freeplay.md``).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "SUB",
    "GRID",
    "FINE",
    "GRAZE_MARGIN",
    "leaves",
    "quick_bracket",
    "exits",
    "graze_index",
    "crossing_time",
    "modal_path",
    "modal_at",
    "rotations_at",
    "rows_at",
    "scan_rows",
    "state_at",
]

SUB = 16
"""Sub-intervals on which a flagged sample interval is scanned for edge crossings (then the
cubic Hermite interpolant of each sub-interval, from the exact values and rates, for grazes)."""
GRID = np.linspace(0.0, 1.0, SUB + 1)
_TH = np.linspace(0.0, 1.0, 33)[:, None]
_HERMITE = (
    2 * _TH**3 - 3 * _TH**2 + 1,
    _TH**3 - 2 * _TH**2 + _TH,
    -2 * _TH**3 + 3 * _TH**2,
    _TH**3 - _TH**2,
)
"""The cubic Hermite basis at 33 points of a sub-interval (graze test)."""
FINE = np.linspace(0.0, 1.0, 257)

GRAZE_MARGIN = 0.05
"""A sample is marched through its closed form whenever the cubic interpolant of a rotation
comes within this fraction of the sample's motion (``|s1 - s0|`` plus the rates times the
step) of an edge (:func:`leaves`)."""


def _turns(s0: float, s1: float, r0: float, r1: float) -> int:
    """Turning points in (0, 1) of the cubic Hermite interpolant with end values ``s0, s1`` and
    end slopes ``r0, r1`` (per unit of the interval)."""
    a = 3.0 * (s1 - s0) - 2.0 * r0 - r1
    b = 2.0 * (s0 - s1) + r0 + r1
    qa, qb, qc = 3.0 * b, 2.0 * a, r0
    if qa == 0.0:
        return int(qb != 0.0 and 0.0 < -qc / qb < 1.0)
    disc = qb * qb - 4.0 * qa * qc
    if disc < 0.0:
        return 0
    sq = disc**0.5
    return sum(0.0 < t < 1.0 for t in ((-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)))


def exits(s, taus, lo_c, hi_c) -> list:
    """``[(t_a, t_b, element, upper, s_a, s_b), ...]`` for every element beyond an edge at the
    first sample (not the first) where any is (``s_a, s_b``: its rotations at ``t_a, t_b``),
    or []; ``lo_c``, ``hi_c``: the edges less and plus their tolerance, as columns."""
    below = s < lo_c
    out = below | (s > hi_c)
    out[:, 0] = False
    if not out.any():
        return []
    j = int(np.flatnonzero(out.any(axis=0))[0])
    return [
        (taus[j - 1], taus[j], int(e), not below[e, j], s[e, j - 1], s[e, j])
        for e in np.flatnonzero(out[:, j])
    ]


def quick_bracket(v0: list, v1: list, rest: float, lo: list, hi: list):
    """From the rotations and rates at the ends of the interval alone (``v0``, ``v1``: the
    rotations then their rates): None when no rotation reaches an edge (none ends beyond one,
    none turns beyond one by its cubic Hermite interpolant); ``(0, rest, element, upper)`` when
    exactly one rotation ends beyond an edge with at most one turning point on the way (one
    crossing); False otherwise (scan)."""
    e = len(v0) // 2
    if not leaves(v0, v1, e, lo, hi, rest):
        return None
    out = [j for j in range(e) if not lo[j] <= v1[j] <= hi[j]]
    if len(out) != 1:
        return False
    j = out[0]
    if _turns(v0[j], v1[j], v0[e + j] * rest, v1[e + j] * rest) > 1:
        return False
    for i in range(e):  # the others must not graze an edge
        if i != j and leaves([v0[i], v0[e + i]], [v1[i], v1[e + i]], 1, [lo[i]], [hi[i]], rest):
            return False
    return 0.0, rest, j, v1[j] > hi[j]


def crossing_time(w, lam, y0, gam, edge, ta, tb, atol, ends=None) -> float:
    """The time in ``[ta, tb]`` where ``w y(tau)`` reaches ``edge`` (a sign change there):
    Newton's method on the closed form, kept in the bracket (bisection when a step leaves it),
    to rounding. A start within ``atol`` of the edge (the rotation has just crossed it) looks
    for the next crossing after its excursion into the region. ``ends``: the rotations at
    ``ta`` and ``tb`` when known."""
    if _far_from_zero(lam):
        off = gam / lam
        wa = w * (y0 + off)
        wl = np.array([wa, wa * lam])  # the rotation and its rate in one product
        c0 = float((w @ off).real) + edge

        def fs(taus):
            return (wa @ np.exp(np.multiply.outer(lam, taus))).real - c0

        def f(tau):
            v, d = (wl @ np.exp(lam * tau)).real.tolist()
            return v - c0, d
    else:
        wd = w[None, :]

        def fs(taus):
            return rotations_at(wd, lam, y0, gam, taus)[0] - edge

        def f(tau):
            v = rotations_at(wd, lam, y0, gam, np.array([tau, tau + 1e-9 * (tb - ta)]))[0]
            return v[0] - edge, (v[1] - v[0]) / (1e-9 * (tb - ta))

    fa, fb = (ends[0] - edge, ends[1] - edge) if ends else (f(ta)[0], f(tb)[0])
    if fb == 0.0:
        return tb
    if abs(fa) <= atol:  # on the edge at the start (just switched): the crossing after it
        for n in (32, 512):
            grid = ta + (tb - ta) * np.arange(1, n + 1) / n
            vals = fs(grid)
            inside = np.flatnonzero(np.sign(vals) == -np.sign(fb))
            if inside.size:
                break
        else:
            return ta  # it only touches the edge: leave now
        after = np.flatnonzero(np.sign(vals[inside[0] :]) == np.sign(fb))
        k = inside[0] + int(after[0])
        ta, fa, tb = grid[k - 1], vals[k - 1], grid[k]
    if _sign(fa) == _sign(fb):
        return ta
    tau = ta + (tb - ta) * fa / (fa - fb)
    span = tb - ta
    for _ in range(60):
        fv, dv = f(tau)
        if fv == 0.0:
            break
        if _sign(fv) == _sign(fa):
            ta, fa = tau, fv
        else:
            tb = tau
        step = tau - fv / dv if dv != 0.0 else 0.5 * (ta + tb)
        new = step if ta < step < tb else 0.5 * (ta + tb)
        done = abs(new - tau) <= 1e-13 * span
        tau = new
        if done:
            break
    # on to the side beyond the edge (steps doubling from 1e-16 of the bracket): the new
    # region starts on its own side
    fv, dv = f(tau)
    if _sign(fv) == _sign(fb):
        return tau
    step = max(2.0 * abs(fv / dv) if dv else 0.0, 8.0 * math.ulp(tau), 1e-18 * span)
    for k in range(12):  # (at k = 0, tau is the point just evaluated)
        if tau >= tb or (k and _sign(f(tau)[0]) == _sign(fb)):
            return min(tau, tb)
        tau, step = max(tau + step, math.nextafter(tau, math.inf)), 2.0 * step
    return tb


def _sign(x: float) -> float:
    """``np.sign`` of a Python float, without the call into NumPy."""
    return 1.0 if x > 0.0 else -1.0 if x < 0.0 else 0.0 if x == 0.0 else x


def _phi1(lam: np.ndarray, taus: np.ndarray) -> np.ndarray:
    """``(exp(lambda tau) - 1) / lambda`` (tau where lambda tau is tiny), (n, n_tau)."""
    z = lam[:, None] * taus[None, :]
    small = np.abs(z) < 1e-8
    safe = np.where(lam == 0, 1.0, lam)[:, None]
    return np.where(small, taus[None, :] * (1.0 + 0.5 * z), np.expm1(z) / safe)


def modal_path(lam, y0, gam, taus) -> np.ndarray:
    """Modal coordinates ``y(tau) = exp(lambda tau) y0 + phi1(lambda, tau) gamma``, (n, n_tau);
    as ``exp(lambda tau) (y0 + gamma/lambda) - gamma/lambda`` when no eigenvalue is near 0."""
    with np.errstate(over="ignore", invalid="ignore"):  # a diverging march: inf, reported
        ex = np.exp(np.multiply.outer(lam, taus))
    if _far_from_zero(lam):
        off = gam / lam
        return ex * (y0 + off)[:, None] - off[:, None]
    return ex * y0[:, None] + _phi1(lam, taus) * gam[:, None]


def modal_at(lam, y0, gam, tau: float) -> np.ndarray:
    """:func:`modal_path` at one time ``tau`` [s] (n,)."""
    if _far_from_zero(lam):
        off = gam / lam
        return np.exp(lam * tau) * (y0 + off) - off
    return modal_path(lam, y0, gam, np.array([tau]))[:, 0]


_SAFE: dict = {}


def _far_from_zero(lam: np.ndarray) -> bool:
    """Whether no eigenvalue is within 1e-6 1/s of zero (cached per eigenvalue array)."""
    key = id(lam)
    hit = _SAFE.get(key)
    if hit is None or hit[0] is not lam:
        hit = _SAFE[key] = (lam, bool(np.abs(lam).min() > 1e-6))
        if len(_SAFE) > 256:
            _SAFE.clear()
            _SAFE[key] = hit
    return hit[1]


def rotations_at(W, lam, y0, gam, taus) -> np.ndarray:
    """Rows of ``W y(tau)`` (real)."""
    return (W @ modal_path(lam, y0, gam, taus)).real


def scan_rows(W, lam, y0, gam, rest: float) -> np.ndarray:
    """:func:`rows_at` at the :data:`GRID` points of ``[0, rest]``, the exponentials as the
    powers of ``exp(lambda rest / SUB)`` (four products: the same rows to rounding)."""
    if lam.size < 16 or not _far_from_zero(lam) or lam.real.max() * rest >= 700.0:
        return rows_at(W, lam, y0, gam, rest * GRID)  # (few modes: the exponentials are cheap)
    off = gam / lam
    ex = np.empty((SUB + 1, lam.size), dtype=complex)  # a row per point: contiguous products
    ex[0] = 1.0
    np.exp(lam * (rest / SUB), out=ex[1])
    n = 1
    while n < SUB:  # rows n+1 .. 2n from 1 .. n
        np.multiply(ex[1 : n + 1], ex[n], out=ex[n + 1 : 2 * n + 1])
        n *= 2
    return ((W * (y0 + off)) @ ex.T).real - (W @ off).real[:, None]


def rows_at(W, lam, y0, gam, taus) -> np.ndarray:
    """:func:`rotations_at` without the modal coordinates: ``Re(W diag(y0 + gamma/lambda)
    exp(lambda tau)) - Re(W gamma/lambda)`` when no eigenvalue is near 0 (the same rows to
    rounding, at the cost of the exponentials alone)."""
    if not _far_from_zero(lam):
        return rotations_at(W, lam, y0, gam, taus)
    off = gam / lam
    z = np.multiply.outer(lam, taus)
    if z.real.max() < 700.0:  # no overflow
        ex = np.exp(z)
    else:
        with np.errstate(over="ignore", invalid="ignore"):  # a diverging march: inf, reported
            ex = np.exp(z)
    return ((W * (y0 + off)) @ ex).real - (W @ off).real[:, None]


def state_at(V, lam, y0, gam, tau: float) -> np.ndarray:
    """The state ``V y(tau)`` (real) at one time ``tau`` [s]."""
    return (V @ modal_at(lam, y0, gam, tau)).real


def graze_index(s, sd, taus, lo, hi, tol):
    """Index of the first sub-interval whose cubic Hermite interpolant of a rotation (from its
    values and rates at the ends) leaves the piece, or None."""
    if not (sd[:, :-1] * sd[:, 1:] < 0).any():  # no rate changes sign: no turn
        return None
    dt = np.diff(taus)
    h00, h10, h01, h11 = _HERMITE
    first = None
    for e in range(s.shape[0]):
        d0, d1 = sd[e, :-1] * dt, sd[e, 1:] * dt
        turn = np.flatnonzero(d0 * d1 < 0)
        if turn.size == 0:
            continue
        p = h00 * s[e, turn] + h10 * d0[turn] + h01 * s[e, turn + 1] + h11 * d1[turn]
        bad = ((p < lo[e] - tol[e]) | (p > hi[e] + tol[e])).any(axis=0)
        if bad.any():
            j = int(turn[np.flatnonzero(bad)[0]]) + 1
            first = j if first is None else min(first, j)
    return first


def leaves(v0, v1, e, lo, hi, dt) -> bool:
    """Whether a rotation may reach an edge of its piece within a sample: it ends beyond one,
    or the cubic Hermite interpolant of its values and rates at the ends comes within
    :data:`GRAZE_MARGIN` of the sample's motion of one (a graze the ends do not show; the
    margin covers the content the cubic misses, up to the sample rate). Python floats: ``e``
    is a handful of elements."""
    for j in range(e):
        s0, s1 = v0[j], v1[j]
        if s1 < lo[j] or s1 > hi[j]:
            return True
        d0, d1 = v0[e + j] * dt, v1[e + j] * dt
        # p(t) = s0 + d0 t + a t^2 + b t^3 on [0, 1]; its extremes at the ends or p'(t) = 0
        a = 3.0 * (s1 - s0) - 2.0 * d0 - d1
        b = 2.0 * (s0 - s1) + d0 + d1
        m = GRAZE_MARGIN * (abs(d0) + abs(d1) + abs(s1 - s0))
        low, high = min(s0, s1) - m, max(s0, s1) + m
        qa, qb, qc = 3.0 * b, 2.0 * a, d0
        if qa == 0.0:
            roots = [-qc / qb] if qb else []
        else:
            disc = qb * qb - 4.0 * qa * qc
            sq = disc**0.5 if disc >= 0.0 else 0.0
            roots = [(-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)] if disc >= 0.0 else []
        for t in roots:
            if 0.0 < t < 1.0:
                p = s0 + t * (d0 + t * (a + t * b))
                low, high = min(low, p - m), max(high, p + m)
        if low < lo[j] or high > hi[j]:
            return True
    return False
