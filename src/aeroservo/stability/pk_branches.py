"""The p-k branches versus speed, clusters of nearly repeated roots included, and the restart of
the p-k at a given onset.

Each branch is continued from the previous speed by the p-k iteration
(:meth:`aeroservo.stability.pk_frozen._PK.converge`). Branches whose roots lie within
:data:`aeroservo.stability.branches.CLUSTER` of each other (the flap modes of a control surface
without torsional stiffness: one per mesh node) are continued as one cluster, as in the
time-domain search: the frozen problem at the cluster's frequency is solved completely, its
roots are assigned to the members' predictions (optimal assignment), each member is converged
from its own root, and the cluster is accepted when its members are distinct and span the
subspace the previous ones spanned (which member is which inside it is arbitrary).

:func:`restart` solves the p-k afresh at one speed and frequency (an onset of the time-domain
search) and finds the p-k crossing next to it: the check that no root below the reported
flutter speed crosses unseen.
"""

from __future__ import annotations

import numpy as np

from .assignment import min_cost_assignment
from .branches import cluster_groups
from .brent import brentq
from .tracking import subspace_share

__all__ = ["track", "restart", "frozen_roots"]

JUMP = 0.3
"""A p-k root that moves by more than this fraction of its modulus in one step has jumped to
another solution: its branch ends."""

RESTART_STEP = 0.01
"""Speed step of the search for a p-k crossing next to a restart point [fraction of speed]."""

RESTART_RANGE = 0.3
"""How far from the restart point the p-k crossing is looked for [fraction of speed]."""


def frozen_roots(pk, V: float, w: float) -> tuple[np.ndarray, np.ndarray]:
    """All roots p (Im >= 0) and shapes q of ``(M p^2 + C(w) p + K(w)) q = 0`` with the
    aerodynamics frozen at ``w`` [rad/s] and speed ``V`` [m/s] (dense eigensolution)."""
    K, C = pk.frozen(V, w)
    n = K.shape[0]
    Minv = np.linalg.inv(pk.M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    lam, X = np.linalg.eig(A)
    keep = lam.imag >= 0
    Q = X[:n, keep]
    return lam[keep], Q / np.linalg.norm(Q, axis=0)


def track(pk, speeds: np.ndarray, p0: np.ndarray, q0: np.ndarray, error: type) -> tuple:
    """Continue the branches ``(p0, q0)`` (V = 0) over ``speeds``.

    Returns
    -------
    P : ndarray (n_speeds, m) complex
        Roots [1/s]; NaN after a branch ended.
    Q : ndarray (n_speeds, n, m) complex
        Shapes.
    ended : dict
        ``"mode j"`` -> speed [m/s] where branch j ended (no consistent p-k root).
    """
    n_speeds, m = speeds.size, p0.size
    P = np.full((n_speeds, m), complex(np.nan, np.nan))
    Q = np.zeros((n_speeds, q0.shape[0], m), dtype=complex)
    P[0], Q[0] = p0, q0
    ended: dict[str, float] = {}
    alive = np.ones(m, dtype=bool)
    for i in range(1, n_speeds):
        V = float(speeds[i])
        guess = P[i - 1] if i < 2 else 2 * P[i - 1] - P[i - 2]
        guess = np.where(np.isfinite(guess), guess, P[i - 1])
        guess = guess.real + 1j * np.abs(guess.imag)
        live = np.flatnonzero(alive)
        groups = [[int(live[g]) for g in grp] for grp in cluster_groups([P[i - 1, live]])]
        in_group = {j for g in groups for j in g}
        for j in live.tolist():
            if j in in_group:
                continue
            try:
                P[i, j], Q[i, :, j] = pk.converge(V, complex(guess[j]), Q[i - 1, :, j])
                if abs(P[i, j] - P[i - 1, j]) > JUMP * abs(P[i - 1, j]):
                    raise error("the p-k root jumped to another solution")
            except error:
                P[i, j] = complex(np.nan, np.nan)
        for g in groups:
            _cluster_step(pk, V, g, guess, P, Q, i, error)
        for j in np.flatnonzero(alive & ~np.isfinite(P[i])).tolist():
            alive[j] = False
            ended[f"mode {j + 1}"] = V  # typically a heavily damped branch
    return P, Q, ended


def _cluster_step(pk, V: float, g: list, guess: np.ndarray, P, Q, i: int, error) -> None:
    """Continue a cluster of branches ``g`` from speed index ``i - 1`` to ``i`` (NaN where
    a member fails)."""
    w = float(np.mean(np.abs(guess[g].imag)))
    roots, shapes = frozen_roots(pk, V, w)
    cost = np.abs(guess[g][:, None] - roots[None, :])
    rows, cols = min_cost_assignment(cost)
    for r, c in zip(rows.tolist(), cols.tolist(), strict=True):
        j = g[r]
        try:
            P[i, j], Q[i, :, j] = pk.converge(V, complex(roots[c]), shapes[:, c])
        except error:
            P[i, j] = complex(np.nan, np.nan)
    ok = [j for j in g if np.isfinite(P[i, j])]
    if not ok:
        return
    share = subspace_share(Q[i - 1][:, g], Q[i][:, ok])
    p = P[i, ok]
    dup = np.abs(p[:, None] - p[None, :]) <= 1e-8 * np.abs(p)[:, None]
    np.fill_diagonal(dup, False)
    moved = np.abs(p - P[i - 1, ok]) > JUMP * np.abs(P[i - 1, ok])
    for k, j in enumerate(ok):
        if share[k] < 0.5 or dup[k, :k].any() or moved[k]:
            P[i, j] = complex(np.nan, np.nan)


def restart(pk, V: float, w: float, v_max: float, rtol: float, error: type):
    """The p-k crossing next to speed ``V`` [m/s] of the root nearest ``i w`` [rad/s].

    The p-k is solved afresh at ``(V, w)`` (:func:`frozen_roots`, then the p-k iteration),
    continued in steps of :data:`RESTART_STEP` x V towards the sign change of its real part
    (at most :data:`RESTART_RANGE` x V away), and the crossing is found by Brent's method.

    Returns
    -------
    (speed [m/s], p at the crossing [1/s], rising) or None
        None: no consistent p-k root there, or no sign change within the range.
    """
    try:
        roots, shapes = frozen_roots(pk, V, w)
        c = int(np.argmin(np.abs(roots - 1j * w)))
        p, q = pk.converge(V, complex(roots[c]), shapes[:, c])
        step = RESTART_STEP * V * (1.0 if p.real < 0 else -1.0)
        v0, p0, q0 = V, p, q
        for _ in range(int(RESTART_RANGE / RESTART_STEP)):
            v1 = min(max(v0 + step, 1e-6 * V), v_max)
            if v1 == v0:
                return None
            p1, q1 = pk.converge(v1, p0, q0)
            if (p1.real < 0) != (p0.real < 0):
                lo, hi = (v0, v1) if v0 < v1 else (v1, v0)
                p_lo, q_lo = (p0, q0) if v0 < v1 else (p1, q1)

                def re_p(v: float, p_lo=p_lo, q_lo=q_lo) -> float:
                    return pk.converge(v, p_lo, q_lo)[0].real

                vs = brentq(re_p, lo, hi, xtol=rtol * hi, rtol=1e-15)
                pc = pk.converge(vs, p_lo, q_lo)[0]
                return float(vs), pc, bool(p_lo.real < 0)
            v0, p0, q0 = v1, p1, q1
    except (error, np.linalg.LinAlgError, ValueError):
        return None
    return None
