"""Trade studies: flutter suppression over a grid of design and controller parameters, on Dask.

* :mod:`.study` - the study definition (:class:`TradeStudy`, :data:`PARAMETERS`, :data:`METRICS`);
* :mod:`.grid` - the grid of cases and their stable ids;
* :mod:`.cases` - one case: variant wing, open and closed loop, gust (:func:`evaluate_case`);
* :mod:`.cluster` - the Dask runner (:func:`run_trade`, :func:`local_cluster`);
* :mod:`.workers` - the Dask cluster, reached and checked, and its failures;
* :mod:`.results` - tables and datasets (:class:`TradeResult`, :func:`load_trade`);
* :mod:`.ranking` - which case is best, and why;
* :mod:`.plots` - heat maps and the Pareto front.
"""

from .cases import evaluate_case, variant_wing
from .cluster import local_cluster, run_trade
from .grid import case_id, study_settings, trade_cases
from .plots import pareto_front
from .results import TradeResult, load_trade
from .study import METRICS, PARAMETERS, TradeStudy

__all__ = [
    "METRICS",
    "PARAMETERS",
    "TradeResult",
    "TradeStudy",
    "case_id",
    "evaluate_case",
    "load_trade",
    "local_cluster",
    "pareto_front",
    "run_trade",
    "study_settings",
    "trade_cases",
    "variant_wing",
]
