"""Flutter-suppression controller design: LQR, LQG, gain scheduling and constrained MPC.

python-control designs the linear loops; casadi solves the MPC quadratic programs. Every
controller here is a *sampled* controller usable by :func:`aeroservo.simulate.simulate`.
"""

from .lqg import KalmanFilter, OutputFeedback, kalman_filter, lqg
from .lqr import Bryson, StateFeedback, bryson_weights, lqr
from .mpc import MPCController, mpc
from .plant import Limits, OpenLoop, SampledPlant, state_map, with_sensor_filters

__all__ = [
    "Bryson",
    "KalmanFilter",
    "Limits",
    "MPCController",
    "OpenLoop",
    "OutputFeedback",
    "SampledPlant",
    "StateFeedback",
    "bryson_weights",
    "kalman_filter",
    "lqg",
    "lqr",
    "mpc",
    "state_map",
    "with_sensor_filters",
]
