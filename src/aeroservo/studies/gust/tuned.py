"""Discrete tuned gusts of CS-25.341(a) on a linear state-space model, open or closed loop.

The gust is ``U(t) = U_ds/2 (1 - cos(pi V t / H))`` for ``0 <= V t <= 2 H`` (V the true
airspeed of the model, ``U_ds`` the rule's design velocity turned into a true one,
:mod:`aeroservo.aero.gust_rules`), fed to the model's ``gust`` input (vertical velocity [m/s],
positive up, uniform along the span; t = 0 when the gust front reaches the leading edge, the
reference of the Kussner function; ``docs/statespace.md``). Loads are incremental (no 1 g
load).

Marches (:mod:`aeroservo.studies.gust.march`): open loop, the exact first-order-hold
discretization with ``dt = (2 H_min / V) / steps_per_gust`` for every gradient; with a
controller, the sampled loop of :func:`aeroservo.simulate.simulate` at the controller's rate,
with its actuator limits. Each extreme is refined by the parabola through its three samples.
The march covers the gust and ``settle_periods`` periods ``2 pi / |lambda|_min`` of the slowest
open-loop pole after it.

Tuning: the peak of each load over time is computed on ``n_gradients`` log-spaced gradients H
and both gust signs; each load's maximum and minimum are then refined by a bounded scalar
search between the grid neighbours of the best grid value. Open loop the model is linear: the
negative gust gives the mirrored response, so only the positive gust is marched. A closed loop
with actuator limits is not linear: both signs are marched.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar

from ...aero.atmosphere import isa
from ...aero.gust_rules import GRADIENT_RANGE, design_gust_velocity, gust_tas
from ...errors import InputError, check_int, check_number
from .march import ExactGustMarch, LoopGustMarch, one_minus_cosine_response, peak

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
    max_correlated, min_correlated : dict
        Every load at the time of the extreme (the correlated loads), by name [their units].
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
    max_correlated: dict = field(default_factory=dict)
    min_correlated: dict = field(default_factory=dict)

    def side(self, which: str) -> tuple[float, float, float, int, dict]:
        """``(value, gradient, time, sign, correlated)`` of ``"max"`` or ``"min"``."""
        if which not in ("max", "min"):
            raise InputError(f"side = {which!r}: expected 'max' or 'min'")
        p = which + "_"
        return (
            self.maximum if which == "max" else self.minimum,
            getattr(self, p + "gradient"),
            getattr(self, p + "time"),
            getattr(self, p + "sign"),
            getattr(self, p + "correlated"),
        )


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
        Time step of the march [s] (the controller's sample period in a closed loop).
    controller : str
        ``"open loop"`` or the controller's name.
    peaks_negative : ndarray or None
        As ``peaks`` for the negative gust, marched only for a loop that is not odd (a
        nonlinear law: MPC, a Python law); None: the mirror image (open loop, or a linear law
        with its symmetric limits, whose down gust is exactly minus the up gust).
    limited : dict
        Closed loop: control -> (n_gradients, 2) time [s] at a magnitude or rate limit, for
        the positive and negative gust (empty open loop).
    histories : dict
        ``(H, sign)`` -> ``(t, gust, y)`` of the critical gusts: times [s], gust velocity
        [m/s true], outputs (n_t, n_loads) in the order of ``loads``.
    loads : tuple of str
        Output names, in the order of the arrays.
    units : dict
        Units by load.
    """

    speed: float
    altitude: float
    gradients: np.ndarray
    amplitudes: np.ndarray
    peaks: np.ndarray
    extremes: dict
    dt: float
    controller: str = "open loop"
    peaks_negative: np.ndarray | None = None
    limited: dict = field(default_factory=dict)
    histories: dict = field(default_factory=dict)
    loads: tuple = ()
    units: dict = field(default_factory=dict)

    @property
    def saturated(self) -> bool:
        """True if a control reached a magnitude or rate limit in any gust of the search."""
        return any(float(np.max(a)) > 0 for a in self.limited.values())

    def history(self, load: str, side: str = "max") -> tuple[np.ndarray, np.ndarray, dict]:
        """Time history of the gust critical for ``load``'s ``side`` (``"max"``/``"min"``):
        ``(t [s], gust [m/s true], {load: values})``."""
        if load not in self.extremes:
            raise InputError(f"load {load!r}: not in the result ({list(self.extremes)})")
        _, h, _, sign, _ = self.extremes[load].side(side)
        t, gust, y = self.histories[(h, sign)]
        return t, gust, {n: y[:, i] for i, n in enumerate(self.loads)}


def _check_model(sys, altitude: float) -> tuple[float, float]:
    speed = check_number("sys.speed", getattr(sys, "speed", None), unit="m/s", lo=0.0, lo_open=True)
    alt = check_number("altitude", altitude, unit="m", lo=0.0)
    rho = isa(alt).density
    dens = getattr(sys, "density", rho)
    if abs(dens - rho) > 1e-3 * rho:
        raise InputError(
            f"model density {dens} kg/m^3 is not the ISA density {rho:.4f} kg/m^3 at {alt} m"
        )
    return speed, alt


def _check_stable(sys, speed: float, controller, delay: bool, sample_rate) -> None:
    """Refuse an unstable open loop, or a linear closed loop that is unstable."""
    if controller is None:
        ev = np.linalg.eigvals(np.asarray(sys.A, dtype=float))
        if ev.real.max() >= 0:
            raise InputError(
                f"model at {speed} m/s has an unstable or neutral pole "
                f"{ev[np.argmax(ev.real)]:.4g}: open-loop gust loads need a stable model "
                "(below the flutter speed)"
            )
        return
    from ...design.interface import as_controller, has_linear_law

    if not has_linear_law(as_controller(controller, sample_rate=sample_rate)):
        return  # a nonlinear law: judged by its march only
    from ...design.closed_loop import closed_loop_matrix

    A, dt = closed_loop_matrix(sys, controller, delay=delay, sample_rate=sample_rate)
    radius = float(np.max(np.abs(np.linalg.eigvals(A))))
    if radius >= 1.0:
        raise InputError(
            f"closed loop at {speed:.4g} m/s TAS is unstable (spectral radius {radius:.6g} of the "
            "sampled loop): gust loads need a stable loop"
        )


def tuned_gust_loads(
    sys,
    altitude: float,
    f_g: float = 1.0,
    *,
    at_vd: bool = False,
    controller=None,
    limits=None,
    delay: bool = False,
    sample_rate: float | None = None,
    n_gradients: int = 20,
    refine: bool = True,
    steps_per_gust: int = 200,
    settle_periods: float = 2.0,
    amplitude: Callable[[float], float] | None = None,
) -> TunedGustResult:
    """Tuned discrete-gust search of CS-25.341(a) on every output of ``sys``.

    Parameters
    ----------
    sys : control.StateSpace
        Model (``aeroservo.statespace`` or ``ControlLoop.plant``) with a ``gust`` input, at the
        ISA density of ``altitude``; its outputs are the loads (e.g. ``root_shear``,
        ``root_bending_moment``, ``root_torque``, ``tip_le_accel``, hinge moments, sensors).
        Open loop it must be stable (below flutter).
    altitude : float
        Altitude [m] (U_ref and the EAS-to-TAS conversion).
    f_g : float
        Flight profile alleviation factor
        (:func:`aeroservo.aero.gust_rules.flight_profile_alleviation`).
    at_vd : bool
        Half U_ref (design dive speed).
    controller : optional
        Any controller of :func:`aeroservo.design.as_controller` (a linear one must give a
        stable sampled loop); None for the open loop. The controls applied are added to the
        loads (e.g. the actuator's hinge moment).
    limits : aeroservo.design.Limits, optional
        Actuator limits of the closed loop (their saturation is reported in ``limited``).
    delay : bool
        One-sample computational delay of the closed loop.
    sample_rate : float, optional
        [Hz] for a continuous python-control compensator.
    n_gradients : int
        Log-spaced gradients H from 30 ft to 350 ft scanned before refinement.
    refine : bool
        Refine each load's maximum and minimum by a bounded scalar search in H.
    steps_per_gust : int
        Open loop: time steps per duration of the shortest gust (2 x 30 ft / V).
    settle_periods : float
        March length after the gust, in periods ``2 pi / |lambda|_min`` of the slowest pole.
    amplitude : callable, optional
        ``H [m] -> U_ds [m/s true]`` in place of the rule's (e.g. a unit gust).

    Returns
    -------
    TunedGustResult
    """
    speed, alt = _check_model(sys, altitude)
    n_g = check_int("n_gradients", n_gradients, lo=3)
    n_step = check_int("steps_per_gust", steps_per_gust, lo=10)
    settle = check_number("settle_periods", settle_periods, lo=0.0)
    if amplitude is None:

        def amplitude(h: float) -> float:
            return gust_tas(design_gust_velocity(h, alt, f_g, at_vd=at_vd), alt)

    _check_stable(sys, speed, controller, delay, sample_rate)
    h_lo, h_hi = GRADIENT_RANGE
    if controller is None:
        march = ExactGustMarch(sys, 2 * h_lo / speed / n_step)
        label, signs = "open loop", (1,)
    else:
        march = LoopGustMarch(sys, controller, limits, delay, sample_rate)
        label = getattr(march.controller, "name", None) or type(march.controller).__name__
        signs = (1,) if march.odd else (1, -1)
    dt = march.dt
    ev = np.linalg.eigvals(np.asarray(sys.A, dtype=float))
    tail = settle * 2 * np.pi / np.abs(ev).min()
    names = list(march.outputs)
    held = {names.index(c) for c in getattr(march, "controls", ())}  # zero-order hold: no parabola
    units = dict(getattr(sys, "signal_units", {}))
    cache: dict[tuple, tuple] = {}

    def run(h: float, sign: int):
        """Peaks ((max, t), (min, t)) per load of the gust (h, sign), its limits and arrays."""
        key = (h, sign)
        if key not in cache:
            t, y, lim = march.response(h, sign * amplitude(h), 2 * h / speed + tail)
            pk = tuple(
                (peak(y[:, i], dt, 1, i not in held), peak(y[:, i], dt, -1, i not in held))
                for i in range(y.shape[1])
            )
            cache[key] = (pk, lim, t, y)
        return cache[key]

    def signed(h: float, sign: int) -> tuple[np.ndarray, np.ndarray]:
        """Times and outputs of the gust (h, sign); open loop the mirror of the positive one."""
        if len(signs) == 1:
            _, _, t, y = run(h, 1)
            return t, sign * y
        _, _, t, y = run(h, sign)
        return t, y

    grid = np.geomspace(h_lo, h_hi, n_g)
    tables = {
        s: np.array([[[p[0][0], p[1][0]] for p in run(h, s)[0]] for h in grid]) for s in signs
    }
    extremes = {}
    for i, name in enumerate(names):
        found = {}
        # one sign marched (an odd loop): the side whose grid extreme is below DOMINATED of the
        # other's cannot win after refinement, so it is not refined (only compared)
        mags = (tables[1][:, i, 0].max(), -tables[1][:, i, 1].min())
        for side, sgn in ((0, 1.0), (1, -1.0)):  # max, min
            cands = []
            dominated = len(signs) == 1 and mags[side] < DOMINATED * mags[1 - side]
            for s in signs:
                k = int(np.argmax(sgn * tables[s][:, i, side]))
                h_best = grid[k]
                if refine and not dominated:
                    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, n_g - 1)]
                    res = minimize_scalar(
                        lambda lh, i=i, side=side, sgn=sgn, s=s: (
                            -sgn * run(float(np.exp(lh)), s)[0][i][side][0]
                        ),
                        bounds=(np.log(lo), np.log(hi)),
                        method="bounded",
                        options={"xatol": 1e-3},
                    )
                    h_try = float(np.exp(res.x))
                    if sgn * run(h_try, s)[0][i][side][0] > sgn * run(h_best, s)[0][i][side][0]:
                        h_best = h_try
                val, t_at = run(h_best, s)[0][i][side]
                cands.append((sgn * val, float(val), float(h_best), float(t_at), s))
            found[side] = max(cands)[1:]
        if len(signs) == 1:  # the negative gust mirrors: its max is -min, its min is -max
            (pmax, hmax, tmax, _), (pmin, hmin, tmin, _) = found[0], found[1]
            if pmax >= -pmin:
                found = {0: (pmax, hmax, tmax, 1), 1: (-pmax, hmax, tmax, -1)}
            else:
                found = {0: (-pmin, hmin, tmin, -1), 1: (pmin, hmin, tmin, 1)}
        corr = []
        for side in (0, 1):
            _, h, t_at, sign = found[side]
            t, y = signed(h, sign)
            corr.append({n: float(np.interp(t_at, t, y[:, j])) for j, n in enumerate(names)})
        extremes[name] = GustExtreme(
            name, units.get(name, ""), *found[0], *found[1], corr[0], corr[1]
        )
    histories = {}
    for e in extremes.values():
        for side in ("max", "min"):
            _, h, _, sign, _ = e.side(side)
            t, y = signed(h, sign)
            histories[(h, sign)] = (t, sign * amplitude(h) * _gust_at(t, speed, h, march), y)
    limited = {}
    for c in getattr(march, "controls", ()):
        limited[c] = np.array([[run(h, s)[1][c] for s in signs] for h in grid])
    amps = np.array([amplitude(h) for h in grid])
    return TunedGustResult(
        speed,
        alt,
        grid,
        amps,
        tables[1],
        extremes,
        dt,
        controller=label,
        peaks_negative=tables.get(-1),
        limited=limited,
        histories=histories,
        loads=tuple(names),
        units={n: units.get(n, "") for n in names},
    )


DOMINATED = 0.5
"""A side (maximum or minimum over the up gust) whose best scanned value is below this share of
the other side's is not refined: refining moves a scanned peak by far less than a factor 2
between neighbouring gradients of a log grid (measured: at most 4.5e-3 of the peak with 20
gradients, the shipped Goland loops open and closed, every load), so the other side gives both
extremes (the down gust mirrors it)."""


def _gust_at(t: np.ndarray, speed: float, h: float, march) -> np.ndarray:
    """The unit gust as the march applied it (the midpoint of each sample in a sampled loop)."""
    from .march import profile

    shift = 0.5 * march.dt if isinstance(march, LoopGustMarch) else 0.0
    return profile(t + shift, speed, h)
