"""The discrete algebraic Riccati equation, solved robustly for lightly damped structural models
(estimators, regulators, anti-windup gains)."""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ..errors import NumericalError

__all__ = ["solve_dare"]


def solve_dare(A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Stabilizing solution X of ``X = A'XA - A'XB (R + B'XB)^-1 B'XA + Q``.

    Structured doubling algorithm (Chu, Fan, Lin & Wang 2004): quadratically convergent, no
    eigenvalue reordering, hence robust for the many lightly damped structural poles close to the
    unit circle that defeat Schur/QZ-based solvers here. Solved in coordinates equilibrated by a
    diagonal similarity; the residual is checked, and that ``A - B K`` has every eigenvalue
    inside the unit circle (a non-stabilisable pair raises :class:`NumericalError` rather
    than returning a huge X).
    """
    n = A.shape[0]
    _, (t, _) = sla.matrix_balance(A, permute=False, separate=True)
    Ak = A * (1.0 / t)[:, None] * t[None, :]
    Bt = B / t[:, None]
    Gk = Bt @ np.linalg.solve(R, Bt.T)
    Hk = Q * t[:, None] * t[None, :]
    I = np.eye(n)
    A0, Q0 = Ak.copy(), Hk.copy()
    for _ in range(100):
        W = np.linalg.solve(I + Gk @ Hk, np.hstack([Ak, Gk]))
        W1, W2 = W[:, :n], W[:, n:]
        H_next = Hk + Ak.T @ Hk @ W1
        Gk = Gk + Ak @ W2 @ Ak.T
        Ak = Ak @ W1
        step = np.linalg.norm(H_next - Hk)
        Hk = 0.5 * (H_next + H_next.T)
        if step <= 1e-14 * np.linalg.norm(Hk):
            break
    # residual in the balanced coordinates, relative to the terms that cancel
    Xb = Hk
    axa = A0.T @ Xb @ A0
    S = R + Bt.T @ Xb @ Bt
    corr = A0.T @ Xb @ Bt @ np.linalg.solve(S, Bt.T @ Xb @ A0)
    res = axa - corr + Q0 - Xb
    scale = np.linalg.norm(axa) + np.linalg.norm(corr) + np.linalg.norm(Q0) + np.linalg.norm(Xb)
    if not (np.all(np.isfinite(Xb)) and np.linalg.norm(res) <= 1e-8 * scale):
        raise NumericalError(
            "discrete Riccati equation: the doubling iteration did not converge (no stabilising "
            "solution: is the pair (A, B) stabilisable?)"
        )
    # the stabilising solution: A - B K has every eigenvalue inside the unit circle (lightly
    # damped modes the gain cannot reach stay just inside; a root outside is no solution)
    rho = np.abs(np.linalg.eigvals(A0 - Bt @ np.linalg.solve(S, Bt.T @ Xb @ A0))).max()
    if not rho <= 1.0 + 1e-8:
        raise NumericalError(
            f"discrete Riccati equation: no stabilising solution (closed-loop spectral radius "
            f"{rho:.6g} > 1: the pair (A, B) is not stabilisable)"
        )
    return Xb / t[:, None] / t[None, :]
