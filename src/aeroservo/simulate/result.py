"""Time histories of a closed-loop simulation, with their limits, units and a standard figure."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..design.plant import Limits
from ..errors import InputError
from ..result_shape import Result

__all__ = ["SimulationResult", "WINDUP_RATIO", "windup_text", "LIMIT_SHOWN", "OPEN_LOOP_SCALE"]

WINDUP_RATIO = 3.0
"""A command beyond this many times its magnitude limit is reported as winding up (a loop that
holds its limits commands within about twice them: measured 1.2-1.9 x on the shipped loops
with anti-windup; the issue-38 run lost at 8.6 x was not flagged at the former 10 x)."""


LIMIT_SHOWN = 3.0
"""A magnitude limit is drawn on the time-history figure when it is within this many times the
signal's peak; otherwise it is named in the panel ("off scale")."""

_GROUPS = ("outputs", "commands", "applied", "disturbance")

OPEN_LOOP_SCALE = 2.0
"""An open-loop overlay is drawn up to where it leaves this many times the closed loop's peak."""


def _display_unit(unit: str) -> tuple[float, str]:
    """Factor and unit a signal is drawn in: angles in degrees, the rest as recorded."""
    if unit == "rad":
        return float(np.degrees(1.0)), "deg"
    if unit.startswith("rad/"):
        return float(np.degrees(1.0)), "deg/" + unit[len("rad/") :]
    return 1.0, unit


def _overlay(ax, t: np.ndarray, y_open: np.ndarray, y_closed: np.ndarray, unit: str) -> None:
    """The open-loop signal, dashed grey, up to where it leaves :data:`OPEN_LOOP_SCALE` x the
    closed loop's peak (marked, with the open loop's own peak named)."""
    bound = OPEN_LOOP_SCALE * float(np.max(np.abs(y_closed), initial=0.0))
    if not bound > 0:
        return
    out = np.flatnonzero(~(np.abs(y_open) <= bound))
    n = out[0] if out.size else y_open.size
    ax.plot(t[:n], y_open[:n], "--", color="0.45", lw=1.0, label="open loop")
    if out.size:
        yb = float(np.clip(y_open[n], -bound, bound))
        ax.plot(t[n], yb, ">", color="0.45", ms=5)
        finite = np.isfinite(y_open)
        top = f"{np.max(np.abs(y_open[finite])):.3g} {unit}" if finite.all() else "non-finite"
        ax.annotate(
            f"open loop leaves the scale at {t[n]:.3g} s\n(reaches {top})",
            (t[n], yb),
            xytext=(8, -4 if yb > 0 else 4),
            textcoords="offset points",
            fontsize=7,
            color="0.3",
            va="top" if yb > 0 else "bottom",
        )


def windup_text(wound: dict) -> str:
    """One line on the controls of :meth:`SimulationResult.windup`."""
    parts = [
        f"{c} commanded up to {w['peak_command']:.3g} against a limit of {w['limit']:.4g} "
        f"({w['ratio']:.3g} x; first beyond {WINDUP_RATIO:g} x at t = {w['first_time']:.4g} s)"
        for c, w in wound.items()
    ]
    return (
        "the controller's commands run away while the actuator saturates (windup, or a loop "
        "its limits cannot hold): " + "; ".join(parts)
    )


@dataclass
class SimulationResult(Result):
    """Time histories of a closed-loop simulation (SI units).

    A result of the common shape (:mod:`aeroservo.result_shape`): :meth:`summary`,
    :attr:`table` (one row per sample), :meth:`plot` (``"time"``), :meth:`to_json` and
    :meth:`save` (the ``.npz`` of ``aeroservo simulate``).

    Attributes
    ----------
    t : ndarray (n,)
        Sample times [s].
    outputs : dict
        Plant outputs by name (as measured, before sensor noise).
    commands, applied : dict
        Controller commands and the inputs actually applied (after limits), by control name.
    disturbance : dict
        Disturbance inputs by name (e.g. ``"gust"`` [m/s]).
    status : list of dict
        Controller status per sample (MPC: solver status, solve time [s], fallback used).
    limits : Limits
    units : dict
        Signal units.
    speed, density : float
    states : ndarray (n, n_states) or None
        Plant states, if recorded.
    wall_time : float
        Wall time of the time marching and output evaluation [s] (the discretization of the
        plant before it is not included).
    run_summary : dict
        Run summary of a result read back by :func:`aeroservo.files.results.load_result` (empty
        otherwise; it was the attribute ``summary`` before ``summary()`` became the text).
    """

    t: np.ndarray
    outputs: dict
    commands: dict
    applied: dict
    disturbance: dict
    status: list
    limits: Limits
    units: dict = field(default_factory=dict)
    speed: float = float("nan")
    density: float = float("nan")
    states: np.ndarray | None = None
    wall_time: float = 0.0
    run_summary: dict = field(default_factory=dict)

    FIGURES = {"time": "plot_time"}

    def signal(self, name: str) -> np.ndarray:
        """Any recorded signal by name."""
        for group in (self.outputs, self.applied, self.disturbance):
            if name in group:
                return group[name]
        known = list(self.outputs) + list(self.applied) + list(self.disturbance)
        raise InputError(f"signal {name!r}: not recorded; known: {known}")

    def at_limits(self) -> dict:
        """``{control: (at_magnitude, at_rate)}``: boolean arrays of the samples where what the
        plant receives sat on its magnitude limit and where it moved at its rate limit. With an
        actuator (outputs ``<c>_actuator``, ``<c>_actuator_rate``) that is its output; else the
        applied command (rate: its step from the previous sample, the first from zero)."""
        mag, rate = self.limits.arrays(list(self.applied))
        dt = float(self.t[1] - self.t[0]) if self.t.size > 1 else 0.0
        out = {}
        for i, (c, u) in enumerate(self.applied.items()):
            y, r = self.outputs.get(c + "_actuator"), self.outputs.get(c + "_actuator_rate")
            if y is not None and r is not None:  # at the stop, or the command clipped
                at_mag = (np.abs(y) >= mag[i] * (1 - 1e-12)) | (np.abs(u) >= mag[i] * (1 - 1e-12))
                at_rate = np.isfinite(rate[i]) & (np.abs(r) >= rate[i] * (1 - 1e-9))
            else:
                u = np.asarray(u, dtype=float)
                at_mag = np.abs(u) >= mag[i] * (1 - 1e-12)
                step = np.abs(np.diff(np.r_[0.0, u]))
                at_rate = np.isfinite(rate[i]) & (step >= rate[i] * dt * (1 - 1e-9)) & (dt > 0)
            out[c] = (at_mag, at_rate)
        return out

    @property
    def saturated_fraction(self) -> dict:
        """Share of samples at which each control sat on its magnitude limit [-]."""
        return {c: float(np.mean(m)) for c, (m, _) in self.at_limits().items()}

    def windup(self, ratio: float = WINDUP_RATIO) -> dict:
        """Controls whose commands ran away beyond their magnitude limit: ``{control:
        {"peak_command", "limit", "ratio", "first_time"}}`` for a peak ``|command|`` above
        ``ratio`` x the limit, or not finite, with the time [s] it first went beyond (empty:
        none)."""
        mag, _ = self.limits.arrays(list(self.commands))
        out = {}
        for i, (c, cmd) in enumerate(self.commands.items()):
            peak = float(np.max(np.abs(cmd))) if np.all(np.isfinite(cmd)) else float("inf")
            if np.isfinite(mag[i]) and peak > ratio * mag[i]:
                first = int(np.flatnonzero(~(np.abs(cmd) <= ratio * mag[i]))[0])
                out[c] = {
                    "peak_command": peak,
                    "limit": float(mag[i]),
                    "ratio": float(peak / mag[i]),
                    "first_time": float(self.t[min(first, self.t.size - 1)]),
                }
        return out

    @property
    def rate_limited_fraction(self) -> dict:
        """Share of samples at which each control moved at its rate limit [-]."""
        return {c: float(np.mean(r)) for c, (_, r) in self.at_limits().items()}

    def time_at_limit(self) -> dict:
        """Time [s] each control spent at its magnitude or rate limit (:meth:`at_limits`):
        the samples at either times the sample period (a measure that does not depend on the
        length of the march)."""
        dt = float(self.t[1] - self.t[0]) if self.t.size > 1 else 0.0
        return {c: float(np.count_nonzero(m | r)) * dt for c, (m, r) in self.at_limits().items()}

    def plot_time(
        self,
        tip: str | None = None,
        control: str | None = None,
        deflection: str | None = None,
        open_loop: SimulationResult | None = None,
    ):
        """Gust (if any), tip response, control input with its limits and commanded values,
        and surface deflection, against time (matplotlib Figure).

        Each axis is scaled to its signal. A magnitude limit is drawn (dotted red) when it is
        within :data:`LIMIT_SHOWN` x the signal's peak, else named in the panel ("off scale");
        a rate limit is named with the share of samples that reached it. Angles are drawn in
        degrees (the result and its files keep radians). With ``open_loop`` (the same plant,
        initial state and disturbance with the controller off), its outputs are drawn dashed
        grey up to where they leave :data:`OPEN_LOOP_SCALE` x the closed loop's peak (a
        diverging open loop), the point where they leave the scale marked and named.

        Parameters
        ----------
        tip, control, deflection : str, optional
            Signals to show (defaults: ``tip_disp`` or the first ``tip_*`` output, the first
            control, the first ``*_deflection`` output).
        open_loop : SimulationResult, optional
            Open-loop run to overlay.
        """
        from .._figures import new_figure

        tip = tip or next(
            (n for n in ("tip_disp", *self.outputs) if n in self.outputs and n.startswith("tip")),
            next(iter(self.outputs)),
        )
        control = control or next(iter(self.applied), None)  # None: no control (open loop)
        deflection = deflection or next(
            (n for n in self.outputs if n.endswith("_deflection")), None
        )
        panels = [g for g in self.disturbance if np.any(self.disturbance[g])] + [tip]
        panels += [control] if control else []
        panels += [deflection] if deflection else []
        fig = new_figure(figsize=(7.5, 2.1 * len(panels)))
        axes = np.atleast_1d(fig.subplots(len(panels), 1, sharex=True))
        for ax, name in zip(axes, panels, strict=True):
            recorded = self.units.get(name) or ("rad" if name == deflection else "")
            k, unit = _display_unit(recorded)
            if name == control:
                self._control_panel(ax, name, k, unit)
            elif name in self.disturbance:
                ax.plot(self.t, self.disturbance[name], color="0.4")
                unit = unit or "m/s"
            else:
                ax.plot(self.t, k * self.outputs[name], label="closed loop")
                if open_loop is not None and name in open_loop.outputs:
                    y_open, y_closed = k * open_loop.outputs[name], k * self.outputs[name]
                    _overlay(ax, open_loop.t, y_open, y_closed, unit)
                    ax.legend(fontsize=8, loc="upper right")
            ax.set_ylabel(f"{name} [{unit}]")
            ax.grid(True, alpha=0.3)
        axes[-1].set_xlabel("time [s]")
        off = not any(np.any(c) for c in self.commands.values())  # e.g. an open-loop run
        fig.suptitle(
            f"{'open loop (no command)' if off else 'closed loop'} at {self.speed:.4g} m/s"
            + ("" if open_loop is None else " (open loop dashed grey)")
        )
        return fig

    def _control_panel(self, ax, name: str, k: float, unit: str) -> None:
        """Applied and commanded input, the axis scaled to the applied input; the limits drawn
        when near it, else named (see :meth:`plot_time`)."""
        act = self.outputs.get(name + "_actuator")  # with an actuator: its output is applied
        applied = k * (self.applied[name] if act is None else act)
        command = k * self.commands[name]
        ax.plot(self.t, applied, label="applied" if act is None else "actuator output (applied)")
        ax.plot(self.t, command, "--", lw=0.8, label="commanded")
        peak = float(np.max(np.abs(applied), initial=0.0))
        mag = self.limits.magnitude.get(name)
        notes = []
        top = peak
        if mag is not None and k * mag <= LIMIT_SHOWN * peak:
            for sgn in (-1, 1):
                ax.axhline(sgn * k * mag, color="r", lw=0.8, ls=":")
            ax.plot([], [], color="r", lw=0.8, ls=":", label=f"limit \u00b1{k * mag:.4g} {unit}")
            top = max(top, k * mag)
        elif mag is not None:
            notes.append(f"limit \u00b1{k * mag:.4g} {unit}, off scale")
        top = top * 1.1 if top > 0 else 1.0
        ax.set_ylim(-top, top)
        wild = float(np.max(np.abs(command), initial=0.0))
        if wild > top:
            notes.append(f"commanded up to {wild:.3g} {unit}, off scale")
        rate = self.limits.rate.get(name)
        if rate is not None:
            share = self.rate_limited_fraction.get(name, 0.0)
            notes.append(
                f"rate limit \u00b1{k * rate:.3g} {unit}/s, reached at {share:.1%} of samples"
            )
        for note in notes:  # legend lines: the legend keeps clear of the curves
            ax.plot([], [], " ", label=note)
        ax.legend(fontsize=7, loc="best")

    @property
    def table(self):
        """The time histories, one row per sample (pandas DataFrame): ``t`` [s], then every
        signal as ``<group>.<name>`` (``outputs``, ``commands``, ``applied``,
        ``disturbance``: the names of the ``.npz`` file) in its unit (:attr:`units`); a signal
        of several columns gives ``<group>.<name>[i]``."""
        import pandas as pd

        cols: dict = {"t": np.asarray(self.t)}
        for group in _GROUPS:
            for name, y in getattr(self, group).items():
                y = np.asarray(y)
                if y.ndim == 1:
                    cols[f"{group}.{name}"] = y
                else:
                    for i, col in enumerate(y.reshape(y.shape[0], -1).T):
                        cols[f"{group}.{name}[{i}]"] = col
        return pd.DataFrame(cols)

    def summary(self) -> str:
        """The march, the peak of every signal and the time each control spent at its
        limits, a line each."""
        n = self.t.size
        dt = float(self.t[1] - self.t[0]) if n > 1 else 0.0
        off = not any(np.any(c) for c in self.commands.values())
        lines = [
            f"{'open loop (no command)' if off else 'closed loop'} at {self.speed:.6g} m/s TAS, "
            f"density {self.density:.5g} kg/m^3: {n} samples of {dt:.4g} s, t = "
            f"{float(self.t[0]) if n else 0.0:.4g} .. {float(self.t[-1]) if n else 0.0:.4g} s"
        ]
        for group, what in (("disturbance", "disturbance"), ("outputs", "output"),
                            ("applied", "applied")):  # fmt: skip
            for name, y in getattr(self, group).items():
                y = np.asarray(y, dtype=float)
                finite = np.isfinite(y).all()
                peak = f"{np.max(np.abs(y), initial=0.0):.4g}" if finite else "non-finite"
                lines.append(f"  {what} {name}: peak {peak} {self.units.get(name, '')}".rstrip())
        at = self.time_at_limit() if n else {}
        for c, s in at.items():
            if s > 0:
                lines.append(f"  {c} at its magnitude or rate limit for {s:.4g} s")
        wound = self.windup()
        if wound:
            lines.append(f"  {windup_text(wound)}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """The time histories and their settings (SI units; ``run_summary`` when read back)."""
        return {
            "speed": self.speed,
            "density": self.density,
            "units": dict(self.units),
            "limits": {"magnitude": self.limits.magnitude, "rate": self.limits.rate},
            "t": np.asarray(self.t),
            **{g: dict(getattr(self, g)) for g in _GROUPS},
            "run_summary": dict(self.run_summary),
        }
