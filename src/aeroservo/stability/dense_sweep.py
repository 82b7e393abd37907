"""All eigenvalues on a speed grid by dense ``eig``, ordered by eigenvector correlation (a second,
independent method, and the full spectrum for plots).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .._threads import blas_limited
from ..errors import RANGES, InputError, check_number
from .assignment import min_cost_assignment
from .boundary import _as_system

__all__ = ["EigenSweep", "eigen_sweep", "MAX_SPEED", "MAX_BYTES"]

MAX_SPEED = RANGES["airspeed"].hi
"""Largest airspeed [m/s] of a sweep."""
MAX_BYTES = 1 << 30
"""Largest memory [bytes] of the eigenvalue table of a sweep (1 GiB)."""


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
        Increasing airspeeds [m/s], in [0, :data:`MAX_SPEED`].
    density : float
        Air density [kg/m^3] (not needed for a FirstOrderSystem).

    Returns
    -------
    EigenSweep
    """
    system, _ = _as_system(model, density)
    speeds = _speed_grid(speeds, system.n_states)
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


def _speed_grid(speeds: object, n_states: int) -> np.ndarray:
    """The speeds as a 1-D increasing float array within [0, MAX_SPEED], or InputError."""
    try:
        ok = isinstance(speeds, (list, tuple, range, np.ndarray))
        arr = np.asarray(speeds) if ok else None
    except ValueError:  # ragged nesting
        arr = None
    if arr is None or arr.dtype.kind not in "iuf" or arr.ndim != 1 or arr.size < 1:
        shown = repr(arr.tolist()) if arr is not None and arr.size <= 8 else repr(speeds)
        if len(shown) > 80 or "\n" in shown:
            shown = f"<{type(speeds).__name__} of shape {np.shape(arr)}>"
        raise InputError(f"speeds = {shown}: expected a 1-D increasing array of real speeds [m/s]")
    need = arr.size * n_states * 16
    if need > MAX_BYTES:
        raise InputError(
            f"speeds: {arr.size} speeds x {n_states} states need {need / 2**30:.3g} GiB of "
            f"eigenvalues, above the limit of {MAX_BYTES / 2**30:g} GiB; use fewer speeds"
        )
    arr = arr.astype(float)
    bad = np.flatnonzero(~np.isfinite(arr) | (arr < 0) | (arr > MAX_SPEED))
    if bad.size:
        i = int(bad[0])
        check_number(f"speeds[{i}]", float(arr[i]), unit="m/s", lo=0.0, hi=MAX_SPEED)
    steps = np.flatnonzero(np.diff(arr) <= 0)
    if steps.size:
        i = int(steps[0]) + 1
        raise InputError(
            f"speeds[{i}] = {arr[i]:g}: speeds must increase (speeds[{i - 1}] = {arr[i - 1]:g})"
        )
    return arr
