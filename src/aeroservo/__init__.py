"""aeroservo: time-domain aero-servo-elastic analysis of wings with control surfaces."""

from . import examples
from .aeroelastic import AeroelasticModel, NaturalModes
from .errors import InputError
from .model import Actuator, ControlSurface, Segment, Wing
from .signals import Sensor
from .stability import FlutterResult, divergence_speed, eigen_sweep, flutter_boundary
from .statespace import Servo, StateSpaceBuilder, statespace, statespace_family
from .wagner import KUSSNER_SETS, WAGNER_SETS, IndicialSet

__version__ = "0.1.0"

__all__ = [
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
