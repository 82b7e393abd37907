"""Linear-quadratic regulator (full-state feedback) with Bryson's-rule weights.

:func:`lqr_controller` designs the sampled controller, a :class:`StateFeedback`. It is not named
``lqr``: ``control.lqr`` returns the matrices ``(K, S, E)``, and a function named like one of
python-control's returns what that one returns (``lqr`` stays one release, deprecated).
``control.lqr`` gives the continuous gain (used for closed-loop flutter boundaries and Bode
analysis) and ``control.dlqr`` the gain for the sampled loop, on the exact zero-order-hold model
with the same weights.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from .._threads import blas_limited
from ..errors import RANGES, InputError, check_number
from ..linear.models import SAMPLE_RATES, check_continuous
from ..linear.signals import check_names, check_signal_map, describe
from .law import LinearLaw, pad_state_map, state_gain
from .plant import SampledPlant, select

BRYSON_RANGE = (RANGES["bryson"].lo, RANGES["bryson"].hi)
"""Allowed values of Bryson's limits [signal units] (their inverse squares stay finite)."""

__all__ = ["Bryson", "bryson_weights", "cost_weights", "StateFeedback", "lqr_controller", "lqr"]


@dataclass(frozen=True)
class Bryson:
    """Bryson's rule: weight each signal by the inverse square of its allowed value.

    Parameters
    ----------
    outputs : dict
        ``{output name: allowed value}`` in the output's unit (e.g. ``{"tip_disp": 0.05}`` m),
        values in [1e-9, 1e9].
    inputs : dict
        ``{control input name: allowed value}`` (e.g. ``{"aileron_hinge_moment": 500.0}`` N m),
        values in [1e-9, 1e9].
    state_weight : float
        Small weight added on every state (times the trace of the output weight / n), to keep
        the Riccati equation well posed when some states are not seen by the outputs; in
        [0, 1e6].
    """

    outputs: dict
    inputs: dict
    state_weight: float = 1e-8

    def __post_init__(self) -> None:
        lo, hi = BRYSON_RANGE
        for kind in ("outputs", "inputs"):
            check_signal_map(f"bryson.{kind}", getattr(self, kind), lo=lo, hi=hi, lo_open=False)
        if not self.outputs or not self.inputs:
            raise InputError("bryson: give at least one output and one input limit")
        check_number("bryson.state_weight", self.state_weight, lo=0.0, hi=1e6)


def bryson_weights(
    sys, controls: Sequence[str], bryson: Bryson
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Q, R, N)`` for ``J = int x'Q x + u'R u + 2 x'N u`` from output and input limits.

    Outputs with a direct feedthrough (accelerations) contribute cross and input terms.
    """
    controls = _controls(sys, controls)
    if not isinstance(bryson, Bryson):
        raise InputError(f"bryson = {describe(bryson)}: expected an aeroservo.design.Bryson")
    for c in bryson.inputs:
        if c not in controls:
            raise InputError(f"bryson.inputs: {c!r} is not a control input {list(controls)}")
    names = list(bryson.outputs)
    _, _, C, D = select(sys, controls, names)
    w = np.array([1.0 / bryson.outputs[n] ** 2 for n in names])
    Q = C.T @ (w[:, None] * C)
    N = C.T @ (w[:, None] * D)
    R = D.T @ (w[:, None] * D) + np.diag(
        [1.0 / bryson.inputs.get(c, np.inf) ** 2 for c in controls]
    )
    if np.any(np.diag(R) <= 0):
        missing = [c for c in controls if c not in bryson.inputs]
        raise InputError(f"bryson.inputs: give an allowed value for every control ({missing})")
    Q = Q + bryson.state_weight * max(np.trace(Q) / Q.shape[0], 1e-300) * np.eye(Q.shape[0])
    return 0.5 * (Q + Q.T), R, N


def cost_weights(
    sys, controls: Sequence[str], Q, R, bryson: Bryson | None, who: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Q, R, N)`` of a design from explicit weights or Bryson's rule (exactly one of them).

    ``who`` names the calling design in error messages (``"lqr"``, ``"lqg"``, ``"mpc"``). Q must
    be symmetric positive semi-definite and R symmetric positive definite.
    """
    controls = _controls(sys, controls)
    A, B, _, _ = select(sys, controls, [])
    n, m = B.shape
    if bryson is not None:
        if Q is not None or R is not None:
            raise InputError(f"{who}: give either Q and R, or bryson, not both")
        return bryson_weights(sys, controls, bryson)
    if Q is None or R is None:
        raise InputError(f"{who}: give Q and R, or bryson")
    Q = _weight(who, "Q", Q, n, "design states", definite=False)
    R = _weight(who, "R", R, m, "controls", definite=True)
    return Q, R, np.zeros((n, m))


def _controls(sys, controls) -> list[str]:
    """The control names, checked (a non-empty list of distinct names), and the model type."""
    check_continuous("sys", sys)
    controls = check_names("controls", controls)
    for i, c in enumerate(controls):
        if c in controls[:i]:
            raise InputError(f"controls: {c!r} appears twice")
    return controls


def _weight(who: str, name: str, value, n: int, what: str, *, definite: bool) -> np.ndarray:
    """A real symmetric n x n weight, positive (semi-)definite to a relative tolerance."""
    try:
        a = np.asarray(value)
    except ValueError:  # ragged nesting
        a = np.asarray(None)
    if a.dtype.kind not in "iuf" or a.ndim > 2:
        raise InputError(f"{who}: {name} = {describe(value)}: expected a real {n}x{n} matrix")
    a = np.atleast_2d(a).astype(float)
    if a.shape != (n, n):
        raise InputError(f"{who}: {name} has shape {a.shape}; expected {n}x{n} ({what})")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{who}: {name} has NaN or infinite entries")
    norm = float(np.linalg.norm(a))
    asym = float(np.abs(a - a.T).max())
    if asym > 1e-10 * norm:
        raise InputError(f"{who}: {name} is not symmetric (max |{name} - {name}^T| = {asym:.3g})")
    a = 0.5 * (a + a.T)
    low = float(np.linalg.eigvalsh(a)[0])
    if definite and not low > 1e-12 * norm:
        raise InputError(f"{who}: {name} must be positive definite (smallest eigenvalue {low:.3g})")
    if not definite and low < -1e-12 * norm:
        raise InputError(
            f"{who}: {name} must be positive semi-definite (smallest eigenvalue {low:.3g})"
        )
    return a


@dataclass
class StateFeedback:
    """``u = -K x_design`` with ``x_design = state_map @ x_plant``.

    Attributes
    ----------
    K : ndarray (n_controls, n_design)
        Continuous-time gain (``control.lqr``).
    Kd : ndarray (n_controls, n_design)
        Gain of the sampled loop (``control.dlqr`` on the zero-order-hold model).
    state_map : ndarray (n_design, n_plant)
    controls : tuple of str
    dt : float
        Sample period [s].
    closed_loop_poles : ndarray
        Continuous closed-loop poles of the design model.
    """

    K: np.ndarray
    Kd: np.ndarray
    state_map: np.ndarray
    controls: tuple
    dt: float
    closed_loop_poles: np.ndarray = field(default_factory=lambda: np.array([]))
    sensors: tuple = ()
    needs_state: bool = True
    design_speed: float = float("nan")

    @property
    def gain(self) -> np.ndarray:
        """Sampled-loop gain on the plant state: ``u = -gain @ x_plant``."""
        return self.Kd @ self.state_map

    @property
    def gain_continuous(self) -> np.ndarray:
        return self.K @ self.state_map

    def law(self, states) -> LinearLaw:
        """``c = -Kd T x`` on a plant with the named ``states`` (filter states padded)."""
        G = self.Kd @ pad_state_map(self.state_map, len(states))
        return state_gain(G, self.controls, self.dt, source="LQR state feedback")

    # sampled-controller protocol used by the simulator
    def reset(self) -> None:
        pass  # stateless

    def command(self, y: np.ndarray, x: np.ndarray) -> np.ndarray:
        return -(self.gain @ x)

    def update(self, y: np.ndarray, u: np.ndarray) -> None:
        pass


def _balanced_lqr(solver, A, B, Q, R, N) -> tuple[np.ndarray, np.ndarray]:
    """Riccati solution in coordinates equilibrated by a diagonal similarity x = T x~.

    Structural models mix stiff and soft unknowns (entries of A from 1e-3 to 1e10); SLICOT's
    Riccati solvers reject them as poorly scaled unless balanced first. The gain maps back as
    ``K = K~ T^-1`` and the closed-loop poles are unchanged.
    """
    _, T = sla.matrix_balance(A, permute=False, separate=True)
    t = T[0] if isinstance(T, tuple) else np.asarray(T)
    At = A * (1.0 / t)[:, None] * t[None, :]
    Bt = B / t[:, None]
    Qt = Q * t[:, None] * t[None, :]
    Nt = N * t[:, None]
    Kt, _, E = solver(At, Bt, Qt, R, Nt)
    return np.asarray(Kt) / t[None, :], np.asarray(E)


@blas_limited
def lqr_controller(
    sys,
    controls: Sequence[str],
    *,
    Q: np.ndarray | None = None,
    R: np.ndarray | None = None,
    bryson: Bryson | None = None,
    sample_rate: float = 1000.0,
    state_map: np.ndarray | None = None,
) -> StateFeedback:
    """Full-state-feedback LQR controller designed on a design model.

    Unlike ``control.lqr``, which returns the gain, the Riccati solution and the closed-loop
    eigenvalues ``(K, S, E)``, this returns the sampled controller: its gains are
    ``StateFeedback.K`` (continuous, ``control.lqr``'s K) and ``StateFeedback.Kd`` (sampled
    loop, ``control.dlqr``'s), its closed-loop poles ``StateFeedback.closed_loop_poles``.

    Parameters
    ----------
    sys : control.StateSpace
        Continuous design model (full or reduced, e.g. from :class:`StateSpaceBuilder` with
        ``n_modes``), with the named control inputs.
    controls : sequence of str
        Inputs the controller drives (e.g. ``["aileron_hinge_moment"]``).
    Q, R : ndarray, optional
        Weights on design states and controls (give these, or ``bryson``).
    bryson : Bryson, optional
        Output and input limits (Bryson's rule).
    sample_rate : float
        Sampling rate of the discrete gain [Hz], in [1, 1e5].
    state_map : ndarray, optional
        ``x_design = state_map @ x_plant`` (see :func:`aeroservo.design.plant.state_map`);
        identity by default.

    Returns
    -------
    StateFeedback
    """
    import control

    rate = check_number(
        "sample_rate", sample_rate, unit="Hz", lo=SAMPLE_RATES[0], hi=SAMPLE_RATES[1]
    )
    controls = _controls(sys, controls)
    A, B, _, _ = select(sys, controls, [])
    n = A.shape[0]
    T = np.eye(n) if state_map is None else _state_map(state_map, n)
    Q, R, N = cost_weights(sys, controls, Q, R, bryson, "lqr")
    K, E = _balanced_lqr(control.lqr, A, B, Q, R, N)
    sp = SampledPlant.from_statespace(sys, 1.0 / rate, controls, (), [])
    Kd, _ = _balanced_lqr(control.dlqr, sp.Phi, sp.Gu, Q / rate, R / rate, N / rate)
    return StateFeedback(
        np.asarray(K),
        np.asarray(Kd),
        T,
        tuple(controls),
        1.0 / rate,
        np.asarray(E),
        design_speed=float(getattr(sys, "speed", np.nan)),
    )


def _state_map(value, n: int) -> np.ndarray:
    try:
        T = np.asarray(value)
    except ValueError:  # ragged nesting
        T = np.asarray(None)
    if T.dtype.kind not in "iuf" or T.ndim != 2:
        raise InputError(f"lqr: state_map = {describe(value)}: expected a real 2-D array")
    if T.shape[0] != n:
        raise InputError(f"lqr: state_map has {T.shape[0]} rows, the design model {n} states")
    if not np.all(np.isfinite(T)):
        raise InputError("lqr: state_map has NaN or infinite entries")
    return T.astype(float)


def lqr(*args, **kwargs) -> StateFeedback:
    """Deprecated name of :func:`lqr_controller` (``control.lqr`` of the same name returns
    ``(K, S, E)``, this a controller); it warns and calls :func:`lqr_controller`."""
    warnings.warn(
        "aeroservo.design.lqr is deprecated and will be removed in the next release: use "
        "aeroservo.design.lqr_controller (control.lqr of the same name returns (K, S, E), this "
        "returns a StateFeedback controller)",
        DeprecationWarning,
        stacklevel=2,
    )
    return lqr_controller(*args, **kwargs)
