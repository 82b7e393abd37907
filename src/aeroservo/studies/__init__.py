"""Studies: scenarios (:mod:`.scenario`) and their runs (:mod:`.runs`), trade studies over
design and controller parameters on Dask (:mod:`.trade`), gust loads of CS-25.341 over
flight points (:mod:`.gust`), limit cycles of nonlinear hinges (:mod:`.lco`); the registry of
scenario kinds (:mod:`.kinds`).
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "LCOSetup": "lco.study",
    "LCOSweep": "lco.study",
    "LCOResult": "lco.result",
    "run_lco": "lco.run",
    "Run": "kinds",
    "Scenario": "scenario",
    "quick": "scenario",
    "run_scenario": "kinds",
    "tuned_gust_loads": "gust.tuned",
    "turbulence_response": "gust.turbulence",
    "FlightPoint": "gust.study",
    "GustLoadsStudy": "gust.study",
    "run_gust_loads": "gust.run",
}

__all__ = [
    "LCOSetup",
    "LCOSweep",
    "LCOResult",
    "run_lco",
    "Run",
    "Scenario",
    "quick",
    "run_scenario",
    "tuned_gust_loads",
    "turbulence_response",
    "FlightPoint",
    "GustLoadsStudy",
    "run_gust_loads",
]

__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC)
