"""The result of a gust-loads study as data: one record per flight point and loop, the time
histories of the critical gusts, the limit-load table, the worst case per load and the
gust-load-alleviation effect of the loop.

Records are plain JSON values (SI units, radians) and the histories numpy arrays, so that a
result written by :mod:`aeroservo.files.gust_loads_file` reads back into the same object and
every figure (:mod:`aeroservo.studies.gust.plots`) redraws from it.

Definitions:

* discrete limit load of a load at a point: ``max(|maximum|, |minimum|)`` of its tuned
  discrete gusts (incremental);
* turbulence limit load: ``U_sigma A_bar``;
* limit load: the larger of the two;
* 1 g load (with the airplane's mass of the mass case): the static aeroelastic trim of the
  wing (:mod:`~aeroservo.studies.gust.one_g`); total limit loads ``1 g + max(discrete max,
  U_sigma A_bar)`` and ``1 g + min(discrete min, -U_sigma A_bar)``;
* rigid ratio (root and station shear, bending moment, torque): the discrete limit load over
  the rigid clamped wing's quasi-static load in the largest design gust
  (:mod:`~aeroservo.studies.gust.rigid_wing`), a check: near 1 for a stiff wing in a long gust;
* gust load alleviation of the loop (per load and per point, discrete and turbulence):
  ``100 (1 - closed / open)`` [%] of the limit loads; a loop **raises** a load when the closed
  loop's limit load exceeds the open loop's by more than :data:`RAISE_TOLERANCE`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from ...result_shape import Result
from .records import totals

__all__ = ["GustLoadsResult", "RAISE_TOLERANCE"]

RAISE_TOLERANCE = 1e-3
"""Relative increase of a limit load above which the loop is said to raise it (0.1 %: ten
times the accuracy of the sampled march against the exact one, ``docs/gust-loads.md``)."""


@dataclass
class GustLoadsResult(Result):
    """Records of a gust-loads study (see the module docstring).

    A result of the common shape (:mod:`aeroservo.result_shape`): :meth:`summary`,
    :attr:`table` (limit loads), :meth:`plot` (``"envelope"``, ``"correlated"``,
    ``"critical-gusts"``, ``"spanwise"``: the figures ``aeroservo loads`` writes),
    :meth:`to_json` and :meth:`save` (its ``.json`` with the ``.npz``, ``.csv`` next to it).

    Attributes
    ----------
    name : str
    records : list of dict
        One per flight point and loop (``"open"``, ``"closed"``).
    arrays : dict
        History arrays by key (``<key>_t`` [s], ``<key>_gust`` [m/s], ``<key>_y``).
    units : dict
        Load units.
    settings : dict
        The study's settings (JSON values).
    """

    name: str
    records: list
    arrays: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)

    FIGURES = {
        "envelope": "plot_envelope",
        "correlated": "plot_correlated",
        "critical-gusts": "plot_critical_gusts",
        "spanwise": "plot_spanwise",
    }

    @property
    def loads(self) -> list[str]:
        """Load names, in the order of the first record."""
        names: list[str] = []
        for r in self.records:
            names += [n for n in r["loads"] if n not in names]
        return names

    @property
    def loops(self) -> list[str]:
        """``"open"`` and/or ``"closed"``."""
        return [lp for lp in ("open", "closed") if any(r["loop"] == lp for r in self.records)]

    @property
    def table(self):
        """Limit loads: one row per flight point, loop and load (pandas DataFrame)."""
        import pandas as pd

        rows = []
        for r in self.records:
            for name, v in r["loads"].items():
                turb = v.get("turbulence", np.nan)
                rows.append(
                    {
                        "point": r["point"],
                        "mass_case": r["mass_case"],
                        "altitude_m": r["altitude"],
                        "speed": r["speed_name"],
                        "eas_m_s": r["eas"],
                        "tas_m_s": r["tas"],
                        "f_g": r["f_g"],
                        "u_sigma_m_s": r["u_sigma"],
                        "loop": r["loop"],
                        "load": name,
                        "unit": v["unit"],
                        "discrete_max": v["max"],
                        "max_gradient_m": v["max_gradient"],
                        "max_time_s": v["max_time"],
                        "max_sign": v["max_sign"],
                        "discrete_min": v["min"],
                        "min_gradient_m": v["min_gradient"],
                        "min_time_s": v["min_time"],
                        "min_sign": v["min_sign"],
                        "a_bar": v.get("a_bar", np.nan),
                        "n0_hz": v.get("n0", np.nan),
                        "turbulence": turb,
                        "limit": np.nanmax([v["discrete"], turb]),
                        "rigid_ratio": v["discrete"] / v["rigid"] if v.get("rigid") else np.nan,
                        **totals(v, turb),
                        "time_at_limit_s": max(r["time_at_limit"].values(), default=0.0),
                    }
                )
        return pd.DataFrame(rows)

    def worst(self, loop: str = "closed"):
        """The largest limit load of each load over every flight point and mass case of
        ``loop`` (``"open"`` or ``"closed"``): a DataFrame indexed by load."""
        if loop not in self.loops:
            raise InputError(f"loop = {loop!r}: the result has {self.loops}")
        t = self.table
        t = t[t["loop"] == loop]
        rows = t.loc[t.groupby("load", sort=False)["limit"].idxmax()]
        turb = rows["turbulence"] > rows[["discrete_max", "discrete_min"]].abs().max(axis=1)
        linear = "turbulence (linear loop; the actuator saturates in the gusts)"
        rows = rows.assign(
            source=np.where(
                turb, np.where(rows["time_at_limit_s"] > 0, linear, "turbulence"), "discrete"
            )
        )
        return rows.set_index("load")

    @property
    def alleviation(self):
        """Gust load alleviation of the loop per flight point and load [%] (DataFrame), and
        ``raised``: the loop raises the discrete or turbulence limit load."""
        import pandas as pd

        if self.loops != ["open", "closed"]:
            raise InputError(
                "gust load alleviation needs both loops at a flight point; this result has "
                f"{self.loops or 'none'}"
            )
        t = self.table
        key = ["point", "load"]
        o = t[t["loop"] == "open"].set_index(key)
        c = t[t["loop"] == "closed"].set_index(key)
        both = o.index.intersection(c.index)
        out = pd.DataFrame(index=both)
        for what in ("discrete", "turbulence"):
            if what == "discrete":
                ov = o.loc[both, ["discrete_max", "discrete_min"]].abs().max(axis=1)
                cv = c.loc[both, ["discrete_max", "discrete_min"]].abs().max(axis=1)
            else:
                ov, cv = o.loc[both, "turbulence"], c.loc[both, "turbulence"]
            out[f"{what}_open"], out[f"{what}_closed"] = ov, cv
            out[f"{what}_alleviation_pct"] = 100.0 * (1.0 - cv / ov)
        rel = np.fmax(
            out["discrete_closed"] / out["discrete_open"],
            out["turbulence_closed"] / out["turbulence_open"],
        )
        out["raised"] = rel > 1.0 + RAISE_TOLERANCE
        return out.reset_index()

    def raised_loads(self) -> list[str]:
        """One line per load the loop raises, at its worst flight point."""
        if self.loops != ["open", "closed"]:
            return []
        a = self.alleviation
        lines = []
        for load, g in a[a["raised"]].groupby("load", sort=False):
            k = g[["discrete_alleviation_pct", "turbulence_alleviation_pct"]].min(axis=1).idxmin()
            row = g.loc[k]
            rec = next(r for r in self.records if r["point"] == row["point"])
            parts = [
                f"{what} {-row[f'{what}_alleviation_pct']:+.1f} %"
                for what in ("discrete", "turbulence")
                if np.isfinite(row[f"{what}_alleviation_pct"])
            ]
            if not parts:  # open-loop load zero
                parts = [f"{load} is zero open loop and {row['discrete_closed']:.4g} closed"]
            lines.append(f"the loop raises {load} at {_point_label(rec)}: " + ", ".join(parts))
        return lines

    def history(self, point: int, loop: str, load: str, side: str = "max"):
        """``(t [s], gust [m/s true], {load: values})`` of the gust critical for ``load``."""
        rec = self.record(point, loop)
        if load not in rec["histories"]:
            raise InputError(f"load {load!r}: not in the result ({list(rec['histories'])})")
        key = rec["histories"][load][side]
        y = self.arrays[key + "_y"]
        names = rec["history_loads"]
        return (
            self.arrays[key + "_t"],
            self.arrays[key + "_gust"],
            {n: y[:, i] for i, n in enumerate(names)},
        )

    def record(self, point: int, loop: str) -> dict:
        """The record of flight point ``point`` (its index) and ``loop``."""
        for r in self.records:
            if r["point"] == point and r["loop"] == loop:
                return r
        raise InputError(
            f"no record for point {point} and loop {loop!r} (points "
            f"{sorted({r['point'] for r in self.records})}, loops {self.loops})"
        )

    def summary_text(self) -> str:
        """Deprecated: :meth:`summary`."""
        import warnings

        warnings.warn("summary_text() is summary()", DeprecationWarning, stacklevel=2)
        return self.summary()

    def to_dict(self) -> dict:
        """The study's name, load units, settings and every record (JSON values; the time
        histories are in :attr:`arrays`)."""
        return {
            "name": self.name,
            "units": dict(self.units),
            "settings": dict(self.settings),
            "records": self.records,
        }

    @property
    def figure_kinds(self) -> tuple[str, ...]:
        """The figures of :attr:`FIGURES` a run writes for this result (``correlated`` with
        both root bending moment and root torque, ``spanwise`` with station loads)."""
        from .plots import drawable

        can = drawable(self)
        return tuple(k for k in self.FIGURES if can.get(k.replace("-", "_"), True))

    def plot(self, kind: str | None = None, **kw):
        """A figure: without options, the one ``aeroservo loads`` writes for ``kind``
        (:func:`~aeroservo.studies.gust.plots.gust_figures`: with station loads the envelope
        and the critical gusts leave those to the spanwise figure); with options, the method
        :attr:`FIGURES` names (e.g. ``plot("correlated", x=..., y=...)``).

        Parameters
        ----------
        kind : {"envelope", "correlated", "critical-gusts", "spanwise"}, optional
            Default ``"envelope"``.
        """
        from .plots import gust_figures

        if kw or kind not in (None, *self.FIGURES):
            return super().plot(kind, **kw)
        kind = kind or "envelope"
        figs = gust_figures(self, (kind.replace("-", "_"),))
        if not figs:
            raise InputError(f"kind = {kind!r}: {self.missing(kind)}")
        return next(iter(figs.values()))

    def missing(self, kind: str) -> str:
        """Why the figure ``kind`` cannot be drawn from this result (one line)."""
        if not self.records:
            return "the result has no loads (no flight point was computed; its summary says why)"
        if kind == "spanwise":
            return "the result has not loads at two or more stations (root loads, load_stations)"
        return "the result has not both root_bending_moment and root_torque as loads"

    def summary(self) -> str:
        """A loads engineer's summary: worst limit load per load and loop, GLA, flags."""
        lines = [f"gust loads {self.name}: {len({r['point'] for r in self.records})} points"]
        if self.settings.get("loop_measures"):
            lines.append(f"  the closed loop feeds back {self.settings['loop_measures']}")
        for loop in self.loops:
            w = self.worst(loop)
            lines.append(f"  {loop} loop, worst limit load (incremental, clamped wing):")
            for load, row in w.iterrows():
                rec = self.record(int(row["point"]), loop)
                total = (
                    f" (1 g {row['one_g']:.5g}: total {row['total_min']:.5g} to "
                    f"{row['total_max']:.5g})"
                    if np.isfinite(row.get("one_g", np.nan))
                    else ""
                )
                lines.append(
                    f"    {load:28s} {row['limit']:12.5g} {row['unit']:7s} {row['source']:10s}"
                    f" at {_point_label(rec)}{total}"
                )
        seen = set()
        for r in self.records:
            t = r.get("trim") or {}
            if t and r["loop"] == self.loops[0]:
                lines.append(
                    f"  1 g trim at {_point_label(r)}: root angle of attack "
                    f"{np.degrees(t['alpha_rad']):.3f} deg, lift {t['lift_N']:.5g} N, wing weight "
                    f"{t['weight_N']:.5g} N"
                )
        for r in self.records:
            for note in r["notes"]:  # a point's notes are in each of its loops' records
                if (r["point"], note) not in seen:
                    seen.add((r["point"], note))
                    lines.append(f"  note, {_point_label(r)}: {note}")
            sat = {c: s for c, s in r["time_at_limit"].items() if s > 0}
            if sat:
                parts = ", ".join(f"{c} for up to {s:.3g} s in a gust" for c, s in sat.items())
                lines.append(
                    f"  {r['loop']} loop at {_point_label(r)}: actuator limit hit ({parts})"
                )
        for sk in self.settings.get("skipped_points", []):
            why = "; ".join(sk["notes"]) or "no loop computed"
            lines.append(f"  NO LOADS at point {sk['point']} ({sk['flight_point']}): {why}")
        for line in self.raised_loads() + list(self.settings.get("warnings", [])):
            lines.append(f"  WARNING: {line}")
        return "\n".join(lines)

    # figures (aeroservo.studies.gust.plots): thin delegates, matplotlib imported on use

    def plot_envelope(self):
        """Limit loads per flight point (:func:`~aeroservo.studies.gust.plots.plot_envelope`)."""
        from .plots import plot_envelope

        return plot_envelope(self)

    def plot_correlated(self, x="root_bending_moment", y="root_torque", *, point=None, loop=None):
        """Correlated loads x against y with the discrete-gust points and the turbulence design
        ellipse (:func:`~aeroservo.studies.gust.plots.plot_correlated`)."""
        from .plots import plot_correlated

        return plot_correlated(self, x, y, point=point, loop=loop)

    def plot_gust_history(self, point: int, load: str, side: str = "max"):
        """The critical gust of ``load`` at flight point ``point``
        (:func:`~aeroservo.studies.gust.plots.plot_gust_history`)."""
        from .plots import plot_gust_history

        return plot_gust_history(self, point, load, side)

    def plot_critical_gusts(self, loads=None, loop=None):
        """The critical gust of every load at its worst flight point
        (:func:`~aeroservo.studies.gust.plots.plot_critical_gusts`)."""
        from .plots import plot_critical_gusts

        return plot_critical_gusts(self, loads, loop)

    def plot_spanwise(self):
        """Limit loads along the span (:func:`~aeroservo.studies.gust.span_plots.plot_spanwise`)."""
        from .span_plots import plot_spanwise

        return plot_spanwise(self)

    def plot_tuning(self, point: int, load: str):
        """Peak load against the gust gradient H at a flight point
        (:func:`~aeroservo.studies.gust.plots.plot_tuning`)."""
        from .plots import plot_tuning

        return plot_tuning(self, point, load)


def _point_label(rec: dict) -> str:
    case = f"{rec['mass_case']} " if rec["mass_case"] else ""
    name = f" {rec['speed_name']}" if rec["speed_name"] else ""
    return f"{case}{rec['altitude']:g} m{name} {rec['eas']:.4g} m/s EAS"
