"""Inputs and outputs of the exported state-space model: names, units and their FE rows.

Inputs (by name; ``<s>`` is a control-surface name):

* ``<s>_hinge_moment`` [N m] - torque between wing and surface about the hinge, positive
  trailing-edge down, applied at the actuators in proportion to their stiffness (spread evenly
  along the surface when it has no actuators). It acts in parallel with the actuator springs.
* ``<s>_command`` [rad] - commanded surface rotation: the actuator springs pull the surface
  towards the (servo-filtered) command, ``k_act (delta_c - delta(x_a))`` at each actuator.
* ``gust`` [m/s] - vertical gust velocity, positive up, uniform along the span.
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
* ``modal_<k>`` [kg^0.5 m] - k-th in-vacuo modal coordinate (mass-normalized modes).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_number
from ..errors import show_value as describe
from ..structure.beam_element import point_shapes
from ..system.swept_assembly import kink_transforms

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
    kind: str  # "hinge_moment" | "command" | "gust" | "element"
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


def output_units(defs) -> dict[str, str]:
    return {d.name: d.unit for d in defs}


def _no_duplicates(names: list[str], what: str) -> None:
    seen = set()
    for n in names:
        if n in seen:
            raise InputError(f"{what}: {n!r} appears twice")
        seen.add(n)


# -- rows and vectors over the (full) structural unknowns --------------------------------------


def _scatter_row(model, e: int, local: np.ndarray) -> np.ndarray:
    row = np.zeros(model.n_dofs)
    dofs = model.mesh.element_dofs[e]
    keep = dofs >= 0
    np.add.at(row, dofs[keep], local[keep])
    return row


def _element_on(model, x: float, surface: int | None = None) -> tuple[int, float]:
    """Element containing x (restricted to a surface's elements if given) and local xi."""
    mesh = model.mesh
    if surface is None:
        return mesh.locate(x)
    own = np.flatnonzero(mesh.surface == surface)
    i = np.searchsorted(mesh.nodes[own + 1], x - 1e-12 * model.wing.span)
    e = own[min(i, own.size - 1)]
    xi = (x - mesh.nodes[e]) / (mesh.nodes[e + 1] - mesh.nodes[e])
    return int(e), float(np.clip(xi, 0.0, 1.0))


def field_row(model, field: int, x: float, surface: int | None = None) -> np.ndarray:
    """Row r with ``r @ q`` = field value at x (0 = w, 1 = phi, 2 = delta of ``surface``)."""
    e, xi = _element_on(model, x, surface if field == 2 else None)
    n, _ = point_shapes(model.mesh.lengths[e], xi)
    kinks = kink_transforms(model.wing, model.mesh)  # None unless the elastic axis is cranked
    return _scatter_row(model, e, n[field] if kinks is None else n[field] @ kinks[e])


def surface_at(model, x: float) -> int | None:
    """Index of the control surface covering station x on the mesh, or None."""
    tol = 1e-12 * model.wing.span
    for k, (start, end) in enumerate(model.mesh.surface_extent):
        if start - tol <= x <= end + tol:
            return k
    return None


def sensor_row(model, s: Sensor) -> np.ndarray:
    """Displacement (or twist) row of a sensor; rates and accelerations use the same row."""
    if s.quantity in ("twist", "twist_rate"):
        return field_row(model, 1, s.x)
    seg = model.wing.segment_at(s.x)
    y = seg.semichord * (s.chord - seg.a)  # m aft of the elastic axis
    row = field_row(model, 0, s.x) - y * field_row(model, 1, s.x)
    k = surface_at(model, s.x)
    if k is not None and s.chord > model.wing.control_surfaces[k].hinge:
        y_h = seg.semichord * (model.wing.control_surfaces[k].hinge - seg.a)
        row -= (y - y_h) * field_row(model, 2, s.x, k)
    return row


def surface_unit(model, k: int) -> np.ndarray:
    """Vector with a unit rotation of surface k: ``e @ f`` is the moment about the hinge."""
    e = np.zeros(model.n_dofs)
    d = model.mesh.dof_delta[k]
    e[d[d >= 0]] = 1.0
    return e


def surface_mean_row(model, k: int) -> np.ndarray:
    """Row giving the span-averaged rotation of surface k (trapezoidal rule: exact, linear)."""
    mesh = model.mesh
    d = mesh.dof_delta[k]
    on = d >= 0
    x = mesh.nodes[on]
    w = np.zeros(x.size)
    h = np.diff(x)
    w[:-1] += h / 2
    w[1:] += h / 2
    row = np.zeros(model.n_dofs)
    row[d[on]] = w / (x[-1] - x[0])
    return row


def actuator_rows(model, k: int) -> list[tuple[float, np.ndarray]]:
    """(stiffness, row of delta at the actuator) for each actuator of surface k."""
    cs = model.wing.control_surfaces[k]
    return [(a.stiffness, field_row(model, 2, a.station, k)) for a in cs.actuators]


def hinge_moment_vector(model, k: int) -> np.ndarray:
    """Generalized force of a unit hinge moment of surface k [per N m].

    At the actuators in proportion to their stiffness; without actuators, spread evenly along
    the surface (a uniform distributed hinge moment of 1/L_s N m per m).
    """
    acts = actuator_rows(model, k)
    if acts:
        k_tot = sum(a for a, _ in acts)
        return sum((a / k_tot) * r for a, r in acts)
    return surface_mean_row(model, k)
