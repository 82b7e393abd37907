"""Figures of limit-cycle oscillations: the describing-function branches (:func:`plot_describing`).

The axes are made by :func:`aeroservo._figures.new_figure` when none is given (the current
pyplot figure when pyplot is in use, detached otherwise).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .._figures import new_figure
from ..errors import InputError

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

    from ..stability.describing_function import DescribingBranches

__all__ = ["plot_describing"]


def plot_describing(branches: DescribingBranches, ax: Axes | None = None, *, per_gap: bool = True):
    """LCO amplitude against airspeed, per branch: solid where stable, dashed where unstable,
    light where another root of the equivalent system is unstable (no LCO is seen there).

    Parameters
    ----------
    branches : DescribingBranches
        From :func:`aeroservo.stability.describing_function.describing_branches`.
    ax : matplotlib Axes, optional
        Axes to draw on (default: a new figure).
    per_gap : bool
        Amplitude over the reference element's gap [-] (freeplay and bilinear laws); otherwise,
        and for a cubic spring, the amplitude in degrees.

    Returns
    -------
    matplotlib Axes
    """
    from ..stability.describing_function import DescribingBranches

    if not isinstance(branches, DescribingBranches):
        raise InputError(f"branches = {branches!r}: expected DescribingBranches")
    if ax is None:
        ax = new_figure(figsize=(7.0, 4.6)).add_subplot()
    scaled = bool(per_gap and branches.gap)
    y_all = branches.amplitude / branches.gap if scaled else np.degrees(branches.amplitude)
    alone = branches.others_stable
    alone = np.ones(branches.speed.size, bool) if alone is None else alone
    for n, b in enumerate(np.unique(branches.branch)):
        sel = np.flatnonzero(branches.branch == b)
        v, y, st, al = branches.speed[sel], y_all[sel], branches.stable[sel], alone[sel]
        f = branches.frequency[sel]
        label = f"branch {b + 1}: {f.min():.3g}-{f.max():.3g} Hz"
        # one line per run of equal stability, joined to the next run
        key = 2 * st.astype(int) + al.astype(int)
        cuts = np.flatnonzero(np.diff(key)) + 1
        for lo, hi in zip(np.r_[0, cuts], np.r_[cuts, sel.size], strict=True):
            stop = min(hi + 1, sel.size)
            ax.plot(
                v[lo:stop],
                y[lo:stop],
                color=f"C{n % 10}",
                ls="-" if st[lo] else "--",
                alpha=1.0 if al[lo] else 0.35,
                marker="." if stop - lo == 1 else None,
                label=label,
            )
            label = None
    ax.plot([], [], color="k", ls="-", label="stable LCO")
    ax.plot([], [], color="k", ls="--", label="unstable LCO")
    if not alone.all():
        ax.plot([], [], color="k", alpha=0.35, label="(light: another root unstable)")
    ax.set_xlabel("airspeed [m/s]")
    what = f"amplitude of {branches.element}"
    ax.set_ylabel(f"{what} / gap [-]" if scaled else f"{what} [deg]")
    ax.set_title("LCO by describing function")
    if branches.speed.size:
        ax.set_yscale("log")
    else:
        ax.text(0.5, 0.5, "no LCO branch", transform=ax.transAxes, ha="center")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    return ax
