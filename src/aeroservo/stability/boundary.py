"""The flutter and divergence boundary of a model at one air density.

:func:`flutter_boundary` follows the lowest modes in speed (:mod:`aeroservo.stability.tracking`),
finds every change of sign of the real part of each tracked branch by root finding (relative
tolerance ``rtol``, not the grid spacing), locates hump modes whose peak lies between grid
points (:func:`sign_changes`), and takes the divergence speed from the steady equations
(:mod:`aeroservo.stability.divergence`).

Damping convention: ``damping_ratio = -Re(lambda) / |lambda|`` (positive: stable);
V-g plots show ``g = -2 zeta`` (positive: unstable).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._threads import blas_limited
from ..errors import InputError, check_int, check_number
from ..system.first_order import FirstOrderSystem
from .divergence import divergence_speed
from .result import Crossing, FlutterResult
from .tracking import EigenTracker, TrackedModes

__all__ = ["flutter_boundary", "sign_changes"]


def _as_system(model: object, density: float | None) -> tuple[FirstOrderSystem, Callable | None]:
    if isinstance(model, FirstOrderSystem):
        return model, None
    if density is None:
        raise InputError("density = None: give the air density [kg/m^3]")
    rho = check_number("density", density, unit="kg/m^3", lo=0.0, lo_open=True)
    return model.system(rho), getattr(model, "label_modes", None)


@blas_limited
def flutter_boundary(
    model: object,
    density: float | None = None,
    *,
    v_max: float | None = None,
    n_modes: int | None = None,
    rtol: float = 1e-7,
    progress: Callable[[float], None] | None = None,
) -> FlutterResult:
    """Flutter and divergence boundaries of a model at one air density.

    Parameters
    ----------
    model : AeroelasticModel, TypicalSection or FirstOrderSystem
        Anything with ``system(density)``; a :class:`FirstOrderSystem` is used as is.
    density : float
        Air density [kg/m^3].
    v_max : float, optional
        Upper end of the speed range [m/s]. Default: 1.2 x the divergence speed, or
        4 b omega_2 (semichord times second in-air frequency) when there is no divergence.
    n_modes : int, optional
        Number of lowest modes tracked (default: 8, or all if the model has fewer).
    rtol : float
        Relative tolerance on crossing speeds (the issue asks 1e-5; default 1e-7).
    progress : callable, optional
        Called with each accepted speed [m/s].

    Returns
    -------
    FlutterResult
    """
    system, labeller = _as_system(model, density)
    n_modes = min(8, system.n_q) if n_modes is None else n_modes
    n_modes = check_int("n_modes", n_modes, lo=1, hi=system.n_q)
    lam0, X0 = system.modes_at_rest(n_modes)
    v_div = divergence_speed(system)
    if v_max is None:
        if v_div is not None:
            v_max = 1.2 * v_div
        else:
            v_max = 4.0 * system.semichord * float(np.abs(lam0[min(1, lam0.size - 1)]))
    v_max = check_number("v_max", v_max, unit="m/s", lo=0.0, lo_open=True)

    tracker = EigenTracker(system)
    tracked = tracker.track(v_max, lam0, X0, progress=progress)
    crossings = _find_crossings(tracker, tracked, rtol)
    if labeller is not None:
        labels = labeller(X0[: system.n_q].real)
    else:
        labels = [f"mode {j + 1}" for j in range(n_modes)]
    return FlutterResult(
        speeds=tracked.speeds,
        eigenvalues=tracked.eigenvalues,
        mode_labels=list(labels),
        crossings=crossings,
        divergence_speed=v_div,
        density=system.density,
        v_max=v_max,
        n_states=system.n_states,
        info={"n_factorizations": tracker.n_factorizations},
    )


class _Branch:
    """One tracked branch: its eigenvalue anywhere in the grid's range, by continuation."""

    def __init__(self, tracker: EigenTracker, tr: TrackedModes, j: int):
        self.tracker = tracker
        self.V = tr.speeds
        self.lam = tr.eigenvalues[:, j]
        self.vec = tr.vectors[:, :, j]
        self.j = j

    def eig(self, v: float, k: int) -> complex:
        """Eigenvalue at speed v, continued from grid point k (the inboard end of a bracket)."""
        V, lam = self.V, self.lam
        t = (v - V[k]) / (V[k + 1] - V[k])
        guess = lam[k] + t * (lam[k + 1] - lam[k])
        return self.tracker.follow(v, guess, self.vec[k], V[k])[0]

    def re(self, v: float, k: int) -> float:
        return float(self.eig(v, k).real)

    def crossing(self, v: float, k: int, rising: bool) -> Crossing:
        """The crossing at speed v (a root of Re(lambda) inside grid interval k)."""
        lam_c = self.eig(v, k)
        osc = abs(lam_c.imag) > 1e-6 * max(abs(lam_c.real), 1.0)
        kind = ("onset" if rising else "recovery") if osc else "divergence"
        return Crossing(float(v), abs(lam_c.imag) / (2 * np.pi) if osc else 0.0, self.j, kind)


HUMP_ZETA = 0.05
"""Interior extrema of Re(lambda) with |damping ratio| below this are refined between grid
points (the step control keeps eigenvalue changes per step below 10 %, so a hump that crosses
zero cannot hide behind grid values further from zero than this)."""


def sign_changes(
    fun: Callable[[float, int], float],
    V: np.ndarray,
    g: np.ndarray,
    zeta: np.ndarray,
    rtol: float,
    first: int = 1,
) -> list[tuple[float, bool, int]]:
    """Roots in speed of a continuous stability measure known on a grid, humps included.

    Parameters
    ----------
    fun : callable
        ``fun(v, k)``: the measure (e.g. Re(lambda) [1/s]) at speed v inside grid interval k.
    V : ndarray
        Increasing grid speeds [m/s].
    g : ndarray
        The measure on the grid (negative: stable).
    zeta : ndarray
        Damping ratio on the grid; interior extrema with ``|zeta| < HUMP_ZETA`` that do not
        change sign on the grid are refined (a hump that crosses zero between grid points).
    rtol : float
        Relative tolerance on the roots.
    first : int
        Index of the first grid point used in the sign test (1 skips V = 0, where an undamped
        structure has Re = 0 exactly).

    Returns
    -------
    list of (speed, rising, k)
        Root [m/s], whether the measure goes from negative to positive, grid interval.
    """
    from scipy.optimize import brentq, minimize_scalar

    def root(k: int, a: float, b: float) -> float:
        return float(brentq(fun, a, b, args=(k,), xtol=rtol * b, rtol=1e-15))

    out = []
    for k in range(first, V.size - 1):
        if (g[k] < 0) != (g[k + 1] < 0):
            out.append((root(k, V[k], V[k + 1]), bool(g[k] < 0), k))
    for k in range(first + 1, V.size - 1):
        for sgn in (1.0, -1.0):
            gk = sgn * g
            if not (gk[k] >= gk[k - 1] and gk[k] >= gk[k + 1] and gk[k] < 0):
                continue
            if abs(zeta[k]) >= HUMP_ZETA:
                continue
            # search both grid intervals around the extreme, continuing from the left one
            sol = minimize_scalar(
                lambda v, s=sgn, k=k: -s * fun(v, k - 1 if v < V[k] else k),
                bounds=(V[k - 1], V[k + 1]),
                method="bounded",
                options={"xatol": rtol * V[k + 1]},
            )
            if -sol.fun > 0:
                vpk = float(sol.x)
                kk = k - 1 if vpk < V[k] else k
                out.append((root(kk, V[kk], vpk), sgn > 0, kk))
                out.append((root(kk, vpk, V[kk + 1]), sgn < 0, kk))
    return sorted(out)


def _find_crossings(tracker: EigenTracker, tr: TrackedModes, rtol: float) -> list[Crossing]:
    V = tr.speeds
    out: list[Crossing] = []
    for j in range(tr.eigenvalues.shape[1]):
        br = _Branch(tracker, tr, j)
        zeta = -br.lam.real / np.maximum(np.abs(br.lam), 1e-300)
        for v, rising, k in sign_changes(br.re, V, br.lam.real, zeta, rtol):
            out.append(br.crossing(v, k, rising))
    out.sort(key=lambda c: c.speed)
    return out
