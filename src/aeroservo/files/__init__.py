"""User files: TOML tables and their validation (:mod:`.toml_tables`), wing, controller and
scenario files (:mod:`.wing_file`, :mod:`.controller_file`, :mod:`.scenario_file`), a wing file
as one model (:mod:`.wing_model`), result files (:mod:`.results`), the outputs of a run written
as a set (:mod:`.outputs`) and state-space exports (:mod:`.statespace_export`).
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "export_mat": "statespace_export",
    "export_npz": "statespace_export",
    "WingModel": "wing_model",
    "load_controller": "controller_file",
    "load_gust_loads": "gust_loads_file",
    "load_hinges": "wing_file",
    "load_lco": "lco_file",
    "load_model": "wing_model",
    "load_result": "results",
    "load_scenario": "scenario_file",
    "load_wing": "wing_file",
    "resolve_wing": "wing_file",
    "save_result": "results",
    "write_gust_loads": "gust_loads_file",
    "write_lco": "lco_file",
    "write_run": "outputs",
}

__all__ = [
    "WingModel",
    "export_mat",
    "export_npz",
    "load_controller",
    "load_gust_loads",
    "load_hinges",
    "load_lco",
    "load_model",
    "load_result",
    "load_scenario",
    "load_wing",
    "resolve_wing",
    "save_result",
    "write_gust_loads",
    "write_lco",
    "write_run",
]

__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC)
