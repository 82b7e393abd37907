"""Figures of open-loop results: V-g / V-f diagrams, root locus, mode shapes, flutter envelope.

Functions return :class:`matplotlib.figure.Figure` objects made by
:func:`aeroservo._figures.new_figure` (the current pyplot figure when pyplot is in use, shown
once in a notebook; detached otherwise).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from .._figures import new_figure
from ..errors import check_quantity

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..stability.result import FlutterResult

__all__ = ["plot_vg", "plot_root_locus", "plot_envelope", "select_modes"]


AUTO_FMAX = 3.0
"""``fmax="auto"``: modes up to this many times the highest crossing frequency (or, without a
crossing, the second mode's frequency at rest) are drawn."""


def auto_fmax(result: FlutterResult) -> float:
    """The frequency [Hz] up to which ``fmax="auto"`` draws modes."""
    f_cross = [c.frequency for c in result.crossings if c.frequency > 0]
    f0 = np.sort(result.frequencies[0][np.isfinite(result.frequencies[0])])
    ref = max(f_cross) if f_cross else (f0[min(1, f0.size - 1)] if f0.size else np.inf)
    return AUTO_FMAX * float(ref)


def select_modes(
    result: FlutterResult, fmax: float | str | None = None, modes: Sequence[int] | None = None
) -> list[int]:
    """Indices of the branches to draw: ``modes`` (1-based), or those whose frequency at the
    start of the sweep is at most ``fmax`` [Hz] (``"auto"``: :func:`auto_fmax`), or all."""
    n = len(result.mode_labels)
    if isinstance(fmax, str):
        if fmax != "auto":
            from ..errors import InputError

            raise InputError(f"fmax = {fmax!r}: a frequency [Hz], 'auto' or None")
        fmax = auto_fmax(result)
    if modes is not None:
        bad = [m for m in modes if not 1 <= int(m) <= n]
        if bad:
            from ..errors import InputError

            raise InputError(f"modes = {list(modes)}: the sweep has modes 1 to {n}")
        return [int(m) - 1 for m in modes]
    if fmax is not None:
        f0 = result.frequencies[0]
        keep = [j for j in range(n) if not f0[j] > fmax]  # NaN kept
        if result.flutter is not None and result.flutter.mode not in keep:
            keep.append(result.flutter.mode)  # the flutter branch is always drawn
        return sorted(keep)
    return list(range(n))


def _oscillatory(lam: np.ndarray) -> np.ndarray:
    return np.isfinite(lam) & (np.abs(lam.imag) > 1e-7 * np.abs(lam))


def plot_vg(
    result: FlutterResult,
    *,
    title: str | None = None,
    g_required: float | None = None,
    units: str = "si",
    eas: bool = False,
    fmax: float | str | None = "auto",
    modes: Sequence[int] | None = None,
    pk: FlutterResult | None = None,
) -> Figure:
    """V-f (top) and V-g (bottom) diagrams of the tracked modes, flutter point marked.

    ``g = -2 zeta`` (positive: unstable). Divergence, when inside the range, is a dashed
    vertical line labelled with its speed; it is marked at 0 Hz only where a drawn branch is
    overdamped there (a real root through zero), never on the V-g panel (a real root has no g).
    Where a branch is overdamped (a pair of real roots) it is drawn dotted at 0 Hz on the V-f
    panel (legend "overdamped" only then) and left out of the V-g panel; the line is broken
    there, so a branch that becomes oscillatory again is not joined to its earlier stretch.
    Crossings are marked on drawn branches only. Near-critical branches (a damping ratio that
    comes within :data:`aeroservo.stability.near_critical.NEAR_ZETA` of zero without crossing)
    are shaded over their speed range and marked at their minimum. The damping axis spans every
    drawn point; the legend sits outside the panels.

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
        Speed axis in m/s or knots.
    eas : bool
        Equivalent instead of true airspeed on the speed axis.
    fmax : float, "auto" or None
        Draw only the modes whose frequency at the start of the sweep is at most ``fmax`` [Hz]
        (the flutter mode is always drawn); ``"auto"`` (default): :data:`AUTO_FMAX` x the
        highest crossing frequency; None: every mode. The legend says how many are left out.
    modes : sequence of int, optional
        Draw only these modes (1-based, as in the table); overrides ``fmax``.
    pk : FlutterResult, optional
        A p-k sweep of the same wing, drawn as crosses (black: its flutter point).
    """
    from ..aero.atmosphere import KNOT, RHO0

    if units not in ("si", "knots"):
        from ..errors import InputError

        raise InputError(f"units = {units!r}: allowed values are 'si', 'knots'")
    scale = (1 / KNOT if units == "knots" else 1.0) * (
        np.sqrt(result.density / RHO0) if eas else 1.0
    )
    fig = new_figure(figsize=(8.2, 6.5))
    ax_f, ax_g = fig.subplots(2, 1, sharex=True)
    V = result.speeds * scale
    f = result.frequencies
    g = -2.0 * result.damping_ratio
    drawn_g = [np.zeros(1)]
    drawn = select_modes(result, fmax, modes)
    overdamped = np.zeros(result.eigenvalues.shape, dtype=bool)  # drawn at 0 Hz
    for j in drawn:
        lam = result.eigenvalues[:, j]
        osc = _oscillatory(lam)
        lab = f"{j + 1}: {result.mode_labels[j]}"
        (line,) = ax_f.plot(V, np.where(osc, f[:, j], np.nan), lw=1.4, label=lab)
        ax_g.plot(V, np.where(osc, g[:, j], np.nan), lw=1.4, color=line.get_color())
        real = np.isfinite(lam) & ~osc
        if real.any():
            ax_f.plot(V, np.where(real, 0.0, np.nan), ":", lw=2.0, color=line.get_color())
            overdamped[:, j] = real
        drawn_g.append(g[osc, j])
    if pk is not None:
        same = len(pk.mode_labels) == len(result.mode_labels)
        pk_drawn = drawn if same else select_modes(pk, fmax, modes)
        pk_osc = _oscillatory(pk.eigenvalues)
        pk_osc[:, [j for j in range(pk_osc.shape[1]) if j not in pk_drawn]] = False
        Vp = np.broadcast_to(pk.speeds[:, None] * scale, pk.eigenvalues.shape)
        gp = -2.0 * pk.damping_ratio
        ax_f.plot(Vp[pk_osc], pk.frequencies[pk_osc], "x", color="0.35", ms=4, label="p-k")
        ax_g.plot(Vp[pk_osc], gp[pk_osc], "x", color="0.35", ms=4)
        drawn_g.append(gp[pk_osc])
        if pk.flutter is not None:
            fp = pk.flutter
            ax_g.plot(fp.speed * scale, 0.0, "X", color="k", ms=8, label="p-k flutter")
            ax_f.plot(fp.speed * scale, fp.frequency, "X", color="k", ms=8)
    if overdamped.any():
        ax_f.plot([], [], ":", color="0.4", lw=2.0, label="overdamped (real roots)")
    left_out = len(result.mode_labels) - len(drawn)
    if left_out:
        ax_f.plot([], [], " ", label=f"{left_out} more mode{'s' * (left_out > 1)} not drawn")
    ax_g.axhline(0.0, color="k", lw=0.8)
    if g_required is not None:
        check_quantity("g_required", g_required, "structural_g")
        label = f"g = -{g_required:g} (required damping)"
        ax_g.axhline(-g_required, color="r", lw=0.9, ls="--", label=label)
    for c in result.crossings:
        if c.mode not in drawn:
            continue
        if c.kind == "divergence":  # at 0 Hz only on a drawn overdamped stretch
            k = int(np.argmin(np.abs(result.speeds - c.speed)))
            if overdamped[k, c.mode]:
                ax_f.plot(c.speed * scale, 0.0, "D", color="k", ms=6, mfc="none")
            continue
        marker, mfc = ("o", "r") if c.kind == "onset" else ("s", "none")
        ax_g.plot(c.speed * scale, 0.0, marker, color="k", ms=6, mfc=mfc)
        ax_f.plot(c.speed * scale, c.frequency, marker, color="k", ms=6, mfc=mfc)
    fl = result.flutter
    unit = ("kt" if units == "knots" else "m/s") + (" EAS" if eas else "")
    for n in getattr(result, "near_critical", ()):  # stable, but within the threshold
        lo, hi = (v * scale for v in n.speed_range)
        label = (
            f"near-critical {lo:.4g}-{hi:.4g} {unit}\n{n.frequency:.3g} Hz, "
            f"g up to {-2 * n.damping_ratio:.1e}"
        )
        for ax in (ax_f, ax_g):
            ax.axvspan(lo, hi, color="tab:orange", alpha=0.18, lw=0)
        ax_g.plot(n.speed * scale, -2 * n.damping_ratio, "v", color="tab:orange", ms=7, label=label)
        ax_f.plot(n.speed * scale, n.frequency, "v", color="tab:orange", ms=7)
    if fl is not None:
        ax_g.plot([], [], "o", color="k", mfc="r", label=f"flutter {fl.speed * scale:.4g} {unit}")
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
        right = vd > V[0] + 0.6 * (V[-1] - V[0])  # the label on the side with room
        ax_f.text(
            vd,
            0.98,
            f" divergence \n V_div = {vd:.4g} {unit} ",
            va="top",
            ha="right" if right else "left",
            fontsize=8,
            transform=ax_f.get_xaxis_transform(),
        )
    ax_f.set_ylabel("frequency [Hz]")
    ax_g.set_ylabel(r"$g = -2\zeta$ [-]  (> 0 unstable)")
    speed = ("equivalent" if eas else "true") + " airspeed"
    ax_g.set_xlabel(f"{speed} [{'kt' if units == 'knots' else 'm/s'}]")
    for ax in (ax_f, ax_g):
        ax.grid(True, alpha=0.3)
    gs = np.concatenate([d[np.isfinite(d)] for d in drawn_g] + [[-(g_required or 0.0)]])
    lo, hi = float(gs.min()), float(gs.max())
    pad = 0.06 * max(hi - lo, 1e-3)
    ax_g.set_ylim(lo - pad, hi + pad)
    ax_f.set_ylim(bottom=-0.02 * max(ax_f.get_ylim()[1], 1.0))
    handles = [h for ax in (ax_f, ax_g) for h in ax.get_legend_handles_labels()[0]]
    labels = [t for ax in (ax_f, ax_g) for t in ax.get_legend_handles_labels()[1]]
    fig.legend(handles, labels, loc="outside right upper", fontsize=8)
    condition = result.condition_text().replace("; ", "\n", 1)
    ax_f.set_title((title + "\n" if title else "V-g / V-f\n") + condition, fontsize=9)
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
    fig = new_figure(figsize=(6.5, 5.5))
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
    comp = {"prandtl-glauert": "Prandtl-Glauert", "dlm": "doublet lattice"}.get(
        envelope.compressibility, "incompressible"
    )
    ax.set_title(
        f"{envelope.wing}: flutter envelope ({comp}; structural damping {envelope.damping})",
        fontsize=9,
    )
    return fig


def plot_root_locus(
    result: FlutterResult,
    *,
    title: str | None = None,
    fmax: float | None = None,
    modes: Sequence[int] | None = None,
    units: str = "si",
) -> Figure:
    """Tracked eigenvalues in the complex plane as speed increases (colour = speed);
    ``fmax``, ``modes`` and ``units`` as in :func:`plot_vg`."""
    from ..aero.atmosphere import KNOT

    scale = 1 / KNOT if units == "knots" else 1.0
    fig = new_figure(figsize=(6.5, 5.0))
    ax = fig.subplots()
    V = result.speeds * scale
    sc = None
    for j in select_modes(result, fmax, modes):
        lam = result.eigenvalues[:, j]
        ax.plot(lam.real, lam.imag, lw=0.8, color="0.6")
        sc = ax.scatter(lam.real, lam.imag, c=V, s=10, cmap="viridis")
        ax.annotate(
            f"{j + 1}: {result.mode_labels[j]}",
            (lam.real[0], lam.imag[0]),
            fontsize=7,
            xytext=(3, 3),
            textcoords="offset points",
        )
    if sc is not None:
        unit = "kt" if units == "knots" else "m/s"
        fig.colorbar(sc, ax=ax, label=f"true airspeed V [{unit}]")
    ax.axvline(0.0, color="k", lw=0.8)
    ax.set_xlabel(r"Re $\lambda$ [1/s]")
    ax.set_ylabel(r"Im $\lambda$ [rad/s]")
    ax.grid(True, alpha=0.3)
    fig.suptitle(title or "root locus versus airspeed")
    return fig
