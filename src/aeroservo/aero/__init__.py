"""Strip aerodynamics independent of the structure: Theodorsen's thin-airfoil theory with a
flap (:mod:`.theodorsen`), Wagner and Kussner indicial functions (:mod:`.indicial`) and gust
velocity fields (:mod:`.gusts`).
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "GustSeries": "gusts",
    "IndicialSet": "indicial",
    "KUSSNER_SETS": "indicial",
    "OneMinusCosine": "gusts",
    "Turbulence": "gusts",
    "WAGNER_SETS": "indicial",
    "kussner_set": "indicial",
    "section_aero": "theodorsen",
    "theodorsen_function": "theodorsen",
    "wagner_set": "indicial",
}

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

__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC)
