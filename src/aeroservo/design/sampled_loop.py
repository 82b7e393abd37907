"""One description of the sampled loop, shared by the loop matrix, the closed-loop boundary, the
loop margins and the time march.

At sample k, with the plant sampled by zero-order hold (:mod:`aeroservo.design.plant`):

* the controller measures ``m_k``: the sensors ``C x_k + Du h_k`` (``h_k = u_{k-1}``, the input
  held over the last interval) or, for state feedback, the plant state ``x_k``;
* it emits the command ``c_k = C s_k + D m_k`` and updates its state
  ``s_{k+1} = A s_k + B m_k + L (u_k - c_k)`` (:class:`~aeroservo.design.law.LinearLaw`; a
  computational delay is part of the law, :func:`~aeroservo.design.law.delayed`);
* the input applied is ``u_k = c_k`` limited (rate, then magnitude);
* ``x_{k+1} = Phi x_k + Gu u_k`` and ``h_{k+1} = u_k``.

:func:`aeroservo.simulate.simulate` marches exactly these equations (with the limits);
:func:`loop_matrix` is their linear part (limits inactive), the transition of the loop state
``[x, h, s]``. The loop is broken where the field breaks it (:func:`broken_loop`): at each
plant input (the actuator), the controller a black box from sensors to commands, so only the
plant sees the perturbation (``u_k - c_k`` is known to the controller's software and is not
perturbed; ``measured_input=True`` models hardware that measures the applied input instead), or
at each sensor (the plant output).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import InputError
from ..linear.signals import describe
from .law import LinearLaw, delayed
from .plant import SampledPlant

__all__ = ["linear_law", "loop_matrix", "broken_loop", "plant_states", "LoopBlocks"]


def plant_states(plant) -> tuple[str, ...]:
    """The state names of a plant (a ``control.StateSpace`` or anything with ``state_labels``)."""
    labels = getattr(plant, "state_labels", None)
    if labels is None:
        raise InputError(f"plant = {describe(plant)}: expected a control.StateSpace")
    return tuple(labels)


def linear_law(controller, states: Sequence[str]) -> LinearLaw:
    """The linear law of a sampled controller around a plant with the named ``states``.

    Parameters
    ----------
    controller
        A controller of :mod:`aeroservo.design` (see :func:`aeroservo.design.as_controller`);
        an MPC gives its law without active constraints (the LQG whose gain is the first move
        of its unconstrained QP); a schedule must be evaluated at a speed first (``at``).
    states : sequence of str
        The plant's state names (filters included), for state feedback on named states.

    Raises
    ------
    InputError
        If the controller has no linear law (a Python law, or an unknown object).
    """
    law = getattr(controller, "law", None)
    if not callable(law):
        raise InputError(
            f"controller = {describe(controller)}: not a linear controller, so it has no "
            "closed-loop eigenvalues or margins; simulate it, or bring its matrices "
            "(aeroservo.design.as_controller(control.ss(A, B, C, D, dt)))"
        )
    return law(tuple(states))


class LoopBlocks:
    """The sampled loop with both break points open (see the module docstring).

    With ``w`` the input applied to the plant and ``v`` the measurement the controller reads,
    the loop state ``z = [x, h, s]`` obeys ``z+ = Az z + Bw w + Bv v``; the controller emits
    ``o = Co z + Dv v`` and the true measurement is ``m = Cm z``. The closed loop is
    ``w = o, v = m``.
    """

    def __init__(self, sp: SampledPlant, law: LinearLaw, measured_input: bool = False):
        n, m = sp.Gu.shape
        ns = law.n_states
        n_h = 0 if law.state_feedback else m  # the held input is seen through the sensors only
        N = n + n_h + ns
        ix, ih, ic = slice(0, n), slice(n, n + n_h), slice(n + n_h, N)
        if law.state_feedback:
            if law.D.shape[1] != n:
                raise InputError(
                    f"state feedback on {law.D.shape[1]} states; the plant has {n} states"
                )
            Cm = np.zeros((n, N))
            Cm[:, ix] = np.eye(n)
        else:
            Cm = np.zeros((len(law.sensors), N))
            Cm[:, ix] = sp.C
            Cm[:, ih] = sp.Du
        # only an estimator's prediction can be fed by a measurement; anti-windup compares the
        # command with its limited value, which software knows
        feeds = measured_input and law.applied_input == "prediction"
        Lm = law.L if feeds else np.zeros_like(law.L)
        Az = np.zeros((N, N))
        Bw = np.zeros((N, m))
        Bv = np.zeros((N, Cm.shape[0]))
        Co = np.zeros((m, N))
        Az[ix, ix] = sp.Phi
        Bw[ix] = sp.Gu
        if n_h:
            Bw[ih] = np.eye(m)
        Az[ic, ic] = law.A - Lm @ law.C
        Bv[ic] = law.B - Lm @ law.D
        Bw[ic] = Lm
        Co[:, ic] = law.C
        self.Az, self.Bw, self.Bv, self.Co, self.Dv, self.Cm = Az, Bw, Bv, Co, law.D, Cm

    def closed(self) -> np.ndarray:
        """Transition matrix of the closed loop."""
        Co = self.Co + self.Dv @ self.Cm
        return self.Az + self.Bw @ Co + self.Bv @ self.Cm

    def at_inputs(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(A, B, C)`` broken at every plant input (sensors closed): ``z+ = A z + B w``,
        ``o = C z``; return ratio ``L = -o / w``."""
        return self.Az + self.Bv @ self.Cm, self.Bw, self.Co + self.Dv @ self.Cm

    def at_sensors(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(A, B, C)`` broken at every measurement at once (inputs closed): the controller
        reads ``v``, the loop gives back ``r = C z``; return ratio ``L = -r / v``."""
        Gv = self.Bw @ self.Dv + self.Bv
        return self.Az + self.Bw @ self.Co, Gv, self.Cm

    def at_sensor(self, j: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(A, B, C)`` broken at measurement ``j`` (inputs and other sensors closed): the
        controller reads ``v`` for it, the loop gives back the true value ``r = C z``; return
        ratio ``L = -r / v``."""
        P = np.eye(self.Cm.shape[0])
        P[j, j] = 0.0
        Gv = self.Bw @ self.Dv + self.Bv
        A = self.Az + self.Bw @ self.Co + Gv @ P @ self.Cm
        return A, Gv[:, [j]], self.Cm[[j]]


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
    return LoopBlocks(sp, delayed(law) if delay else law).closed()


def broken_loop(sp: SampledPlant, law: LinearLaw, delay: bool = False, measured_input=False):
    """The loop broken at the plant inputs: ``(A, B, C)`` from the input applied ``w_k`` to the
    input the controller would apply ``o_k``: ``s_{k+1} = A s_k + B w_k``, ``o_k = C s_k``.
    The return ratio is ``L = -o / w`` and the closed loop ``w = o`` is :func:`loop_matrix`.

    ``measured_input``: the controller reads the applied input from hardware (so the
    perturbation reaches its estimator too) instead of knowing its own command.
    """
    return LoopBlocks(sp, delayed(law) if delay else law, measured_input).at_inputs()
