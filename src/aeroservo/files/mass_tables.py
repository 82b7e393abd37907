"""The ``[[wing.masses]]`` tables of a wing file: concentrated masses read and written.

Keys (SI, ``docs/wing-file.md``): ``station`` [m] and ``mass`` [kg] required; ``offset`` [m,
+ aft of the elastic axis, or of the hinge with ``surface``], ``inertia`` [kg m^2, about its
own CG], ``vertical_offset`` [m, + up], ``surface`` (a control surface's name) and ``name``
optional. Every error names the table, the key and the value.
"""

from __future__ import annotations

import json
from collections.abc import Mapping

from ..errors import InputError, check_number
from ..structure.masses import ConcentratedMass

__all__ = ["MASS_REQUIRED", "MASS_OPTIONAL", "masses_from_list", "masses_toml"]

MASS_REQUIRED = ("station", "mass")
MASS_OPTIONAL = ("offset", "inertia", "vertical_offset", "surface", "name")
_UNITS = {
    "station": "m",
    "mass": "kg",
    "offset": "m",
    "inertia": "kg m^2",
    "vertical_offset": "m",
}


def masses_from_list(where: str, value: object) -> tuple[ConcentratedMass, ...]:
    """The concentrated masses of a ``[[wing.masses]]`` array of tables.

    Parameters
    ----------
    where : str
        Dotted name of the array for messages (e.g. ``"wing.masses"``).
    value : object
        The array as read from TOML.

    Raises
    ------
    InputError
        A missing or unknown key, or a value of the wrong type or out of range.
    """
    if not isinstance(value, list) or not all(isinstance(v, Mapping) for v in value):
        raise InputError(f"{where} = {value!r}: expected an array of tables ([[{where}]])")
    out = []
    for i, tbl in enumerate(value):
        w = f"{where}[{i}]"
        unknown = [k for k in tbl if k not in MASS_REQUIRED + MASS_OPTIONAL]
        if unknown:
            allowed = ", ".join(MASS_REQUIRED + MASS_OPTIONAL)
            raise InputError(f"{w}.{unknown[0]}: unknown key (allowed: {allowed})")
        missing = [k for k in MASS_REQUIRED if k not in tbl]
        if missing:
            raise InputError(f"{w}.{missing[0]}: missing required key")
        nums = {k: check_number(f"{w}.{k}", tbl[k], unit=u) for k, u in _UNITS.items() if k in tbl}
        for key in ("surface", "name"):
            if key in tbl and not isinstance(tbl[key], str):
                raise InputError(f"{w}.{key} = {tbl[key]!r}: expected a string")
        name = tbl.get("name", w)
        out.append(ConcentratedMass(**nums, surface=tbl.get("surface"), name=name))
    return tuple(out)


def masses_toml(masses: tuple[ConcentratedMass, ...]) -> list[str]:
    """The ``[[wing.masses]]`` tables (lines) of ``masses``; numbers with ``repr`` (exact)."""
    lines: list[str] = []
    for pm in masses:
        lines += ["", "[[wing.masses]]"]
        if "masses[" not in pm.name:  # a name of its own, not the key path the reader gave
            lines.append(f"name = {json.dumps(pm.name)}")
        lines += [f"{k} = {float(getattr(pm, k))!r}" for k in _UNITS]
        if pm.surface is not None:
            lines.append(f"surface = {json.dumps(pm.surface)}")
    return lines
