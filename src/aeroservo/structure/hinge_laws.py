"""Nonlinear restoring moments of a hinge or an actuator linkage: freeplay, bilinear, cubic.

A law gives the moment ``M(s)`` [N m/rad x rad] a spring of linear stiffness ``k`` exerts at the
rotation ``s`` [rad] of the surface at that spring, restoring (positive ``M`` pulls ``s`` back
towards its rest). The linear model keeps the spring closed (``M = k s``); the difference
``k s - M(s)`` enters the equations as a moment on the surface (``docs/freeplay.md``).

* :class:`Freeplay` - no stiffness inside a gap of total width ``gap`` centred at ``offset``
  (a preload shifts the gap), ``k`` outside; ``inner_ratio`` > 0 gives a bilinear spring.
* :class:`Bilinear` - the same with a stiffness ``inner_ratio k`` inside the band.
* :class:`Cubic` - ``M = k s + coefficient s^3``: hardening (coefficient > 0) or softening (< 0).

The describing function of a law is the first-harmonic gain of its moment under a sinusoidal
rotation ``s = A sin(theta)`` about zero (Gelb & Vander Velde, "Multiple-input describing
functions and nonlinear system design", 1968, ch. 2):
``N(A) = 1/(pi A) int_0^(2 pi) M(A sin theta) sin theta d theta``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_number

__all__ = ["Freeplay", "Bilinear", "Cubic", "HingeLaw", "check_law", "freeplay_gain"]

_GAUSS = np.polynomial.legendre.leggauss(24)


@dataclass(frozen=True)
class Freeplay:
    """Freeplay: zero stiffness in a gap, the spring's stiffness ``k`` outside.

    Parameters
    ----------
    gap : float
        Total width of the gap [rad] (>= 0; 0 is the linear spring).
    offset : float
        Centre of the gap [rad] (a preload: the spring is free on
        ``[offset - gap/2, offset + gap/2]``); default 0.
    inner_ratio : float
        Stiffness inside the gap as a fraction of ``k`` (0: freeplay; > 0: bilinear).

    Notes
    -----
    The moment is continuous: ``k_in (s - offset)`` inside the band and
    ``k (s - edge) +- k_in gap/2`` beyond each edge.
    """

    gap: float
    offset: float = 0.0
    inner_ratio: float = 0.0

    kind = "freeplay"
    piecewise_linear = True

    def __post_init__(self) -> None:
        check_number(f"{self.kind}.gap", self.gap, unit="rad", lo=0.0, hi=0.5)
        check_number(f"{self.kind}.offset", self.offset, unit="rad", lo=-0.5, hi=0.5)
        check_number(f"{self.kind}.inner_ratio", self.inner_ratio, lo=0.0, hi=100.0)

    @property
    def edges(self) -> np.ndarray:
        """The rotations [rad] where the stiffness changes, ascending."""
        h = 0.5 * self.gap
        return np.array([self.offset - h, self.offset + h])

    def pieces(self, k: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(edges, slopes, intercepts)``: on piece ``i`` (between ``edges[i-1]`` and
        ``edges[i]``; three pieces) ``M = slopes[i] s + intercepts[i]`` [N m]."""
        lo, hi = self.edges
        k_in = self.inner_ratio * k
        h = 0.5 * self.gap
        slopes = np.array([k, k_in, k])
        icpt = np.array([-k * lo - k_in * h, -k_in * self.offset, -k * hi + k_in * h])
        return self.edges, slopes, icpt

    def moment(self, s, k: float) -> np.ndarray:
        """Restoring moment [N m] at the rotation ``s`` [rad] of a spring of stiffness ``k``."""
        s = np.asarray(s, dtype=float)
        edges, slopes, icpt = self.pieces(k)
        i = np.searchsorted(edges, s, side="right")
        return slopes[i] * s + icpt[i]

    def describing_function(self, amplitude, k: float) -> np.ndarray:
        """Equivalent stiffness ``N(A)`` [N m/rad] at the amplitudes ``A`` [rad] (about zero).

        Closed form for a gap centred at zero; by Gauss quadrature between the angles where
        the rotation crosses an edge otherwise (exact to rounding: the integrand is smooth
        there).
        """
        a = np.asarray(amplitude, dtype=float)
        if self.offset == 0.0:
            return k * (self.inner_ratio + (1.0 - self.inner_ratio) * freeplay_gain(a, self.gap))
        return _quadrature(self, a, k)

    def describe(self) -> str:
        what = f"gap {self.gap:.4g} rad = {np.degrees(self.gap):.4g} deg"
        if self.offset:
            what += f" centred at {self.offset:.4g} rad"
        if self.inner_ratio:
            what += f", inner stiffness {self.inner_ratio:g} k"
        return f"{self.kind} ({what})"


@dataclass(frozen=True)
class Bilinear(Freeplay):
    """Bilinear stiffness: ``inner_ratio k`` in a band of width ``gap`` about ``offset``,
    ``k`` outside (see :class:`Freeplay`)."""

    kind = "bilinear"


@dataclass(frozen=True)
class Cubic:
    """Cubic spring ``M = k s + coefficient s^3``.

    Parameters
    ----------
    coefficient : float
        [N m/rad^3]: > 0 hardening, < 0 softening (a softening spring loses its stiffness at
        ``|s| = sqrt(-k / (3 coefficient))``: a march past it diverges).
    """

    coefficient: float

    kind = "cubic"
    piecewise_linear = False

    def __post_init__(self) -> None:
        check_number("cubic.coefficient", self.coefficient, unit="N m/rad^3", lo=-1e12, hi=1e12)

    def moment(self, s, k: float) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        return k * s + self.coefficient * s**3

    def stiffness(self, s, k: float) -> np.ndarray:
        """Tangent stiffness dM/ds [N m/rad]."""
        return k + 3.0 * self.coefficient * np.asarray(s, dtype=float) ** 2

    def describing_function(self, amplitude, k: float) -> np.ndarray:
        """``N(A) = k + 3/4 coefficient A^2`` [N m/rad]."""
        return k + 0.75 * self.coefficient * np.asarray(amplitude, dtype=float) ** 2

    def describe(self) -> str:
        kind = "hardening" if self.coefficient >= 0 else "softening"
        return f"cubic {kind} ({self.coefficient:g} N m/rad^3)"


HingeLaw = Freeplay | Bilinear | Cubic


def check_law(field: str, law: object) -> HingeLaw:
    """``law`` if it is a hinge law, else an InputError naming ``field``."""
    if not isinstance(law, (Freeplay, Cubic)):
        raise InputError(
            f"{field} = {law!r}: expected aeroservo Freeplay(gap), Bilinear(gap, inner_ratio) "
            "or Cubic(coefficient)"
        )
    return law


def freeplay_gain(amplitude, gap: float) -> np.ndarray:
    """Describing function of a freeplay of total width ``gap`` centred at zero, per unit
    stiffness: ``1 - (2/pi) (asin(u) + u sqrt(1 - u^2))`` with ``u = gap / (2 A)`` for
    ``A > gap/2``, 0 inside the gap [-]."""
    a = np.asarray(amplitude, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(a > 0.5 * gap, 0.5 * gap / np.where(a > 0, a, 1.0), 1.0)
    return 1.0 - (2.0 / np.pi) * (np.arcsin(u) + u * np.sqrt(np.clip(1.0 - u * u, 0.0, None)))


def _quadrature(law: Freeplay, a: np.ndarray, k: float) -> np.ndarray:
    """``N(A)`` by Gauss-Legendre quadrature between the edge crossings of ``A sin theta``."""
    x, w = _GAUSS
    out = np.empty(a.shape)
    for idx, amp in np.ndenumerate(a):
        if amp <= 0.0:
            out[idx] = law.pieces(k)[1][int(np.searchsorted(law.edges, 0.0, side="right"))]
            continue
        cuts = [0.0, 2.0 * np.pi]
        for e in law.edges:
            if abs(e) < amp:
                t = float(np.arcsin(e / amp))
                cuts += [t % (2.0 * np.pi), np.pi - t]
        cuts = np.unique(np.clip(cuts, 0.0, 2.0 * np.pi))
        total = 0.0
        for t0, t1 in zip(cuts[:-1], cuts[1:], strict=True):
            th = 0.5 * (t1 - t0) * x + 0.5 * (t1 + t0)
            total += 0.5 * (t1 - t0) * np.dot(w, law.moment(amp * np.sin(th), k) * np.sin(th))
        out[idx] = total / (np.pi * amp)
    return out
