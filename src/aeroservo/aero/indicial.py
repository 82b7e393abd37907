"""Indicial functions: Wagner (step change of angle of attack) and Kussner (sharp-edged gust).

Both are written ``phi(s) = 1 - sum_i A_i exp(-b_i s)`` in reduced time s = U t / b
(semichords travelled). In the frequency domain this is the rational approximation
``C(k) = 1 - sum_i A_i (i k) / (i k + b_i)``.

In the time domain each term i contributes one aerodynamic lag state per strip (here: per
mesh node, interpolated linearly along the span, the seed's x-bar):
``zdot_i = -(b_i U / b) z_i + Q`` and ``C Q -> (1 - sum A_i) Q + sum_i A_i (b_i U / b) z_i``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, check_quantity

__all__ = [
    "IndicialSet",
    "WAGNER_SETS",
    "KUSSNER_SETS",
    "wagner_set",
    "kussner_set",
    "wagner_exact",
    "fit_wagner",
]


MAX_TERMS = 12
"""Most exponential terms of an indicial set (one lag state per term and node)."""


def _coefficients(field: str, values: object, quantity: str) -> tuple[float, ...]:
    """A non-empty list of numbers within ``quantity``'s range (strings, booleans refused)."""
    if isinstance(values, np.ndarray):
        values = values.tolist() if values.ndim == 1 else [values.tolist()]
    if isinstance(values, (int, float)) and not isinstance(values, bool):
        values = [values]
    if not isinstance(values, (list, tuple)) or not values:
        raise InputError(f"{field} = {values!r}: expected a non-empty list of numbers")
    if len(values) > MAX_TERMS:
        raise InputError(f"{field}: {len(values)} terms; at most {MAX_TERMS}")
    return tuple(check_quantity(f"{field}[{i}]", x, quantity) for i, x in enumerate(values))


@dataclass(frozen=True)
class IndicialSet:
    """Exponential approximation ``1 - sum A_i exp(-b_i s)`` of an indicial function.

    Parameters
    ----------
    A : tuple of float
        Amplitudes [-], each > 0, with sum(A) <= 1 (1/2 for Wagner so that phi(0) = 1/2; 1 for
        Kussner).
    b : tuple of float
        Decay rates per semichord travelled [-], each > 0.
    name : str
        Identifier.
    source : str
        Where the numbers come from.
    """

    A: tuple[float, ...]
    b: tuple[float, ...]
    name: str = "user"
    source: str = "user supplied"

    def __post_init__(self) -> None:
        where = f"indicial set {self.name!r}"
        A = _coefficients(f"{where}: A", self.A, "wagner_coefficient")
        b = _coefficients(f"{where}: b", self.b, "wagner_exponent")
        object.__setattr__(self, "A", A)
        object.__setattr__(self, "b", b)
        if len(A) == 0 or len(A) != len(b):
            raise InputError(
                f"{where}: A has {len(A)} terms and b has {len(b)}; need the same number (>= 1)"
            )
        if sum(A) > 1.0 + 1e-12:
            raise InputError(
                f"indicial set '{self.name}': sum(A) = {sum(A):g}: must be <= 1 "
                "(the function must not start below zero)"
            )

    @property
    def n_terms(self) -> int:
        """Number of exponential terms (lag states per node)."""
        return len(self.A)

    def __call__(self, s: np.ndarray | float) -> np.ndarray:
        """Evaluate the indicial function at reduced time ``s`` [-]."""
        s = np.asarray(s, dtype=float)
        A = np.asarray(self.A)
        b = np.asarray(self.b)
        return 1.0 - np.sum(A * np.exp(-np.multiply.outer(s, b)), axis=-1)

    def transfer(self, k: np.ndarray | float) -> np.ndarray:
        """Frequency-domain counterpart at reduced frequency ``k`` (approximates C(k))."""
        ik = 1j * np.asarray(k, dtype=float)[..., None]
        A = np.asarray(self.A)
        b = np.asarray(self.b)
        return 1.0 - np.sum(A * ik / (ik + b), axis=-1)


WAGNER_SETS: dict[str, IndicialSet] = {
    s.name: s
    for s in (
        IndicialSet(
            (0.165, 0.335),
            (0.0455, 0.3),
            "rt_jones",
            "R. T. Jones (1939/1940), NACA TN-682 / Rep. 681 (as in AeroSandbox, AeroBeams)",
        ),
        IndicialSet(
            (0.165, 0.335),
            (0.041, 0.32),
            "wp_jones",
            "W. P. Jones, as used in Fung-style C(k) approximations",
        ),
        IndicialSet(
            (0.5,),
            (0.14418707,),
            "one_term",
            "least-squares fit to the exact Wagner function, A fixed at 1/2, "
            "aeroservo.aero.indicial.fit_wagner(1); max |error| 0.045",
        ),
        IndicialSet(
            (0.13794, 0.36206),
            (0.03616, 0.26906),
            "fit2",
            "2-term least-squares fit, shared/reference sec. 6.3 (max |error| 0.0105)",
        ),
        IndicialSet(
            (0.04075, 0.24509, 0.21416),
            (0.01240, 0.10407, 0.41830),
            "fit3",
            "3-term least-squares fit, shared/reference sec. 6.3 (max |error| 0.0028)",
        ),
        IndicialSet(
            (0.02042, 0.11283, 0.26131, 0.10545),
            (0.00662, 0.05201, 0.19127, 0.62196),
            "fit4",
            "4-term least-squares fit, shared/reference sec. 6.3 (max |error| 0.00068)",
        ),
    )
}
"""Named Wagner approximations; ``"rt_jones"`` is the default."""

KUSSNER_SETS: dict[str, IndicialSet] = {
    s.name: s
    for s in (
        IndicialSet(
            (0.5, 0.5),
            (0.13, 1.0),
            "sears_sparks",
            "Sears & Sparks (1941), as in AeroSandbox and Palacios' flexibleaircraftbook",
        ),
        IndicialSet(
            (0.3694, 0.0550, 0.2654, 0.1829, 0.0861, 0.0412),
            (0.3733, 0.0179, 0.1096, 1.6003, 10.428, 170.93),
            "berci_righi",
            "Berci & Righi 6-term fit (AeroBeams IndicialGust)",
        ),
    )
}
"""Named Kussner approximations; ``"sears_sparks"`` is the default."""


def _resolve(spec: object, table: Mapping[str, IndicialSet], kind: str) -> IndicialSet:
    if isinstance(spec, IndicialSet):
        return spec
    if isinstance(spec, str):
        try:
            return table[spec]
        except KeyError:
            raise InputError(
                f"{kind} = {spec!r}: unknown set; known sets are {sorted(table)} "
                "or a mapping {'A': [...], 'b': [...]}"
            ) from None
    if isinstance(spec, Mapping):
        extra = set(spec) - {"A", "b", "name", "source"}
        if extra or not {"A", "b"} <= set(spec):
            raise InputError(
                f"{kind} = {dict(spec)!r}: a user set needs exactly the keys 'A' and 'b' "
                "(optionally 'name', 'source')"
            )
        A = _coefficients(f"{kind}.A", spec["A"], "wagner_coefficient")
        b = _coefficients(f"{kind}.b", spec["b"], "wagner_exponent")
        if len(A) != len(b):
            raise InputError(
                f"{kind}: A has {len(A)} terms and b has {len(b)}; need the same number (>= 1)"
            )
        name = str(spec.get("name", "user"))
        try:
            return IndicialSet(A, b, name, str(spec.get("source", "user")))
        except InputError as exc:  # named by the key, not by the set's default name
            raise InputError(str(exc).replace(f"indicial set {name!r}", kind, 1)) from None
    raise InputError(f"{kind} = {spec!r}: expected a set name, an IndicialSet or a mapping")


def wagner_set(spec: object = "rt_jones") -> IndicialSet:
    """Resolve a Wagner approximation from a name, a mapping ``{"A":..., "b":...}`` or a set."""
    return _resolve(spec, WAGNER_SETS, "wagner")


def kussner_set(spec: object = "sears_sparks") -> IndicialSet:
    """Resolve a Kussner approximation from a name, a mapping or a set."""
    return _resolve(spec, KUSSNER_SETS, "kussner")


def _im_c_on_cut(x: np.ndarray) -> np.ndarray:
    """Im C(p) on the upper side of the branch cut p = x e^{i pi}, x > 0 (scaled Bessels)."""
    from scipy.special import ive, kve

    e2 = np.exp(-2.0 * x)
    k0 = kve(0, x) * e2
    k1 = kve(1, x) * e2
    i0 = ive(0, x)
    i1 = ive(1, x)
    return ((-k1 - 1j * np.pi * i1) / (k0 - k1 - 1j * np.pi * (i0 + i1))).imag


def wagner_exact(s: np.ndarray | float) -> np.ndarray:
    """Exact Wagner function by inversion of C(p)/p along the branch cut.

    ``phi(s) = 1 + (1/pi) int_0^inf exp(-x s) Im C(-x + i0) / x dx`` with
    C(p) = K1(p) / (K0(p) + K1(p)).

    Parameters
    ----------
    s : array_like
        Reduced time U t / b [-], s >= 0.

    Returns
    -------
    ndarray
        phi(s); phi(0) = 1/2, phi(inf) = 1.
    """
    from scipy.integrate import quad

    s_arr = np.atleast_1d(np.asarray(s, dtype=float))
    if np.any(s_arr < 0):
        raise ValueError("s must be >= 0")
    out = np.empty_like(s_arr)
    for i, si in enumerate(s_arr):

        def f(x: float, si: float = si) -> float:
            return float(np.exp(-x * si) * _im_c_on_cut(np.array(x)) / x)

        total = quad(f, 0.0, 1.0, limit=200)[0] + quad(f, 1.0, np.inf, limit=200)[0]
        out[i] = 1.0 + total / np.pi
    return out.reshape(np.shape(s))


def fit_wagner(n_terms: int, s_max: float = 300.0) -> IndicialSet:
    """Least-squares fit of ``1 - sum A_i exp(-b_i s)`` to the exact Wagner function.

    The fit uses 201 points on [0, 20] and 300 on (20, s_max] and enforces sum(A) = 1/2.

    Parameters
    ----------
    n_terms : int
        Number of exponential terms.
    s_max : float
        Upper end of the fitted reduced-time interval [-].

    Returns
    -------
    IndicialSet
    """
    from scipy.optimize import least_squares

    s = np.concatenate([np.linspace(0.0, 20.0, 201), np.linspace(20.0, s_max, 301)[1:]])
    phi = wagner_exact(s)
    n = int(n_terms)

    def unpack(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        A = np.r_[p[: n - 1], 0.5 - np.sum(p[: n - 1])]
        return A, np.exp(p[n - 1 :])

    def residual(p: np.ndarray) -> np.ndarray:
        A, b = unpack(p)
        return 1.0 - np.sum(A[:, None] * np.exp(-b[:, None] * s), axis=0) - phi

    p0 = np.r_[np.full(n - 1, 0.5 / n), np.log(np.geomspace(0.02, 0.5, n))]
    sol = least_squares(residual, p0, xtol=1e-14, ftol=1e-14)
    A, b = unpack(sol.x)
    err = float(np.max(np.abs(sol.fun)))
    return IndicialSet(
        tuple(A), tuple(b), f"fit{n}_aeroservo", f"fit_wagner({n}); max |error| {err:.2g}"
    )
