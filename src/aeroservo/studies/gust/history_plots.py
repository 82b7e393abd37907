"""Time-history figures of a gust-loads study (CS-25.341(a)), drawn from a
:class:`~aeroservo.studies.gust.results.GustLoadsResult`: the critical gust of one load at one
flight point (:func:`plot_gust_history`), that of every load at its worst flight point
(:func:`plot_critical_gusts`) and the tuning search over the gust gradient (:func:`plot_tuning`).

Times are counted from the moment the gust front reaches the leading edge; loads are increments
of the wing clamped at its root. Open loop is grey, closed loop blue (as in
:mod:`aeroservo.studies.gust.plots`).
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
    check_side,
    critical_gust,
    display_unit,
    footer,
    panel_columns,
    panel_grid,
    point_label,
    point_notes,
    record_of,
)

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["plot_gust_history", "plot_critical_gusts", "plot_tuning", "magnitude_limit"]

TIME_LABEL = "time after the gust front reaches the leading edge [s]"


def _gust_label(lp: str, h: float, sign: int, u_ds: float) -> str:
    way = "up" if sign > 0 else "down"
    return f"{lp} loop: H = {h:.1f} m, U_ds = {u_ds:.2f} m/s TAS, {way}"


def magnitude_limit(result, control: str) -> float | None:
    """The magnitude limit of a control [SI] from the result's settings (``limits`` as
    ``{"magnitude": {control: value}}`` or ``{control: value}``); None when not stored."""
    lim = (result.settings or {}).get("limits") or {}
    value = (lim.get("magnitude") or {}).get(control, lim.get(control))
    return float(value) if isinstance(value, int | float) else None


def _draw_load(ax, result, rec: dict, lp: str, load: str, side: str, t, y, prefix: str = ""):
    """A loop's load history with its extreme starred; the legend entry gives the extreme and
    its time (after ``prefix``, e.g. the gust, when given)."""
    unit, f = display_unit(result, load)
    _, _, _, value, t_ext = critical_gust(rec, load, side)
    text = f"{side} {value * f:.4g} {unit} at t = {t_ext:.3f} s"
    label = f"{prefix}\n  {text}" if prefix else f"{lp} loop: {text}"
    ax.plot(t, y * f, color=LOOP_COLORS[lp], lw=1.2, label=label)
    ax.plot(t_ext, value * f, "*", color=LOOP_COLORS[lp], mec="k", ms=11)


def _span(t, y, t_gust: float) -> float:
    """End of the interesting part of a history: the gust and the response until it stays
    below 2 % of its peak, plus 10 %."""
    big = np.flatnonzero(np.abs(y) > 0.02 * np.max(np.abs(y)))
    return 1.1 * max(t_gust, float(t[big[-1]]) if big.size else 0.0)


def _draw_control(ax, result, rec: dict, control: str, t, u, k: int) -> None:
    """A control applied by the loop, with its magnitude limit when stored and near."""
    unit, f = display_unit(result, control)
    at_limit = rec["time_at_limit"].get(control, 0.0)
    limit = magnitude_limit(result, control)
    label = f"{control} (closed loop)"
    if limit is None and at_limit > 0:
        label += f": at a limit for up to {at_limit:.3g} s in a gust (limit not stored)"
    elif limit is None:
        label += ": never at a limit in the search"
    ax.plot(t, u * f, color=f"C{k + 2}", lw=1.2, label=label)
    if limit is not None and limit <= 3.0 * float(np.max(np.abs(u))):
        for s in (1, -1):
            text = f"{control} magnitude limit +-{limit * f:.4g} {unit}" if s > 0 else None
            ax.axhline(s * limit * f, color="tab:red", ls="--", lw=1.0, label=text)


def plot_gust_history(result, point: int, load: str, side: str = "max") -> Figure:
    """The critical discrete gust of ``load`` (its maximum or minimum) at one flight point.

    Stacked panels against the time after the gust front reaches the leading edge: the gust
    velocity [m/s TAS] of each loop's own critical gust (gradient H and U_ds in the legend); the
    load, open and closed loop overlaid, each extreme starred with its time; the controls the
    loop applied in its gust, with their magnitude limit when the settings store it and it is
    within 3 x the signal (otherwise the legend gives the share of samples at a limit).

    Parameters
    ----------
    result : GustLoadsResult
    point : int
        Flight point index.
    load : str
    side : {"max", "min"}
    """
    from ..._figures import new_figure

    point, load, side = check_point(result, point), check_load(result, load), check_side(side)
    recs = {lp: record_of(result, point, lp) for lp in result.loops}
    recs = {lp: r for lp, r in recs.items() if r is not None and load in r["loads"]}
    if not recs:
        raise InputError(f"load {load!r}: not computed at point {point} (see the notes)")
    closed = recs.get("closed")
    controls = (
        [c for c in closed["time_at_limit"] if c in closed["history_loads"]] if closed else []
    )
    n = 2 + bool(controls)
    fig = new_figure(figsize=(8.0, 2.4 * n + 1.2))
    axs = list(fig.subplots(n, 1, sharex=True))
    end = 0.0
    for lp, rec in recs.items():
        t, gust, ys = result.history(point, lp, load, side)
        h, sign, u_ds, _, _ = critical_gust(rec, load, side)
        end = max(end, _span(t, ys[load], 2 * h / rec["tas"]))
        lw = 2.6 if lp == "open" else 1.2  # both seen when the two loops' gusts are the same
        axs[0].plot(t, gust, color=LOOP_COLORS[lp], lw=lw, label=_gust_label(lp, h, sign, u_ds))
        _draw_load(axs[1], result, rec, lp, load, side, t, ys[load])
        for k, c in enumerate(controls if lp == "closed" else ()):
            _draw_control(axs[2], result, rec, c, t, ys[c], k)
    axs[0].set_ylabel("gust velocity\n[m/s TAS]")
    axs[1].set_ylabel(axis_label(result, load))
    if controls:
        axs[2].set_ylabel("applied control\n[" + display_unit(result, controls[0])[0] + "]")
    for ax in axs:
        ax.grid(True, alpha=0.3)
        ax.axhline(0, color="k", lw=0.6)
        ax.margins(y=0.2)
        ax.legend(fontsize=7, loc="best")
    axs[0].set_xlim(0, end)
    axs[-1].set_xlabel(TIME_LABEL)
    if "closed" in result.loops and "closed" not in recs:
        footer(fig, point_notes(result, [point], []))
    fig.suptitle(
        f"{result.name}: critical gust of {side} {load} at point {point} "
        f"({point_label(any_record(result, point))})\n{INCREMENTAL}",
        fontsize=9,
    )
    return fig


def plot_critical_gusts(result, loads=None, loop: str | None = None) -> Figure:
    """The critical discrete gust of each load at its worst flight point: one small panel per
    load, the load against time, open and closed loop overlaid (each loop's own critical gust).

    The worst point of a load is that of its largest discrete-gust load ``max(|max|, |min|)``
    over the loops drawn (that of
    :meth:`~aeroservo.studies.gust.results.GustLoadsResult.worst` when the discrete gust
    governs the limit load); the side drawn (maximum or minimum) is the larger in magnitude
    there.

    Parameters
    ----------
    result : GustLoadsResult
    loads : list of str, optional
        Default: every load.
    loop : {"open", "closed"}, optional
        Default: both.
    """
    from ..._figures import new_figure

    loops = check_loops(result, loop)
    loads = list(result.loads if loads is None else loads)
    for n in loads:
        check_load(result, n)
    table = result.table
    table = table[table["loop"].isin(loops)]
    cols = panel_columns(len(loads))
    fig = new_figure(figsize=(4.4 * cols, 2.7 * math.ceil(len(loads) / cols) + 0.9))
    axs, _ = panel_grid(fig, len(loads), cols)
    for ax, load in zip(axs, loads, strict=True):
        rows = table[table["load"] == load]
        if rows.empty:
            ax.set_title(f"{load}: not computed in the {' / '.join(loops)} loop", fontsize=8)
            continue
        discrete = rows[["discrete_max", "discrete_min"]].abs().max(axis=1)
        p = int(rows.loc[discrete.idxmax(), "point"])
        end = 0.0
        for lp in loops:
            rec = record_of(result, p, lp)
            if rec is None or load not in rec["loads"]:
                why = "not computed at this point" if rec is None else f"no {load}"
                ax.plot([], [], color=LOOP_COLORS[lp], ls=":", label=f"{lp} loop: {why}")
                continue
            v = rec["loads"][load]
            side = "max" if abs(v["max"]) >= abs(v["min"]) else "min"
            t, _, ys = result.history(p, lp, load, side)
            h, sign, u_ds, _, _ = critical_gust(rec, load, side)
            _draw_load(ax, result, rec, lp, load, side, t, ys[load], _gust_label(lp, h, sign, u_ds))
            end = max(end, _span(t, ys[load], 2 * h / rec["tas"]))
        ax.set_xlim(0, end or None)
        ax.axhline(0, color="k", lw=0.6)
        ax.set_ylabel(axis_label(result, load), fontsize=8)
        ax.set_title(
            f"{load}\nworst at point {p}: {point_label(any_record(result, p))}", fontsize=8
        )
        ax.legend(fontsize=6, loc="best")
        ax.grid(True, alpha=0.3)
    for ax in axs:
        ax.set_xlabel(TIME_LABEL, fontsize=7)
    fig.suptitle(f"{result.name}: critical discrete gusts, {INCREMENTAL}", fontsize=10)
    return fig


def plot_tuning(result, point: int, load: str) -> Figure:
    """Peak of ``load`` over time against the gust gradient H at one flight point (the tuning
    search of CS-25.341(a)), one panel per loop.

    Curves: the maximum (red) and minimum (blue) over time of the up (solid) and down (dashed)
    gust at each scanned gradient (log scale, 30 to 350 ft); stars: the tuned extremes after the
    refinement between grid points (on or beyond the curves' best point; one at an end of the
    range is bounded by the rule's range of H, not by the wing).

    Parameters
    ----------
    result : GustLoadsResult
    point : int
        Flight point index.
    load : str
    """
    from ..._figures import new_figure

    point, load = check_point(result, point), check_load(result, load)
    recs = [(lp, record_of(result, point, lp)) for lp in result.loops]
    recs = [(lp, r) for lp, r in recs if r is not None and load in r.get("tuning", {})]
    if not recs:
        raise InputError(f"load {load!r}: not computed at point {point} (see the notes)")
    unit, f = display_unit(result, load)
    fig = new_figure(figsize=(4.8 * len(recs) + 0.6, 4.8))
    axs = list(np.atleast_1d(fig.subplots(1, len(recs), sharey=True, squeeze=False)).ravel())
    for ax, (lp, rec) in zip(axs, recs, strict=True):
        h = np.asarray(rec["gradients"])
        for key, values in rec["tuning"][load].items():
            way, side = key.split("_")
            style = dict(ls="-" if way == "up" else "--", marker="^" if side == "max" else "v")
            color = "tab:red" if side == "max" else "tab:blue"
            label = f"{way} gust, {side} over time"
            ax.plot(h, np.asarray(values) * f, ms=4, color=color, label=label, **style)
        for side in ("max", "min"):
            hh, sign, _, value, _ = critical_gust(rec, load, side)
            ax.plot(hh, value * f, "*", color="k", ms=13, mfc="gold", label="tuned extreme")
            end = " (end of range)" if not h[0] * 1.0001 < hh < h[-1] * 0.9999 else ""
            text = f"{value * f:.4g} {unit}\nH = {hh:.1f} m{end}, {'up' if sign > 0 else 'down'}"
            right = math.log(hh / h[0]) > 0.5 * math.log(h[-1] / h[0])
            up = side == "max"
            where = dict(ha="right" if right else "left", va="bottom" if up else "top")
            shift = (-8 if right else 8, 8 if up else -8)
            ax.annotate(
                text, (hh, value * f), shift, textcoords="offset points", fontsize=7, **where
            )
        ax.margins(y=0.18)
        ax.set_xscale("log")
        ax.axhline(0, color="k", lw=0.6)
        ax.set_xlabel("gust gradient H [m] (30 to 350 ft)")
        ax.set_title(f"{lp} loop", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = axs[0].get_legend_handles_labels()
    legend = dict(loc="outside lower center", ncols=5, fontsize=7, frameon=False)
    fig.legend(handles[:5], labels[:5], **legend)
    axs[0].set_ylabel(f"peak {axis_label(result, load)}")
    fig.suptitle(
        f"{result.name}: tuning of {load} at point {point} "
        f"({point_label(recs[0][1])}), {INCREMENTAL}",
        fontsize=9,
    )
    return fig
