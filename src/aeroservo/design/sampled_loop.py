"""One description of the sampled loop, shared by the loop matrix, the closed-loop boundary, the
loop margins and (through the same step equations) the time march.

At sample k, with the plant sampled by zero-order hold (:mod:`aeroservo.design.plant`):

* the sensors are read: ``y_k = C x_k + Du h_k`` (``h_k = u_{k-1}``, the input held over the
  last interval);
* the controller computes a command ``c_k``: state feedback ``c_k = -G x_k``; an estimator-based
  law (LQG, MPC without active constraints, its Kalman filter ``xi``)
  ``xi+ = xi- + M (y_k - Ca xi-)``, ``c_k = -K xi+``; or a discrete compensator (H-infinity)
  ``c_k = Cc s_k + Dc y_k``, ``s_{k+1} = Ac s_k + Bc y_k``;
* the input applied is ``u_k = c_k``, or ``u_k = p_k`` (the command computed one sample
  earlier) with a computational delay, then limited (rate, then magnitude);
* ``x_{k+1} = Phi x_k + Gu u_k``, ``h_{k+1} = u_k``, ``p_{k+1} = c_k`` and the estimator
  predicts with the input *applied*: ``xi-_{k+1} = Ad xi+ + Bu u_k``.

:func:`simulate` marches exactly these equations (with the limits); :func:`loop_matrix` is
their linear part (limits inactive), the transition of the loop state ``[x, h, p, xi-, s]``.
Before this module the loop matrix let an LQG predict with its own command while the simulator
predicted with the delayed one, so the two disagreed with a delay.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .plant import SampledPlant

__all__ = ["LinearLaw", "linear_law", "loop_matrix", "broken_loop"]


@dataclass
class LinearLaw:
    """A linear sampled controller as matrices (see the module docstring).

    Attributes
    ----------
    kind : str
        ``"state"`` (``c = -G x``), ``"estimator"`` (``c = -K xi+``) or ``"compensator"``.
    controls, sensors : tuple of str
    dt : float
        Sample period [s].
    G : ndarray or None
        State-feedback gain on the plant state.
    K, Ad, Bu, Ca, M : ndarray or None
        Estimator law.
    Ac, Bc, Cc, Dc : ndarray or None
        Discrete compensator from the sensors to the commands.
    """

    kind: str
    controls: tuple
    sensors: tuple
    dt: float
    G: np.ndarray | None = None
    K: np.ndarray | None = None
    Ad: np.ndarray | None = None
    Bu: np.ndarray | None = None
    Ca: np.ndarray | None = None
    M: np.ndarray | None = None
    Ac: np.ndarray | None = None
    Bc: np.ndarray | None = None
    Cc: np.ndarray | None = None
    Dc: np.ndarray | None = None

    @property
    def n_states(self) -> int:
        if self.kind == "estimator":
            return self.Ad.shape[0]
        if self.kind == "compensator":
            return self.Ac.shape[0]
        return 0


def _pad(T: np.ndarray, n_plant: int) -> np.ndarray:
    """State map padded with zero columns for plant states appended after the model's own
    (e.g. sensor filters of :func:`~aeroservo.design.plant.with_sensor_filters`)."""
    if T.shape[1] > n_plant:
        raise InputError(
            f"state feedback: the gain needs {T.shape[1]} plant states, the plant has {n_plant}"
        )
    return np.hstack([T, np.zeros((T.shape[0], n_plant - T.shape[1]))])


def linear_law(controller, n_plant: int) -> LinearLaw:
    """The linear law of a sampled controller.

    Parameters
    ----------
    controller : StateFeedback, OutputFeedback, MPCController, DiscreteCompensator or OpenLoop
        An MPC controller gives its law without active constraints (the LQG whose gain is the
        first move of the unconstrained QP).
    n_plant : int
        States of the plant the loop is closed around (filters included).
    """
    controls = tuple(controller.controls)
    sensors = tuple(getattr(controller, "sensors", ()))
    dt = float(controller.dt)
    if getattr(controller, "needs_state", False):
        G = controller.Kd @ _pad(controller.state_map, n_plant)
        return LinearLaw("state", controls, (), dt, G=G)
    if hasattr(controller, "compensator_matrices"):
        Ac, Bc, Cc, Dc = controller.compensator_matrices()
        return LinearLaw("compensator", controls, sensors, dt, Ac=Ac, Bc=Bc, Cc=Cc, Dc=Dc)
    kf = getattr(controller, "kf", None)
    if kf is None:  # open loop: no command
        return LinearLaw("state", controls, (), dt, G=np.zeros((len(controls), n_plant)))
    K = controller.unconstrained_gain() if hasattr(controller, "unconstrained_gain") else None
    K = controller.K if K is None else K
    return LinearLaw("estimator", controls, sensors, dt, K=K, Ad=kf.Ad, Bu=kf.Bu, Ca=kf.Ca, M=kf.M)


def _blocks(sp: SampledPlant, law: LinearLaw, delay: bool):
    """Transition of the loop state with the loop broken at the plant input.

    Returns ``(A0, Bw, Cc, Dc, sizes)``: with ``w_k`` the input applied to the plant,
    ``state_{k+1} = A0 state_k + Bw w_k`` and the command ``c_k = Cc state_k + Dc w_k``...
    For the estimator law ``c_k`` does not depend on ``w_k`` (``Dc = 0``): the sensors see
    the held input, not the new one.
    """
    n, m = sp.Gu.shape
    ne = law.n_states
    n_h = m if law.kind != "state" else 0  # the held input only matters through the sensors
    n_p = m if delay else 0
    N = n + n_h + n_p + ne
    ix, ih = slice(0, n), slice(n, n + n_h)
    ip, ie = slice(n + n_h, n + n_h + n_p), slice(n + n_h + n_p, N)
    A = np.zeros((N, N))
    Bw = np.zeros((N, m))
    Cc = np.zeros((m, N))  # the command c_k from the state
    A[ix, ix] = sp.Phi
    Bw[ix] = sp.Gu
    if n_h:
        Bw[ih] = np.eye(m)
    if law.kind == "state":
        Cc[:, ix] = -law.G
    else:
        Cy = np.zeros((len(law.sensors), N))  # y_k from the state
        Cy[:, ix] = sp.C
        Cy[:, ih] = sp.Du
        if law.kind == "estimator":
            F = np.eye(ne) - law.M @ law.Ca
            post = np.zeros((ne, N))  # xi+ from the state
            post[:, ie] = F
            post += law.M @ Cy
            Cc = -law.K @ post
            A[ie] = law.Ad @ post
            Bw[ie] = law.Bu
        else:
            Cc[:, ie] = law.Cc
            Cc += law.Dc @ Cy
            A[ie, ie] = law.Ac
            A[ie] += law.Bc @ Cy
    if n_p:
        A[ip] = Cc
        out = np.zeros((m, N))  # with a delay the input applied is the pending command
        out[:, ip] = np.eye(m)
        return A, Bw, out, {"n_x": n, "n_h": n_h, "n_p": n_p, "n_e": ne}
    return A, Bw, Cc, {"n_x": n, "n_h": n_h, "n_p": n_p, "n_e": ne}


def loop_matrix(sp: SampledPlant, law: LinearLaw, delay: bool = False) -> np.ndarray:
    """Transition matrix of the closed sampled loop (limits inactive).

    Parameters
    ----------
    sp : SampledPlant
        The plant sampled at the law's period, with the law's controls and its sensors as
        outputs (in that order).
    law : LinearLaw
    delay : bool
        One-sample computational delay.
    """
    A, Bw, Cu, _ = _blocks(sp, law, delay)
    return A + Bw @ Cu


def broken_loop(sp: SampledPlant, law: LinearLaw, delay: bool = False):
    """The loop broken at the plant input: ``(A, B, C)`` from the input applied ``w_k`` to the
    input the controller would apply ``o_k`` (the command, or with a delay the pending one):
    ``s_{k+1} = A s_k + B w_k``, ``o_k = C s_k``. The return ratio is ``L = -o / w`` and the
    closed loop ``w = o`` is :func:`loop_matrix`."""
    A, Bw, Cu, _ = _blocks(sp, law, delay)
    return A, Bw, Cu
