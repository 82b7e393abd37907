"""Branches of the modal model's eigenvalues versus speed, by a dense eigensolution at every step.

At each speed every eigenvalue of the (small) modal model is computed with dense ``eig``, so no
eigenvalue can be lost and nothing has to converge: a pair that meets its partner on the real
axis and splits into two real roots (an exceptional point), a double real root or an
overdamped mode needs no special treatment. Branches (one per mode at rest) are then matched
between consecutive speeds by an optimal assignment on the distance to a linear prediction; a
step is accepted when every complex branch is matched unambiguously, moved by less than a
fraction of its modulus and correlates with its previous eigenvector, else it is halved. A branch
far from the imaginary axis (damping ratio beyond :data:`FAR_ZETA` at both ends of the step) may
move twice as far: a crossing hidden between two grid points would need it to travel at least
its distance to the axis.
Where a branch is real (overdamped) its identity is that of the nearest real root and no
ambiguity test applies: flutter crossings happen off the real axis, real roots cross zero only
at the static divergence speeds (:mod:`aeroservo.stability.divergence`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..system.first_order import FirstOrderSystem
from .assignment import min_cost_assignment
from .tracking import subspace_share

__all__ = ["Branches", "sweep_branches", "is_complex", "cluster", "cluster_groups", "CLUSTER"]

COMPLEX = 1e-7
"""A branch is complex (oscillatory) where ``Im(lambda) > COMPLEX |lambda|``."""


FAR_ZETA = 0.25
"""Branches whose ``|damping ratio|`` exceeds this at both ends of a step count half their change
in the step control (:func:`sweep_branches`)."""


CLUSTER = 1e-2
"""Oscillatory branches whose eigenvalues lie within this fraction of their modulus of each
other (transitively) form a cluster of nearly repeated eigenvalues (e.g. the flap modes of a
control surface without torsional stiffness: one per mesh node). The modal error (up to about
1e-2 of the modulus on fine meshes) then exceeds their separation, so each modal eigenvector is
an arbitrary mixture of the cluster's full-model eigenvectors: a cluster is matched, verified
and followed as one invariant subspace, not member by member."""


def cluster_groups(rows: Sequence[np.ndarray]) -> list[list[int]]:
    """Clusters (of two or more branches) of the branch eigenvalues in any of the rows: two
    oscillatory branches within :data:`CLUSTER` of each other in one row are in one cluster."""
    m = rows[0].size
    near = np.zeros((m, m), dtype=bool)
    for lam in rows:
        osc = is_complex(lam)
        close = np.abs(lam[:, None] - lam[None, :]) <= CLUSTER * np.abs(lam)[:, None]
        near |= close & osc[:, None] & osc[None, :]
    np.fill_diagonal(near, False)
    groups, seen = [], np.zeros(m, dtype=bool)
    for j in np.flatnonzero(near.any(axis=1)).tolist():
        if seen[j]:
            continue
        group, todo = {j}, [j]
        while todo:
            for n in np.flatnonzero(near[todo.pop()]).tolist():
                if n not in group:
                    group.add(n)
                    todo.append(n)
        seen[list(group)] = True
        groups.append(sorted(group))
    return groups


def cluster(rows: Sequence[np.ndarray], j: int) -> list[int]:
    """Branch j's cluster in the rows (:func:`cluster_groups`), or ``[j]``."""
    return next((g for g in cluster_groups(rows) if j in g), [j])


def is_complex(lam: np.ndarray) -> np.ndarray:
    """Whether eigenvalues are oscillatory (``Im > COMPLEX |lambda|``)."""
    lam = np.asarray(lam)
    return lam.imag > COMPLEX * np.abs(lam)


@dataclass
class Branches:
    """Modal-model eigenvalues along each branch on the accepted speed grid.

    Attributes
    ----------
    speeds : ndarray (n,)
        [m/s], increasing, from 0.
    eigenvalues : ndarray (n, m) complex
        Branch eigenvalues [1/s] (Im >= 0).
    vectors : ndarray (n, n_states, m) complex
        Unit eigenvectors of the modal model.
    spectra : list of ndarray
        Every eigenvalue of the modal model at each speed (the certificate compares them).
    n_ambiguous : int
        Steps accepted at the smallest step with an ambiguous match (near coalescences).
    stopped : str or None
        Why the sweep ended before ``v_max`` (None: it reached it).
    """

    speeds: np.ndarray
    eigenvalues: np.ndarray
    vectors: np.ndarray
    spectra: list
    n_ambiguous: int = 0
    stopped: str | None = None

    @property
    def n_speeds(self) -> int:
        return self.speeds.size


def _predict(speeds: list, lams: list, v: float) -> np.ndarray:
    """Branch eigenvalues at ``v`` extrapolated from the last (up to) three accepted speeds
    (Lagrange polynomial: constant, linear, then quadratic)."""
    n = min(len(speeds), 3)
    xs, ys = speeds[-n:], lams[-n:]
    out = None
    for i in range(n):
        weight = 1.0
        for j in range(n):
            if j != i:
                weight *= (v - xs[j]) / (xs[i] - xs[j])
        term = weight * ys[i]
        out = term if out is None else out + term
    return out


def _scale(lam: np.ndarray) -> np.ndarray:
    """Per-branch scale of eigenvalue distances: the modulus, at least 1e-3 of the largest."""
    mod = np.abs(lam)
    return np.maximum(mod, 1e-3 * np.max(mod) + 1e-12)


def _far(lam: np.ndarray) -> np.ndarray:
    """Whether eigenvalues are far from the imaginary axis (``|Re| > FAR_ZETA |lambda|``)."""
    return np.abs(lam.real) > FAR_ZETA * np.abs(lam)


def sweep_branches(
    system: FirstOrderSystem,
    lam0: np.ndarray,
    X0: np.ndarray,
    v_max: float,
    *,
    forced: Sequence[float] = (),
    progress: Callable[[float], None] | None = None,
    max_rel_change: float = 0.1,
    pred_tol: float = 1e-2,
    mac_min: float = 0.5,
) -> Branches:
    """Follow the branches starting at ``(lam0, X0)`` (V = 0) up to ``v_max`` [m/s].

    Parameters
    ----------
    system : FirstOrderSystem
        The (modal) model; its dense state matrix is solved at every step.
    lam0, X0 : ndarray
        Branch eigenvalues and eigenvectors at V = 0.
    v_max : float
        Upper speed [m/s].
    forced : sequence of float
        Speeds that must be grid points (checkpoints).
    progress : callable, optional
        Called with each accepted speed.
    max_rel_change : float
        Largest change of a branch eigenvalue per step relative to its modulus (bounds how far
        a hump can hide between grid points); twice that for a branch far from the axis
        (:data:`FAR_ZETA`).
    pred_tol : float
        Target miss of the linear predictor relative to the modulus (fine steps where a branch
        bends).
    mac_min : float
        Smallest eigenvector correlation of a complex branch between consecutive speeds.
    """
    a0, a1, a2 = system.state_matrix_terms()
    h_max = v_max / 15.0
    h = v_max / 30.0
    h_min = v_max * 1e-6
    h_ambiguous = v_max * 1e-4  # below this, an ambiguous match is accepted (coalescence)
    stops = sorted({float(v) for v in forced if 0.0 < v < v_max} | {float(v_max)})
    speeds = [0.0]
    lams = [np.asarray(lam0, dtype=complex)]
    vecs = [np.asarray(X0, dtype=complex)]
    n_amb = 0
    V = 0.0
    w_all = [np.concatenate([lams[0], np.conj(lams[0])])]
    # of the last accepted speed: distance scale, oscillatory, far from the axis
    scale, osc_prev, far_prev = _scale(lams[0]), is_complex(lams[0]), _far(lams[0])
    while V < v_max * (1 - 1e-12):
        nxt = next(s for s in stops if s > V * (1 + 1e-12))
        # a checkpoint within 10 % beyond the step is reached in this step (no sliver step)
        V1 = nxt if nxt - V - 1.1 * h < 1e-9 * v_max else V + h
        try:
            w, X = np.linalg.eig(a0 + V1 * a1 + (V1 * V1) * a2)
            w, X = w.astype(complex, copy=False), X.astype(complex, copy=False)
        except (ValueError, np.linalg.LinAlgError) as exc:
            return _done(
                speeds, lams, vecs, w_all, n_amb, f"eigensolution failed at {V1:.6g} m/s ({exc})"
            )
        if not np.isfinite(w).all():
            return _done(
                speeds, lams, vecs, w_all, n_amb, f"non-finite eigenvalues at {V1:.6g} m/s"
            )
        cand = np.flatnonzero(w.imag >= 0)
        prev = lams[-1]
        pred = _predict(speeds, lams, V1)
        cost = np.abs(w[cand][None, :] - pred[:, None]) / scale[:, None]
        rows, cols = min_cost_assignment(cost)
        pick = np.empty(prev.size, dtype=int)
        pick[rows] = cand[cols]
        new_l = w[pick]
        new_x = X[:, pick]
        new_x = new_x / np.sqrt(np.einsum("ij,ij->j", new_x.conj(), new_x).real)
        osc_new, far_new = is_complex(new_l), _far(new_l)
        osc = osc_new & osc_prev
        weight = np.where(far_prev & far_new, 0.5, 1.0)
        change = float((np.abs(new_l - prev) / scale * weight).max())
        miss = float((np.abs(new_l - pred) / scale).max())
        slow = change <= 2 * max_rel_change
        ok = slow
        if ok and osc.any():
            d1 = cost[rows, cols]
            c2 = cost.copy()
            c2[rows, cols] = np.inf
            corr = np.abs(np.einsum("ij,ij->j", vecs[-1].conj(), new_x)) ** 2  # unit vectors
            # a cluster is matched as a whole: which member is which inside it is arbitrary
            # (only the candidates outside it make a match ambiguous), and its eigenvectors
            # must span the subspace the previous ones spanned
            for g in cluster_groups([prev, new_l]):
                rg = np.flatnonzero(np.isin(rows, g))
                c2[np.ix_(rows[rg], cols[rg])] = np.inf
                corr[g] = subspace_share(vecs[-1][:, g], new_x[:, g])
            d2 = c2.min(axis=1) if c2.shape[1] > 1 else np.full(rows.size, np.inf)
            clear = d1 <= 0.5 * d2 + 1e-12
            ok = bool(clear[osc[rows]].all()) and bool((corr[osc] >= mac_min).all())
        if not ok and (h > h_ambiguous or (not slow and h > h_min)):
            h = 0.5 * min(h, V1 - V)
            continue
        n_amb += not ok
        speeds.append(V1)
        lams.append(new_l)
        vecs.append(new_x)
        w_all.append(w)
        V = V1
        scale, osc_prev, far_prev = _scale(new_l), osc_new, far_new
        if progress is not None:
            progress(V)
        # the next step scales the one just taken (a step cut short to reach a checkpoint
        # does not shrink the next); the predictor's miss grows as h^order
        order = 3.0 if len(speeds) >= 4 else 2.0
        factor = min(
            0.9 * max_rel_change / max(change, 1e-12),
            0.9 * (pred_tol / max(miss, 1e-12)) ** (1.0 / order),
        )
        h = min(max(h, V1 - speeds[-2]) * min(max(factor, 0.5), 2.0), h_max)
    return _done(speeds, lams, vecs, w_all, n_amb, None)


def _done(speeds, lams, vecs, w_all, n_amb, stopped) -> Branches:
    return Branches(
        speeds=np.array(speeds),
        eigenvalues=np.array(lams),
        vectors=np.array(vecs),
        spectra=list(w_all),
        n_ambiguous=n_amb,
        stopped=stopped,
    )
