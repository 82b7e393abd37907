"""The wing description and its structural finite-element discretization: segments, control
surfaces and actuators (:mod:`.wing`), the spanwise mesh (:mod:`.mesh`), the aeroelastic beam
element's shape functions (:mod:`.beam_element`) and the built-in wings (:mod:`.examples`).
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "Freeplay": "hinge_laws",
    "Bilinear": "hinge_laws",
    "Cubic": "hinge_laws",
    "Actuator": "wing",
    "ControlSurface": "wing",
    "Mesh": "mesh",
    "Segment": "wing",
    "Wing": "wing",
    "build_mesh": "mesh",
}

_MODULES = {"examples": "examples"}

__all__ = [
    "Freeplay",
    "Bilinear",
    "Cubic",
    "Actuator",
    "ControlSurface",
    "Mesh",
    "Segment",
    "Wing",
    "build_mesh",
    "examples",
]

__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC, _MODULES)
