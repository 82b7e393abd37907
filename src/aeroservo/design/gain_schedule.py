"""Gain scheduling over airspeed: linear controllers designed on a speed grid, interpolated.

A fixed controller is only good near its design speed. :func:`schedule` designs one controller
per grid speed with a user function (e.g. an LQR or LQG on the model at that speed) and
:class:`GainSchedule` interpolates their gains linearly in speed (held constant outside the
grid). All designs must share the same design-model states (the in-vacuo modal basis and the
lag states do not depend on speed, so models from one :class:`~aeroservo.StateSpaceBuilder`
qualify): then interpolating the gains, and for LQG the sampled design model and Kalman gain
of the estimator, defines a proper observer-based scheduled controller.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError
from .closed_loop import speeds_grid
from .output_feedback import KalmanFilter, OutputFeedback
from .state_feedback import StateFeedback

__all__ = ["GainSchedule", "schedule"]


@dataclass
class GainSchedule:
    """Linear controllers on a speed grid, interpolated linearly in speed (a
    :class:`~aeroservo.design.protocol.ScheduledController`: every engine takes the controller
    :meth:`at` the plant's speed).

    Attributes
    ----------
    speeds : ndarray
        Design speeds [m/s], increasing.
    controllers : list of StateFeedback or OutputFeedback
        One design per speed, all of the same kind and size.
    design_speed : float
        Reference speed [m/s] of the schedule's closed-loop boundary (optional).
    """

    speeds: np.ndarray
    controllers: list
    design_speed: float = float("nan")

    def __post_init__(self) -> None:
        self.speeds = speeds_grid(self.speeds)
        if len(self.controllers) != self.speeds.size:
            raise InputError(
                f"schedule: {len(self.controllers)} controllers for {self.speeds.size} speeds"
            )
        kinds = {type(c) for c in self.controllers}
        if len(kinds) != 1 or not kinds <= {StateFeedback, OutputFeedback}:
            raise InputError("schedule: all controllers must be LQR or all LQG designs")
        first = self.controllers[0]
        for c in self.controllers[1:]:
            if c.controls != first.controls or c.dt != first.dt or c.sensors != first.sensors:
                raise InputError("schedule: designs differ in controls, sensors or sample rate")
            if np.shape(c.K) != np.shape(first.K):
                raise InputError("schedule: designs differ in their number of states")

    @property
    def controls(self) -> tuple:
        return self.controllers[0].controls

    @property
    def sensors(self) -> tuple:
        return self.controllers[0].sensors

    @property
    def dt(self) -> float:
        return self.controllers[0].dt

    @property
    def needs_state(self) -> bool:
        return self.controllers[0].needs_state

    def _weights(self, speed: float) -> tuple[int, float]:
        v = float(np.clip(speed, self.speeds[0], self.speeds[-1]))
        k = int(np.clip(np.searchsorted(self.speeds, v) - 1, 0, self.speeds.size - 2))
        return k, (v - self.speeds[k]) / (self.speeds[k + 1] - self.speeds[k])

    def at(self, speed: float):
        """The controller at ``speed`` [m/s] (gains interpolated; held outside the grid)."""
        k, t = self._weights(speed)
        a, b = self.controllers[k], self.controllers[k + 1]

        def mix(x, y):
            return (1.0 - t) * np.asarray(x) + t * np.asarray(y)

        if isinstance(a, StateFeedback):
            if not np.array_equal(a.state_map, b.state_map):
                raise InputError("schedule: LQR designs use different state maps")
            return replace(a, K=mix(a.K, b.K), Kd=mix(a.Kd, b.Kd), design_speed=float(speed))
        kf = KalmanFilter(
            mix(a.kf.Ad, b.kf.Ad), mix(a.kf.Bu, b.kf.Bu), mix(a.kf.Ca, b.kf.Ca), mix(a.kf.M, b.kf.M)
        )
        cont = {key: mix(a.continuous[key], b.continuous[key]) for key in a.continuous}
        return replace(a, K=mix(a.K, b.K), kf=kf, continuous=cont, design_speed=float(speed))


def schedule(
    design: Callable[[float], StateFeedback | OutputFeedback],
    speeds: Sequence[float],
    progress: Callable[[float], None] | None = None,
) -> GainSchedule:
    """Design a controller at every speed of a grid and schedule them.

    Parameters
    ----------
    design : callable
        ``design(V)`` returns an LQR (:func:`~aeroservo.design.lqr_controller`) or LQG
        (:func:`~aeroservo.design.lqg`) controller designed on the model at speed V [m/s].
    speeds : sequence of float
        Increasing design speeds [m/s].
    progress : callable, optional
        Called with each speed once its design is done.

    Returns
    -------
    GainSchedule
    """
    grid = speeds_grid(speeds)
    out = []
    for v in grid:
        out.append(design(float(v)))
        if progress is not None:
            progress(float(v))
    return GainSchedule(grid, out)
