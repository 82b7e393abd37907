"""The convergence figure of a tailoring optimization (:func:`aeroservo.studies.optimize`).

Panels over the SLSQP iterations: the objective; the flutter (and divergence) speed with the
constraint bounds (unless the objective is the flutter speed and nothing constrains a speed);
each constraint's ``speed / bound - 1`` on a symmetric log scale (0: active, negative:
violated; when there are constraints); and each design variable's place between its bounds
(0: lower, 1: upper), so that an active bound shows as a line on 0 or 1.
"""

from __future__ import annotations

import numpy as np

from .optimize import ACTIVE, Optimization

__all__ = ["plot_convergence"]


def _values(history: list, key: str) -> np.ndarray:
    return np.array([np.nan if h[key] is None else h[key] for h in history], dtype=float)


def plot_convergence(result: Optimization, bounds: dict, objective: object, *, title: str = ""):
    """Objective, speeds, constraint activity and design variables against the iteration.

    Parameters
    ----------
    result : Optimization
        From :func:`~aeroservo.studies.optimize.optimize_wing` (its ``history``).
    bounds : dict
        Design variable -> (lower, upper), in the variable's unit.
    objective : dict or str
        The objective given to the optimizer: ``{name: weight}`` or ``"flutter_speed"``.
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .._figures import new_figure

    h = result.history
    it = np.array([r["iteration"] for r in h])
    constrained = {k: m["bound"] for k, m in result.constraints.items()}
    speeds = bool(constrained) or objective != "flutter_speed"
    n = 2 + speeds + bool(constrained)
    fig = new_figure(figsize=(7.0, 2.0 + 1.7 * n))
    axs = list(fig.subplots(n, 1, sharex=True))
    ax_obj, ax_x = axs[0], axs[-1]
    ax_v = axs[1] if speeds else None
    ax_c = axs[2] if constrained else None

    ax_obj.plot(it, _values(h, "objective"), "o-", color="C0", ms=4)
    if objective == "flutter_speed":
        ax_obj.set_ylabel("flutter speed [m/s]\n(maximized)")
    else:
        ax_obj.set_ylabel("sum of weight x value\n(minimized)")
    if ax_v is not None:
        _speeds(ax_v, it, h, constrained)
    if ax_c is not None:
        _constraints(ax_c, it, h, constrained)
    _variables(ax_x, it, h, bounds, result.active)
    for ax in axs:
        ax.grid(True, alpha=0.3)
    active = ", ".join(result.active) or "none"
    state = "converged" if result.success else f"NOT converged ({result.message})"
    fig.suptitle(
        f"{title}\n{state}; active at the optimum: {active}" if title else state, fontsize=9
    )
    return fig


def _speeds(ax_v, it, h: list, constrained: dict) -> None:
    """Flutter (and constrained divergence) speed with the constraint bounds."""
    ax_v.plot(it, _values(h, "flutter_speed"), "o-", color="C1", ms=4, label="flutter speed")
    if "divergence_speed_min" in constrained:
        ax_v.plot(
            it, _values(h, "divergence_speed"), "s-", color="C2", ms=4, label="divergence speed"
        )
    for k, bound in constrained.items():
        color = "C1" if k == "flutter_speed_min" else "C2"
        ax_v.axhline(bound, color=color, ls="--", lw=1.0, label=f"{k} = {bound:.4g} m/s")
    ax_v.set_ylabel("speed [m/s]")
    ax_v.legend(fontsize=7)


def _constraints(ax_c, it, h: list, constrained: dict) -> None:
    """Each constraint's ``speed / bound - 1``, the active ones circled."""
    for n, k in enumerate(constrained):
        g = np.array([r["constraints"][k] for r in h], dtype=float)
        active = np.abs(g) < ACTIVE
        ax_c.plot(it, g, "o-", color=f"C{n + 3}", ms=4, label=f"{k}: speed / bound - 1")
        ax_c.plot(it[active], g[active], "o", color="k", ms=7, mfc="none")
    ax_c.plot([], [], "o", color="k", mfc="none", label=f"active (|.| < {ACTIVE:g})")
    ax_c.set_yscale("symlog", linthresh=ACTIVE)
    ax_c.axhline(0.0, color="k", lw=0.8)
    ax_c.axhspan(-ACTIVE, ACTIVE, color="0.85", lw=0)
    ax_c.legend(fontsize=7)
    ax_c.set_ylabel("constraint margin [-]\n(< 0 violated)")


def _variables(ax_x, it, h: list, bounds: dict, active: list) -> None:
    """Each design variable between its bounds (0 lower, 1 upper)."""
    for n, name in enumerate(bounds):
        lo, hi = bounds[name]
        x = np.array([r["variables"][name] for r in h], dtype=float)
        at = "bound " + name in active
        ax_x.plot(
            it,
            (x - lo) / (hi - lo),
            "o-",
            ms=4,
            color=f"C{n}",
            label=f"{name} [{lo:.4g}, {hi:.4g}]" + (" (at a bound)" if at else ""),
        )
    for edge in (0.0, 1.0):
        ax_x.axhline(edge, color="k", ls=":", lw=0.8)
    ax_x.set_ylim(-0.08, 1.08)
    ax_x.set_ylabel("variable in its bounds\n(0 lower, 1 upper)")
    ax_x.set_xlabel("SLSQP iteration")
    ax_x.legend(fontsize=7)
    ax_x.xaxis.get_major_locator().set_params(integer=True)
