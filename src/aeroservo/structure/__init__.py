"""The wing description and its structural finite-element discretization: segments, control
surfaces and actuators (:mod:`.wing`), the spanwise mesh (:mod:`.mesh`), the aeroelastic beam
element's shape functions (:mod:`.beam_element`) and the built-in wings (:mod:`.examples`).
"""

from . import examples
from .mesh import Mesh, build_mesh
from .wing import Actuator, ControlSurface, Segment, Wing

__all__ = [
    "Actuator",
    "ControlSurface",
    "Mesh",
    "Segment",
    "Wing",
    "build_mesh",
    "examples",
]
