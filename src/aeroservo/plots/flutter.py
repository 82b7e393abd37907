"""Figures of open-loop results: V-g / V-f diagrams, root locus, mode shapes, flutter envelope.

Functions return :class:`matplotlib.figure.Figure` objects built without ``pyplot`` (no GUI
backend needed; they display inline in notebooks and save with ``fig.savefig``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..stability.result import FlutterResult
    from ..system.aeroelastic import AeroelasticModel, NaturalModes

__all__ = ["plot_vg", "plot_root_locus", "plot_mode_shapes", "plot_envelope"]


def _figure(**kw) -> Figure:
    from matplotlib.figure import Figure

    return Figure(layout="constrained", **kw)


def plot_vg(
    result: FlutterResult,
    *,
    title: str | None = None,
    g_required: float | None = None,
    units: str = "si",
) -> Figure:
    """V-f (top) and V-g (bottom) diagrams of the tracked modes, flutter point marked.

    ``g = -2 zeta`` (positive: unstable). Divergence, when inside the range, is a dashed line.

    Parameters
    ----------
    result : FlutterResult
    title : str, optional
        First title line (the flight condition and damping model are added below it).
    g_required : float, optional
        Required damping (e.g. 0.03): the line ``g = -g_required`` that every branch must stay
        below. The branches are the total damping of the model (its structural damping
        included): apply the requirement to the undamped model's curves, as is usual.
    units : {"si", "knots"}
        Speed axis in m/s or knots (TAS).
    """
    from ..aero.atmosphere import KNOT

    scale = 1 / KNOT if units == "knots" else 1.0
    fig = _figure(figsize=(7.0, 6.5))
    ax_f, ax_g = fig.subplots(2, 1, sharex=True)
    V = result.speeds * scale
    f = result.frequencies
    g = -2.0 * result.damping_ratio
    for j, lab in enumerate(result.mode_labels):
        (line,) = ax_f.plot(V, f[:, j], lw=1.4, label=lab)
        ax_g.plot(V, g[:, j], lw=1.4, color=line.get_color())
    ax_g.axhline(0.0, color="k", lw=0.8)
    if g_required is not None:
        label = f"g = -{g_required:g} (required damping {g_required:g})"
        ax_g.axhline(-g_required, color="r", lw=0.9, ls="--", label=label)
        ax_g.legend(fontsize=8, loc="lower left")
    for c in result.crossings:
        marker = "o" if c.kind == "onset" else ("s" if c.kind == "recovery" else "D")
        mfc = "none" if c.kind != "onset" else "r"
        ax_g.plot(c.speed * scale, 0.0, marker, color="k", ms=6, mfc=mfc)
        ax_f.plot(c.speed * scale, c.frequency, marker, color="k", ms=6, mfc=mfc)
    fl = result.flutter
    if fl is not None:
        unit = "kt" if units == "knots" else "m/s"
        ax_g.annotate(
            f"flutter {fl.speed * scale:.4g} {unit}\n{fl.frequency:.4g} Hz",
            (fl.speed * scale, 0.0),
            xytext=(10, 25),
            textcoords="offset points",
            arrowprops={"arrowstyle": "->"},
        )
    vd = None if result.divergence_speed is None else result.divergence_speed * scale
    if vd is not None and vd <= V[-1]:
        for ax in (ax_f, ax_g):
            ax.axvline(vd, color="k", ls="--", lw=0.8)
        ax_f.text(
            vd, 0.98, " divergence", va="top", fontsize=8, transform=ax_f.get_xaxis_transform()
        )
    ax_f.set_ylabel("frequency [Hz]")
    ax_g.set_ylabel(r"$g = -2\zeta$ [-]  (> 0 unstable)")
    ax_g.set_xlabel("true airspeed V [kt]" if units == "knots" else "true airspeed V [m/s]")
    ax_f.legend(fontsize=8, ncol=2)
    for ax in (ax_f, ax_g):
        ax.grid(True, alpha=0.3)
    lo = min(np.nanmin(g), -(g_required or 0.0))
    ax_g.set_ylim(max(lo, -1.0) * 1.05, max(0.1, np.nanmax(g) * 1.1))
    condition = result.condition_text().replace("; ", "\n", 1)
    fig.suptitle((title + "\n" if title else "V-g / V-f\n") + condition, fontsize=9)

    return fig


def plot_envelope(envelope, *, units: str = "si", x: str = "eas") -> Figure:
    """Flutter clearance: altitude against EAS (or Mach).

    The flutter and divergence boundaries, the design envelope ``min(V_D, M_D)`` and the margin
    line (``margin x`` envelope), the points that fail the margin marked with red crosses.

    Parameters
    ----------
    envelope : Envelope
        From :func:`aeroservo.studies.envelope.flutter_envelope`.
    units : {"si", "knots"}
        EAS axis in m/s or knots.
    x : {"eas", "mach"}
        Horizontal axis.
    """
    from ..aero.atmosphere import KNOT

    if x not in ("eas", "mach"):
        from ..errors import InputError

        raise InputError(f"x = {x!r}: allowed values are 'eas', 'mach'")
    fig = _figure(figsize=(6.5, 5.5))
    ax = fig.subplots()
    h = envelope.altitudes / 1000.0
    scale = 1 / KNOT if units == "knots" else 1.0
    a = envelope.column("speed_of_sound")
    sig = np.sqrt(envelope.column("density") / 1.225)

    def axis(eas):  # an EAS column on the chosen axis
        return eas * scale if x == "eas" else eas / (sig * a)

    flutter = axis(envelope.column("flutter_eas"))
    div = axis(envelope.column("divergence_eas"))
    ax.plot(
        flutter,
        h,
        "o-",
        color="C3",
        label="flutter (matched)" if envelope.compressibility else "flutter",
    )
    if np.isfinite(div).any():
        ax.plot(div, h, "s--", color="C4", label="divergence")
    searched = axis(envelope.column("searched_eas"))
    none = ~np.isfinite(flutter)
    if none.any():
        ax.plot(searched[none], h[none], ">", color="C3", mfc="none", label="no flutter below")
    if envelope.envelope:  # on a fine altitude grid: the V_D / M_D knee is drawn where it is
        hf = np.linspace(envelope.altitudes.min(), envelope.altitudes.max(), 200)
        env_f, sig_f, a_f = envelope.envelope_line(hf)
        line = env_f * scale if x == "eas" else env_f / (sig_f * a_f)
        ax.plot(line, hf / 1000.0, "k-", lw=1.5, label="design envelope (V_D / M_D)")
        ax.plot(
            envelope.margin * line,
            hf / 1000.0,
            "k--",
            lw=1.0,
            label=f"{envelope.margin:g} x envelope",
        )
        bad = np.array([p.margin_ok is False for p in envelope.points])
        if bad.any():
            pts = np.where(np.isfinite(flutter), flutter, searched)
            ax.plot(pts[bad], h[bad], "x", color="r", ms=11, mew=2.5, label="fails the margin")
    unit = "kt" if units == "knots" else "m/s"
    ax.set_xlabel(f"equivalent airspeed [{unit}]" if x == "eas" else "Mach number [-]")
    ax.set_ylabel("altitude [km] (ISA, geopotential)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    comp = {"prandtl-glauert": "Prandtl-Glauert"}.get(envelope.compressibility, "incompressible")
    ax.set_title(
        f"{envelope.wing}: flutter envelope ({comp}; structural damping {envelope.damping})",
        fontsize=9,
    )
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
