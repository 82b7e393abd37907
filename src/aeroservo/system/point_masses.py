"""Mass matrix of the concentrated masses, consistent through the beam element's shape functions.

A rigid mass m with CG at chordwise distance y aft of the elastic axis and height z above it,
attached at station x_m, moves up by ``w(x_m) - y phi(x_m)`` (``docs/conventions.md``) and
aft by ``z phi(x_m)``; its kinetic energy

    T = 1/2 m (w' - y phi')^2 + 1/2 (I + m z^2) phi'^2

gives the point mass matrix on ``[w, phi]``

    [[ m,    -m y            ],
     [-m y,   I + m (y^2 + z^2)]]

the section matrix of ``system/assembly.py`` with S_alpha = m y and I_alpha = I + m (y^2 + z^2)
concentrated at x_m. On a control surface with hinge y_h = b (c - a) aft of the elastic axis, a
mass at y_f aft of the hinge turns with the surface (phi + delta, the same sense) and moves up
by ``w - (y_h + y_f) phi - y_f delta``, the section matrix with flap of ``docs/conventions.md``
with S_beta = m y_f and I_beta = I + m (y_f^2 + z^2). The 3x3 point matrix is spread on the
element's unknowns by the field shape functions at x_m (``N^T M N``), like the actuators.
"""

from __future__ import annotations

import numpy as np

from ..structure.beam_element import point_shapes
from ..structure.masses import ConcentratedMass
from ..structure.mesh import Mesh
from ..structure.wing import Wing

__all__ = ["point_mass_section", "point_mass_blocks", "locate_mass"]


def point_mass_section(wing: Wing, pm: ConcentratedMass) -> np.ndarray:
    """The 3x3 mass matrix of one concentrated mass on ``[w, phi, delta]`` at its station.

    Parameters
    ----------
    wing : Wing
        The wing it is attached to (elastic axis, semichord and hinge at its station).
    pm : ConcentratedMass

    Returns
    -------
    ndarray (3, 3)
        [kg, kg m, kg m^2] blocks; the delta row and column are zero unless it sits on a surface.
    """
    m, z2 = pm.mass, pm.vertical_offset**2
    rot = pm.inertia + m * z2  # pitch inertia about the axis through the EA height
    out = np.zeros((3, 3))
    if pm.surface is None:
        y_e, y_f = pm.offset, 0.0
    else:
        seg = wing.segment_at(pm.station)
        y_f = pm.offset
        y_e = seg.semichord * (wing.surface(pm.surface).hinge - seg.a) + y_f
    out[0, 0] = m
    out[0, 1] = out[1, 0] = -m * y_e
    out[1, 1] = rot + m * y_e**2
    if pm.surface is not None:
        out[0, 2] = out[2, 0] = -m * y_f
        out[1, 2] = out[2, 1] = rot + m * y_e * y_f
        out[2, 2] = rot + m * y_f**2
    return out


def locate_mass(wing: Wing, mesh: Mesh, pm: ConcentratedMass) -> tuple[int, float]:
    """Element and local coordinate xi in [0, 1] of a mass (an element of its surface if it
    sits on one, so that the flap rotation is defined there)."""
    if pm.surface is None:
        return mesh.locate(min(pm.station, float(mesh.nodes[-1])))
    k = [cs.name for cs in wing.control_surfaces].index(pm.surface)
    own = np.flatnonzero(mesh.surface == k)
    i = np.searchsorted(mesh.nodes[own + 1], pm.station - 1e-12 * wing.span)
    e = int(own[min(i, own.size - 1)])
    xi = (pm.station - mesh.nodes[e]) / (mesh.nodes[e + 1] - mesh.nodes[e])
    return e, float(np.clip(xi, 0.0, 1.0))


def point_mass_blocks(wing: Wing, mesh: Mesh) -> np.ndarray | float:
    """Element mass blocks (n_el, 8, 8) of all concentrated masses, ``N^T M_point N`` in the
    element holding each mass (order ``mesh.LOCAL_DOFS``); ``0.0`` when there are none, so the
    assembly of a wing without masses is unchanged to the last bit."""
    if not wing.masses:
        return 0.0
    out = np.zeros((mesh.n_elements, 8, 8))
    for pm in wing.masses:
        e, xi = locate_mass(wing, mesh, pm)
        n, _ = point_shapes(mesh.lengths[e], xi)
        out[e] += n.T @ point_mass_section(wing, pm) @ n
    return out
