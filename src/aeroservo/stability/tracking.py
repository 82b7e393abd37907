"""Eigenpair correction on the full model: ``(A0 + V A1 + V^2 A2) x = lambda E x`` at one speed.

The stability sweep runs on a modal model (:mod:`aeroservo.stability.branches`); every decision
that depends on the sign of a real part near the imaginary axis is made on the full model, by
shifted inverse iteration started from the modal model's eigenpair, or block inverse
iteration for a cluster of nearly repeated eigenvalues (one LU of
``A(V) - sigma E`` per correction, LAPACK for small systems and SuperLU for large ones,
re-shifted when convergence is slow).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.linalg.lapack import zgetrf, zgetrs

from ..system.first_order import FirstOrderSystem
from .assignment import min_cost_assignment

__all__ = ["EigenTracker", "mac", "subspace_share"]

DENSE_LIMIT = 200
"""Systems up to this many states use dense LU; larger ones use sparse LU (SuperLU)."""


CLUSTER_GUARD = 2
"""Extra vectors of the block that converges a cluster of nearly repeated eigenpairs."""

CLUSTER_ITERATIONS = 40
"""Largest number of block inverse iterations for a cluster."""


def mac(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Modal assurance criterion |x^H y|^2 / (|x|^2 |y|^2), column-wise for 2-D inputs."""
    num = np.abs(np.sum(np.conj(x) * y, axis=0)) ** 2
    den = np.sum(np.abs(x) ** 2, axis=0) * np.sum(np.abs(y) ** 2, axis=0)
    return num / den


class EigenTracker:
    """Eigenpair correction of one :class:`FirstOrderSystem` (the full model).

    Parameters
    ----------
    system : FirstOrderSystem
    tol : float
        Relative residual ``|(A - lam E) x| / (|A x| + |lam| |E x|)`` accepted as converged.
        An eigenvalue that no longer changes (1e-10 relative) with a residual below 1e-6 is
        accepted too: for fine meshes the residual floor is set by the conditioning of the
        stiffness matrix, not by the eigenvalue's accuracy.
    mac_min : float
        Minimum eigenvector correlation between consecutive speeds.
    """

    def __init__(self, system: FirstOrderSystem, tol: float = 1e-11, mac_min: float = 0.8):
        self.system = system
        self.tol = tol
        self.mac_min = mac_min
        self.n_q = system.n_q
        self.dense = system.n_states <= DENSE_LIMIT
        if self.dense:
            # a complex E: a mixed real-complex product would convert E at every iteration
            e, *self._A = system.dense_pencil()
            self._E = e.astype(complex)
            self._E_nz = np.nonzero(e)  # the shift A - sigma E changes only these entries
        else:
            self._E = system.E.tocsc()
            self._A = tuple(a.tocsc() for a in (system.A0, system.A1, system.A2))
        self.n_factorizations = 0

    # -- linear algebra -------------------------------------------------------------------
    def _pencil(self, speed: float):
        a0, a1, a2 = self._A
        out = a0 + speed * a1 + (speed * speed) * a2
        return out.astype(complex) if self.dense else out

    def _shifted(self, A, sigma: complex):
        """``A - sigma E`` (dense: a copy of A with E's entries shifted)."""
        if not self.dense:
            return A - sigma * self._E
        out = A.copy()
        out[self._E_nz] -= sigma * self._E[self._E_nz]
        return out

    def _factor(self, A, sigma: complex) -> Callable[[np.ndarray], np.ndarray]:
        """LU of ``A - sigma E``: LAPACK for dense systems, SuperLU for sparse ones."""
        self.n_factorizations += 1
        if self.dense:
            lu, piv, info = zgetrf(self._shifted(A, sigma), overwrite_a=True)
            if info > 0:  # the shift is an exact eigenvalue: nudge it
                lu, piv, info = zgetrf(
                    self._shifted(A, sigma * (1 + 1e-12) + 1e-12), overwrite_a=True
                )
            return lambda b: zgetrs(lu, piv, b)[0]
        from scipy.sparse.linalg import splu

        return splu(self._shifted(A, sigma).astype(complex).tocsc()).solve

    def correct(
        self, speed: float, lam0: complex, x0: np.ndarray
    ) -> tuple[complex, np.ndarray, bool]:
        """Converge the eigenpair nearest to ``(lam0, x0)`` at ``speed``.

        Returns
        -------
        lam : complex
        x : ndarray
            Unit eigenvector, phase aligned with ``x0``.
        converged : bool
        """
        lam, X, conv = self.correct_many(speed, np.array([lam0]), np.asarray(x0)[:, None])
        return complex(lam[0]), X[:, 0], bool(conv[0])

    def correct_many(
        self, speed: float, lam0: np.ndarray, X0: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Converge several eigenpairs (columns of ``X0``) at ``speed``.

        Returns
        -------
        lam : ndarray (m,) complex
        X : ndarray (n, m) complex
            Unit eigenvectors, phase aligned with ``X0``.
        converged : ndarray (m,) bool
        """
        A = self._pencil(speed)
        m = len(lam0)
        lam = np.empty(m, dtype=complex)
        X = np.empty((X0.shape[0], m), dtype=complex)
        conv = np.zeros(m, dtype=bool)
        for j in range(m):
            lam[j], X[:, j], conv[j] = self._inverse_iteration(A, complex(lam0[j]), X0[:, j])
            ph = np.vdot(X0[:, j], X[:, j])
            if ph != 0:
                X[:, j] *= abs(ph) / ph
        return lam, X, conv

    def _inverse_iteration(self, A, lam0: complex, x0: np.ndarray, max_shifts: int = 6):
        """Shifted inverse iteration; the shift moves to the estimate when progress is slow.

        The residual is evaluated only once the eigenvalue estimate has settled.
        """
        E = self._E
        x = np.asarray(x0, dtype=complex)
        x = x / _norm(x)
        sigma = lam = lam0
        for _shift in range(max_shifts):
            solve = self._factor(A, sigma)
            prev_dl = np.inf
            for _it in range(10):
                y = solve(E @ x)
                lam_new = sigma + 1.0 / np.vdot(x, y)
                x = y / _norm(y)
                dl = abs(lam_new - lam) / abs(lam_new)
                lam = lam_new
                if dl < 1e-9:
                    ax = A @ x
                    ex = E @ x
                    res = _norm(ax - lam * ex) / (_norm(ax) + abs(lam) * _norm(ex))
                    if res < self.tol or (dl <= 1e-10 and res < 1e-6):
                        return lam, x, True
                if dl > 0.2 * prev_dl:
                    break  # slow: move the shift to the current estimate
                prev_dl = dl
            sigma = lam
        return lam, x, False

    def correct_cluster(
        self, speed: float, lam0: np.ndarray, X0: np.ndarray, guard: int = CLUSTER_GUARD
    ) -> tuple[np.ndarray, np.ndarray, bool]:
        """Converge a cluster of nearly repeated eigenpairs as one invariant subspace.

        Inside a cluster whose spread is below the error of the starting pairs, each starting
        vector is an arbitrary mixture of the cluster's eigenvectors, so one-vector inverse
        iteration converges to whichever member it likes (two of them to the same one, and a
        member is never checked). Here the block ``[X0, guard vectors]`` is iterated with one
        LU of ``A - sigma E`` (sigma: the cluster's centre) until the Ritz pairs of
        ``(A - sigma E)^-1 E`` on its span are eigenpairs; the ``p`` Ritz values nearest to
        ``lam0`` (optimal assignment) are the cluster's. The convergence factor per iteration is
        the cluster's distance to sigma over that of the first eigenvalue outside the block.

        Parameters
        ----------
        speed : float
            [m/s]
        lam0 : ndarray (p,)
            Starting eigenvalues [1/s] (the cluster's modal values, or predictions).
        X0 : ndarray (n, p)
            Starting vectors (full-model states).
        guard : int
            Extra block vectors besides ``p`` more (they absorb eigenvalues near the cluster
            that the starting values lack: a cluster often sits among more eigenvalues of the
            same spacing).

        Returns
        -------
        lam : ndarray (p,) complex
            The eigenvalues assigned to the starting values, in their order.
        X : ndarray (n, p) complex
            Unit eigenvectors.
        converged : bool
            Every assigned pair has a residual below ``tol`` (or below 1e-4 with the
            eigenvalues settled to 1e-10).
        """
        A = self._pencil(speed)
        lam0 = np.asarray(lam0, dtype=complex)
        p = lam0.size
        n = X0.shape[0]
        rng = np.random.default_rng(p)  # deterministic guard vectors
        guard = guard + p  # a cluster sits among more eigenvalues of the same spacing
        block = np.hstack([X0, rng.standard_normal((n, guard)) + 0j])
        Q = np.linalg.qr(block)[0]
        spread = float(np.max(np.abs(lam0 - lam0.mean()))) if p > 1 else 0.0
        sigma = lam0.mean() + 0.5j * spread  # off the cluster's members
        solve = self._factor(A, sigma)
        E = self._E
        prev = None
        lam = lam0
        X = X0
        for _ in range(CLUSTER_ITERATIONS):
            Y = solve(E @ Q)
            theta, S = np.linalg.eig(Q.conj().T @ Y)
            ok = np.abs(theta) > 1e-300
            ritz = np.full(theta.shape, np.inf + 0j)
            ritz[ok] = sigma + 1.0 / theta[ok]
            cost = np.abs(lam0[:, None] - ritz[None, :])
            rows, cols = min_cost_assignment(cost)
            pick = cols[np.argsort(rows)]
            lam = ritz[pick]
            X = Q @ S[:, pick]
            X = X / np.sqrt(np.einsum("ij,ij->j", X.conj(), X).real)
            AX = A @ X
            EX = E @ X
            res = np.sqrt(np.einsum("ij,ij->j", (AX - EX * lam).conj(), AX - EX * lam).real) / (
                np.linalg.norm(AX, axis=0) + np.abs(lam) * np.linalg.norm(EX, axis=0)
            )
            settled = prev is not None and bool(np.all(np.abs(lam - prev) <= 1e-10 * np.abs(lam)))
            # the Ritz values of a non-normal cluster (heavily damped, nearly defective
            # members) settle long before its vectors: settled values are accepted with a
            # residual up to 1e-4 (dense eig agrees with them to 1e-8 on the corpus)
            if np.all(res < self.tol) or (settled and np.all(res < 1e-4)):
                return lam, X, True
            prev = lam
            Q = np.linalg.qr(Y)[0]
        return lam, X, False

    def follow(
        self, speed: float, lam0: complex, x0: np.ndarray, v0: float
    ) -> tuple[complex, np.ndarray]:
        """Eigenpair at ``speed`` continued from a converged pair ``(lam0, x0)`` at ``v0``.

        Used by root finding inside a bracket: a direct correction, falling back to sub-steps
        if the correction fails or loses correlation.
        """
        lam, x, conv = self.correct(speed, lam0, x0)
        if conv and mac(x0[: self.n_q], x[: self.n_q]) >= self.mac_min:
            return lam, x
        n_sub = 4
        lam_c, x_c = lam0, x0
        for k in range(1, n_sub + 1):
            v = v0 + (speed - v0) * k / n_sub
            lam_c, x_c, conv = self.correct(v, lam_c, x_c)
            if not conv:
                raise RuntimeError(f"eigenpair could not be followed to V = {speed:.6g} m/s")
        return lam_c, x_c


def subspace_share(B: np.ndarray, X: np.ndarray) -> np.ndarray:
    """Fraction of each column of X in the span of the columns of B (1: inside it): the
    subspace form of the MAC, for a cluster of nearly repeated eigenvalues."""
    Q = np.linalg.qr(B)[0]
    inside = np.sum(np.abs(Q.conj().T @ X) ** 2, axis=0)
    return inside / np.sum(np.abs(X) ** 2, axis=0)


def _norm(x: np.ndarray) -> float:
    """2-norm of a complex vector (cheaper than ``np.linalg.norm`` for the small vectors here)."""
    return float(np.sqrt(np.vdot(x, x).real))


def _has_duplicates(lam: np.ndarray) -> bool:
    if lam.size < 2:
        return False
    d = np.abs(lam[:, None] - lam[None, :])
    d[np.diag_indices(lam.size)] = np.inf
    scale = np.maximum(np.abs(lam)[:, None], np.abs(lam)[None, :]) + 1e-12
    return bool(np.any(d < 1e-7 * scale))
