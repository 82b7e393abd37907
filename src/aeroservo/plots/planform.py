"""The planform of a wing seen from above: segments (swept or not), elastic axis, control
surfaces, actuators and concentrated masses (:func:`plot_planform`).

Geometry as the model takes it (``docs/sweep.md``, ``docs/conventions.md``): stations run along
the elastic axis, each segment turned by its sweep (+ backward); sections, hinge lines and mass
offsets are normal to the elastic axis, the leading edge ``b (1 + a)`` ahead of it and the
trailing edge ``b (1 - a)`` aft. At a crank the two segments' sections meet at an angle (a stick
model's planform has a notch or an overlap there).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .._figures import new_figure

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["plot_planform", "planform_points"]


def _axis_frames(wing) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per segment: the elastic axis at its start (X aft, Y outboard) [m], the unit vector
    along the axis and the unit normal pointing aft."""
    out, origin = [], np.zeros(2)
    for seg in wing.segments:
        sweep = float(getattr(seg, "sweep", 0.0))
        along = np.array([np.sin(sweep), np.cos(sweep)])
        aft = np.array([np.cos(sweep), -np.sin(sweep)])
        out.append((origin.copy(), along, aft))
        origin = origin + (seg.end - seg.start) * along
    return out


def planform_points(wing, station: float, offset) -> np.ndarray:
    """Points of the planform [m] (X aft, Y outboard, from the root's elastic axis): at
    ``station`` along the elastic axis [m], ``offset`` aft of it, normal to it [m]."""
    frames = _axis_frames(wing)
    i = next(
        (k for k, s in enumerate(wing.segments) if station <= s.end + 1e-12 * wing.span),
        len(wing.segments) - 1,
    )
    origin, along, aft = frames[i]
    base = origin + (station - wing.segments[i].start) * along
    return base + np.multiply.outer(np.atleast_1d(offset), aft)


def plot_planform(wing, *, title: str | None = None, lattice=None) -> Figure:
    """Top view of a wing: outline, elastic axis, control surfaces (shaded aft of their hinge
    lines), actuators (crosses on the hinge line) and concentrated masses (circles at their
    CG, area proportional to the mass, labelled), equal axes in metres.

    Parameters
    ----------
    wing : Wing
    title : str, optional
    lattice : Lattice, optional
        Doublet-lattice boxes to draw on it (``model.dlm.grid.lattice``): their outlines and
        load points (the 1/4-chord points of the boxes).
    """
    ends = [
        planform_points(wing, s.end, [-s.semichord * (1 + s.a), s.semichord * (1 - s.a)])
        for s in wing.segments
    ]
    pts = np.vstack([planform_points(wing, 0.0, [-1.0, 1.0]) * wing.segments[0].semichord, *ends])
    ratio = np.ptp(pts[:, 0]) / max(np.ptp(pts[:, 1]), 1e-9)  # chordwise / spanwise extent
    fig = new_figure(figsize=(7.2, float(np.clip(7.2 * ratio + 1.6, 3.2, 8.0))))
    ax = fig.subplots()
    for k, seg in enumerate(wing.segments):
        le, te = -seg.semichord * (1 + seg.a), seg.semichord * (1 - seg.a)
        corners = [
            planform_points(wing, seg.start + 1e-9 * wing.span, le)[0],
            planform_points(wing, seg.end, le)[0],
            planform_points(wing, seg.end, te)[0],
            planform_points(wing, seg.start + 1e-9 * wing.span, te)[0],
        ]
        xy = np.array(corners + corners[:1])
        ax.fill(xy[:, 1], xy[:, 0], color="0.92", ec="0.2", lw=1.0)
        ea = np.array(
            [
                planform_points(wing, seg.start + 1e-9 * wing.span, 0.0)[0],
                planform_points(wing, seg.end, 0.0)[0],
            ]
        )
        ax.plot(ea[:, 1], ea[:, 0], "k-.", lw=0.9, label="elastic axis" if k == 0 else None)
    for j, cs in enumerate(wing.control_surfaces):
        pieces = [s for s in wing.segments if s.end > cs.start and s.start < cs.end]
        for n, seg in enumerate(pieces):
            lo, hi = max(cs.start, seg.start) + 1e-9 * wing.span, min(cs.end, seg.end)
            hinge = seg.semichord * (cs.hinge - seg.a)
            te = seg.semichord * (1 - seg.a)
            xy = np.array(
                [
                    planform_points(wing, lo, hinge)[0],
                    planform_points(wing, hi, hinge)[0],
                    planform_points(wing, hi, te)[0],
                    planform_points(wing, lo, te)[0],
                ]
            )
            ax.fill(
                xy[:, 1],
                xy[:, 0],
                color=f"C{j}",
                alpha=0.45,
                lw=0,
                label=cs.name if n == 0 else None,
            )
        for act in cs.actuators:
            seg = wing.segment_at(act.station)
            p = planform_points(wing, act.station, seg.semichord * (cs.hinge - seg.a))[0]
            ax.plot(p[1], p[0], "x", color="k", ms=7, mew=1.5)
    if any(cs.actuators for cs in wing.control_surfaces):
        ax.plot([], [], "x", color="k", ms=7, mew=1.5, label="actuator")
    masses = tuple(getattr(wing, "masses", ()))
    if masses:
        top = max(m.mass for m in masses)
        for m in masses:
            seg = wing.segment_at(m.station)
            y = m.offset
            if m.surface is not None:
                y += seg.semichord * (wing.surface(m.surface).hinge - seg.a)
            p = planform_points(wing, m.station, y)[0]
            size = 40 + 260 * m.mass / top if top > 0 else 40
            rotary = m.mass == 0.0  # a rotary inertia (no mass): a hollow marker
            ax.scatter(p[1], p[0], s=size, color="none" if rotary else "C3", ec="k", zorder=5)
            ax.annotate(
                f"{m.name} {m.inertia:.3g} kg m^2" if rotary else f"{m.name} {m.mass:g} kg",
                (p[1], p[0]),
                xytext=(6, 6),
                textcoords="offset points",
                fontsize=8,
            )
        if top > 0:
            ax.scatter([], [], s=60, color="C3", ec="k", label="concentrated mass (CG)")
        if any(m.mass == 0.0 for m in masses):
            ax.scatter([], [], s=40, color="none", ec="k", label="rotary inertia (no mass)")
    if lattice is not None:
        _draw_lattice(ax, lattice)
    ax.set_aspect("equal")
    ax.invert_yaxis()  # the free stream comes from the top of the page
    ax.set_xlabel("spanwise position Y [m]")
    ax.set_ylabel("X [m], aft of the root's elastic axis")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    sweeps = sorted({round(np.degrees(getattr(s, "sweep", 0.0)), 3) for s in wing.segments})
    sweep_text = ", ".join(f"{s:g}" for s in sweeps)
    ax.set_title(
        (title or f"{wing.name}: planform")
        + f"\nsweep {sweep_text} deg; sections normal to the elastic axis",
        fontsize=9,
    )
    return fig


def _draw_lattice(ax, lattice) -> None:
    """Box outlines (planform coordinates: x spanwise, y aft) and load points."""
    from matplotlib.collections import PolyCollection

    boxes = PolyCollection(
        lattice.corners, facecolors="none", edgecolors="C0", linewidths=0.5, alpha=0.8
    )
    ax.add_collection(boxes)
    pts = lattice.load_points
    ax.plot(pts[:, 0], pts[:, 1], ".", color="C0", ms=2)
    where = "mirrored at the root" if lattice.symmetric else "no root symmetry plane"
    ax.plot([], [], "s", mfc="none", mec="C0", label=f"{lattice.n_boxes} DLM boxes ({where})")
