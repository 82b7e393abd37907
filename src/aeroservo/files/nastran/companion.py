"""What a beam deck does not say: the companion table and the options of a Nastran import.

A beam deck has no aerodynamic chord, no elastic-axis position within the chord and no control
surfaces; these come from the command line (``--chord``, ``--semichord``, ``--elastic-axis``)
or a small TOML table (``docs/nastran.md``)::

    name = "my wing"
    semichord = 0.9144          # or chord [m]
    a = -0.34                   # elastic axis, semichords aft of mid-chord
    x_alpha = 0.2               # optional: (CG - EA)/b where the deck gives no CG offset
    inertia = 8.64              # optional: pitch inertia per length [kg m]
    free_stream = [1, 0, 0]     # optional: the flow direction in the deck's basic frame
    up = [0, 0, 1]              # optional: the wing's vertical in the basic frame

    [[sections]]                # optional: other values over a span interval [m]
    start = 0.0
    end = 2.0
    semichord = 1.1

    [[control_surfaces]]        # as [[wing.control_surfaces]] of a wing file
    name = "aileron"
    ...

Precedence: a ``[[sections]]`` value over its interval, then the command-line option, then the
table's top-level value, then what the deck gives.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import InputError, check_number, check_quantity
from ..toml_tables import read_toml
from .deck import vector_text

__all__ = ["ImportOptions", "SpanValues", "import_options", "check_sections", "VALUE_KEYS"]

VALUE_KEYS = ("semichord", "a", "x_alpha", "inertia", "mass")
"""Section values a companion table (or an option) may give [SI]."""

TOP_KEYS = (*VALUE_KEYS, "chord", "name", "free_stream", "up", "sections", "control_surfaces")
SECTION_KEYS = ("start", "end", "chord", *VALUE_KEYS)


@dataclass(frozen=True)
class SpanValues:
    """Values over ``[start, end]`` [m] along the elastic axis, with where they came from."""

    start: float
    end: float
    values: dict[str, float]
    source: str


@dataclass(frozen=True)
class ImportOptions:
    """Resolved options of a Nastran import.

    Attributes
    ----------
    defaults : dict
        key -> (value, source) for the whole span.
    sections : tuple of SpanValues
        Values over span intervals (they win over ``defaults``).
    free_stream, up : ndarray (3,)
        Flow direction and the wing's vertical in the deck's basic frame (unit vectors).
    control_surfaces : list of dict
        ``[[control_surfaces]]`` tables, as in a wing file.
    """

    name: str | None = None
    defaults: dict[str, tuple[float, str]] = field(default_factory=dict)
    sections: tuple[SpanValues, ...] = ()
    free_stream: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))
    up: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    control_surfaces: list = field(default_factory=list)
    companion: str | None = None

    def value(self, key: str, x: float) -> tuple[float, str] | None:
        """The value of ``key`` at station ``x`` [m] and its source, or None."""
        for sec in self.sections:
            if sec.start <= x <= sec.end and key in sec.values:
                return sec.values[key], sec.source
        return self.defaults.get(key)


def _values(where: str, tbl: Mapping) -> dict[str, float]:
    out = {}
    if "chord" in tbl and "semichord" in tbl:
        raise InputError(f"{where}.chord: give chord or semichord, not both")
    if "chord" in tbl:
        out["semichord"] = check_quantity(f"{where}.chord", tbl["chord"], "semichord") / 2.0
    if "semichord" in tbl:
        out["semichord"] = check_quantity(f"{where}.semichord", tbl["semichord"], "semichord")
    if "a" in tbl:
        out["a"] = check_number(f"{where}.a", tbl["a"], lo=-1.0, hi=1.0)
    if "x_alpha" in tbl:
        out["x_alpha"] = check_number(f"{where}.x_alpha", tbl["x_alpha"], lo=-2.0, hi=2.0)
    if "inertia" in tbl:
        out["inertia"] = check_quantity(f"{where}.inertia", tbl["inertia"], "inertia_per_length")
    if "mass" in tbl:
        out["mass"] = check_quantity(f"{where}.mass", tbl["mass"], "mass_per_length")
    return out


def _unit_vector(where: str, value: object) -> np.ndarray:
    if not isinstance(value, list) or len(value) != 3:
        raise InputError(f"{where} = {value!r}: expected a vector of 3 numbers [basic frame]")
    v = np.array([check_number(f"{where}[{i}]", x) for i, x in enumerate(value)])
    n = float(np.linalg.norm(v))
    if n == 0.0:
        raise InputError(f"{where} = {value!r}: a zero vector has no direction")
    return v / n


def _check_keys(where: str, tbl: object, allowed: tuple) -> Mapping:
    if not isinstance(tbl, Mapping):
        raise InputError(f"{where} = {tbl!r}: expected a table")
    unknown = sorted(set(tbl) - set(allowed))
    if unknown:
        raise InputError(f"{where}.{unknown[0]}: unknown key; allowed keys are {sorted(allowed)}")
    return tbl


def import_options(
    companion: str | Path | None = None,
    *,
    chord: float | None = None,
    semichord: float | None = None,
    elastic_axis: float | None = None,
    x_alpha: float | None = None,
    inertia: float | None = None,
    name: str | None = None,
) -> ImportOptions:
    """Resolve the companion table and the options (precedence in the module docstring).

    Raises
    ------
    InputError
        One line naming the file (or option), the key and the value.
    """
    defaults: dict[str, tuple[float, str]] = {}
    sections: list[SpanValues] = []
    kw: dict = {}
    if companion is not None:
        path = Path(companion)
        data = read_toml(path, "companion table (TOML)")
        try:
            _check_keys("(top level)", data, TOP_KEYS)
            for k, v in _values("(top level)", data).items():
                defaults[k] = (v, f"{path.name}: {k}")
            for key in ("free_stream", "up"):
                if key in data:
                    kw[key] = _unit_vector(key, data[key])
            if "name" in data:
                if not isinstance(data["name"], str):
                    raise InputError(f"name = {data['name']!r}: expected a string")
                kw["name"] = data["name"]
            tables = data.get("sections", [])
            if not isinstance(tables, list):
                raise InputError(f"sections = {tables!r}: expected [[sections]] tables")
            for i, tbl in enumerate(tables):
                w = f"sections[{i}]"
                _check_keys(w, tbl, SECTION_KEYS)
                for key in ("start", "end"):
                    if key not in tbl:
                        raise InputError(f"{w}.{key}: missing required key [m]")
                start = check_number(f"{w}.start", tbl["start"], unit="m", lo=0.0)
                end = check_number(f"{w}.end", tbl["end"], unit="m", lo=start, lo_open=True)
                src = f"{path.name}: sections[{i}] ({start:g} to {end:g} m)"
                sections.append(SpanValues(start, end, _values(w, tbl), src))
            surfaces = data.get("control_surfaces", [])
            if not isinstance(surfaces, list):
                raise InputError(
                    f"control_surfaces = {surfaces!r}: expected [[control_surfaces]] tables"
                )
            kw["control_surfaces"] = surfaces
        except InputError as exc:
            raise InputError(f"{path}: {exc}") from None
        kw["companion"] = str(path)
    if chord is not None and semichord is not None:
        raise InputError("--chord and --semichord: give one of them")
    if chord is not None:
        defaults["semichord"] = (check_quantity("--chord", chord, "semichord") / 2.0, "--chord")
    if semichord is not None:
        value = check_quantity("--semichord", semichord, "semichord")
        defaults["semichord"] = (value, "--semichord")
    if elastic_axis is not None:
        defaults["a"] = (
            check_number("--elastic-axis", elastic_axis, lo=-1.0, hi=1.0),
            "--elastic-axis",
        )
    if x_alpha is not None:
        defaults["x_alpha"] = (check_number("x_alpha", x_alpha, lo=-2.0, hi=2.0), "x_alpha")
    if inertia is not None:
        defaults["inertia"] = (check_quantity("inertia", inertia, "inertia_per_length"), "inertia")
    if name is not None:
        if not isinstance(name, str):
            raise InputError(f"name = {name!r}: expected a string")
        kw["name"] = name
    opts = ImportOptions(defaults=defaults, sections=tuple(sections), **kw)
    if abs(float(opts.free_stream @ opts.up)) > 1.0 - 1e-6:
        raise InputError(
            f"free_stream = {vector_text(opts.free_stream)} is along up = "
            f"{vector_text(opts.up)}: the flow must lie in the wing's plane"
        )
    return opts


def check_sections(opts: ImportOptions, midpoints: list[float], span: float, units) -> None:
    """Refuse a ``[[sections]]`` interval that ends beyond the tip (by more than 1 %) or holds
    no element's midpoint: its values would apply nowhere, silently (a table written for
    another wing, or in the deck's units rather than in metres).

    Parameters
    ----------
    opts : ImportOptions
        The resolved options (their companion table named in the message).
    midpoints : list of float
        The elements' midpoints along the beam line [m].
    span : float
        The beam line's length [m].
    units : UnitSystem
        The deck's units (named in the message).
    """
    read = "SI" if units.name == "si" else f"{units.name} converted to SI"
    for i, sec in enumerate(opts.sections):
        where = f"{opts.companion}: sections[{i}]"
        if sec.end > 1.01 * span:
            raise InputError(
                f"{where}.end = {sec.end:g} m: beyond the tip, the beam line is {span:.6g} m "
                f"long (the deck read as {read}; the table is in metres)"
            )
        if not any(sec.start <= x <= sec.end for x in midpoints):
            raise InputError(
                f"{where} ({sec.start:g} to {sec.end:g} m) holds no element's midpoint: its "
                "values would apply to no element (each element takes the values at its "
                "midpoint); widen it"
            )
