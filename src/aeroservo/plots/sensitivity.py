"""Bar chart of normalized flutter-speed sensitivities (:mod:`aeroservo.stability.sensitivity`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .._figures import new_figure

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..stability.sensitivity import FlutterSensitivities

__all__ = ["plot_sensitivities"]


def plot_sensitivities(s: FlutterSensitivities, *, top: int = 20, title: str = "") -> Figure:
    """Horizontal bars of ``p / V_f dV_f/dp`` (and of the divergence speed's, if any).

    Parameters
    ----------
    s : FlutterSensitivities
    top : int
        Largest ``top`` parameters by magnitude (default 20).
    title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    flutter = s.normalized() if s.d_flutter_speed else {}
    div = (
        {k: s.values[k] * d / s.divergence_speed for k, d in s.d_divergence_speed.items()}
        if s.d_divergence_speed
        else {}
    )
    names = sorted(
        set(flutter) | set(div), key=lambda k: -max(abs(flutter.get(k, 0.0)), abs(div.get(k, 0.0)))
    )
    names = names[:top][::-1]
    fig = new_figure(figsize=(8.0, 1.2 + 0.32 * max(len(names), 1)))
    ax = fig.add_subplot()
    y = np.arange(len(names))
    h = 0.4 if div and flutter else 0.7
    if flutter:
        vf = f"V_f = {s.flutter_speed:.4g} m/s"
        ax.barh(y + (h / 2 if div else 0), [flutter.get(k, 0.0) for k in names], h, label=vf)
    if div:
        vd = f"V_d = {s.divergence_speed:.4g} m/s"
        ax.barh(y - (h / 2 if flutter else 0), [div.get(k, 0.0) for k in names], h, label=vd)
    ax.set_yticks(y, names, fontsize=8)
    ax.axvline(0.0, color="k", lw=0.8)
    ax.set_xlabel("normalized sensitivity  (p / V) dV/dp  [% of speed per % of parameter]")
    note = f" (flutter: {s.non_differentiable})" if s.non_differentiable else ""
    where = f", rho = {s.density:.4g} kg/m^3"
    if s.altitude is not None:
        where = f", {s.altitude:.5g} m ({s.density:.4g} kg/m^3)"
    if s.mach:
        where += f", Mach {s.mach:.3g}" + (" matched" if s.matched else "")
    ax.set_title((title or "Speed sensitivities") + where + note, fontsize=9)
    if flutter or div:
        ax.legend(fontsize=8, loc="best")
    ax.grid(axis="x", alpha=0.3)
    return fig
