"""Figures of loop margins at the actuator: Nyquist and broken-loop Bode diagrams of one channel,
and the margins versus airspeed (:mod:`aeroservo.design.margins`, ``margin_sweep``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .._figures import new_figure

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..design.margin_sweep import MarginSweep
    from ..design.margins import LoopMargins

__all__ = ["plot_loop_margins", "plot_margin_sweep", "BODE_RANGE_DB"]

BODE_RANGE_DB = 100.0
"""The Bode magnitude axis spans this many dB below the larger of the peak ``|L|`` and 0 dB
(a loop gain far below that does not matter to the margins); the phase is not drawn there."""


def _disk(ax, size: float, **kw) -> None:
    """The points -1/f of the balanced disk of gain-phase variations f of size alpha."""
    if not 0 < size < 2:
        return
    a, b = (2 - size) / (2 + size), (2 + size) / (2 - size)

    t = np.linspace(0, 2 * np.pi, 200)
    c, r = -(a + b) / 2, (b - a) / 2
    ax.fill(c + r * np.cos(t), r * np.sin(t), **kw)


def plot_loop_margins(
    margins: LoopMargins, control: str | None = None, title: str | None = None
) -> Figure:
    """Nyquist diagram (left, zoomed on -1), broken-loop Bode diagram and the sensitivity ``S``
    and complementary sensitivity ``T`` at the plant input (right) of one control channel, with
    its gain, phase and disk margins, the requirement and the break point.

    ``L`` is the sampled loop's return ratio ``L(exp(j omega T))`` from 0 to the Nyquist
    frequency ``pi / T`` (its mirror image, dashed, closes the Nyquist contour). The Bode
    magnitude axis spans :data:`BODE_RANGE_DB` below its peak (or 0 dB); phases in degrees.

    Parameters
    ----------
    margins : LoopMargins
    control : str, optional
        Channel (default the first).
    title : str, optional
    """
    control = control or next(iter(margins.channels))
    ch = margins.channels[control]
    req = margins.requirement
    fig = new_figure(figsize=(11.5, 7.0))
    grid = fig.add_gridspec(3, 2, width_ratios=[1.0, 1.25])
    ax_n = fig.add_subplot(grid[:, 0])
    ax_m = fig.add_subplot(grid[0, 1])
    ax_p = fig.add_subplot(grid[1, 1], sharex=ax_m)
    ax_s = fig.add_subplot(grid[2, 1], sharex=ax_m)
    L = ch.response
    f = ch.omega / (2 * np.pi)

    # Nyquist: the requirement region, the disk the loop clears, L and its mirror image
    k = 10 ** (req.gain_db / 20)
    t = np.radians(np.linspace(-req.phase_deg, req.phase_deg, 60))
    ax_n.plot(-np.cos(t), np.sin(t), color="tab:orange", lw=3, alpha=0.5)
    ax_n.plot(
        [-k, -1 / k],
        [0, 0],
        color="tab:orange",
        lw=3,
        alpha=0.5,
        label=f"requirement: {req.gain_db:g} dB, {req.phase_deg:g} deg",
    )
    _disk(
        ax_n,
        ch.disk_margin,
        color="tab:red",
        alpha=0.15,
        label=f"disk margin alpha = {ch.disk_margin:.3g}",
    )
    label = (
        rf"$L(e^{{j\omega T}})$, loop broken at {control}"
        + "\n"
        + rf"$\omega$ = 0 to $\pi/T$ (Nyquist), T = {margins.dt * 1e3:.4g} ms"
    )
    ax_n.plot(L.real, L.imag, "C0", lw=1.2, label=label)
    ax_n.plot(L.real, -L.imag, "C0", lw=0.8, ls="--", alpha=0.6, label=r"mirror ($\omega < 0$)")
    u = np.linspace(0, 2 * np.pi, 200)
    ax_n.plot(np.cos(u), np.sin(u), color="0.6", lw=0.8, ls=":")
    ax_n.plot(-1, 0, "r+", ms=12, mew=2)
    ax_n.set_xlim(-3.0, 1.5)
    ax_n.set_ylim(-2.25, 2.25)
    ax_n.set_aspect("equal")
    ax_n.set_xlabel("Re L")
    ax_n.set_ylabel("Im L")
    ax_n.grid(True, alpha=0.3)
    verdict = "stable" if ch.stable else "UNSTABLE"
    ax_n.set_title(
        f"Nyquist: {ch.open_loop_unstable} unstable open-loop poles, "
        f"{ch.encirclements:.0f} encirclements of -1 ({verdict})",
        fontsize=9,
    )
    ax_n.legend(fontsize=7, loc="lower left")

    # Bode of the return ratio
    keep = f > 0
    db = 20 * np.log10(np.maximum(np.abs(L[keep]), 1e-300))
    top = max(float(db.max()), 0.0)
    floor = max(float(db.min()), top - BODE_RANGE_DB)
    ax_m.semilogx(f[keep], db, "C0")
    ax_m.set_ylim(floor - 0.05 * (top - floor) - 1.0, top + 0.1 * (top - floor) + 1.0)
    ax_m.axhline(0, color="k", lw=0.8)
    phase = np.where(db >= floor, np.degrees(np.angle(-L[keep])), np.nan)
    ax_p.semilogx(f[keep], phase, "C0")
    ax_p.axhline(0, color="k", lw=0.8)
    marks = (
        (ch.gain_frequencies[0], f"gain reduction {ch.gain_reduction_margin_db:.3g} dB", "C3"),
        (ch.gain_frequencies[1], f"gain increase {ch.gain_margin_db:.3g} dB", "C1"),
        (ch.phase_frequency, f"phase {ch.phase_margin_deg:.3g} deg", "C2"),
        (ch.disk_frequency, f"disk alpha {ch.disk_margin:.3g}", "C4"),
    )
    for x, lab, color in marks:
        if x:
            ax_m.axvline(x, color=color, lw=0.9, ls="--", label=f"{lab} at {x:.3g} Hz")
            ax_p.axvline(x, color=color, lw=0.9, ls="--")
    ax_m.legend(fontsize=7, loc="upper right")
    ax_m.set_xlim(max(f[keep].min(), 0.05), f.max())
    ax_m.set_ylabel("|L| [dB]")
    ax_p.set_ylabel("phase of L + 180 [deg]")
    ax_p.set_yticks([-180, -90, 0, 90, 180])
    _sensitivity(ax_s, margins)
    for ax in (ax_m, ax_p, ax_s):
        ax.grid(True, which="both", alpha=0.3)
    status = "meets" if not ch.violations(req) else "MISSES"
    fig.suptitle(
        (title + "\n" if title else "")
        + f"V = {margins.speed:.4g} m/s, loop broken at {control}: {margins.break_point}"
        + (", one-sample delay" if margins.delay else "")
        + f"; {status} the requirement",
        fontsize=9,
    )
    return fig


def _sensitivity(ax, margins: LoopMargins) -> None:
    """|S| and |T| at the plant input [dB] (largest singular values) with their peaks."""
    s = margins.sensitivity
    f = s["omega"] / (2 * np.pi)
    keep = f > 0
    for key, color, name in (("S", "C0", "S = (I + L)^-1"), ("T", "C1", "T = I - S")):
        db = 20 * np.log10(np.maximum(s[key][keep], 1e-300))
        peak = s[f"peak_{key}"]
        ax.semilogx(
            f[keep],
            db,
            color,
            label=f"|{name}|, peak {peak:.3g} ({20 * np.log10(peak):.3g} dB) at "
            f"{s[f'peak_{key}_frequency']:.3g} Hz",
        )
    ax.axhline(0, color="k", lw=0.8)
    ax.set_ylim(-40, max(10.0, 20 * np.log10(max(s["peak_S"], s["peak_T"])) + 5))
    ax.set_ylabel("plant input [dB]")
    ax.set_xlabel("frequency [Hz]")
    ax.legend(fontsize=7, loc="lower left")


def plot_margin_sweep(
    sweep: MarginSweep, control: str | None = None, title: str | None = None
) -> Figure:
    """Gain (both ways), phase and disk margins of one channel versus airspeed, with the
    requirement; speeds where the loop is unstable are shaded."""
    control = control or sweep.controls[0]
    t = sweep.table_for(control)
    req = sweep.requirement
    v = sweep.speeds
    fig = new_figure(figsize=(7.5, 7.0))
    ax_g, ax_p, ax_d = fig.subplots(3, 1, sharex=True)

    def finite(a, cap):
        return np.where(np.isinf(a), np.sign(a) * cap, a)

    ax_g.plot(v, finite(t["gain_margin_db"], 40), "o-", ms=3, label="gain increase")
    ax_g.plot(v, finite(t["gain_reduction_margin_db"], 40), "s-", ms=3, label="gain reduction")
    for s in (1, -1):
        ax_g.axhline(s * req.gain_db, color="tab:orange", ls="--", lw=1)
    ax_g.set_ylabel("gain margin [dB]")
    ax_g.set_ylim(-40, 40)
    ax_g.legend(fontsize=7)
    ax_p.plot(v, finite(t["phase_margin_deg"], 180), "o-", ms=3)
    ax_p.axhline(req.phase_deg, color="tab:orange", ls="--", lw=1, label="requirement")
    ax_p.set_ylabel("phase margin [deg]")
    ax_p.set_ylim(0, 180)
    ax_p.legend(fontsize=7)
    ax_d.plot(v, t["disk_margin"], "o-", ms=3)
    if req.disk_alpha is not None:
        ax_d.axhline(req.disk_alpha, color="tab:orange", ls="--", lw=1)
    ax_d.set_ylabel("disk margin alpha [-]")
    ax_d.set_xlabel("airspeed V [m/s]")
    for ax in (ax_g, ax_p, ax_d):
        ax.grid(True, alpha=0.3)
        for i in np.flatnonzero(~t["stable"]):
            lo = v[max(i - 1, 0)] if i else v[0]
            hi = v[min(i + 1, v.size - 1)]
            ax.axvspan(0.5 * (lo + v[i]), 0.5 * (hi + v[i]), color="0.85", lw=0)
        if sweep.reference_speed is not None:
            ax.axvline(sweep.reference_speed, color="g", ls="--", lw=1)
    meets = t["meets"]
    note = (
        "requirement met at every speed"
        if meets.all()
        else f"requirement MISSED at {np.count_nonzero(~meets)} of {meets.size} speeds"
    )
    fig.suptitle(
        (title + "\n" if title else "")
        + f"margins at {control} (controller a black box) versus airspeed: {note}\n"
        "(grey: closed loop unstable; green: design speed; infinite margins at the axis limits)",
        fontsize=9,
    )
    return fig
