"""Continuation of selected eigenpairs of ``(A0 + V A1 + V^2 A2) x = lambda E x`` in speed.

Each tracked eigenpair is corrected at a new speed by shifted inverse iteration started from
an extrapolated prediction (one LU of ``A(V) - sigma E`` per mode and step, LAPACK for small
systems and SuperLU for large ones, re-shifted when convergence is slow). A step is accepted
only when every mode converged, its eigenvector correlates with the previous one (MAC above a
threshold) and no two modes landed on the same eigenvalue; otherwise the step is halved.
Branches therefore never swap where frequencies cross, and the cost grows with the number of
tracked modes, not with the size of the model.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.linalg.lapack import zgetrf, zgetrs

from ..system.first_order import FirstOrderSystem

__all__ = ["EigenTracker", "TrackedModes", "mac"]

DENSE_LIMIT = 200
"""Systems up to this many states use dense LU; larger ones use sparse LU (SuperLU)."""


def mac(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Modal assurance criterion |x^H y|^2 / (|x|^2 |y|^2), column-wise for 2-D inputs."""
    num = np.abs(np.sum(np.conj(x) * y, axis=0)) ** 2
    den = np.sum(np.abs(x) ** 2, axis=0) * np.sum(np.abs(y) ** 2, axis=0)
    return num / den


@dataclass
class TrackedModes:
    """Eigenvalues of tracked modes on a speed grid.

    Attributes
    ----------
    speeds : ndarray (n_speeds,)
        Airspeeds [m/s], increasing.
    eigenvalues : ndarray (n_speeds, n_modes) complex
        Eigenvalues [1/s]; Im >= 0 for the tracked member of each complex pair.
    vectors : ndarray (n_speeds, n_states, n_modes) complex
        Unit state eigenvectors.
    """

    speeds: np.ndarray
    eigenvalues: np.ndarray
    vectors: np.ndarray


class EigenTracker:
    """Eigenpair correction and continuation for one :class:`FirstOrderSystem`.

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
            # complex copies: mixed real-complex products would convert at every iteration
            self._E = system.E.toarray().astype(complex)
            self._A = tuple(a.toarray().astype(complex) for a in (system.A0, system.A1, system.A2))
        else:
            self._E = system.E.tocsc()
            self._A = tuple(a.tocsc() for a in (system.A0, system.A1, system.A2))
        self.n_factorizations = 0

    # -- linear algebra -------------------------------------------------------------------
    def _pencil(self, speed: float):
        a0, a1, a2 = self._A
        return a0 + speed * a1 + (speed * speed) * a2

    def _factor(self, A, sigma: complex) -> Callable[[np.ndarray], np.ndarray]:
        """LU of ``A - sigma E``: LAPACK for dense systems, SuperLU for sparse ones."""
        self.n_factorizations += 1
        if self.dense:
            lu, piv, info = zgetrf(A - sigma * self._E, overwrite_a=True)
            if info > 0:  # the shift is an exact eigenvalue: nudge it
                lu, piv, info = zgetrf(
                    A - (sigma * (1 + 1e-12) + 1e-12) * self._E, overwrite_a=True
                )
            return lambda b: zgetrs(lu, piv, b)[0]
        from scipy.sparse.linalg import splu

        return splu((A - sigma * self._E).astype(complex).tocsc()).solve

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

    # -- continuation ---------------------------------------------------------------------
    def track(
        self,
        v_max: float,
        lam0: np.ndarray,
        X0: np.ndarray,
        *,
        h_init: float | None = None,
        h_max: float | None = None,
        max_rel_change: float = 0.1,
        pred_tol: float = 1e-2,
        progress: Callable[[float], None] | None = None,
    ) -> TrackedModes:
        """Follow eigenpairs ``(lam0, X0)`` given at V = 0 up to ``v_max`` [m/s].

        The step adapts so that no eigenvalue moves by more than ``max_rel_change`` of its
        modulus between consecutive speeds (this bounds how far a hump can hide between grid
        points), so that the linear predictor misses by at most about ``pred_tol`` of the
        modulus (fine steps where a branch bends), and never exceeds ``h_max`` (default
        ``v_max / 15``).
        """
        h_max = h_max or v_max / 15.0
        h = h_init or v_max / 30.0
        h_min = v_max * 1e-7
        speeds = [0.0]
        lams = [np.asarray(lam0, dtype=complex)]
        vecs = [np.asarray(X0, dtype=complex)]
        V = 0.0
        while V < v_max * (1 - 1e-12):
            h = min(h, v_max - V)
            V1 = V + h
            if len(speeds) >= 2:
                slope = (lams[-1] - lams[-2]) / (speeds[-1] - speeds[-2])
                lam_pred = lams[-1] + slope * h
            else:
                lam_pred = lams[-1]
            new_l, new_x, conv = self.correct_many(V1, lam_pred, vecs[-1])
            ok = bool(conv.all())
            if ok:
                corr = mac(vecs[-1][: self.n_q], new_x[: self.n_q])
                ok = bool(np.all(corr >= self.mac_min)) and not _has_duplicates(new_l)
            scale = np.maximum(np.abs(lams[-1]), 1e-3 * np.max(np.abs(lams[-1])) + 1e-12)
            change = np.max(np.abs(new_l - lams[-1]) / scale) if ok else np.inf
            miss = np.max(np.abs(new_l - lam_pred) / scale) if ok else np.inf
            if not ok or (change > 2 * max_rel_change and h > h_min):
                h *= 0.5
                if h < h_min:
                    raise RuntimeError(
                        f"eigenvalue tracking failed near V = {V:.6g} m/s: a tracked mode could "
                        "not be continued (coalescing eigenvalues?)"
                    )
                continue
            flip = new_l.imag < 0  # keep the Im >= 0 member of a pair
            new_l[flip] = np.conj(new_l[flip])
            new_x[:, flip] = np.conj(new_x[:, flip])
            speeds.append(V1)
            lams.append(new_l)
            vecs.append(new_x)
            V = V1
            if progress is not None:
                progress(V)
            # the change grows like h and the predictor miss like h^2: aim at both targets
            factor = min(
                0.9 * max_rel_change / max(change, 1e-12),
                0.9 * np.sqrt(pred_tol / max(miss, 1e-12)),
            )
            h = min(h * float(np.clip(factor, 0.5, 2.0)), h_max)
        return TrackedModes(np.array(speeds), np.array(lams), np.array(vecs))

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
