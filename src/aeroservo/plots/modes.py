"""Mode-shape figures and animations: natural modes and the flutter mode along the span.

A mode is given as nodal fields (:meth:`aeroservo.system.aeroelastic.AeroelasticModel.
mode_fields`): bending ``w`` [m], twist ``phi`` [rad] and flap rotations ``delta_<surface>``
[rad] (relative to the wing) at the stations ``x`` [m]. A deflection and a rotation are not
comparable, so each field is drawn divided by its own peak over the span (its peak, in m or
deg, is in the legend) and a mode's make-up is given by its share of strain energy per kind of
deformation when the model is known (:func:`strain_energy_shares`; the same measure names the
modes, :meth:`~aeroservo.system.aeroelastic.AeroelasticModel.label_modes`). A complex mode (the
flutter mode) is drawn as magnitude and phase [deg] along the span, the phase relative to one
reference point named on the axis. A flap rotation is drawn over its surface only.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from .._figures import detached, new_figure

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = [
    "plot_mode_shapes",
    "plot_modes",
    "strain_energy_shares",
    "animate_mode",
    "gif_writer",
    "PHASE_FLOOR",
]

PHASE_FLOOR = 0.02
"""The phase of a field is not drawn where its magnitude is below this share of its peak."""


def _on_surface(x: np.ndarray, y: np.ndarray, span: Sequence[float] | None) -> np.ndarray:
    if span is None:
        return y
    inside = (x >= span[0] - 1e-9) & (x <= span[1] + 1e-9)
    return np.where(inside, y, np.nan)


def _name(key: str) -> tuple[str, str, float]:
    """Legend name, unit and scale to that unit of a field (rotations in degrees)."""
    if key == "w":
        return "bending w", "m", 1.0
    if key == "phi":
        return "twist \u03c6", "deg", np.degrees(1.0)
    return f"{key[len('delta_') :]} rotation \u03b4", "deg", np.degrees(1.0)


def strain_energy_shares(model, shapes: np.ndarray) -> dict[str, np.ndarray]:
    """Share of each mode's strain energy by kind of deformation, keyed like the nodal fields.

    ``"w"``: bending (EI w''^2), ``"phi"``: torsion (GJ phi'^2), ``"delta_<surface>"``: the
    surface's hinge springs, actuators and own torsion; each (n_modes,), summing to 1. The
    measure :meth:`~aeroservo.system.aeroelastic.AeroelasticModel.label_modes` names modes by
    (for a natural mode the kinetic energy splits the same way).

    Parameters
    ----------
    model : AeroelasticModel
    shapes : ndarray (n_q, n_modes)
        Mode shapes (real or complex).
    """
    shapes = np.asarray(shapes)
    key = {"bending": "w", "torsion": "phi"}
    energy = {}
    for name, k in model.matrices.stiffness_parts.items():
        field = key.get(name) or "delta_" + name[len("flap (") : -1]
        energy[field] = np.real(np.einsum("ij,ij->j", shapes.conj(), np.asarray(k @ shapes)))
    total = sum(energy.values())
    total = np.where(total > 0, total, 1.0)
    return {k: e / total for k, e in energy.items()}


def _fields(fields: dict, j: int, surfaces: dict) -> dict[str, np.ndarray]:
    """Column j of each field (flap rotations over their surface only, NaN elsewhere)."""
    out = {}
    for key in fields:
        if key == "w" or key == "phi" or key.startswith("delta_"):
            y = np.asarray(fields[key][:, j])
            span = surfaces.get(key[len("delta_") :]) if key.startswith("delta_") else None
            out[key] = _on_surface(fields["x"], y, span)
    return out


def _share_text(shares: dict | None, j: int) -> str:
    if not shares:
        return ""
    parts = sorted(((float(v[j]), k) for k, v in shares.items()), reverse=True)
    kind = {"w": "bending", "phi": "torsion"}
    named = [f"{kind.get(k, k[len('delta_') :])} {v:.0%}" for v, k in parts if v >= 0.005]
    return "\nstrain energy: " + ", ".join(named)


def _legend(key: str, peak: float) -> str:
    name, unit, scale = _name(key)
    return f"{name} / {peak * scale:.3g} {unit}"


def _real_panel(ax, x, cols: dict) -> list:
    """Each field of a real mode divided by its peak."""
    lines = []
    for k, (key, y) in enumerate(cols.items()):
        peak = float(np.nanmax(np.abs(y))) if np.any(np.isfinite(y)) else 0.0
        if peak == 0.0:
            continue
        lines += ax.plot(x, y / peak, f"C{k}-", label=_legend(key, peak))
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_ylim(-1.08, 1.08)
    ax.set_ylabel("field / its peak [-]")
    return lines


def _reference(cols: dict, shares: dict | None, j: int) -> tuple[str, int]:
    """The field and station the phase is measured from: the peak of the field with the largest
    energy share, or (without shares) the largest value of the mode as scaled."""
    if shares:
        key = max((k for k in cols if k in shares), key=lambda k: shares[k][j])
    else:
        key = max(cols, key=lambda k: np.nanmax(np.abs(cols[k])))
    return key, int(np.nanargmax(np.abs(cols[key])))


def _complex_panels(ax_m, ax_p, x, cols: dict, shares: dict | None, j: int) -> list:
    """Magnitude (each field divided by its peak) and phase [deg] of a complex mode."""
    ref_key, i_ref = _reference(cols, shares, j)
    ref = cols[ref_key][i_ref]
    lines = []
    for k, (key, y) in enumerate(cols.items()):
        mag = np.abs(y)
        peak = float(np.nanmax(mag)) if np.any(np.isfinite(mag)) else 0.0
        if peak == 0.0:
            continue
        with np.errstate(invalid="ignore"):
            phase = np.degrees(np.angle(y / ref))
        at_peak = phase[int(np.nanargmax(mag))]
        label = f"{_legend(key, peak)}, phase {at_peak:+.0f} deg at its peak"
        lines += ax_m.plot(x, mag / peak, f"C{k}-", label=label)
        ax_p.plot(x, np.where(mag >= PHASE_FLOOR * peak, phase, np.nan), f"C{k}-")
    ax_m.set_ylim(0.0, 1.08)
    ax_m.set_ylabel("|field| / its peak [-]")
    ax_p.set_ylim(-190.0, 190.0)
    ax_p.set_yticks([-180, -90, 0, 90, 180])
    ax_p.axhline(0.0, color="0.6", lw=0.6)
    name = _name(ref_key)[0]
    ax_p.set_ylabel(f"phase [deg]\nrel. to {name}\nat x = {x[i_ref]:.3g} m", fontsize=8)
    return lines


def plot_modes(
    fields: dict,
    labels: Sequence[str],
    frequencies: Sequence[float],
    *,
    surfaces: dict | None = None,
    modes: Sequence[int] | None = None,
    title: str | None = None,
    shares: dict | None = None,
    masses: dict | None = None,
) -> Figure:
    """Panels of mode shapes along the span, one per mode (two for a complex mode).

    Each field (bending w, twist, flap rotation) is divided by its own peak over the span; the
    legend gives the peaks (in m and deg, for the mode as scaled in ``fields``); with
    ``shares``, each title lists the mode's strain energy by kind of deformation. Complex
    fields (the flutter mode) are drawn as magnitude and phase [deg] relative to the peak of
    the field with the largest energy share (without ``shares``: to the largest value of the
    mode as scaled, where ``fields`` makes the mode real); the phase is left out where a field
    is below :data:`PHASE_FLOOR` of its peak.

    Parameters
    ----------
    fields : dict
        Nodal fields (:meth:`~aeroservo.system.aeroelastic.AeroelasticModel.mode_fields`, or a
        saved result's ``modes``): ``x`` [m], ``w`` [m], ``phi`` and ``delta_<surface>`` [rad],
        each (n_nodes, n_modes).
    labels, frequencies : sequence
        Name and frequency [Hz] of each column.
    surfaces : dict, optional
        Control surface name -> (start, end) [m]: flap rotation drawn over its surface only.
    modes : sequence of int, optional
        Columns to draw (0-based; default all).
    title : str, optional
    shares : dict, optional
        ``{field: (n_columns,) array}`` of strain-energy shares (:func:`strain_energy_shares`).
    masses : dict, optional
        Concentrated mass name -> station [m]: a dotted line and a marker at each.
    """
    surfaces = surfaces or {}
    cols = list(range(fields["w"].shape[1])) if modes is None else list(modes)
    cplx = np.iscomplexobj(fields["w"])
    rows = 2 * len(cols) if cplx else len(cols)
    heights = [1.0, 0.7] * len(cols) if cplx else None
    fig = new_figure(figsize=(8.6, (2.0 if cplx else 2.3) * rows + 0.6))
    axes = np.atleast_1d(fig.subplots(rows, 1, sharex=True, height_ratios=heights))
    x = fields["x"]
    for n, j in enumerate(cols):
        col = _fields(fields, j, surfaces)
        head = f"{labels[j]}  {frequencies[j]:.4g} Hz" + _share_text(shares, j)
        if cplx:
            ax, ax_p = axes[2 * n], axes[2 * n + 1]
            lines = _complex_panels(ax, ax_p, x, col, shares, j)
            ax_p.grid(True, alpha=0.3)
        else:
            ax = axes[n]
            lines = _real_panel(ax, x, col)
        ax.set_title(head, fontsize=9)
        ax.grid(True, alpha=0.3)
        lines += _mass_marks(ax, masses or {})
        ax.legend(handles=lines, fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    axes[-1].set_xlabel("spanwise station x [m]")
    note = "each field divided by its own peak (in the legend)"
    if shares:
        note += "; the mode is named by its largest share of strain energy"
    if cplx:
        note = "magnitude: " + note + "; phase [deg] relative to the point named on the axis"
    fig.suptitle((title + "\n" if title else "") + note, fontsize=9)
    return fig


def _mass_marks(ax, masses: dict) -> list:
    """A dotted line at each concentrated mass's station, a marker on the axis, one legend
    entry for them all."""
    from matplotlib.transforms import blended_transform_factory

    if not masses:
        return []
    at_bottom = blended_transform_factory(ax.transData, ax.transAxes)
    for station in masses.values():
        ax.axvline(station, color="0.35", ls=":", lw=1.0)
        ax.plot([station], [0.0], "v", color="0.2", ms=7, transform=at_bottom, clip_on=False)
    names = ", ".join(f"{k} ({v:.3g} m)" for k, v in masses.items())
    return ax.plot([], [], "v:", color="0.2", label=f"mass: {names}")


def plot_mode_shapes(model, modes, *, n: int = 4) -> Figure:
    """The first ``n`` natural modes of a model (``modes``: :class:`NaturalModes`), with their
    strain-energy shares."""
    n = min(n, modes.shapes.shape[1])
    fields = model.mode_fields(modes.shapes[:, :n])
    surfaces = {cs.name: (cs.start, cs.end) for cs in model.wing.control_surfaces}
    shares = strain_energy_shares(model, modes.shapes[:, :n])
    masses = {pm.name: pm.station for pm in model.wing.masses}
    return plot_modes(
        fields,
        modes.labels[:n],
        modes.frequencies[:n],
        surfaces=surfaces,
        shares=shares,
        masses=masses,
    )


def animate_mode(
    fields: dict,
    j: int,
    *,
    label: str,
    frequency: float,
    semichord: float,
    elastic_axis: float,
    hinge: float | None = None,
    frames: int = 36,
):
    """Animation of one mode at the tip section over one cycle (chord line, flap drawn).

    Parameters
    ----------
    fields : dict
        Nodal fields; column ``j`` is animated as ``Re(q exp(i t))``.
    label : str
    frequency : float
        [Hz], shown in the title.
    semichord, elastic_axis : float
        Tip semichord b [m] and elastic axis a [semichords aft of mid-chord].
    hinge : float, optional
        Hinge position c [semichords]; the flap rotation of the first surface is drawn aft of
        it.
    frames : int

    Returns
    -------
    (Figure, matplotlib.animation.FuncAnimation)
    """
    from matplotlib.animation import FuncAnimation

    w = complex(fields["w"][-1, j])
    phi = complex(fields["phi"][-1, j])
    keys = [k for k in fields if k.startswith("delta_")]
    delta = complex(fields[keys[0]][-1, j]) if keys and hinge is not None else 0j
    amp = 0.25 * semichord / max(abs(w), abs(phi) * semichord, abs(delta) * semichord, 1e-12)
    fig = new_figure(figsize=(6.0, 3.6))
    ax = fig.subplots()
    b, a = semichord, elastic_axis
    lim = 1.3 * b
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-0.8 * lim, 0.8 * lim)
    ax.set_aspect("equal")
    ax.set_xlabel("chordwise [m] (leading edge left)")
    ax.set_ylabel("plunge, up [m]")
    ax.axhline(0.0, color="0.8", lw=0.8)
    ax.set_title(f"{label}  {frequency:.4g} Hz: tip section (amplitude scaled)", fontsize=9)
    (wing,) = ax.plot([], [], "C0-", lw=3)
    (flap,) = ax.plot([], [], "C2-", lw=3)
    (ea,) = ax.plot([], [], "ko", ms=4)

    def draw(k: int):
        e = np.exp(2j * np.pi * k / frames)
        h = amp * (w * e).real
        th = amp * (phi * e).real  # nose up positive
        dl = amp * (delta * e).real
        xe = a * b
        xh = b if hinge is None or not keys else hinge * b
        le = np.array([-b - xe, 0.0])
        hp = np.array([xh - xe, 0.0])
        rot = np.array([[np.cos(th), np.sin(th)], [-np.sin(th), np.cos(th)]])
        p_le, p_h = rot @ le, rot @ hp
        te_local = np.array([b - xh, 0.0])
        rot_f = np.array([[np.cos(th + dl), np.sin(th + dl)], [-np.sin(th + dl), np.cos(th + dl)]])
        p_te = p_h + rot_f @ te_local
        wing.set_data([p_le[0] + xe, p_h[0] + xe], [p_le[1] + h, p_h[1] + h])
        flap.set_data([p_h[0] + xe, p_te[0] + xe], [p_h[1] + h, p_te[1] + h])
        ea.set_data([xe], [h])
        return wing, flap, ea

    return fig, FuncAnimation(fig, draw, frames=frames, interval=50, blit=True)


def gif_writer(fields: dict, j: int, wing, *, label: str, frequency: float):
    """A writer (for :mod:`aeroservo.atomic`) of the tip-section animation of mode ``j`` of
    ``fields`` on ``wing`` (its tip semichord and elastic axis, and the hinge of a surface that
    reaches the tip), as a GIF (Pillow)."""
    from matplotlib.animation import PillowWriter

    tip = wing.segments[-1]
    cs = [c for c in wing.control_surfaces if c.end >= wing.span - 1e-9]
    with detached():  # written to a file, not shown
        _, anim = animate_mode(
            fields,
            j,
            label=label,
            frequency=frequency,
            semichord=tip.semichord,
            elastic_axis=tip.a,
            hinge=cs[0].hinge if cs else None,
        )
    return lambda p: anim.save(p, writer=PillowWriter(fps=20))
