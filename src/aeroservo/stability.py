"""Aeroelastic stability versus airspeed: flutter and divergence boundaries, eigenvalue sweeps.

* :func:`flutter_boundary` follows the lowest modes in speed (:mod:`aeroservo.tracking`), finds
  every change of sign of the real part of each tracked branch by root finding (relative
  tolerance ``rtol``, not the grid spacing), locates hump modes whose peak lies between grid
  points, and computes the divergence speed from the steady equations.
* :func:`divergence_speed` solves ``(Ks + rho V^2 K_static) q = 0`` as a generalized
  eigenproblem; ``det A(V) = 0`` exactly there, so it is the speed at which a real eigenvalue of
  the first-order system passes through zero.
* :func:`eigen_sweep` computes all eigenvalues on a grid with dense ``eig`` and orders them by
  eigenvector correlation (a second, independent method, and the full spectrum for plots).

Damping convention: ``damping_ratio = -Re(lambda) / |lambda|`` (positive: stable);
V-g plots show ``g = -2 zeta`` (positive: unstable).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from ._threads import blas_limited
from .errors import InputError, check_int, check_number
from .system import FirstOrderSystem
from .tracking import EigenTracker, TrackedModes

__all__ = [
    "Crossing",
    "FlutterResult",
    "flutter_boundary",
    "divergence_speed",
    "eigen_sweep",
    "EigenSweep",
]


@dataclass(frozen=True)
class Crossing:
    """A tracked eigenvalue crossing the imaginary axis.

    Attributes
    ----------
    speed : float
        Airspeed [m/s].
    frequency : float
        Frequency at the crossing [Hz] (0 for divergence).
    mode : int
        Index of the tracked branch.
    kind : str
        ``"onset"`` (becomes unstable as speed increases), ``"recovery"`` (becomes stable
        again: the end of a hump) or ``"divergence"`` (a real eigenvalue through zero).
    """

    speed: float
    frequency: float
    mode: int
    kind: str


@dataclass
class FlutterResult:
    """Stability of a model versus airspeed at one density.

    Attributes
    ----------
    speeds : ndarray (n_speeds,)
        Grid on which the tracked modes are reported [m/s].
    eigenvalues : ndarray (n_speeds, n_modes) complex
        Tracked eigenvalues [1/s].
    mode_labels : list of str
        Name of each tracked branch (from its shape at V = 0).
    crossings : list of Crossing
        Every crossing found, in increasing speed.
    divergence_speed : float or None
        Static divergence speed [m/s] from the steady equations, or None if there is none.
    density : float
        Air density [kg/m^3].
    v_max : float
        Upper end of the speed range searched [m/s].
    n_states : int
        Size of the first-order system.
    """

    speeds: np.ndarray
    eigenvalues: np.ndarray
    mode_labels: list[str]
    crossings: list[Crossing]
    divergence_speed: float | None
    density: float
    v_max: float
    n_states: int
    info: dict = field(default_factory=dict)

    @property
    def frequencies(self) -> np.ndarray:
        """Frequencies of the tracked branches, Im(lambda)/2pi [Hz]."""
        return np.abs(self.eigenvalues.imag) / (2 * np.pi)

    @property
    def damping_ratio(self) -> np.ndarray:
        """-Re(lambda)/|lambda| [-] (positive: stable)."""
        mag = np.abs(self.eigenvalues)
        out = np.where(np.isnan(mag), np.nan, 0.0)  # NaN where a branch has ended (p-k)
        return np.divide(-self.eigenvalues.real, mag, out=out, where=mag > 0)

    @property
    def flutter(self) -> Crossing | None:
        """The lowest-speed oscillatory onset, or None if no flutter below ``v_max``."""
        onsets = [c for c in self.crossings if c.kind == "onset"]
        return min(onsets, key=lambda c: c.speed) if onsets else None

    @property
    def flutter_speed(self) -> float | None:
        """Flutter speed [m/s] or None."""
        f = self.flutter
        return None if f is None else f.speed

    @property
    def flutter_frequency(self) -> float | None:
        """Flutter frequency [Hz] or None."""
        f = self.flutter
        return None if f is None else f.frequency

    @property
    def flutter_mode(self) -> str | None:
        """Label of the branch that goes unstable first."""
        f = self.flutter
        return None if f is None else self.mode_labels[f.mode]

    def to_dict(self) -> dict:
        """JSON-ready summary (SI units: m/s, Hz, kg/m^3)."""
        return {
            "flutter_speed": self.flutter_speed,
            "flutter_frequency": self.flutter_frequency,
            "flutter_mode": self.flutter_mode,
            "divergence_speed": self.divergence_speed,
            "density": self.density,
            "n_states": self.n_states,
            "v_max": self.v_max,
            "crossings": [
                {
                    "speed": c.speed,
                    "frequency": c.frequency,
                    "mode": self.mode_labels[c.mode],
                    "kind": c.kind,
                }
                for c in self.crossings
            ],
            "modes": [
                {"label": lab, "frequency_at_rest": float(self.frequencies[0, j])}
                for j, lab in enumerate(self.mode_labels)
            ],
            **self.info,
        }

    def summary(self) -> str:
        """Readable multi-line summary."""
        lines = [f"density {self.density:g} kg/m^3, speeds searched 0 .. {self.v_max:.4g} m/s"]
        if self.flutter is None:
            lines.append("flutter: none found in the searched range")
        else:
            lines.append(
                f"flutter: {self.flutter_speed:.6g} m/s at {self.flutter_frequency:.5g} Hz "
                f"({self.flutter_mode})"
            )
        if self.divergence_speed is None:
            lines.append("divergence: none")
        else:
            lines.append(f"divergence: {self.divergence_speed:.6g} m/s")
        for c in self.crossings:
            lines.append(
                f"  {c.kind:<10s} {c.speed:10.6g} m/s  {c.frequency:8.5g} Hz  "
                f"{self.mode_labels[c.mode]}"
            )
        lines.append(
            f"{self.n_states} states; tracked: "
            + ", ".join(
                f"{lab} ({self.frequencies[0, j]:.4g} Hz)" for j, lab in enumerate(self.mode_labels)
            )
        )
        return "\n".join(lines)


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
    from scipy.optimize import linear_sum_assignment

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
            rows, cols = linear_sum_assignment(-corr)
            order = cols[np.argsort(rows)]
            w, X = w[order], X[:, order]
        out[i] = w
        prev = X
    return EigenSweep(speeds, out)
