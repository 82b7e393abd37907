"""Closed-loop stability versus airspeed: the flutter boundary a linear controller buys.

For a fixed linear controller (LQR state feedback, LQG compensator, or a gain schedule of
either) the closed loop is formed at each airspeed with the plant at that speed, and its
stability measure is

* sampled loop (default, what :func:`aeroservo.simulate.simulate` runs): ``ln(rho) / dt`` with
  rho the spectral radius of the discrete closed loop (zero-order hold, exact discretization);
* continuous loop: the spectral abscissa ``max Re(lambda)`` of the continuous closed loop
  (continuous LQR gain / continuous LQG compensator).

Both are continuous functions of speed whose sign changes are exactly the closed-loop stability
boundaries. They are bracketed on a speed grid and found by Brent's method to a relative
tolerance ``rtol`` (the open-loop root finder,
:func:`aeroservo.stability.boundary.sign_changes`), with the same search for humps that
cross zero between grid points.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from .._threads import blas_limited
from ..errors import InputError, check_int, check_number
from ..linear.signals import describe
from ..stability.boundary import sign_changes
from .boundary_result import ClosedLoopBoundary
from .interface import as_controller, controller_at, has_linear_law
from .law import pad_state_map
from .plant import SampledPlant, select
from .sampled_loop import linear_law, loop_matrix, plant_states

__all__ = ["ClosedLoopBoundary", "closed_loop_boundary", "closed_loop_matrix"]


def plant_function(plant_at) -> Callable[[float], object]:
    """``V -> control.StateSpace`` from a ControlLoop (its ``plant``), a StateSpaceBuilder (its
    ``at``) or such a function."""
    return getattr(plant_at, "at", None) or getattr(plant_at, "plant", None) or plant_at


def linear_controller(controller, who: str, sample_rate: float | None = None):
    """The controller through :func:`~aeroservo.design.as_controller`, refused unless it has a
    linear law (``who`` names the analysis in the message)."""
    ctrl = as_controller(controller, sample_rate=sample_rate)
    if not has_linear_law(ctrl):
        what = getattr(controller, "name", None) or describe(controller)
        raise InputError(
            f"{who}: controller = {what} is not linear (a Python law or a "
            "protocol object): it has no closed-loop eigenvalues or margins; simulate it, or "
            "bring its matrices (aeroservo.design.as_controller(control.ss(A, B, C, D, dt)))"
        )
    return ctrl


def closed_loop_matrix(
    plant,
    controller,
    *,
    sampled: bool = True,
    delay: bool = False,
    sample_rate: float | None = None,
):
    """State matrix of the loop of a linear controller around a plant at one speed.

    The sampled loop is the one :func:`aeroservo.simulate.simulate` marches
    (:mod:`aeroservo.design.sampled_loop`: with a delay, the estimator predicts with the input
    actually applied); an MPC controller gives its loop without active constraints.

    Parameters
    ----------
    plant : control.StateSpace
        Continuous plant with the controller's control inputs and sensors.
    controller
        A linear controller (see :func:`aeroservo.design.as_controller`; a schedule is
        evaluated at the plant's speed).
    sampled : bool
        True: the discrete loop at the controller's sample rate; False: the continuous loop
        (continuous LQR and LQG designs only).
    delay : bool
        One-sample computational delay (sampled loop only).
    sample_rate : float, optional
        [Hz] for a continuous python-control compensator (discretised by Tustin's method).

    Returns
    -------
    A : ndarray
        Closed-loop state matrix (discrete if ``sampled``).
    dt : float or None
        Sample period [s] of a discrete loop, None for a continuous one.
    """
    import control

    controller = linear_controller(controller, "closed_loop_matrix", sample_rate)
    controller = controller_at(controller, float(getattr(plant, "speed", np.nan)))
    controls = list(controller.controls)
    if sampled:
        law = linear_law(controller, plant_states(plant))
        sp = SampledPlant.from_statespace(plant, law.dt, controls, (), list(law.sensors))
        return loop_matrix(sp, law, delay), law.dt
    if delay:
        raise InputError("closed_loop_matrix: delay applies to the sampled loop only")
    if not hasattr(controller, "K") or not (
        hasattr(controller, "state_map") or hasattr(controller, "compensator_continuous")
    ):
        raise InputError(
            "closed_loop_matrix: sampled=False needs a continuous design (LQR or LQG); "
            f"{describe(controller)} is a sampled controller"
        )
    if getattr(controller, "needs_state", False):  # state feedback
        A, B, _, _ = select(plant, controls, [])
        return A - B @ (controller.K @ pad_state_map(controller.state_map, plant.nstates)), None
    sensors = list(controller.sensors)
    A, B, C, D = select(plant, controls, sensors)
    p = control.ss(A, B, C, D)
    comp = controller.compensator_continuous
    loop = control.feedback(p, control.ss(comp.A, comp.B, comp.C, comp.D), sign=1)
    return np.asarray(loop.A), None


def _measure(A: np.ndarray, dt: float | None) -> tuple[float, complex]:
    """Stability measure [1/s] (negative: stable) and the continuous eigenvalue behind it."""
    lam = np.linalg.eigvals(A)
    if dt is None:
        i = int(np.argmax(lam.real))
        return float(lam[i].real), complex(lam[i])
    i = int(np.argmax(np.abs(lam)))
    s = np.log(complex(lam[i])) / dt  # continuous-equivalent eigenvalue
    return float(np.log(abs(lam[i])) / dt), complex(s.real, abs(s.imag))


@blas_limited
def closed_loop_boundary(
    plant_at: Callable[[float], object],
    controller,
    v_max: float,
    *,
    v_min: float | None = None,
    n_grid: int = 41,
    reference_speed: float | None = None,
    sampled: bool = True,
    delay: bool = False,
    rtol: float = 1e-7,
    progress: Callable[[float], None] | None = None,
    sample_rate: float | None = None,
) -> ClosedLoopBoundary:
    """Closed-loop flutter boundary of a linear controller.

    Parameters
    ----------
    plant_at : ControlLoop, StateSpaceBuilder or callable
        The plant at a speed: a :class:`~aeroservo.design.loop.ControlLoop` (its sampled
        plants, cached), a builder (its ``at``) or ``V -> control.StateSpace`` (e.g. with
        sensor filters added).
    controller
        A linear controller (:func:`aeroservo.design.as_controller`); a schedule is evaluated
        at each speed; an MPC by its law without active constraints. A Python law is refused.
    v_max : float
        Upper end of the speed range [m/s].
    v_min : float, optional
        Lower end [m/s] (default ``v_max / 20``; at V = 0 undamped structural modes sit on the
        stability boundary).
    n_grid : int
        Grid points used to bracket sign changes (refined by root finding).
    reference_speed : float, optional
        Speed [m/s] whose stable interval defines the closed-loop flutter speed (default: the
        controller's ``design_speed`` if it has one, else ``v_min``).
    sampled, delay : bool
        See :func:`closed_loop_matrix`.
    rtol : float
        Relative tolerance on crossing speeds.
    progress : callable, optional
        Called with each grid speed [m/s].
    sample_rate : float, optional
        [Hz] for a continuous python-control compensator.

    Returns
    -------
    ClosedLoopBoundary
    """
    controller = linear_controller(controller, "closed_loop_boundary", sample_rate)
    v_max = check_number("v_max", v_max, unit="m/s", lo=0.0, lo_open=True)
    v_min = v_max / 20.0 if v_min is None else v_min
    v_min = check_number("v_min", v_min, unit="m/s", lo=0.0, hi=v_max, lo_open=True, hi_open=True)
    n_grid = check_int("n_grid", n_grid, lo=3, hi=10_000)
    check_number("rtol", rtol, lo=0.0, hi=1e-2, lo_open=True)
    at = plant_function(plant_at)
    if reference_speed is None:
        reference_speed = getattr(controller, "design_speed", None)
        if reference_speed is None or not np.isfinite(reference_speed):
            reference_speed = v_min
    reference_speed = check_number("reference_speed", reference_speed, unit="m/s", lo=0.0)
    n_eval = [0]

    cached = getattr(plant_at, "sampled_plant", None) if sampled else None
    known: dict[float, tuple[float, complex]] = {}  # the root finder starts at grid points
    source: list[str] = []

    def evaluate(v: float) -> tuple[float, complex]:
        v = float(v)
        if v in known:
            return known[v]
        n_eval[0] += 1
        ctrl = controller_at(controller, v)
        if cached is not None:  # a ControlLoop: its sampled plants are reused across designs
            law = linear_law(ctrl, plant_at.state_labels)
            source[:] = [law.source]
            sp = cached(v, law.dt, list(law.controls), list(law.sensors))
            known[v] = _measure(loop_matrix(sp, law, delay), law.dt)
        else:
            plant = at(v)
            if sampled:
                source[:] = [linear_law(ctrl, plant_states(plant)).source]
            A, dt = closed_loop_matrix(plant, ctrl, sampled=sampled, delay=delay)
            known[v] = _measure(A, dt)
        return known[v]

    V = np.linspace(v_min, v_max, n_grid)
    g = np.empty(n_grid)
    lam = np.empty(n_grid, dtype=complex)
    for i, v in enumerate(V):
        g[i], lam[i] = evaluate(v)
        if progress is not None:
            progress(float(v))
    zeta = -lam.real / np.maximum(np.abs(lam), 1e-300)
    roots = sign_changes(lambda v, k: evaluate(v)[0], V, g, zeta, rtol, first=0)
    crossings = []
    for v, rising, _k in roots:
        _, lc = evaluate(v)
        freq = float(abs(lc.imag) / (2 * np.pi))
        crossings.append(
            {
                "speed": float(v),
                "frequency": freq,
                "kind": "onset" if rising else "recovery",
                "static": bool(abs(lc.imag) <= 1e-6 * max(abs(lc.real), 1.0)),
            }
        )
    g_ref = evaluate(float(reference_speed))[0] if v_min <= reference_speed <= v_max else None
    return ClosedLoopBoundary(
        speeds=V,
        abscissa=g,
        frequencies=np.abs(lam.imag) / (2 * np.pi),
        crossings=crossings,
        sampled=sampled,
        reference_speed=float(reference_speed),
        info={"n_evaluations": n_eval[0], "law": source[0] if source else ""},
        delay=bool(delay),
        reference_abscissa=g_ref,
    )


def speeds_grid(values: Sequence[float]) -> np.ndarray:
    """Validated increasing speed grid [m/s]."""
    v = np.asarray(values, dtype=float)
    if v.ndim != 1 or v.size < 2 or not np.all(np.isfinite(v)) or np.any(np.diff(v) <= 0):
        raise InputError(f"speeds = {values!r}: expected an increasing list of speeds [m/s]")
    if v[0] < 0:
        raise InputError(f"speeds[0] = {v[0]:g}: speeds must be >= 0 m/s")
    return v
