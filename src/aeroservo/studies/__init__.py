"""Studies: scenarios (:mod:`.scenario`) and their runs (:mod:`.runs`), trade studies over
design and controller parameters on Dask (:mod:`.trade`).
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "Run": "runs",
    "Scenario": "scenario",
    "quick": "scenario",
    "run_scenario": "runs",
    "tuned_gust_loads": "tuned_gusts",
}

__all__ = [
    "Run",
    "Scenario",
    "quick",
    "run_scenario",
    "tuned_gust_loads",
]

__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC)
