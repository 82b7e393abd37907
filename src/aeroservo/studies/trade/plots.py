"""Figures of a trade study: heat map of a metric over two parameters, Pareto front."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...errors import InputError, check_int, check_number
from .study import METRICS, PARAMETERS

__all__ = ["pareto_front"]


def _label(name: str) -> str:
    unit = (PARAMETERS.get(name) or METRICS.get(name) or ("-",))[0]
    return f"{name} [{unit}]"


def _heatmap(ds, parameters: dict, metric: str, x, y, fixed: dict):
    from matplotlib.figure import Figure

    names = list(parameters)
    if metric not in METRICS:
        raise InputError(f"metric = {metric!r}: unknown; known are {list(METRICS)}")
    if len(names) < 2:
        raise InputError(f"heatmap: needs two swept parameters; this study sweeps {names}")
    x = names[0] if x is None else x
    y = (names[1] if names[1] != x else names[0]) if y is None else y
    for key, v in (("x", x), ("y", y)):
        if v not in names:
            raise InputError(f"{key} = {v!r}: not a swept parameter; swept are {names}")
    if x == y:
        raise InputError(f"x = y = {x!r}: give two different parameters")
    sel: dict = {}
    for k, v in fixed.items():
        if k not in names or k in (x, y):
            others = [n for n in names if n not in (x, y)]
            raise InputError(f"{k} = {v!r}: not a parameter to fix; the others are {others}")
        vals = parameters[k]
        if isinstance(v, (int, np.integer)) and not isinstance(v, bool):
            sel[k] = check_int(f"{k} (index)", v, lo=0, hi=len(vals) - 1)
        else:
            v = check_number(k, v)
            sel[k] = int(np.argmin(np.abs(np.asarray(vals) - v)))
    for k in names:
        if k not in (x, y):
            sel.setdefault(k, 0)
    da = ds[metric].isel(sel).transpose(y, x)
    z = np.ma.masked_invalid(np.asarray(da.values, dtype=float))
    failed = np.asarray(ds["status"].isel(sel).transpose(y, x).values).astype(str) != "ok"
    xs, ys = parameters[x], parameters[y]

    fig = Figure(
        layout="constrained", figsize=(1.2 + 0.9 * max(len(xs), 4), 1.0 + 0.6 * max(len(ys), 4))
    )
    ax = fig.subplots()
    import matplotlib

    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="0.85")
    im = ax.imshow(z, origin="lower", aspect="auto", cmap=cmap, interpolation="nearest")
    ax.set_xticks(range(len(xs)), [f"{v:.4g}" for v in xs])
    ax.set_yticks(range(len(ys)), [f"{v:.4g}" for v in ys])
    ax.set_xlabel(_label(x))
    ax.set_ylabel(_label(y))
    fig.colorbar(im, ax=ax, label=_label(metric))
    if z.size <= 400:
        lo, hi = (float(z.min()), float(z.max())) if z.count() else (0.0, 1.0)
        for (i, j), v in np.ndenumerate(z.filled(np.nan)):
            if np.isfinite(v):
                dark = (v - lo) < 0.5 * (hi - lo) if hi > lo else True
                ax.text(
                    j,
                    i,
                    f"{v:.4g}",
                    ha="center",
                    va="center",
                    fontsize=7,
                    color="w" if dark else "k",
                )
            else:
                text = "failed" if failed[i, j] else "n/a"
                ax.text(j, i, text, ha="center", va="center", fontsize=7, color="0.4")
    rest = [f"{k} = {parameters[k][i]:.4g}" for k, i in sel.items()]
    ax.set_title(f"{metric}" + (f" ({', '.join(rest)})" if rest else ""), fontsize=9)
    return fig


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


def _pareto(table, name: str):
    from matplotlib.figure import Figure

    t = table
    ok = (t["status"] == "ok").to_numpy()
    margin = t["suppression_margin"].to_numpy(dtype=float).copy()
    # stable up to the end of the search: the margin is at least v_max / V_ol - 1
    bound = (
        ok
        & ~np.isfinite(margin)
        & (t["stable_at_design"].to_numpy(dtype=float) == 1.0)
        & np.isfinite(t["closed_loop_v_max"].to_numpy(dtype=float))
    )
    v_ol = t["open_loop_flutter_speed"].to_numpy(dtype=float)
    margin[bound] = t["closed_loop_v_max"].to_numpy(dtype=float)[bound] / v_ol[bound] - 1.0
    peak = t["hinge_moment_peak"].to_numpy(dtype=float)
    usable = ok & np.isfinite(margin) & np.isfinite(peak)
    unstable = usable & (t["stable_at_design"].to_numpy(dtype=float) != 1.0)
    front = pareto_front(np.where(usable & ~unstable, margin, np.nan), peak)

    fig = Figure(layout="constrained", figsize=(6.5, 4.5))
    ax = fig.subplots()
    plain = usable & ~front & ~bound & ~unstable
    ax.scatter(peak[plain], margin[plain], s=18, color="C0", alpha=0.6, label="case")
    if bound.any():
        ax.scatter(
            peak[bound & usable],
            margin[bound & usable],
            marker="^",
            s=30,
            color="C2",
            label="stable to search limit (margin >=)",
        )
    if unstable.any():
        ax.scatter(
            peak[unstable],
            margin[unstable],
            marker="x",
            s=30,
            color="C3",
            label="unstable at design speed",
        )
    if front.any():
        order = np.argsort(peak[front])
        ax.plot(
            peak[front][order], margin[front][order], "o-", color="C1", ms=6, label="Pareto front"
        )
    n_bad = int((~usable).sum())
    ax.set_xlabel(_label("hinge_moment_peak"))
    ax.set_ylabel(_label("suppression_margin"))
    ax.axhline(0.0, color="k", lw=0.8)
    ax.grid(True, alpha=0.3)
    ax.set_title(
        f"{name}: {int(usable.sum())} cases" + (f", {n_bad} without result" if n_bad else ""),
        fontsize=9,
    )
    if usable.any():
        ax.legend(fontsize=8)
    return fig
