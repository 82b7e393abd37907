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
from dataclasses import dataclass, field

import numpy as np

from .._threads import blas_limited
from ..errors import InputError, check_int, check_number
from ..stability.boundary import sign_changes
from .plant import SampledPlant, select
from .sampled_loop import _pad, linear_law, loop_matrix

__all__ = ["ClosedLoopBoundary", "closed_loop_boundary", "closed_loop_matrix"]


def _controller_at(controller, speed: float):
    """The linear controller in force at ``speed`` (a schedule is evaluated there)."""
    return controller.at(speed) if hasattr(controller, "at") else controller


def closed_loop_matrix(plant, controller, *, sampled: bool = True, delay: bool = False):
    """State matrix of the loop of a linear controller around a plant at one speed.

    The sampled loop is the one :func:`aeroservo.simulate.simulate` marches
    (:mod:`aeroservo.design.sampled_loop`: with a delay, the estimator predicts with the input
    actually applied); an MPC controller gives its loop without active constraints.

    Parameters
    ----------
    plant : control.StateSpace
        Continuous plant with the controller's control inputs and sensors.
    controller : StateFeedback, OutputFeedback, MPCController or a compensator
        Linear controller (see :mod:`aeroservo.design`).
    sampled : bool
        True: the discrete loop at the controller's sample rate; False: the continuous loop.
    delay : bool
        One-sample computational delay (sampled loop only).

    Returns
    -------
    A : ndarray
        Closed-loop state matrix (discrete if ``sampled``).
    dt : float or None
        Sample period [s] of a discrete loop, None for a continuous one.
    """
    import control

    controls = list(controller.controls)
    if sampled:
        law = linear_law(controller, plant.nstates)
        sp = SampledPlant.from_statespace(plant, controller.dt, controls, (), list(law.sensors))
        return loop_matrix(sp, law, delay), controller.dt
    if delay:
        raise InputError("closed_loop_matrix: delay applies to the sampled loop only")
    if getattr(controller, "needs_state", False):  # state feedback
        A, B, _, _ = select(plant, controls, [])
        return A - B @ (controller.K @ _pad(controller.state_map, plant.nstates)), None
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


@dataclass
class ClosedLoopBoundary:
    """Closed-loop stability of a linear controller versus airspeed.

    Attributes
    ----------
    speeds : ndarray
        Grid speeds [m/s].
    abscissa : ndarray
        Stability measure on the grid [1/s]: growth rate of the least stable closed-loop pole
        (negative: stable).
    frequencies : ndarray
        Frequency of that pole on the grid [Hz].
    crossings : list of dict
        ``{"speed" [m/s], "frequency" [Hz], "kind": "onset" | "recovery", "static": bool}``
        in increasing speed; ``static`` marks a real pole through zero (divergence-like, 0 Hz).
    sampled : bool
        Whether the measure is that of the sampled loop.
    delay : bool
        Whether the loop has a one-sample computational delay.
    reference_speed : float
        Speed [m/s] whose stable interval defines :attr:`flutter_speed`.
    """

    speeds: np.ndarray
    abscissa: np.ndarray
    frequencies: np.ndarray
    crossings: list
    sampled: bool
    reference_speed: float
    info: dict = field(default_factory=dict)
    delay: bool = False
    reference_abscissa: float | None = None

    @property
    def stable_at_reference(self) -> bool:
        """Whether the loop is stable at the reference (e.g. design) speed (from its own
        eigenvalues when computed, else interpolated on the grid)."""
        g = self.reference_abscissa
        return bool((self._g(self.reference_speed) if g is None else g) < 0)

    def _g(self, v: float) -> float:
        return float(np.interp(v, self.speeds, self.abscissa))

    @property
    def flutter(self) -> dict | None:
        """First onset above the reference speed (None: stable to the end of the range)."""
        ons = [c for c in self.crossings if c["kind"] == "onset"]
        above = [c for c in ons if c["speed"] >= self.reference_speed]
        return above[0] if above else None

    @property
    def flutter_speed(self) -> float | None:
        """Closed-loop flutter speed [m/s]: where the loop first loses stability above the
        reference speed, through a complex pair (flutter) or a real pole (``static`` in
        :attr:`flutter`); None if it stays stable up to the end of the range."""
        f = self.flutter
        return None if f is None else float(f["speed"])

    @property
    def flutter_frequency(self) -> float | None:
        """Frequency [Hz] of the closed-loop flutter onset."""
        f = self.flutter
        return None if f is None else float(f["frequency"])

    def stable_intervals(self) -> list[tuple[float, float]]:
        """Speed intervals [m/s] inside the searched range where the loop is stable.

        Between two crossings the loop is stable after a recovery and unstable after an onset
        (the crossing kinds come from the refined roots, not from the coarse grid, which can
        step over a short unstable interval); before the first crossing it is the opposite of
        that crossing.
        """
        edges = [self.speeds[0]] + [c["speed"] for c in self.crossings] + [self.speeds[-1]]
        if self.crossings:
            first = self.crossings[0]["kind"] == "onset"
            stable = [first] + [c["kind"] == "recovery" for c in self.crossings]
        else:
            stable = [bool(np.all(self.abscissa < 0))]
        out = []
        for a, b, ok in zip(edges[:-1], edges[1:], stable, strict=True):
            if b > a and ok:
                out.append((float(a), float(b)))
        return out

    def to_dict(self) -> dict:
        """JSON-ready summary (m/s, Hz)."""
        f = self.flutter
        return {
            "closed_loop_flutter_speed": self.flutter_speed,
            "closed_loop_flutter_frequency": self.flutter_frequency,
            "closed_loop_instability": None
            if f is None
            else (
                "static (real pole, divergence-like)" if f["static"] else "oscillatory (flutter)"
            ),
            "reference_speed": self.reference_speed,
            "stable_at_reference": self.stable_at_reference,
            "sampled": self.sampled,
            "delay": self.delay,
            "crossings": self.crossings,
            "stable_intervals": self.stable_intervals(),
            "v_range": [float(self.speeds[0]), float(self.speeds[-1])],
        }

    def plot(self, ax=None, open_loop=None):
        """Growth rate of the least stable pole versus speed, crossings marked.

        Parameters
        ----------
        ax : matplotlib Axes, optional
        open_loop : FlutterResult, optional
            Adds the open-loop tracked modes' real parts for comparison.
        """
        from matplotlib.figure import Figure

        if ax is None:
            fig = Figure(layout="constrained", figsize=(7, 3.6))
            ax = fig.subplots()
        else:
            fig = ax.figure
        if open_loop is not None:
            ol = np.max(open_loop.eigenvalues.real, axis=1)
            ax.plot(open_loop.speeds, ol, color="0.6", lw=1, label="open loop (tracked modes)")
            if open_loop.flutter_speed is not None:
                ax.axvline(open_loop.flutter_speed, color="0.6", ls=":", lw=1)
        ax.plot(self.speeds, self.abscissa, label="closed loop")
        ax.axhline(0, color="k", lw=0.8)
        ax.axvline(self.reference_speed, color="g", ls="--", lw=1, label="design speed")
        for c in self.crossings:
            ax.plot(c["speed"], 0, "ro" if c["kind"] == "onset" else "bs")
        if self.flutter_speed is not None:
            ax.annotate(
                f"closed-loop flutter {self.flutter_speed:.4g} m/s",
                (self.flutter_speed, 0),
                xytext=(10, 20),
                textcoords="offset points",
                arrowprops={"arrowstyle": "->"},
            )
        lo, hi = np.percentile(self.abscissa, [2, 98])
        pad = 0.2 * (hi - lo + 1e-9)
        ax.set_ylim(min(lo, -pad) - pad, max(hi, pad) + pad)
        ax.set_xlabel("airspeed V [m/s]")
        ax.set_ylabel("growth rate of least stable pole [1/s]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        return fig


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
) -> ClosedLoopBoundary:
    """Closed-loop flutter boundary of a linear controller.

    Parameters
    ----------
    plant_at : ControlLoop, StateSpaceBuilder or callable
        The plant at a speed: a :class:`~aeroservo.design.loop.ControlLoop` (its sampled
        plants, cached), a builder (its ``at``) or ``V -> control.StateSpace`` (e.g. with
        sensor filters added).
    controller : StateFeedback, OutputFeedback or GainSchedule
        Linear controller; a schedule is evaluated at each speed.
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

    Returns
    -------
    ClosedLoopBoundary
    """
    if getattr(controller, "is_linear", True) is False:
        raise InputError(
            "closed_loop_boundary: the controller is not linear (MPC); simulate it instead"
        )
    v_max = check_number("v_max", v_max, unit="m/s", lo=0.0, lo_open=True)
    v_min = v_max / 20.0 if v_min is None else v_min
    v_min = check_number("v_min", v_min, unit="m/s", lo=0.0, hi=v_max, lo_open=True, hi_open=True)
    n_grid = check_int("n_grid", n_grid, lo=3, hi=10_000)
    check_number("rtol", rtol, lo=0.0, hi=1e-2, lo_open=True)
    at = getattr(plant_at, "at", None) or getattr(plant_at, "plant", None) or plant_at
    if reference_speed is None:
        reference_speed = getattr(controller, "design_speed", None)
        if reference_speed is None or not np.isfinite(reference_speed):
            reference_speed = v_min
    reference_speed = check_number("reference_speed", reference_speed, unit="m/s", lo=0.0)
    n_eval = [0]

    cached = getattr(plant_at, "sampled_plant", None) if sampled else None
    known: dict[float, tuple[float, complex]] = {}  # the root finder starts at grid points

    def evaluate(v: float) -> tuple[float, complex]:
        v = float(v)
        if v in known:
            return known[v]
        n_eval[0] += 1
        ctrl = _controller_at(controller, v)
        if cached is not None:  # a ControlLoop: its sampled plants are reused across designs
            law = linear_law(ctrl, plant_at.n_plant_states)
            sp = cached(v, ctrl.dt, list(ctrl.controls), list(law.sensors))
            known[v] = _measure(loop_matrix(sp, law, delay), ctrl.dt)
        else:
            A, dt = closed_loop_matrix(at(v), ctrl, sampled=sampled, delay=delay)
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
        info={"n_evaluations": n_eval[0]},
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
