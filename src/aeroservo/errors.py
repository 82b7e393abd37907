"""The errors aeroservo raises, each with the exit code the command line gives it, and the
checks of user numbers.

* :class:`InputError` (a ``ValueError``), exit code 2: bad input; the message names the file,
  the key and the value.
* :class:`NumericalError` (an ``ArithmeticError``), exit code 1: a computation that cannot be
  completed.
* :class:`VerdictFailure`, exit code 3: a design that fails the verdict it was judged by.

All three derive from :class:`AeroservoError`; the built-in bases keep ``except ValueError`` and
``except ArithmeticError`` working as before.
"""

from __future__ import annotations

import math
import re

__all__ = [
    "AeroservoError",
    "InputError",
    "NumericalError",
    "VerdictFailure",
    "check_number",
    "check_int",
    "check_derived_speed",
    "parse_number",
    "show_value",
]


class AeroservoError(Exception):
    """Base of aeroservo's errors; ``exit_code`` is what the command line returns for it."""

    exit_code: int = 1


class InputError(AeroservoError, ValueError):
    """Invalid user input: the message names the field, the value and what is allowed
    (exit code 2)."""

    exit_code = 2


class NumericalError(AeroservoError, ArithmeticError):
    """A computation that cannot be completed on valid input: a solver that does not
    converge, a defective eigenproblem, a march that diverges numerically (exit code 1)."""

    exit_code = 1


class VerdictFailure(AeroservoError):
    """A design judged and found failing (an unstable closed loop, margins below the
    requirement), where the scenario did not expect it (exit code 3). The message is the
    verdict's one-line reason."""

    exit_code = 3


def check_number(
    field: str,
    value: object,
    *,
    unit: str = "",
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    hi_open: bool = False,
) -> float:
    """Validate one scalar and return it as ``float``.

    Parameters
    ----------
    field
        Dotted name of the field, used in the error message (e.g. ``"segments[0].EI"``).
    value
        The value to check. Booleans and non-numbers are rejected.
    unit
        Unit shown in the message (e.g. ``"N m^2"``).
    lo, hi
        Bounds; ``None`` means unbounded.
    lo_open, hi_open
        Whether the bound itself is excluded.

    Raises
    ------
    InputError
        If the value is not a finite real number within the bounds.
    """
    unit_txt = f" [{unit}]" if unit else ""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        try:
            import numpy as np

            if isinstance(value, np.generic) and np.isrealobj(value):
                value = float(value)
            else:
                raise TypeError
        except TypeError:
            raise InputError(
                f"{field} = {show_value(value)}: expected a real number{unit_txt}"
            ) from None
    try:
        v = float(value)
    except OverflowError:  # an integer beyond the floating-point range
        raise InputError(
            f"{field} = {show_value(value)}: must be a finite number{unit_txt}"
        ) from None
    if not math.isfinite(v):
        raise InputError(f"{field} = {v!r}: must be a finite number{unit_txt}")
    lo_ok = lo is None or (v > lo if lo_open else v >= lo)
    hi_ok = hi is None or (v < hi if hi_open else v <= hi)
    if not (lo_ok and hi_ok):
        left = "(-inf" if lo is None else ("(" if lo_open else "[") + f"{lo:g}"
        right = "inf)" if hi is None else f"{hi:g}" + (")" if hi_open else "]")
        raise InputError(f"{field} = {v:g}: allowed range is {left}, {right}{unit_txt}")
    return v


NUMBER = re.compile(r"[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?|[+-]?(inf|nan)", re.I)
"""A decimal number as text: what Python's ``float`` reads minus its digit separators
(``1_000``) and non-ASCII digits."""


def parse_number(text: str) -> float:
    """``float(text)`` for a plain decimal number only (ValueError otherwise)."""
    if not NUMBER.fullmatch(text.strip()):
        raise ValueError(f"not a number: {text!r}")
    return float(text)


def show_value(value: object) -> str:
    """A value as shown in a message: its repr on one line, at most 80 characters."""
    try:
        text = " ".join(repr(value).split())
    except Exception:  # a repr that fails (e.g. an integer too long to print)
        text = f"<{type(value).__name__}>"
    return text if len(text) <= 80 else text[:77] + "..."


def check_int(field: str, value: object, *, lo: int | None = None, hi: int | None = None) -> int:
    """Validate an integer (booleans rejected) within optional inclusive bounds."""
    if isinstance(value, bool) or not isinstance(value, int):
        try:
            import numpy as np

            if isinstance(value, np.integer):
                value = int(value)
            else:
                raise TypeError
        except TypeError:
            raise InputError(f"{field} = {show_value(value)}: expected an integer") from None
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        left = "-inf" if lo is None else str(lo)
        right = "inf" if hi is None else str(hi)
        raise InputError(f"{field} = {value}: allowed range is [{left}, {right}]")
    return int(value)


class Range:
    """The allowed values of one physical quantity: the one rule files, CLI and API share.

    Parameters
    ----------
    lo, hi : float
        Bounds [unit].
    unit : str
        SI unit shown in messages.
    lo_open, hi_open : bool
        Whether the bound itself is excluded.
    """

    __slots__ = ("lo", "hi", "unit", "lo_open", "hi_open")

    def __init__(self, lo, hi, unit="", lo_open=False, hi_open=False):
        self.lo, self.hi, self.unit = lo, hi, unit
        self.lo_open, self.hi_open = lo_open, hi_open

    def text(self) -> str:
        """The range as written in messages and in ``docs/conventions.md``."""
        left = ("(" if self.lo_open else "[") + f"{self.lo:g}"
        right = f"{self.hi:g}" + (")" if self.hi_open else "]")
        return f"{left}, {right}" + (f" {self.unit}" if self.unit else "")


MAX_ELEMENTS = 300
"""Most beam elements of a model (files, CLI and API), a 2 400-state system (at 400 elements
the modal branches lose their match with the full model on the Goland wing)."""

RANGES: dict[str, Range] = {
    # flight condition
    "density": Range(1e-4, 2.0, "kg/m^3"),
    "airspeed": Range(0.0, 1000.0, "m/s"),
    "flight_speed": Range(0.1, 1000.0, "m/s"),
    "speed_factor": Range(0.05, 10.0),
    # wing geometry, mass and stiffness
    "span": Range(1e-3, 1e4, "m"),
    "semichord": Range(1e-4, 1e3, "m"),
    "mass_per_length": Range(1e-6, 1e6, "kg/m"),
    "inertia_per_length": Range(0.0, 1e6, "kg m", lo_open=True),
    "static_moment": Range(-1e6, 1e6, "kg m/m"),
    "stiffness": Range(1e-6, 1e13, "N m^2"),
    "flap_stiffness": Range(0.0, 1e13, "N m^2"),
    "hinge_stiffness": Range(0.0, 1e12, "N m/rad per m"),
    "actuator_stiffness": Range(0.0, 1e12, "N m/rad", lo_open=True),
    "point_mass": Range(0.0, 1e6, "kg"),
    "point_inertia": Range(0.0, 1e7, "kg m^2"),
    # aerodynamics
    "wagner_coefficient": Range(0.0, 1.0, lo_open=True),
    "wagner_exponent": Range(1e-4, 1000.0),
    "gust_length": Range(0.01, 1e5, "m"),
    "gust_velocity": Range(-50.0, 50.0, "m/s"),
    # time marching and control
    "duration": Range(0.0, 600.0, "s", lo_open=True),
    "time": Range(0.0, 600.0, "s"),
    "sample_rate": Range(1.0, 1e5, "Hz"),
    "bryson": Range(1e-9, 1e9, "signal units"),
    "limit": Range(0.0, 1e12, "signal units (per s for rates)", lo_open=True),
    "variance": Range(0.0, 1e6, "signal units^2"),
    "frequency": Range(0.0, 1e5, "Hz"),
    "structural_g": Range(0.0, 2.0, hi_open=True),
    "rayleigh_alpha": Range(0.0, 1e3, "1/s"),
    "rayleigh_beta": Range(0.0, 1.0, "s"),
    "estimator_variance": Range(0.0, 1e6, "signal units^2", lo_open=True),
    "input_noise": Range(0.0, 1e12, "control units^2"),
}
"""Allowed range of every physical quantity (documented in ``docs/conventions.md``)."""


def check_quantity(field: str, value: object, quantity: str) -> float:
    """Validate ``value`` against the range of ``quantity`` in :data:`RANGES`.

    Parameters
    ----------
    field
        Dotted name used in the message (e.g. ``"wing.segments[0].EI"``).
    value
        The value to check.
    quantity
        A key of :data:`RANGES` (e.g. ``"stiffness"``).

    Raises
    ------
    InputError
        If the value is not a finite real number within the quantity's range.
    """
    r = RANGES[quantity]
    return check_number(
        field, value, unit=r.unit, lo=r.lo, hi=r.hi, lo_open=r.lo_open, hi_open=r.hi_open
    )


def check_derived_speed(field: str, value: object, speed: float, how: str) -> float:
    """A speed [m/s] derived from a user's key (a multiple of the open-loop flutter speed, a
    margin on a speed), refused beyond the airspeed range of :data:`RANGES` with the key that
    produced it.

    Parameters
    ----------
    field
        The key, with its file: ``"scenario.toml: flight.speed_factor"``.
    value
        The key's value.
    speed
        The speed it gives [m/s].
    how
        How it gives it, e.g. ``"x the open-loop flutter speed 137.4 m/s"``.

    Raises
    ------
    InputError
        ``"<field> = <value>: gives <speed> m/s (<how>), beyond the airspeed range ..."``.
    """
    r = RANGES["airspeed"]
    if not r.lo <= speed <= r.hi:
        raise InputError(
            f"{field} = {show_value(value)}: gives {speed:.6g} m/s ({how}), beyond the airspeed "
            f"range {r.text()}"
        )
    return speed
