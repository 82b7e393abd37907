"""Figures of a gust-loads study (CS-25.341), drawn from a
:class:`~aeroservo.studies.gust.results.GustLoadsResult` alone (so they redraw from its files).

* :func:`plot_envelope`: limit loads per flight point, open and closed loop, with the gust load
  alleviation (GLA) of the loop and the loads it raises in red;
* :func:`plot_correlated`: correlated loads (e.g. root bending moment against root torque): the
  discrete-gust points and the turbulence design ellipse (:func:`design_ellipse`);
* :func:`plot_gust_history`, :func:`plot_critical_gusts`, :func:`plot_tuning`
  (:mod:`aeroservo.studies.gust.history_plots`): the critical gust of one load at one flight
  point, that of every load at its worst point, and the tuning search over the gust gradient;
* :func:`gust_figures`: the figures a run writes (and ``GustLoadsResult.plot`` draws).

Loads are increments of the wing clamped at its root (no rigid-body modes, no 1 g load). Data
are SI; the figures show kN, kN m and degrees (:data:`~aeroservo.studies.gust.figure_support.
DISPLAY_UNITS`). Open loop is grey, closed loop blue; red marks what the loop makes worse.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ...errors import InputError
from .figure_support import (
    INCREMENTAL,
    LOOP_COLORS,
    any_record,
    axis_label,
    check_load,
    check_loops,
    check_point,
    display_unit,
    footer,
    marker,
    panel_columns,
    panel_grid,
    place_legend,
    point_indices,
    point_label,
    point_notes,
    record_of,
)
from .history_plots import plot_critical_gusts, plot_gust_history, plot_tuning

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = [
    "plot_envelope",
    "plot_correlated",
    "plot_gust_history",
    "plot_critical_gusts",
    "plot_tuning",
    "design_ellipse",
    "discrete_points",
    "gust_figures",
    "drawable",
    "FIGURES",
    "CORRELATED",
]

SIDE_MARKERS = {("x", "max"): ">", ("x", "min"): "<", ("y", "max"): "^", ("y", "min"): "v"}
"""Marker of each discrete extreme in the correlated-load plot."""


def plot_envelope(result, loads=None) -> Figure:
    """Limit loads per flight point: one panel per load, open and closed loop side by side.

    The bar is the limit load (the larger of the discrete tuned-gust load ``max(|max|, |min|)``
    and the turbulence load ``U_sigma A_bar``); a black dash marks the discrete load and a white
    diamond the turbulence load. Above each closed-loop bar: the gust load alleviation
    ``GLA = 100 (1 - closed / open)`` [%] of the limit load; a bar edged and labelled in red is a
    load the loop raises (discrete or turbulence,
    :attr:`~aeroservo.studies.gust.results.GustLoadsResult.alleviation`). A loop that was not
    computed at a point is written in place of its bar; the notes are listed below the panels.

    Parameters
    ----------
    result : GustLoadsResult
    loads : list of str, optional
        Default: every load.
    """
    from matplotlib.colors import to_rgba
    from matplotlib.patches import Patch

    from ..._figures import new_figure

    points, loops = point_indices(result), result.loops
    loads = list(result.loads if loads is None else loads)
    for n in loads:
        check_load(result, n)
    raised: dict = {}
    if loops == ["open", "closed"]:
        a = result.alleviation
        raised = dict(zip(zip(a["point"], a["load"], strict=True), a["raised"], strict=True))
    cols = panel_columns(len(loads))
    width = min(max(2.0 + 1.3 * len(points), 4.0) * cols, 16.0)
    fig = new_figure(figsize=(width, 3.3 * math.ceil(len(loads) / cols) + 1.6))
    w = 0.8 / max(len(loops), 1)
    turb_drawn = False
    missing = dict(rotation=90, ha="center", va="bottom", fontsize=7, color="tab:red")
    axs, spare = panel_grid(fig, len(loads), cols)
    for ax, load in zip(axs, loads, strict=True):
        unit, f = display_unit(result, load)
        top = 0.0
        for i, p in enumerate(points):
            lim = {}
            for j, lp in enumerate(loops):
                x = i + (j - (len(loops) - 1) / 2) * w
                rec = record_of(result, p, lp)
                if rec is None:  # the loop was not computed here (unstable, failed)
                    ax.text(x, 0, f" no {lp} loop", **missing)
                if rec is None or load not in rec["loads"]:
                    continue
                v = rec["loads"][load]
                disc, turb = float(v["discrete"]), float(v.get("turbulence", np.nan))
                lim[lp] = np.nanmax([disc, turb])
                red = lp == "closed" and bool(raised.get((p, load), False))
                ec = "tab:red" if red else "none"
                ax.bar(x, lim[lp] * f, w * 0.9, fc=to_rgba(LOOP_COLORS[lp], 0.75), ec=ec, lw=2)
                ax.plot(x, disc * f, "_", color="k", ms=w * 30, mew=2)
                if np.isfinite(turb):
                    ax.plot(x, turb * f, "D", mfc="w", mec="k", ms=5)
                    turb_drawn = True
                top = max(top, lim[lp] * f)
            if len(lim) == 2 and lim["open"] > 0:
                gla = 100.0 * (1.0 - lim["closed"] / lim["open"])
                red = bool(raised.get((p, load), False))
                style = dict(color="tab:red", fontweight="bold") if red else dict(color="k")
                style.update(ha="center", va="bottom", fontsize=7, textcoords="offset points")
                xy = (i + w / 2, lim["closed"] * f)
                text = f"GLA\n{gla:.1f} %"
                if red and gla >= 0:  # the limit load falls, but one of its parts rises
                    o, c = record_of(result, p, "open"), record_of(result, p, "closed")
                    d = 100.0 * (1 - c["loads"][load]["discrete"] / o["loads"][load]["discrete"])
                    text += f"\n(1-cos {d:.1f} %)"
                ax.annotate(text, xy, xytext=(0, 5), **style)
        ax.set_ylim(0, 1.35 * top if top > 0 else 1.0)
        ax.set_xticks(
            range(len(points)), [point_label(any_record(result, p), "\n") for p in points]
        )
        ax.tick_params(axis="x", labelsize=7)
        ax.set_xlim(-0.6, len(points) - 0.4)
        ax.set_ylabel(f"limit load [{unit}]", fontsize=8)
        only = [
            lp for lp in loops if any(load in r["loads"] for r in result.records if r["loop"] == lp)
        ]
        only = f" ({only[0]} loop only)" if len(only) == 1 < len(loops) else ""
        ax.set_title(load + only, fontsize=9)
        ax.grid(True, axis="y", alpha=0.3)
    handles = [Patch(fc=to_rgba(LOOP_COLORS[lp], 0.75), label=f"{lp} loop") for lp in loops]
    handles.append(
        marker("_", "discrete tuned gust (1-cos): max(|max|, |min|)", color="k", ms=12, mew=2)
    )
    if turb_drawn:
        handles.append(marker("D", "continuous turbulence: U_sigma A_bar", mfc="w", mec="k"))
    if raised:
        label = "the loop raises the load; GLA = 100 (1 - closed / open) of the limit load"
        handles.append(Patch(fc="w", ec="tab:red", lw=2, label=label))
    place_legend(fig, spare, handles)
    extra = [] if turb_drawn else ["continuous turbulence not computed: discrete gusts only"]
    footer(fig, extra + point_notes(result, points, loops))
    fig.suptitle(f"{result.name}: limit loads per flight point, {INCREMENTAL}", fontsize=10)
    return fig


def design_ellipse(
    a_x: float, a_y: float, rho: float, u_sigma: float, n: int = 361
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The equal-probability design ellipse of two correlated loads in continuous turbulence.

    For loads x and y with RMS ``A_x``, ``A_y`` per unit gust RMS and correlation coefficient
    ``rho = E[x y] / (A_x A_y)`` (from their covariance per unit gust variance), the ellipse is
    ``{z : z^T S^-1 z = U_sigma^2}`` with ``S = [[A_x^2, rho A_x A_y], [rho A_x A_y, A_y^2]]``,
    drawn as::

        x(t) = U_sigma A_x cos t,   y(t) = U_sigma A_y (rho cos t + sqrt(1 - rho^2) sin t).

    Its extremes are ``+-U_sigma A_x`` and ``+-U_sigma A_y`` (the turbulence limit loads); its
    design points, where it touches its bounding box, are ``(+-U_sigma A_x, +-rho U_sigma A_y)``
    and ``(+-rho U_sigma A_x, +-U_sigma A_y)``: each limit load with its correlated load
    ``rho U_sigma A`` of the other. This is the equal-probability design ellipse of combined
    (correlated) loads of F. M. Hoblit, *Gust Loads on Aircraft: Concepts and Applications*,
    AIAA Education Series, 1988 (the chapter on combined loads).

    Parameters
    ----------
    a_x, a_y : float
        A_bar of the two loads [their units per m/s].
    rho : float
        Correlation coefficient, in [-1, 1].
    u_sigma : float
        Design turbulence intensity [m/s TAS].
    n : int
        Points on the ellipse.

    Returns
    -------
    x, y : ndarray
        The ellipse [the loads' units], closed (first point repeated last).
    design : ndarray
        (4, 2): the design points at max x, min x, max y, min y.
    """
    rho = float(np.clip(rho, -1.0, 1.0))
    t = np.linspace(0.0, 2.0 * np.pi, n)
    ux, uy = u_sigma * a_x, u_sigma * a_y
    x, y = ux * np.cos(t), uy * (rho * np.cos(t) + math.sqrt(1.0 - rho * rho) * np.sin(t))
    design = np.array([[ux, rho * uy], [-ux, -rho * uy], [rho * ux, uy], [-rho * ux, -uy]])
    return x, y, design


def _covariance(rec: dict, x: str, y: str) -> tuple[float, float, float] | None:
    """(A_x, A_y, rho) from a record's turbulence covariance (None when absent)."""
    cov = rec.get("covariance")
    if not cov or x not in cov["outputs"] or y not in cov["outputs"]:
        return None
    c = np.asarray(cov["matrix"], dtype=float)
    i, j = cov["outputs"].index(x), cov["outputs"].index(y)
    a_x, a_y = math.sqrt(c[i, i]), math.sqrt(c[j, j])
    return a_x, a_y, (c[i, j] / (a_x * a_y) if a_x * a_y > 0 else 0.0)


def discrete_points(rec: dict, x: str, y: str) -> dict:
    """``{("x" | "y", "max" | "min"): (x, y)}`` [SI] of a record: each discrete extreme of x and
    of y with its correlated load (the other load at the instant of the extreme)."""
    out = {}
    for axis, name in (("x", x), ("y", y)):
        v = rec["loads"][name]
        for side in ("max", "min"):
            corr = v[f"{side}_correlated"]
            out[(axis, side)] = tuple(v[side] if n == name else corr[n] for n in (x, y))
    return out


def plot_correlated(
    result,
    x: str = "root_bending_moment",
    y: str = "root_torque",
    *,
    point: int | None = None,
    loop: str | None = None,
) -> Figure:
    """Correlated loads x against y: one panel per flight point (or the one given).

    For each loop: the four discrete tuned-gust points (:func:`discrete_points`: the maximum
    and minimum of x, each with the y of the same instant, and those of y with their x) and,
    when the turbulence covariance was computed, the design ellipse of :func:`design_ellipse`
    with its four design points.

    Parameters
    ----------
    result : GustLoadsResult
    x, y : str
        Loads on the axes.
    point : int, optional
        Flight point index (default: every point).
    loop : {"open", "closed"}, optional
        Default: both.
    """
    from matplotlib.lines import Line2D

    from ..._figures import new_figure

    check_load(result, x, "x")
    check_load(result, y, "y")
    if x == y:
        raise InputError(f"x = y = {x!r}: give two different loads")
    loops = check_loops(result, loop)
    points = point_indices(result) if point is None else [check_point(result, point)]
    if point is not None and loop is not None:
        result.record(points[0], loop)  # one line when that loop is missing there
    fx, fy = display_unit(result, x)[1], display_unit(result, y)[1]
    cols = min(len(points), 3)
    fig = new_figure(figsize=(4.0 * cols + 3.0, 3.8 * math.ceil(len(points) / cols) + 1.0))
    ellipse = missing = False
    absent, notes = [], []
    axs, _ = panel_grid(fig, len(points), cols, sharex=True, sharey=True)
    for ax, p in zip(axs, points, strict=True):
        for lp in loops:
            rec, c = record_of(result, p, lp), LOOP_COLORS[lp]
            if rec is None or x not in rec["loads"] or y not in rec["loads"]:
                absent.append(p)
                continue
            for key, (px, py) in discrete_points(rec, x, y).items():
                ax.plot(px * fx, py * fy, SIDE_MARKERS[key], color=c, ms=8, mec="k", mew=0.5)
            cov = _covariance(rec, x, y)
            if cov is None:
                missing = True
                continue
            ex, ey, design = design_ellipse(*cov, rec["u_sigma"])
            ax.plot(ex * fx, ey * fy, "-", color=c, lw=1.3)
            ax.plot(design[:, 0] * fx, design[:, 1] * fy, "o", mfc="w", mec=c, mew=1.5, ms=6)
            ellipse = True
        ax.axhline(0, color="k", lw=0.6)
        ax.axvline(0, color="k", lw=0.6)
        ax.tick_params(labelbottom=True, labelleft=True)
        ax.set_xlabel(axis_label(result, x), fontsize=8)
        ax.set_ylabel(axis_label(result, y), fontsize=8)
        ax.set_title(f"point {p}: {point_label(any_record(result, p))}", fontsize=8)
        ax.grid(True, alpha=0.3)
    names = {"x": x, "y": y}
    handles = [marker("s", f"{lp} loop", color=LOOP_COLORS[lp]) for lp in loops]
    for (axis, side), m in SIDE_MARKERS.items():
        label = f"discrete gust: {side} {names[axis]}\n  with the other load at that instant"
        handles.append(marker(m, label, color="w", mec="k", ms=8))
    if ellipse:
        label = "turbulence design ellipse\n  (U_sigma A_bar, correlation rho)"
        handles.append(Line2D([], [], color="k", lw=1.3, label=label))
        label = "turbulence design points:\n  a limit load with rho x the other"
        handles.append(marker("o", label, mfc="w", mec="k", mew=1.5))
    if missing:
        notes.append("turbulence covariance not computed (turbulence off): discrete points only")
    if absent:
        gone = sorted(set(absent))
        notes += point_notes(result, gone, []) or [f"points {gone}: a loop has no {x} or {y}"]
    fig.legend(handles=handles, loc="outside right center", fontsize=7, frameon=False)
    footer(fig, notes)
    fig.suptitle(f"{result.name}: correlated loads\n{INCREMENTAL}", fontsize=10)
    return fig


CORRELATED = ("root_bending_moment", "root_torque")
"""The pair of loads of the correlated-load figure (x, y), drawn when both are loads."""

FIGURES = ("envelope", "correlated", "critical_gusts", "spanwise")
"""The figures of a gust-loads run, by file suffix (:func:`gust_figures`)."""


def gust_figures(result, which=FIGURES) -> dict:
    """The figures a gust-loads run writes, by file suffix: ``envelope`` (limit loads per flight
    point), ``correlated`` (root bending moment against root torque, only when both are loads)
    ``critical_gusts`` (time histories of the critical gusts) and ``spanwise`` (limit loads along
    the span, only with loads at two or more stations, whose loads the envelope and the critical
    gusts then leave to it); ``which``: those to draw. See :mod:`aeroservo.studies.gust.span_plots`
    for the spanwise figure."""
    from . import span_plots as gust_span_plots

    span = gust_span_plots.span_loads(result)
    # the station loads are the spanwise figure's; the per-load figures keep the others
    stations = {n for items in span.values() for _x, n in items if not n.startswith("root_")}
    loads = [n for n in result.loads if n not in stations]
    draw = {
        "envelope": lambda r: plot_envelope(r, loads),
        "correlated": lambda r: plot_correlated(r, *CORRELATED),
        "critical_gusts": lambda r: plot_critical_gusts(r, loads),
        "spanwise": gust_span_plots.plot_spanwise,
    }
    can = drawable(result, span)
    return {name: draw[name](result) for name in FIGURES if name in which and can.get(name, True)}


def drawable(result, span: dict | None = None) -> dict:
    """Whether the figures of a run can be drawn, by file suffix: any with loads at a flight
    point at least (a study whose every point was skipped has none), ``correlated`` with both
    loads of :data:`CORRELATED` and ``spanwise`` with loads at two or more stations (``span``:
    :func:`~aeroservo.studies.gust.span_plots.span_loads` when known)."""
    from .span_plots import span_loads

    if not result.records:
        return dict.fromkeys(FIGURES, False)
    return {
        "correlated": all(n in result.loads for n in CORRELATED),
        "spanwise": bool(span_loads(result) if span is None else span),
    }
