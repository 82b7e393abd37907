"""Analysis of a simulated loop beyond its time history: loop margins at the actuator at the
scenario's speed, and (when the scenario asks for the closed-loop boundary) the closed-loop
flutter boundary and the margins swept over the same speed range."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .scenario import Scenario

__all__ = ["LoopAnalysis", "analyse_loop"]

LINEAR_TYPES = ("lqr", "lqg", "hinf")
"""Controller types with a closed-loop boundary (MPC has margins of its unconstrained law)."""


@dataclass
class LoopAnalysis:
    """Margins (``LoopMargins``), boundary (``ClosedLoopBoundary``) and margin sweep
    (``MarginSweep``) of a run; None where not computed."""

    margins: object = None
    boundary: object = None
    sweep: object = None

    def summary(self, open_loop_flutter_speed: float | None) -> dict:
        """JSON-ready entries ``margins``, ``closed_loop`` and ``margin_sweep``."""
        out: dict = {}
        if self.margins is not None:
            out["margins"] = self.margins.to_dict()
        if self.boundary is not None:
            cl = self.boundary.to_dict()
            vf, v = open_loop_flutter_speed, self.boundary.flutter_speed
            if vf is not None and v is not None:
                cl["flutter_speed_increase"] = v / vf - 1
            out["closed_loop"] = cl
        if self.sweep is not None:
            out["margin_sweep"] = self.sweep.to_dict()
        return out


def analyse_loop(
    scenario: Scenario,
    loop,
    plant,
    controller,
    speed: float,
    flutter_speed: float | None,
    bar: Callable[[float, str], tuple[Callable, Callable]],
) -> LoopAnalysis:
    """Margins at ``speed`` [m/s]; boundary and margin sweep if the scenario asks.

    ``plant`` is ``loop.plant(speed)``, the plant the run simulated; ``bar(total, label)``
    returns ``(update, close)`` of a progress bar.
    """
    from ..design.closed_loop import closed_loop_boundary
    from ..design.margin_sweep import margins_over_speed
    from ..design.margins import loop_margins

    spec = scenario.controller
    res = LoopAnalysis()
    if spec.type == "none":
        return res
    res.margins = loop_margins(plant, controller, delay=scenario.delay, requirement=spec.margins)

    if not (scenario.closed_loop_boundary and spec.type in LINEAR_TYPES):
        return res
    v_top = scenario.v_max_factor * (flutter_speed or speed)
    update, close = bar(v_top, "closed-loop sweep")
    try:
        res.boundary = closed_loop_boundary(
            loop.plant,
            controller,
            v_top,
            n_grid=scenario.n_grid,
            reference_speed=speed,
            delay=scenario.delay,
            progress=update,
        )
    finally:
        close()
    if scenario.margin_speeds:
        speeds = _sweep_speeds(res.boundary, speed, scenario.margin_speeds)

        update, close = bar(v_top, "margin sweep")
        try:
            res.sweep = margins_over_speed(
                loop.plant,
                controller,
                speeds,
                delay=scenario.delay,
                requirement=spec.margins,
                reference_speed=speed,
                progress=update,
            )
        finally:
            close()
    return res


def _sweep_speeds(boundary, speed: float, n: int) -> np.ndarray:
    """``n`` speeds [m/s] across the stable interval that holds ``speed`` (1 % inside its ends,
    where the margins vanish), plus ``speed``; the whole range if no interval holds it."""
    lo, hi = boundary.speeds[0], boundary.speeds[-1]
    for a, b in boundary.stable_intervals():
        if a <= speed <= b:
            pad = 0.01 * (b - a)
            lo, hi = a + pad, b - pad
            break
    return np.unique(np.r_[np.linspace(lo, hi, n), speed])
