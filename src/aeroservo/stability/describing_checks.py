"""What a describing function's grids do not resolve: hidden crossings and stopping branches.

The crossings of :mod:`.equivalent_system` and :mod:`aeroservo.design.hinge_describing` count
the growing roots at each grid speed; where the count changes, Brent's method finds the sign
change of each sorted rate. Two roots crossing in opposite directions within one grid interval
leave the count unchanged and were missed. Here the roots at the two ends of an interval are
paired by continuity (least total distance, :func:`.assignment.min_cost_assignment`) and each
root's own sign change is counted: where the two counts disagree the interval is bisected
(at most :data:`MAX_DEPTH` times) until they agree, and the sub-intervals where the count
changes are searched as before. An interval that still disagrees at the last depth (the roots
cross within ``(b - a) / 2**MAX_DEPTH`` of each other, or the pairing cannot follow them) is
reported. A single root that crosses and crosses back within one interval is still not seen
(its own sign does not change either): refine the speeds.

A branch continued in amplitude (the crossings at successive amplitudes) stops where the next
amplitude has no crossing like it. On a *flat* branch (the limit-cycle amplitude almost
constant over a range of speeds: the crossing speed changes fast with amplitude), one step in
amplitude moves the crossing further than the amplitudes resolve; :func:`stop_notes` names
the amplitude and speed where such a branch stops and why.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .assignment import min_cost_assignment

__all__ = [
    "MAX_DEPTH",
    "FLAT",
    "search_intervals",
    "own_sign_changes",
    "hidden_note",
    "stop_notes",
]

MAX_DEPTH = 6
"""Most bisections of a grid interval whose roots' own sign changes disagree with the count."""
FLAT = 0.05
"""A branch whose speed changed by more than this fraction over its last amplitude step, and
that stops there, is flat: the amplitudes do not resolve it."""


def own_sign_changes(w0: np.ndarray, w1: np.ndarray, pos0: np.ndarray, pos1: np.ndarray) -> int:
    """Number of roots that change between growing and not, the roots ``w0`` (n,) and ``w1``
    (n,) at two speeds paired by continuity; ``pos0``, ``pos1``: whether each grows."""
    rows, cols = min_cost_assignment(np.abs(w0[:, None] - w1[None, :]))
    return int(np.count_nonzero(pos0[rows] != pos1[cols]))


def search_intervals(
    speeds: np.ndarray,
    roots: np.ndarray,
    growing: Callable[[np.ndarray], np.ndarray],
    at: Callable[[float], np.ndarray],
    depth: int = MAX_DEPTH,
) -> tuple[list[tuple[float, float, int, int]], list[tuple[float, float]]]:
    """The speed intervals to search for crossings, and those left unresolved.

    Parameters
    ----------
    speeds : ndarray (n_speeds,)
        Increasing grid [m/s].
    roots : ndarray (n_speeds, n)
        Every root at each grid speed (any order).
    growing : callable
        ``growing(w) -> bool array``: which roots ``w`` grow.
    at : callable
        ``at(v) -> ndarray (n,)``: the roots at speed ``v`` [m/s] (the bisections).
    depth : int
        Most bisections of a grid interval.

    Returns
    -------
    intervals : list of (a, b, n_a, n_b)
        Increasing intervals [m/s] where the number of growing roots changes (``n_a`` at
        ``a``, ``n_b`` at ``b``): every grid interval where it does and the roots' own sign
        changes agree (as the count alone), and the sub-intervals of the bisection of those
        where they disagree.
    unresolved : list of (a, b)
        Grid sub-intervals [m/s] that still disagree at the last bisection.
    """
    pos = growing(roots)
    out: list[tuple[float, float, int, int]] = []
    lost: list[tuple[float, float]] = []

    def split(a, b, wa, wb, pa, pb, level):
        na, nb = int(pa.sum()), int(pb.sum())
        agree = own_sign_changes(wa, wb, pa, pb) == abs(na - nb)
        if agree or level == 0:
            if not agree:
                lost.append((a, b))
            if na != nb:
                out.append((a, b, na, nb))
            return
        m = 0.5 * (a + b)
        wm = at(m)
        pm = growing(wm)
        split(a, m, wa, wm, pa, pm, level - 1)
        split(m, b, wm, wb, pm, pb, level - 1)

    for i in range(speeds.size - 1):
        split(float(speeds[i]), float(speeds[i + 1]), roots[i], roots[i + 1], pos[i], pos[i + 1],
              depth)  # fmt: skip
    return out, lost


def hidden_note(a: float, b: float) -> str:
    """The note of an unresolved interval ``[a, b]`` [m/s]."""
    return f"two roots cross within [{a:.6g}, {b:.6g}] m/s: refine speeds"


def stop_notes(amps, points: list, ids: list, speeds: np.ndarray, gap: float | None) -> list[str]:
    """Notes on the branches that stop before the last amplitude because they are flat.

    Parameters
    ----------
    amps : ndarray
        Amplitudes [rad] of the reference element.
    points : list of lists
        The points (``speed`` [m/s], ``frequency`` [Hz]) found at each amplitude.
    ids : list of lists
        Their branch ids.
    speeds : ndarray
        The speed grid [m/s].
    gap : float or None
        Total gap [rad] (amplitudes are said per gap), None for a cubic law.

    Returns
    -------
    list of str
        One note per branch that stops at an amplitude ``A_k`` (not the last) after its speed
        changed by more than :data:`FLAT` over the step ``A_(k-1) -> A_k`` and whose speed
        extrapolated to ``A_(k+1)`` is on the grid: where it stops, that speed, and the
        amplitudes to refine. None for a branch extrapolated off the grid (it leaves the
        speeds searched, as drawn), nor for one that meets another branch of its frequency
        (within 10 %) stopping at the same amplitude, their extrapolated speeds crossing: a
        fold in amplitude (no limit cycle of a larger amplitude there).
    """

    def amp(a: float) -> str:
        return f"{a / gap:.4g} gap" if gap else f"{a:.4g} rad"

    hist: dict[int, list] = {}
    for k, (row, bs) in enumerate(zip(points, ids, strict=True)):
        for p, b in zip(row, bs, strict=True):
            hist.setdefault(b, []).append((k, p))
    ends = []  # every branch that stops early: (branch, k, point, change, ahead, previous A)
    for b, h in sorted(hist.items()):
        k1, p1 = h[-1]
        if k1 == len(amps) - 1:
            continue
        dv, ahead, a0 = 0.0, p1.speed, amps[k1]
        if len(h) > 1:
            k0, p0 = h[-2]
            dv, a0 = p1.speed - p0.speed, amps[k0]
            ahead = p1.speed + dv * (amps[k1 + 1] - amps[k1]) / (amps[k1] - amps[k0])
        ends.append((b, k1, p1, dv, ahead, a0))
    fold = {
        s[0]
        for s in ends
        for t in ends
        if s is not t
        and s[1] == t[1]
        and abs(s[2].frequency - t[2].frequency) <= 0.1 * s[2].frequency
        and (s[2].speed - t[2].speed) * (s[4] - t[4]) < 0
    }
    stops = [e for e in ends if abs(e[3]) > FLAT * e[2].speed]
    notes = []
    for b, k1, p1, dv, ahead, a0 in stops:
        if b in fold or not speeds[0] <= ahead <= speeds[-1]:
            continue  # a fold, or it leaves the speed grid (as drawn)
        notes.append(
            f"branch {b} ({p1.frequency:.4g} Hz) stops at {amp(amps[k1])}, {p1.speed:.5g} m/s: "
            f"flat (its speed changed by {dv:+.3g} m/s from {amp(a0)}; extrapolated to "
            f"{ahead:.4g} m/s at {amp(amps[k1 + 1])}, where it is not found): refine the "
            f"amplitudes between {amp(amps[k1])} and {amp(amps[k1 + 1])}"
        )
    return notes
