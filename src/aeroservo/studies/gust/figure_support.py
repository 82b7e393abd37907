"""What the gust-loads figures (:mod:`aeroservo.studies.gust.plots`) share: their arguments
checked against a :class:`~aeroservo.studies.gust.results.GustLoadsResult`, flight-point labels,
display units, notes and the critical gust of a load in a record."""

from __future__ import annotations

import math
import textwrap

import numpy as np

from ...errors import InputError

__all__ = [
    "DISPLAY_UNITS",
    "LOOP_COLORS",
    "INCREMENTAL",
    "point_indices",
    "check_point",
    "check_loops",
    "check_load",
    "check_side",
    "any_record",
    "record_of",
    "point_label",
    "display_unit",
    "axis_label",
    "point_notes",
    "footer",
    "panel_grid",
    "panel_columns",
    "place_legend",
    "critical_gust",
    "marker",
]

DISPLAY_UNITS = {
    "N": ("kN", 1e-3),
    "N m": ("kN m", 1e-3),
    "rad": ("deg", 180.0 / math.pi),
    "rad/s": ("deg/s", 180.0 / math.pi),
    "rad/s^2": ("deg/s^2", 180.0 / math.pi),
}
"""SI unit -> (unit shown, factor from SI)."""

LOOP_COLORS = {"open": "0.45", "closed": "tab:blue"}
"""Colour of each loop in every gust-loads figure."""

INCREMENTAL = "incremental loads, clamped wing (no 1 g)"
"""What every load of the figures is (said in their titles)."""


def point_indices(result) -> list[int]:
    """The flight point indices of a result."""
    return sorted({r["point"] for r in result.records})


def check_point(result, point) -> int:
    """``point`` if it is a flight point index of ``result``, else one line listing them."""
    points = point_indices(result)
    if isinstance(point, bool) or not isinstance(point, int | np.integer) or point not in points:
        shown = "; ".join(f"{p}: {point_label(any_record(result, p))}" for p in points)
        raise InputError(f"point = {point!r}: not a flight point of the result ({shown})")
    return int(point)


def check_loops(result, loop) -> list[str]:
    """The loops to draw: all of the result's (``loop`` None) or the one given."""
    if loop is None:
        return list(result.loops)
    if loop not in result.loops:
        raise InputError(f"loop = {loop!r}: the result has the loops {result.loops}")
    return [loop]


def check_load(result, load, key: str = "load") -> str:
    """``load`` if it is a load of ``result``, else one line listing them."""
    if load not in result.loads:
        raise InputError(f"{key} = {load!r}: not a load of the result; loads are {result.loads}")
    return load


def check_side(side) -> str:
    """``"max"`` or ``"min"``."""
    if side not in ("max", "min"):
        raise InputError(f"side = {side!r}: expected 'max' or 'min'")
    return side


def any_record(result, point: int) -> dict:
    """A record of flight point ``point`` (for its flight condition and notes)."""
    return next(r for r in result.records if r["point"] == point)


def record_of(result, point: int, loop: str) -> dict | None:
    """The record of ``point`` and ``loop``, None when the loop was not computed there."""
    return next((r for r in result.records if r["point"] == point and r["loop"] == loop), None)


def point_label(rec: dict, sep: str = " / ") -> str:
    """``mass case / altitude / V_C|V_D / EAS`` of a record's flight point."""
    parts = [rec["mass_case"], f"{rec['altitude']:g} m", rec["speed_name"], f"{rec['eas']:.4g}"]
    return sep.join(p for p in parts if p) + " m/s EAS"


def display_unit(result, load: str) -> tuple[str, float]:
    """(unit shown, factor from SI) of a load (:data:`DISPLAY_UNITS`)."""
    unit = result.units.get(load) or next(
        (r["loads"][load]["unit"] for r in result.records if load in r["loads"]), ""
    )
    return DISPLAY_UNITS.get(unit, (unit or "-", 1.0))


def axis_label(result, load: str) -> str:
    """``load [unit shown]``."""
    return f"{load} [{display_unit(result, load)[0]}]"


def point_notes(result, points: list[int], loops: list[str]) -> list[str]:
    """The notes of the points (loops missing or unstable) and the actuator saturation of the
    ``loops`` there, one line each."""
    lines = []
    for p in points:
        notes = dict.fromkeys(n for r in result.records if r["point"] == p for n in r["notes"])
        lines += [f"point {p} ({point_label(any_record(result, p))}): {n}" for n in notes]
        for lp in loops:
            rec = record_of(result, p, lp)
            for c, at_limit in (rec["time_at_limit"] if rec else {}).items():
                if at_limit > 0:
                    lines.append(
                        f"point {p}, {lp} loop: {c} at its limit for up to {at_limit:.3g} s "
                        "in a gust of the search"
                    )
    return lines


def footer(fig, lines: list[str]) -> None:
    """Notes in small type below the panels (wrapped to the figure's width)."""
    if lines:
        width = max(60, int(fig.get_figwidth() * 16))
        text = "\n".join("\n".join(textwrap.wrap(s, width, subsequent_indent="  ")) for s in lines)
        fig.supxlabel(text, fontsize=7, x=0.01, ha="left", color="0.2")


def panel_columns(n: int) -> int:
    """Columns of a grid of ``n`` small panels."""
    return 1 if n == 1 else (2 if n <= 4 else 3)


def panel_grid(fig, n: int, cols: int, **kw) -> tuple[list, list]:
    """``n`` axes on a grid of ``cols`` columns, and the spare cells' axes (hidden)."""
    rows = math.ceil(n / cols)
    axs = list(np.atleast_1d(fig.subplots(rows, cols, squeeze=False, **kw)).ravel())
    for ax in axs[n:]:
        ax.set_visible(False)
    return axs[:n], axs[n:]


def place_legend(fig, spare: list, handles: list) -> None:
    """The figure's legend in the first spare cell of its grid, else right of the panels (the
    bottom holds the notes)."""
    kw = dict(handles=handles, fontsize=7, frameon=False)
    if spare:
        spare[0].set_visible(True)
        spare[0].axis("off")
        spare[0].legend(loc="center", **kw)
    else:
        fig.legend(loc="outside right center", **kw)


def critical_gust(rec: dict, load: str, side: str) -> tuple[float, int, float, float, float]:
    """``(H [m], sign, U_ds [m/s TAS], value [SI], time [s])`` of the gust giving ``load``'s
    ``side`` in a record; ``U_ds`` from the scanned amplitudes, ``U_ds ~ H^(1/6)``
    (CS-25.341(a)(5))."""
    v = rec["loads"][load]
    h = float(v[f"{side}_gradient"])
    u_ds = rec["amplitudes"][0] * (h / rec["gradients"][0]) ** (1.0 / 6.0)
    return h, int(v[f"{side}_sign"]), u_ds, float(v[side]), float(v[f"{side}_time"])


def marker(symbol: str, label: str, **kw):
    """A legend entry of a marker alone."""
    from matplotlib.lines import Line2D

    return Line2D([], [], ls="", marker=symbol, label=label, **kw)
