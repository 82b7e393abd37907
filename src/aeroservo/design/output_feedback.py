"""Kalman filtering and LQG output feedback for the sampled loop.

The estimator works on the sampled design model augmented with the held command
(:meth:`SampledPlant.augmented`), in filter ("current estimate") form:

* correction at sample k: ``xi_k = xi_k^- + M (y_k - Ca xi_k^-)``
* command: ``c_k = -K xi_k`` (LQR gain on the same augmented model)
* prediction with the command actually applied (after limits): ``xi_{k+1}^- = Ad xi_k + Bu u_k``

Process noise enters through the disturbance (gust) input, measurement noise per sensor. The
linear compensator (when no limit is active) is available as a discrete ``control.StateSpace``,
and the continuous-time LQG with the same weights for Bode plots, margins and closed-loop
flutter boundaries.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.linalg as sla

from .._threads import blas_limited
from ..errors import InputError, check_number, check_quantity
from .law import LinearLaw
from .plant import SampledPlant, select
from .riccati import solve_dare
from .state_feedback import Bryson, _balanced_lqr, cost_weights

__all__ = ["KalmanFilter", "kalman_filter", "OutputFeedback", "lqg", "estimator_law"]


@dataclass
class KalmanFilter:
    """Steady-state discrete Kalman filter in filter form on ``(Ad, Bu, Ca)``."""

    Ad: np.ndarray
    Bu: np.ndarray
    Ca: np.ndarray
    M: np.ndarray
    x_prior: np.ndarray = field(default=None)

    def __post_init__(self) -> None:
        if self.x_prior is None:
            self.x_prior = np.zeros(self.Ad.shape[0])

    def reset(self, x0: np.ndarray | None = None) -> None:
        self.x_prior = np.zeros(self.Ad.shape[0]) if x0 is None else np.asarray(x0, float).copy()

    def correct(self, y: np.ndarray) -> np.ndarray:
        """Posterior estimate at this sample."""
        self.x_post = self.x_prior + self.M @ (y - self.Ca @ self.x_prior)
        return self.x_post

    def predict(self, u: np.ndarray) -> None:
        self.x_prior = self.Ad @ self.x_post + self.Bu @ u


def kalman_filter(
    plant: SampledPlant,
    sensors: Sequence[str],
    process_noise: dict,
    sensor_noise: dict,
    input_noise: dict | None = None,
) -> KalmanFilter:
    """Steady-state Kalman filter of a sampled plant (augmented with the held command).

    Parameters
    ----------
    plant : SampledPlant
        With the disturbance inputs named in ``process_noise`` and the sensors as outputs.
    sensors : sequence of str
    process_noise : dict
        ``{disturbance input: variance of its sampled value}`` (e.g. ``{"gust": 1.0}`` (m/s)^2).
    sensor_noise : dict
        ``{sensor: variance}`` in the sensor's unit squared; every sensor needs one.
    input_noise : dict, optional
        ``{control: q^2}``: fictitious noise entering with each control [unit^2], for loop
        transfer recovery at the plant input (Doyle & Stein, "Robustness with observers", IEEE
        TAC 24(4), 1979; Maciejowski, *Multivariable Feedback Design*, sec. 5.6): the process
        noise gains ``q^2 Bu Bu'`` (``Bu`` the control's column of the augmented model), and as
        ``q^2`` grows the LQG's loop at the plant input tends to the LQR's.
    """
    missing = [s for s in sensors if s not in sensor_noise]
    if missing:
        raise InputError(f"sensor_noise: give a variance for every sensor (missing {missing})")
    for name, v in list(process_noise.items()) + list(sensor_noise.items()):
        check_number(f"noise variance of {name!r}", v, lo=0.0, lo_open=True)
    Ad, Bu, Bd, Ca = plant.augmented()
    rows = [plant.outputs.index(s) for s in sensors]
    Ca = Ca[rows]
    cols = []
    for d in process_noise:
        if d not in plant.disturbances:
            raise InputError(
                f"process_noise: {d!r} is not a disturbance input {list(plant.disturbances)}"
            )
        cols.append(plant.disturbances.index(d))
    G = Bd[:, cols]
    W = np.diag([process_noise[d] for d in process_noise])
    V = np.diag([sensor_noise[s] for s in sensors])
    Qn = G @ W @ G.T
    for c, q2 in (input_noise or {}).items():
        if c not in plant.controls:
            raise InputError(f"input_noise: {c!r} is not a control input {list(plant.controls)}")
        b = Bu[:, plant.controls.index(c)]
        Qn = Qn + check_number(f"input noise of {c!r}", q2, lo=0.0) * np.outer(b, b)
    # filter-form gain from the a-priori covariance of the DARE (balanced for conditioning)
    P = _dare_balanced(Ad, Ca, Qn, V)
    S = Ca @ P @ Ca.T + V
    M = np.linalg.solve(S.T, (P @ Ca.T).T).T
    return KalmanFilter(Ad, Bu, Ca, M)


def _dare_balanced(A: np.ndarray, C: np.ndarray, Q: np.ndarray, R: np.ndarray) -> np.ndarray:
    """A-priori covariance of the estimation DARE ``P = A P A' - ... + Q`` (dual of control)."""
    return solve_dare(A.T, C.T, Q, R)


@dataclass
class OutputFeedback:
    """LQG compensator: Kalman filter plus LQR gain on the augmented sampled design model.

    Attributes
    ----------
    K : ndarray
        Gain on the augmented design state ``[x, h]``.
    kf : KalmanFilter
    controls, sensors : tuple of str
    dt : float
    continuous : dict
        Pieces of the continuous LQG (design model ``A, B, C, D``, gains ``K``, ``L``).
    design_speed : float
        Speed of the design model [m/s].
    applied_input : bool
        Whether the estimator predicts with the input applied after the actuator limits (the
        default) or with its own command (``aeroservo.design.anti_windup``).
    """

    K: np.ndarray
    kf: KalmanFilter
    controls: tuple
    sensors: tuple
    dt: float
    continuous: dict = field(default_factory=dict)
    design_speed: float = float("nan")
    needs_state: bool = False
    applied_input: bool = True

    def law(self, states=()) -> LinearLaw:
        """Its :class:`~aeroservo.design.law.LinearLaw` (the estimator predicts with the input
        applied, ``L = Bu``, or with its command, ``L = 0``)."""
        law = estimator_law(self.K, self.kf, self.controls, self.sensors, self.dt, "LQG")
        return law if self.applied_input else replace(law, L=np.zeros_like(law.L))

    @property
    def compensator(self):
        """Discrete compensator (``control.StateSpace``) from sensors to controls, valid while
        no actuator limit is active: the controller seen as a black box."""
        return discrete_compensator(self.K, self.kf, self.dt, self.sensors, self.controls)

    @property
    def compensator_continuous(self):
        """Continuous-time LQG compensator with the same weights (noise intensities =
        variances x dt)."""
        return continuous_compensator(self.continuous, self.sensors, self.controls)

    def reset(self) -> None:
        self.kf.reset()

    def command(self, y: np.ndarray, x: np.ndarray | None = None) -> np.ndarray:
        self._c = -(self.K @ self.kf.correct(y))
        return self._c

    def update(self, y: np.ndarray, u: np.ndarray) -> None:
        self.kf.predict(u if self.applied_input else self._c)


@blas_limited
def lqg(
    sys,
    controls: Sequence[str],
    sensors: Sequence[str],
    *,
    process_noise: dict,
    sensor_noise: dict,
    input_noise: dict | None = None,
    Q: np.ndarray | None = None,
    R: np.ndarray | None = None,
    bryson: Bryson | None = None,
    sample_rate: float = 1000.0,
) -> OutputFeedback:
    """LQG output feedback designed on a (possibly reduced) continuous model.

    Parameters
    ----------
    sys : control.StateSpace
        Continuous design model with the control and disturbance inputs and the sensors (and
        the Bryson outputs) as outputs.
    controls, sensors : sequence of str
    process_noise, sensor_noise : dict
        See :func:`kalman_filter` (variances of the sampled signals).
    input_noise : dict, optional
        Loop transfer recovery at the plant input, see :func:`kalman_filter`.
    Q, R, bryson :
        LQR weights, see :func:`aeroservo.design.state_feedback.lqr_controller`.
    sample_rate : float
        [Hz].

    Returns
    -------
    OutputFeedback
    """
    import control

    rate = check_quantity("sample_rate", sample_rate, "sample_rate")
    dt = 1.0 / rate
    A, B, _, _ = select(sys, controls, [])
    n, m = B.shape
    Q, R, N = cost_weights(sys, controls, Q, R, bryson, "lqg")
    dist = tuple(process_noise)
    sp = SampledPlant.from_statespace(sys, dt, controls, dist, list(sensors))
    kf = kalman_filter(sp, sensors, process_noise, sensor_noise, input_noise)
    Ad, Bu, _, Ca = sp.augmented()
    # LQR on the augmented model [x, h]: no weight on the held command states
    Qa = np.zeros((n + m, n + m))
    Qa[:n, :n] = Q
    Na = np.zeros((n + m, m))
    Na[:n] = N
    Kd, _ = _balanced_lqr(control.dlqr, Ad, Bu, Qa * dt, R * dt, Na * dt)

    # continuous counterpart (for Bode, margins, closed-loop flutter boundaries)
    Kc, _ = _balanced_lqr(control.lqr, A, B, Q, R, N)
    _, Bd_c, C_s, _ = select(sys, dist, list(sensors))
    _, _, _, D_u = select(sys, controls, list(sensors))
    Wc = np.diag([process_noise[d] for d in dist]) * dt
    Vc = np.diag([sensor_noise[s] for s in sensors]) * dt
    L = _continuous_kalman(A, Bd_c, C_s, Wc, Vc)
    return OutputFeedback(
        Kd,
        kf,
        tuple(controls),
        tuple(sensors),
        dt,
        continuous={"A": A, "B": B, "C": C_s, "D": D_u, "K": Kc, "L": L},
        design_speed=float(getattr(sys, "speed", np.nan)),
    )


def estimator_law(K, kf: KalmanFilter, controls, sensors, dt: float, source: str) -> LinearLaw:
    """The law of a Kalman filter (filter form) with the gain ``K`` on its estimate.

    State: the a-priori estimate ``xi-``; ``c = -K (I - M Ca) xi- - K M y`` and
    ``xi-[k+1] = Ad xi+ + Bu u = (Ad - Bu K)(I - M Ca) xi- + (Ad - Bu K) M y + Bu (u - c)``.
    """
    F = np.eye(kf.Ad.shape[0]) - kf.M @ kf.Ca
    AK = kf.Ad - kf.Bu @ K
    return LinearLaw(
        AK @ F,
        AK @ kf.M,
        -K @ F,
        -K @ kf.M,
        kf.Bu,
        tuple(controls),
        tuple(sensors),
        float(dt),
        "estimator",
        source,
        "prediction",
    )


def discrete_compensator(K, kf: KalmanFilter, dt: float, sensors, controls):
    """Linear discrete LQG compensator (filter form) as a ``control.StateSpace``: the law of
    :func:`estimator_law` without its use of the applied input (the black box from the sensors
    to the commands, exact while no actuator limit is active)."""
    import control

    law = estimator_law(K, kf, controls, sensors, dt, "LQG")
    return control.ss(
        law.A, law.B, law.C, law.D, dt, inputs=list(sensors), outputs=list(controls), name="lqg"
    )


def continuous_compensator(c: dict, sensors, controls):
    """Continuous LQG compensator from the pieces ``A, B, C, D`` (design model from the
    controls to the sensors), ``K`` (LQR gain) and ``L`` (Kalman gain)."""
    import control

    Ak = c["A"] - c["B"] @ c["K"] - c["L"] @ c["C"] + c["L"] @ c["D"] @ c["K"]
    comp = control.ss(
        Ak,
        c["L"],
        -c["K"],
        np.zeros((c["K"].shape[0], len(sensors))),
        inputs=list(sensors),
        outputs=list(controls),
        name="lqg_continuous",
    )
    comp.K, comp.L = c["K"], c["L"]
    return comp


def _continuous_kalman(A, G, C, W, V) -> np.ndarray:
    """Continuous Kalman gain ``L = P C' V^-1`` in balanced coordinates."""
    _, (t, _) = sla.matrix_balance(A, permute=False, separate=True)
    At = A * (1.0 / t)[:, None] * t[None, :]
    Ct = C * t[None, :]
    Gt = G / t[:, None]
    Q = Gt @ W @ Gt.T
    Pt = sla.solve_continuous_are(At.T, Ct.T, Q + 1e-14 * np.trace(Q) * np.eye(len(t)) / len(t), V)
    P = Pt * t[:, None] * t[None, :]
    return P @ C.T @ np.linalg.inv(V)
