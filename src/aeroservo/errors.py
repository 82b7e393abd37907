"""Error types raised by aeroservo."""

from __future__ import annotations

import math


class InputError(ValueError):
    """Invalid user input: the message names the field, the value and what is allowed."""


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
            raise InputError(f"{field} = {value!r}: expected a real number{unit_txt}") from None
    v = float(value)
    if not math.isfinite(v):
        raise InputError(f"{field} = {v!r}: must be a finite number{unit_txt}")
    lo_ok = lo is None or (v > lo if lo_open else v >= lo)
    hi_ok = hi is None or (v < hi if hi_open else v <= hi)
    if not (lo_ok and hi_ok):
        left = "(-inf" if lo is None else ("(" if lo_open else "[") + f"{lo:g}"
        right = "inf)" if hi is None else f"{hi:g}" + (")" if hi_open else "]")
        raise InputError(f"{field} = {v:g}: allowed range is {left}, {right}{unit_txt}")
    return v


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
            raise InputError(f"{field} = {value!r}: expected an integer") from None
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        left = "-inf" if lo is None else str(lo)
        right = "inf" if hi is None else str(hi)
        raise InputError(f"{field} = {value}: allowed range is [{left}, {right}]")
    return int(value)
