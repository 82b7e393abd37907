"""The aeroelastic system: structure and aerodynamics assembled into speed- and
density-independent matrices (:mod:`.assembly`, :mod:`.matrices`), the first-order equations
``E x' = (A0 + V A1 + V^2 A2) x`` (:mod:`.first_order`), and the models that tie them
together: a wing stick model (:mod:`.aeroelastic`) and a typical section (:mod:`.section`).
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "NonlinearHinge": "hinge_elements",
    "HingeElements": "hinge_elements",
    "conner_section": "section",
    "AeroMatrices": "matrices",
    "AeroelasticModel": "aeroelastic",
    "FirstOrderSystem": "first_order",
    "NaturalModes": "aeroelastic",
    "StripGroup": "matrices",
    "TypicalSection": "section",
}

__all__ = [
    "NonlinearHinge",
    "HingeElements",
    "conner_section",
    "AeroMatrices",
    "AeroelasticModel",
    "FirstOrderSystem",
    "NaturalModes",
    "StripGroup",
    "TypicalSection",
]

__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC)
