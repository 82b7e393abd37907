"""Servo dynamics between a commanded surface deflection and the actuator springs."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_number
from .signals import describe

__all__ = ["Servo", "servos_of", "MAX_BANDWIDTH"]

MAX_BANDWIDTH = 1.0e6
"""Largest servo bandwidth [rad/s] (beyond it the servo is ideal for any flutter problem)."""


@dataclass(frozen=True)
class Servo:
    """Servo dynamics between a commanded deflection and the actuator springs.

    Parameters
    ----------
    order : int
        0 (ideal: the springs follow the command), 1 (first order, ``y' = w (u - y)``) or 2
        (second order, ``y'' = w^2 (u - y) - 2 zeta w y'``).
    bandwidth : float
        w [rad/s] for order 1 and 2 (at most :data:`MAX_BANDWIDTH`).
    damping : float
        zeta [-] for order 2 (at most 100).
    """

    order: int = 0
    bandwidth: float = 0.0
    damping: float = 0.7

    def __post_init__(self) -> None:
        order = self.order
        is_int = isinstance(order, (int, np.integer)) and not isinstance(order, bool)
        if not is_int or order not in (0, 1, 2):
            raise InputError(f"servo.order = {describe(order)}: expected an integer 0, 1 or 2")
        object.__setattr__(self, "order", int(order))
        w = check_number(
            "servo.bandwidth",
            self.bandwidth,
            unit="rad/s",
            lo=0.0,
            lo_open=self.order > 0,
            hi=MAX_BANDWIDTH,
        )
        zeta = check_number("servo.damping", self.damping, lo=0.0, lo_open=True, hi=100.0)
        object.__setattr__(self, "bandwidth", w)
        object.__setattr__(self, "damping", zeta)

    @property
    def n_states(self) -> int:
        return self.order


def servos_of(wing, servo, inputs) -> dict[int, Servo]:
    """Servo of each surface with a commanded-deflection input."""
    if servo is not None and not isinstance(servo, (Servo, dict)):
        raise InputError(
            f"servo = {describe(servo)}: expected a Servo or a dict of Servo by surface"
        )
    if isinstance(servo, dict):
        surfaces = [cs.name for cs in wing.control_surfaces]
        for name, sv in servo.items():
            if name not in surfaces:
                raise InputError(
                    f"servo[{name!r}]: unknown control surface; this wing has {surfaces}"
                )
            if not isinstance(sv, Servo):
                raise InputError(f"servo[{name!r}] = {describe(sv)}: expected an aeroservo.Servo")
    out = {}
    for d in inputs:
        if d.kind != "command":
            continue
        name = wing.control_surfaces[d.surface].name
        if servo is None:
            sv = Servo()
        elif isinstance(servo, Servo):
            sv = servo
        else:
            sv = servo.get(name, Servo())
        out[d.surface] = sv
    return out
