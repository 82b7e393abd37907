"""The judgement of a loop over the speeds where it is engaged.

A flutter-suppression loop is switched on over a range of airspeeds, and it must be stable at
every one of them, not only at its design point: a loop that removes flutter at 1.1 V_f but
makes the wing flutter at 0.7 V_f is not a working design. The judgement follows the structure
of the field's rules: the margin requirement holds over the speeds where the loop operates
(MIL-F-9490D, 6 dB / 45 deg at the actuator), and aeroelastic stability holds with a flutter
margin beyond them, up to 1.15 x the top speed (CS-25.629(b)(1) and 14 CFR 25.629(b)(1):
stability up to V_D/M_D enlarged by 15 % in equivalent airspeed). :func:`judge_loop`

* finds where the closed loop is unstable from the bottom of the engaged range to
  ``flutter_margin`` x its top (the closed-loop boundary of
  :func:`~aeroservo.design.closed_loop.closed_loop_boundary`, roots refined, humps between
  grid points searched), naming each loss (oscillatory flutter at f Hz or static divergence);
* judges the margin requirement at the plant inputs, controller a black box
  (:func:`~aeroservo.design.margins.loop_margins`), on a grid of speeds across the engaged
  range.

The default engaged range runs from half the open-loop flutter speed (:data:`LOW_FACTOR`) to the
design (scenario) speed, with the flutter margin :data:`FLUTTER_MARGIN`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, check_int, check_number
from .boundary_result import ClosedLoopBoundary
from .closed_loop import closed_loop_boundary, linear_controller
from .margin_sweep import MarginSweep, margins_over_speed
from .margins import MarginRequirement

__all__ = ["EngagedRange", "LoopJudgement", "judge_loop", "LOW_FACTOR", "FLUTTER_MARGIN"]

LOW_FACTOR = 0.5
"""Default lower end of the engaged range, times the open-loop flutter speed."""

FLUTTER_MARGIN = 1.15
"""Stability is required up to this factor times the top of the engaged range
(CS-25.629(b)(1))."""


@dataclass(frozen=True)
class EngagedRange:
    """Airspeeds [m/s] over which the loop is engaged, and the flutter margin beyond them.

    Attributes
    ----------
    low, high : float
        [m/s], ``0 < low < high``: the margin requirement is judged here.
    source : str
        How the range was set (printed with it), e.g. ``"default: 0.5 V_f to the scenario
        speed"``.
    flutter_margin : float
        Stability is required from ``low`` to ``flutter_margin x high`` (>= 1; default 1.15).
    """

    low: float
    high: float
    source: str = ""
    flutter_margin: float = FLUTTER_MARGIN

    def __post_init__(self) -> None:
        check_number("engaged.low", self.low, unit="m/s", lo=0.0, lo_open=True)
        check_number("engaged.high", self.high, unit="m/s", lo=0.0, lo_open=True)
        check_number("flutter_margin", self.flutter_margin, lo=1.0, hi=3.0)
        if not self.high > self.low:
            raise InputError(
                f"engaged speeds = [{self.low:g}, {self.high:g}] m/s: the upper end must be "
                "above the lower end"
            )

    @classmethod
    def default(cls, flutter_speed: float | None, speed: float) -> EngagedRange:
        """:data:`LOW_FACTOR` x the open-loop flutter speed (x the speed if there is none) to
        the design speed [m/s], flutter margin :data:`FLUTTER_MARGIN`."""
        low = LOW_FACTOR * (flutter_speed if flutter_speed else speed)
        return cls(
            min(low, 0.5 * speed),
            speed,
            f"default: {LOW_FACTOR:g} V_f to the scenario speed",
        )

    @property
    def stable_to(self) -> float:
        """Top of the speeds [m/s] where stability is required: ``flutter_margin x high``."""
        return self.flutter_margin * self.high

    def text(self) -> str:
        return f"{self.low:.4g}-{self.high:.4g} m/s"

    def to_dict(self) -> dict:
        return {
            "low": self.low,
            "high": self.high,
            "source": self.source,
            "flutter_margin": self.flutter_margin,
            "stable_to": self.stable_to,
        }


@dataclass
class LoopJudgement:
    """A loop judged over its engaged range.

    Attributes
    ----------
    engaged : EngagedRange
    boundary : ClosedLoopBoundary
        Closed-loop stability over the engaged range.
    unstable : list of dict
        Unstable speed intervals inside the range (``from``, ``to`` [m/s], ``kind``,
        ``frequency`` [Hz], ``static``): empty for a stable loop.
    sweep : MarginSweep or None
        Margins at the plant inputs (black box) on a grid of speeds across the range.
    requirement : MarginRequirement
    """

    engaged: EngagedRange
    boundary: ClosedLoopBoundary
    unstable: list
    sweep: MarginSweep | None
    requirement: MarginRequirement = field(default_factory=MarginRequirement)

    @property
    def stable(self) -> bool:
        """Stable at every speed of the engaged range."""
        return not self.unstable

    def margin_failures(self) -> list[dict]:
        """``{"speed", "violations"}`` at each sweep speed that misses the requirement."""
        if self.sweep is None:
            return []
        out = []
        for v, lm in zip(self.sweep.speeds, self.sweep.margins, strict=True):
            bad = lm.violations()
            if bad:
                out.append({"speed": float(v), "violations": bad})
        return out

    @property
    def meets_requirement(self) -> bool:
        """The margin requirement holds at every sweep speed."""
        return self.sweep is not None and not self.margin_failures()

    @property
    def passed(self) -> bool:
        return self.stable and self.meets_requirement

    def lines(self) -> list[str]:
        """What fails, one line per kind (empty when the loop passes)."""
        out = []
        where = f"the engaged range {self.engaged.text()}"
        if self.unstable:
            e = self.engaged
            parts = [f"{u['from']:.4g}-{u['to']:.4g} m/s ({u['kind']})" for u in self.unstable]
            out.append(
                f"closed loop unstable between {e.low:.4g} m/s and {e.flutter_margin:g} x "
                f"{e.high:.4g} = {e.stable_to:.4g} m/s (engaged range and flutter margin): "
                + "; ".join(parts)
            )
        fails = self.margin_failures()
        if fails and self.stable:
            req = self.requirement.describe()
            # the reference (design) speed first, then the worst: nothing decisive is folded
            ref = getattr(self.boundary, "reference_speed", None)
            order = sorted(
                fails,
                key=lambda f: (
                    ref is None or abs(f["speed"] - ref) > 1e-9 * ref,
                    -len(f["violations"]),
                ),
            )
            shown = "; ".join(
                f"at {f['speed']:.4g} m/s {', '.join(f['violations'])}" for f in order[:3]
            )
            rest = sorted(f["speed"] for f in order[3:])
            more = f" (also at {', '.join(f'{v:.4g}' for v in rest)} m/s)" if rest else ""
            out.append(
                f"loop margins (controller a black box) miss {req} in {where}: {shown}{more}"
            )
        return out

    def to_dict(self) -> dict:
        """JSON-ready (m/s, Hz)."""
        return {
            "engaged_range": self.engaged.to_dict(),
            "stable_over_range": self.stable,
            "unstable_intervals": self.unstable,
            "lower_speed": self.boundary.lower_speed,
            "lower_speed_kind": self.boundary.lower_speed_kind,
            "margins_over_range": {
                "meets": self.meets_requirement,
                "speeds": [] if self.sweep is None else self.sweep.speeds.tolist(),
                "failures": self.margin_failures(),
            },
            "passed": self.passed,
        }


def judge_loop(
    plant_at,
    controller,
    engaged: EngagedRange | tuple[float, float],
    *,
    requirement: MarginRequirement | None = None,
    delay: bool = False,
    reference_speed: float | None = None,
    n_grid: int = 41,
    margin_speeds: int = 9,
    sample_rate: float | None = None,
    progress: Callable[[float], None] | None = None,
    boundary: ClosedLoopBoundary | None = None,
) -> LoopJudgement:
    """Judge a linear loop over the speeds where it is engaged (module docstring).

    Parameters
    ----------
    plant_at : ControlLoop, StateSpaceBuilder or callable
        The plant at a speed (see :func:`~aeroservo.design.closed_loop_boundary`).
    controller
        A linear controller (:func:`aeroservo.design.as_controller`); a schedule is evaluated
        at each speed.
    engaged : EngagedRange or (float, float)
        [m/s]: margins judged over it, stability up to its flutter margin x its top.
    requirement : MarginRequirement, optional
        Default MIL-F-9490D (6 dB, 45 deg) at the plant inputs.
    delay : bool
        One-sample computational delay.
    reference_speed : float, optional
        Design speed [m/s], one of the margin speeds (default the controller's design speed).
    n_grid : int
        Grid of the stability search over the range.
    margin_speeds : int
        Speeds of the margin sweep across the range (ends included; 0: no sweep, so the
        requirement is not judged).
    sample_rate : float, optional
        [Hz] for a continuous python-control compensator.
    progress : callable, optional
        Called with each speed [m/s] analysed.
    boundary : ClosedLoopBoundary, optional
        A boundary of the same loop already computed over a range that holds the engaged one
        (its crossings are used instead of a new search).

    Returns
    -------
    LoopJudgement
    """
    if not isinstance(engaged, EngagedRange):
        try:
            lo, hi = engaged
        except (TypeError, ValueError):
            raise InputError(f"engaged = {engaged!r}: expected (low, high) speeds [m/s]") from None
        engaged = EngagedRange(lo, hi, "given")
    ctrl = linear_controller(controller, "judge_loop", sample_rate)
    req = requirement or MarginRequirement()
    margin_speeds = check_int("margin_speeds", margin_speeds, lo=0, hi=1000)
    ref = reference_speed if reference_speed is not None else getattr(ctrl, "design_speed", None)
    if ref is None or not np.isfinite(ref):
        ref = engaged.high
    b = boundary
    top = engaged.stable_to
    if b is None or not (b.v_range[0] <= engaged.low and top <= b.v_range[1]):
        b = closed_loop_boundary(
            plant_at,
            ctrl,
            top,
            v_min=engaged.low,
            n_grid=n_grid,
            reference_speed=float(np.clip(ref, engaged.low, top)),
            delay=delay,
            progress=progress,
        )
    unstable = b.unstable_intervals(engaged.low, top)
    sweep = None
    if margin_speeds:
        speeds = np.linspace(engaged.low, engaged.high, margin_speeds)
        if engaged.low <= ref <= engaged.high:
            speeds = np.unique(np.r_[speeds, ref])
        sweep = margins_over_speed(
            plant_at,
            ctrl,
            speeds,
            delay=delay,
            requirement=req,
            reference_speed=ref,
            progress=progress,
        )
    return LoopJudgement(engaged, b, unstable, sweep, req)
