"""Which case of a trade study is best, and the quantities the ranking and the figures share.

A closed-loop study ranks its cases by the suppression margin ``V_cl / V_ol - 1`` among the
cases whose closed loop is stable at the design speed; a case stable up to the end of the
closed-loop search has no closed-loop flutter speed, only the bound ``v_max / V_ol - 1`` on its
margin, and is ranked with that bound. Ties (e.g. several cases stable to the search limit)
go to the lowest peak hinge moment in the gust, so the best case is always on the Pareto front
of margin against hinge moment. An open-loop study ranks by the open-loop flutter speed.
"""

from __future__ import annotations

import numpy as np

__all__ = ["BEST_CRITERION", "best_index", "effective_margin", "is_closed_loop", "saturated"]

BEST_CRITERION = {
    True: "highest suppression margin, stable at the design speed; ties: lowest peak hinge moment",
    False: "highest open-loop flutter speed",
}
"""What "best" means, by whether the study is closed loop."""


def _column(table, name: str) -> np.ndarray:
    return table[name].to_numpy(dtype=float)


def is_closed_loop(table, settings: dict | None = None) -> bool:
    """Whether the study designed controllers (its settings say so; otherwise its table)."""
    if settings and "closed_loop" in settings:
        return bool(settings["closed_loop"])
    return bool(np.isfinite(_column(table, "design_speed")).any())


def effective_margin(table) -> tuple[np.ndarray, np.ndarray]:
    """The suppression margin [-] of each case and where it is only a lower bound.

    Returns
    -------
    margin : ndarray
        ``V_cl / V_ol - 1``; for a case stable up to the end of the closed-loop search
        ``v_max / V_ol - 1``; NaN where neither exists (failed, open loop).
    at_least : ndarray of bool
        True where ``margin`` is that lower bound.
    """
    ok = (table["status"] == "ok").to_numpy()
    margin = _column(table, "suppression_margin").copy()
    v_max = _column(table, "closed_loop_v_max")
    at_least = (
        ok & ~np.isfinite(margin) & (_column(table, "stable_at_design") == 1.0) & np.isfinite(v_max)
    )
    v_ol = _column(table, "open_loop_flutter_speed")
    margin[at_least] = v_max[at_least] / v_ol[at_least] - 1.0
    return margin, at_least


def saturated(table) -> np.ndarray:
    """Cases whose control sat on its magnitude limit in the gust (some samples at the limit)."""
    return _column(table, "hinge_moment_saturation") > 0.0


def best_index(table, closed_loop: bool) -> int | None:
    """Row of the best case (:data:`BEST_CRITERION`), or None if no case qualifies."""
    ok = (table["status"] == "ok").to_numpy().copy()
    if closed_loop:
        score, _ = effective_margin(table)
        ok &= _column(table, "stable_at_design") == 1.0
        tie = _column(table, "hinge_moment_peak")
    else:
        score = _column(table, "open_loop_flutter_speed")
        tie = np.zeros(len(score))
    ok &= np.isfinite(score)
    score = np.round(score, 9)  # bounds v_max / V_ol - 1 of different cases tie
    if not ok.any():
        return None
    tie = np.where(np.isfinite(tie), tie, np.inf)
    rows = np.flatnonzero(ok)
    # highest score first, then lowest tie-breaker, then grid order
    order = np.lexsort((rows, tie[rows], -score[rows]))
    return int(rows[order[0]])
