"""Figures: V-g / V-f diagrams, root locus, mode shapes.

Functions return :class:`matplotlib.figure.Figure` objects built without ``pyplot`` (no GUI
backend needed; they display inline in notebooks and save with ``fig.savefig``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from .stability.result import FlutterResult
    from .system.aeroelastic import AeroelasticModel, NaturalModes

__all__ = ["plot_vg", "plot_root_locus", "plot_mode_shapes"]


def _figure(**kw) -> Figure:
    from matplotlib.figure import Figure

    return Figure(layout="constrained", **kw)


def plot_vg(result: FlutterResult, *, title: str | None = None) -> Figure:
    """V-f (top) and V-g (bottom) diagrams of the tracked modes, flutter point marked.

    ``g = -2 zeta`` (positive: unstable). Divergence, when inside the range, is a dashed line.
    """
    fig = _figure(figsize=(7.0, 6.5))
    ax_f, ax_g = fig.subplots(2, 1, sharex=True)
    V = result.speeds
    f = result.frequencies
    g = -2.0 * result.damping_ratio
    for j, lab in enumerate(result.mode_labels):
        (line,) = ax_f.plot(V, f[:, j], lw=1.4, label=lab)
        ax_g.plot(V, g[:, j], lw=1.4, color=line.get_color())
    ax_g.axhline(0.0, color="k", lw=0.8)
    for c in result.crossings:
        marker = "o" if c.kind == "onset" else ("s" if c.kind == "recovery" else "D")
        ax_g.plot(c.speed, 0.0, marker, color="k", ms=6, mfc="none" if c.kind != "onset" else "r")
        ax_f.plot(
            c.speed, c.frequency, marker, color="k", ms=6, mfc="none" if c.kind != "onset" else "r"
        )
    fl = result.flutter
    if fl is not None:
        ax_g.annotate(
            f"flutter {fl.speed:.4g} m/s\n{fl.frequency:.4g} Hz",
            (fl.speed, 0.0),
            xytext=(10, 25),
            textcoords="offset points",
            arrowprops={"arrowstyle": "->"},
        )
    if result.divergence_speed is not None and result.divergence_speed <= V[-1]:
        for ax in (ax_f, ax_g):
            ax.axvline(result.divergence_speed, color="k", ls="--", lw=0.8)
        ax_f.text(result.divergence_speed, ax_f.get_ylim()[1], " divergence", va="top", fontsize=8)
    ax_f.set_ylabel("frequency [Hz]")
    ax_g.set_ylabel(r"$g = -2\zeta$ [-]  (> 0 unstable)")
    ax_g.set_xlabel("airspeed V [m/s]")
    ax_f.legend(fontsize=8, ncol=2)
    for ax in (ax_f, ax_g):
        ax.grid(True, alpha=0.3)
    lo = np.nanmin(g)
    ax_g.set_ylim(max(lo, -1.0) * 1.05, max(0.1, np.nanmax(g) * 1.1))
    fig.suptitle(title or f"V-g / V-f, density {result.density:g} kg/m$^3$")
    return fig


def plot_root_locus(result: FlutterResult, *, title: str | None = None) -> Figure:
    """Tracked eigenvalues in the complex plane as speed increases (colour = speed)."""
    fig = _figure(figsize=(6.5, 5.0))
    ax = fig.subplots()
    V = result.speeds
    for j, lab in enumerate(result.mode_labels):
        lam = result.eigenvalues[:, j]
        ax.plot(lam.real, lam.imag, lw=0.8, color="0.6")
        sc = ax.scatter(lam.real, lam.imag, c=V, s=10, cmap="viridis")
        ax.annotate(
            lab, (lam.real[0], lam.imag[0]), fontsize=7, xytext=(3, 3), textcoords="offset points"
        )
    fig.colorbar(sc, ax=ax, label="airspeed V [m/s]")
    ax.axvline(0.0, color="k", lw=0.8)
    ax.set_xlabel(r"Re $\lambda$ [1/s]")
    ax.set_ylabel(r"Im $\lambda$ [rad/s]")
    ax.grid(True, alpha=0.3)
    fig.suptitle(title or "root locus versus airspeed")
    return fig


def plot_mode_shapes(model: AeroelasticModel, modes: NaturalModes, *, n: int = 4) -> Figure:
    """Bending w, twist phi and flap rotations of the first ``n`` natural modes along the span."""
    n = min(n, modes.shapes.shape[1])
    fig = _figure(figsize=(7.0, 2.2 * n))
    axes = np.atleast_1d(fig.subplots(n, 1, sharex=True))
    for j, ax in enumerate(axes):
        fld = model.nodal_fields(modes.shapes[:, j])
        scale = max(np.max(np.abs(fld["w"])), 1e-30)
        ax.plot(fld["x"], fld["w"] / scale, label="w (normalized)")
        ax2 = ax.twinx()
        ax2.plot(fld["x"], np.degrees(fld["phi"]) / scale, "C1", label=r"$\phi$ [deg per unit w]")
        for k, key in enumerate(k for k in fld if k.startswith("delta_")):
            ax2.plot(fld["x"], np.degrees(fld[key]) / scale, f"C{k + 2}--", label=key)
        ax.set_title(f"{modes.labels[j]}  {modes.frequencies[j]:.4g} Hz", fontsize=9)
        ax.set_ylabel("w")
        ax2.set_ylabel("rotation [deg]")
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("spanwise station x [m]")
    return fig
