"""Actuator dynamics between a controller's command and the plant input it drives.

An :class:`ActuatorDynamics` is a linear transfer function of unit static gain, first to third
order, in series with one control input of the plant (a hinge moment or a commanded deflection):

* order 1: ``y' = w (c - y)``, ``A(s) = w / (s + w)``;
* order 2: ``y'' = w^2 (c - y) - 2 zeta w y'``, ``A(s) = w^2 / (s^2 + 2 zeta w s + w^2)``;
* order 3: a real pole ``p`` before the second-order pair, ``z' = p (c - z)``,
  ``y'' = w^2 (z - y) - 2 zeta w y'``, ``A(s) = p w^2 / ((s + p)(s^2 + 2 zeta w s + w^2))``,
  the form identified for the trailing-edge and spoiler actuators of NASA's BACT wind-tunnel
  model (Waszak & Fung, NASA TM-1998-208452) and used for the servos of the Active Flexible
  Wing programme.

``c`` is the command, ``y`` the actuator output (what the plant receives), in the control's
unit. Its states are appended to the plant as ``<control>_actuator`` (``y``),
``<control>_actuator_rate`` (``y'``, orders 2 and 3) and ``<control>_actuator_lag`` (``z``,
order 3), unscaled, and its output and rate are plant outputs ``<control>_actuator`` and
``<control>_actuator_rate``. The position and rate limits of a loop bound this output
(:mod:`aeroservo.simulate.actuator_limits`); linear analyses (eigenvalues, margins broken at
the command, the closed-loop boundary) see the transfer function.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_number
from ..linear.signals import describe

__all__ = [
    "ActuatorDynamics",
    "actuator_arrays",
    "actuator_labels",
    "actuator_outputs",
    "actuators_of",
    "MAX_ACTUATOR",
    "STATE_SUFFIXES",
]

MAX_ACTUATOR = 1.0e5
"""Largest actuator frequency [rad/s] (beyond it an actuator is ideal for any flutter loop)."""


@dataclass(frozen=True)
class ActuatorDynamics:
    """A unit-gain actuator transfer function of order 1 to 3.

    Parameters
    ----------
    order : int
        1, 2 or 3 (see the module docstring).
    bandwidth : float
        ``w`` [rad/s]: the pole of order 1, the natural frequency of the pair of orders 2-3.
    damping : float
        ``zeta`` [-] of the pair (orders 2 and 3).
    pole : float, optional
        ``p`` [rad/s], the real pole of order 3 (default: ``bandwidth``).
    """

    order: int = 2
    bandwidth: float = 100.0
    damping: float = 0.7
    pole: float | None = None

    def __post_init__(self) -> None:
        order = self.order
        is_int = isinstance(order, (int, np.integer)) and not isinstance(order, bool)
        if not is_int or order not in (1, 2, 3):
            raise InputError(f"actuator.order = {describe(order)}: expected an integer 1, 2 or 3")
        object.__setattr__(self, "order", int(order))
        w = check_number(
            "actuator.bandwidth", self.bandwidth, unit="rad/s", lo=0.0, lo_open=True,
            hi=MAX_ACTUATOR,
        )  # fmt: skip
        zeta = check_number("actuator.damping", self.damping, lo=0.0, lo_open=True, hi=10.0)
        if self.pole is not None and self.order != 3:
            raise InputError(
                f"actuator.pole = {describe(self.pole)}: only an order-3 actuator has one"
            )
        p = w if self.pole is None else self.pole
        p = check_number("actuator.pole", p, unit="rad/s", lo=0.0, lo_open=True, hi=MAX_ACTUATOR)
        object.__setattr__(self, "bandwidth", w)
        object.__setattr__(self, "damping", zeta)
        object.__setattr__(self, "pole", p if self.order == 3 else None)

    @property
    def n_states(self) -> int:
        return self.order

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(A, B, C, D)`` with states ``[y, y', z][:order]`` and outputs ``[y, y']``."""
        w, z = self.bandwidth, self.damping
        if self.order == 1:
            return (np.array([[-w]]), np.array([[w]]), np.array([[1.0], [-w]]),
                    np.array([[0.0], [w]]))  # fmt: skip
        A = np.zeros((self.order, self.order))
        B = np.zeros((self.order, 1))
        A[0, 1] = 1.0
        A[1, 0], A[1, 1] = -(w**2), -2.0 * z * w
        if self.order == 2:
            B[1, 0] = w**2
        else:
            A[1, 2] = w**2
            A[2, 2], B[2, 0] = -self.pole, self.pole
        C = np.zeros((2, self.order))
        C[0, 0] = C[1, 1] = 1.0
        return A, B, C, np.zeros((2, 1))

    def response(self, f_hz: np.ndarray) -> np.ndarray:
        """Frequency response ``A(j 2 pi f)`` [-] at ``f_hz`` [Hz]."""
        s = 2j * np.pi * np.asarray(f_hz, dtype=float)
        w, z = self.bandwidth, self.damping
        if self.order == 1:
            return w / (s + w)
        pair = w**2 / (s**2 + 2 * z * w * s + w**2)
        return pair if self.order == 2 else pair * self.pole / (s + self.pole)

    def text(self) -> str:
        """One line, e.g. ``order 3, pair 25 Hz zeta 0.7, pole 40 Hz``."""
        hz = 1.0 / (2.0 * np.pi)
        if self.order == 1:
            return f"order 1, pole {self.bandwidth * hz:.4g} Hz"
        pair = f"pair {self.bandwidth * hz:.4g} Hz zeta {self.damping:.3g}"
        return f"order {self.order}, {pair}" + (
            f", pole {self.pole * hz:.4g} Hz" if self.order == 3 else ""
        )


STATE_SUFFIXES = ("_actuator", "_actuator_rate", "_actuator_lag")
"""Suffixes of an actuator's states on a control: position, rate, lag (the first two are also
its outputs)."""


def actuator_labels(control: str, actuator: ActuatorDynamics) -> list[str]:
    """State names of ``actuator`` on ``control`` (position, rate, lag)."""
    return [control + s for s in STATE_SUFFIXES[: actuator.order]]


def actuator_outputs(controls) -> list[str]:
    """Output names of the actuators on ``controls``: position and rate of each, in order."""
    return [c + s for c in controls for s in STATE_SUFFIXES[:2]]


def actuators_of(actuator, controls: Sequence[str]) -> dict[str, ActuatorDynamics]:
    """The actuator of each control: one :class:`ActuatorDynamics` for all, a mapping by control
    name (controls it omits are ideal), or None (all ideal)."""
    controls = [c for c in controls if c != "gust"]
    if actuator is None:
        return {}
    if isinstance(actuator, ActuatorDynamics):
        return dict.fromkeys(controls, actuator)
    if not isinstance(actuator, Mapping):
        raise InputError(
            f"actuator = {describe(actuator)}: expected an ActuatorDynamics or a dict of them by "
            "control"
        )
    for name, a in actuator.items():
        if name not in controls:
            raise InputError(f"actuator[{name!r}]: not a control of this loop; controls {controls}")
        if not isinstance(a, ActuatorDynamics):
            raise InputError(
                f"actuator[{name!r}] = {describe(a)}: expected an aeroservo ActuatorDynamics"
            )
    return {c: actuator[c] for c in controls if c in actuator}


def actuator_arrays(
    A, B, C, D, columns: Sequence[int], actuators: Sequence[ActuatorDynamics]
) -> tuple:
    """A plant's ``(A, B, C, D)`` with actuators in series with its inputs ``columns``.

    The actuator states are appended in the order given (states of :func:`actuator_labels`),
    then two outputs per actuator (its output and rate) after the plant's. The input of each
    actuated column becomes the command; the plant input is the actuator output ``y``.
    """
    n, m = B.shape
    p = C.shape[0]
    parts = [a.arrays() for a in actuators]
    na = sum(a.order for a in actuators)
    Aa = np.zeros((n + na, n + na))
    Ba = np.zeros((n + na, m))
    Ca = np.zeros((p + 2 * len(actuators), n + na))
    Da = np.zeros((p + 2 * len(actuators), m))
    Aa[:n, :n], Ba[:n], Ca[:p, :n], Da[:p] = A, B, C, D
    i = n
    for j, (col, (a, b, c, d)) in enumerate(zip(columns, parts, strict=True)):
        k = a.shape[0]
        s = slice(i, i + k)
        Aa[s, s], Ba[s, col] = a, b[:, 0]
        Aa[:n, i] = B[:, col]  # the plant receives the actuator output y = x[i]
        Ba[:n, col] = 0.0
        Ca[:p, i] = D[:, col]
        Da[:p, col] = 0.0
        Ca[p + 2 * j : p + 2 * j + 2, s], Da[p + 2 * j : p + 2 * j + 2, col] = c, d[:, 0]
        i += k
    return Aa, Ba, Ca, Da
