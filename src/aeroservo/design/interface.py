"""The controller interface: anything that maps sensors (or plant states) to commands at a sample
rate, accepted the same way by the simulator, the closed-loop boundary, the margins, the
verdicts, scenarios and trade studies.

:func:`as_controller` takes

* a controller of :mod:`aeroservo.design` (LQR, LQG, MPC, H-infinity, gain schedule, open loop,
  :class:`~aeroservo.design.compensator.DiscreteCompensator`, :class:`StaticGain`,
  :class:`PythonLaw`): returned as it is;
* a python-control ``StateSpace`` or ``TransferFunction`` whose inputs are named after sensors
  and outputs after controls: discrete at the loop's period, or continuous and discretised at
  the loop's sample rate (:func:`~aeroservo.design.compensator.compensator_from_lti`);
* an object with the attributes of the sampled-controller protocol
  (:class:`~aeroservo.design.protocol.Controller`: ``dt``, ``controls``, ``reset()``,
  ``command(y, x)``, ``update(y, u)``): a nonlinear law, simulated as it is.

Static gains (:func:`static_gain`, on named sensors or named plant states) and Python functions
(:func:`python_law`) need their signal names, so they are built by those functions. Anything
else is an :class:`~aeroservo.errors.InputError`. Linear controllers
(:class:`~aeroservo.design.protocol.LinearController`) have a
:class:`~aeroservo.design.law.LinearLaw` (``law``); the linear analyses (boundary, margins)
refuse a controller without one, never treating it as an open loop.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..linear.signals import check_names, describe
from .compensator import check_period, compensator_from_lti, sample_period
from .law import LinearLaw, state_gain
from .protocol import Controller, ScheduledController
from .user_code import PythonLaw, python_law

__all__ = [
    "as_controller",
    "controller_at",
    "static_gain",
    "python_law",
    "StaticGain",
    "PythonLaw",
    "has_linear_law",
]

ACCEPTED = (
    "a controller of aeroservo.design (lqr_controller, lqg, mpc, hinf, schedule, static_gain, "
    "python_law, DiscreteCompensator), a python-control StateSpace or TransferFunction with "
    "inputs named after sensors and outputs after controls, or an object with dt, controls, "
    "reset(), command(y, x) and update(y, u)"
)


def has_linear_law(controller: object) -> bool:
    """Whether a controller (or a gain schedule) has a linear law the analyses can use: a
    :class:`~aeroservo.design.protocol.LinearController` (its ``law``) or a
    :class:`~aeroservo.design.protocol.ScheduledController` (its ``at``)."""
    return callable(getattr(controller, "law", None)) or hasattr(controller, "at")


def controller_at(controller: Controller | ScheduledController, speed: float) -> Controller:
    """The controller in force at ``speed`` [m/s]: a schedule (anything with ``at``) evaluated
    there and what it returns checked by :func:`as_controller` at the schedule's rate; any
    other controller as it is."""
    if not hasattr(controller, "at"):
        return controller
    inner = controller.at(speed)
    if inner is controller or hasattr(inner, "at"):
        raise InputError(f"controller.at({speed:g}) returned a schedule, not a controller")
    return as_controller(inner, sample_rate=1.0 / controller.dt)


def as_controller(
    obj: object,
    *,
    sample_rate: float | None = None,
    method: str = "tustin",
    prewarp: float | None = None,
    sign: int = 1,
) -> Controller | ScheduledController:
    """Any supported controller as a sampled controller of this package (module docstring).

    Parameters
    ----------
    obj
        The controller.
    sample_rate : float, optional
        The loop's sample rate [Hz]: discretises a continuous python-control system, and is
        checked against the period of a discrete one.
    method, prewarp, sign
        Discretisation and sign of a python-control system, see
        :func:`~aeroservo.design.compensator.compensator_from_lti`.

    Returns
    -------
    Controller or ScheduledController
        ``obj`` itself when it is a controller (a :class:`~aeroservo.design.protocol.Controller`,
        a controller with a linear law, or a gain schedule), else a
        :class:`~aeroservo.design.compensator.DiscreteCompensator`.

    Raises
    ------
    InputError
        For an object that is none of the accepted kinds, or a period other than the loop's.
    """
    dt_loop = sample_period(sample_rate)
    if has_linear_law(obj) or isinstance(obj, Controller):
        dt = getattr(obj, "dt", None)
        if not isinstance(dt, (int, float, np.floating)) or isinstance(dt, bool) or not dt > 0:
            raise InputError(f"controller.dt = {describe(dt)}: expected a sample period [s] > 0")
        check_period(float(dt), dt_loop, "the controller")
        return obj
    if type(obj).__module__.startswith("control."):
        import control

        if isinstance(obj, (control.StateSpace, control.TransferFunction)):
            return compensator_from_lti(
                obj, sample_rate=sample_rate, method=method, prewarp=prewarp, sign=sign
            )
    if isinstance(obj, (np.ndarray, list, tuple, int, float)):
        raise InputError(
            f"controller = {describe(obj)}: a gain matrix needs its signal names: "
            "aeroservo.design.static_gain(K, controls=[...], sensors=[...] or states=[...], "
            "sample_rate=...)"
        )
    if callable(obj):
        raise InputError(
            f"controller = {describe(obj)}: a Python function needs its signals: "
            "aeroservo.design.python_law(fn, controls=[...], sensors=[...], sample_rate=...)"
        )
    raise InputError(f"controller = {describe(obj)}: expected {ACCEPTED}")


@dataclass
class StaticGain:
    """``u = sign K m``: a static gain, without controller state, on named sensors (``m = y``)
    or on named plant states (``m`` the named entries of the plant state ``x``).

    The states are those of the plant the loop closes around (``plant.state_labels``; the
    models of :class:`~aeroservo.StateSpaceBuilder` and ``aes.statespace`` are balanced, so a
    gain designed on them applies as it is). Use :func:`static_gain` to build one.

    Attributes
    ----------
    K : ndarray (n_controls, n_sensors or n_states)
        The gain, in the signals' units (e.g. N m per rad).
    controls : tuple of str
        The commands (rows of ``K``).
    sensors : tuple of str
        The measured sensors (columns of ``K``), or ``()`` for a gain on states.
    states : tuple of str
        The plant states (columns of ``K``), or ``()`` for a gain on sensors.
    dt : float
        Sample period [s].
    sign : {-1, 1}
        ``-1``: ``u = -K m`` (negative feedback, ``control.lqr``'s K); ``1``: ``u = +K m``.
    design_speed : float
        [m/s] (NaN if unknown).
    """

    K: np.ndarray
    controls: tuple
    sensors: tuple
    states: tuple
    dt: float
    sign: int = -1
    design_speed: float = float("nan")
    _placed: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        # u = -G x: the gain on the named states in their order, until law() places it on a
        # plant's states
        self._placed = -self.sign * self.K

    @property
    def needs_state(self) -> bool:
        """Whether it feeds back plant states (a gain on ``states``) rather than sensors."""
        return bool(self.states)

    @property
    def gain(self) -> np.ndarray:
        """``sign K``: the matrix with ``u = gain @ m``."""
        return self.sign * self.K

    def law(self, states: Sequence[str] = ()) -> LinearLaw:
        """The law around a plant with the named ``states`` (plant state names, filters
        included): a gain on states places its columns on them (every named state must be one
        of them); a gain on sensors ignores them."""
        if not self.states:
            m, p = self.K.shape
            z = np.zeros
            return LinearLaw(
                z((0, 0)), z((0, p)), z((m, 0)), self.sign * self.K, z((0, m)),
                self.controls, self.sensors, self.dt, "compensator", "static output gain",
            )  # fmt: skip
        states = list(states)
        missing = [s for s in self.states if s not in states]
        if missing:
            raise InputError(
                f"static gain: states {missing[:5]} are not states of the plant "
                f"({len(states)} states, e.g. {states[:4]})"
            )
        G = np.zeros((len(self.controls), len(states)))
        G[:, [states.index(s) for s in self.states]] = -self.sign * self.K
        self._placed = G
        return state_gain(G, self.controls, self.dt, source="static state gain")

    def reset(self) -> None:
        pass

    def command(self, y: np.ndarray, x: np.ndarray | None = None) -> np.ndarray:
        """``sign K y`` on sensors; on states ``sign K x[states]``, with ``x`` the named states
        in order or, once :meth:`law` has placed the gain on a plant's states, that plant's
        state."""
        if not self.states:
            return self.gain @ y
        if self._placed.shape[1] != np.size(x):
            raise InputError(
                f"static gain: the plant state has {np.size(x)} entries, the gain "
                f"{self._placed.shape[1]} columns: call law(plant.state_labels) to place it on "
                "the plant's states"
            )
        return -(self._placed @ x)

    def update(self, y: np.ndarray, u: np.ndarray) -> None:
        pass


MAX_GAIN = 1e12
"""Largest magnitude of a static gain's entry [signal units], as a gain file's ``matrix``."""


def static_gain(
    K,
    controls: Sequence[str],
    *,
    sensors: Sequence[str] | None = None,
    states: Sequence[str] | None = None,
    sample_rate: float,
    sign: int = -1,
) -> StaticGain:
    """A static output or state feedback ``u = sign K y`` (or ``u = sign K x``); by default
    ``u = -K y``, the LQR convention (``control.lqr``'s K). ``docs/conventions.md``.

    Parameters
    ----------
    K : array_like (n_controls, n_sensors or n_states)
        The gain, in the signals' units (e.g. N m per m/s^2).
    controls : sequence of str
        The commands (rows of K).
    sensors, states : sequence of str
        The measured sensors, or the plant states, the columns of K refer to (exactly one).
    sample_rate : float
        [Hz]
    sign : {-1, 1}
        ``-1`` (default): ``u = -K y``, negative feedback; ``1``: ``u = +K y``, the matrix maps
        the measurements to the command (as a controller file's ``sign``).

    Returns
    -------
    StaticGain
    """
    if isinstance(sign, bool) or sign not in (1, -1):
        raise InputError(f"sign = {describe(sign)}: expected -1 (u = -K y) or 1 (u = +K y)")
    controls = tuple(check_names("controls", controls))
    if (sensors is None) == (states is None):
        raise InputError("static_gain: give either sensors=[...] or states=[...], not both")
    cols = tuple(check_names("sensors" if states is None else "states", sensors or states))
    try:
        G = np.atleast_2d(np.array(K, dtype=float))  # a copy: the caller may change K
    except (TypeError, ValueError):
        raise InputError(f"K = {describe(K)}: expected a real matrix") from None
    if G.shape != (len(controls), len(cols)):
        raise InputError(
            f"K has shape {G.shape}; expected {(len(controls), len(cols))} "
            f"(controls x {'sensors' if states is None else 'states'})"
        )
    if not np.all(np.isfinite(G)):
        raise InputError("K has NaN or infinite entries")
    if np.abs(G).max(initial=0.0) > MAX_GAIN:
        raise InputError(
            f"K has an entry of {np.abs(G).max():.3g} in magnitude: at most {MAX_GAIN:g} (signal "
            "units; a controller file's gain matrix has the same bound)"
        )
    dt = sample_period(sample_rate)
    if states is not None:
        return StaticGain(G, controls, (), cols, dt, sign)
    return StaticGain(G, controls, cols, (), dt, sign)
