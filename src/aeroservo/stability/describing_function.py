"""Limit-cycle oscillations predicted by the describing function (equivalent linearisation).

Each nonlinear hinge element ``j`` (:mod:`aeroservo.system.hinge_elements`) oscillating with the
amplitude ``a_j`` [rad] is replaced by its equivalent stiffness ``N_j(a_j)`` [N m/rad]
(:mod:`aeroservo.structure.hinge_laws`, about zero rotation). The linear model keeps the
springs closed, so the equivalent system is

    x' = (A(V) + B_n diag(k - N) C_n) x,

with ``B_n, C_n`` of :meth:`HingeElements.lure`. An LCO of amplitude ``A`` (the first element's,
the reference) is a speed where this system has a root on the imaginary axis; its frequency is
that root's. Continuing the speed in ``A`` gives the LCO branches (Gelb & Vander Velde 1968;
for the freeplay section: Conner, Tang, Dowell & Virgin 1997, J. Fluids Struct. 11, 89-109).

Method, per amplitude:

* **Crossings.** All eigenvalues on the speed grid (one batched dense ``eig`` over the speeds).
  The real parts sorted in descending order (conjugate pairs counted twice) are continuous
  functions of speed, whatever the ordering of the roots. Where the number ``m`` of roots with
  ``Re > 0`` changes between two grid speeds, the sorted real part of rank ``j`` (for each ``j``
  between the two counts) changes sign there, and Brent's method finds its zero to ``tol``
  (relative). No eigenvalue matching is needed, and several roots crossing at different speeds
  are each found. A real root crossing zero (static divergence of the equivalent system) is
  not an LCO and is left out, as is a crossing of a mode the elements do not move.
  Two roots crossing in opposite directions within one grid interval leave ``m`` unchanged:
  the roots at its ends are paired by continuity and, where their own sign changes disagree
  with ``m``, the interval is bisected (:mod:`.describing_checks`; a note if that does not
  separate them). A root that crosses and crosses back within one interval is missed (refine
  ``speeds``).
* **Several elements.** The amplitude ratios ``a_j / A`` are those of the neutral eigenvector,
  ``|C_n v|`` over its reference entry; starting from 1 they are iterated (the crossing found
  again near the last one with the new ratios) until they change by less than
  :data:`.equivalent_system.RATIO_TOL` (1e-8), at most 30 times (a warning if not converged).
* **Stability.** At fixed speed, the real part ``sigma`` of the crossing root at the amplitudes
  ``A (1 +- h)``, ``h =`` :data:`STEP` (ratios re-converged): the LCO is stable when
  ``d sigma / dA < 0`` (a larger oscillation is damped, a smaller one grows).
  ``others_stable`` tells whether every other root is damped there: if not, the LCO is not
  seen even where ``stable`` (another oscillation grows).
* **Branches.** A crossing continues the previous amplitude's crossing of the same direction
  in speed with the nearest mode shape (MAC) and frequency; a fold in speed is within a branch
  (parametrised by amplitude), a fold in amplitude ends two branches.

Amplitudes at or inside a freeplay gap give the inner stiffness (no LCO amplitude there: the
speed does not depend on ``A`` and the point is not flagged stable).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .._threads import blas_limited
from ..errors import InputError, check_number
from ..system.first_order import FirstOrderSystem
from ..system.hinge_elements import HingeElements
from .describing_checks import stop_notes
from .equivalent_system import EquivalentSystem, converge, crossings, growth

__all__ = ["DescribingBranches", "describing_branches", "STEP"]

STEP = 1e-5
"""Relative step in amplitude of the central difference ``d sigma / dA``."""


@dataclass(frozen=True)
class DescribingBranches:
    """LCO branches predicted by the describing function.

    Attributes
    ----------
    amplitude : ndarray (n_pts,)
        Rotation amplitude [rad] of the reference element (``element``) at the LCO.
    speed : ndarray (n_pts,)
        Airspeed [m/s] where the equivalent linear system is neutrally stable.
    frequency : ndarray (n_pts,)
        LCO frequency [Hz].
    stable : ndarray (n_pts,) bool
        The LCO is stable (``d sigma / dA < 0`` at fixed speed, ``sigma`` the real part of the
        crossing root; False at amplitudes inside a gap, where ``sigma`` does not change).
    branch : ndarray (n_pts,) int
        Branch id: one per crossing of the imaginary axis, continued in amplitude.
    ratios : ndarray (n_pts, n_e)
        Amplitude of each element over the reference element's [-].
    gap : float or None
        Total gap [rad] of the reference element's law (None for a cubic spring).
    element : str
        Name of the reference element.
    names : tuple of str
        Names of all the elements (columns of ``ratios``).
    others_stable : ndarray (n_pts,) bool
        Every other root of the equivalent system is damped at that point (if not, the LCO is
        not observed even where ``stable``: another oscillation grows).
    notes : tuple of str
        What the grids did not resolve (:mod:`.describing_checks`): two roots crossing within
        one speed interval that bisection could not separate, a flat branch that stops.
    """

    amplitude: np.ndarray
    speed: np.ndarray
    frequency: np.ndarray
    stable: np.ndarray
    branch: np.ndarray
    ratios: np.ndarray
    gap: float | None
    element: str
    names: tuple[str, ...] = ()
    others_stable: np.ndarray | None = None
    notes: tuple[str, ...] = ()

    @classmethod
    def from_table(
        cls, rows: list, *, gap: float | None, element: str, names: tuple = ()
    ) -> DescribingBranches:
        """The branches of :meth:`table`'s rows (e.g. read back from a result file); ``gap``,
        ``element`` and ``names`` as the attributes (``names``: the columns of ``ratios``,
        default those of the first row)."""
        try:
            names = tuple(names or ()) or (tuple(rows[0]["ratios"]) if rows else (element,))
            ratios = [[float(r["ratios"][n]) for n in names] for r in rows]
            others = [r["others_stable"] for r in rows]
            return cls(
                amplitude=np.array([r["amplitude_rad"] for r in rows], dtype=float),
                speed=np.array([r["speed_m_s"] for r in rows], dtype=float),
                frequency=np.array([r["frequency_hz"] for r in rows], dtype=float),
                stable=np.array([bool(r["stable"]) for r in rows], dtype=bool),
                branch=np.array([r["branch"] for r in rows], dtype=int),
                ratios=np.array(ratios, dtype=float).reshape(len(rows), len(names)),
                gap=None if gap is None else float(gap),
                element=str(element),
                names=names,
                others_stable=None
                if rows and any(o is None for o in others)
                else np.array([bool(o) for o in others], dtype=bool),
            )
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
            raise InputError(f"describing-function table: not valid ({exc!r:.80})") from None

    def onset(self) -> float:
        """Lowest speed [m/s] of any LCO branch (NaN without a branch)."""
        return float(self.speed.min()) if self.speed.size else float("nan")

    def table(self) -> list[dict]:
        """One JSON-able row per LCO point (amplitudes in rad, speeds in m/s, Hz)."""
        names = self.names or tuple(f"element{j + 1}" for j in range(self.ratios.shape[1]))
        rows = []
        for i in range(self.speed.size):
            a = float(self.amplitude[i])
            rows.append(
                {
                    "branch": int(self.branch[i]),
                    "element": self.element,
                    "amplitude_rad": a,
                    "amplitude_per_gap": a / self.gap if self.gap else None,
                    "speed_m_s": float(self.speed[i]),
                    "frequency_hz": float(self.frequency[i]),
                    "stable": bool(self.stable[i]),
                    "others_stable": None
                    if self.others_stable is None
                    else bool(self.others_stable[i]),
                    "ratios": {n: float(r) for n, r in zip(names, self.ratios[i], strict=True)},
                }
            )
        return rows


def _branch_ids(points: list[list[_Point]]) -> list[list[int]]:
    """Branch ids: each crossing continues the previous amplitude's crossing of the same
    direction whose structural shape (MAC) and frequency are nearest, if near enough."""
    ids, prev, nxt = [], [], 0
    for pts in points:
        free = list(range(len(prev)))
        row = []
        for p in pts:
            cost = {c: _distance(prev[c][0], p) for c in free if prev[c][0].rising == p.rising}
            c = min(cost, key=cost.get, default=None)
            if c is not None and cost[c] < MATCH:
                free.remove(c)
                row.append(prev[c][1])
            else:
                row.append(nxt)
                nxt += 1
        ids.append(row)
        prev = list(zip(pts, row, strict=True))
    return ids


MATCH = 0.5
"""Largest ``1 - MAC + |df| / f`` between crossings at successive amplitudes on one branch."""


def _distance(p: _Point, q: _Point) -> float:
    mac = abs(np.vdot(p.shape, q.shape)) ** 2
    return 1.0 - mac + abs(p.frequency - q.frequency) / max(p.frequency, q.frequency)


@blas_limited
def describing_branches(
    system: FirstOrderSystem,
    elements: HingeElements,
    amplitudes,
    *,
    speeds=None,
    tol: float = 1e-10,
) -> DescribingBranches:
    """LCO branches of a system with nonlinear hinges by the describing function.

    Parameters
    ----------
    system : FirstOrderSystem
        The linear system, every hinge spring closed.
    elements : HingeElements
        The nonlinear elements on that system (laws about zero: a freeplay with an offset is
        refused).
    amplitudes : array_like
        Amplitudes [rad] of the reference element (``elements.names[0]``), positive and
        increasing (e.g. ``gap/2 (1 + logspace(-3, 1.5, n))``).
    speeds : array_like, optional
        Increasing speed grid [m/s] searched for crossings. Default ``linspace(0.01, 3, 300)``
        times the gap-closed flutter speed (the linear system's lowest oscillatory crossing,
        found on ``linspace(0.01, 1, 200)`` times ``8 b omega_2``).
    tol : float
        Relative tolerance on the speeds.

    Returns
    -------
    DescribingBranches
    """
    if not isinstance(system, FirstOrderSystem):
        raise InputError(f"system = {system!r}: expected an aeroservo FirstOrderSystem")
    if not isinstance(elements, HingeElements):
        raise InputError(f"elements = {elements!r}: expected aeroservo HingeElements")
    check_centred(elements)
    amps = _check_amplitudes(amplitudes)
    tol = check_number("tol", tol, lo=1e-14, hi=1e-3)
    eq = EquivalentSystem(system, elements)
    grid = _default_speeds(eq, system) if speeds is None else _check_speeds(speeds)
    ones = np.ones(elements.n)
    points: list[list[_Point]] = []
    notes: list[str] = []
    for a in amps:
        row: list[_Point] = []
        hidden: list[str] = []
        for start in crossings(eq, eq.base(a, ones), grid, tol, hidden):
            hit = converge(eq, a, grid, tol, start, elements.names)
            if hit is not None and all(abs(hit[0] - p.speed) > 1e-6 * hit[0] for p in row):
                row.append(_point(eq, a, *hit, tol))
        points.append(row)
        notes += [f"amplitude {a:.6g} rad: {n}" for n in hidden]
    ids = _branch_ids(points)
    notes += stop_notes(amps, points, ids, grid, getattr(elements.laws[0], "gap", None))
    return branches_from_points(amps, points, ids, elements, notes)


class _Point(NamedTuple):
    speed: float
    frequency: float
    rising: bool
    stable: bool
    others_stable: bool
    ratios: np.ndarray
    shape: np.ndarray


def _point(
    eq: EquivalentSystem,
    a: float,
    v: float,
    lam: complex,
    vec: np.ndarray,
    ratios: np.ndarray,
    tol: float,
) -> _Point:
    """An LCO point: its direction in speed, stability and the other roots' at ``(v, a)``."""
    d = growth(eq, a * (1 + STEP), ratios, v, lam) - growth(eq, a * (1 - STEP), ratios, v, lam)
    rising = growth(eq, a, ratios, v * (1 + 1e3 * tol), lam) > 0
    w = np.linalg.eigvals(eq.matrix(eq.base(a, ratios), v))
    pair = [int(np.argmin(np.abs(w - lam))), int(np.argmin(np.abs(w - np.conj(lam))))]
    others = np.delete(w.real, pair)
    q = vec[: eq.n_q]
    return _Point(
        v,
        lam.imag / (2 * np.pi),
        bool(rising),
        bool(d < 0),
        bool(np.all(others < 0)),
        ratios,
        q / np.linalg.norm(q),
    )


def _check_amplitudes(amplitudes) -> np.ndarray:
    try:
        a = np.asarray(amplitudes, dtype=float)
    except (TypeError, ValueError):
        raise InputError(
            f"amplitudes = {amplitudes!r}: expected increasing positive amplitudes [rad]"
        ) from None
    if a.ndim != 1 or a.size == 0:
        raise InputError(
            f"amplitudes: expected a non-empty 1-D array of amplitudes [rad], got shape {a.shape}"
        )
    bad = np.flatnonzero(~np.isfinite(a) | (a <= 0))
    if bad.size:
        i = int(bad[0])
        raise InputError(f"amplitudes[{i}] = {a[i]!r}: expected a positive finite amplitude [rad]")
    steps = np.flatnonzero(np.diff(a) <= 0)
    if steps.size:
        i = int(steps[0]) + 1
        raise InputError(
            f"amplitudes[{i}] = {a[i]:g} rad: not above amplitudes[{i - 1}] = {a[i - 1]:g} rad "
            "(give them increasing)"
        )
    return a


def _check_speeds(speeds) -> np.ndarray:
    try:
        v = np.asarray(speeds, dtype=float)
    except (TypeError, ValueError):
        v = np.zeros(0)
    if v.ndim != 1 or v.size < 2 or not np.all(np.isfinite(v)) or v[0] <= 0:
        raise InputError("speeds: expected at least 2 positive finite speeds [m/s], increasing")
    steps = np.flatnonzero(np.diff(v) <= 0)
    if steps.size:
        i = int(steps[0]) + 1
        raise InputError(f"speeds[{i}] = {v[i]:g} m/s: not above speeds[{i - 1}] = {v[i - 1]:g}")
    return v


def _default_speeds(eq: EquivalentSystem, system: FirstOrderSystem) -> np.ndarray:
    """``linspace(0.01, 3, 300) U_F`` with ``U_F`` the gap-closed flutter speed [m/s]."""
    lam, _ = system.modes_at_rest(2)
    top = 8.0 * system.semichord * float(np.abs(lam[-1]))
    coarse = np.linspace(0.01, 1.0, 200) * min(top, 1000.0)
    found = crossings(eq, eq.a0, coarse, 1e-6)
    if not found:
        return np.linspace(0.01, 1.0, 300) * coarse[-1]
    return np.linspace(0.01, 3.0, 300) * min(c[0] for c in found)


def check_centred(elements) -> None:
    """An InputError for a law whose gap is not centred at zero (the describing function here
    is about zero rotation)."""
    for name, law in zip(elements.names, elements.laws, strict=True):
        if getattr(law, "offset", 0.0) != 0.0:
            raise InputError(
                f"hinge '{name}': {law.describe()}: the describing function here is about zero "
                "rotation; march the nonlinear system instead"
            )


def branches_from_points(amps, points: list, ids: list, elements, notes=()) -> DescribingBranches:
    """The :class:`DescribingBranches` of the neutral points found at each amplitude
    (``points[i]``: the points at ``amps[i]``, ``ids[i]``: their branch ids; ``notes``)."""
    flat = [
        (a, p, b)
        for a, row, bs in zip(amps, points, ids, strict=True)
        for p, b in zip(row, bs, strict=True)
    ]
    law0 = elements.laws[0]

    def col(name: str, dtype=float) -> np.ndarray:
        return np.array([getattr(f[1], name) for f in flat], dtype=dtype)

    return DescribingBranches(
        amplitude=np.array([f[0] for f in flat], dtype=float),
        speed=col("speed"),
        frequency=col("frequency"),
        stable=col("stable", bool),
        branch=np.array([f[2] for f in flat], dtype=int),
        ratios=col("ratios").reshape(len(flat), elements.n),
        gap=float(law0.gap) if hasattr(law0, "gap") else None,
        element=elements.names[0],
        names=tuple(elements.names),
        others_stable=col("others_stable", bool),
        notes=tuple(notes),
    )
