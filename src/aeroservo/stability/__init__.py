"""Stability versus airspeed: eigenpair continuation (:mod:`.tracking`), the flutter and
divergence boundary (:mod:`.boundary`, :mod:`.divergence`), dense eigenvalue sweeps
(:mod:`.sweep`), the frequency-domain p-k method with exact Theodorsen aerodynamics
(:mod:`.pk`) and analytic sensitivities of the flutter and divergence speeds
(:mod:`.sensitivity`).
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "DescribingBranches": "describing_function",
    "describing_branches": "describing_function",
    "Crossing": "result",
    "EigenSweep": "dense_sweep",
    "FlutterResult": "result",
    "divergence_speed": "divergence",
    "eigen_sweep": "dense_sweep",
    "flutter_boundary": "boundary",
    "flutter_sensitivities": "sensitivity",
    "FlutterSensitivities": "sensitivity",
    "pk_flutter": "pk",
}

__all__ = [
    "DescribingBranches",
    "describing_branches",
    "Crossing",
    "EigenSweep",
    "FlutterResult",
    "divergence_speed",
    "eigen_sweep",
    "flutter_boundary",
    "flutter_sensitivities",
    "FlutterSensitivities",
    "pk_flutter",
]

__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC)
