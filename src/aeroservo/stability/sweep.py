"""All eigenvalues on a speed grid by dense ``eig``, ordered by eigenvector correlation (a second,
independent method, and the full spectrum for plots).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .._threads import blas_limited
from ..errors import InputError
from .assignment import min_cost_assignment
from .boundary import _as_system

__all__ = ["EigenSweep", "eigen_sweep"]


@dataclass
class EigenSweep:
    """All eigenvalues on a speed grid, ordered consistently by eigenvector correlation.

    Attributes
    ----------
    speeds : ndarray (n_speeds,)
        [m/s]
    eigenvalues : ndarray (n_speeds, n_states) complex
        Column j follows one branch [1/s].
    """

    speeds: np.ndarray
    eigenvalues: np.ndarray


@blas_limited
def eigen_sweep(model: object, speeds: np.ndarray, density: float | None = None) -> EigenSweep:
    """Dense eigenvalues of ``A(V)`` on a grid, branch-ordered by eigenvector correlation.

    Parameters
    ----------
    model : AeroelasticModel, TypicalSection or FirstOrderSystem
    speeds : array_like
        Increasing airspeeds [m/s].
    density : float
        Air density [kg/m^3] (not needed for a FirstOrderSystem).

    Returns
    -------
    EigenSweep
    """
    system, _ = _as_system(model, density)
    speeds = np.asarray(speeds, dtype=float)
    if speeds.ndim != 1 or speeds.size < 1 or np.any(np.diff(speeds) <= 0):
        raise InputError("speeds: must be a 1-D increasing array [m/s]")
    out = np.empty((speeds.size, system.n_states), dtype=complex)
    prev = None
    for i, v in enumerate(speeds):
        w, X = sla.eig(system.state_matrix(v))
        X = X / np.linalg.norm(X, axis=0)
        if prev is not None:
            corr = np.abs(prev.conj().T @ X) ** 2
            rows, cols = min_cost_assignment(-corr)
            order = cols[np.argsort(rows)]
            w, X = w[order], X[:, order]
        out[i] = w
        prev = X
    return EigenSweep(speeds, out)
