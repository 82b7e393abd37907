"""Wing description files (TOML, schema in ``docs/wing-file.md``).

A file has a ``[wing]`` table (``span``, ``[[wing.segments]]``, optional
``[[wing.control_surfaces]]`` with ``[[wing.control_surfaces.actuators]]``), an optional
``[analysis]`` table with defaults for ``density`` or ``altitude`` / ``altitude_ft``,
``compressibility``, ``elements``, ``wagner``, ``v_max``, ``n_modes``, ``aero`` and ``mach``, an
optional ``[dlm]`` table (doublet-lattice settings, :mod:`aeroservo.files.aero_tables`) and an
optional ``[damping]`` table (``ratio``, ``alpha`` and ``beta``, or ``g``). Every error names
the file, the key and the value.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path

from ..aero.atmosphere import isa, isa_ft
from ..aero.indicial import wagner_set
from ..errors import (
    MAX_ELEMENTS,
    InputError,
    check_int,
    check_number,
    check_quantity,
    show_value,
)
from ..stability.matched import COMPRESSIBILITY
from ..structure.wing import Actuator, ControlSurface, Segment, Wing, check_sweep
from ..system.damping import NO_DAMPING, StructuralDamping
from .mass_tables import masses_from_list, masses_toml
from .toml_tables import read_toml

__all__ = [
    "AnalysisOptions",
    "load_wing",
    "wing_from_dict",
    "wing_toml",
    "resolve_wing",
    "damping_from_dict",
    "load_hinges",
]

SEGMENT_KEYS = ("start", "end", "semichord", "a", "mass", "x_alpha", "inertia", "EI", "GJ")
SEGMENT_OPTIONAL = ("sweep", "sweep_deg")
SURFACE_REQUIRED = ("name", "start", "end", "hinge", "static_moment", "inertia")
SURFACE_OPTIONAL = ("GJ", "hinge_stiffness", "actuators")
ACTUATOR_KEYS = ("station", "stiffness")
ANALYSIS_KEYS = (
    "density",
    "altitude",
    "altitude_ft",
    "compressibility",
    "elements",
    "wagner",
    "v_max",
    "n_modes",
    "aero",
    "mach",
)
DAMPING_KEYS = ("ratio", "alpha", "beta", "g", "dof_ratio", "plunge_mass")


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
        Fewest modes of the modal model (default: automatic).
    altitude : float or None
        Geopotential altitude [m] (standard atmosphere; replaces ``density``).
    compressibility : str or None
        ``"prandtl-glauert"`` or ``"matched"`` (Mach matched to the speed at the altitude: the
        Prandtl-Glauert correction of strip theory, the doublet lattice's own Mach number) or
        None.
    damping : StructuralDamping
        Structural damping (default none).
    aero : DoubletLattice or None
        The doublet-lattice settings of ``aero = "dlm"`` (``[dlm]``); None: strip theory.
    mach : float or None
        A fixed Mach number [-] of the aerodynamics (None: not given; then 0, or matched with
        ``compressibility``).
    """

    density: float = 1.225
    elements: int = 10
    wagner: object = "rt_jones"
    v_max: float | None = None
    n_modes: int | None = None
    altitude: float | None = None
    compressibility: str | None = None
    damping: StructuralDamping = NO_DAMPING
    aero: object = None
    mach: float | None = None


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
    tbl = _check_keys(where, data, ("span", "segments"), ("name", "control_surfaces", "masses"))
    name = tbl.get("name", "wing")
    if not isinstance(name, str):
        raise InputError(f"{where}.name = {name!r}: expected a string")
    segments = []
    for i, seg in enumerate(_list_of_tables(f"{where}.segments", tbl["segments"])):
        w = f"{where}.segments[{i}]"
        _check_keys(w, seg, SEGMENT_KEYS, SEGMENT_OPTIONAL)
        vals = {k: check_number(f"{w}.{k}", seg[k]) for k in SEGMENT_KEYS}
        vals["sweep"] = segment_sweep(w, seg)
        segments.append(Segment(**vals, name=w))
    surfaces, taken = [], set()
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
            _check_keys(wa, act, ACTUATOR_KEYS, ("name",))
            a = Actuator(
                station=check_number(f"{wa}.station", act["station"], unit="m"),
                stiffness=check_number(f"{wa}.stiffness", act["stiffness"], unit="N m/rad"),
                name=wa,  # its key path in the messages of the checks
            )
            acts.append(replace(a, name=_actuator_name(wa, act, taken)))
        nums = {
            k: check_number(f"{w}.{k}", cs[k])
            for k in ("start", "end", "hinge", "static_moment", "inertia", "GJ", "hinge_stiffness")
            if k in cs
        }
        surfaces.append(ControlSurface(name=cs["name"], actuators=tuple(acts), **nums))
    span = check_number(f"{where}.span", tbl["span"], unit="m")
    masses = masses_from_list(f"{where}.masses", tbl.get("masses", []))
    return Wing(
        span=span,
        segments=tuple(segments),
        control_surfaces=tuple(surfaces),
        name=name,
        masses=masses,
    )


def _actuator_name(where: str, act: Mapping, taken: set) -> str:
    """An actuator's ``name`` (letters, digits and underscores: it names signals such as
    ``<actuator>_rotation``), default ``actuator<k>`` numbered along the wing from 1."""
    name = act.get("name", f"actuator{len(taken) + 1}")
    if not isinstance(name, str) or not _SIGNAL_NAME.fullmatch(name):
        raise InputError(
            f"{where}.name = {show_value(name)}: expected a name of letters, digits and "
            "underscores (it names signals such as <actuator>_rotation)"
        )
    if name in taken:
        raise InputError(f"{where}.name = {name!r}: another actuator of the wing has this name")
    taken.add(name)
    return name


_SIGNAL_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}")


def segment_sweep(where: str, seg: Mapping) -> float:
    """The sweep angle [rad] of a segment table: ``sweep`` [rad] or ``sweep_deg`` [deg], 0 if
    neither is given (one clear line when both are, or when it is beyond +-60 deg)."""
    if "sweep" in seg and "sweep_deg" in seg:
        raise InputError(f"{where}.sweep_deg = {seg['sweep_deg']!r}: give sweep [rad] or sweep_deg")
    if "sweep_deg" in seg:
        return check_sweep(f"{where}.sweep_deg", seg["sweep_deg"], degrees=True)
    return check_sweep(f"{where}.sweep", seg.get("sweep", 0.0))


def analysis_from_dict(
    data: Mapping, where: str = "analysis", dlm: object = None
) -> AnalysisOptions:
    """Build :class:`AnalysisOptions` from the ``[analysis]`` table (and the ``[dlm]`` table
    of a wing file, ``dlm``)."""
    tbl = _check_keys(where, data, (), ANALYSIS_KEYS)
    opts = {}
    given = [k for k in ("density", "altitude", "altitude_ft") if k in tbl]
    if len(given) > 1:
        raise InputError(
            f"{where}.{given[1]} = {tbl[given[1]]!r}: give one of density, altitude, altitude_ft"
        )
    if "density" in tbl:
        opts["density"] = check_quantity(f"{where}.density", tbl["density"], "density")
    if "altitude" in tbl or "altitude_ft" in tbl:
        key = given[0]
        try:
            atm = isa(tbl[key]) if key == "altitude" else isa_ft(tbl[key])
        except InputError as exc:
            raise InputError(f"{where}.{exc}") from None
        opts["altitude"], opts["density"] = atm.altitude, atm.density
    if "compressibility" in tbl:
        comp = tbl["compressibility"]
        if comp not in COMPRESSIBILITY:
            raise InputError(
                f"{where}.compressibility = {comp!r}: allowed values are {list(COMPRESSIBILITY)}"
            )
        if comp != "none" and "altitude" not in opts:
            raise InputError(
                f"{where}.compressibility = {comp!r}: needs altitude or altitude_ft (the speed "
                "of sound)"
            )
        opts["compressibility"] = None if comp == "none" else comp
    if "elements" in tbl:
        opts["elements"] = check_int(f"{where}.elements", tbl["elements"], lo=1, hi=MAX_ELEMENTS)
    if "wagner" in tbl:
        try:
            wagner_set(tbl["wagner"])
        except InputError as exc:
            msg = str(exc)
            raise InputError(f"{where}.{msg}" if msg.startswith("wagner") else msg) from None
        opts["wagner"] = tbl["wagner"]
    if "v_max" in tbl:
        opts["v_max"] = check_quantity(f"{where}.v_max", tbl["v_max"], "flight_speed")
    if "n_modes" in tbl:
        opts["n_modes"] = check_int(f"{where}.n_modes", tbl["n_modes"], lo=1)
    if "aero" in tbl or "mach" in tbl or dlm is not None:
        from .aero_tables import aero_options

        opts["aero"], opts["mach"] = aero_options(
            tbl, where, dlm, "dlm", opts.get("compressibility")
        )
    return AnalysisOptions(**opts)


def damping_from_dict(data: Mapping, where: str = "damping") -> StructuralDamping:
    """Structural damping from a ``[damping]`` table: ``ratio`` (a number or a list, one per
    in-vacuo mode), ``alpha`` and ``beta`` (Rayleigh), ``g`` (structural damping), or
    ``dof_ratio`` (per-DOF viscous ratios, with ``plunge_mass`` on a typical section)."""
    tbl = _check_keys(where, data, (), DAMPING_KEYS)
    forms = [k for k in ("ratio", "g", "dof_ratio") if k in tbl] + (
        ["alpha/beta"] if "alpha" in tbl or "beta" in tbl else []
    )
    if len(forms) > 1:
        raise InputError(
            f"{where}: give one of ratio, g, dof_ratio, or alpha and beta (given {forms})"
        )
    if "plunge_mass" in tbl and "dof_ratio" not in tbl:
        raise InputError(
            f"{where}.plunge_mass = {tbl['plunge_mass']!r}: only with dof_ratio (per-DOF damping)"
        )
    try:
        if "dof_ratio" in tbl:
            return StructuralDamping.per_dof(tbl["dof_ratio"], tbl.get("plunge_mass"))
        if "ratio" in tbl:
            return StructuralDamping.modal(tbl["ratio"])
        if "g" in tbl:
            return StructuralDamping.structural(tbl["g"])
        if forms:
            return StructuralDamping.rayleigh(tbl.get("alpha", 0.0), tbl.get("beta", 0.0))
    except InputError as exc:
        raise InputError(str(exc).replace("damping.", f"{where}.", 1)) from None
    return NO_DAMPING


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
    data = read_toml(path, "wing file (TOML)")
    path = Path(path)
    try:
        _check_keys("(top level)", data, ("wing",), ("analysis", "damping", "hinges", "dlm"))
        opts = analysis_from_dict(data.get("analysis", {}), dlm=data.get("dlm"))
        if "damping" in data:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                opts = replace(opts, damping=damping_from_dict(data["damping"]))
            for w in caught:  # the file's name in front of the key
                warnings.warn(f"{path}: {w.message}", w.category, stacklevel=2)
        wing = wing_from_dict(data["wing"])
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    if "hinges" in data:  # checked here too: a wrong table is found whatever reads the file
        _hinges(data["hinges"], wing, str(path))
    return wing, opts


def _hinges(items: object, wing: Wing, file: str) -> tuple:
    from .hinge_tables import check_targets, hinges_from_list

    hinges = hinges_from_list(items, file)
    check_targets(hinges, wing, file)
    return hinges


def load_hinges(path: str | Path) -> tuple:
    """The nonlinear hinges of a wing file's top-level ``[[hinges]]`` tables (keys in
    ``docs/wing-file.md``; :mod:`aeroservo.files.hinge_tables`), checked against its wing.

    The linear analyses of the wing (flutter, simulations) keep every spring closed and do not
    read them; limit-cycle studies (``kind = "lco"`` scenarios) do.

    Parameters
    ----------
    path : str or Path
        The wing file (TOML).

    Returns
    -------
    tuple of NonlinearHinge
        Empty when the file has no ``[[hinges]]``.
    """
    wing, _opts = load_wing(path)
    data = read_toml(path, "wing file (TOML)")
    return _hinges(data["hinges"], wing, str(Path(path))) if "hinges" in data else ()


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


def wing_toml(wing: Wing) -> str:
    """The ``[wing]`` table of a wing file describing ``wing`` (read back by :func:`load_wing`;
    numbers written with ``repr``, so the round trip is exact; actuator names when they are
    unique signal names other than the default ``actuator<k>``)."""
    import json

    def num(x: float) -> str:
        return repr(float(x))

    lines = ["[wing]", f"name = {json.dumps(wing.name)}", f"span = {num(wing.span)}"]
    for seg in wing.segments:
        lines += ["", "[[wing.segments]]"]
        lines += [f"{k} = {num(getattr(seg, k))}" for k in SEGMENT_KEYS]
        if seg.sweep != 0.0:
            lines.append(f"sweep = {num(seg.sweep)}")
    names = [a.name for cs in wing.control_surfaces for a in cs.actuators]
    named = len(set(names)) == len(names) and all(_SIGNAL_NAME.fullmatch(n) for n in names)
    for cs in wing.control_surfaces:
        lines += ["", "[[wing.control_surfaces]]", f"name = {json.dumps(cs.name)}"]
        keys = SURFACE_REQUIRED[1:] + ("GJ", "hinge_stiffness")
        lines += [f"{k} = {num(getattr(cs, k))}" for k in keys]
        for act in cs.actuators:
            lines += ["", "[[wing.control_surfaces.actuators]]"]
            lines += [f"{k} = {num(getattr(act, k))}" for k in ACTUATOR_KEYS]
            if named and act.name != f"actuator{names.index(act.name) + 1}":
                lines.append(f"name = {json.dumps(act.name)}")  # not the default: kept
    lines += masses_toml(wing.masses)
    return "\n".join(lines) + "\n"
