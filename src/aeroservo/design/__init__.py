"""Flutter-suppression controller design and the analysis of any controller's loop.

python-control designs the linear loops (LQR, LQG, H-infinity); casadi solves the MPC quadratic
programs. Every controller is a *sampled* controller; :func:`as_controller` takes one designed
here or elsewhere (a python-control ``StateSpace``/``TransferFunction``, a
:func:`static_gain`, a :func:`python_law`), and the same object works in
:func:`aeroservo.simulate.simulate`, :func:`closed_loop_boundary`, :func:`loop_margins`,
:func:`margins_over_speed` and :func:`judge_loop`. A :class:`ControlLoop` holds the plant and
design models of one wing and turns a :class:`ControllerSpec` (a controller file) into a
controller at a design speed.
"""

from .actuator import ActuatorDynamics
from .boundary_result import ClosedLoopBoundary
from .closed_loop import closed_loop_boundary, closed_loop_matrix
from .compensator import DiscreteCompensator, compensator_from_lti
from .hinge_loop import loop_hinge_plant
from .interface import PythonLaw, StateGain, as_controller, python_law, static_gain
from .judgement import EngagedRange, LoopJudgement, judge_loop
from .law import LinearLaw
from .loop import ControlLoop
from .lqg import KalmanFilter, OutputFeedback, kalman_filter, lqg
from .lqr import Bryson, StateFeedback, bryson_weights, lqr
from .margin_sweep import MarginSweep, margins_over_speed
from .margins import LoopMargins, MarginRequirement, loop_margins
from .mpc import MPCController, mpc
from .plant import Limits, OpenLoop, SampledPlant, state_map, with_sensor_filters
from .schedule import GainSchedule, schedule
from .spec import ControllerSpec

__all__ = [
    "ActuatorDynamics",
    "loop_hinge_plant",
    "Bryson",
    "ClosedLoopBoundary",
    "ControlLoop",
    "ControllerSpec",
    "DiscreteCompensator",
    "EngagedRange",
    "GainSchedule",
    "KalmanFilter",
    "Limits",
    "LinearLaw",
    "LoopJudgement",
    "LoopMargins",
    "MPCController",
    "MarginRequirement",
    "MarginSweep",
    "OpenLoop",
    "OutputFeedback",
    "PythonLaw",
    "SampledPlant",
    "StateFeedback",
    "StateGain",
    "as_controller",
    "bryson_weights",
    "closed_loop_boundary",
    "closed_loop_matrix",
    "compensator_from_lti",
    "judge_loop",
    "kalman_filter",
    "loop_margins",
    "lqg",
    "lqr",
    "margins_over_speed",
    "mpc",
    "python_law",
    "schedule",
    "state_map",
    "static_gain",
    "with_sensor_filters",
]
