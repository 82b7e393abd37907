"""aeroservo: time-domain aero-servo-elastic analysis of wings with control surfaces."""

from ._version import __version__
from .aero.indicial import KUSSNER_SETS, WAGNER_SETS, IndicialSet
from .errors import InputError
from .linear.models import statespace, statespace_family
from .linear.signals import Sensor
from .linear.state_space import Servo, StateSpaceBuilder
from .stability.boundary import flutter_boundary
from .stability.divergence import divergence_speed
from .stability.result import FlutterResult
from .stability.sweep import eigen_sweep
from .structure import examples
from .structure.wing import Actuator, ControlSurface, Segment, Wing
from .system.aeroelastic import AeroelasticModel, NaturalModes

__all__ = [
    "__version__",
    "AeroelasticModel",
    "Actuator",
    "ControlSurface",
    "FlutterResult",
    "IndicialSet",
    "InputError",
    "KUSSNER_SETS",
    "NaturalModes",
    "Segment",
    "Sensor",
    "Servo",
    "StateSpaceBuilder",
    "WAGNER_SETS",
    "Wing",
    "divergence_speed",
    "eigen_sweep",
    "examples",
    "flutter_boundary",
    "statespace",
    "statespace_family",
]
