"""Rows and vectors of the exported model's outputs and inputs over the (full) structural
unknowns: sensors at any point, control-surface rotations and hinge moments, actuators."""

from __future__ import annotations

import numpy as np

from ..structure.beam_element import point_shapes
from ..system.swept_assembly import kink_transforms
from .signals import Sensor

__all__ = [
    "actuator_rows",
    "field_row",
    "hinge_moment_vector",
    "sensor_row",
    "surface_at",
    "surface_mean_row",
    "surface_unit",
]


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
