"""Figures of a trade study: heat maps of a metric over two parameters, Pareto front.

A heat map shows one metric over two swept parameters. Further parameters either give one
panel per value (small multiples on one colour scale, when there are few: at most
:data:`MAX_PANELS` panels) or are held at their values in the best case
(:mod:`aeroservo.studies.trade.ranking`). The best case is outlined, cases whose actuator sat
on its limit in the gust and cases unstable at their design speed are marked, and a margin or
closed-loop flutter speed that is only a lower bound (stable to the end of the search) is
written with a greater-or-equal sign.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence

import numpy as np

from ...errors import InputError, check_int, check_number
from .ranking import effective_margin, saturated
from .study import METRICS, PARAMETERS

__all__ = ["HEATMAP_METRICS", "MAX_PANELS", "pareto_front"]

HEATMAP_METRICS = {
    True: (
        "suppression_margin",
        "closed_loop_flutter_speed",
        "hinge_moment_peak",
        "tip_accel_peak",
        "disk_margin",
    ),
    False: ("open_loop_flutter_speed", "open_loop_flutter_frequency"),
}
"""The metrics a closed-loop (True) or open-loop (False) study draws a heat map of."""

MAX_PANELS = 12
"""Most panels of a small-multiples heat map; beyond, the other parameters are held at the
best case."""

_BOUNDED = ("suppression_margin", "closed_loop_flutter_speed")
_TITLES = {
    "suppression_margin": "suppression margin V_cl / V_ol - 1",
    "closed_loop_flutter_speed": "closed-loop flutter speed V_cl",
    "hinge_moment_peak": "peak |hinge moment| in the 1-cos gust",
    "tip_accel_peak": "peak |tip acceleration| in the 1-cos gust",
    "disk_margin": "disk margin at the design speed (loop broken at the actuator)",
}


def _label(name: str) -> str:
    unit = (PARAMETERS.get(name) or METRICS.get(name) or ("-",))[0]
    return f"{name} [{unit}]"


def _wrap(text: str, width_in: float) -> str:
    """Each line of ``text`` wrapped to a figure ``width_in`` inches wide (small type)."""
    width = max(40, int(width_in * 15))
    return "\n".join(
        "\n".join(textwrap.wrap(line, width, break_on_hyphens=False)) for line in text.split("\n")
    )


def _axes(names: list, metric: str, x, y, fixed: dict) -> tuple[str, str]:
    if metric not in METRICS:
        raise InputError(f"metric = {metric!r}: unknown; known are {list(METRICS)}")
    if len(names) < 2:
        raise InputError(f"heatmap: needs two swept parameters; this study sweeps {names}")
    free = [n for n in names if n not in fixed]
    if x is None:
        x = next((n for n in free if n != y), names[0])
    if y is None:
        y = next((n for n in free if n != x), names[1] if names[1] != x else names[0])
    for key, v in (("x", x), ("y", y)):
        if v not in names:
            raise InputError(f"{key} = {v!r}: not a swept parameter; swept are {names}")
    if x == y:
        raise InputError(f"x = y = {x!r}: give two different parameters")
    return x, y


def _positions(parameters: dict, fixed: dict, axes: tuple) -> dict:
    """Indices of the fixed parameters (an int: an index; a number: the nearest value)."""
    sel: dict = {}
    for k, v in fixed.items():
        if k not in parameters or k in axes:
            others = [n for n in parameters if n not in axes]
            raise InputError(f"{k} = {v!r}: not a parameter to fix; the others are {others}")
        vals = parameters[k]
        if isinstance(v, (int, np.integer)) and not isinstance(v, bool):
            sel[k] = check_int(f"{k} (index)", v, lo=0, hi=len(vals) - 1)
        else:
            v = check_number(k, v)
            sel[k] = int(np.argmin(np.abs(np.asarray(vals) - v)))
    return sel


def _panels(parameters: dict, free: list, small_multiples: bool) -> tuple[list, int, int]:
    """One ``{name: index}`` per panel for the free parameters, with the panel rows, columns."""
    sizes = [len(parameters[n]) for n in free]
    n = math.prod(sizes)
    if not free:
        return [{}], 1, 1
    if not small_multiples or len(free) > 2 or n > MAX_PANELS:
        return [], 0, 0
    if len(free) == 2:
        rows, cols = sizes
        return [{free[0]: i, free[1]: j} for i in range(rows) for j in range(cols)], rows, cols
    cols = n if n <= 4 else math.ceil(math.sqrt(n))
    return [{free[0]: i} for i in range(n)], math.ceil(n / cols), cols


def _heatmap(
    table,
    parameters: dict,
    metric: str,
    x=None,
    y=None,
    fixed: dict | None = None,
    *,
    best: int | None = None,
    criterion: str = "",
    name: str = "",
    small_multiples: bool = True,
):
    """Heat map figure (see :meth:`TradeResult.heatmap`); ``best`` is the best case's row."""
    import matplotlib
    from matplotlib.patches import Rectangle

    from ..._figures import new_figure

    names = list(parameters)
    fixed = dict(fixed or {})
    x, y = _axes(names, metric, x, y, fixed)
    sel = _positions(parameters, fixed, (x, y))
    shape = tuple(len(v) for v in parameters.values())
    best_at = np.unravel_index(best, shape) if best is not None else None
    free = [n for n in names if n not in (x, y) and n not in sel]
    panels, rows, cols = _panels(parameters, free, small_multiples)
    held = []
    if not panels:  # too many panels: the other parameters at the best case
        for n in free:
            sel[n] = int(best_at[names.index(n)]) if best_at is not None else 0
        held = free
        panels, rows, cols = [{}], 1, 1

    def grid(values) -> np.ndarray:
        return np.asarray(values).reshape(shape)

    z_all = grid(table[metric].to_numpy(dtype=float)).copy()
    at_least = np.zeros(shape, dtype=bool)
    if metric in _BOUNDED:
        margin, bound = effective_margin(table)
        at_least = grid(bound)
        alt = margin if metric == "suppression_margin" else table["closed_loop_v_max"]
        z_all[at_least] = grid(np.asarray(alt, dtype=float))[at_least]
    failed = grid(table["status"].astype(str).to_numpy() != "ok")
    sat = grid(saturated(table)) & ~failed
    unstable = grid(table["stable_at_design"].to_numpy(dtype=float) == 0.0)

    def cut(arr: np.ndarray, panel: dict) -> np.ndarray:
        pos = {**sel, **panel}
        idx = tuple(slice(None) if n in (x, y) else pos[n] for n in names)
        out = arr[idx]  # the two axes remain, in the parameters' order
        return out.T if names.index(x) < names.index(y) else out

    xs, ys = parameters[x], parameters[y]
    cut_all = [cut(z_all, p) for p in panels]
    finite = np.concatenate([c[np.isfinite(c)] for c in cut_all])
    lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    norm = matplotlib.colors.Normalize(lo, hi if hi > lo else lo + 1.0)
    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="0.85")
    w = 0.8 * max(len(xs), 3) + 1.0
    h = 0.5 * max(len(ys), 3) + 0.8
    fig = new_figure(figsize=(cols * w + 1.4, rows * h + 1.6))
    axs = np.atleast_1d(fig.subplots(rows, cols, sharex=True, sharey=True, squeeze=False)).ravel()
    for ax in axs[len(panels) :]:
        ax.set_visible(False)
    marks = set()
    for ax, panel, z in zip(axs, panels, cut_all, strict=False):
        im = ax.imshow(np.ma.masked_invalid(z), origin="lower", aspect="auto", cmap=cmap, norm=norm)
        bits = [cut(b, panel) for b in (at_least, failed, sat, unstable)]
        if z.size <= 400:
            for (i, j), v in np.ndenumerate(z):
                if np.isfinite(v):
                    r, g, b, _ = cmap(norm(v))
                    dark = 0.299 * r + 0.587 * g + 0.114 * b < 0.5
                    text = ("\u2265" if bits[0][i, j] else "") + f"{v:.4g}"
                    color = "w" if dark else "k"
                else:
                    text, color = ("failed" if bits[1][i, j] else "n/a"), "0.35"
                ax.text(j, i, text, ha="center", va="center", fontsize=7, color=color)
        for i, j in zip(*np.nonzero(bits[2]), strict=True):
            ax.plot(j + 0.36, i + 0.3, "v", color="red", ms=5, mec="w", mew=0.5)
            marks.add("saturated")
        for i, j in zip(*np.nonzero(bits[3]), strict=True):
            ax.plot(j - 0.36, i + 0.3, "X", color="k", ms=5, mec="w", mew=0.5)
            marks.add("unstable")
        if bits[0].any():
            marks.add("bound")
        if best_at is not None and all(
            best_at[names.index(n)] == {**sel, **panel}[n] for n in names if n not in (x, y)
        ):
            i, j = best_at[names.index(y)], best_at[names.index(x)]
            for lw, color in ((3.5, "k"), (1.3, "w")):
                ax.add_patch(
                    Rectangle((j - 0.47, i - 0.47), 0.94, 0.94, fill=False, lw=lw, ec=color)
                )
            marks.add("best")
        if panel:
            ax.set_title(
                ", ".join(f"{k} = {parameters[k][i]:.4g}" for k, i in panel.items()), fontsize=8
            )
    for ax in axs[: len(panels)]:
        ax.set_xticks(range(len(xs)), [f"{v:.4g}" for v in xs])
        ax.set_yticks(range(len(ys)), [f"{v:.4g}" for v in ys])
    for k in range(len(panels)):
        if k % cols == 0:
            axs[k].set_ylabel(_label(y))
        if k >= len(panels) - cols:  # the lowest panel of its column
            axs[k].set_xlabel(_label(x))
            axs[k].tick_params(labelbottom=True)
    fig.colorbar(im, ax=list(axs[: len(panels)]), label=_label(metric), shrink=0.9)

    held_at = {n: sel[n] for n in held}
    fixed_at = {n: i for n, i in sel.items() if n not in held}
    title = _title(metric, name, parameters, best_at, criterion, fixed_at, held_at)
    width = fig.get_figwidth()
    fig.suptitle(_wrap(title, width), fontsize=8)
    _legend(fig, marks, width)
    return fig


def _title(metric, name, parameters, best_at, criterion, fixed_at, held_at) -> str:
    """The heat map's title: the metric, the best case and why, the slice."""

    def values(at: dict) -> str:
        return ", ".join(f"{n} = {parameters[n][i]:.4g}" for n, i in at.items())

    what = _TITLES.get(metric, METRICS[metric][1])
    lines = [f"{name}: {what}" if name else what]
    if best_at is not None:
        lines.append(
            f"best case ({criterion}): {values(dict(zip(parameters, best_at, strict=True)))}"
        )
    else:
        lines.append("no case qualifies as best" + (f" ({criterion})" if criterion else ""))
    if fixed_at:
        lines.append(f"slice: {values(fixed_at)}")
    if held_at:
        how = "the best case" if best_at is not None else "their first values"
        lines.append(f"held at {how}: {values(held_at)}")
    return "\n".join(lines)


def _legend(fig, marks: set, width: float) -> None:
    """The legend of the markers drawn (below the panels)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Rectangle

    legend = {
        "best": (Rectangle((0, 0), 1, 1, fill=False, lw=2, ec="k"), "best case"),
        "saturated": (
            Line2D([], [], ls="", marker="v", color="red", mec="w"),
            "actuator saturated in the gust",
        ),
        "unstable": (
            Line2D([], [], ls="", marker="X", color="k", mec="w"),
            "closed loop unstable at the design speed",
        ),
        "bound": (Line2D([], [], ls=""), "\u2265: stable to the end of the search (a bound)"),
    }
    shown = [legend[k] for k in ("best", "saturated", "unstable", "bound") if k in marks]
    if shown:
        fig.legend(
            *zip(*shown, strict=True),
            loc="outside lower center",
            ncols=min(len(shown), 2 if width < 6 else 4),
            fontsize=7,
            frameon=False,
        )


def pareto_front(margin: Sequence[float], peak: Sequence[float]) -> np.ndarray:
    """Mask of the Pareto-optimal points: no other point has a margin at least as high and a
    peak hinge moment at least as low, one of them strictly (NaN points are never optimal)."""
    m = np.asarray(margin, dtype=float)
    h = np.asarray(peak, dtype=float)
    ok = np.isfinite(m) & np.isfinite(h)
    front = np.zeros(m.shape, dtype=bool)
    for i in np.flatnonzero(ok):
        better = ok & (m >= m[i]) & (h <= h[i]) & ((m > m[i]) | (h < h[i]))
        front[i] = not better.any()
    return front


MAX_LABELS = 12
"""Most Pareto-front points labelled with their parameter values (spread along the front)."""


def _pareto(table, name: str, names: Sequence[str] = (), best: int | None = None):
    from ..._figures import new_figure

    t = table
    ok = (t["status"] == "ok").to_numpy()
    margin, bound = effective_margin(t)
    peak = t["hinge_moment_peak"].to_numpy(dtype=float)
    usable = ok & np.isfinite(margin) & np.isfinite(peak)
    unstable = usable & (t["stable_at_design"].to_numpy(dtype=float) != 1.0)
    front = pareto_front(np.where(usable & ~unstable, margin, np.nan), peak)
    sat = usable & saturated(t)

    fig = new_figure(figsize=(7.0, 4.8))
    ax = fig.subplots()
    plain = usable & ~front & ~bound & ~unstable
    ax.scatter(peak[plain], margin[plain], s=18, color="C0", alpha=0.6, label="case")
    marks = (  # (cases, scatter style, legend)
        (bound & usable & ~front, {"marker": "^", "s": 30, "color": "C2"},
         "stable to search limit (\u2265)"),
        (unstable, {"marker": "x", "s": 30, "color": "C3"}, "unstable at design speed"),
        (sat, {"marker": "s", "s": 70, "facecolors": "none", "edgecolors": "red", "lw": 1.0},
         "actuator saturated in the gust"),
    )  # fmt: skip
    for mask, style, label in marks:
        if mask.any():
            ax.scatter(peak[mask], margin[mask], label=label, **style)
    if front.any():
        order = np.flatnonzero(front)[np.argsort(peak[front])]
        ax.plot(peak[order], margin[order], "o-", color="C1", ms=6, label="Pareto front")
        step = max(1, math.ceil(len(order) / MAX_LABELS))
        labelled = list(order[::step]) + ([best] if best is not None and front[best] else [])
        lo, hi = float(peak[usable].min()), float(peak[usable].max())
        for k, i in enumerate(dict.fromkeys(labelled)):
            text = " / ".join(f"{t[n].iloc[i]:.4g}" for n in names) or str(t["case_id"].iloc[i])
            left = hi > lo and (peak[i] - lo) > 0.6 * (hi - lo)  # keep the label inside
            ax.annotate(
                text + (" (\u2265)" if bound[i] else ""),
                (peak[i], margin[i]),
                xytext=(-8 if left else 6, 7 if k % 2 == 0 else -12),
                textcoords="offset points",
                ha="right" if left else "left",
                fontsize=7,
                color="C1",
            )
    if best is not None and usable[best]:
        ax.plot(peak[best], margin[best], "*", color="k", ms=12, mfc="gold", label="best case")
    n_bad = int((~usable).sum())
    ax.set_xlabel(_label("hinge_moment_peak"))
    ax.set_ylabel(_label("suppression_margin"))
    if (margin[usable] <= 0.0).any():  # worse than the open loop
        ax.axhline(0.0, color="k", lw=0.8)
    ax.grid(True, alpha=0.3)
    title = f"{name}: {int(usable.sum())} cases" + (f", {n_bad} without result" if n_bad else "")
    if names and front.any():
        title += "\nfront labelled " + " / ".join(_label(n) for n in names)
    ax.set_title(_wrap(title, 7.0), fontsize=8)
    if usable.any():
        ax.legend(fontsize=7)
    return fig
