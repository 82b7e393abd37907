"""Discrete tuned gusts of CS-25.341(a) on a linear state-space model (open loop).

The gust is ``U(t) = U_ds/2 (1 - cos(pi V t / H))`` for ``0 <= V t <= 2 H`` (V the true
airspeed of the model, ``U_ds`` the rule's design velocity turned into a true one,
:mod:`aeroservo.aero.gust_rules`), fed to the model's ``gust`` input (vertical velocity [m/s],
positive up, uniform along the span; t = 0 when the gust front reaches the leading edge, the
reference of the Kussner function; ``docs/statespace.md``). Loads are incremental (no 1 g
load).

Time march: exact discretization of ``x' = A x + B u`` for an input linear between samples
(first-order hold, by the matrix exponential of the augmented matrix, Van Loan 1978). It is
exact for every mode whatever its frequency (no stability limit), so the step only has to
resolve the input and the extremes: ``dt = (2 H_min / V) / steps_per_gust`` for every gradient
of the search (one exponential), and each extreme is refined by the parabola through its three
samples. The march covers the gust and ``settle_periods`` periods ``2 pi / |lambda|_min`` of the
slowest pole after it.

Tuning: the peak of each load over time is computed on ``n_gradients`` log-spaced gradients H;
each load's maximum and minimum are then refined by a bounded scalar search between the grid
neighbours of the best grid value. The model is linear: the negative gust gives the mirrored
response, so each load's maximum is ``max(max y+, -min y+)`` and its minimum the opposite.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from scipy.optimize import minimize_scalar

from ..aero.atmosphere import isa
from ..aero.gust_rules import GRADIENT_RANGE, design_gust_velocity, gust_tas
from ..errors import InputError, check_int, check_number

__all__ = ["GustExtreme", "TunedGustResult", "one_minus_cosine_response", "tuned_gust_loads"]


@dataclass(frozen=True)
class GustExtreme:
    """Extremes of one incremental load over the tuned-gust search.

    Attributes
    ----------
    load, unit : str
        Output name and unit.
    maximum, minimum : float
        Largest and smallest incremental load [unit] over gradients and both gust signs.
    max_gradient, min_gradient : float
        Tuned gust gradient H [m] of each.
    max_time, min_time : float
        Time [s] of each after the gust front reaches the wing.
    max_sign, min_sign : int
        Gust sign giving each (+1 up, -1 down).
    """

    load: str
    unit: str
    maximum: float
    max_gradient: float
    max_time: float
    max_sign: int
    minimum: float
    min_gradient: float
    min_time: float
    min_sign: int


@dataclass(frozen=True)
class TunedGustResult:
    """Result of :func:`tuned_gust_loads`.

    Attributes
    ----------
    speed : float
        True airspeed [m/s].
    altitude : float
        [m]
    gradients : ndarray
        Scanned gradients H [m].
    amplitudes : ndarray
        True design gust velocity U_ds [m/s] at each scanned gradient.
    peaks : ndarray
        (n_gradients, n_loads, 2): max and min over time of each load for the positive gust.
    extremes : dict
        Load name -> :class:`GustExtreme` (refined).
    dt : float
        Time step of the march [s].
    """

    speed: float
    altitude: float
    gradients: np.ndarray
    amplitudes: np.ndarray
    peaks: np.ndarray
    extremes: dict
    dt: float


class _March:
    """First-order-hold exact march of one input of a state-space model."""

    def __init__(self, sys, dt: float):
        names = list(sys.input_labels)
        if "gust" not in names:
            raise InputError(f"model inputs {names}: a 'gust' input is needed")
        j = names.index("gust")
        A = np.asarray(sys.A, dtype=float)
        n = A.shape[0]
        self.B = np.asarray(sys.B, dtype=float)[:, j]
        self.C = np.asarray(sys.C, dtype=float)
        self.D = np.asarray(sys.D, dtype=float)[:, j]
        M = np.zeros((n + 2, n + 2))
        M[:n, :n] = A * dt
        M[:n, n] = self.B * dt
        M[n, n + 1] = 1.0
        E = sla.expm(M)
        # x1 = Phi x0 + G0 u0 + G1 (u1 - u0), G0 = int_0^dt e^{A s} ds B,
        # G1 = int_0^dt e^{A s} (1 - s/dt) ds B
        self.Phi, self.G0, self.G1 = E[:n, :n], E[:n, n], E[:n, n + 1]
        self.dt = dt

    def run(self, u: np.ndarray) -> np.ndarray:
        """Outputs (n_samples, n_outputs) for the input samples ``u`` from rest."""
        du = np.diff(u)
        f = np.outer(u[:-1], self.G0) + np.outer(du, self.G1)
        x = np.zeros((u.size, self.Phi.shape[0]))
        PhiT = self.Phi.T
        for k in range(u.size - 1):
            x[k + 1] = x[k] @ PhiT + f[k]
        return x @ self.C.T + np.outer(u, self.D)


def _profile(t: np.ndarray, speed: float, gradient: float) -> np.ndarray:
    s = speed * t
    return np.where(s <= 2 * gradient, 0.5 * (1 - np.cos(np.pi * s / gradient)), 0.0)


def _peak(y: np.ndarray, dt: float, sign: int) -> tuple[float, float]:
    """Extreme (sign +1 max, -1 min) of samples ``y`` and its time, refined by a parabola."""
    k = int(np.argmax(sign * y))
    if 0 < k < y.size - 1:
        ym, y0, yp = sign * y[k - 1 : k + 2]
        den = ym - 2 * y0 + yp
        if den < 0:
            d = 0.5 * (ym - yp) / den
            return sign * (y0 - 0.25 * (ym - yp) * d), (k + d) * dt
    return float(y[k]), k * dt


def one_minus_cosine_response(
    sys, gradient: float, amplitude: float, duration: float, dt: float
) -> tuple[np.ndarray, np.ndarray]:
    """Response of every output to one 1-cos gust (``U(t) = amplitude/2 (1 - cos(pi V t/H))``).

    Parameters
    ----------
    sys : control.StateSpace
        Model with a ``gust`` input [m/s] and ``sys.speed`` [m/s] (true airspeed).
    gradient : float
        Gust gradient H [m] (half the gust length).
    amplitude : float
        U_ds [m/s true], signed.
    duration, dt : float
        Length and step of the march [s].

    Returns
    -------
    t : ndarray
        Times [s].
    y : ndarray
        (n_times, n_outputs) outputs in their units.
    """
    gradient = check_number("gust gradient H", gradient, unit="m", lo=0.0, lo_open=True)
    amplitude = check_number("gust amplitude", amplitude, unit="m/s")
    dt = check_number("dt", dt, unit="s", lo=0.0, lo_open=True)
    duration = check_number("duration", duration, unit="s", lo=dt)
    t = np.arange(int(np.ceil(duration / dt)) + 1) * dt
    return t, _March(sys, dt).run(amplitude * _profile(t, float(sys.speed), gradient))


def tuned_gust_loads(
    sys,
    altitude: float,
    f_g: float = 1.0,
    *,
    at_vd: bool = False,
    n_gradients: int = 20,
    refine: bool = True,
    steps_per_gust: int = 200,
    settle_periods: float = 2.0,
    amplitude: Callable[[float], float] | None = None,
) -> TunedGustResult:
    """Tuned discrete-gust search of CS-25.341(a), open loop, on every output of ``sys``.

    Parameters
    ----------
    sys : control.StateSpace
        Stable model (``aeroservo.statespace``) with a ``gust`` input, at the ISA density of
        ``altitude``; its outputs are the loads (e.g. ``root_shear``, ``root_bending_moment``,
        ``root_torque``, ``tip_le_accel``, hinge moments, sensors).
    altitude : float
        Altitude [m] (U_ref and the EAS-to-TAS conversion).
    f_g : float
        Flight profile alleviation factor
        (:func:`aeroservo.aero.gust_rules.flight_profile_alleviation`).
    at_vd : bool
        Half U_ref (design dive speed).
    n_gradients : int
        Log-spaced gradients H from 30 ft to 350 ft scanned before refinement.
    refine : bool
        Refine each load's maximum and minimum by a bounded scalar search in H.
    steps_per_gust : int
        Time steps per duration of the shortest gust (2 x 30 ft / V).
    settle_periods : float
        March length after the gust, in periods ``2 pi / |lambda|_min`` of the slowest pole.
    amplitude : callable, optional
        ``H [m] -> U_ds [m/s true]`` in place of the rule's (e.g. a unit gust).

    Returns
    -------
    TunedGustResult
    """
    speed = check_number("sys.speed", getattr(sys, "speed", None), unit="m/s", lo=0.0, lo_open=True)
    alt = check_number("altitude", altitude, unit="m", lo=0.0)
    rho = isa(alt).density
    dens = getattr(sys, "density", rho)
    if abs(dens - rho) > 1e-3 * rho:
        raise InputError(
            f"model density {dens} kg/m^3 is not the ISA density {rho:.4f} kg/m^3 at {alt} m"
        )
    n_g = check_int("n_gradients", n_gradients, lo=3)
    n_step = check_int("steps_per_gust", steps_per_gust, lo=10)
    settle = check_number("settle_periods", settle_periods, lo=0.0)
    if amplitude is None:

        def amplitude(h: float) -> float:
            return gust_tas(design_gust_velocity(h, alt, f_g, at_vd=at_vd), alt)

    ev = np.linalg.eigvals(np.asarray(sys.A, dtype=float))
    if ev.real.max() >= 0:
        raise InputError(
            f"model at {speed} m/s has an unstable or neutral pole {ev[np.argmax(ev.real)]:.4g}:"
            " open-loop gust loads need a stable model (below the flutter speed)"
        )
    h_lo, h_hi = GRADIENT_RANGE
    dt = 2 * h_lo / speed / n_step
    march = _March(sys, dt)
    tail = settle * 2 * np.pi / np.abs(ev).min()
    names = list(sys.output_labels)
    units = getattr(sys, "signal_units", {})
    cache: dict[float, tuple] = {}

    def peaks(h: float) -> tuple:
        if h not in cache:
            t = np.arange(int(np.ceil((2 * h / speed + tail) / dt)) + 1) * dt
            u = amplitude(h)
            y = march.run(u * _profile(t, speed, h))
            cache[h] = tuple(
                (_peak(y[:, i], dt, 1), _peak(y[:, i], dt, -1)) for i in range(y.shape[1])
            )
        return cache[h]

    grid = np.geomspace(h_lo, h_hi, n_g)
    table = np.array([[[p[0][0], p[1][0]] for p in peaks(h)] for h in grid])
    extremes = {}
    for i, name in enumerate(names):
        best = []
        for side, sgn in ((0, 1.0), (1, -1.0)):  # positive-gust max, positive-gust min
            k = int(np.argmax(sgn * table[:, i, side]))
            h_best = grid[k]
            if refine:
                lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, n_g - 1)]
                res = minimize_scalar(
                    lambda lh, i=i, side=side, sgn=sgn: -sgn * peaks(float(np.exp(lh)))[i][side][0],
                    bounds=(np.log(lo), np.log(hi)),
                    method="bounded",
                    options={"xatol": 1e-4},
                )
                h_try = float(np.exp(res.x))
                if sgn * peaks(h_try)[i][side][0] > sgn * peaks(h_best)[i][side][0]:
                    h_best = h_try
            val, t_at = peaks(h_best)[i][side]
            best.append((val, h_best, t_at))
        (pmax, hmax, tmax), (pmin, hmin, tmin) = best
        # negative gust mirrors: its max is -pmin, its min is -pmax
        if pmax >= -pmin:
            mx = (pmax, hmax, tmax, 1)
            mn = (-pmax, hmax, tmax, -1)
        else:
            mx = (-pmin, hmin, tmin, -1)
            mn = (pmin, hmin, tmin, 1)
        mx, mn = (tuple(float(v) for v in e[:3]) + (e[3],) for e in (mx, mn))
        extremes[name] = GustExtreme(name, units.get(name, ""), *mx, *mn)
    amps = np.array([amplitude(h) for h in grid])
    return TunedGustResult(speed, alt, grid, amps, table, extremes, dt)
