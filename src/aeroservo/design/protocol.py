"""The controller protocol: what every sampled controller provides, and what a linear one adds.

Every engine of the package takes a controller through
:func:`~aeroservo.design.interface.as_controller` and then uses only what is declared here:

* :class:`Controller`, what every controller provides: the time march
  (:func:`aeroservo.simulate.simulate`, the marches with nonlinear hinges and of the gust-loads
  studies) calls ``reset()`` before a run, then at each sample ``t_k = k dt`` ``command(y_k, x_k)``
  and, once the limits have made the applied input ``u_k`` of the command, ``update(y_k, u_k)``;
* :class:`LinearController`, what a linear one adds: its
  :class:`~aeroservo.design.law.LinearLaw` around a plant (``law(states)``), which the linear
  analyses use (closed-loop boundary, loop margins, judgement, realisability) and which the
  time march steps in place of ``command`` and ``update`` when the law is the controller
  exactly (:func:`steps_its_law`);
* :class:`ScheduledController`, a family of linear controllers over airspeed (a gain schedule):
  every engine takes the controller in force at the plant's speed, ``at(speed)``, first.

The classes are :class:`typing.Protocol` classes: a controller need not inherit from them, it
only has their attributes (``isinstance`` checks that it has them; it does not call them). Every
controller built by :mod:`aeroservo.design` satisfies its protocol
(``tests/test_controller_protocol.py``), and a user's object with the attributes of
:class:`Controller` is simulated as it is.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np

if TYPE_CHECKING:
    from .law import LinearLaw

__all__ = ["Controller", "LinearController", "ScheduledController", "steps_its_law"]


@runtime_checkable
class Controller(Protocol):
    """A sampled controller: what every controller provides (module docstring).

    Attributes
    ----------
    dt : float
        Sample period [s], > 0; it must be the loop's.
    controls : tuple of str
        The commands it emits, in order: names of plant inputs (e.g.
        ``"aileron_hinge_moment"``), in their units (N m).

    Notes
    -----
    The engines also read, when present:

    ``sensors`` : tuple of str
        The plant outputs it measures, in order, in their units (default ``()``: none).
    ``needs_state`` : bool
        Whether ``command`` reads the plant state ``x`` (default False).
    ``name`` : str
        What messages and result files call it (default its class name).

    A controller is ready to use once built: ``command`` works before any ``reset``.
    """

    dt: float
    controls: tuple[str, ...]

    def reset(self) -> None:
        """Clear its memory (estimator, integrator, sample counter): called before each run."""

    def command(self, y: np.ndarray, x: np.ndarray | None) -> np.ndarray:
        """The command at this sample.

        Parameters
        ----------
        y : ndarray (n_sensors,)
            The sensors' values at the sample, in ``sensors`` order and their units.
        x : ndarray (n_states,) or None
            The plant state at the sample (read only by a controller that ``needs_state``).

        Returns
        -------
        ndarray (n_controls,)
            One finite command per control, in ``controls`` order and their units.
        """

    def update(self, y: np.ndarray, u: np.ndarray) -> None:
        """Advance its state to the next sample.

        Parameters
        ----------
        y : ndarray (n_sensors,)
            The sensors' values passed to ``command`` at this sample.
        u : ndarray (n_controls,)
            The input applied to the plant: the command after the actuator's rate and magnitude
            limits (an estimator predicts with it, a compensator's anti-windup uses it).
        """


@runtime_checkable
class LinearController(Controller, Protocol):
    """A linear sampled controller: a :class:`Controller` with a linear law (module docstring).

    Attributes
    ----------
    sensors : tuple of str
        The plant outputs it measures, in order (``()`` for state feedback).
    needs_state : bool
        Whether it feeds back the plant state (LQR, a static gain on named states) rather than
        sensors.

    Notes
    -----
    The engines also read, when present:

    ``is_linear`` : bool
        False when the law holds only while no constraint is active (an MPC: its law is the
        LQG of its unconstrained first move); the time march then calls ``command`` and
        ``update``, and the linear analyses still use the law (default True).
    ``design_speed`` : float
        The airspeed it was designed at [m/s], the reference speed of its closed-loop boundary
        and judgement (default: none, NaN).
    """

    sensors: tuple[str, ...]
    needs_state: bool

    def law(self, states: Sequence[str]) -> LinearLaw:
        """Its :class:`~aeroservo.design.law.LinearLaw` around a plant.

        Parameters
        ----------
        states : sequence of str
            The plant's state names, sensor filters included (``plant.state_labels``): a state
            feedback places its gain on them; a controller reading sensors ignores them.
        """


@runtime_checkable
class ScheduledController(Protocol):
    """Linear controllers scheduled over airspeed (:class:`~aeroservo.design.GainSchedule`).

    Attributes
    ----------
    dt : float
        Sample period [s] of every controller of the schedule.
    controls, sensors : tuple of str
        Their commands and measured sensors.
    needs_state : bool
        Whether they feed back the plant state.
    design_speed : float
        Reference speed [m/s] of the schedule's closed-loop boundary and judgement (NaN if
        none).
    """

    dt: float
    controls: tuple[str, ...]
    sensors: tuple[str, ...]
    needs_state: bool
    design_speed: float

    def at(self, speed: float) -> LinearController:
        """The controller in force at ``speed`` [m/s]."""


def steps_its_law(controller: object) -> bool:
    """Whether the time march steps the controller's linear law in place of its ``command``
    and ``update``: a :class:`LinearController` whose law is the controller exactly (its
    ``is_linear`` is not False)."""
    return callable(getattr(controller, "law", None)) and bool(
        getattr(controller, "is_linear", True)
    )
