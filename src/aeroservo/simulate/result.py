"""Time histories of a closed-loop simulation, with their limits, units and a standard figure."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..design.plant import Limits
from ..errors import InputError

__all__ = ["SimulationResult", "WINDUP_RATIO", "windup_text"]

WINDUP_RATIO = 10.0
"""A command beyond this many times its magnitude limit is reported as winding up."""


def windup_text(wound: dict) -> str:
    """One line on the controls of :meth:`SimulationResult.windup`."""
    parts = [
        f"{c} commanded up to {w['peak_command']:.3g} against a limit of {w['limit']:.4g} "
        f"({w['ratio']:.3g} x)"
        for c, w in wound.items()
    ]
    return (
        "the controller's commands run away while the actuator saturates (windup, or a loop "
        "its limits cannot hold): " + "; ".join(parts)
    )


@dataclass
class SimulationResult:
    """Time histories of a closed-loop simulation (SI units).

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
    summary : dict
        Run summary of a result read back by :func:`aeroservo.files.results.load_result` (empty
        otherwise).
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
    summary: dict = field(default_factory=dict)

    def signal(self, name: str) -> np.ndarray:
        """Any recorded signal by name."""
        for group in (self.outputs, self.applied, self.disturbance):
            if name in group:
                return group[name]
        known = list(self.outputs) + list(self.applied) + list(self.disturbance)
        raise InputError(f"signal {name!r}: not recorded; known: {known}")

    def saturated_fraction(self) -> dict:
        """Share of samples at which each control sat on its magnitude limit."""
        mag, _ = self.limits.arrays(list(self.applied))
        return {
            c: float(np.mean(np.abs(u) >= mag[i] * (1 - 1e-12)))
            for i, (c, u) in enumerate(self.applied.items())
        }

    def windup(self, ratio: float = WINDUP_RATIO) -> dict:
        """Controls whose commands ran away beyond their magnitude limit: ``{control:
        {"peak_command", "limit", "ratio"}}`` for a peak ``|command|`` above ``ratio`` x the
        limit, or not finite (empty: none)."""
        mag, _ = self.limits.arrays(list(self.commands))
        out = {}
        for i, (c, cmd) in enumerate(self.commands.items()):
            peak = float(np.max(np.abs(cmd))) if np.all(np.isfinite(cmd)) else float("inf")
            if np.isfinite(mag[i]) and peak > ratio * mag[i]:
                out[c] = {
                    "peak_command": peak,
                    "limit": float(mag[i]),
                    "ratio": float(peak / mag[i]),
                }
        return out

    def rate_limited_fraction(self) -> dict:
        """Share of samples at which each control moved at its rate limit (the command was
        rate-limited; the first sample starts from zero)."""
        _, rate = self.limits.arrays(list(self.applied))
        dt = float(self.t[1] - self.t[0]) if self.t.size > 1 else 0.0
        out = {}
        for i, (c, u) in enumerate(self.applied.items()):
            step = np.abs(np.diff(np.r_[0.0, np.asarray(u, dtype=float)]))
            limited = np.isfinite(rate[i]) & (step >= rate[i] * dt * (1 - 1e-9))
            out[c] = float(np.mean(limited)) if dt > 0 else 0.0
        return out

    def plot(
        self, tip: str | None = None, control: str | None = None, deflection: str | None = None
    ):
        """Gust (if any), tip response, control input with its limits and commanded values,
        and surface deflection, against time (matplotlib Figure).

        Parameters
        ----------
        tip, control, deflection : str, optional
            Signals to show (defaults: ``tip_disp`` or the first ``tip_*`` output, the first
            control, the first ``*_deflection`` output).
        """
        from matplotlib.figure import Figure

        tip = tip or next(
            (n for n in ("tip_disp", *self.outputs) if n in self.outputs and n.startswith("tip")),
            next(iter(self.outputs)),
        )
        control = control or next(iter(self.applied))
        deflection = deflection or next(
            (n for n in self.outputs if n.endswith("_deflection")), None
        )
        panels = [g for g in self.disturbance if np.any(self.disturbance[g])] + [tip, control]
        panels += [deflection] if deflection else []
        fig = Figure(layout="constrained", figsize=(7.5, 2.1 * len(panels)))
        axes = np.atleast_1d(fig.subplots(len(panels), 1, sharex=True))
        for ax, name in zip(axes, panels, strict=True):
            unit = self.units.get(name, "")
            if name == control:
                ax.plot(self.t, self.applied[name], label="applied")
                ax.plot(self.t, self.commands[name], "--", lw=0.8, label="commanded")
                mag = self.limits.magnitude.get(name)
                if mag is not None:
                    for sgn in (-1, 1):
                        ax.axhline(sgn * mag, color="r", lw=0.8, ls=":")
                ax.legend(fontsize=8)
            elif name == deflection:
                ax.plot(self.t, np.degrees(self.outputs[name]))
                unit = "deg"
            elif name in self.disturbance:
                ax.plot(self.t, self.disturbance[name], color="0.4")
                unit = unit or "m/s"
            else:
                ax.plot(self.t, self.outputs[name])
            ax.set_ylabel(f"{name} [{unit}]")
            ax.grid(True, alpha=0.3)
        axes[-1].set_xlabel("time [s]")
        fig.suptitle(f"closed loop at {self.speed:.4g} m/s")
        return fig
