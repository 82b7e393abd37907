"""Strip aerodynamics independent of the structure: Theodorsen's thin-airfoil theory with a
flap (:mod:`.theodorsen`), Wagner and Kussner indicial functions (:mod:`.indicial`) and gust
velocity fields (:mod:`.gusts`), the numbers of the gust rule CS-25.341(a) (:mod:`.gust_rules`).
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "GustSeries": "gusts",
    "IndicialSet": "indicial",
    "KUSSNER_SETS": "indicial",
    "OneMinusCosine": "gusts",
    "Turbulence": "gusts",
    "WAGNER_SETS": "indicial",
    "design_gust_velocity": "gust_rules",
    "flight_profile_alleviation": "gust_rules",
    "gust_tas": "gust_rules",
    "kussner_set": "indicial",
    "reference_gust_velocity": "gust_rules",
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
    "design_gust_velocity",
    "flight_profile_alleviation",
    "gust_tas",
    "kussner_set",
    "reference_gust_velocity",
    "section_aero",
    "theodorsen_function",
    "wagner_set",
]

__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC)
