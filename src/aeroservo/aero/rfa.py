"""Rational-function approximations (RFA) of frequency-domain aerodynamic forces.

Generalized aerodynamic forces tabulated at reduced frequencies, ``Q(ik)`` (``k = omega b /
V`` on a reference semichord b), are approximated in the Laplace variable ``p = s b / V`` so
that they can be written in the time domain with aerodynamic lag states:

* **Roger** (Roger 1977): ``Q(p) ~ A0 + A1 p + A2 p^2 + sum_j B_j p / (p + g_j)``, one
  matrix ``B_j`` per lag root ``g_j`` (a lag state per root and per column);
* **minimum-state** (Karpel 1982): ``Q(p) ~ A0 + A1 p + A2 p^2 + D (p I - R)^-1 E p``,
  ``R = -diag(g)``: one lag state per root for the whole matrix, ``D`` and ``E`` found by the
  alternating least squares of Karpel's method (Tiffany and Adams 1988 review the variants);
* **lag only** (gust columns, whose input has no derivatives in the time domain):
  ``Q(p) ~ C0 + sum_j C_j p / (p + g_j)``.

``A0`` is the steady value ``Q(0)`` exactly when k = 0 is tabulated (divergence and trim then
equal the steady theory's). With ``dissipative`` (the size of the leading square block of the
structural unknowns, in mass-normalized modal coordinates) the fit keeps the high-frequency
behaviour of potential flow, which a least-squares fit over a finite k range does not: the
symmetric parts of the apparent mass ``-A2`` and of the damping ``-A1`` are made positive
semi-definite (no motion loses mass, every motion is damped at high frequency, where the lag
terms vanish; their antisymmetric parts, the circulatory coupling the fit puts there, are kept),
and the lag terms are then fitted again with these two held.

Default lag roots (:func:`lag_roots`): ``g_j = 1.7 k_max (j / (n + 1))^2``, spread over the
tabulated range (Tiffany and Adams 1988).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, NumericalError

__all__ = ["RationalFit", "fit_roger", "fit_minimum_state", "fit_lags", "lag_roots", "RFA_KINDS"]

RFA_KINDS = ("roger", "minimum-state")


def lag_roots(k_max: float, n: int) -> np.ndarray:
    """Default lag roots ``1.7 k_max (j / (n + 1))^2``, j = 1..n [-]."""
    j = np.arange(1, n + 1)
    return 1.7 * float(k_max) * (j / (n + 1.0)) ** 2


@dataclass(frozen=True)
class RationalFit:
    """A rational-function approximation ``Q(p)`` (module notes).

    Attributes
    ----------
    kind : {"roger", "minimum-state", "lags"}
    roots : ndarray (n_r,)
        Lag roots g_j [-] (poles at ``p = -g_j``).
    A0, A1, A2 : ndarray (rows, cols)
        Steady, damping and apparent-mass terms (zero for ``"lags"`` except ``A0 = C0``).
    B : ndarray (n_r, rows, cols) or None
        Roger and lag-only lag matrices.
    D : ndarray (rows, n_r) or None
    E : ndarray (n_r, cols) or None
        Minimum-state matrices.
    """

    kind: str
    roots: np.ndarray
    A0: np.ndarray
    A1: np.ndarray
    A2: np.ndarray
    B: np.ndarray | None = None
    D: np.ndarray | None = None
    E: np.ndarray | None = None

    @property
    def n_lag_states(self) -> int:
        """Lag states of the time-domain model: roots x columns (Roger), roots (minimum-state)."""
        if self.kind == "minimum-state":
            return int(self.roots.size)
        return int(self.roots.size * self.A0.shape[1])

    def __call__(self, k: np.ndarray) -> np.ndarray:
        """``Q(ik)`` of the approximation at reduced frequencies ``k``, (n_k, rows, cols)."""
        p = 1j * np.atleast_1d(np.asarray(k, dtype=float))[:, None, None]
        out = self.A0 + p * self.A1 + p * p * self.A2
        if self.B is not None:
            for g, b in zip(self.roots, self.B, strict=True):
                out = out + (p / (p + g)) * b
        if self.D is not None:
            w = p[:, :, 0] / (p[:, :, 0] + self.roots[None, :])  # (n_k, n_r)
            out = out + np.einsum("ia,ka,aj->kij", self.D, w, self.E)
        return out

    def project(self, left: np.ndarray, right: np.ndarray) -> RationalFit:
        """The fit of ``left^T Q right`` (a Galerkin projection; exact for Roger's linear fit)."""
        lt = np.asarray(left).T

        def both(a):
            return lt @ a @ right

        return RationalFit(
            self.kind,
            self.roots,
            both(self.A0),
            both(self.A1),
            both(self.A2),
            None if self.B is None else np.einsum("ri,aij,jc->arc", lt, self.B, right),
            None if self.D is None else lt @ self.D,
            None if self.E is None else self.E @ right,
        )


def _check(k: np.ndarray, Q: np.ndarray, roots: np.ndarray) -> tuple:
    k = np.asarray(k, dtype=float).ravel()
    Q = np.asarray(Q, dtype=complex)
    roots = np.asarray(roots, dtype=float).ravel()
    if Q.ndim != 3 or Q.shape[0] != k.size:
        raise InputError(f"rfa: Q has shape {Q.shape}, expected ({k.size}, rows, cols)")
    if roots.size == 0 or np.any(roots <= 0) or not np.all(np.isfinite(roots)):
        raise InputError(f"rfa: lag roots {roots.tolist()}: expected positive numbers")
    if np.unique(roots).size != roots.size:
        raise InputError(f"rfa: lag roots {roots.tolist()}: must differ from each other")
    if np.any(k < 0) or np.unique(k).size != k.size:
        raise InputError("rfa: reduced frequencies must be distinct and >= 0")
    if not np.all(np.isfinite(Q)):
        raise NumericalError("rfa: the tabulated forces have NaN or infinite values")
    return k, Q, roots


def _split(k: np.ndarray, Q: np.ndarray) -> tuple:
    """A0 (Q(0) if tabulated, else None), the oscillatory frequencies and their data."""
    zero = np.flatnonzero(k == 0.0)
    a0 = Q[zero[0]].real.copy() if zero.size else None
    osc = k > 0
    return a0, k[osc], Q[osc]


def _lstsq(G: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """Least squares for many right-hand sides (columns of Y), scaled columns of G."""
    s = np.linalg.norm(G, axis=0)
    s[s == 0] = 1.0
    x = np.linalg.lstsq(G / s, Y, rcond=None)[0]
    return x / s[:, None]


def _roger_design(k: np.ndarray, roots: np.ndarray, with_a0: bool, with_a1a2: bool) -> np.ndarray:
    """Real design matrix: rows [Re at each k; Im at each k], columns [A0?, A1?, A2?, B_j]."""
    kk = k[:, None]
    g = roots[None, :]
    lag_re = kk**2 / (kk**2 + g**2)
    lag_im = kk * g / (kk**2 + g**2)
    cols_re, cols_im = [], []
    if with_a0:
        cols_re.append(np.ones_like(kk))
        cols_im.append(np.zeros_like(kk))
    if with_a1a2:
        cols_re += [np.zeros_like(kk), -(kk**2)]
        cols_im += [kk, np.zeros_like(kk)]
    return np.vstack([np.hstack(cols_re + [lag_re]), np.hstack(cols_im + [lag_im])])


def _dissipative(a: np.ndarray, s: int) -> np.ndarray:
    """``a`` with the symmetric part of its leading ``s`` x ``s`` block clipped to negative
    semi-definite (its antisymmetric part kept)."""
    a = a.copy()
    blk = a[:s, :s]
    lam, vec = np.linalg.eigh(0.5 * (blk + blk.T))
    a[:s, :s] = (vec * np.minimum(lam, 0.0)) @ vec.T + 0.5 * (blk - blk.T)
    return a


def fit_roger(
    k: np.ndarray, Q: np.ndarray, roots: np.ndarray, *, dissipative: int = 0
) -> RationalFit:
    """Roger's approximation by linear least squares (the same design for every element).

    Parameters
    ----------
    k : ndarray (n_k,)
        Reduced frequencies [-], distinct, >= 0 (k = 0 fixes ``A0 = Q(0)``).
    Q : ndarray (n_k, rows, cols) complex
    roots : ndarray (n_r,)
        Lag roots [-].
    dissipative : int
        Size of the leading square block (structural unknowns) whose apparent mass and
        damping are made dissipative (module notes; 0: none).
    """
    k, Q, roots = _check(k, Q, roots)
    return _linear_fit(k, Q, roots, True, dissipative, "roger")


def fit_lags(k: np.ndarray, Q: np.ndarray, roots: np.ndarray) -> RationalFit:
    """The lag-only approximation ``C0 + sum_j C_j p / (p + g_j)`` (no A1, A2) of gust columns."""
    k, Q, roots = _check(k, Q, roots)
    return _linear_fit(k, Q, roots, False, 0, "lags")


def _linear_fit(k, Q, roots, with_a1a2: bool, dissipative: int, kind: str) -> RationalFit:
    a0, ko, Qo = _split(k, Q)
    n_k, rows, cols = Q.shape
    n_unknown = (2 if with_a1a2 else 0) + roots.size + (1 if a0 is None else 0)
    if 2 * ko.size < n_unknown:
        raise InputError(
            f"rfa: {ko.size} oscillatory reduced frequencies for {n_unknown} real unknowns per "
            "element: tabulate more frequencies or use fewer lag roots"
        )
    Y = np.vstack([Qo.real.reshape(ko.size, -1), Qo.imag.reshape(ko.size, -1)])
    if a0 is not None:
        Y[: ko.size] -= a0.reshape(1, -1)
    G = _roger_design(ko, roots, a0 is None, with_a1a2)
    X = _lstsq(G, Y).reshape(-1, rows, cols)
    i = 0
    if a0 is None:
        a0, i = X[0], 1
    zero = np.zeros((rows, cols))
    a1, a2 = (X[i], X[i + 1]) if with_a1a2 else (zero, zero)
    B = X[i + (2 if with_a1a2 else 0) :]
    if with_a1a2 and dissipative:
        a1 = _dissipative(a1, dissipative)
        a2 = _dissipative(a2, dissipative)
        # the other unknowns again, with A1 and A2 held: the lags absorb the change
        Y2 = Y - G[:, [i]] @ a1.reshape(1, -1) - G[:, [i + 1]] @ a2.reshape(1, -1)
        keep = [c for c in range(G.shape[1]) if c not in (i, i + 1)]
        X2 = _lstsq(G[:, keep], Y2).reshape(-1, rows, cols)
        if i:
            a0 = X2[0]
        B = X2[i:]
    return RationalFit(kind, roots, a0, a1, a2, B=np.ascontiguousarray(B))


def fit_minimum_state(
    k: np.ndarray,
    Q: np.ndarray,
    roots: np.ndarray,
    *,
    dissipative: int = 0,
    iterations: int = 60,
    tol: float = 1e-7,
) -> RationalFit:
    """Karpel's minimum-state approximation by alternating least squares on D and E.

    Starts from the Roger fit's lag matrices (their leading singular vectors) and alternates:
    with E fixed, A1, A2 and D row by row; with D fixed, A1, A2 and E column by column; until
    the relative change of the residual is below ``tol``. With ``dissipative``, A1 and A2 are
    then made dissipative (module notes) and D fitted again with them held.

    Parameters
    ----------
    k, Q, roots, dissipative
        As :func:`fit_roger`; k = 0 must be tabulated (A0 = Q(0)).
    iterations : int
        Most D-E alternations.
    tol : float
        Convergence on the residual norm.
    """
    k, Q, roots = _check(k, Q, roots)
    a0, ko, Qo = _split(k, Q)
    if a0 is None:
        raise InputError("rfa: the minimum-state fit needs k = 0 among the reduced frequencies")
    n_r = roots.size
    rows, cols = Q.shape[1:]
    if 2 * ko.size < 2 + n_r:
        raise InputError(f"rfa: {ko.size} oscillatory reduced frequencies are too few")
    rog = _linear_fit(k, Q, roots, True, 0, "roger")
    # initial E: per root, the leading right singular vector of Roger's lag matrix
    E = np.array([np.linalg.svd(b)[2][0] for b in rog.B])
    p = 1j * ko
    lag = p[:, None] / (p[:, None] + roots[None, :])  # (n_k, n_r)
    base = np.stack([p, p * p], axis=1)  # (n_k, 2): A1, A2
    R = Qo - a0[None]  # (n_k, rows, cols)

    def ri(a: np.ndarray) -> np.ndarray:  # complex (n_k, ...) -> real (2 n_k, ...)
        return np.concatenate([a.real, a.imag])

    Pb = ri(base)  # (2 n_k, 2)
    proj = np.eye(2 * ko.size) - Pb @ np.linalg.pinv(Pb)  # removes A1, A2 of each element
    prev = np.inf
    D = np.zeros((rows, n_r))
    for _ in range(iterations):
        # D given E: element (i, j) is sum_a D_ia lag_a(k) E_aj, rows over (k, j)
        F = (proj @ ri(lag[:, None, :] * E.T[None, :, :]).reshape(2 * ko.size, -1)).reshape(-1, n_r)
        Yd = np.einsum("kq,qij->kji", proj, ri(R)).reshape(-1, rows)
        D = _lstsq(F, Yd).T
        # E given D
        H = (proj @ ri(lag[:, None, :] * D[None, :, :]).reshape(2 * ko.size, -1)).reshape(-1, n_r)
        Ye = np.einsum("kq,qij->kij", proj, ri(R)).reshape(-1, cols)
        E = _lstsq(H, Ye)
        res = np.linalg.norm(Ye - H @ E)
        if abs(prev - res) <= tol * max(res, 1e-300):
            break
        prev = res
    # A1, A2 per element given D E
    lagpart = np.einsum("ia,ka,aj->kij", D, lag, E)
    Yb = ri(R - lagpart).reshape(2 * ko.size, -1)
    X = _lstsq(Pb, Yb).reshape(2, rows, cols)
    a1, a2 = X[0], X[1]
    if dissipative:
        a1 = _dissipative(a1, dissipative)
        a2 = _dissipative(a2, dissipative)
        Yr = ri(R - p[:, None, None] * a1[None] - p[:, None, None] ** 2 * a2[None])
        F = ri(lag[:, None, :] * E.T[None, :, :]).reshape(-1, n_r)  # (2 n_k cols, n_r)
        D = _lstsq(F, np.moveaxis(Yr, 2, 1).reshape(-1, rows)).T
    return RationalFit("minimum-state", roots, a0, a1, a2, D=D, E=E)
