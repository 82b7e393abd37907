"""Flutter-suppression controller design: LQR, LQG, gain scheduling and constrained MPC.

python-control designs the linear loops; casadi solves the MPC quadratic programs. Every
controller here is a *sampled* controller usable by :func:`aeroservo.simulate.simulate`;
:func:`closed_loop_boundary` finds the flutter speed of a linear loop. A
:class:`ControlLoop` holds the plant and design models of one wing and turns a
:class:`ControllerSpec` (a controller file) into a controller at a design speed.
"""

from .closed_loop import ClosedLoopBoundary, closed_loop_boundary, closed_loop_matrix
from .loop import ControlLoop
from .lqg import KalmanFilter, OutputFeedback, kalman_filter, lqg
from .lqr import Bryson, StateFeedback, bryson_weights, lqr
from .mpc import MPCController, mpc
from .plant import Limits, OpenLoop, SampledPlant, state_map, with_sensor_filters
from .schedule import GainSchedule, schedule
from .spec import ControllerSpec

__all__ = [
    "Bryson",
    "ClosedLoopBoundary",
    "ControlLoop",
    "ControllerSpec",
    "GainSchedule",
    "KalmanFilter",
    "Limits",
    "MPCController",
    "OpenLoop",
    "OutputFeedback",
    "SampledPlant",
    "StateFeedback",
    "bryson_weights",
    "closed_loop_boundary",
    "closed_loop_matrix",
    "kalman_filter",
    "lqg",
    "lqr",
    "mpc",
    "schedule",
    "state_map",
    "with_sensor_filters",
]
