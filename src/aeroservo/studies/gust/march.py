"""The responses of a wing to one 1-cos gust, open loop (exact) or with a controller (sampled).

* **Open loop**: exact discretization of ``x' = A x + B u`` for an input linear between samples
  (first-order hold, by the matrix exponential of the augmented matrix, Van Loan 1978). It is
  exact for every mode whatever its frequency (no stability limit), so the step only has to
  resolve the input and the extremes.
* **Closed loop**: the loop :func:`aeroservo.simulate.simulate` marches (the controller at its
  own sample rate, zero-order hold on the commands, the actuator limits, an optional one-sample
  delay), the plant exact between samples. The gust is held over each sample at its value at the
  middle of the sample (the midpoint rule: second order in the sample period, where holding the
  value at the start of the sample would be first order).

Time is counted from the moment the gust front reaches the leading edge (the reference of the
Kussner function); the gust is ``U(t) = U_ds/2 (1 - cos(pi V t / H))`` for ``0 <= V t <= 2 H``.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg as sla

from ...errors import InputError, check_number

__all__ = ["one_minus_cosine_response", "profile", "peak", "ExactGustMarch", "LoopGustMarch"]


def profile(t: np.ndarray, speed: float, gradient: float) -> np.ndarray:
    """The 1-cos gust of unit amplitude at times ``t`` [s] for a true airspeed ``speed`` [m/s]
    and gradient H [m]."""
    s = speed * np.asarray(t, dtype=float)
    return np.where((s >= 0) & (s <= 2 * gradient), 0.5 * (1 - np.cos(np.pi * s / gradient)), 0.0)


def peak(y: np.ndarray, dt: float, sign: int, refine: bool = True) -> tuple[float, float]:
    """Extreme (sign +1 max, -1 min) of samples ``y`` and its time [s], refined by the parabola
    through the extreme sample and its neighbours (``refine``; not for a signal held constant
    between samples, such as a command)."""
    k = int(np.argmax(sign * y))
    if refine and 0 < k < y.size - 1:
        ym, y0, yp = sign * y[k - 1 : k + 2]
        den = ym - 2 * y0 + yp
        if den < 0:
            d = 0.5 * (ym - yp) / den
            return sign * (y0 - 0.25 * (ym - yp) * d), (k + d) * dt
    return float(y[k]), k * dt


def _gust_column(sys) -> int:
    names = list(sys.input_labels)
    if "gust" not in names:
        raise InputError(f"model inputs {names}: a 'gust' input is needed")
    return names.index("gust")


class ExactGustMarch:
    """First-order-hold exact march of the gust input of a state-space model (open loop).

    Parameters
    ----------
    sys : control.StateSpace
        Model with a ``gust`` input [m/s] and ``sys.speed`` [m/s].
    dt : float
        Time step [s].
    """

    controls: tuple = ()

    def __init__(self, sys, dt: float):
        j = _gust_column(sys)
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
        self.speed = float(sys.speed)
        self.outputs = tuple(sys.output_labels)

    def run(self, u: np.ndarray) -> np.ndarray:
        """Outputs (n_samples, n_outputs) for the input samples ``u`` from rest."""
        du = np.diff(u)
        f = np.outer(u[:-1], self.G0) + np.outer(du, self.G1)
        x = np.zeros((u.size, self.Phi.shape[0]))
        PhiT = self.Phi.T
        for k in range(u.size - 1):
            x[k + 1] = x[k] @ PhiT + f[k]
        return x @ self.C.T + np.outer(u, self.D)

    def response(self, gradient: float, amplitude: float, duration: float):
        """``(t, y, limited)`` for one gust: times [s], outputs (n_t, n_outputs) and the
        time at a limit per control (none open loop)."""
        t = np.arange(int(np.ceil(duration / self.dt)) + 1) * self.dt
        return t, self.run(amplitude * profile(t, self.speed, gradient)), {}


class LoopGustMarch:
    """A controller's loop around a model marched through one gust (see the module docstring).

    Parameters
    ----------
    sys : control.StateSpace
        Continuous plant with the controller's controls, a ``gust`` input and its sensors.
    controller
        Any controller :func:`aeroservo.design.as_controller` accepts (a schedule is evaluated
        at ``sys.speed``).
    limits : aeroservo.design.Limits, optional
    delay : bool
        One-sample computational delay.
    sample_rate : float, optional
        [Hz] for a continuous python-control compensator.

    Attributes
    ----------
    outputs : tuple of str
        The plant's outputs, then the controls applied (e.g. the hinge moment of the actuator).
    """

    def __init__(self, sys, controller, limits=None, delay: bool = False, sample_rate=None):
        from ...design.interface import as_controller, controller_at
        from ...design.protocol import steps_its_law

        _gust_column(sys)
        ctrl = as_controller(controller, sample_rate=sample_rate)
        self.controller = controller_at(ctrl, float(sys.speed))
        self.sys, self.limits, self.delay = sys, limits, delay
        self.dt = float(self.controller.dt)
        self.speed = float(sys.speed)
        self.controls = tuple(self.controller.controls)
        extra = tuple(c for c in self.controls if c not in sys.output_labels)
        self.outputs = tuple(sys.output_labels) + extra
        c = self.controller
        # a linear law with symmetric limits (magnitude +-M, rate +-R) and no noise is an odd
        # loop: the down gust's response is exactly minus the up gust's (IEEE arithmetic
        # commutes with negation), so one sign is marched; a nonlinear law marches both
        self.odd = steps_its_law(c)

    def response(self, gradient: float, amplitude: float, duration: float):
        """``(t, y, limited)``: times [s], outputs (n_t, n_outputs) and ``{control: time [s]
        at a magnitude or rate limit}``."""
        from ...simulate.march import simulate

        half, v = 0.5 * self.dt, self.speed

        def gust(t, speed):
            return amplitude * profile(t + half, v, gradient)

        with warnings.catch_warnings():  # windup is reported through ``limited``
            warnings.simplefilter("ignore", RuntimeWarning)
            res = simulate(
                self.sys,
                self.controller,
                duration=duration,
                disturbance=gust,
                limits=self.limits,
                delay=self.delay,
            )
        y = np.column_stack([res.signal(n) for n in self.outputs])
        at_limit = res.time_at_limit()
        return res.t, y, {c: at_limit[c] for c in self.controls}


def one_minus_cosine_response(
    sys, gradient: float, amplitude: float, duration: float, dt: float
) -> tuple[np.ndarray, np.ndarray]:
    """Open-loop response of every output to one 1-cos gust (exact first-order hold).

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
    t, y, _ = ExactGustMarch(sys, dt).response(gradient, amplitude, duration)
    return t, y
