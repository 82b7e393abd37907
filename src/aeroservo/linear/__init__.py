"""Linear models for control design: named signals and sensors (:mod:`.signals`), the
state-space builder (:mod:`.state_space`), models at a flight condition or over a speed grid
(:mod:`.models`) and model reduction (:mod:`.reduction`).
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "NonlinearPlant": "hinge_plant",
    "nonlinear_plant": "hinge_plant",
    "section_plant": "hinge_plant",
    "Sensor": "signals",
    "Servo": "state_space",
    "StateSpaceBuilder": "state_space",
    "balanced_truncation": "reduction",
    "compare_frequency_response": "reduction",
    "discretize": "models",
    "modal_controllability": "reduction",
    "statespace": "models",
    "statespace_family": "models",
}

__all__ = [
    "NonlinearPlant",
    "nonlinear_plant",
    "section_plant",
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

__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC)
