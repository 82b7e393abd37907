"""Strip aerodynamics independent of the structure: Theodorsen's thin-airfoil theory with a
flap (:mod:`.theodorsen`), Wagner and Kussner indicial functions (:mod:`.indicial`) and gust
velocity fields (:mod:`.gusts`).
"""

from .gusts import GustSeries, OneMinusCosine, Turbulence
from .indicial import KUSSNER_SETS, WAGNER_SETS, IndicialSet, kussner_set, wagner_set
from .theodorsen import section_aero, theodorsen_function

__all__ = [
    "GustSeries",
    "IndicialSet",
    "KUSSNER_SETS",
    "OneMinusCosine",
    "Turbulence",
    "WAGNER_SETS",
    "kussner_set",
    "section_aero",
    "theodorsen_function",
    "wagner_set",
]
