"""Mode-shape figures and animations: natural modes and the flutter mode along the span.

A mode is given as nodal fields (:meth:`aeroservo.system.aeroelastic.AeroelasticModel.
nodal_fields`): bending ``w`` [m], twist ``phi`` [rad] and flap rotations ``delta_<surface>``
[rad] at the stations ``x`` [m], normalised so that the largest deflection or rotation is 1
(in m or rad). Bending is drawn in metres on the left axis, twist and flap rotation in degrees
on the right one; a flap rotation only over its surface.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["plot_mode_shapes", "plot_modes", "animate_mode", "gif_writer"]


def _on_surface(x: np.ndarray, y: np.ndarray, span: Sequence[float] | None) -> np.ndarray:
    if span is None:
        return y
    inside = (x >= span[0] - 1e-9) & (x <= span[1] + 1e-9)
    return np.where(inside, y, np.nan)


def _align_zero(ax1, ax2) -> None:
    """Put zero at the same height on both axes of a panel (extending a lower limit)."""
    lims = [[min(a.get_ylim()[0], 0.0), max(a.get_ylim()[1], 0.0)] for a in (ax1, ax2)]
    frac = [-lo / (hi - lo) if hi > lo else 0.5 for lo, hi in lims]
    f = max(frac)
    if f > 0.95:
        return
    for ax, (lo, hi) in zip((ax1, ax2), lims, strict=True):
        ax.set_ylim(min(lo, -f / (1 - f) * hi), hi)


def _panel(ax, x, fields: dict, j: int, surfaces: dict, part: str, style: str) -> list:
    """Draw one mode (column j, real or imaginary part) on ``ax`` and a twin axis."""
    get = np.real if part == "real" else np.imag
    suffix = "" if part == "real" else " (imag.)"
    ax2 = ax.right if hasattr(ax, "right") else ax.twinx()
    ax.right = ax2
    lines = ax.plot(x, get(fields["w"][:, j]), "C0" + style, label="bending w [m]" + suffix)
    lines += ax2.plot(
        x, np.degrees(get(fields["phi"][:, j])), "C1" + style, label="twist [deg]" + suffix
    )
    for k, key in enumerate(k for k in fields if k.startswith("delta_")):
        name = key[len("delta_") :]
        y = _on_surface(x, np.degrees(get(fields[key][:, j])), surfaces.get(name))
        lines += ax2.plot(x, y, f"C{k + 2}" + style, label=f"{name} rotation [deg]" + suffix)
    ax.set_ylabel("w [m]")
    ax2.set_ylabel("rotation [deg]")
    return lines


def plot_modes(
    fields: dict,
    labels: Sequence[str],
    frequencies: Sequence[float],
    *,
    surfaces: dict | None = None,
    modes: Sequence[int] | None = None,
    title: str | None = None,
) -> Figure:
    """Panels of mode shapes along the span, one per mode.

    Parameters
    ----------
    fields : dict
        Nodal fields (:meth:`~aeroservo.system.aeroelastic.AeroelasticModel.mode_fields`, or a
        saved result's ``modes``); complex fields (the
        flutter mode) are drawn as real (solid) and imaginary (dashed) parts.
    labels, frequencies : sequence
        Name and frequency [Hz] of each column.
    surfaces : dict, optional
        Control surface name -> (start, end) [m]: flap rotation drawn over its surface only.
    modes : sequence of int, optional
        Columns to draw (0-based; default all).
    title : str, optional
    """
    from ..plots.flutter import _figure

    surfaces = surfaces or {}
    cols = list(range(fields["w"].shape[1])) if modes is None else list(modes)
    fig = _figure(figsize=(8.2, 2.3 * len(cols) + 0.6))
    axes = np.atleast_1d(fig.subplots(len(cols), 1, sharex=True))
    x = fields["x"]
    for ax, j in zip(axes, cols, strict=True):
        lines = _panel(ax, x, fields, j, surfaces, "real", "-")
        if np.iscomplexobj(fields["w"]):
            lines += _panel(ax, x, fields, j, surfaces, "imag", "--")
        _align_zero(ax, ax.right)
        ax.set_title(f"{labels[j]}  {frequencies[j]:.4g} Hz", fontsize=9)
        ax.grid(True, alpha=0.3)
        ax.legend(handles=lines, fontsize=7, loc="upper left", bbox_to_anchor=(1.12, 1.0))
    axes[-1].set_xlabel("spanwise station x [m]")
    fig.suptitle(
        (title + "\n" if title else "")
        + "normalised: largest deflection or rotation = 1 (m or rad)",
        fontsize=9,
    )
    return fig


def plot_mode_shapes(model, modes, *, n: int = 4) -> Figure:
    """The first ``n`` natural modes of a model (``modes``: :class:`NaturalModes`)."""
    n = min(n, modes.shapes.shape[1])
    fields = model.mode_fields(modes.shapes[:, :n])
    surfaces = {cs.name: (cs.start, cs.end) for cs in model.wing.control_surfaces}
    return plot_modes(fields, modes.labels[:n], modes.frequencies[:n], surfaces=surfaces)


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

    from ..plots.flutter import _figure

    w = complex(fields["w"][-1, j])
    phi = complex(fields["phi"][-1, j])
    keys = [k for k in fields if k.startswith("delta_")]
    delta = complex(fields[keys[0]][-1, j]) if keys and hinge is not None else 0j
    amp = 0.25 * semichord / max(abs(w), abs(phi) * semichord, abs(delta) * semichord, 1e-12)
    fig = _figure(figsize=(6.0, 3.6))
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
