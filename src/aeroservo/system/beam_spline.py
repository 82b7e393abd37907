"""The beam spline: box displacements and slopes from the beam's unknowns (Nastran's SPLINE2).

Chordwise lines normal to the elastic axis are rigid and attached to it (the assumption of the
beam element itself): a point at station ``s`` along the axis and distance ``d`` aft of it,
normal to it, moves up by

``z = w(s) - d phi(s) - [on a control surface] (d - d_h) delta(s)``

with ``d_h = b (c - a)`` the hinge line's distance (``docs/conventions.md``). Its streamwise
slope, with the axis swept by ``L`` (``ds/dy = sin L``, ``dd/dy = cos L``), is

``dz/dy = sin L (w' - d phi' - (d - d_h) delta') - cos L (phi + delta)``

(the bending slope of a swept wing changes the angle of attack; without sweep
``dz/dy = -(phi + delta)``). Points inboard of the clamped root section (the root triangle of a
swept wing) do not move; points beyond the tip section move with it (``w(L) + (s - L) w'(L)``,
``phi(L)``). A surface's rotation is taken at the nearest station inside the surface.

Rows are over the extended unknowns of :func:`aeroservo.system.assembly.extended_dofs` (the
free unknowns, then the clamped root's ``w, theta, phi``), so the transposed rows give the
generalized forces of box loads on the free unknowns and the root reactions (virtual work).
"""

from __future__ import annotations

import numpy as np

from ..structure.beam_element import pointwise_shapes
from ..structure.mesh import Mesh
from ..structure.wing import Wing
from .assembly import extended_dofs
from .panel_grid import axis_frames

__all__ = ["spline_rows"]


def _scatter(rows: np.ndarray, edofs: np.ndarray, n: int) -> np.ndarray:
    """Dense (n_p, n) rows from per-point element rows (n_p, 8) and their unknowns."""
    out = np.zeros((rows.shape[0], n))
    keep = edofs >= 0
    p_idx = np.broadcast_to(np.arange(rows.shape[0])[:, None], edofs.shape)
    np.add.at(out, (p_idx[keep], edofs[keep]), rows[keep])
    return out


def _fields(mesh: Mesh, s: np.ndarray) -> tuple:
    """Element, shape rows and the beyond-tip length of stations ``s`` [m] (clipped to the
    beam)."""
    nodes = mesh.nodes
    L = nodes[-1]
    sc = np.clip(s, 0.0, L)
    e = np.clip(np.searchsorted(nodes, sc, side="right") - 1, 0, mesh.n_elements - 1)
    xi = (sc - nodes[e]) / mesh.lengths[e]
    N, D, S = pointwise_shapes(mesh.lengths[e], xi)
    return e, N, D, S, np.maximum(s - L, 0.0)


def spline_rows(
    wing: Wing,
    mesh: Mesh,
    points: np.ndarray,
    segment: np.ndarray,
    surface: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Rows of the displacement ``z`` [m] and the streamwise slope ``dz/dy`` [rad] of points.

    Parameters
    ----------
    wing : Wing
    mesh : Mesh
    points : ndarray (n_p, 2)
        ``(x, y)`` [m]: spanwise, and aft of the root's elastic axis.
    segment : ndarray (n_p,) of int
        Segment whose axis the point is attached to.
    surface : ndarray (n_p,) of int
        Control surface the point rotates with (-1: none).

    Returns
    -------
    Z, Zy : ndarray (n_p, n_q + 3)
        ``z = Z @ q_ext`` and ``dz/dy = Zy @ q_ext`` over the extended unknowns.
    """
    frames = axis_frames(wing)
    points = np.asarray(points, dtype=float)
    origin = np.array([frames[i][0] for i in segment])
    along = np.array([frames[i][1] for i in segment])
    aft = np.array([frames[i][2] for i in segment])
    start = np.array([wing.segments[i].start for i in segment])
    rel = points - origin
    s = start + np.einsum("pi,pi->p", rel, along)
    d = np.einsum("pi,pi->p", rel, aft)
    sin, cos = along[:, 1], along[:, 0]
    edofs_all = extended_dofs(mesh)
    n_ext = mesh.n_dofs + 3

    e, N, D, S, beyond = _fields(mesh, s)
    w = N[:, 0] + beyond[:, None] * S  # rigid extension beyond the tip
    dw = S
    phi, dphi = N[:, 1], np.where(beyond[:, None] > 0, 0.0, D[:, 1])
    z = w - d[:, None] * phi
    zy = sin[:, None] * (dw - d[:, None] * dphi) - cos[:, None] * phi
    Z = _scatter(z, edofs_all[e], n_ext)
    Zy = _scatter(zy, edofs_all[e], n_ext)

    flap = np.flatnonzero(surface >= 0)
    if flap.size:
        ef = np.empty(flap.size, dtype=int)
        sf = np.empty(flap.size)
        for j in np.unique(surface[flap]):
            sel = surface[flap] == j
            elems = np.flatnonzero(mesh.surface == j)  # the surface's own elements
            sf[sel] = np.clip(s[flap[sel]], mesh.nodes[elems[0]], mesh.nodes[elems[-1] + 1])
            e_j = np.searchsorted(mesh.nodes, sf[sel], side="right") - 1
            ef[sel] = np.clip(e_j, elems[0], elems[-1])
        Nf, Df, _ = pointwise_shapes(mesh.lengths[ef], (sf - mesh.nodes[ef]) / mesh.lengths[ef])
        d_h = np.array(
            [
                wing.segments[i].semichord * (wing.control_surfaces[j].hinge - wing.segments[i].a)
                for i, j in zip(segment[flap], surface[flap], strict=True)
            ]
        )
        arm = (d[flap] - d_h)[:, None]
        zf = -arm * Nf[:, 2]
        zyf = -sin[flap, None] * arm * Df[:, 2] - cos[flap, None] * Nf[:, 2]
        Z[flap] += _scatter(zf, edofs_all[ef], n_ext)
        Zy[flap] += _scatter(zyf, edofs_all[ef], n_ext)
    clamped = s < 0.0
    Z[clamped] = 0.0
    Zy[clamped] = 0.0
    return Z, Zy
