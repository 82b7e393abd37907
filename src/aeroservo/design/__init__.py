"""Flutter-suppression controller design and the analysis of any controller's loop.

python-control designs the linear loops (LQR, LQG, H-infinity); casadi solves the MPC quadratic
programs. Every controller is a *sampled* controller with the attributes of the protocol
:class:`Controller` (a linear one those of :class:`LinearController`, a gain schedule those of
:class:`ScheduledController`; :mod:`aeroservo.design.protocol`); :func:`as_controller` takes one
designed here or elsewhere (a python-control ``StateSpace``/``TransferFunction``, a
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
from .gain_schedule import GainSchedule, schedule
from .hinge_loop import loop_hinge_plant
from .interface import PythonLaw, StaticGain, as_controller, python_law, static_gain
from .judgement import EngagedRange, LoopJudgement, judge_loop
from .law import LinearLaw
from .loop import ControlLoop
from .margin_sweep import MarginSweep, margins_over_speed
from .margins import LoopMargins, MarginRequirement, loop_margins
from .model_predictive import MPCController, mpc
from .output_feedback import KalmanFilter, OutputFeedback, kalman_filter, lqg
from .plant import Limits, OpenLoop, SampledPlant, state_map, with_sensor_filters
from .protocol import Controller, LinearController, ScheduledController
from .spec import ControllerSpec
from .state_feedback import Bryson, StateFeedback, bryson_weights, lqr, lqr_controller

__all__ = [
    "ActuatorDynamics",
    "loop_hinge_plant",
    "Bryson",
    "ClosedLoopBoundary",
    "ControlLoop",
    "Controller",
    "ControllerSpec",
    "DiscreteCompensator",
    "EngagedRange",
    "GainSchedule",
    "KalmanFilter",
    "Limits",
    "LinearController",
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
    "ScheduledController",
    "StateFeedback",
    "StaticGain",
    "as_controller",
    "bryson_weights",
    "closed_loop_boundary",
    "closed_loop_matrix",
    "compensator_from_lti",
    "judge_loop",
    "kalman_filter",
    "loop_margins",
    "lqg",
    "lqr",  # deprecated: lqr_controller
    "lqr_controller",
    "margins_over_speed",
    "mpc",
    "python_law",
    "schedule",
    "state_map",
    "static_gain",
    "with_sensor_filters",
]


def __getattr__(name: str) -> object:
    """Deprecated names, kept one release: ``StateGain`` (now :class:`StaticGain`, which also
    holds a gain on sensors)."""
    if name == "StateGain":
        import warnings

        warnings.warn(
            "aeroservo.design.StateGain is deprecated and will be removed in the next release: "
            "use aeroservo.design.StaticGain (static_gain builds it, on sensors or states)",
            DeprecationWarning,
            stacklevel=2,
        )
        return StaticGain
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
