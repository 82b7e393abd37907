"""Inputs and outputs of the exported state-space model: names, units and their FE rows.

Inputs (by name; ``<s>`` is a control-surface name):

* ``<s>_hinge_moment`` [N m] - torque between wing and surface about the hinge, positive
  trailing-edge down, applied at the actuators in proportion to their stiffness (spread evenly
  along the surface when it has no actuators). It acts in parallel with the actuator springs.
* ``<s>_command`` [rad] - commanded surface rotation: the actuator springs pull the surface
  towards the (servo-filtered) command, ``k_act (delta_c - delta(x_a))`` at each actuator.
* ``gust`` [m/s] - vertical gust velocity, positive up, uniform along the span.
* ``load_factor`` [-] - vertical load factor n_z: every mass of the wing loaded by ``n_z g``
  downward (its weight in 1 g flight; the inertia of the airplane's vertical acceleration
  otherwise), standard gravity g = 9.80665 m/s^2; strip model only.
* ``<a>_nonlinear_moment`` [N m] - moment at actuator ``<a>`` alone (a nonlinear hinge's).

Outputs (by name, or :class:`Sensor` for any point):

* ``tip_le_accel``, ``tip_te_accel``, ``tip_accel`` [m/s^2]; ``..._vel`` [m/s]; ``..._disp`` [m]
  - vertical motion at the tip leading edge, trailing edge and elastic axis;
* ``tip_twist`` [rad], ``tip_twist_rate`` [rad/s];
* ``<s>_deflection`` [rad], ``<s>_rate`` [rad/s] - span-averaged surface rotation;
  ``<a>_rotation`` [rad], ``<a>_rotation_rate`` [rad/s] - at the station of actuator ``<a>``;
* ``<s>_aero_hinge_moment`` [N m] - aerodynamic moment about the hinge, integrated over the span
  of the surface, positive trailing-edge down;
* ``<s>_actuator_moment`` [N m] - moment the actuators (and the hinge-moment input) exert on
  the surface, positive trailing-edge down;
* ``root_shear`` [N], ``root_bending_moment`` [N m], ``root_torque`` [N m] - internal loads
  carried by the root section (positive for upward loads, tip-up bending, nose-up torque);
* ``shear_at_<x>mm`` [N], ``bending_moment_at_<x>mm`` [N m], ``torque_at_<x>mm`` [N m] - the
  same at the spanwise station ``<x>`` in whole millimetres (e.g. ``bending_moment_at_2500mm``
  at 2.5 m; python-control allows no '.' in a name), which must be a mesh node within 0.5 mm
  (``AeroelasticModel(..., load_stations=[2.5])`` puts one there): the loads the wing carries
  there from everything outboard (``docs/gust-loads.md``);
* ``modal_<k>`` [kg^0.5 m] - k-th in-vacuo modal coordinate (mass-normalized modes).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_number
from ..errors import show_value as describe

__all__ = [
    "Sensor",
    "DEFAULT_OUTPUTS",
    "check_names",
    "check_signal_map",
    "describe",
    "input_names",
    "output_units",
    "InputDef",
    "OutputDef",
]

DEFAULT_OUTPUTS = ("tip_le_accel", "tip_te_accel", "tip_twist")
"""Outputs used when none are given: tip accelerometers at both edges and tip twist."""

QUANTITIES = {
    "displacement": ("disp", "m"),
    "velocity": ("vel", "m/s"),
    "acceleration": ("accel", "m/s^2"),
    "twist": ("twist", "rad"),
    "twist_rate": ("twist_rate", "rad/s"),
}


@dataclass(frozen=True)
class Sensor:
    """A point sensor.

    Parameters
    ----------
    name : str
        Output signal name.
    quantity : str
        ``"displacement"`` [m], ``"velocity"`` [m/s], ``"acceleration"`` [m/s^2] (vertical, up)
        or ``"twist"`` [rad], ``"twist_rate"`` [rad/s].
    x : float
        Spanwise station [m].
    chord : float
        Chordwise position in semichords aft of mid-chord (-1 leading edge, +1 trailing edge);
        points aft of a hinge line on a control surface move with the surface. Ignored for
        twist.
    """

    name: str
    quantity: str
    x: float
    chord: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise InputError(f"sensor.name = {self.name!r}: expected a non-empty string")
        if not isinstance(self.quantity, str) or self.quantity not in QUANTITIES:
            raise InputError(
                f"sensor '{self.name}'.quantity = {self.quantity!r}: expected one of "
                f"{sorted(QUANTITIES)}"
            )
        check_number(f"sensor '{self.name}'.x", self.x, unit="m", lo=0.0)
        check_number(f"sensor '{self.name}'.chord", self.chord, lo=-1.0, hi=1.0)


@dataclass(frozen=True)
class InputDef:
    name: str
    kind: str  # "hinge_moment" | "command" | "gust" | "element" | "load_factor"
    surface: int | None
    unit: str
    actuator: int | None = None


@dataclass(frozen=True)
class OutputDef:
    name: str
    kind: str
    unit: str
    surface: int | None = None
    sensor: Sensor | None = None
    index: int | None = None
    node: int | None = None  # the mesh node of a load station


def input_names(wing) -> dict[str, InputDef]:
    """All inputs a wing offers, by name."""
    out = {}
    for k, cs in enumerate(wing.control_surfaces):
        out[f"{cs.name}_hinge_moment"] = InputDef(
            f"{cs.name}_hinge_moment", "hinge_moment", k, "N m"
        )
        if cs.actuators:
            out[f"{cs.name}_command"] = InputDef(f"{cs.name}_command", "command", k, "rad")
        for j, a in enumerate(cs.actuators):
            name = f"{a.name}_nonlinear_moment"
            out[name] = InputDef(name, "element", k, "N m", actuator=j)
    out["gust"] = InputDef("gust", "gust", None, "m/s")
    out["load_factor"] = InputDef("load_factor", "load_factor", None, "-")
    return out


def check_signal_map(
    field: str, value: object, *, lo: float = 0.0, hi: float | None = None, lo_open: bool = True
) -> dict:
    """A mapping ``{signal name: number}`` (limits, Bryson values, noise levels), each value
    finite and within ``[lo, hi]`` (``lo`` excluded if ``lo_open``) [signal units]."""
    if not isinstance(value, Mapping):
        raise InputError(
            f"{field} = {describe(value)}: expected a mapping of signal name -> number, e.g. "
            "{'tip_disp': 0.05}"
        )
    for name, v in value.items():
        if not isinstance(name, str):
            raise InputError(f"{field}: key {describe(name)} is not a signal name")
        check_number(f"{field}[{name!r}]", v, unit="signal units", lo=lo, hi=hi, lo_open=lo_open)
    return dict(value)


def check_names(field: str, value: object, *, items=(str,), empty: bool = False) -> list:
    """A list of signal names (a list, tuple or 1-D array; not a bare string), as a list.

    ``items`` are the accepted types of the entries; ``empty``: whether ``[]`` is allowed.
    """
    if isinstance(value, str):
        raise InputError(
            f"{field} = {describe(value)}: expected a list of signal names, not a bare string "
            f"(pass [{value!r}])"
        )
    if isinstance(value, np.ndarray) and value.ndim == 1:
        value = value.tolist()
    if not isinstance(value, (list, tuple)):
        raise InputError(f"{field} = {describe(value)}: expected a list of signal names")
    if not value and not empty:
        raise InputError(f"{field} = {value!r}: give at least one signal name")
    for i, v in enumerate(value):
        if not isinstance(v, items) or (isinstance(v, str) and not v):
            what = "a signal name" if items == (str,) else "a signal name or an aeroservo.Sensor"
            raise InputError(f"{field}[{i}] = {describe(v)}: expected {what}")
    return list(value)


def resolve_inputs(wing, names) -> list[InputDef]:
    table = input_names(wing)
    if names is None:
        names = [n for n, d in table.items() if d.kind in ("hinge_moment", "gust")]
    names = check_names("inputs", names)
    out = []
    for n in names:
        if n not in table:
            hint = ""
            if n.endswith("_command") and n[: -len("_command")] in [
                c.name for c in wing.control_surfaces
            ]:
                hint = " (that surface has no actuators)"
            raise InputError(f"input {n!r}: unknown{hint}; this wing offers {sorted(table)}")
        out.append(table[n])
    _no_duplicates([d.name for d in out], "inputs")
    return out


_TIP = re.compile(r"^tip_(le|te)?_?(disp|vel|accel)$")
_MODAL = re.compile(r"^modal_(\d+)$")


def resolve_outputs(model, specs, n_modes_available: int) -> list[OutputDef]:
    """Turn output names / sensors into definitions (validating every one)."""
    wing = model.wing
    if specs is None:
        specs = DEFAULT_OUTPUTS
    if isinstance(specs, Sensor):
        specs = [specs]
    specs = check_names("outputs", specs, items=(str, Sensor))
    surfaces = {cs.name: k for k, cs in enumerate(wing.control_surfaces)}
    actuators = {
        a.name: (k, j)
        for k, cs in enumerate(wing.control_surfaces)
        for j, a in enumerate(cs.actuators)
    }
    out = []
    for spec in specs:
        if isinstance(spec, Sensor):
            if spec.x > wing.span * (1 + 1e-12):
                raise InputError(
                    f"sensor '{spec.name}'.x = {spec.x:g}: outside the wing, allowed range is "
                    f"[0, {wing.span:g}] [m]"
                )
            out.append(OutputDef(spec.name, "sensor", QUANTITIES[spec.quantity][1], sensor=spec))
            continue
        if not isinstance(spec, str):
            raise InputError(f"output {describe(spec)}: expected a name or an aeroservo.Sensor")
        m = _TIP.match(spec)
        if m:
            edge, q = m.groups()
            chord = {"le": -1.0, "te": 1.0, None: None}[edge]
            quantity = {"disp": "displacement", "vel": "velocity", "accel": "acceleration"}[q]
            if chord is None:
                chord = wing.segment_at(wing.span).a  # the elastic axis
            s = Sensor(spec, quantity, wing.span, chord)
            out.append(OutputDef(spec, "sensor", QUANTITIES[quantity][1], sensor=s))
            continue
        if spec in ("tip_twist", "tip_twist_rate"):
            s = Sensor(spec, spec[4:], wing.span)
            out.append(OutputDef(spec, "sensor", QUANTITIES[s.quantity][1], sensor=s))
            continue
        if spec in ("root_shear", "root_bending_moment", "root_torque"):
            unit = "N" if spec == "root_shear" else "N m"
            idx = ("root_shear", "root_bending_moment", "root_torque").index(spec)
            out.append(OutputDef(spec, "root", unit, index=idx))
            continue
        m = _CUT.match(spec)
        if m:
            quantity, station = m.groups()
            node = _station_node(model, spec, station)
            unit = "N" if quantity == "shear" else "N m"
            idx = STATION_QUANTITIES.index(quantity)
            out.append(OutputDef(spec, "cut", unit, index=idx, node=node))
            continue
        m = _MODAL.match(spec)
        if m:
            digits = m.group(1).lstrip("0") or "0"
            k = int(digits) if len(digits) <= 9 else n_modes_available + 1  # no huge int()
            if not 1 <= k <= n_modes_available:
                raise InputError(
                    f"output {describe(spec)}: mode number must be in [1, {n_modes_available}]"
                )
            out.append(OutputDef(spec, "modal", "kg^0.5 m", index=k - 1))
            continue
        name, _, rate = spec.partition("_rotation")
        if name in actuators and rate in ("", "_rate"):
            k, j = actuators[name]
            kind, unit = (
                ("actuator_rotation", "rad") if not rate else ("actuator_rotation_rate", "rad/s")
            )
            out.append(OutputDef(spec, kind, unit, surface=k, index=j))
            continue
        for suffix, kind, unit in (
            ("_deflection", "deflection", "rad"),
            ("_rate", "rate", "rad/s"),
            ("_aero_hinge_moment", "aero_hinge_moment", "N m"),
            ("_actuator_moment", "actuator_moment", "N m"),
        ):
            if spec.endswith(suffix) and spec[: -len(suffix)] in surfaces:
                out.append(OutputDef(spec, kind, unit, surface=surfaces[spec[: -len(suffix)]]))
                break
        else:
            names = ", ".join(
                [
                    "tip_{le,te,}_{disp,vel,accel}",
                    "tip_twist",
                    "tip_twist_rate",
                    "root_shear",
                    "root_bending_moment",
                    "root_torque",
                    "{shear,bending_moment,torque}_at_<station>mm",
                    "modal_<k>",
                ]
                + [f"{s}_{{deflection,rate,aero_hinge_moment,actuator_moment}}" for s in surfaces]
                + [f"{a}_rotation[_rate]" for a in actuators]
            )
            raise InputError(
                f"output {describe(spec)}: unknown sensor; known outputs: {names}, or a Sensor"
            )
    _no_duplicates([d.name for d in out], "outputs")
    return out


_CUT = re.compile(r"^(shear|bending_moment|torque)_at_(.*)mm$")


def station_of(name: str) -> tuple[str, float] | None:
    """``(quantity, station [m])`` of a root or station load name (``root_shear`` is at 0,
    ``torque_at_2500mm`` at 2.5 m), or None for any other output."""
    if name.startswith("root_") and name[5:] in STATION_QUANTITIES:
        return name[5:], 0.0
    m = _CUT.match(name)
    if m is None or not m.group(2).isdigit():
        return None
    return m.group(1), int(m.group(2)) / 1000.0


STATION_QUANTITIES = ("shear", "bending_moment", "torque")
"""The internal loads of a section, in the order of its reaction rows."""


def station_output(quantity: str, station: float) -> str:
    """Name of the load output at a station [m], e.g. ``bending_moment_at_2500mm``."""
    return f"{quantity}_at_{round(station * 1000.0)}mm"


def _station_node(model, spec: str, station: str) -> int:
    """The mesh node at the station of a load output ``<quantity>_at_<x>mm``."""
    span = model.wing.span
    x = int(station) / 1000.0 if station.isdigit() and len(station) <= 9 else -1.0
    if not 0.0 <= x <= span * (1 + 1e-12) + 5e-4:
        raise InputError(
            f"output {describe(spec)}: the station after '_at_' must be whole millimetres in "
            f"[0, {span * 1000:.0f}], e.g. {station_output('bending_moment', 0.5 * span)!r}"
        )
    nodes = model.mesh.nodes
    j = int(np.argmin(np.abs(nodes - x)))
    if abs(nodes[j] - x) > 5e-4 * (1 + 1e-6) + 1e-9 * span:  # the name's rounding to 1 mm
        near = ", ".join(f"{v:.6g}" for v in nodes[max(j - 1, 0) : j + 2])
        raise InputError(
            f"output {describe(spec)}: no mesh node at {x:g} m (nearest nodes {near} m); "
            f"put one there with AeroelasticModel(..., load_stations=[{x:g}]) (a study's "
            "load_stations do)"
        )
    return j


def output_units(defs) -> dict[str, str]:
    return {d.name: d.unit for d in defs}


def _no_duplicates(names: list[str], what: str) -> None:
    seen = set()
    for n in names:
        if n in seen:
            raise InputError(f"{what}: {n!r} appears twice")
        seen.add(n)
