"""User files: TOML tables and their validation (:mod:`.toml_tables`), wing, controller and
scenario files (:mod:`.wing_file`, :mod:`.controller_file`, :mod:`.scenario_file`), result
files (:mod:`.results`), the outputs of a run written as a set (:mod:`.outputs`) and
state-space exports (:mod:`.statespace_export`).
"""

from .controller_file import load_controller
from .outputs import write_run
from .results import load_result, save_result
from .scenario_file import load_scenario
from .statespace_export import export_mat, export_npz
from .wing_file import load_wing, resolve_wing

__all__ = [
    "export_mat",
    "export_npz",
    "load_controller",
    "load_result",
    "load_scenario",
    "load_wing",
    "resolve_wing",
    "save_result",
    "write_run",
]
