"""Reduced-order models for control design.

* Modal truncation of the structure: ``StateSpaceBuilder(..., n_modes=r)`` (or
  ``statespace(..., n_modes=r)``) keeps r in-vacuo modes; the aerodynamic lag states stay
  complete and consistent with the projected downwash.
* :func:`balanced_truncation`: balanced truncation of any ``control.StateSpace`` with the
  H-infinity error bound ``2 sum(discarded Hankel singular values)`` of its stable part (unstable
  modes, e.g. above the flutter speed, are kept exactly; python-control / slycot underneath).
* :func:`compare_frequency_response`: full versus reduced frequency responses, per channel.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from ..errors import InputError, check_int

__all__ = [
    "BalancedTruncation",
    "balanced_truncation",
    "FRFComparison",
    "compare_frequency_response",
]


@dataclass
class BalancedTruncation:
    """Result of :func:`balanced_truncation`.

    Attributes
    ----------
    system : control.StateSpace
        The reduced model (same input and output names).
    hsv : ndarray
        Hankel singular values of the stable part, decreasing.
    n_unstable : int
        Unstable (and marginal) modes, kept exactly.
    error_bound : float
        H-infinity bound on the error ``|G - G_r|`` (in the units of the outputs per input).
    """

    system: object
    hsv: np.ndarray
    n_unstable: int
    error_bound: float


def _stable_part(
    A: np.ndarray, B: np.ndarray, C: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Stable subsystem (A11, B1, C1) of an additive stable/unstable decomposition."""
    T, Z, k = sla.schur(A, output="real", sort="lhp")
    bt, ct = Z.T @ B, C @ Z
    if k == A.shape[0]:
        return T, bt, ct, 0
    a11, a12, a22 = T[:k, :k], T[:k, k:], T[k:, k:]
    X = sla.solve_sylvester(a11, -a22, -a12)
    return a11, bt[:k] - X @ bt[k:], ct[:, :k], A.shape[0] - k


def _hankel_singular_values(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Square-root method: Cholesky factors of both Gramians (Hammarling, slycot), then an SVD.

    (Taking ``sqrt(eig(Wc Wo))`` loses the small values and can even return complex ones for
    the badly scaled matrices of a structural model.)
    """
    import control

    if a.size == 0:
        return np.array([])
    s = control.ss(a, b, c, 0)
    lc = control.gram(s, "cf")
    lo = control.gram(s, "of")
    return np.linalg.svd(lo @ lc.T, compute_uv=False)


def balanced_truncation(sys, order: int, method: str = "truncate") -> BalancedTruncation:
    """Balanced truncation to ``order`` states, with its error bound.

    The realization is first equilibrated by a diagonal similarity (LAPACK balancing; the
    transfer function is unchanged), which the badly scaled structural matrices need.

    Parameters
    ----------
    sys : control.StateSpace
        Continuous-time model.
    order : int
        States kept (including every unstable mode).
    method : {"truncate", "matchdc"}
        Passed to :func:`control.balanced_reduction`.

    Returns
    -------
    BalancedTruncation

    Notes
    -----
    For acceleration outputs the high-frequency structural modes carry large Hankel singular
    values, so the bound (and the error) in a low-frequency band can stay large: truncate the
    structure modally first (``n_modes``), then balance.
    """
    import control

    order = check_int("order", order, lo=1, hi=sys.nstates)
    A, B, C, D = (np.asarray(x) for x in (sys.A, sys.B, sys.C, sys.D))
    lam = np.linalg.eigvals(A)
    if np.any(np.abs(lam.real) <= 1e-10 * np.maximum(np.abs(lam), 1.0)):
        raise InputError(
            "balanced_truncation: the model has eigenvalues on the imaginary axis (e.g. lag "
            "states at V = 0); reduce a model at a nonzero speed away from the flutter speed"
        )
    A, T = sla.matrix_balance(A, permute=False, separate=False)
    B, C = np.linalg.solve(T, B), C @ T
    a11, b1, c1, n_u = _stable_part(A, B, C)
    if order < n_u:
        raise InputError(f"order = {order}: the model has {n_u} unstable states that must be kept")
    hsv = _hankel_singular_values(a11, b1, c1)
    bound = 2.0 * float(np.sum(hsv[order - n_u :]))
    red = control.balanced_reduction(control.ss(A, B, C, D), order, method=method)
    red = control.ss(red.A, red.B, red.C, red.D, inputs=sys.input_labels, outputs=sys.output_labels)
    for attr in ("speed", "density", "signal_units"):
        if hasattr(sys, attr):
            setattr(red, attr, getattr(sys, attr))
    return BalancedTruncation(red, hsv, n_u, bound)


@dataclass
class FRFComparison:
    """Full versus reduced frequency responses.

    Attributes
    ----------
    omega : ndarray
        Frequencies [rad/s].
    full, reduced : ndarray (n_outputs, n_inputs, n_omega) complex
    errors : dict
        ``(output, input) -> max_omega |G_r - G| / max_omega |G|`` (relative to the channel's
        peak over the band).
    max_error : float
        Largest of ``errors``.
    """

    omega: np.ndarray
    full: np.ndarray
    reduced: np.ndarray
    errors: dict = field(default_factory=dict)
    max_error: float = 0.0
    inputs: tuple = ()
    outputs: tuple = ()

    def plot(self, output: str, input: str):
        """Bode magnitude of one channel, full and reduced (matplotlib Figure)."""
        from matplotlib.figure import Figure

        i, j = self.outputs.index(output), self.inputs.index(input)
        fig = Figure(layout="constrained", figsize=(6.5, 4))
        ax = fig.subplots()
        f = self.omega / (2 * np.pi)
        ax.loglog(f, np.abs(self.full[i, j]), label="full")
        ax.loglog(f, np.abs(self.reduced[i, j]), "--", label="reduced")
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel(f"|{output} / {input}|")
        ax.legend()
        ax.grid(True, which="both", alpha=0.3)
        return fig


def _frf(sys, omega: np.ndarray) -> np.ndarray:
    A, B, C, D = (np.asarray(x) for x in (sys.A, sys.B, sys.C, sys.D))
    n = A.shape[0]
    out = np.empty((C.shape[0], B.shape[1], omega.size), dtype=complex)
    for k, w in enumerate(omega):
        out[:, :, k] = C @ np.linalg.solve(1j * w * np.eye(n) - A, B) + D
    return out


def compare_frequency_response(full, reduced, omega: np.ndarray) -> FRFComparison:
    """Compare two models with the same input and output names on a frequency grid [rad/s]."""
    if tuple(full.input_labels) != tuple(reduced.input_labels) or tuple(
        full.output_labels
    ) != tuple(reduced.output_labels):
        raise InputError("compare_frequency_response: the models have different signal names")
    omega = np.asarray(omega, dtype=float)
    g, gr = _frf(full, omega), _frf(reduced, omega)
    peak = np.max(np.abs(g), axis=2)
    err = np.max(np.abs(gr - g), axis=2) / np.where(peak > 0, peak, 1.0)
    errors = {
        (o, i): float(err[a, b])
        for a, o in enumerate(full.output_labels)
        for b, i in enumerate(full.input_labels)
    }
    return FRFComparison(
        omega, g, gr, errors, float(err.max()), tuple(full.input_labels), tuple(full.output_labels)
    )


def modal_controllability(sys, eigenvalue: complex) -> dict:
    """Scale-invariant test of how each input reaches, and each output sees, one mode.

    With right and left eigenvectors v, w of A for the eigenvalue nearest ``eigenvalue``, the
    index of input j is ``|w^H b_j| / sum_i |w_i| |b_ij|`` and that of output i is
    ``|c_i v| / sum_k |c_ik| |v_k|``: the inner product that decides controllability
    (observability) divided by the bound on its rounding error. It does not change when states
    are rescaled (units), it is 1 without cancellation and of the order of 1e-16 for a
    mathematically zero coupling (a zero column of B, an unobservable mode). Accelerometer rows
    typically give 1e-7..1e-5 because stiffness and inertia forces nearly cancel in a mode.

    Returns
    -------
    dict
        ``{"eigenvalue": lam, "inputs": {name: index}, "outputs": {name: index}}``.
    """
    A = np.asarray(sys.A)
    lam, W, V = sla.eig(A, left=True, right=True)
    i = int(np.argmin(np.abs(lam - eigenvalue)))
    v, w = V[:, i], W[:, i]
    B, C = np.asarray(sys.B), np.asarray(sys.C)

    def index(num: np.ndarray, den: np.ndarray) -> np.ndarray:
        return np.divide(num, den, out=np.zeros_like(num), where=den > 0)

    ctrb = index(np.abs(w.conj() @ B), np.abs(w) @ np.abs(B))
    obsv = index(np.abs(C @ v), np.abs(C) @ np.abs(v))
    return {
        "eigenvalue": complex(lam[i]),
        "inputs": dict(zip(sys.input_labels, ctrb.tolist(), strict=True)),
        "outputs": dict(zip(sys.output_labels, obsv.tolist(), strict=True)),
    }
