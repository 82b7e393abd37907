"""Switching a controller's use of the applied input on or off (its anti-windup).

When the actuator limits cut a command, a controller with states can update them with the
input actually applied (known in software) or with its own command. The first keeps an
estimator's model of the plant input right (LQG: predicting with ``u``) and a compensator's
state bounded in observer form (Astrom & Rundqwist, ACC 1989); the second is the plain linear
law, which may wind up. Both are the same law while no limit is active, so every linear
analysis (boundary, margins) is the same; only saturated time histories differ.
:func:`aeroservo.studies.recovery.recoverable_set` measures which recovers from more.

The types and their switch: an LQG and an LQG schedule (the estimator's prediction), a
compensator (H-infinity, a
brought compensator: its observer-form gain ``L``). An LQR, a static gain and an open loop
have no state to wind up; an MPC plans within its limits; a Python law does what it does:
they are refused.
"""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np

from ..errors import InputError
from .compensator import DiscreteCompensator
from .gain_schedule import GainSchedule
from .interface import StaticGain
from .output_feedback import OutputFeedback

__all__ = ["with_anti_windup", "has_anti_windup"]


def has_anti_windup(controller) -> bool | None:
    """Whether the controller uses the applied input (None: it has no such switch)."""
    if isinstance(controller, OutputFeedback):
        return bool(controller.applied_input)
    if isinstance(controller, GainSchedule):
        return has_anti_windup(controller.controllers[0])
    if isinstance(controller, DiscreteCompensator):
        return controller.n_states > 0 and bool(np.any(controller.anti_windup))
    if isinstance(controller, StaticGain) and not controller.needs_state:
        return False  # a compensator without state: nothing to wind up
    return None


def with_anti_windup(controller, on: bool):
    """A copy of ``controller`` with its use of the applied input switched on or off.

    Parameters
    ----------
    controller : OutputFeedback or DiscreteCompensator
    on : bool
        On: the LQG's estimator predicts with the applied input, a compensator gets its
        observer-form gain (:func:`~aeroservo.design.law.anti_windup_gain`); off: neither.

    Raises
    ------
    InputError
        A controller without a state to wind up, or one that plans within its limits.
    """
    if not isinstance(on, (bool, np.bool_)):
        raise InputError(f"anti_windup = {on!r}: expected True or False")
    if isinstance(controller, OutputFeedback):
        return replace(controller, applied_input=bool(on), kf=copy.deepcopy(controller.kf))
    if isinstance(controller, GainSchedule) and isinstance(
        controller.controllers[0], OutputFeedback
    ):
        members = [with_anti_windup(c, on) for c in controller.controllers]
        return replace(controller, controllers=members)
    if isinstance(controller, DiscreteCompensator):
        if controller.n_states == 0:
            return controller  # a static gain: nothing to wind up, nothing to switch
        own = controller.anti_windup
        gain = (own if np.any(own) else None) if on else np.zeros_like(own)
        return replace(controller, anti_windup=gain)
    if isinstance(controller, StaticGain) and not controller.needs_state:
        return controller  # a static gain on sensors: nothing to wind up, nothing to switch
    name = getattr(controller, "name", "") or type(controller).__name__
    raise InputError(
        f"anti_windup: not a switch of {name} (an LQR, static gain or open loop has no state "
        "to wind up, an MPC plans within its limits, a Python law is its own); LQG and "
        "compensators (H-infinity, brought) have it"
    )
