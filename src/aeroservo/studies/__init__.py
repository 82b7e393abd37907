"""Studies: scenarios (:mod:`.scenario`) and their runs (:mod:`.runs`), trade studies over
design and controller parameters on Dask (:mod:`.trade`).
"""

from .runs import Run, run_scenario
from .scenario import Scenario, quick

__all__ = [
    "Run",
    "Scenario",
    "quick",
    "run_scenario",
]
