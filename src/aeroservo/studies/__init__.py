"""Studies: scenarios (:mod:`.scenario`) and their runs (:mod:`.runs`), trade studies over
design and controller parameters on Dask (:mod:`.trade`), gust loads of CS-25.341 over
flight points (:mod:`.gust_loads`, :mod:`.gust_run`).
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "LCOSetup": "lco",
    "LCOSweep": "lco",
    "LCOResult": "lco_result",
    "run_lco": "lco_run",
    "Run": "kinds",
    "Scenario": "scenario",
    "quick": "scenario",
    "run_scenario": "kinds",
    "tuned_gust_loads": "tuned_gusts",
    "turbulence_response": "turbulence",
    "FlightPoint": "gust_loads",
    "GustLoadsStudy": "gust_loads",
    "run_gust_loads": "gust_run",
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
