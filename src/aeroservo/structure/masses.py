"""Concentrated masses on a wing: stores, engines, tip tanks and balance weights (SI units).

A :class:`ConcentratedMass` is a rigid body attached to the elastic axis at a spanwise
station (anywhere, not only at mesh nodes). Its CG lies ``offset`` aft of the elastic axis
(of the hinge line when it sits on a control surface) and ``vertical_offset`` above it; it
adds its mass, its static moment and its pitch inertia to the wing's mass matrix
(``system/point_masses.py``). Signs follow ``docs/conventions.md``.

The checks that need the wing (station inside the span, on its surface, offsets within a
few chords) are :func:`check_masses`, called by :class:`~aeroservo.structure.wing.Wing`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

from ..errors import RANGES, InputError, check_number, check_quantity

__all__ = ["ConcentratedMass", "check_masses", "OFFSET_CHORDS"]

OFFSET_CHORDS = 3.0
"""Largest chordwise or vertical offset of a mass's CG, in local chords (2 b): a store on a
pylon sits within a chord or two of the wing; beyond three chords a value is a unit error."""


@dataclass(frozen=True)
class ConcentratedMass:
    """A rigid concentrated mass attached to the wing.

    Parameters
    ----------
    station : float
        Spanwise position along the elastic axis [m], 0 < station <= span (need not be a
        mesh node).
    mass : float
        Mass [kg], >= 0 (0: a pure rotary inertia, which then needs ``inertia`` > 0; its
        offsets then carry no mass and change nothing).
    offset : float
        Chordwise position of its CG [m], positive aft, from the elastic axis (from the hinge
        line when ``surface`` is given: a balance weight ahead of the hinge has offset < 0).
    inertia : float
        Pitch moment of inertia about its own CG, axis along the span [kg m^2], >= 0.
    vertical_offset : float
        Height of its CG above the elastic axis [m] (adds ``mass * vertical_offset**2`` to the
        pitch inertia).
    surface : str or None
        Name of the control surface it sits on (it then rotates with the surface and is part
        of the flap's inertia), or ``None`` for a mass on the wing box.
    name : str
        Label used in messages, plots and reports.
    """

    station: float
    mass: float
    offset: float = 0.0
    inertia: float = 0.0
    vertical_offset: float = 0.0
    surface: str | None = None
    name: str = "mass"

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise InputError(f"mass.name = {self.name!r}: expected a string")
        n = label(self)
        span_hi = RANGES["span"].hi
        check_number(f"{n}.station", self.station, unit="m", lo=0.0, hi=span_hi, lo_open=True)
        check_quantity(f"{n}.mass", self.mass, "point_mass")
        check_number(f"{n}.offset", self.offset, unit="m", lo=-span_hi, hi=span_hi)
        check_quantity(f"{n}.inertia", self.inertia, "point_inertia")
        check_number(
            f"{n}.vertical_offset", self.vertical_offset, unit="m", lo=-span_hi, hi=span_hi
        )
        if self.mass == 0.0 and not (self.inertia > 0.0):
            raise InputError(f"{n}.mass = 0: a mass of 0 needs inertia > 0 (a rotary inertia)")
        if self.surface is not None and not isinstance(self.surface, str):
            raise InputError(
                f"{n}.surface = {self.surface!r}: expected the name of a control surface"
            )
        for key in ("station", "mass", "offset", "inertia", "vertical_offset"):
            object.__setattr__(self, key, float(getattr(self, key)))


def label(pm: ConcentratedMass) -> str:
    """How messages name a mass: ``mass 'store'``, or the key path a file reader gave as its
    name (``wing.masses[0]``)."""
    return pm.name if "masses[" in pm.name else f"mass '{pm.name}'"


class WingLike(Protocol):
    """What :func:`check_masses` needs of a :class:`~aeroservo.structure.wing.Wing` (which
    imports this module)."""

    span: float
    masses: tuple
    control_surfaces: tuple

    def segment_at(self, x: float) -> Any: ...

    def surface(self, name: str) -> Any: ...


def check_masses(wing: WingLike) -> None:
    """Check the wing's masses against the wing: inside the span, on their surface, offsets
    within :data:`OFFSET_CHORDS` local chords.

    Raises
    ------
    InputError
        One line naming the mass, the key and the value.
    """
    tol = 1e-9 * wing.span
    for i, pm in enumerate(wing.masses):
        if not isinstance(pm, ConcentratedMass):
            raise InputError(f"wing.masses[{i}] = {pm!r}: expected a ConcentratedMass")
        n = label(pm)
        if pm.station > wing.span + tol:
            raise InputError(
                f"{n}.station = {pm.station:g}: outside the wing, allowed range is "
                f"(0, {wing.span:g}] [m]"
            )
        chord = 2.0 * wing.segment_at(pm.station).semichord
        limit = OFFSET_CHORDS * chord
        for key in ("offset", "vertical_offset"):
            value = getattr(pm, key)
            if abs(value) > limit:
                raise InputError(
                    f"{n}.{key} = {value:g}: allowed range is [{-limit:g}, {limit:g}] [m] "
                    f"({OFFSET_CHORDS:g} local chords of {chord:g} m); is it in millimetres?"
                )
        if pm.surface is None:
            continue
        names = [cs.name for cs in wing.control_surfaces]
        if pm.surface not in names:
            raise InputError(
                f"{n}.surface = {pm.surface!r}: unknown; this wing has {names or 'none'}"
            )
        cs = wing.surface(pm.surface)
        if not cs.start - tol <= pm.station <= cs.end + tol:
            raise InputError(
                f"{n}.station = {pm.station:g}: not on control surface '{cs.name}', which "
                f"spans [{cs.start:g}, {cs.end:g}] [m]"
            )
