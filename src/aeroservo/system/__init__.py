"""The aeroelastic system: structure and aerodynamics assembled into speed- and
density-independent matrices (:mod:`.assembly`, :mod:`.matrices`), the first-order equations
``E x' = (A0 + V A1 + V^2 A2) x`` (:mod:`.first_order`), and the models that tie them
together: a wing stick model (:mod:`.aeroelastic`) and a typical section (:mod:`.section`).
"""

from .aeroelastic import AeroelasticModel, NaturalModes
from .first_order import FirstOrderSystem
from .matrices import AeroMatrices, StripGroup
from .section import TypicalSection

__all__ = [
    "AeroMatrices",
    "AeroelasticModel",
    "FirstOrderSystem",
    "NaturalModes",
    "StripGroup",
    "TypicalSection",
]
