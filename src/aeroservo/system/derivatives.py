"""Derivatives of the speed-independent matrices with respect to one wing parameter.

The derivative of every matrix of :class:`~aeroservo.system.matrices.AeroMatrices` comes from
the element integrals of the derivative of the section coefficients
(:func:`aeroservo.system.assembly.section_coefficients`): the mass, stiffness and Theodorsen
coefficients of each element are differentiated by a complex step in the element's property
(exact to rounding: no difference is taken, so there is no step-size error), then integrated
with the same shape functions and Gauss rule as the assembly. The structural matrices are linear
in mass, x_alpha, inertia, EI, GJ and the flap's properties; the elastic axis ``a``, the
semichord and the hinge line enter the aerodynamic coefficients (Theodorsen's T functions) and
the couplings ``S_alpha = m x_alpha b``, ``b (c - a) S_beta`` nonlinearly.

An actuator is a point spring ``k delta(x_a)^2``: its stiffness derivative is the spring of unit
stiffness, its station derivative ``k (n' n^T + n n'^T)`` with the flap's linear shape functions
``n`` of the element holding it. On a mesh node the discretized model has a kink in the station
(the two elements give different one-sided derivatives): :func:`station_on_node` tells, and
``side`` picks the element.

A concentrated mass's parameters move its point mass matrix only
(:mod:`aeroservo.system.mass_derivatives`, with the same one-sided rule for its station); a
mass on a control surface also moves with the segment's ``a`` and ``semichord`` and the
surface's ``hinge`` (its distance from the elastic axis is ``b (c - a) + offset``), a term
added to those parameters' ``Ms`` derivative.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import scipy.sparse as sp

from ..structure.beam_element import field_shapes, gauss_rule, integrate, lag_shapes
from ..structure.mesh import Mesh
from ..structure.wing import Wing
from .assembly import (
    actuator_stiffness,
    element_properties,
    scatter_blocks,
    section_coefficients,
)
from .mass_derivatives import (
    MASS_KEYS,
    mass_coupling_derivative,
    mass_station_kink,
    point_mass_derivative,
)
from .matrices import AeroMatrices, StripGroup
from .swept_assembly import gradient_shapes, kink_transforms, strip_coefficients, to_nodal

__all__ = [
    "PARAMETERS",
    "matrix_derivative",
    "station_on_node",
    "station_kink",
    "zero_derivative",
]

PARAMETERS = {
    "segment": ("mass", "x_alpha", "inertia", "EI", "GJ", "a", "semichord"),
    "surface": ("hinge", "static_moment", "inertia", "GJ", "hinge_stiffness"),
    "actuator": ("stiffness", "station"),
    "mass": MASS_KEYS,
}
"""Differentiable wing parameters by owner (wing-file keys)."""

_PROPERTY = {
    ("segment", "semichord"): "b",
    ("surface", "hinge"): "c",
    ("surface", "static_moment"): "s_beta",
    ("surface", "inertia"): "i_beta",
    ("surface", "GJ"): "GJ_f",
    ("surface", "hinge_stiffness"): "k_delta",
}
"""Wing-file key -> element property of :func:`element_properties` (where the names differ)."""

STEP = 1e-20
"""Complex step (relative to nothing: the derivative of an analytic function is Im f(x + ih)/h
to rounding for any small h; this one is far below every property's rounding)."""


def matrix_derivative(
    wing: Wing,
    mesh: Mesh,
    owner: str,
    index: tuple[int, ...],
    key: str,
    *,
    side: int = 1,
    sweep_terms: str = "full",
) -> AeroMatrices:
    """Derivatives of the structural and aerodynamic matrices with respect to one parameter.

    Parameters
    ----------
    wing : Wing
    mesh : Mesh
    owner : {"segment", "surface", "actuator", "mass"}
    index : tuple of int
        ``(i,)`` for ``segments[i]``, ``control_surfaces[i]`` or ``masses[i]``, ``(k, j)`` for
        ``control_surfaces[k].actuators[j]``.
    key : str
        The wing-file key (:data:`PARAMETERS`).
    side : {1, -1}
        For an actuator's or a mass's station on a mesh node: the element outboard (1) or
        inboard (-1).
    sweep_terms : {"full", "classical"}
        Spanwise-convection terms of swept segments, as in the model's assembly.

    Returns
    -------
    AeroMatrices
        Each matrix is the derivative per unit of the parameter (free unknowns; one strip group
        holds the circulatory derivatives; ``Mz1`` is zero; no root rows).
    """
    if key not in PARAMETERS.get(owner, ()):
        raise ValueError(f"{owner} parameter {key!r}: not a differentiable parameter")
    n_q, n_n = mesh.n_dofs, mesh.n_nodes
    zero_q, zero_n = sp.csr_matrix((n_q, n_q)), sp.csr_matrix((n_n, n_n))
    if owner == "actuator":
        dk = _station_derivative(wing, mesh, *index, side) if key == "station" else None
        if dk is None:  # the wing with this actuator alone, of unit stiffness
            k, j = index
            act = replace(wing.control_surfaces[k].actuators[j], stiffness=1.0)
            surfaces = tuple(
                replace(c, actuators=(act,) if i == k else ())
                for i, c in enumerate(wing.control_surfaces)
            )
            dk = actuator_stiffness(replace(wing, control_surfaces=surfaces), mesh, n_q)
        return _matrices(mesh, {"Ks": dk}, zero_q, zero_n)
    if owner == "mass":  # the point mass matrix alone (mass_derivatives.py)
        dm = point_mass_derivative(wing, mesh, index[0], key, side=side)
        return _matrices(mesh, {"Ms": dm}, zero_q, zero_n)

    p = element_properties(wing, mesh)
    on = (mesh.segment if owner == "segment" else mesh.surface) == index[0]
    prop = _PROPERTY.get((owner, key), key)
    pc = {k: v.astype(complex) for k, v in p.items()}
    pc[prop] = pc[prop] + 1j * STEP * on
    ms, kd, kn, aero = section_coefficients(pc)
    coef = strip_coefficients(wing, mesh, aero, pc["b"], sweep_terms)  # swept strips if swept
    del coef["b"]  # the reduced frequency's semichord: the exact C(k) is not differentiated
    ms, kd, kn = (np.imag(x) / STEP for x in (ms, kd, kn))
    aero = {k: np.imag(v) / STEP for k, v in coef.items() if v is not None}

    # only the elements of the parameter's owner carry a derivative: integrate those
    L = mesh.lengths[on]
    xi, wts = gauss_rule()
    N, D, S = field_shapes(L, xi)
    N1 = gradient_shapes(N, D, S)
    nz = lag_shapes(xi)[None, :, None, :].repeat(L.size, axis=0)
    dofs = mesh.element_dofs[on]  # the clamped root's unknowns are -1: dropped
    lag = np.flatnonzero(on)
    lag = np.stack([lag, lag + 1], axis=1)
    shapes = {"q": n_q, "z": n_n}
    kinks = kink_transforms(wing, mesh)
    kinks = None if kinks is None else kinks[on]

    def block(left, coef, right, rows="q", cols="q"):
        coef = coef[on]
        if not np.any(coef):
            return None
        blocks = integrate(L, wts, left, coef[:, None], right)
        blocks = to_nodal(blocks, kinks, rows == "q", cols == "q")
        ri, ci = (dofs if k == "q" else lag for k in (rows, cols))
        return scatter_blocks(blocks, ri, ci, (shapes[rows], shapes[cols]))

    on_masses = mass_coupling_derivative(wing, mesh, owner, index[0], key)  # on a surface
    parts = {
        "Ms": _sum(block(N, ms, N), on_masses),
        "Ks": _sum(block(D, kd, D), block(N, kn, N)),
        "Mnc": block(N, aero["Mnc"], N),
        "Cnc": block(N, aero["Cnc"], N),
        "Knc": block(N, aero["Knc"], N),
        "Pq": _sum(block(N, aero["Pq"], N), _maybe(block, N, aero.get("Pg"), N1)),
        "Pd": block(N, aero["Pd"], N),
        "Lz1": block(nz, aero["inv_b"][:, None, None], nz, "z", "z"),
        "E1": _sum(
            block(nz, aero["r_q"][:, None, :], N, "z"),
            _maybe(block, nz, _lag_row(aero.get("r_g")), N1, "z"),
        ),
        "F1": block(nz, aero["r_d"][:, None, :], N, "z"),
        "W1": block(N, aero["w"][:, :, None], nz, "q", "z"),
    }
    return _matrices(mesh, {k: v for k, v in parts.items() if v is not None}, zero_q, zero_n)


def _sum(a, b):
    return b if a is None else a if b is None else a + b


def _maybe(block, left, coef, right, rows="q"):
    """``block(left, coef, right)``, or None without a coefficient (an unswept wing)."""
    return None if coef is None else block(left, coef, right, rows)


def _lag_row(r):
    return None if r is None else r[:, None, :]


def zero_derivative(mesh: Mesh) -> AeroMatrices:
    """Matrix derivatives that are all zero (for parameters outside the wing, e.g. damping)."""
    n_q, n_n = mesh.n_dofs, mesh.n_nodes
    return _matrices(mesh, {}, sp.csr_matrix((n_q, n_q)), sp.csr_matrix((n_n, n_n)))


def _matrices(mesh: Mesh, parts: dict, zero_q, zero_n) -> AeroMatrices:
    n_q = mesh.n_dofs
    get = parts.get
    return AeroMatrices(
        Ms=get("Ms", zero_q),
        Ks=get("Ks", zero_q),
        Mnc=get("Mnc", zero_q),
        Cnc=get("Cnc", zero_q),
        Knc=get("Knc", zero_q),
        circ_groups=(StripGroup(np.nan, get("Pq", zero_q), get("Pd", zero_q), np.zeros(n_q)),),
        Mz1=zero_n,
        Lz1=get("Lz1", zero_n),
        E1=get("E1", sp.csr_matrix((mesh.n_nodes, n_q))),
        F1=get("F1", sp.csr_matrix((mesh.n_nodes, n_q))),
        W1=get("W1", sp.csr_matrix((n_q, mesh.n_nodes))),
        dof_labels=mesh.dof_labels,
        lag_labels=tuple(str(i) for i in range(mesh.n_nodes)),
    )


def station_on_node(wing: Wing, mesh: Mesh, k: int, j: int) -> str | None:
    """Where actuator ``j`` of control surface ``k`` sits on a mesh node: ``"edge"`` (an end
    of its surface: the station's bound, one inward derivative), ``"node"`` (an interior node:
    the discretized model's stiffness has a kink there) or None."""
    cs = wing.control_surfaces[k]
    x, tol = cs.actuators[j].station, 1e-12 * wing.span
    if abs(x - cs.start) <= tol or abs(x - cs.end) <= tol:
        return "edge"
    return "node" if np.any(np.abs(mesh.nodes - x) <= tol) else None


def station_kink(
    wing: Wing, mesh: Mesh, owner: str, index: tuple[int, ...]
) -> tuple[str | None, int, str]:
    """Where the station of an actuator (``index = (k, j)``) or a mass (``(i,)``) has no
    two-sided derivative: ``("edge", inward side, why)`` on a bound of the station,
    ``("node", 0, why)`` on an interior mesh node (two one-sided derivatives), ``("jump", 0,
    why)`` where the matrices jump (no derivative), or ``(None, 1, "")``."""
    if owner == "mass":
        return mass_station_kink(wing, mesh, index[0])
    where = station_on_node(wing, mesh, *index)
    if where == "edge":  # the station may only move into its surface
        cs = wing.control_surfaces[index[0]]
        x = cs.actuators[index[1]].station
        why = "at an end of its control surface (a bound of the station): one-sided"
        return where, 1 if abs(x - cs.start) < abs(x - cs.end) else -1, why
    if where == "node":
        return where, 0, "on a mesh node: the discretized model has a kink there"
    return None, 1, ""


def _station_derivative(wing: Wing, mesh: Mesh, k: int, j: int, side: int) -> sp.csr_matrix:
    """``d/dx_a`` of the point spring ``k_act n(x_a) n(x_a)^T`` on the flap rotation."""
    act = wing.control_surfaces[k].actuators[j]
    x = act.station
    own = np.flatnonzero(mesh.surface == k)
    lo, hi = mesh.nodes[own], mesh.nodes[own + 1]
    tol = 1e-12 * wing.span
    inside = (lo - tol <= x) & (x <= hi + tol)
    if inside.sum() > 1:  # on a node: the element on the chosen side
        inside &= (lo > x - tol) if side > 0 else (hi < x + tol)
    if not inside.any():  # the surface's end node, from outside: the only element there
        inside = (lo - tol <= x) & (x <= hi + tol)
    e = own[np.flatnonzero(inside)[0]]
    length = mesh.nodes[e + 1] - mesh.nodes[e]
    xi = float(np.clip((x - mesh.nodes[e]) / length, 0.0, 1.0))
    n = np.array([1.0 - xi, xi])
    dn = np.array([-1.0, 1.0]) / length
    block = act.stiffness * (np.outer(dn, n) + np.outer(n, dn))
    dofs = mesh.element_dofs[e, 6:8]
    rows, cols = np.meshgrid(dofs, dofs, indexing="ij")
    n_q = mesh.n_dofs
    return sp.coo_matrix((block.ravel(), (rows.ravel(), cols.ravel())), shape=(n_q, n_q)).tocsr()
