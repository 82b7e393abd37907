"""Stability versus airspeed: eigenpair continuation (:mod:`.tracking`), the flutter and
divergence boundary (:mod:`.boundary`, :mod:`.divergence`), dense eigenvalue sweeps
(:mod:`.sweep`) and the frequency-domain p-k method with exact Theodorsen aerodynamics
(:mod:`.pk`).
"""

from .._lazy import lazy_attributes

_PUBLIC = {
    "Crossing": "result",
    "EigenSweep": "sweep",
    "FlutterResult": "result",
    "divergence_speed": "divergence",
    "eigen_sweep": "sweep",
    "flutter_boundary": "boundary",
    "pk_flutter": "pk",
}

__all__ = [
    "Crossing",
    "EigenSweep",
    "FlutterResult",
    "divergence_speed",
    "eigen_sweep",
    "flutter_boundary",
    "pk_flutter",
]

__getattr__, __dir__ = lazy_attributes(__name__, _PUBLIC)
