"""Closed-loop time marching: a continuous linear plant, a sampled controller and actuator
limits (:mod:`.march`), and the time histories it produces (:mod:`.result`).
"""

from .march import simulate
from .result import SimulationResult

__all__ = [
    "SimulationResult",
    "simulate",
]
