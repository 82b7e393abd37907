"""Position and rate limits on the output of an actuator in the sampled march.

A plant with actuators (:mod:`aeroservo.design.actuator`: states ``<c>_actuator``,
``<c>_actuator_rate``, ``<c>_actuator_lag``) is marched exactly between samples as a linear
system. Where the actuator output would leave its position limit, or move faster than its rate
limit, during a sample, :class:`ActuatorLimits` marches the actuator alone over ``M``
substeps (exact linear steps of ``dt / M``, ``M`` such that ``w dt / M <= 0.005`` for its
fastest frequency ``w``) and clamps it after each: the rate (``y'``, or the step of ``y`` for a
first-order actuator) to the rate limit, then the position, with the rate set to zero where the
position sits at its stop and pushes outward. The rest of the plant is corrected for the
difference between the clamped and the linear outputs, taken as piecewise linear between
substeps (a first-order hold, exact for an actuator moving at its rate limit). A sample in
which no limit is reached is left exact. The command itself keeps its magnitude limit (a flight
computer clips its commands to the surface's authority) but not its rate limit.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.linalg as sla

from ..design.actuator import STATE_SUFFIXES
from ..design.plant import zoh

__all__ = ["ActuatorLimits", "SUBSTEP"]

SUBSTEP = 0.005
"""Largest ``w dt / M`` of the clamped substeps (``w`` the actuator's fastest frequency)."""


def _foh_weights(A: np.ndarray, b: np.ndarray, h: float, M: int) -> np.ndarray:
    """``F`` (M x n): the state at the end of ``M`` substeps of ``h`` driven by an input
    ``b u(t)``, ``u`` piecewise linear with ``u(0) = 0`` and ``u(j h) = e_j`` (j = 1..M)."""
    n = A.shape[0]
    E = np.zeros((n + 2, n + 2))
    E[:n, :n], E[:n, n], E[n, n + 1] = A * h, b * h, 1.0
    X = sla.expm(E)
    Phi, g1, g2 = X[:n, :n], X[:n, n], X[:n, n + 1]  # u = u0 + (u1 - u0) t/h
    G0, G1 = g1 - g2, g2
    F = np.empty((M, n))
    a, b = G1.copy(), None  # a = Phi^k G1, b = Phi^(k-1) G0 for k = M - j
    for j in range(M, 0, -1):  # node j ends substep j and starts substep j + 1
        F[j - 1] = a if b is None else a + b
        b = G0.copy() if b is None else Phi @ b
        a = Phi @ a
    return F


class _One:
    """The limits of one actuator."""

    def __init__(self, A, B, idx: list[int], col: int, mag: float, rate: float, dt: float):
        self.idx = np.asarray(idx)
        self.k = len(idx)
        Aa, ba = A[np.ix_(idx, idx)], B[idx, col]
        w = float(np.max(np.abs(np.linalg.eigvals(Aa))))
        self.M = M = int(min(1024, max(4, np.ceil(w * dt / SUBSTEP))))
        self.h = h = dt / M
        self.Phi, G = zoh(Aa, ba[:, None], h)
        self.G = G[:, 0]
        self.mag, self.rate = mag, rate
        self.w1 = -Aa[0, 0] if self.k == 1 else None
        # the linear substep states: x_j = P_j x0 + Q_j c
        P, Q = np.eye(self.k), np.zeros(self.k)
        Ps, Qs = [], []
        for _ in range(M):
            P, Q = self.Phi @ P, self.Phi @ Q + self.G
            Ps.append(P)
            Qs.append(Q)
        Ps, Qs = np.array(Ps), np.array(Qs)
        # predicted positions and rates at the substeps: [y_1..y_M, r_1..r_M]
        if self.k == 1:  # r = w (c - y)
            rP, rQ = -self.w1 * Ps[:, 0, :], self.w1 * (1.0 - Qs[:, 0])
        else:
            rP, rQ = Ps[:, 1, :], Qs[:, 1]
        self.pred_P = np.vstack([Ps[:, 0, :], rP])
        self.pred_Q = np.concatenate([Qs[:, 0], rQ])
        self.end_P, self.end_Q = Ps[-1], Qs[-1]
        # a bound of |position| and |rate| over the substeps, cheap enough for every sample:
        # |y_j| <= sum_i max_j |P_j[i]| |x0_i| + max_j |Q_j| |c| (likewise the rate)
        self._bound_y = (np.abs(Ps[:, 0, :]).max(axis=0).tolist(), float(np.abs(Qs[:, 0]).max()))
        self._bound_r = (np.abs(rP).max(axis=0).tolist(), float(np.abs(rQ).max()))
        self._phi = self.Phi.tolist()
        self._g = self.G.tolist()
        rest = np.setdiff1d(np.arange(A.shape[0]), self.idx)
        self.rest = rest
        self.F = _foh_weights(A[np.ix_(rest, rest)], A[rest, idx[0]], h, M)

    def _within(self, x0: list, c: float) -> bool:
        """Whether the bound proves the linear sample within both limits."""
        ay, by = self._bound_y
        ar, br = self._bound_r
        ac = abs(c)
        y = by * ac + sum(a * abs(v) for a, v in zip(ay, x0, strict=True))
        r = br * ac + sum(a * abs(v) for a, v in zip(ar, x0, strict=True))
        return y <= self.mag and r <= self.rate

    def correction(self, xa0: np.ndarray, c: float):
        """``None`` if the linear sample keeps within the limits, else ``(dx_rest, dx_act)``."""
        x0 = xa0.tolist()
        if self._within(x0, c):
            return None
        pred = self.pred_P @ xa0 + self.pred_Q * c
        M = self.M
        if np.all(np.abs(pred[:M]) <= self.mag) and np.all(np.abs(pred[M:]) <= self.rate):
            return None
        ys = self._clamped(x0, c)
        x = np.array(self._last)
        dy = np.asarray(ys) - pred[:M]
        return self.F.T @ dy, x - (self.end_P @ xa0 + self.end_Q * c)

    def _clamped(self, x: list, c: float) -> list:
        """The clamped substep positions (Python floats: the actuator has 1-3 states); the
        final state is kept in ``_last``."""
        phi, g, k = self._phi, self._g, self.k
        rate, mag, rh = self.rate, self.mag, self.rate * self.h
        ys = []
        for _ in range(self.M):
            y0 = x[0]
            x = [sum(p * v for p, v in zip(row, x, strict=True)) + gi * c
                 for row, gi in zip(phi, g, strict=True)]  # fmt: skip
            if k == 1:
                x[0] = min(max(x[0], y0 - rh), y0 + rh)
            else:
                x[1] = min(max(x[1], -rate), rate)
            if x[0] > mag or x[0] < -mag:
                x[0] = mag if x[0] > 0 else -mag
                if k > 1 and x[1] * x[0] > 0:
                    x[1] = 0.0
            ys.append(x[0])
        self._last = x
        return ys


class ActuatorLimits:
    """Position and rate limits on the actuator outputs of a plant with actuators.

    Parameters
    ----------
    plant : control.StateSpace
        The continuous plant (with the ``<c>_actuator`` states).
    controls : sequence of str
        The controls marched, in order.
    mag, rate : ndarray
        Position [control unit] and rate [unit/s] limits per control (inf: none).
    dt : float
        Sample period [s].
    """

    def __init__(self, plant, controls: Sequence[str], mag, rate, dt: float):
        A, B = np.asarray(plant.A), np.asarray(plant.B)
        states = list(plant.state_labels)
        inputs = list(plant.input_labels)
        self.n = A.shape[0]
        self.parts: list[tuple[int, _One]] = []
        for i, c in enumerate(controls):
            if c + "_actuator" not in states or not (np.isfinite(mag[i]) or np.isfinite(rate[i])):
                continue
            idx = [states.index(c + s) for s in STATE_SUFFIXES if c + s in states]
            self.parts.append((i, _One(A, B, idx, inputs.index(c), mag[i], rate[i], dt)))
        self.controls = list(controls)

    def recorded_rates(self, outputs: dict) -> None:
        """Make the recorded ``<c>_actuator_rate`` of a first-order actuator (``w (c - y)``,
        the demanded rate) the rate it moves at: clipped to its rate limit, zero at a stop."""
        for i, p in self.parts:
            c = self.controls[i]
            r, y = outputs.get(c + "_actuator_rate"), outputs.get(c + "_actuator")
            if p.k != 1 or r is None or y is None:
                continue
            r = np.clip(r, -p.rate, p.rate)
            r[(np.abs(y) >= p.mag * (1 - 1e-12)) & (r * y > 0)] = 0.0
            outputs[c + "_actuator_rate"] = r

    @staticmethod
    def command_limits(plant, controls: Sequence[str], mag, rate) -> tuple:
        """The limits left on the commands, and whether any control has an actuator. On a
        control with an actuator the command keeps its magnitude limit (the flight computer's
        authority, which an anti-windup sees) and loses its rate limit (the actuator's rate is
        limited instead)."""
        states = set(plant.state_labels)
        act = np.array([c + "_actuator" in states for c in controls], dtype=bool)
        return mag, np.where(act, np.inf, rate), bool(act.any())

    def clamp(self, x0: np.ndarray, u, x1: np.ndarray) -> np.ndarray | None:
        """The change ``dx`` to the linear end-of-sample state (``x1``, from ``x0`` and the
        commands ``u``) that the limits make, or None (the linear state is then exact)."""
        dx = None
        for i, p in self.parts:
            out = p.correction(x0[p.idx], float(u[i]))
            if out is None:
                continue
            if dx is None:
                dx = np.zeros(self.n)
            dx[p.rest] += out[0]
            dx[p.idx] += out[1]
        return dx
