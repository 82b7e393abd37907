"""The spanwise envelope of a gust-loads study: shear, bending moment and torque against the
spanwise station (the root and every load station), as a loads engineer reads the wing.

One panel per quantity; for each loop, the largest limit load over every flight point and
mass case at each station (solid, with the discrete tuned-gust part dashed and the turbulence
part dotted), and the rigid clamped wing's quasi-static load in the largest design gust of the
same worst point as a thin black line (:mod:`~aeroservo.studies.gust.rigid_wing`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...errors import InputError
from ...linear.signals import STATION_QUANTITIES, station_of
from .figure_support import INCREMENTAL, LOOP_COLORS, display_unit, footer, point_notes

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["plot_spanwise", "span_loads"]


def span_loads(result) -> dict[str, list[tuple[float, str]]]:
    """``{quantity: [(station [m], load name), ...]}`` of the root and station loads of a
    result, by increasing station (a quantity with fewer than two stations is left out)."""
    out: dict[str, list[tuple[float, str]]] = {q: [] for q in STATION_QUANTITIES}
    for name in result.loads:
        which = station_of(name)
        if which is not None:
            out[which[0]].append((which[1], name))
    return {q: sorted(v) for q, v in out.items() if len({x for x, _ in v}) >= 2}


def _envelope(result, loop: str, name: str) -> tuple[float, float, float, float]:
    """Largest limit, discrete, turbulence load and the rigid load of the worst point."""
    best = (np.nan, np.nan, np.nan, np.nan)
    for r in result.records:
        v = r["loads"].get(name) if r["loop"] == loop else None
        if v is None:
            continue
        disc, turb = float(v["discrete"]), float(v.get("turbulence", np.nan))
        lim = np.nanmax([disc, turb])
        if not lim <= best[0]:  # NaN-safe: the first one or a larger one
            best = (lim, disc, turb, float(v.get("rigid", np.nan)))
    return best


def plot_spanwise(result) -> Figure:
    """Limit loads along the span (see the module docstring).

    Parameters
    ----------
    result : GustLoadsResult
        With loads at two or more stations (the root and ``load_stations``).
    """
    from ..._figures import new_figure

    spans = span_loads(result)
    if not spans:
        raise InputError(
            "the spanwise envelope needs shear, bending moment or torque at two or more "
            "stations (the root loads and load_stations)"
        )
    fig = new_figure(figsize=(4.2 * len(spans) + 0.6, 4.4))
    axs = fig.subplots(1, len(spans), squeeze=False)[0]
    for ax, (q, items) in zip(axs, spans.items(), strict=True):
        x = np.array([s for s, _ in items])
        unit, f = display_unit(result, items[0][1])
        for lp in result.loops:
            env = np.array([_envelope(result, lp, n) for _, n in items])
            c = LOOP_COLORS[lp]
            ax.plot(x, env[:, 0] * f, "o-", color=c, lw=2, label=f"{lp} loop: limit load")
            ax.plot(x, env[:, 1] * f, "--", color=c, lw=1, label=f"{lp}: discrete (1-cos)")
            if np.isfinite(env[:, 2]).any():
                ax.plot(x, env[:, 2] * f, ":", color=c, lw=1.5, label=f"{lp}: turbulence")
            if lp == result.loops[0] and np.isfinite(env[:, 3]).any():
                ax.plot(x, env[:, 3] * f, "-", color="k", lw=0.8, label="rigid wing, quasi-static")
        ax.set_xlabel("spanwise station [m]", fontsize=8)
        ax.set_ylabel(f"{q.replace('_', ' ')} [{unit}]", fontsize=8)
        ax.set_title(q.replace("_", " "), fontsize=9)
        ax.set_ylim(bottom=0.0)
        ax.grid(True, alpha=0.3)
    axs[0].legend(fontsize=7, loc="upper right")
    footer(fig, point_notes(result, sorted({r["point"] for r in result.records}), result.loops))
    fig.suptitle(
        f"{result.name}: limit loads along the span, worst flight point at each station, "
        f"{INCREMENTAL}",
        fontsize=10,
    )
    return fig
