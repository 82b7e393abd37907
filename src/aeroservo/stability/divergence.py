"""Static divergence: the speeds at which the steady aeroelastic stiffness becomes singular."""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ..system.first_order import FirstOrderSystem

__all__ = ["divergence_speed"]


def divergence_speed(system: FirstOrderSystem) -> float | None:
    """Static divergence speed [m/s] of a first-order system, or None.

    Solves ``Ks q = -rho V^2 K_static q`` for the smallest positive ``V^2``.
    """
    ks = system.Ks.toarray()
    mu = sla.eigvals(-system.K_static, ks)
    mu = mu[np.isfinite(mu)]
    real = np.abs(mu.imag) <= 1e-8 * np.abs(mu)
    mu = mu[real & (mu.real > 0)].real
    if mu.size == 0:
        return None
    return float(1.0 / np.sqrt(system.density * mu.max()))
