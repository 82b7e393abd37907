"""Linear models for control design: named signals and sensors (:mod:`.signals`), the
state-space builder (:mod:`.state_space`), models at a flight condition or over a speed grid
(:mod:`.models`) and model reduction (:mod:`.reduction`).
"""

from .models import discretize, statespace, statespace_family
from .reduction import balanced_truncation, compare_frequency_response, modal_controllability
from .signals import Sensor
from .state_space import Servo, StateSpaceBuilder

__all__ = [
    "Sensor",
    "Servo",
    "StateSpaceBuilder",
    "balanced_truncation",
    "compare_frequency_response",
    "discretize",
    "modal_controllability",
    "statespace",
    "statespace_family",
]
