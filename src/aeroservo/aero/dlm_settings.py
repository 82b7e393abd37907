"""Settings of the doublet-lattice aerodynamic model: boxes, reduced frequencies, the
rational-function approximation (``docs/dlm.md``).

Reduced frequencies ``k = omega b_ref / V`` are on the model's reference semichord ``b_ref``
(the span-averaged semichord, ``AeroelasticModel.semichord``), as everywhere in aeroservo.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_int, check_number
from .dlm import KERNELS
from .rfa import RFA_KINDS, lag_roots

__all__ = ["DoubletLattice", "K_SPACING", "AERO_MODELS", "as_aero"]

AERO_MODELS = ("strip", "dlm")
"""Aerodynamic models of a wing: 2-D strip theory (default) or the doublet-lattice method."""

K_SPACING = (0.01, 0.03, 0.06, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.65, 0.8, 1.0)
"""Default reduced frequencies as fractions of ``k_max`` (k = 0 is always added)."""

MAX_BOXES = 4000
"""Most boxes of a lattice (the AICs are dense: 4000 boxes need 256 MB per frequency)."""


@dataclass(frozen=True)
class DoubletLattice:
    """The doublet-lattice model of a wing and its time-domain approximation.

    Parameters
    ----------
    chordwise : int
        Boxes along the chord (default 6); a control surface's hinge line is always a box edge,
        with at least 2 boxes on the surface.
    spanwise : int, optional
        Strips along the span; default: square boxes (at least 8 strips), with edges at every
        segment boundary and control-surface edge (``docs/dlm.md``: the convergence study).
    k_max : float
        Highest tabulated reduced frequency ``omega b_ref / V`` [-] (default 1.0, twice the
        flutter reduced frequencies of beam-like wings, 0.1-0.6; ``docs/dlm.md`` has the
        measured trade between range and fit error): at a speed V the approximation is fitted
        to frequencies up to ``k_max V / (2 pi b_ref)`` Hz.
    reduced_frequencies : sequence of float, optional
        The tabulated k (instead of :data:`K_SPACING` x ``k_max``); 0 is added.
    rfa : {"roger", "minimum-state"}
        Rational-function approximation (Roger 1977; Karpel 1982).
    lags : int
        Lag roots (default 4): Roger adds ``lags`` x structural unknowns lag states, the
        minimum-state form ``lags`` states.
    lag_roots : sequence of float, optional
        The lag roots [-] (default ``1.7 k_max (j / (lags + 1))^2``).
    kernel : {"quartic", "parabolic"}
        Kernel approximation of the doublet-lattice method (default quartic, Rodden, Taylor and
        McIntosh 1998).
    symmetric : bool
        The root is a plane of symmetry (a wall or a fuselage side; default True): the mirror
        wing moves with the wing. False: an isolated wing (Nastran's AERO SYMXZ = 0).
    modes : int, optional
        In-vacuo modes the model is written on (its aerodynamic basis; default as many as
        spanwise strips, at least 12, at most every mode).
    """

    chordwise: int = 6
    spanwise: int | None = None
    k_max: float = 1.0
    reduced_frequencies: tuple | None = None
    rfa: str = "roger"
    lags: int = 4
    lag_roots: tuple | None = None
    kernel: str = "quartic"
    symmetric: bool = True
    modes: int | None = None

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "chordwise", check_int("dlm.chordwise", self.chordwise, lo=2, hi=100))
        if self.spanwise is not None:
            set_(self, "spanwise", check_int("dlm.spanwise", self.spanwise, lo=1, hi=1000))
            if self.spanwise * self.chordwise > MAX_BOXES:
                raise InputError(
                    f"dlm.spanwise = {self.spanwise}: {self.spanwise} x {self.chordwise} boxes, "
                    f"above the limit of {MAX_BOXES} (dense AICs of that size need "
                    f"{16 * MAX_BOXES**2 / 2**20:.0f} MB per frequency)"
                )
        set_(self, "k_max", check_number("dlm.k_max", self.k_max, lo=0.05, hi=20.0))
        if self.rfa not in RFA_KINDS:
            raise InputError(f"dlm.rfa = {self.rfa!r}: allowed values are {', '.join(RFA_KINDS)}")
        if self.kernel not in KERNELS:
            raise InputError(
                f"dlm.kernel = {self.kernel!r}: allowed values are {', '.join(KERNELS)}"
            )
        set_(self, "lags", check_int("dlm.lags", self.lags, lo=1, hi=12))
        if self.modes is not None:
            set_(self, "modes", check_int("dlm.modes", self.modes, lo=1, hi=2000))
        if not isinstance(self.symmetric, (bool, np.bool_)):
            raise InputError(f"dlm.symmetric = {self.symmetric!r}: expected true or false")
        if self.reduced_frequencies is not None:
            ks = _numbers("dlm.reduced_frequencies", self.reduced_frequencies, 0.0, 50.0)
            ks = np.unique(np.concatenate([[0.0], ks]))
            set_(self, "reduced_frequencies", tuple(float(v) for v in ks))
            set_(self, "k_max", float(ks[-1]))
        if self.lag_roots is not None:
            roots = _numbers("dlm.lag_roots", self.lag_roots, 1e-4, 100.0)
            if np.unique(roots).size != roots.size:
                raise InputError(f"dlm.lag_roots = {list(roots)}: the roots must differ")
            set_(self, "lag_roots", tuple(float(v) for v in roots))
            set_(self, "lags", len(roots))
        n_osc = self.k_values.size - 1
        need = self.lags + 2  # A1, A2 and a matrix per lag root, real and imaginary rows
        if 2 * n_osc < need:
            raise InputError(
                f"dlm.reduced_frequencies: {n_osc} non-zero values cannot fit {self.lags} lag "
                f"roots (give at least {(need + 1) // 2})"
            )

    @property
    def k_values(self) -> np.ndarray:
        """Tabulated reduced frequencies [-], 0 first."""
        if self.reduced_frequencies is not None:
            return np.asarray(self.reduced_frequencies, dtype=float)
        return np.concatenate([[0.0], self.k_max * np.asarray(K_SPACING)])

    @property
    def roots(self) -> np.ndarray:
        """Lag roots of the rational-function approximation [-]."""
        if self.lag_roots is not None:
            return np.asarray(self.lag_roots, dtype=float)
        return lag_roots(self.k_max, self.lags)

    def describe(self) -> str:
        """One line for reports."""
        span = "auto" if self.spanwise is None else str(self.spanwise)
        sym = "root symmetry plane" if self.symmetric else "isolated wing"
        return (
            f"doublet lattice ({self.kernel} kernel, {self.chordwise} chordwise x {span} "
            f"spanwise boxes, {sym}), {self.rfa} RFA with {self.lags} lags over k <= "
            f"{self.k_max:g} ({self.k_values.size} frequencies)"
        )

    def to_dict(self) -> dict:
        """The settings as plain values (JSON, TOML)."""
        return {
            "chordwise": self.chordwise,
            "spanwise": self.spanwise,
            "k_max": self.k_max,
            "reduced_frequencies": list(self.k_values),
            "rfa": self.rfa,
            "lags": self.lags,
            "lag_roots": list(self.roots),
            "kernel": self.kernel,
            "symmetric": bool(self.symmetric),
            "modes": self.modes,
        }


def _numbers(field_: str, value: object, lo: float, hi: float) -> np.ndarray:
    if not isinstance(value, (list, tuple, np.ndarray)) or len(value) == 0:
        raise InputError(f"{field_} = {value!r}: expected a non-empty list of numbers")
    return np.array(
        [check_number(f"{field_}[{i}]", v, lo=lo, hi=hi) for i, v in enumerate(value)], dtype=float
    )


def as_aero(aero: object) -> DoubletLattice | None:
    """The aerodynamic model from ``"strip"`` (None), ``"dlm"`` (default settings), a mapping of
    :class:`DoubletLattice`'s keys, or a :class:`DoubletLattice`."""
    if aero is None or (isinstance(aero, str) and aero == "strip"):
        return None
    if isinstance(aero, DoubletLattice):
        return aero
    if isinstance(aero, str) and aero == "dlm":
        return DoubletLattice()
    if isinstance(aero, dict):
        known = set(DoubletLattice.__dataclass_fields__)
        bad = sorted(set(aero) - known)
        if bad:
            raise InputError(f"dlm.{bad[0]}: unknown key; allowed are {', '.join(sorted(known))}")
        return DoubletLattice(**aero)
    raise InputError(
        f"aero = {aero!r}: allowed values are 'strip', 'dlm' or an aeroservo DoubletLattice"
    )
