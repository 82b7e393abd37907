"""Servo dynamics between a commanded surface deflection and the actuator springs."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError, check_number

__all__ = ["Servo", "servos_of"]


@dataclass(frozen=True)
class Servo:
    """Servo dynamics between a commanded deflection and the actuator springs.

    Parameters
    ----------
    order : int
        0 (ideal: the springs follow the command), 1 (first order, ``y' = w (u - y)``) or 2
        (second order, ``y'' = w^2 (u - y) - 2 zeta w y'``).
    bandwidth : float
        w [rad/s] for order 1 and 2.
    damping : float
        zeta [-] for order 2.
    """

    order: int = 0
    bandwidth: float = 0.0
    damping: float = 0.7

    def __post_init__(self) -> None:
        if self.order not in (0, 1, 2):
            raise InputError(f"servo.order = {self.order!r}: allowed values are 0, 1, 2")
        if self.order > 0:
            check_number("servo.bandwidth", self.bandwidth, unit="rad/s", lo=0.0, lo_open=True)
        if self.order == 2:
            check_number("servo.damping", self.damping, lo=0.0, lo_open=True)

    @property
    def n_states(self) -> int:
        return self.order


def servos_of(wing, servo, inputs) -> dict[int, Servo]:
    """Servo of each surface with a commanded-deflection input."""
    out = {}
    for d in inputs:
        if d.kind != "command":
            continue
        name = wing.control_surfaces[d.surface].name
        if servo is None:
            sv = Servo()
        elif isinstance(servo, Servo):
            sv = servo
        elif isinstance(servo, dict):
            sv = servo.get(name, Servo())
        else:
            raise InputError(f"servo = {servo!r}: expected a Servo or a dict of Servo by surface")
        out[d.surface] = sv
    return out
