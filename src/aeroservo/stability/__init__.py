"""Stability versus airspeed: eigenpair continuation (:mod:`.tracking`), the flutter and
divergence boundary (:mod:`.boundary`, :mod:`.divergence`), dense eigenvalue sweeps
(:mod:`.sweep`) and the frequency-domain p-k method with exact Theodorsen aerodynamics
(:mod:`.pk`).
"""

from .boundary import flutter_boundary
from .divergence import divergence_speed
from .pk import pk_flutter
from .result import Crossing, FlutterResult
from .sweep import EigenSweep, eigen_sweep

__all__ = [
    "Crossing",
    "EigenSweep",
    "FlutterResult",
    "divergence_speed",
    "eigen_sweep",
    "flutter_boundary",
    "pk_flutter",
]
