"""Static divergence: the speeds at which the steady aeroelastic stiffness becomes singular.

``(Ks + rho V^2 K_static) q = 0`` has a non-trivial solution where ``V^2 = 1 / (rho mu)`` for a
real positive eigenvalue ``mu`` of ``-Ks^-1 K_static``. Exactly there ``det A(V) = 0``: a real
eigenvalue of the first-order system passes through zero. The eigenvalues are computed in the
basis of in-vacuo modes scaled to unit stiffness (``Ks -> I``), so that round-off is relative to
each mode's own scale, and an eigenvalue counts as a divergence only if it is real and positive
well above round-off (:data:`ROUND_OFF`): a wing whose elastic axis lies ahead of the quarter
chord has no divergence, and round-off eigenvalues (1e-13 of the largest) must not report one at
1e9 m/s.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ..errors import InputError, check_number
from ..system.first_order import FirstOrderSystem
from .modal import model_cache

__all__ = ["divergence_speed", "divergence_speeds", "static_speeds"]

ROUND_OFF = 1e-9
"""Eigenvalues ``mu`` below this fraction of the largest ``|mu|`` are round-off, not divergence."""


def static_speeds(Ks: np.ndarray, K_static: np.ndarray, density: float) -> np.ndarray:
    """Every static divergence speed [m/s], increasing.

    Parameters
    ----------
    Ks : ndarray (n, n)
        Structural stiffness (symmetric positive definite).
    K_static : ndarray (n, n)
        Steady aerodynamic stiffness per unit ``rho V^2`` (lag states eliminated).
    density : float
        Air density [kg/m^3].
    """
    Ks, K_static = _square("Ks", Ks), _square("K_static", K_static)
    if K_static.shape != Ks.shape:
        raise InputError(f"K_static: shape {K_static.shape}, expected {Ks.shape} like Ks")
    density = check_number("density", density, unit="kg/m^3", lo=0.0, lo_open=True)
    return _speeds(_divergence_eigenvalues(Ks, K_static), density)


def _divergence_eigenvalues(Ks: np.ndarray, K_static: np.ndarray) -> np.ndarray:
    """The real positive eigenvalues ``mu`` of ``-Ks^-1 K_static`` above round-off [m s^2/kg]:
    ``rho V^2 = 1 / mu`` at divergence (independent of the density)."""
    w2, phi = sla.eigh(Ks)  # Ks = phi diag(w2) phi^T, w2 > 0
    scale = phi / np.sqrt(np.clip(w2, np.finfo(float).tiny, None))
    S = -(scale.T @ K_static @ scale)
    mu = sla.eigvals(S)
    mu = mu[np.isfinite(mu)]
    if mu.size == 0:
        return np.empty(0)
    big = float(np.max(np.abs(mu)))
    keep = (mu.real > ROUND_OFF * big) & (np.abs(mu.imag) <= 1e-8 * np.abs(mu))
    return mu.real[keep]


def _speeds(mu: np.ndarray, density: float) -> np.ndarray:
    return np.sort(1.0 / np.sqrt(density * mu))


def divergence_speeds(system: FirstOrderSystem, model: object = None) -> np.ndarray:
    """Every static divergence speed [m/s] of a first-order system, increasing.

    Parameters
    ----------
    system : FirstOrderSystem
    model : AeroelasticModel, optional
        The model ``system`` comes from: the eigenvalues, which do not depend on the density,
        are then solved once per Mach number and kept on the model.
    """
    _check_system(system)
    if model is None:
        return static_speeds(system.Ks.toarray(), system.K_static, system.density)
    cache = model_cache(model)
    key = ("divergence", system.mach)
    if key not in cache:
        cache[key] = _divergence_eigenvalues(system.Ks.toarray(), system.K_static)
    return _speeds(cache[key], system.density)


def divergence_speed(system: FirstOrderSystem) -> float | None:
    """The lowest static divergence speed [m/s] of a first-order system, or None.

    Solves ``Ks q = -rho V^2 K_static q`` for the smallest positive ``V^2``
    (:func:`static_speeds`).
    """
    _check_system(system)
    v = divergence_speeds(system)
    return float(v[0]) if v.size else None


def _check_system(system: object) -> None:
    if not isinstance(system, FirstOrderSystem):
        what = type(system).__name__ if system is not None else "None"
        raise InputError(
            f"system = <{what}>: expected a FirstOrderSystem (pass model.system(density) for "
            "an AeroelasticModel or a TypicalSection)"
        )


def _square(field: str, value: object) -> np.ndarray:
    """A finite real square matrix as a float array, or InputError."""
    try:
        a = np.asarray(value)
    except ValueError:  # ragged nesting
        a = np.asarray(None)
    if a.dtype.kind not in "iuf" or a.ndim != 2 or a.shape[0] != a.shape[1] or a.size == 0:
        raise InputError(f"{field}: expected a real square matrix, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{field}: has NaN or infinite entries")
    return a.astype(float)
