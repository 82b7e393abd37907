"""Derivatives of the concentrated masses' mass matrix (:mod:`aeroservo.system.point_masses`).

A mass adds ``n(x_m)^T M_p n(x_m)`` to the mass matrix, with ``M_p`` its 3x3 point matrix on
``[w, phi, delta]`` and ``n`` the field shape functions of the element holding it at its station
``x_m``. ``M_p`` is a polynomial in the mass ``m``, the chordwise offset, the pitch inertia ``I``
and the vertical offset ``z``; for a mass on a control surface its distance from the elastic
axis is ``y_h + offset`` with the hinge's ``y_h = b (c - a)``, so it also depends on the
semichord ``b`` and elastic axis ``a`` of the segment holding it and on the surface's hinge
line ``c``. Those derivatives are taken by a complex step of the point matrix (exact to
rounding); the station derivative is

    d/dx_m (n^T M_p n) = n'^T M_p n + n^T M_p n'

with ``n' = [w', phi', delta']`` of the element's shape functions (Hermite slope, linear
gradients). ``M_p`` does not change with the station inside a segment.

One-sided rule: the twist and flap rotations are linear in each element, so ``n'`` jumps at a
mesh node. A station on an interior mesh node has two one-sided derivatives (the elements
inboard, ``side = -1``, and outboard, ``side = 1``), reported as such and never averaged; a
station on its bound (the tip, or an end of the control surface it sits on) has the inward
one only. A mass on a control surface exactly on a segment boundary where ``b (c - a)`` changes
has a mass matrix that jumps with the station there: no derivative.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..structure.beam_element import field_shapes
from ..structure.mesh import Mesh
from ..structure.wing import Wing
from .assembly import scatter_blocks
from .point_masses import locate_mass
from .swept_assembly import gradient_shapes, kink_transforms, to_nodal

__all__ = ["MASS_KEYS", "point_mass_derivative", "mass_coupling_derivative", "mass_station_kink"]

MASS_KEYS = ("mass", "station", "offset", "inertia", "vertical_offset")
"""Differentiable keys of a concentrated mass (wing-file keys of ``[[wing.masses]]``)."""

STEP = 1e-20
"""Complex step (the point matrix is a polynomial: exact to rounding for any small step)."""

_COUPLED = {("segment", "a"): "a", ("segment", "semichord"): "b", ("surface", "hinge"): "c"}
"""Wing parameters that move a mass on a control surface (through ``y_h = b (c - a)``)."""


def _section(m, offset, inertia, z, y_h, on_surface: bool) -> np.ndarray:
    """The point matrix of :func:`~aeroservo.system.point_masses.point_mass_section` from
    its numbers (complex ones give complex-step derivatives)."""
    rot = inertia + m * z * z
    y_f = offset if on_surface else 0.0
    y_e = y_h + offset if on_surface else offset
    out = np.zeros((3, 3), dtype=np.result_type(m, offset, inertia, z, y_h, float))
    out[0, 0] = m
    out[0, 1] = out[1, 0] = -m * y_e
    out[1, 1] = rot + m * y_e * y_e
    if on_surface:
        out[0, 2] = out[2, 0] = -m * y_f
        out[1, 2] = out[2, 1] = rot + m * y_e * y_f
        out[2, 2] = rot + m * y_f * y_f
    return out


def _arguments(wing: Wing, i: int) -> dict:
    """The numbers of mass ``i``'s point matrix (and ``b``, ``c``, ``a`` of its hinge)."""
    pm = wing.masses[i]
    args = {"m": pm.mass, "offset": pm.offset, "inertia": pm.inertia, "z": pm.vertical_offset}
    args.update(a=0.0, b=0.0, c=0.0)
    if pm.surface is not None:
        seg = wing.segment_at(pm.station)
        args.update(a=seg.a, b=seg.semichord, c=wing.surface(pm.surface).hinge)
    return args


def _d_section(wing: Wing, i: int, arg: str) -> np.ndarray:
    """d M_p / d(argument ``arg``) of mass ``i``, by a complex step."""
    x = _arguments(wing, i)
    x[arg] = x[arg] + 1j * STEP
    y_h = x["b"] * (x["c"] - x["a"])
    on = wing.masses[i].surface is not None
    return np.imag(_section(x["m"], x["offset"], x["inertia"], x["z"], y_h, on)) / STEP


def _scatter(wing: Wing, mesh: Mesh, e: int, block: np.ndarray) -> sp.csr_matrix:
    """One element block (8, 8) into the free unknowns (through a crank's transform)."""
    blocks = np.zeros((mesh.n_elements, 8, 8))
    blocks[e] = block
    blocks = to_nodal(blocks, kink_transforms(wing, mesh), True, True)
    n_q = mesh.n_dofs
    return scatter_blocks(blocks, mesh.element_dofs, mesh.element_dofs, (n_q, n_q))


def _shapes(length: float, xi: float) -> tuple[np.ndarray, np.ndarray]:
    """``n`` (3, 8) and ``n' = dn/dx`` (3, 8) at one point of an element."""
    N, D, S = field_shapes(np.array([length]), np.array([xi]))
    return N[0, 0], gradient_shapes(N, D, S)[0, 0]


def _element(wing: Wing, mesh: Mesh, i: int, side: int) -> tuple[int, float]:
    """Element and local xi of mass ``i``; on a node, the element on ``side`` (1: outboard,
    -1: inboard) among the elements it may sit in (its surface's, if on one)."""
    pm = wing.masses[i]
    x, tol = pm.station, 1e-12 * wing.span
    if pm.surface is None:
        own = np.arange(mesh.n_elements)
    else:
        k = [cs.name for cs in wing.control_surfaces].index(pm.surface)
        own = np.flatnonzero(mesh.surface == k)
    lo, hi = mesh.nodes[own], mesh.nodes[own + 1]
    inside = (lo - tol <= x) & (x <= hi + tol)
    if inside.sum() > 1:
        inside &= (lo > x - tol) if side > 0 else (hi < x + tol)
    if not inside.any():  # an end of the range, from outside: the only element there
        inside = (lo - tol <= x) & (x <= hi + tol)
    e = int(own[np.flatnonzero(inside)[0]])
    xi = float(np.clip((x - mesh.nodes[e]) / (mesh.nodes[e + 1] - mesh.nodes[e]), 0.0, 1.0))
    return e, xi


def point_mass_derivative(
    wing: Wing, mesh: Mesh, i: int, key: str, *, side: int = 1
) -> sp.csr_matrix:
    """d Ms / d(``masses[i].key``) on the free unknowns.

    Parameters
    ----------
    wing : Wing
    mesh : Mesh
    i : int
        Index of the mass in ``wing.masses``.
    key : {"mass", "station", "offset", "inertia", "vertical_offset"}
        Units: kg, m, m, kg m^2, m.
    side : {1, -1}
        For a station on a mesh node: the element outboard (1) or inboard (-1).

    Returns
    -------
    scipy.sparse.csr_matrix
        [kg, kg m, kg m^2 per unit of the parameter].
    """
    if key not in MASS_KEYS:
        raise ValueError(f"mass parameter {key!r}: not a differentiable parameter")
    if key == "station":
        e, xi = _element(wing, mesh, i, side)
        n, dn = _shapes(mesh.lengths[e], xi)
        mp = _section_of(wing, i)
        return _scatter(wing, mesh, e, dn.T @ mp @ n + n.T @ mp @ dn)
    e, xi = locate_mass(wing, mesh, wing.masses[i])
    n, _ = _shapes(mesh.lengths[e], xi)
    arg = {"mass": "m", "vertical_offset": "z"}.get(key, key)
    return _scatter(wing, mesh, e, n.T @ _d_section(wing, i, arg) @ n)


def _section_of(wing: Wing, i: int) -> np.ndarray:
    x = _arguments(wing, i)
    on = wing.masses[i].surface is not None
    return _section(x["m"], x["offset"], x["inertia"], x["z"], x["b"] * (x["c"] - x["a"]), on)


def mass_coupling_derivative(
    wing: Wing, mesh: Mesh, owner: str, index: int, key: str
) -> sp.csr_matrix | None:
    """d Ms / d(a segment's ``a`` or ``semichord``, a surface's ``hinge``) of the masses on
    control surfaces held by that segment or surface (``y_h = b (c - a)``); None if none."""
    arg = _COUPLED.get((owner, key))
    if arg is None:
        return None
    out = None
    for i, pm in enumerate(wing.masses):
        if pm.surface is None:
            continue
        if owner == "segment":
            if wing.segment_at(pm.station) is not wing.segments[index]:
                continue
        elif wing.control_surfaces[index].name != pm.surface:
            continue
        e, xi = locate_mass(wing, mesh, pm)
        n, _ = _shapes(mesh.lengths[e], xi)
        d = _scatter(wing, mesh, e, n.T @ _d_section(wing, i, arg) @ n)
        out = d if out is None else out + d
    return out


def mass_station_kink(wing: Wing, mesh: Mesh, i: int) -> tuple[str | None, int, str]:
    """Where mass ``i``'s station has no two-sided derivative: ``("edge", inward side, why)``
    on its bound (the tip, an end of its surface), ``("node", 0, why)`` on an interior mesh node,
    ``("jump", 0, why)`` where its mass matrix jumps, or ``(None, 1, "")``."""
    pm = wing.masses[i]
    x, tol = pm.station, 1e-12 * wing.span
    if pm.surface is not None:
        cs = wing.surface(pm.surface)
        for end, inward in ((cs.start, 1), (cs.end, -1)):
            if abs(x - end) <= tol:
                why = "at an end of its control surface (a bound of the station): one-sided"
                return "edge", inward, why
    if abs(x - wing.span) <= tol:
        return "edge", -1, "at the tip (a bound of the station): one-sided"
    if not np.any(np.abs(mesh.nodes - x) <= tol):
        return None, 1, ""
    if pm.surface is not None:
        e_in, e_out = (_element(wing, mesh, i, s)[0] for s in (-1, 1))
        c = wing.surface(pm.surface).hinge
        y_in, y_out = (
            wing.segments[mesh.segment[e]].semichord * (c - wing.segments[mesh.segment[e]].a)
            for e in (e_in, e_out)
        )
        if y_in != y_out:
            why = "on a segment boundary where the hinge's distance b (c - a) changes: the mass "
            return "jump", 0, why + "matrix jumps with the station, no derivative"
    return "node", 0, "on a mesh node: the discretized model has a kink there"
