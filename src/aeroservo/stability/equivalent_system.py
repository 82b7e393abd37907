"""The equivalent linear system of the describing function and its crossings at one amplitude.

With the elements' equivalent stiffnesses ``N_j(a_j)`` [N m/rad] the system reads
``x' = (E^-1 (A0 + V A1 + V^2 A2) + B_n diag(k - N) C_n) x`` (``B_n, C_n`` of
:meth:`aeroservo.system.hinge_elements.HingeElements.lure`: the linear model keeps the springs
closed, ``k``). :func:`crossings` finds every speed of a grid interval where a root crosses the
imaginary axis (sorted real parts and Brent, see :mod:`.describing_function`), :func:`converge`
makes the amplitude ratios of several elements self-consistent with the neutral eigenvector,
:func:`growth` gives the real part of one root at a speed and amplitude.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg as sla

from ..system.first_order import FirstOrderSystem
from ..system.hinge_elements import HingeElements
from .brent import RTOL_MIN, BracketError, brentq
from .describing_checks import hidden_note, search_intervals

__all__ = ["EquivalentSystem", "crossings", "converge", "growth", "RATIO_TOL", "MAX_ITER"]

RATIO_TOL = 1e-8
"""Convergence of the amplitude ratios of several elements (absolute, ratios are ~1) [-]."""
MAX_ITER = 30
"""Largest number of ratio iterations per LCO point."""
STATIC = 1e-9
"""A crossing root with ``|Im| <= STATIC |lambda|`` is static (divergence), not an LCO."""


class EquivalentSystem:
    """The equivalent linear system of a first-order system with hinge elements.

    Parameters
    ----------
    system : FirstOrderSystem
        Every hinge spring closed (stiffness ``k``).
    elements : HingeElements
        The nonlinear elements on ``system``.
    """

    def __init__(self, system: FirstOrderSystem, elements: HingeElements):
        self.a0, self.a1, self.a2 = system.state_matrix_terms()
        self.b_n, self.c_n, _ = elements.lure(system)
        self.k = np.asarray(elements.stiffness, dtype=float)
        self.laws = elements.laws
        self.n_q = system.n_q

    def base(self, amplitude: float, ratios: np.ndarray) -> np.ndarray:
        """``A0' = E^-1 A0 + B_n diag(k - N) C_n`` [1/s] at the element amplitudes."""
        a = amplitude * np.asarray(ratios)
        n = np.array(
            [
                float(law.describing_function(aj, kj))
                for law, aj, kj in zip(self.laws, a, self.k, strict=True)
            ]
        )
        return self.a0 + (self.b_n * (self.k - n)) @ self.c_n

    def matrix(self, base: np.ndarray, v: float) -> np.ndarray:
        """State matrix [1/s] at speed ``v`` [m/s] from :meth:`base`."""
        return base + v * self.a1 + (v * v) * self.a2

    def eigvals(self, base: np.ndarray, speeds: np.ndarray) -> np.ndarray:
        """Eigenvalues (n_speeds, n) at every speed, one batched ``eig``."""
        s = speeds[:, None, None]
        return np.linalg.eigvals(base[None] + s * self.a1[None] + (s * s) * self.a2[None])

    def ratios(self, vec: np.ndarray) -> np.ndarray | None:
        """Element amplitudes over the reference element's, or None if it does not move."""
        amp = np.abs(self.c_n @ vec)
        if not amp[0] > 1e-10 * np.abs(vec[: self.n_q]).max():
            return None
        return amp / amp[0]


def crossings(
    eq: EquivalentSystem,
    base: np.ndarray,
    speeds: np.ndarray,
    tol: float,
    notes: list[str] | None = None,
) -> list[tuple[float, complex, np.ndarray]]:
    """Every oscillatory crossing of the imaginary axis on a speed grid.

    Parameters
    ----------
    eq : EquivalentSystem
    base : ndarray (n, n)
        Speed-independent part at the amplitude (:meth:`EquivalentSystem.base`) [1/s].
    speeds : ndarray
        Increasing speeds [m/s].
    tol : float
        Relative tolerance on the crossing speeds.
    notes : list of str, optional
        Receives a note per grid interval where two roots cross in opposite directions and the
        bisections of :func:`.describing_checks.search_intervals` could not separate them.

    Returns
    -------
    list of (speed, lambda, vector)
        Crossing speed [m/s], the root there (``Im > 0``) [1/s] and its right eigenvector.
    """
    speeds = np.asarray(speeds, dtype=float)
    found, lost = search_intervals(
        speeds,
        eq.eigvals(base, speeds),
        lambda w: w.real > 0,
        lambda v: np.linalg.eigvals(eq.matrix(base, v)),
    )
    if notes is not None:
        notes.extend(hidden_note(a, b) for a, b in lost)

    def rank(v: float, j: int) -> float:
        return float(-np.sort(-np.linalg.eigvals(eq.matrix(base, v)).real)[j])

    out = []
    for va, vb, na, nb in found:
        lo, hi = sorted((na, nb))
        roots: list[float] = []
        for j in range(lo, hi):
            try:
                v = brentq(rank, va, vb, (j,), tol * vb, RTOL_MIN)
            except BracketError:  # a real part at rounding level at a grid speed
                continue
            if all(abs(v - r) > 10 * tol * v for r in roots):
                roots.append(v)
        for v in roots:
            w, x = sla.eig(eq.matrix(base, v))
            m = int(np.argmin(np.abs(w.real)))
            if abs(w[m].imag) <= STATIC * abs(w[m]):
                continue  # static: divergence of the equivalent system
            lam, vec = (w[m], x[:, m]) if w[m].imag > 0 else (w[m].conj(), x[:, m].conj())
            out.append((float(v), complex(lam), vec))
    return out


def _nearest(found: list, v0: float, lam0: complex):
    """The crossing of ``found`` nearest in speed and frequency, or None."""
    if not found:
        return None
    return min(found, key=lambda c: abs(c[0] - v0) / v0 + abs(c[1].imag - lam0.imag) / lam0.imag)


def converge(
    eq: EquivalentSystem,
    amplitude: float,
    speeds: np.ndarray,
    tol: float,
    start: tuple[float, complex, np.ndarray],
    names: tuple[str, ...],
) -> tuple[float, complex, np.ndarray, np.ndarray] | None:
    """The crossing near ``start`` with amplitude ratios equal to its eigenvector's.

    Parameters
    ----------
    eq : EquivalentSystem
    amplitude : float
        Reference element's amplitude [rad].
    speeds : ndarray
        The speed grid [m/s]; the crossing is searched again in the grid intervals around the
        last one (the whole grid if it moved out of them).
    tol : float
        Relative tolerance on speed.
    start : (speed, lambda, vector)
        A crossing of :func:`crossings` at ratios 1.
    names : tuple of str
        Element names (for the warning).

    Returns
    -------
    (speed, lambda, vector, ratios) or None
        None when the reference element does not move in the crossing mode or the crossing is
        lost while iterating. A RuntimeWarning if the ratios did not converge to
        :data:`RATIO_TOL` in :data:`MAX_ITER` iterations (the last iterate is returned).
    """
    v, lam, vec = start
    ratios = eq.ratios(vec)
    if ratios is None or ratios.size == 1:
        return None if ratios is None else (v, lam, vec, ratios)
    for _ in range(MAX_ITER):
        i = int(np.searchsorted(speeds, v))
        window = speeds[max(i - 3, 0) : i + 4]
        base = eq.base(amplitude, ratios)
        hit = _nearest(crossings(eq, base, window, tol) or crossings(eq, base, speeds, tol), v, lam)
        if hit is None:
            return None
        v, lam, vec = hit
        new = eq.ratios(vec)
        if new is None:
            return None
        done = np.abs(new - ratios).max() <= RATIO_TOL
        ratios = new
        if done:
            return v, lam, vec, ratios
    warnings.warn(
        f"describing function: the amplitude ratios of {', '.join(names)} did not converge to "
        f"{RATIO_TOL:g} in {MAX_ITER} iterations at amplitude {amplitude:.6g} rad",
        RuntimeWarning,
        stacklevel=3,
    )
    return v, lam, vec, ratios


def growth(
    eq: EquivalentSystem, amplitude: float, ratios: np.ndarray, v: float, lam: complex
) -> float:
    """Real part [1/s] of the root nearest ``lam`` [1/s] at speed ``v`` [m/s] and reference
    amplitude ``amplitude`` [rad], the ratios of several elements re-converged from
    ``ratios``."""
    for _ in range(MAX_ITER if ratios.size > 1 else 1):
        w, x = sla.eig(eq.matrix(eq.base(amplitude, ratios), v))
        m = int(np.argmin(np.abs(w - lam)))
        new = eq.ratios(x[:, m]) if ratios.size > 1 else ratios
        if new is None or np.abs(new - ratios).max() <= RATIO_TOL:
            break
        ratios = new
    return float(w[m].real)
