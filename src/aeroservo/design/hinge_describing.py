"""Limit cycles of a sampled flutter-suppression loop with nonlinear hinges, by the describing
function.

:mod:`aeroservo.stability.describing_function` replaces each nonlinear element ``j`` by its
equivalent stiffness ``N_j(a_j)`` [N m/rad] in the wing's equations (the open loop). Here the
same is done to the plant a controller flies (:func:`~aeroservo.design.hinge_loop.
loop_hinge_plant`: ``x' = A x + B u + B_n phi``, ``y = C x + D u + D_n phi`` with
``phi = (k - N) C_n x``): the equivalent plant ``A + B_n diag(k - N) C_n``,
``C + D_n diag(k - N) C_n`` is sampled with a zero-order hold on the command only (the hinge
moments act continuously, as in the march) and closed with the controller's linear law: the
transition matrix ``M(V, A)`` of :func:`~aeroservo.design.sampled_loop.loop_matrix`, the loop
:func:`~aeroservo.simulate.hinges.march.march_hinges` marches (limits inactive). An LCO of
amplitude ``A`` is a speed where ``M`` has a root ``mu`` on the unit circle. The method is the
open loop's, on the growth rates ``ln|mu| / dt`` [1/s] of the sampled loop:

* **Crossings.** The rates of every root on the speed grid, sorted in descending order, are
  continuous in speed (rank 0: the spectral radius). Where the number of growing roots changes
  between grid speeds, Brent's method finds the sign change of each rank in between; where two
  roots cross in opposite directions within one grid interval (the roots paired by continuity
  change sign more often than the count), the interval is bisected until they separate, or a
  note says so (:mod:`aeroservo.stability.describing_checks`). With
  a zero command ``M = expm(A dt)``, whose rates are the real parts of the continuous roots: the
  open-loop describing function. A real ``mu`` (static at +1, or the two-sample oscillation at
  -1) is not a first-harmonic limit cycle and is left out.
* **Frequency** ``arg(mu) / (2 pi dt)`` [Hz] in ``[0, f_s / 2]``: a loop root above the Nyquist
  frequency would be seen folded (aliased) below it; compare with a march when ``f`` is not
  small against ``f_s / 2``.
* **Several elements.** Amplitude ratios ``|C_n x|`` of the critical eigenvector (``x``: its
  plant states), iterated as in the open loop (``RATIO_TOL``, at most ``MAX_ITER`` times).
* **Stability** ``d sigma / dA < 0`` at fixed speed (central difference of the critical root's
  rate, step ``STEP``); ``others_stable``: every other root inside the unit circle.

The plant at a speed comes from one :class:`~aeroservo.linear.state_space.StateSpaceBuilder`
(``matrices``) and the loop's sensor filters, as :meth:`ControlLoop.sampled_plant` does.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np
import scipy.linalg as sla

from .._threads import blas_limited
from ..errors import InputError, check_number
from ..linear.hinge_plant import hinge_inputs
from ..stability.brent import RTOL_MIN, BracketError, brentq
from ..stability.describing_checks import hidden_note, search_intervals, stop_notes
from ..stability.describing_function import (
    MATCH,
    STEP,
    DescribingBranches,
    _check_amplitudes,
    _check_speeds,
    _distance,
    _Point,
    branches_from_points,
    check_centred,
)
from ..stability.equivalent_system import MAX_ITER, RATIO_TOL, STATIC
from ..system.hinge_elements import NonlinearHinge
from .closed_loop import linear_controller
from .hinge_loop import loop_hinge_plant
from .interface import controller_at
from .plant import SampledPlant, filter_arrays
from .sampled_loop import linear_law, loop_matrix

__all__ = ["loop_describing_branches", "EquivalentLoop"]

Crossing = tuple[float, complex, np.ndarray]
"""A crossing: speed [m/s], the loop's root ``mu`` there (``Im mu > 0``), its eigenvector."""


class EquivalentLoop:
    """The sampled loop of a wing's equivalent plant at any speed and element amplitudes.

    Parameters
    ----------
    loop : ControlLoop
    hinges : sequence of NonlinearHinge
    controller
        A linear controller (checked by :func:`~aeroservo.design.closed_loop.linear_controller`;
        a gain schedule is evaluated at each speed).
    delay : bool
        One-sample computational delay.
    speed : float
        Any speed [m/s] (the plant's channels do not depend on it).
    """

    def __init__(self, loop, hinges: Sequence[NonlinearHinge], controller, delay: bool, speed):
        nplant = loop_hinge_plant(loop, hinges, speed)
        self.elements = nplant.elements
        self.k = np.asarray(self.elements.stiffness, dtype=float)
        self.c_n = nplant.c_n
        self.builder = nplant.plant.builder
        self.n_q = self.builder.system.n_q
        self.states = tuple(nplant.plant.state_labels)
        self.controller, self.delay = controller, bool(delay)
        self.dt = float(controller.dt)
        self._filter = None
        outs, ins = list(self.builder.output_labels), list(self.builder.input_labels)
        if loop.sensor_filter is not None:
            rows = [outs.index(s) for s in loop.filtered]
            self._filter = (rows, loop.sensor_filter, loop.filter_order)
        self._labels = (ins, outs)
        self._hinge = [ins.index(n) for n in hinge_inputs(self.elements)]
        self._law = None
        self._law = None if hasattr(controller, "at") else self.law(speed)  # one for all
        self._blocks: dict[float, tuple] = {}

    def law(self, v: float):
        """The controller's linear law at speed ``v`` [m/s] around the plant's states."""
        if self._law is not None:
            return self._law
        return linear_law(controller_at(self.controller, v), self.states)

    def blocks(self, v: float, keep: bool = False) -> tuple:
        """``(law, A, Bu, Bn, Cs, Ds, Dn)`` of the plant at ``v`` [m/s] (filters included; ``u``
        the law's controls, rows ``s`` its sensors, ``n`` the element moments); ``keep``: cache
        them (the grid speeds)."""
        hit = self._blocks.get(v)
        if hit is not None:
            return hit
        law = self.law(v)
        A, B, C, D = self.builder.matrices(v, balanced=True)
        if self._filter is not None:
            A, B, C, D = filter_arrays(A, B, C, D, *self._filter)
        ins, outs = self._labels
        ii = [_position(ins, c, "control") for c in law.controls]
        oo = [_position(outs, s, "sensor") for s in law.sensors]
        jj = self._hinge
        out = (law, A, B[:, ii], B[:, jj], C[oo], D[np.ix_(oo, ii)], D[np.ix_(oo, jj)])
        if keep:
            self._blocks[v] = out
        return out

    def dk(self, amplitude: float, ratios: np.ndarray) -> np.ndarray:
        """``k - N(a)`` [N m/rad] of each element at the amplitudes ``amplitude * ratios``."""
        a = amplitude * np.asarray(ratios)
        laws = zip(self.elements.laws, a, self.k, strict=True)
        return self.k - np.array([float(law.describing_function(aj, k)) for law, aj, k in laws])

    def matrices(self, speeds, dk: np.ndarray, keep: bool = False) -> np.ndarray:
        """Transition matrices (n_speeds, n_z, n_z) of the closed sampled loop at ``speeds``
        [m/s] with the elements' stiffnesses lowered by ``dk`` [N m/rad]."""
        parts = [self.blocks(float(v), keep) for v in speeds]
        n, m = parts[0][2].shape
        aug = np.zeros((len(parts), n + m, n + m))
        for i, (_, A, Bu, Bn, _, _, _) in enumerate(parts):
            aug[i, :n, :n] = A + (Bn * dk) @ self.c_n
            aug[i, :n, n:] = Bu
        E = sla.expm(aug * self.dt)  # zero-order hold on the command, all speeds at once
        out = []
        for i, (law, _, _, _, Cs, Ds, Dn) in enumerate(parts):
            p = Cs.shape[0]
            sp = SampledPlant(
                E[i, :n, :n], E[i, :n, n:], np.zeros((n, 0)), Cs + (Dn * dk) @ self.c_n, Ds,
                np.zeros((p, 0)), self.dt, law.controls, (), law.sensors,
            )  # fmt: skip
            out.append(loop_matrix(sp, law, self.delay))
        return np.stack(out)

    def rates(self, mats: np.ndarray) -> np.ndarray:
        """Growth rates ``ln|mu| / dt`` [1/s] of every root, in descending order."""
        with np.errstate(divide="ignore"):
            g = np.log(np.abs(np.linalg.eigvals(mats))) / self.dt
        return -np.sort(-g, axis=-1)

    def ratios(self, vec: np.ndarray) -> np.ndarray | None:
        """Element amplitudes over the reference element's in the loop mode ``vec``, or None
        if the reference element does not move."""
        x = vec[: self.c_n.shape[1]]
        amp = np.abs(self.c_n @ x)
        if not amp[0] > 1e-10 * np.abs(x[: self.n_q]).max():
            return None
        return amp / amp[0]


def _position(labels: list, name: str, what: str) -> int:
    if name not in labels:
        raise InputError(f"controller {what} {name!r}: not a signal of the loop's plant {labels}")
    return labels.index(name)


def crossings(
    eq: EquivalentLoop, dk: np.ndarray, speeds, tol: float, keep: bool = True, notes=None
) -> list[Crossing]:
    """Every oscillatory crossing of the unit circle on a speed grid (module docstring);
    ``keep``: cache the plant at the grid speeds; ``notes`` (a list) receives a note per grid
    interval where two roots cross and bisection could not separate them."""
    speeds = np.asarray(speeds, dtype=float)

    def growing(w: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore"):
            return np.log(np.abs(w)) / eq.dt > 0

    def rank(v: float, j: int) -> float:
        return float(eq.rates(eq.matrices([v], dk))[0, j])

    w = np.linalg.eigvals(eq.matrices(speeds, dk, keep))
    found, lost = search_intervals(
        speeds, w, growing, lambda v: np.linalg.eigvals(eq.matrices([v], dk)[0])
    )
    if notes is not None:
        notes.extend(hidden_note(a, b) for a, b in lost)
    out: list[Crossing] = []
    for va, vb, na, nb in found:
        lo, hi = sorted((na, nb))
        j = lo
        while j < hi:
            try:
                v = brentq(rank, va, vb, (j,), tol * vb, RTOL_MIN)
            except BracketError:  # a rate at rounding level at a grid speed
                j += 1
                continue
            w, x = sla.eig(eq.matrices([v], dk)[0])
            m = int(np.argmin(np.abs(np.log(np.abs(w) + 1e-300))))
            static = abs(w[m].imag) <= STATIC * abs(w[m])
            j += 1 if static else 2  # rank j + 1 is the conjugate of a complex root
            if static or any(abs(v - c[0]) <= 10 * tol * v for c in out):
                continue  # a real root: static, or the two-sample oscillation
            mu, vec = (w[m], x[:, m]) if w[m].imag > 0 else (w[m].conj(), x[:, m].conj())
            out.append((float(v), complex(mu), vec))
    return out


def converge(
    eq: EquivalentLoop, amplitude: float, speeds: np.ndarray, tol: float, start: Crossing
) -> tuple[float, complex, np.ndarray, np.ndarray] | None:
    """The crossing near ``start`` (found at ratios 1) with amplitude ratios equal to its
    eigenvector's: ``(speed, mu, vector, ratios)``, or None if the reference element does not
    move or the crossing is lost (as :func:`aeroservo.stability.equivalent_system.converge`;
    searched first in a bracket of a few times the last step in speed around the last one)."""
    v, mu, vec = start
    ratios = eq.ratios(vec)
    if ratios is None or ratios.size == 1:
        return None if ratios is None else (v, mu, vec, ratios)
    h = 1e-3 * v
    for _ in range(MAX_ITER):
        i = int(np.searchsorted(speeds, v))
        dk = eq.dk(amplitude, ratios)
        found = (
            crossings(eq, dk, [v - h, v + h], tol, keep=False)
            or crossings(eq, dk, speeds[max(i - 3, 0) : i + 4], tol)
            or crossings(eq, dk, speeds, tol)
        )
        if not found:
            return None
        f0 = np.angle(mu)
        hit = min(found, key=lambda c: abs(c[0] - v) / v + abs(np.angle(c[1]) - f0) / f0)
        h = min(max(4.0 * abs(hit[0] - v), 1e3 * tol * v), 0.01 * v)
        v, mu, vec = hit
        new = eq.ratios(vec)
        if new is None:
            return None
        done = np.abs(new - ratios).max() <= RATIO_TOL
        ratios = new
        if done:
            return v, mu, vec, ratios
    warnings.warn(
        f"loop describing function: the amplitude ratios of {', '.join(eq.elements.names)} did "
        f"not converge to {RATIO_TOL:g} in {MAX_ITER} iterations at amplitude {amplitude:.6g} rad",
        RuntimeWarning,
        stacklevel=3,
    )
    return v, mu, vec, ratios


def growth(eq: EquivalentLoop, amplitude: float, ratios: np.ndarray, v: float, mu: complex):
    """Growth rate [1/s] of the loop's root nearest ``mu`` at speed ``v`` [m/s] and reference
    amplitude ``amplitude`` [rad], the ratios of several elements re-converged."""
    for _ in range(MAX_ITER if ratios.size > 1 else 1):
        w, x = sla.eig(eq.matrices([v], eq.dk(amplitude, ratios))[0])
        m = int(np.argmin(np.abs(w - mu)))
        new = eq.ratios(x[:, m]) if ratios.size > 1 else ratios
        if new is None or np.abs(new - ratios).max() <= RATIO_TOL:
            break
        ratios = new
    return float(np.log(abs(w[m])) / eq.dt)


def _point(eq: EquivalentLoop, a: float, v, mu, vec, ratios, tol: float) -> _Point:
    """An LCO point: its direction in speed, stability and the other roots' at ``(v, a)``."""
    d = growth(eq, a * (1 + STEP), ratios, v, mu) - growth(eq, a * (1 - STEP), ratios, v, mu)
    rising = growth(eq, a, ratios, v * (1 + 1e3 * tol), mu) > 0
    w = np.linalg.eigvals(eq.matrices([v], eq.dk(a, ratios))[0])
    pair = [int(np.argmin(np.abs(w - mu))), int(np.argmin(np.abs(w - np.conj(mu))))]
    others = np.delete(np.abs(w), pair)
    q = vec[: eq.n_q]
    return _Point(
        float(v),
        float(np.angle(mu)) / (2 * np.pi * eq.dt),
        bool(rising),
        bool(d < 0),
        bool(np.all(others < 1.0)),
        ratios,
        q / np.linalg.norm(q),
    )


def _branch_ids(points: list[list[_Point]]) -> list[list[int]]:
    """Branch ids: the pairs (previous amplitude's crossing, this one's) of the same direction
    in speed are joined cheapest first, the cost that of the open loop (shape and frequency,
    :data:`~aeroservo.stability.describing_function.MATCH`) plus the relative change of speed
    (a loop has crossings of one mode far apart in speed)."""
    ids, prev, nxt = [], [], 0
    for pts in points:
        pairs = sorted(
            (_distance(q, p) + abs(q.speed - p.speed) / q.speed, c, i)
            for c, (q, _) in enumerate(prev)
            for i, p in enumerate(pts)
            if q.rising == p.rising
        )
        row: list[int | None] = [None] * len(pts)
        used = set()
        for cost, c, i in pairs:
            if cost < MATCH and c not in used and row[i] is None:
                used.add(c)
                row[i] = prev[c][1]
        for i in range(len(pts)):
            if row[i] is None:
                row[i], nxt = nxt, nxt + 1
        ids.append(row)
        prev = list(zip(pts, row, strict=True))
    return ids


@blas_limited
def loop_describing_branches(
    loop,
    hinges: Sequence[NonlinearHinge],
    controller,
    amplitudes,
    speeds,
    *,
    delay: bool = False,
    tol: float = 1e-9,
) -> DescribingBranches:
    """LCO branches of a sampled control loop with nonlinear hinges by the describing function.

    Parameters
    ----------
    loop : ControlLoop
        The loop of the wing (its plant, sensor filters and state basis).
    hinges : sequence of NonlinearHinge
        Laws on actuators (or on every actuator of a surface), about zero (a freeplay with an
        offset is refused: march it).
    controller
        A linear controller designed on ``loop`` (LQR, LQG, compensator, static gain, MPC
        without active constraints, a gain schedule evaluated at each speed; ``OpenLoop``: the
        open-loop describing function). A Python law is refused.
    amplitudes : array_like
        Amplitudes [rad] of the reference element (the first), positive and increasing.
    speeds : array_like
        Increasing speed grid [m/s] searched for crossings.
    delay : bool
        One-sample computational delay, as in the march.
    tol : float
        Relative tolerance on the speeds.

    Returns
    -------
    DescribingBranches
        As :func:`aeroservo.stability.describing_function.describing_branches`; frequencies
        [Hz] of the sampled loop's roots (aliased below ``f_s / 2`` if above it).
    """
    from .loop import ControlLoop

    if not isinstance(loop, ControlLoop):
        raise InputError(f"loop = {loop!r:.60}: expected an aeroservo ControlLoop")
    ctrl = linear_controller(controller, "loop_describing_branches")
    amps = _check_amplitudes(amplitudes)
    grid = _check_speeds(speeds)
    tol = check_number("tol", tol, lo=1e-14, hi=1e-3)
    eq = EquivalentLoop(loop, hinges, ctrl, delay, float(grid[0]))
    check_centred(eq.elements)
    ones = np.ones(eq.elements.n)
    points: list[list[_Point]] = []
    notes: list[str] = []
    for a in amps:
        row: list[_Point] = []
        hidden: list[str] = []
        for start in crossings(eq, eq.dk(a, ones), grid, tol, notes=hidden):
            hit = converge(eq, a, grid, tol, start)
            if hit is not None and all(abs(hit[0] - p.speed) > 1e-6 * hit[0] for p in row):
                row.append(_point(eq, a, *hit, tol))
        points.append(row)
        notes += [f"amplitude {a:.6g} rad: {n}" for n in hidden]
    ids = _branch_ids(points)
    notes += stop_notes(amps, points, ids, grid, getattr(eq.elements.laws[0], "gap", None))
    return branches_from_points(amps, points, ids, eq.elements, notes)
