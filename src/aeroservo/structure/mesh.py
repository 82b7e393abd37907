"""Spanwise mesh of a wing and numbering of the nodal unknowns.

Nodes are placed at every segment boundary and control-surface edge; the requested number of
elements is shared among those intervals in proportion to their length (at least one each).
Edges closer to each other (or to the root or tip) than :data:`EDGE_TOLERANCE` x span are merged
first, so that no sliver element is built: rounding in a wing file (an aileron ending 1 mm short
of the tip, a segment edge a few nanometres from it) would otherwise make an element thousands of
times shorter than its neighbours. The root and tip win over segment boundaries, which win over
control-surface edges; each merge is reported in :attr:`Mesh.warnings`.

Structural unknowns per node: ``w`` (bending displacement, up) [m], ``theta`` = dw/dx [rad],
``phi`` (twist, nose-up) [rad], and one ``delta`` (flap rotation, trailing-edge down) [rad]
per control surface covering the node. The root node is clamped (w = theta = phi = 0); flap
rotations are never clamped. Unknowns are numbered node by node (small bandwidth).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MAX_ELEMENTS, InputError, check_int, check_number
from .wing import Wing

__all__ = ["Mesh", "build_mesh", "LOCAL_DOFS", "EDGE_TOLERANCE"]

EDGE_TOLERANCE = 1e-3
"""Segment and control-surface edges closer than this fraction of the span are merged."""

LOCAL_DOFS = ("w_i", "theta_i", "w_j", "theta_j", "phi_i", "phi_j", "delta_i", "delta_j")
"""Order of the 8 structural unknowns of one element (Hermite, linear twist, linear flap)."""


@dataclass(frozen=True)
class Mesh:
    """Nodes, elements and unknown numbering of a wing stick model.

    Attributes
    ----------
    nodes : ndarray (n_nodes,)
        Spanwise stations [m].
    segment : ndarray (n_elements,) of int
        Index of the wing segment each element lies in.
    surface : ndarray (n_elements,) of int
        Index of the control surface on each element, -1 where there is none.
    element_dofs : ndarray (n_elements, 8) of int
        Global structural unknown of each local unknown (order ``LOCAL_DOFS``), -1 if removed
        (clamped root, or no flap on the element).
    dof_w, dof_theta, dof_phi : ndarray (n_nodes,) of int
        Global unknown per node, -1 at the clamped root.
    dof_delta : ndarray (n_surfaces, n_nodes) of int
        Flap unknown per surface and node, -1 where the surface is absent.
    dof_labels : tuple of str
        Name of each structural unknown, e.g. ``"w_3"``, ``"delta_aileron_7"``.
    surface_extent : ndarray (n_surfaces, 2)
        Spanwise start and end of each control surface on the mesh [m] (after merging).
    warnings : tuple of str
        Edges that were merged, one sentence each.
    """

    nodes: np.ndarray
    segment: np.ndarray
    surface: np.ndarray
    element_dofs: np.ndarray
    dof_w: np.ndarray
    dof_theta: np.ndarray
    dof_phi: np.ndarray
    dof_delta: np.ndarray
    dof_labels: tuple[str, ...]
    surface_extent: np.ndarray = None
    warnings: tuple[str, ...] = ()

    @property
    def n_nodes(self) -> int:
        return int(self.nodes.size)

    @property
    def n_elements(self) -> int:
        return int(self.nodes.size - 1)

    @property
    def n_dofs(self) -> int:
        """Number of structural unknowns after the root clamp."""
        return len(self.dof_labels)

    @property
    def lengths(self) -> np.ndarray:
        """Element lengths [m]."""
        return np.diff(self.nodes)

    def locate(self, x: float) -> tuple[int, float]:
        """Element index and local coordinate xi in [0, 1] of station ``x`` [m]."""
        span = self.nodes[-1]
        if not (0.0 <= x <= span * (1 + 1e-12)):
            raise InputError(
                f"station = {x:g}: outside the wing, allowed range is [0, {span:g}] [m]"
            )
        e = int(np.clip(np.searchsorted(self.nodes, x, side="right") - 1, 0, self.n_elements - 1))
        xi = (x - self.nodes[e]) / (self.nodes[e + 1] - self.nodes[e])
        return e, float(np.clip(xi, 0.0, 1.0))


def _edges(wing: Wing, stations=()) -> tuple[list[tuple[float, int, str]], float]:
    """Every breakpoint with its priority (0 root/tip, 1 segment edge, 2 surface edge, 3 load
    station)."""
    span = wing.span
    pts = [(0.0, 0, "the root"), (span, 0, "the tip")]
    pts += [(float(x), 3, f"load station {x:g} m") for x in stations]
    for i, seg in enumerate(wing.segments[:-1]):
        pts.append((seg.end, 1, f"segments[{i}].end"))
    for cs in wing.control_surfaces:
        pts += [
            (cs.start, 2, f"control surface '{cs.name}' start"),
            (cs.end, 2, f"control surface '{cs.name}' end"),
        ]
    return sorted(pts), EDGE_TOLERANCE * span


def _merged_edges(wing: Wing, stations=()) -> tuple[dict[float, float], np.ndarray, list[str]]:
    """Clusters of edges closer than the tolerance, each replaced by one representative.

    Returns the map from every original edge to its representative, the sorted breakpoints
    and one warning per merge.
    """
    pts, tol = _edges(wing, stations)
    clusters: list[list[tuple[float, int, str]]] = []
    for p in pts:
        if clusters and p[0] - clusters[-1][-1][0] < tol:
            clusters[-1].append(p)
        else:
            clusters.append([p])
    snap: dict[float, float] = {}
    warnings = []
    for cl in clusters:
        best = min(c[1] for c in cl)
        tops = [c for c in cl if c[1] == best]
        rep = tops[0][0] if best < 2 else float(np.mean([c[0] for c in tops]))
        if any(c[1] == 0 and c[0] == 0.0 for c in cl):
            rep = 0.0
        for c in cl:
            snap[c[0]] = rep
        moved = [c for c in cl if abs(c[0] - rep) > 1e-12 * wing.span]
        if moved:
            names = ", ".join(f"{c[2]} ({c[0]:.6g} m)" for c in moved)
            warnings.append(
                f"mesh: {names} moved to {rep:.6g} m (edges closer than "
                f"{EDGE_TOLERANCE:g} x span = {tol:.3g} m are merged: no sliver elements)"
            )
    return snap, np.unique([snap[c[0]] for c in pts]), warnings


def _allocate(lengths: np.ndarray, n: int) -> np.ndarray:
    """Share ``n`` elements among intervals: at least one each, sizes as even as possible."""
    counts = np.maximum(1, np.floor(n * lengths / lengths.sum()).astype(int))
    while counts.sum() < n:
        counts[np.argmax(lengths / counts)] += 1
    while counts.sum() > n:
        ratio = np.where(counts > 1, lengths / counts, np.inf)
        counts[np.argmin(ratio)] -= 1
    return counts


def build_mesh(wing: Wing, n_elements: int, stations: tuple[float, ...] = ()) -> Mesh:
    """Mesh a wing with ``n_elements`` beam elements.

    Parameters
    ----------
    wing : Wing
        The wing.
    n_elements : int
        Total number of elements; at least one per interval between segment boundaries,
        control-surface edges and load stations.
    stations : tuple of float
        Load stations [m]: nodes are put there (a station closer than the edge tolerance to an
        edge moves to it, with a warning), so that the loads there are outputs.

    Returns
    -------
    Mesh
    """
    n_elements = check_int("n_elements", n_elements, lo=1, hi=MAX_ELEMENTS)
    for x in stations:
        check_number("load station", x, unit="m", lo=0.0, hi=wing.span)
    snap, bp, warnings = _merged_edges(wing, stations)
    extent = np.array([[snap[cs.start], snap[cs.end]] for cs in wing.control_surfaces])
    extent = extent.reshape(len(wing.control_surfaces), 2)
    for k, cs in enumerate(wing.control_surfaces):
        if extent[k, 1] <= extent[k, 0]:
            raise InputError(
                f"control surface '{cs.name}': {cs.start:g} to {cs.end:g} m is shorter than the "
                f"mesh tolerance {EDGE_TOLERANCE:g} x span = {EDGE_TOLERANCE * wing.span:.3g} m"
            )
    if n_elements < bp.size - 1:
        raise InputError(
            f"n_elements = {n_elements}: at least {bp.size - 1} are needed to put nodes at "
            "every segment boundary, control-surface edge and load station"
        )
    counts = _allocate(np.diff(bp), n_elements)
    nodes = np.concatenate(
        [np.linspace(bp[i], bp[i + 1], counts[i] + 1)[:-1] for i in range(bp.size - 1)] + [bp[-1:]]
    )
    mid = 0.5 * (nodes[:-1] + nodes[1:])
    seg_ends = np.array([s.end for s in wing.segments])
    segment = np.searchsorted(seg_ends, mid)
    surface = np.full(mid.size, -1)
    for k in range(len(wing.control_surfaces)):
        surface[(mid > extent[k, 0]) & (mid < extent[k, 1])] = k

    n_nodes = nodes.size
    n_surf = len(wing.control_surfaces)
    tol = 1e-9 * wing.span
    dof_w = np.full(n_nodes, -1)
    dof_theta = np.full(n_nodes, -1)
    dof_phi = np.full(n_nodes, -1)
    dof_delta = np.full((n_surf, n_nodes), -1)
    labels: list[str] = []
    for i, x in enumerate(nodes):
        if i > 0:
            for arr, name in ((dof_w, "w"), (dof_theta, "theta"), (dof_phi, "phi")):
                arr[i] = len(labels)
                labels.append(f"{name}_{i}")
        for k, cs in enumerate(wing.control_surfaces):
            if extent[k, 0] - tol <= x <= extent[k, 1] + tol:
                dof_delta[k, i] = len(labels)
                labels.append(f"delta_{cs.name}_{i}")

    n_el = n_nodes - 1
    el = np.arange(n_el)
    edofs = np.full((n_el, 8), -1)
    edofs[:, 0] = dof_w[el]
    edofs[:, 1] = dof_theta[el]
    edofs[:, 2] = dof_w[el + 1]
    edofs[:, 3] = dof_theta[el + 1]
    edofs[:, 4] = dof_phi[el]
    edofs[:, 5] = dof_phi[el + 1]
    has = surface >= 0
    edofs[has, 6] = dof_delta[surface[has], el[has]]
    edofs[has, 7] = dof_delta[surface[has], el[has] + 1]
    return Mesh(
        nodes=nodes,
        segment=segment,
        surface=surface,
        element_dofs=edofs,
        dof_w=dof_w,
        dof_theta=dof_theta,
        dof_phi=dof_phi,
        dof_delta=dof_delta,
        dof_labels=tuple(labels),
        surface_extent=extent,
        warnings=tuple(warnings),
    )
