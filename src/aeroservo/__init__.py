"""aeroservo: time-domain aero-servo-elastic analysis of wings with control surfaces.

The public names below are imported on first use (PEP 562), so ``import aeroservo`` and the
command line load only what a task needs (``aeroservo --help`` does not import scipy).
"""

from __future__ import annotations

from ._lazy import lazy_attributes
from ._version import __version__
from .errors import AeroservoError, InputError, NumericalError, VerdictFailure
from .result_shape import use_shell as _use_shell

_PUBLIC = {
    "Freeplay": "structure.hinge_laws",
    "Bilinear": "structure.hinge_laws",
    "Cubic": "structure.hinge_laws",
    "NonlinearHinge": "system.hinge_elements",
    "TypicalSection": "system.section",
    "march_hinges": "simulate.hinges.march",
    "nonlinear_plant": "linear.hinge_plant",
    "run_lco": "studies.lco.run",
    "LCOSetup": "studies.lco.study",
    "LCOSweep": "studies.lco.study",
    "FlightPoint": "studies.gust.study",
    "GustLoadsStudy": "studies.gust.study",
    "run_gust_loads": "studies.gust.run",
    "TradeStudy": "studies.trade.study",
    "run_trade": "studies.trade.cluster",
    "import_nastran": "files.nastran.importer",
    "AeroelasticModel": "system.aeroelastic",
    "DoubletLattice": "aero.dlm_settings",
    "ConcentratedMass": "structure.masses",
    "Actuator": "structure.wing",
    "ControlSurface": "structure.wing",
    "FlutterResult": "stability.result",
    "IndicialSet": "aero.indicial",
    "KUSSNER_SETS": "aero.indicial",
    "NaturalModes": "system.aeroelastic",
    "Segment": "structure.wing",
    "Sensor": "linear.signals",
    "Servo": "linear.state_space",
    "StateSpaceBuilder": "linear.state_space",
    "WAGNER_SETS": "aero.indicial",
    "Wing": "structure.wing",
    "divergence_speed": "stability.divergence",
    "eigen_sweep": "stability.dense_sweep",
    "flutter_boundary": "stability.boundary",
    "flutter_sensitivities": "stability.sensitivity",
    "load_model": "files.wing_model",
    "load_result": "files.results",
    "save_result": "files.results",
    "statespace": "linear.models",
    "statespace_family": "linear.models",
    "as_controller": "design.interface",
    "Controller": "design.protocol",
    "LinearController": "design.protocol",
    "ScheduledController": "design.protocol",
}
_SUBPACKAGES = {
    "examples": "structure.examples",
    "aero": "aero",
    "design": "design",
    "files": "files",
    "linear": "linear",
    "plots": "plots",
    "simulate": "simulate",
    "stability": "stability",
    "structure": "structure",
    "studies": "studies",
    "system": "system",
}

__all__ = [
    "__version__",
    "AeroservoError",
    "InputError",
    "NumericalError",
    "VerdictFailure",
    "examples",
    *sorted(_PUBLIC),
]


__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC, _SUBPACKAGES)


def _shell(name: str):
    """The functions of the upper stages that results use (:mod:`aeroservo.result_shape`):
    the one writer of result files and the figures ``plots/`` draws of results below it,
    imported when first asked for."""
    if name == "save_result":
        from .files.results import save_result

        return save_result
    if name in ("plot_vg", "plot_root_locus"):
        from .plots import flutter

        return getattr(flutter, name)
    if name in ("plot_loop_margins", "plot_margin_sweep"):
        from .plots import margins

        return getattr(margins, name)
    raise KeyError(name)


_use_shell(_shell)
