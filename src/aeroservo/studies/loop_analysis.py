"""Analysis of a simulated loop beyond its time history: loop margins at the scenario's speed
(at the actuator, controller a black box; at each sensor; simultaneous), the judgement over the
engaged speed range (stability everywhere in it, margins across it), and when the scenario asks
the closed-loop boundary over a wider range.

A nonlinear controller (a Python law) has no eigenvalues or margins: its engaged range is
judged by simulating it at speeds across the range (:class:`SimulatedJudgement`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..errors import check_derived_speed
from .scenario import Scenario
from .verdict import GROWS, signal_growth

__all__ = ["LoopAnalysis", "SimulatedJudgement", "analyse_loop"]


@dataclass
class SimulatedJudgement:
    """A nonlinear loop judged by time marching at speeds across its engaged range.

    Attributes
    ----------
    engaged : EngagedRange
    speeds : ndarray
        [m/s]
    growing : dict
        ``{speed: [growing signals]}`` at the speeds where the response grows.
    """

    engaged: object
    speeds: np.ndarray
    growing: dict = field(default_factory=dict)
    meets_requirement = None  # margins are not defined for a nonlinear law

    @property
    def stable(self) -> bool:
        return not self.growing

    @property
    def passed(self) -> bool:
        return self.stable

    def lines(self) -> list[str]:
        if self.stable:
            return []
        at = ", ".join(f"{v:.4g} m/s ({', '.join(g[:2])} grow)" for v, g in self.growing.items())
        e = self.engaged
        return [
            f"closed loop unstable between {e.low:.4g} m/s and {e.flutter_margin:g} x "
            f"{e.high:.4g} = {e.stable_to:.4g} m/s (engaged range and flutter margin), "
            f"simulated: at {at}"
        ]

    def to_dict(self) -> dict:
        return {
            "engaged_range": self.engaged.to_dict(),
            "method": "time marching at each speed (a nonlinear controller has no closed-loop "
            "eigenvalues or margins)",
            "stable_over_range": self.stable,
            "speeds": self.speeds.tolist(),
            "unstable_speeds": sorted(self.growing),
            "margins_over_range": {"meets": None, "note": "not defined for a nonlinear law"},
            "passed": self.passed,
        }


@dataclass
class LoopAnalysis:
    """Margins (``LoopMargins``), engaged-range judgement (``LoopJudgement`` or
    :class:`SimulatedJudgement`), boundary (``ClosedLoopBoundary``) and margin sweep over the
    engaged range (``MarginSweep``) of a run; None where not computed."""

    margins: object = None
    boundary: object = None
    sweep: object = None
    judgement: object = None

    def summary(self, open_loop_flutter_speed: float | None) -> dict:
        """JSON-ready entries ``margins``, ``engaged``, ``closed_loop`` and ``margin_sweep``."""
        out: dict = {}
        if self.margins is not None:
            out["margins"] = self.margins.to_dict()
        if self.judgement is not None:
            out["engaged"] = self.judgement.to_dict()
        if self.boundary is not None:
            cl = self.boundary.to_dict()
            vf, v = open_loop_flutter_speed, self.boundary.flutter_speed
            if vf is not None and v is not None:
                cl["flutter_speed_increase"] = v / vf - 1
            out["closed_loop"] = cl
        if self.sweep is not None:
            out["margin_sweep"] = self.sweep.to_dict()
        return out


def _simulated(scenario: Scenario, loop, controller, engaged, x0, bar) -> SimulatedJudgement:
    """Time marching at ``scenario.margin_speeds`` speeds (at least 3) from the bottom of the
    range to its flutter margin."""
    from ..simulate.march import simulate

    speeds = np.linspace(engaged.low, engaged.stable_to, max(scenario.margin_speeds, 3))
    out = SimulatedJudgement(engaged, speeds)
    update, close = bar(engaged.stable_to, "engaged range")
    try:
        for v in speeds:
            sim = simulate(
                loop.plant(float(v)),
                controller,
                duration=scenario.duration,
                x0=x0,
                disturbance=scenario.disturbance.gust,
                limits=scenario.controller.limits,
                delay=scenario.delay,
            )
            signals = {**sim.outputs, **sim.applied}
            grows = sorted(n for n, y in signals.items() if np.nan_to_num(signal_growth(y)) > GROWS)
            if grows:
                out.growing[float(v)] = grows
            update(float(v))
    finally:
        close()
    return out


def analyse_loop(
    scenario: Scenario,
    loop,
    plant,
    controller,
    speed: float,
    flutter_speed: float | None,
    bar: Callable[[float, str], tuple[Callable, Callable]],
    x0=None,
) -> LoopAnalysis:
    """Margins at ``speed`` [m/s], the judgement over the engaged range, and the wide boundary
    if the scenario asks.

    ``plant`` is ``loop.plant(speed)``, the plant the run simulated; ``bar(total, label)``
    returns ``(update, close)`` of a progress bar; ``x0`` is the run's initial state (for the
    time marches that judge a nonlinear controller).
    """
    from ..design.closed_loop import closed_loop_boundary
    from ..design.interface import has_linear_law
    from ..design.judgement import judge_loop
    from ..design.margins import loop_margins

    spec = scenario.controller
    res = LoopAnalysis()
    if spec.type == "none":
        return res
    engaged = scenario.engaged_range(flutter_speed, speed)
    if not has_linear_law(controller):
        res.judgement = _simulated(scenario, loop, controller, engaged, x0, bar)
        return res
    res.margins = loop_margins(
        plant, controller, delay=scenario.delay, requirement=spec.margins, outputs=True
    )
    if scenario.closed_loop_boundary:
        v_top = max(scenario.v_max_factor * (flutter_speed or speed), engaged.stable_to)
        base = "open-loop flutter" if flutter_speed else "design"
        check_derived_speed(
            f"{scenario.source}: analysis.v_max_factor", scenario.v_max_factor, v_top,
            f"the closed-loop sweep's top, x the {base} speed {flutter_speed or speed:.6g} m/s",
        )  # fmt: skip
        update, close = bar(v_top, "closed-loop sweep")
        try:
            res.boundary = closed_loop_boundary(
                loop,
                controller,
                v_top,
                v_min=min(v_top / 20.0, engaged.low),
                n_grid=scenario.n_grid,
                reference_speed=speed,
                delay=scenario.delay,
                progress=update,
            )
        finally:
            close()
    update, close = bar(engaged.stable_to, "engaged range")
    try:
        res.judgement = judge_loop(
            loop,
            controller,
            engaged,
            requirement=spec.margins,
            delay=scenario.delay,
            reference_speed=speed,
            n_grid=scenario.n_grid,
            margin_speeds=scenario.margin_speeds,
            boundary=res.boundary,
            progress=update,
        )
    finally:
        close()
    res.sweep = res.judgement.sweep
    return res
