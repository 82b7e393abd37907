"""Closed-loop time marching: a continuous linear plant, a sampled controller and actuator
limits (:mod:`.march`), and the time histories it produces (:mod:`.result`).
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "march_hinges": "hinges.march",
    "HingeSimulation": "hinges.march",
    "classify": "lco_detect",
    "LCOVerdict": "lco_detect",
    "SimulationResult": "result",
    "simulate": "march",
}

__all__ = [
    "march_hinges",
    "HingeSimulation",
    "classify",
    "LCOVerdict",
    "SimulationResult",
    "simulate",
]

__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC)
