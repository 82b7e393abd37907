"""The doublet-lattice boxes of a wing, generated from the planform its segments describe.

Planform (``docs/sweep.md``, ``docs/conventions.md``): each segment's elastic axis is turned by
its sweep, sections are normal to it, the leading edge ``b (1 + a)`` ahead and the trailing edge
``b (1 - a)`` aft. Seen in the stream, a segment is a band of span ``x`` between the spanwise
positions of its axis' ends, with straight leading and trailing edges and a streamwise chord
``2 b / cos(sweep)``: the lattice is made of **streamwise strips** in those bands (box side
edges along the flow, as Nastran's CAERO1 requires), so the root of a swept wing is the plane
x = 0 and its tip is cut streamwise at the tip of the axis.

Strip edges lie at every segment band edge and at the spanwise position where each control
surface's hinge line starts and ends; inside a surface's strips the hinge line is a chordwise
box edge (``(1 + c) / 2`` of the chord; at least 2 boxes on the surface), so that a surface
rotation moves whole boxes and is represented exactly. (For a swept surface the side edges,
normal to the axis, are replaced by the streamwise strip edges through the hinge line's ends.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..aero.dlm_settings import MAX_BOXES, DoubletLattice
from ..aero.lattice import Lattice, strip_lattice
from ..errors import InputError
from ..structure.wing import Wing

__all__ = ["PanelGrid", "panel_grid", "axis_frames"]

MIN_STRIPS = 8
"""Fewest spanwise strips of the default box division."""

BOX_ASPECT = 1.0
"""Default box width over box chord: square boxes (the measured convergence of docs/dlm.md)."""

MERGE = 1e-3
"""Strip edges closer than this fraction of the span are merged."""


def axis_frames(wing: Wing) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per segment: the elastic axis at its start ``(x, y)`` [m] (x spanwise, y aft, from the
    root's elastic axis), the unit vector along the axis and the unit normal pointing aft."""
    out, origin = [], np.zeros(2)
    for seg in wing.segments:
        c, s = np.cos(seg.sweep), np.sin(seg.sweep)
        along, aft = np.array([c, s]), np.array([-s, c])
        out.append((origin.copy(), along, aft))
        origin = origin + (seg.end - seg.start) * along
    return out


@dataclass(frozen=True)
class PanelGrid:
    """The lattice of a wing and what each box belongs to.

    Attributes
    ----------
    lattice : Lattice
    segment : ndarray (n_boxes,) of int
        Wing segment whose band holds each box.
    surface : ndarray (n_boxes,) of int
        Control surface a box belongs to (it is aft of the hinge line), -1 for the wing.
    reference_y : float
        Most forward leading-edge point [m] (chordwise y): the gust front is there at t = 0.
    """

    lattice: Lattice
    segment: np.ndarray
    surface: np.ndarray
    reference_y: float

    @property
    def n_boxes(self) -> int:
        return self.lattice.n_boxes


def _share(lengths: np.ndarray, n: int) -> np.ndarray:
    """``n`` strips shared by intervals in proportion to their length, at least one each."""
    counts = np.ones(lengths.size, dtype=int)
    for _ in range(max(0, n - lengths.size)):
        counts[int(np.argmax(lengths / counts))] += 1
    return counts


def _hinge_station(wing: Wing, frames, i: int, cs, x: float) -> float:
    """Station along the axis [m] of the point of ``cs``'s hinge line at spanwise x, in
    segment ``i``'s band."""
    seg = wing.segments[i]
    origin, along, aft = frames[i]
    d_h = seg.semichord * (cs.hinge - seg.a)
    return seg.start + (x - origin[0] - d_h * aft[0]) / along[0]


def _hinge_x(wing: Wing, frames, station: float, cs) -> float:
    """Spanwise position [m] of the point of ``cs``'s hinge line at ``station``."""
    i = next(
        (j for j, s in enumerate(wing.segments) if station <= s.end + 1e-12 * wing.span),
        len(wing.segments) - 1,
    )
    seg = wing.segments[i]
    origin, along, aft = frames[i]
    d_h = seg.semichord * (cs.hinge - seg.a)
    return float(origin[0] + (station - seg.start) * along[0] + d_h * aft[0])


def panel_grid(wing: Wing, settings: DoubletLattice) -> PanelGrid:
    """Box the planform of ``wing`` (module notes).

    Parameters
    ----------
    wing : Wing
    settings : DoubletLattice
        Box counts and the root's symmetry.
    """
    frames = axis_frames(wing)
    tip = frames[-1][0] + (wing.segments[-1].end - wing.segments[-1].start) * frames[-1][1]
    band = np.array([f[0][0] for f in frames] + [tip[0]])
    x_tip = float(tip[0])
    edges = list(band)
    for cs in wing.control_surfaces:
        for station in (cs.start, cs.end):
            edges.append(float(np.clip(_hinge_x(wing, frames, station, cs), 0.0, x_tip)))
    edges = np.unique(np.round(np.sort(edges), 12))
    merged = [edges[0]]
    for e in edges[1:]:
        if e - merged[-1] > MERGE * x_tip:
            merged.append(e)
    merged[-1] = x_tip
    edges = np.asarray(merged)
    lengths = np.diff(edges)
    chord_mean = np.mean([2 * s.semichord / np.cos(s.sweep) for s in wing.segments])
    if settings.spanwise is None:
        width = BOX_ASPECT * chord_mean / settings.chordwise
        n_total = max(MIN_STRIPS, int(np.ceil(x_tip / width)))
        n_total = min(n_total, MAX_BOXES // settings.chordwise)
    else:
        n_total = settings.spanwise
    if n_total < lengths.size:
        raise InputError(
            f"dlm.spanwise = {n_total}: the planform has {lengths.size} spanwise pieces (segment "
            "bands and control-surface edges), each needs at least one strip"
        )
    counts = _share(lengths, n_total)
    x = np.concatenate(
        [
            np.linspace(a, b, c + 1)[:-1]
            for a, b, c in zip(edges[:-1], edges[1:], counts, strict=True)
        ]
        + [[x_tip]]
    )
    strips = np.column_stack([x[:-1], x[1:]])
    mids = strips.mean(axis=1)
    seg_of = np.clip(np.searchsorted(band, mids, side="right") - 1, 0, len(wing.segments) - 1)
    le, chord, fractions, surf_of, n_main = [], [], [], [], []
    for (x0, x1), i in zip(strips, seg_of, strict=True):
        seg = wing.segments[i]
        origin, along, _aft = frames[i]
        tan, cos = along[1] / along[0], along[0]
        offset = seg.semichord * (1 + seg.a) / cos
        le.append([origin[1] + (x - origin[0]) * tan - offset for x in (x0, x1)])
        chord.append([2 * seg.semichord / cos] * 2)
        surf = -1
        for j, cs in enumerate(wing.control_surfaces):
            s_h = _hinge_station(wing, frames, i, cs, 0.5 * (x0 + x1))
            if cs.start < s_h < cs.end:
                surf = j
        surf_of.append(surf)
        n_c = settings.chordwise
        if surf < 0:
            fractions.append(np.linspace(0.0, 1.0, n_c + 1))
            n_main.append(n_c)
            continue
        f_h = 0.5 * (1.0 + wing.control_surfaces[surf].hinge)
        n_flap = max(2, int(round(n_c * (1.0 - f_h))))
        n_m = max(1, n_c - n_flap)
        fractions.append(
            np.concatenate([np.linspace(0.0, f_h, n_m + 1)[:-1], np.linspace(f_h, 1.0, n_flap + 1)])
        )
        n_main.append(n_m)
    lattice = strip_lattice(
        strips, np.asarray(le), np.asarray(chord), fractions, symmetric=settings.symmetric
    )
    if lattice.n_boxes > MAX_BOXES:
        raise InputError(
            f"dlm: {lattice.n_boxes} boxes, above the limit of {MAX_BOXES}: use fewer chordwise "
            "or spanwise boxes"
        )
    st = lattice.strip
    on_flap = lattice.row >= np.asarray(n_main)[st]
    surface = np.where(on_flap, np.asarray(surf_of)[st], -1)
    return PanelGrid(lattice, seg_of[st], surface, float(lattice.corners[:, :, 1].min()))
