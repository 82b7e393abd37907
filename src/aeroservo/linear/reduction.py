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

import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from ..errors import InputError, check_int
from .tags import carry_tags

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
        The reduced model (same input and output names, physical signal units).
    hsv : ndarray
        Hankel singular values of the stable part of the scaled model, decreasing.
    n_unstable : int
        Unstable (and marginal) modes, kept exactly.
    error_bound : float
        H-infinity bound on the error of the *scaled* model (dimensionless: outputs divided by
        ``output_scale``, inputs in units of ``input_scale``).
    input_scale, output_scale : dict
        Nominal magnitude of each signal [its SI unit], given or defaulted.
    channel_bounds : dict
        ``(output, input) -> error_bound * output_scale / input_scale``: the bound on
        ``|G_ij - G_r,ij|`` in the channel's physical units.
    channel_errors : dict
        ``(output, input) -> max |G_r,ij - G_ij| / max |G_ij|`` over ``omega``, measured.
    channel_peaks : dict
        ``(output, input) -> max |G_ij|`` over ``omega`` (physical units).
    omega : ndarray
        The logarithmic frequency grid [rad/s] of the default scales and of the measured errors.
    """

    system: object
    hsv: np.ndarray
    n_unstable: int
    error_bound: float
    input_scale: dict = field(default_factory=dict)
    output_scale: dict = field(default_factory=dict)
    channel_bounds: dict = field(default_factory=dict)
    channel_errors: dict = field(default_factory=dict)
    channel_peaks: dict = field(default_factory=dict)
    omega: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def max_channel_error(self) -> float:
        """Largest measured relative channel error."""
        return max(self.channel_errors.values(), default=0.0)

    def relative_bound(self, output: str, input: str) -> float:
        """The bound of one channel relative to its peak gain (compare with its error)."""
        return self.channel_bounds[output, input] / self.channel_peaks[output, input]


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


def _response_grid(A: np.ndarray) -> np.ndarray:
    """Logarithmic grid [rad/s] over the model's dynamics: a decade beyond its poles."""
    mag = np.abs(np.linalg.eigvals(A)) if A.size else np.array([1.0])
    mag = mag[mag > 0] if np.any(mag > 0) else np.array([1.0])
    return np.geomspace(mag.min() / 10.0, mag.max() * 10.0, 400)


def _scales(names, given, what: str) -> np.ndarray | None:
    """Nominal magnitudes from a dict or sequence (None: to be defaulted)."""
    if given is None:
        return None
    if isinstance(given, dict):
        unknown = sorted(set(given) - set(names))
        if unknown:
            raise InputError(f"{what}: unknown signal {unknown[0]!r}; signals are {list(names)}")
        missing = [n for n in names if n not in given]
        if missing:
            raise InputError(f"{what}: no nominal magnitude for {missing[0]!r}")
        given = [given[n] for n in names]
    vals = np.asarray(given, dtype=float).ravel()
    if vals.size != len(names) or not np.all(np.isfinite(vals)) or np.any(vals <= 0):
        raise InputError(f"{what}: need {len(names)} positive finite magnitudes, got {given!r}")
    return vals


def _equilibrate(peak: np.ndarray, u0: np.ndarray | None, y0: np.ndarray | None):
    """Default nominal magnitudes ``(u0, y0)`` from the peak-gain matrix [y_i / u_j].

    Each free side is chosen so that the scaled peak gains ``peak * u0 / y0`` have unit row
    (column) maxima; both free: alternating square-root (Ruiz) steps. Given sides stay fixed.
    """
    tiny = np.finfo(float).tiny
    p = np.maximum(peak, tiny)
    if u0 is not None and y0 is not None:
        return u0, y0
    if u0 is not None:
        return u0, (p * u0[None, :]).max(axis=1)
    if y0 is not None:
        return 1.0 / (p / y0[:, None]).max(axis=0), y0
    u, y = np.ones(p.shape[1]), np.ones(p.shape[0])
    for _ in range(50):
        y *= np.sqrt((p * u[None, :] / y[:, None]).max(axis=1))
        u /= np.sqrt((p * u[None, :] / y[:, None]).max(axis=0))
    return u, y


def balanced_truncation(
    sys,
    order: int,
    method: str = "truncate",
    *,
    input_scale=None,
    output_scale=None,
) -> BalancedTruncation:
    """Balanced truncation to ``order`` states of the signal-scaled model, with its error bound.

       The inputs and outputs are first divided by nominal magnitudes, so that the truncation and
       its bound do not mix metres, radians and newton-metres; the realization is equilibrated by a
       diagonal similarity (LAPACK balancing; the transfer function is unchanged). The reduced
       model is returned in physical units, with per-channel bounds and measured errors.

       Parameters
       ----------
       sys : control.StateSpace
           Continuous-time model.
       order : int
           States kept (including every unstable mode; fewer if the model's minimal realization
           has fewer).
       method : {"truncate", "matchdc"}
           Passed to :func:`control.balanced_reduction`.
       input_scale, output_scale
    : dict or sequence, optional
           Nominal magnitude of each input / output [SI unit of the signal], e.g.
           ``{"aileron_hinge_moment": 100.0, "gust": 1.0}``. Default: the peak frequency-response
           gains equilibrated so that each input's largest response and each output's largest
           excitation have unit peak (a side that is given stays fixed).

       Returns
       -------
       BalancedTruncation

       Notes
       -----
       For acceleration outputs the high-frequency structural modes carry large Hankel singular
       values, so the bound (and the error) in a low-frequency band can stay large: truncate the
       structure modally first (``n_modes``), then balance. A weak channel can still have a
       relative bound above one (``relative_bound``): give it a smaller nominal magnitude.
    """
    import control

    order = check_int("order", order, lo=1, hi=sys.nstates)
    A, B, C, D = (np.asarray(x, dtype=float) for x in (sys.A, sys.B, sys.C, sys.D))
    lam = np.linalg.eigvals(A)
    if np.any(np.abs(lam.real) <= 1e-10 * np.maximum(np.abs(lam), 1.0)):
        raise InputError(
            "balanced_truncation: the model has eigenvalues on the imaginary axis (e.g. lag "
            "states at V = 0); reduce a model at a nonzero speed away from the flutter speed"
        )
    ins, outs = tuple(sys.input_labels), tuple(sys.output_labels)
    u0 = _scales(ins, input_scale, "input_scale")
    y0 = _scales(outs, output_scale, "output_scale")
    omega = _response_grid(A)
    g = _frf(sys, omega)
    peak = np.abs(g).max(axis=2)
    u0, y0 = _equilibrate(peak, u0, y0)
    A, T = sla.matrix_balance(A, permute=False, separate=False)
    Bs, Cs = np.linalg.solve(T, B) * u0[None, :], (C @ T) / y0[:, None]
    Ds = D * u0[None, :] / y0[:, None]
    a11, b1, c1, n_u = _stable_part(A, Bs, Cs)
    if order < n_u:
        raise InputError(f"order = {order}: the model has {n_u} unstable states that must be kept")
    hsv = _hankel_singular_values(a11, b1, c1)
    bound = 2.0 * float(np.sum(hsv[order - n_u :]))
    with warnings.catch_warnings():  # order above the minimal one: slycot keeps the minimal
        warnings.filterwarnings("ignore", message=r"(?s).*nsmin")
        red = control.balanced_reduction(control.ss(A, Bs, Cs, Ds), order, method=method)
    red = control.ss(
        red.A,
        np.asarray(red.B) / u0[None, :],
        np.asarray(red.C) * y0[:, None],
        np.asarray(red.D) * y0[:, None] / u0[None, :],
        inputs=list(ins),
        outputs=list(outs),
    )
    carry_tags(sys, red)
    err = np.abs(_frf(red, omega) - g).max(axis=2) / np.where(peak > 0, peak, 1.0)
    pairs = [(o, i) for o in outs for i in ins]
    idx = {(o, i): (a, b) for a, o in enumerate(outs) for b, i in enumerate(ins)}
    return BalancedTruncation(
        red,
        hsv,
        n_u,
        bound,
        input_scale=dict(zip(ins, u0.tolist(), strict=True)),
        output_scale=dict(zip(outs, y0.tolist(), strict=True)),
        channel_bounds={p: bound * y0[idx[p][0]] / u0[idx[p][1]] for p in pairs},
        channel_errors={p: float(err[idx[p]]) for p in pairs},
        channel_peaks={p: float(peak[idx[p]]) for p in pairs},
        omega=omega,
    )


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
        from .._figures import new_figure

        i, j = self.outputs.index(output), self.inputs.index(input)
        fig = new_figure(figsize=(6.5, 4))
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
