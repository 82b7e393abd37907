"""Wing description files (TOML, schema in ``docs/wing-file.md``).

A file has a ``[wing]`` table (``span``, ``[[wing.segments]]``, optional
``[[wing.control_surfaces]]`` with ``[[wing.control_surfaces.actuators]]``) and an optional
``[analysis]`` table with defaults for ``density``, ``elements``, ``wagner``, ``v_max`` and
``n_modes``. Every error names the file, the key and the value.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from ..aero.indicial import wagner_set
from ..errors import InputError, check_int, check_number
from ..structure.wing import Actuator, ControlSurface, Segment, Wing

__all__ = ["AnalysisOptions", "load_wing", "wing_from_dict", "resolve_wing"]

SEGMENT_KEYS = ("start", "end", "semichord", "a", "mass", "x_alpha", "inertia", "EI", "GJ")
SURFACE_REQUIRED = ("name", "start", "end", "hinge", "static_moment", "inertia")
SURFACE_OPTIONAL = ("GJ", "hinge_stiffness", "actuators")
ACTUATOR_KEYS = ("station", "stiffness")
ANALYSIS_KEYS = ("density", "elements", "wagner", "v_max", "n_modes")


@dataclass(frozen=True)
class AnalysisOptions:
    """Analysis defaults stored with a wing; command-line options override them.

    Attributes
    ----------
    density : float
        Air density [kg/m^3] (default 1.225, sea level).
    elements : int
        Number of beam elements (default 10).
    wagner : object
        Wagner set name or ``{"A": [...], "b": [...]}`` (default ``"rt_jones"``).
    v_max : float or None
        Upper end of the speed search [m/s] (default: automatic).
    n_modes : int or None
        Tracked modes (default: automatic).
    """

    density: float = 1.225
    elements: int = 10
    wagner: object = "rt_jones"
    v_max: float | None = None
    n_modes: int | None = None


def _check_keys(where: str, table: object, required: tuple, optional: tuple = ()) -> Mapping:
    if not isinstance(table, Mapping):
        raise InputError(f"{where} = {table!r}: expected a table")
    unknown = sorted(set(table) - set(required) - set(optional))
    if unknown:
        raise InputError(
            f"{where}.{unknown[0]}: unknown key; allowed keys are {sorted(required + optional)}"
        )
    missing = [k for k in required if k not in table]
    if missing:
        raise InputError(f"{where}.{missing[0]}: missing required key")
    return table


def _list_of_tables(where: str, value: object) -> list:
    if not isinstance(value, list) or not all(isinstance(v, Mapping) for v in value):
        raise InputError(f"{where} = {value!r}: expected an array of tables ([[{where}]])")
    return value


def wing_from_dict(data: Mapping, where: str = "wing") -> Wing:
    """Build a :class:`Wing` from the ``[wing]`` table of a wing file."""
    tbl = _check_keys(where, data, ("span", "segments"), ("name", "control_surfaces"))
    name = tbl.get("name", "wing")
    if not isinstance(name, str):
        raise InputError(f"{where}.name = {name!r}: expected a string")
    segments = []
    for i, seg in enumerate(_list_of_tables(f"{where}.segments", tbl["segments"])):
        w = f"{where}.segments[{i}]"
        _check_keys(w, seg, SEGMENT_KEYS)
        vals = {k: check_number(f"{w}.{k}", seg[k]) for k in SEGMENT_KEYS}
        segments.append(Segment(**vals, name=w))
    surfaces = []
    for i, cs in enumerate(
        _list_of_tables(f"{where}.control_surfaces", tbl.get("control_surfaces", []))
    ):
        w = f"{where}.control_surfaces[{i}]"
        _check_keys(w, cs, SURFACE_REQUIRED, SURFACE_OPTIONAL)
        if not isinstance(cs["name"], str):
            raise InputError(f"{w}.name = {cs['name']!r}: expected a string")
        acts = []
        for j, act in enumerate(_list_of_tables(f"{w}.actuators", cs.get("actuators", []))):
            wa = f"{w}.actuators[{j}]"
            _check_keys(wa, act, ACTUATOR_KEYS)
            acts.append(
                Actuator(
                    station=check_number(f"{wa}.station", act["station"], unit="m"),
                    stiffness=check_number(f"{wa}.stiffness", act["stiffness"], unit="N m/rad"),
                    name=wa,
                )
            )
        nums = {
            k: check_number(f"{w}.{k}", cs[k])
            for k in ("start", "end", "hinge", "static_moment", "inertia", "GJ", "hinge_stiffness")
            if k in cs
        }
        surfaces.append(ControlSurface(name=cs["name"], actuators=tuple(acts), **nums))
    span = check_number(f"{where}.span", tbl["span"], unit="m")
    return Wing(span=span, segments=tuple(segments), control_surfaces=tuple(surfaces), name=name)


def analysis_from_dict(data: Mapping, where: str = "analysis") -> AnalysisOptions:
    """Build :class:`AnalysisOptions` from the ``[analysis]`` table."""
    tbl = _check_keys(where, data, (), ANALYSIS_KEYS)
    opts = {}
    if "density" in tbl:
        opts["density"] = check_number(
            f"{where}.density", tbl["density"], unit="kg/m^3", lo=0.0, lo_open=True
        )
    if "elements" in tbl:
        opts["elements"] = check_int(f"{where}.elements", tbl["elements"], lo=1, hi=100_000)
    if "wagner" in tbl:
        wagner_set(tbl["wagner"])
        opts["wagner"] = tbl["wagner"]
    if "v_max" in tbl:
        opts["v_max"] = check_number(
            f"{where}.v_max", tbl["v_max"], unit="m/s", lo=0.0, lo_open=True
        )
    if "n_modes" in tbl:
        opts["n_modes"] = check_int(f"{where}.n_modes", tbl["n_modes"], lo=1)
    return AnalysisOptions(**opts)


def load_wing(path: str | Path) -> tuple[Wing, AnalysisOptions]:
    """Read a wing file.

    Parameters
    ----------
    path : str or Path
        TOML file (schema: ``docs/wing-file.md``).

    Returns
    -------
    (Wing, AnalysisOptions)

    Raises
    ------
    InputError
        With the file name, the key and the value of the first problem found.
    """
    path = Path(path)
    try:
        with path.open("rb") as fh:
            data = tomllib.load(fh)
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML: {exc}") from None
    try:
        _check_keys("(top level)", data, ("wing",), ("analysis",))
        return wing_from_dict(data["wing"]), analysis_from_dict(data.get("analysis", {}))
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None


def resolve_wing(spec: str | Path) -> tuple[Wing, AnalysisOptions]:
    """A built-in wing by name (``goland``, ``goland_aileron``) or a wing file by path."""
    from ..structure.examples import BUILTIN_WINGS

    if isinstance(spec, str) and spec in BUILTIN_WINGS:
        return BUILTIN_WINGS[spec](), AnalysisOptions()
    p = Path(spec)
    if p.suffix == ".toml" or p.exists():
        return load_wing(p)
    raise InputError(
        f"wing = {str(spec)!r}: not a built-in wing {sorted(BUILTIN_WINGS)} nor a .toml file"
    )
