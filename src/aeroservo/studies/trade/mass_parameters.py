"""Concentrated-mass parameters of a trade study: ``masses[i].mass``, ``.offset`` and the rest.

A trade study may sweep any of the five wing-file keys of the base wing's concentrated mass
``i`` (:class:`~aeroservo.structure.masses.ConcentratedMass`): ``masses[i].mass`` [kg],
``masses[i].station`` [m], ``masses[i].offset`` [m, + aft], ``masses[i].inertia`` [kg m^2] and
``masses[i].vertical_offset`` [m, + up], in the units and with the meaning of the wing file
(absolute values, not fractions). The product of ``masses[0].mass`` and ``masses[0].offset`` is
the classic store-flutter carpet (flutter speed over store mass and chordwise CG position).
:class:`TradeParameters` makes them known wherever the trade study looks its parameters up.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Mapping

from ...errors import InputError, check_number
from ...structure.wing import Wing

__all__ = [
    "MASS_PARAMETER",
    "TradeParameters",
    "mass_parameter",
    "check_mass_values",
    "with_masses",
]

MASS_PARAMETER = re.compile(r"masses\[(\d+)\]\.(mass|station|offset|inertia|vertical_offset)")
"""Name of a concentrated-mass parameter: ``masses[<index>].<key>``."""

_INFO = {
    "mass": ("kg", "mass"),
    "station": ("m", "spanwise station along the elastic axis"),
    "offset": ("m", "chordwise CG position, + aft of the elastic axis (of the hinge on a flap)"),
    "inertia": ("kg m^2", "pitch moment of inertia about its own CG"),
    "vertical_offset": ("m", "vertical CG position, + above the elastic axis"),
}

_DOMAINS = {
    "mass": {"lo": 0.0, "lo_open": True},
    "station": {"lo": 0.0, "lo_open": True},
    "offset": {},
    "inertia": {"lo": 0.0},
    "vertical_offset": {},
}


def mass_parameter(name: object) -> tuple[int, str] | None:
    """``(index, key)`` of a mass parameter's name, or None for any other name."""
    hit = MASS_PARAMETER.fullmatch(name) if isinstance(name, str) else None
    return None if hit is None else (int(hit.group(1)), hit.group(2))


class TradeParameters(dict):
    """The fixed parameters of a trade study (name -> (unit, description)); a name
    ``masses[i].key`` (:data:`MASS_PARAMETER`) is known too, with its unit and description,
    although not listed (the base wing says how many masses there are)."""

    def __missing__(self, name):
        hit = mass_parameter(name)
        if hit is None:
            raise KeyError(name)
        unit, what = _INFO[hit[1]]
        return unit, f"{what} of the base wing's concentrated mass {hit[0]}"

    def __contains__(self, name: object) -> bool:
        return dict.__contains__(self, name) or mass_parameter(name) is not None

    def get(self, name, default=None):
        return self[name] if name in self else default


def check_mass_values(wing: Wing, name: str, values: tuple) -> tuple[float, ...]:
    """Check the swept values of mass parameter ``name`` against the base wing (the mass
    exists; every value gives a valid wing); returns them as floats.

    Raises
    ------
    InputError
        One line naming ``parameters.<name>[j]`` and the value.
    """
    i, key = mass_parameter(name)
    if i >= len(wing.masses):
        raise InputError(
            f"parameters.{name}: the base wing has {len(wing.masses)} concentrated masses "
            f"(masses[0] to masses[{len(wing.masses) - 1}])"
            if wing.masses
            else f"parameters.{name}: the base wing has no concentrated masses ([[wing.masses]])"
        )
    unit = _INFO[key][0]
    out = []
    for j, v in enumerate(values):
        label = f"parameters.{name}[{j}]"
        v = check_number(label, v, unit=unit, **_DOMAINS[key])
        try:
            with_masses(wing, {name: v})
        except InputError as exc:
            raise InputError(f"{label} = {v:g}: {exc}") from None
        out.append(v)
    return tuple(out)


def with_masses(wing: Wing, params: Mapping) -> Wing:
    """The wing with the mass parameters of ``params`` set (other names are ignored)."""
    masses = list(wing.masses)
    changed = False
    for name, v in params.items():
        hit = mass_parameter(name)
        if hit is None:
            continue
        i, key = hit
        if i >= len(masses):
            raise InputError(f"parameters.{name}: the wing has {len(masses)} concentrated masses")
        masses[i] = dataclasses.replace(masses[i], **{key: float(v)})
        changed = True
    return dataclasses.replace(wing, masses=tuple(masses)) if changed else wing
