"""Figures of a limit-cycle study: the bifurcation diagram and example time histories."""

from __future__ import annotations

import numpy as np

from ..._figures import new_figure
from ...errors import InputError
from ...simulate.lco_detect import SUSTAINED

__all__ = ["plot_bifurcation", "plot_histories"]

_MARK = {
    "quasi-periodic": ("D", None),
    "chaotic": ("*", None),
    "decay": ("o", "none"),
    "growing": ("v", "none"),
    "unsettled": ("^", "none"),
    "undecided": ("s", "none"),
}
_SIZED = (*SUSTAINED, "growing", "unsettled", "undecided")
"""Verdicts drawn at their amplitude."""


def _scale(result, per_gap: bool) -> tuple[float, str]:
    gap = result.gap
    if per_gap and gap:
        return 1.0 / gap, "LCO amplitude / total gap [-]"
    return float(np.degrees(1.0)), "LCO amplitude [deg]"


def plot_bifurcation(result, ax=None, *, per_gap: bool = True, describing: bool = True):
    """LCO amplitude (half peak-to-peak of the reference rotation) against airspeed.

    Points marched from rest with each initial rotation are dots where they settled in a limit
    cycle (colour: initial rotation), diamonds in a quasi-periodic and stars in a chaotic
    oscillation; the up and down sweeps (continuation) are lines with ``>`` and ``<`` markers;
    marches that decayed are open circles at zero, that diverged crosses at the top, that were
    unsettled or undecided open triangles and squares, and that were still growing (not
    settled) open down-triangles, at their amplitude. The describing-function branches are
    drawn over it (solid stable, dashed unstable).
    """
    if ax is None:
        ax = new_figure(figsize=(10.0, 5.0)).add_subplot()
    k, ylabel = _scale(result, per_gap)
    rows = result.rows
    finite = [
        r["amplitude"] * k for r in rows if r["kind"] in _SIZED and np.isfinite(r["amplitude"])
    ]
    top = 1.15 * max(finite + [1.0 if per_gap and result.gap else 1e-3])
    amps = sorted({r["initial"] for r in rows if r["start"] == "point"})
    cmap = __import__("matplotlib").colormaps["viridis"]
    for i, a0 in enumerate(amps):
        col = cmap(0.15 + 0.7 * i / max(len(amps) - 1, 1))
        pts = [r for r in rows if r["start"] == "point" and r["initial"] == a0]
        lab = f"from rest, initial {a0 * k:.3g}" + (" x gap" if per_gap and result.gap else " deg")
        lco = [r for r in pts if r["kind"] == "lco"]
        ax.plot(
            [r["speed"] for r in lco], [r["amplitude"] * k for r in lco], "o", color=col,
            ms=6, label=lab, zorder=3,
        )  # fmt: skip
        for kind, (m, face) in _MARK.items():
            sel = [r for r in pts if r["kind"] == kind]
            y = [0.0 if kind == "decay" else r["amplitude"] * k for r in sel]
            ms = 9 if m == "*" else 5
            ax.plot([r["speed"] for r in sel], y, m, color=col, mfc=face or col, ms=ms, zorder=3)
        div = [r for r in pts if r["kind"] in ("divergence", "failed")]
        ax.plot([r["speed"] for r in div], [top] * len(div), "x", color=col, ms=7, zorder=3)
    for start, m, col in (("up", ">", "tab:red"), ("down", "<", "tab:blue")):
        sw = sorted((r for r in rows if r["start"] == start), key=lambda r: r["speed"])
        if not sw:
            continue
        y = [
            top if r["kind"] in ("divergence", "failed")
            else 0.0 if r["kind"] == "decay" else r["amplitude"] * k
            for r in sw
        ]  # fmt: skip
        ax.plot(
            [r["speed"] for r in sw], y, "-", marker=m, color=col, lw=1.0, ms=4, alpha=0.8,
            label=f"speed swept {start} (continuation)", zorder=2,
        )  # fmt: skip
    if describing and result.branches is not None and len(result.branches.speed):
        from ...plots.lco import plot_describing

        plot_describing(result.branches, ax=ax, per_gap=per_gap)
        ax.set_yscale("linear")
    ax.plot([], [], "D", color="grey", label="quasi-periodic (sustained)")
    ax.plot([], [], "*", color="grey", ms=9, label="chaotic (sustained)")
    ax.plot([], [], "o", color="grey", mfc="none", label="decays (drawn at 0)")
    ax.plot([], [], "v", color="grey", mfc="none", label="still growing (not settled)")
    ax.plot([], [], "^", color="grey", mfc="none", label="unsettled")
    ax.plot([], [], "x", color="grey", label="diverges (drawn at the top)")
    ax.set_ylim(-0.03 * top, 1.05 * top)
    v = result.settings.get("speeds", [r["speed"] for r in rows])
    pad = 0.03 * (max(v) - min(v) + 1e-9)
    ax.set_xlim(min(v) - pad, max(v) + pad)
    ax.set_xlabel("airspeed [m/s]")
    ax.set_ylabel(ylabel)
    s = result.settings
    import textwrap

    title = (
        f"{s.get('scenario') or s.get('name', '')}\n{s.get('reference', '')}: "
        f"{'; '.join(s.get('laws', [])[:1])}; {s.get('controller', '')}"
    )
    ax.set_title("\n".join(textwrap.fill(line, 90) for line in title.split("\n")), fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return ax


def plot_histories(result, speeds=None, *, n: int = 4, signals=None):
    """The end of the marches at a few speeds: the reference rotation (per gap) and its
    hinge moment, one row per speed (default: up to ``n`` speeds where a sustained oscillation
    settled, spread over the range; marches from rest with the largest initial rotation)."""
    rows = [r for r in result.rows if r["start"] == "point" and r["history"]]
    if not rows:
        raise InputError("the result has no time histories")
    a_max = max(r["initial"] for r in rows)
    rows = [r for r in rows if r["initial"] == a_max]
    if speeds is None:
        pick = [r for r in rows if r["kind"] in SUSTAINED] or rows
        idx = np.unique(np.linspace(0, len(pick) - 1, min(n, len(pick))).round().astype(int))
        chosen = [pick[i] for i in idx]
    else:
        chosen = [min(rows, key=lambda r, v=v: abs(r["speed"] - v)) for v in np.atleast_1d(speeds)]
    ref = result.settings.get("reference")
    gap = result.gap
    fig = new_figure(figsize=(8.0, 1.9 * len(chosen) + 0.6))
    axes = fig.subplots(len(chosen), 1, sharex=True, squeeze=False)[:, 0]
    freqs = [r["frequency"] for r in chosen if np.isfinite(r["frequency"]) and r["frequency"] > 0]
    window = 6.0 / min(freqs) if freqs else np.inf  # six cycles of the slowest
    for ax, r in zip(axes, chosen, strict=True):
        h = r["history"]
        t = np.asarray(h["t"])
        f = r["frequency"]
        keep = t >= t[-1] - window
        t = t[keep]
        y = np.asarray(h[f"{ref}_rotation"])[keep]
        ax.plot(t, y / gap if gap else np.degrees(y), color="tab:blue", lw=1.0)
        if gap:
            for e in (-0.5, 0.5):
                ax.axhline(e, color="grey", ls=":", lw=0.8)
        ax.set_ylabel("rotation / gap" if gap else "rotation [deg]", fontsize=8)
        ax2 = ax.twinx()
        ax2.plot(t, np.asarray(h[f"{ref}_hinge_moment"])[keep], color="tab:orange", lw=0.8)
        ax2.set_ylabel("hinge moment [N m]", fontsize=8, color="tab:orange")
        ax.set_title(
            f"{r['speed']:.4g} m/s: {r['kind']} ({r['confidence']}), "
            + (f"{f:.3g} Hz, " if np.isfinite(f) else "")
            + (f"amplitude {r['amplitude_per_gap']:.3g} x gap" if gap else ""),
            fontsize=9,
        )
    axes[-1].set_xlabel("time [s] (the last cycles of each march)")
    title = result.settings.get("scenario") or result.settings.get("name", "")
    fig.suptitle(f"{title}: {ref} (dotted: gap edges)", fontsize=10)
    return fig
