"""Loop margins at the actuator swept over airspeed (:func:`aeroservo.design.margins`).

A fixed controller (a schedule is evaluated at each speed) around the plant at each speed of a
grid: where the loop is stable the gain, gain-reduction, phase and disk margins of every
control channel; where it is not, NaN.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..result_shape import Result, shell
from .closed_loop import plant_function
from .margins import LoopMargins, MarginRequirement, loop_margins

__all__ = ["MarginSweep", "margins_over_speed", "QUANTITIES"]

QUANTITIES = (
    "gain_margin_db",
    "gain_reduction_margin_db",
    "phase_margin_deg",
    "disk_margin",
)
"""The margins tabulated per speed (dB, dB, deg, dimensionless)."""


@dataclass
class MarginSweep(Result):
    """Margins of a loop over a speed grid.

    A result of the common shape (:mod:`aeroservo.result_shape`): :meth:`summary`,
    :attr:`table` (one row per control and speed), :meth:`plot` (``"margin-sweep"``),
    :meth:`to_json` and :meth:`save` (a ``.npz``); :meth:`table_for` gives one channel's
    arrays.

    Attributes
    ----------
    speeds : ndarray
        [m/s]
    margins : list of LoopMargins
        One per speed.
    requirement : MarginRequirement
    reference_speed : float or None
        Design or scenario speed [m/s], marked on plots.
    """

    speeds: np.ndarray
    margins: list
    requirement: MarginRequirement
    reference_speed: float | None = None

    FIGURES = {"margin-sweep": "plot_sweep"}

    @property
    def controls(self) -> tuple:
        return tuple(self.margins[0].channels) if self.margins else ()

    @property
    def table(self):
        """One row per control and speed (:func:`~.margin_tables.sweep_table`)."""
        from .margin_tables import sweep_table

        return sweep_table(self)

    def summary(self) -> str:
        """Per control, where the requirement holds and the least margins."""
        from .margin_tables import sweep_summary

        return sweep_summary(self)

    def plot_sweep(self, control: str | None = None, title: str | None = None):
        """Margins of one channel versus airspeed (:func:`aeroservo.plots.plot_margin_sweep`)."""
        return shell("plot_margin_sweep")(self, control, title)

    def to_state(self) -> dict:
        """Every field as plain data and arrays (for a file; :meth:`from_state`)."""
        from .margin_tables import requirement_state

        return {
            "speeds": self.speeds,
            "margins": [m.to_state() for m in self.margins],
            "requirement": requirement_state(self.requirement),
            "reference_speed": self.reference_speed,
        }

    @classmethod
    def from_state(cls, state: dict) -> MarginSweep:
        """The sweep of :meth:`to_state`."""
        from .margin_tables import requirement_from_state

        return cls(
            np.asarray(state["speeds"], dtype=float),
            [LoopMargins.from_state(m) for m in state["margins"]],
            requirement_from_state(state["requirement"]),
            state["reference_speed"],
        )

    def table_for(self, control: str | None = None) -> dict:
        """``{quantity: ndarray over speed}`` for one channel (default the first); infinite
        margins stay inf, speeds where the loop is unstable are NaN; ``stable`` and ``meets``
        are boolean arrays."""
        control = control or self.controls[0]
        out = {q: np.full(self.speeds.size, np.nan) for q in QUANTITIES}
        out["stable"] = np.zeros(self.speeds.size, dtype=bool)
        out["meets"] = np.zeros(self.speeds.size, dtype=bool)
        for i, lm in enumerate(self.margins):
            ch = lm.channels[control]
            out["stable"][i] = ch.stable
            out["meets"][i] = not ch.violations(self.requirement)
            if ch.stable:
                for q in QUANTITIES:
                    out[q][i] = getattr(ch, q)
        return out

    def meeting_range(self, control: str | None = None) -> tuple[float, float] | None:
        """Speeds [m/s] of the grid interval around the reference speed where the requirement
        holds (None if it fails there)."""
        meets = self.table_for(control)["meets"]
        ref = self.reference_speed if self.reference_speed is not None else self.speeds[0]
        i = int(np.argmin(np.abs(self.speeds - ref)))
        if not meets[i]:
            return None
        lo = hi = i
        while lo > 0 and meets[lo - 1]:
            lo -= 1
        while hi < meets.size - 1 and meets[hi + 1]:
            hi += 1
        return float(self.speeds[lo]), float(self.speeds[hi])

    def to_dict(self) -> dict:
        """JSON-ready: speeds [m/s] and, per control, the margins (null where unstable or
        infinite) and the speed range that meets the requirement."""

        def clean(a):
            return [None if not np.isfinite(x) else float(x) for x in a]

        per = {}
        for c in self.controls:
            t = self.table_for(c)
            per[c] = {q: clean(t[q]) for q in QUANTITIES}
            per[c]["stable"] = t["stable"].tolist()
            per[c]["meets"] = t["meets"].tolist()
            per[c]["meeting_range"] = self.meeting_range(c)
        return {"speeds": self.speeds.tolist(), "channels": per}


def margins_over_speed(
    plant_at,
    controller,
    speeds: Sequence[float],
    *,
    delay: bool = False,
    requirement: MarginRequirement | None = None,
    reference_speed: float | None = None,
    progress: Callable[[float], None] | None = None,
) -> MarginSweep:
    """Loop margins of a fixed controller at each speed of a grid.

    Parameters
    ----------
    plant_at : ControlLoop, StateSpaceBuilder or callable
        The plant at a speed (its ``plant``, its ``at``, or ``V -> control.StateSpace``, filters
        included).
    controller
        Linear sampled controller or gain schedule.
    speeds : sequence of float
        [m/s]
    delay : bool
        One-sample computational delay.
    requirement : MarginRequirement, optional
    reference_speed : float, optional
        [m/s], for :meth:`MarginSweep.meeting_range` (default the controller's design speed).
    progress : callable, optional
        Called with each speed [m/s].
    """
    at = plant_function(plant_at)
    req = requirement or MarginRequirement()
    v = np.asarray(speeds, dtype=float)
    out: list[LoopMargins] = []
    for s in v:  # loop_margins evaluates a schedule at the plant's speed
        out.append(
            # loop_margins breaks at the sensors when the requirement judges them
            loop_margins(at(float(s)), controller, delay=delay, requirement=req, sensors=False)
        )

        if progress is not None:
            progress(float(s))
    ref = (
        reference_speed
        if reference_speed is not None
        else getattr(controller, "design_speed", None)
    )
    return MarginSweep(v, out, req, None if ref is None else float(ref))
