"""The result of a limit-cycle study: the verdict of every march, the table, the summary.

Amplitudes are those of the rotation of the reference element (the first nonlinear hinge):
half its peak-to-peak over the settled window (``amplitude``) and its RMS about the window mean
(``rms``) [rad], and both per total gap (``*_per_gap``). A *sustained oscillation* is a march
that settled in a bounded, stationary motion of any class: periodic (``kind`` "lco", a limit
cycle), "quasi-periodic" or "chaotic" (:data:`aeroservo.simulate.lco_detect.SUSTAINED`); the
onset and the summary's ranges count all three, each class named. Figures: :mod:`.plots`.
"""

from __future__ import annotations

import numpy as np

from ...result_shape import Result
from ...simulate.lco_detect import SUSTAINED

__all__ = ["LCOResult", "TABLE_COLUMNS", "NOT_SETTLED", "describing_lines", "class_ranges"]

NOT_SETTLED = ("unsettled", "undecided", "failed")
"""Verdicts of marches that settled in nothing the study can name."""

TABLE_COLUMNS = (
    "start",
    "speed",
    "initial",
    "kind",
    "confidence",
    "frequency",
    "modulation",
    "amplitude",
    "rms",
    "mean",
    "amplitude_per_gap",
    "rms_per_gap",
    "growth",
    "switches_per_second",
    "reason",
)
"""Columns of :attr:`LCOResult.table` (SI: m/s, rad, Hz, 1/s). ``frequency`` is the
fundamental of a limit cycle, the strongest line of the spectrum of a quasi-periodic or chaotic
oscillation; ``modulation`` the frequency of a quasi-periodic one's modulation."""


class LCOResult(Result):
    """Verdicts of the marches of a study and the describing-function branches.

    A result of the common shape (:mod:`aeroservo.result_shape`): :meth:`summary`,
    :attr:`table` (one row per march), :meth:`plot` (``"bifurcation"``, ``"histories"``),
    :meth:`to_json` and :meth:`save` (the ``.json`` of ``aeroservo lco`` with its files).

    Attributes
    ----------
    rows : list of dict
        One per march: ``start`` ("point", "up" or "down"), ``speed`` [m/s], ``initial``
        rotation [rad] (nan for a sweep's march that starts from the state carried on),
        ``kind`` (sustained: lco (periodic), quasi-periodic, chaotic; otherwise decay, growing,
        divergence, unsettled, undecided, failed), ``confidence``, ``reason``, ``frequency``
        and ``modulation`` [Hz], ``amplitude`` and ``rms`` [rad] of the reference rotation, per
        gap, ``peaks``/``rmss`` of every recorded signal, and ``history`` (the end of the
        march).
    settings : dict
        What was run (elements, laws, speeds, amplitudes, duration, controller, timing, notes).
    branches : DescribingBranches or None
    """

    FIGURES = {"bifurcation": "_bifurcation_figure", "histories": "plot_histories"}

    def __init__(self, rows: list, settings: dict, branches=None):
        self.rows = list(rows)
        self.settings = dict(settings)
        self.branches = branches

    def __repr__(self) -> str:
        return (
            f"LCOResult({self.settings.get('name', '')!r}, {len(self.rows)} marches, "
            f"onset {self.onset():.4g} m/s)"
        )

    @property
    def gap(self) -> float | None:
        return self.settings.get("gap")

    def table_rows(self, start: str | None = None) -> list[dict]:
        """Rows without histories, the columns :data:`TABLE_COLUMNS` (of one ``start`` kind,
        ``"point"``, ``"up"`` or ``"down"``, if given)."""
        return [
            {k: r[k] for k in TABLE_COLUMNS}
            for r in self.rows
            if start is None or r["start"] == start
        ]

    @property
    def table(self):
        """One row per march, the columns :data:`TABLE_COLUMNS` (pandas DataFrame; SI: m/s,
        rad, Hz, 1/s; NaN where a number is undefined)."""
        import pandas as pd

        return pd.DataFrame(self.table_rows(), columns=list(TABLE_COLUMNS))

    def to_dict(self) -> dict:
        """The settings, every march's row without its history and the describing-function
        branches (JSON values, SI units)."""
        b = self.branches
        return {
            "name": self.settings.get("name", ""),
            "settings": dict(self.settings),
            "rows": [{k: v for k, v in r.items() if k != "history"} for r in self.rows],
            "branches": None
            if b is None
            else {"gap": b.gap, "element": b.element, "names": list(b.names), "table": b.table()},
        }

    @property
    def figure_kinds(self) -> tuple[str, ...]:
        """``bifurcation``, and ``histories`` when the marches kept time histories."""
        has = any(r.get("history") for r in self.rows)
        return ("bifurcation", "histories") if has else ("bifurcation",)

    def lco_rows(self) -> list[dict]:
        """The marches that settled in a limit cycle (periodic)."""
        return [r for r in self.rows if r["kind"] == "lco"]

    def sustained_rows(self) -> list[dict]:
        """The marches that settled in a sustained oscillation of any class (periodic,
        quasi-periodic, chaotic)."""
        return [r for r in self.rows if r["kind"] in SUSTAINED]

    def onset(self, kinds=tuple(SUSTAINED)) -> float:
        """Lowest speed [m/s] where any march settled in a sustained oscillation of one of
        ``kinds`` (default every class; ``("lco",)``: periodic ones only); nan if none."""
        v = [r["speed"] for r in self.rows if r["kind"] in kinds]
        return float(min(v)) if v else float("nan")

    def diverged_from(self) -> float:
        """Lowest speed [m/s] where a march diverged (nan if none)."""
        v = [r["speed"] for r in self.rows if r["kind"] == "divergence"]
        return float(min(v)) if v else float("nan")

    def hysteresis(self) -> list[float]:
        """Speeds [m/s] where the up and down sweeps end in different states (different
        verdicts, or limit cycles whose amplitudes, irregular oscillations whose RMS, differ
        by more than 5 %)."""
        up = {r["speed"]: r for r in self.rows if r["start"] == "up"}
        down = {r["speed"]: r for r in self.rows if r["start"] == "down"}
        out = []
        for v in sorted(set(up) & set(down)):
            a, b = up[v], down[v]
            # a limit cycle by its amplitude, an irregular oscillation by its RMS (its peaks
            # are those of single excursions)
            size = "amplitude" if a["kind"] == "lco" else "rms"
            if a["kind"] != b["kind"]:
                out.append(v)
            elif a["kind"] in SUSTAINED and abs(a[size] - b[size]) > 0.05 * max(a[size], b[size]):
                out.append(v)
        return out

    def summary_text(self) -> str:
        """Deprecated: :meth:`summary`."""
        import warnings

        warnings.warn("summary_text() is summary()", DeprecationWarning, stacklevel=2)
        return self.summary()

    def summary(self) -> str:
        """A few lines a flutter engineer reads first."""
        s = self.settings
        gap = self.gap
        lines = [
            f"{s.get('name', 'lco')}: {len(self.rows)} marches of {s.get('duration', 0):g} s "
            f"({s.get('controller', '')}), elements {', '.join(s.get('elements', []))}: "
            f"{'; '.join(s.get('laws', []))}",
        ]
        ranges = class_ranges(self)
        if ranges:
            k, unit = (1.0 / gap, "x gap") if gap else (1.0, "rad")
            speeds = [self.onset(), max(r["speed"] for r in self.sustained_rows())]
            lines.append(
                f"sustained oscillations {_span(speeds, '.4g', 'from')} m/s (half peak-to-peak "
                f"and RMS of {s.get('reference')}):"
            )
            for name, c in ranges.items():
                lines.append(
                    f"  {name} at {_speeds_text(c['speeds'])} m/s: amplitude "
                    f"{_span(c['amplitude_range'], '.3g', scale=k)} {unit}, RMS "
                    f"{_span(c['rms_range'], '.3g', scale=k)} {unit}, "
                    f"{_span(c['frequency_range'], '.3g')} Hz"
                    + ("" if name == "periodic" else " (the spectrum's strongest line)")
                    + (
                        f", modulated at {_span(c['modulation_range'], '.3g')} Hz"
                        if c["modulation_range"]
                        else ""
                    )
                )
        else:
            lines.append(
                "no sustained oscillation (periodic, quasi-periodic or chaotic) at any speed"
            )
        dv = self.diverged_from()
        if np.isfinite(dv):
            lines.append(f"divergent motion from {dv:.4g} m/s")
        grow = sorted({r["speed"] for r in self.rows if r["kind"] == "growing"})
        if grow:
            lines.append(
                "still growing at the end of the march (not settled; march longer) at "
                + ", ".join(f"{v:.4g}" for v in grow)
                + " m/s"
            )
        hyst = self.hysteresis()
        if hyst:
            lines.append(
                "hysteresis (up and down sweeps differ) at "
                + ", ".join(f"{v:.4g}" for v in hyst)
                + " m/s"
            )
        other = [r for r in self.rows if r["kind"] in NOT_SETTLED]
        if other:
            lines.append(
                f"{len(other)} marches not settled ({', '.join(NOT_SETTLED)}): see the "
                "table's reason column"
            )
        lines += describing_lines(self)
        lines += list(s.get("notes", []))
        return "\n".join(lines)

    def plot_bifurcation(self, ax=None, **kw):
        """The bifurcation diagram (:func:`.plots.plot_bifurcation`): its Axes."""
        from .plots import plot_bifurcation

        return plot_bifurcation(self, ax=ax, **kw)

    def _bifurcation_figure(self, **kw):
        return self.plot_bifurcation(**kw).figure

    def plot_histories(self, speeds=None, **kw):
        """Example time histories (:func:`.plots.plot_histories`)."""
        from .plots import plot_histories

        return plot_histories(self, speeds=speeds, **kw)


def describing_lines(result) -> list[str]:
    """The describing-function prediction against the marches: where its stable limit cycles
    (every other root damped) lie, and its amplitude and frequency at the speeds where the
    marches settled in one."""
    b = result.branches
    if b is None or not len(b.speed):
        return []
    seen = b.stable & (b.others_stable if b.others_stable is not None else True)
    if not seen.any():
        return ["describing function: no stable limit cycle with every other root damped"]
    lines = [
        f"describing function: stable limit cycles (every other root damped) from "
        f"{b.speed[seen].min():.4g} to {b.speed[seen].max():.4g} m/s, "
        f"{b.frequency[seen].min():.3g}-{b.frequency[seen].max():.3g} Hz"
    ]
    onset = result.onset(("lco",))  # a describing function predicts periodic motion
    marched = min(r["speed"] for r in result.rows)
    early = b.speed[seen & (b.speed >= marched)]  # within the marched speeds only
    if np.isfinite(onset) and early.size and early.min() < 0.9 * onset:
        lines.append(
            f"  it predicts limit cycles below {onset:.4g} m/s, where no march settles in a "
            f"periodic one (down to {early.min():.4g} m/s): near the gap edges the motion is "
            "far from the one harmonic it keeps"
        )
    errs = []
    for r in result.lco_rows():
        hit = _branch_at(b, seen, r["speed"], r["frequency"])
        if hit is not None:
            errs.append((hit[0] / r["amplitude"] - 1.0, hit[1] / r["frequency"] - 1.0))
    if errs:
        e = np.array(errs)
        lines.append(
            f"  against the {len(errs)} settled marches on such a branch (interpolated at their "
            f"speed, frequency within 20 %): amplitude {100 * e[:, 0].min():+.1f} "
            f"to {100 * e[:, 0].max():+.1f} %, frequency {100 * e[:, 1].min():+.1f} to "
            f"{100 * e[:, 1].max():+.1f} %"
        )
    return lines


def _branch_at(b, seen, speed: float, freq: float):
    """``(amplitude, frequency)`` of the describing function interpolated at ``speed`` between
    two points of neighbouring amplitudes (or the same amplitude: across a fold) whose
    frequencies are within 3 % (the same limit cycle), both stable and the one nearer in speed
    seen (every other root damped); of the candidates, the one nearest in frequency within 20 %
    of ``freq``; None if no branch passes there."""
    amps = np.unique(b.amplitude)
    best = None
    for a0, a1 in zip(amps, np.r_[amps[1:], np.inf], strict=True):
        here = np.flatnonzero(b.amplitude == a0)
        for i in here:
            for j in np.flatnonzero((b.amplitude == a1) | (b.amplitude == a0)):
                v0, v1 = b.speed[i], b.speed[j]
                if i == j or v0 == v1 or not min(v0, v1) <= speed <= max(v0, v1):
                    continue
                if abs(b.frequency[j] / b.frequency[i] - 1.0) > 0.03:
                    continue
                w = (speed - v0) / (v1 - v0)
                if not (b.stable[i] and b.stable[j] and seen[i if w < 0.5 else j]):
                    continue
                f = (1 - w) * b.frequency[i] + w * b.frequency[j]
                a = (1 - w) * b.amplitude[i] + w * b.amplitude[j]
                if abs(f / freq - 1.0) < 0.2 and (
                    best is None or abs(f - freq) < abs(best[1] - freq)
                ):
                    best = (a, f)
    return best


def class_ranges(result) -> dict:
    """Per class of sustained oscillation (``"periodic"``, ``"quasi-periodic"``,
    ``"chaotic"``, in that order, those present): its ``speeds`` [m/s] and the ranges
    ``[min, max]`` of ``amplitude`` and ``rms`` [rad], ``frequency`` and ``modulation`` [Hz]
    (``None`` where no march has one) over its marches."""
    out = {}
    for kind, name in SUSTAINED.items():
        rows = [r for r in result.rows if r["kind"] == kind]
        if not rows:
            continue
        out[name] = {"speeds": sorted({r["speed"] for r in rows})}
        for key in ("amplitude", "rms", "frequency", "modulation"):
            v = [r[key] for r in rows if np.isfinite(r.get(key, np.nan))]
            out[name][f"{key}_range"] = [min(v), max(v)] if v else None
    return out


def _speeds_text(speeds) -> str:
    """``4, 5, 6`` or ``4 to 9 (6 speeds)``."""
    if len(speeds) <= 4:
        return ", ".join(f"{v:.4g}" for v in speeds)
    return f"{speeds[0]:.4g} to {speeds[-1]:.4g} ({len(speeds)} speeds)"


def _span(v, fmt: str, lead: str = "", scale: float = 1.0) -> str:
    """``lo to hi`` (with ``lead`` before: ``from lo to hi``), or the one value when they are
    equal (``at v``); ``?`` for ``None``."""
    if not v:
        return "?"
    lo, hi = (format(x * scale, fmt) for x in v)
    if lo == hi:
        return f"at {lo}" if lead else lo
    return f"{lead} {lo} to {hi}" if lead else f"{lo} to {hi}"
