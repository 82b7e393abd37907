"""Theodorsen's thin-airfoil unsteady aerodynamics with a trailing-edge flap.

Theodorsen (1935), NACA Report 496, written in aeroservo's coordinates (``docs/conventions.md``):
section unknowns ``[w, phi, delta]`` = plunge of the elastic axis (up), twist (nose-up) and
flap rotation (trailing-edge down). Theodorsen's plunge h is positive down, so h = -w.

The generalized section loads are ``f = [L, M_alpha, M_beta]`` (lift up [N/m], pitching
moment about the elastic axis nose-up [N m/m], hinge moment trailing-edge down [N m/m]):

* non-circulatory part: ``-rho * (Mnc qdd + U Cnc qd + U^2 Knc q)``
* circulatory part: ``rho U b w (C Q)``, with the 3/4-chord downwash
  ``Q = U r_q.q + r_d.qd = U phi - wd + b(1/2 - a) phid + (U/pi) T10 delta + (b/2pi) T11 deltad``.

``C Q`` is ``C(k) Q`` for harmonic motion and a Wagner convolution in the time domain
(:mod:`aeroservo.aero.indicial`). All coefficient arrays are per unit air density and exclude the
factors of U shown above, so they are built once and scaled at every speed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["theodorsen_function", "t_functions", "SectionAero", "section_aero"]


#: Below this reduced frequency the Hankel functions come from their power series, above it
#: from their asymptotic expansion; C(k) is then good to 2e-11 relative (tests/test_theodorsen.py
#: compares with scipy.special.hankel2).
SERIES_LIMIT = 13.0
_EULER_GAMMA = 0.5772156649015329


def _powers(z: np.ndarray, n: int) -> np.ndarray:
    """``z[i]^m`` for ``m = 0 .. n - 1`` (rows: the points), by repeated multiplication."""
    out = np.empty((z.size, n))
    out[:, 0] = 1.0
    if n > 1:
        out[:, 1:] = z[:, None]
        np.cumprod(out[:, 1:], axis=1, out=out[:, 1:])
    return out


def _series_coefficients(n_terms: int) -> np.ndarray:
    """Coefficients of the four power series in ``q = -(x/2)^2`` of :func:`_hankel_ratio_series`
    (rows: J0, J1 / (x/2), S0, S1 / (x/2)), for ``m = 0 .. n_terms - 1``."""
    out = np.zeros((4, n_terms))
    t, harmonic = 1.0, 0.0  # 1 / m!^2 and H_m
    for m in range(n_terms):
        if m:
            t /= m * m
            harmonic += 1.0 / m
        u = t / (m + 1)  # 1 / (m! (m+1)!)
        out[:, m] = (t, u, -harmonic * t, (2 * harmonic + 1.0 / (m + 1) - 2 * _EULER_GAMMA) * u)
    return out


_SERIES = _series_coefficients(200)


def _hankel_ratio_series(x: np.ndarray) -> np.ndarray:
    """H1(2)(x) / H0(2)(x) from the power series of J0, J1, Y0, Y1 (A&S 9.1.10-11), x > 0.

    ``J0 = sum q^m / m!^2``, ``J1 = (x/2) sum q^m / (m! (m+1)!)`` with ``q = -(x/2)^2``, and the
    sums ``S0 = -sum H_m q^m / m!^2``, ``S1 = (x/2) sum (2 H_m + 1/(m+1) - 2 gamma) q^m /
    (m! (m+1)!)`` of Y0 and Y1, all four as one product of the powers of q with the coefficients.
    """
    half = float(np.max(x)) / 2
    n_terms, t = 1, 1.0  # terms until (x/2)^2m / m!^2 is below 1e-17 past its peak
    while n_terms < 200 and (n_terms <= half or t > 1e-17):
        t *= half * half / (n_terms * n_terms)
        n_terms += 1
    acc = _powers(-((x / 2) ** 2), n_terms) @ _SERIES[:, :n_terms].T
    j0, s0 = acc[:, 0], acc[:, 2]
    j1, s1 = (x / 2) * acc[:, 1], (x / 2) * acc[:, 3]
    log = np.log(x / 2)
    y0 = (2 / np.pi) * ((log + _EULER_GAMMA) * j0 + s0)
    y1 = (2 / np.pi) * log * j1 - 2 / (np.pi * x) - s1 / np.pi
    return (j1 - 1j * y1) / (j0 - 1j * y0)


def _asymptotic_coefficients(n_terms: int) -> np.ndarray:
    """``(-i)^k a_k(nu)`` of the Hankel expansions (A&S 9.2.7-8), rows nu = 0 and nu = 1."""
    out = np.zeros((2, n_terms), dtype=complex)
    for i, mu in enumerate((0.0, 4.0)):  # 4 nu^2
        a = 1.0 + 0j
        out[i, 0] = a
        for k in range(1, n_terms):
            a = a * (-1j) * (mu - (2 * k - 1) ** 2) / (8 * k)
            out[i, k] = a
    return out


_ASYMPTOTIC = _asymptotic_coefficients(60)
_ASYMPTOTIC_ABS = np.abs(_ASYMPTOTIC)


def _hankel_ratio_asymptotic(x: np.ndarray) -> np.ndarray:
    """H1(2)(x) / H0(2)(x) = i S1 / S0 from the Hankel expansions (A&S 9.2.7-8), x large:
    S_nu = sum_k (-i)^k a_k(nu) / x^k, summed while the terms of the smallest x decrease
    (both sums as one product of the powers of 1/x with the coefficients)."""
    x_min = float(np.min(x))
    table = np.zeros_like(_ASYMPTOTIC)  # zero beyond each sum's last term
    with np.errstate(over="ignore"):  # a huge x_min: its powers are inf, its terms 0
        powers = x_min ** np.arange(60.0)
    n_max = 1
    for i in range(2):
        terms = _ASYMPTOTIC_ABS[i] / powers
        stop = (terms[1:] >= terms[:-1]) | (terms[:-1] < 1e-17)  # term k is not added
        n = 1 + (int(np.argmax(stop)) if stop.any() else 59)
        table[i, :n] = _ASYMPTOTIC[i, :n]
        n_max = max(n_max, n)
    total = _powers(1.0 / x, n_max) @ table[:, :n_max].T
    return 1j * total[:, 1] / total[:, 0]


def theodorsen_function(k: np.ndarray | float) -> np.ndarray | complex:
    """Theodorsen's function C(k) = H1(2)(k) / (H1(2)(k) + i H0(2)(k)).

    The Hankel functions are evaluated here with numpy (power series below
    :data:`SERIES_LIMIT`, asymptotic expansion above), without ``scipy.special``.

    Parameters
    ----------
    k : array_like
        Reduced frequency omega b / U [-], k >= 0. C(0) = 1.

    Returns
    -------
    complex or ndarray of complex
        C(k) = F(k) + i G(k).
    """
    k_arr = np.asarray(k, dtype=float)
    if not np.all((k_arr >= 0) & (k_arr < np.inf)):  # NaN fails both
        raise ValueError(f"k = {k!r}: reduced frequency must be finite and >= 0")
    out = np.ones(k_arr.shape, dtype=complex)
    for sel, ratio in (
        ((k_arr > 0) & (k_arr < SERIES_LIMIT), _hankel_ratio_series),
        (k_arr >= SERIES_LIMIT, _hankel_ratio_asymptotic),
    ):
        if np.any(sel):
            r = ratio(k_arr[sel])
            out[sel] = r / (r + 1j)
    return out if out.ndim else complex(out)


def _real_or_complex(x) -> np.ndarray:
    """``x`` as a float array, or a complex one when given complex (complex-step derivatives
    of the coefficients, :mod:`aeroservo.system.derivatives`)."""
    x = np.asarray(x)
    return x.astype(complex if np.iscomplexobj(x) else float)


def t_functions(c: np.ndarray | float, a: np.ndarray | float) -> dict[str, np.ndarray]:
    """Theodorsen's flap geometry functions T1..T14.

    Parameters
    ----------
    c : array_like
        Hinge position in semichords aft of mid-chord [-], -1 <= c <= 1. c = 1 is a
        zero-chord flap, for which every T vanishes except T14. Complex values (a complex
        step) are evaluated without clipping.
    a : array_like
        Elastic-axis position in semichords aft of mid-chord [-].

    Returns
    -------
    dict
        Keys ``"T1"`` .. ``"T14"``, arrays broadcast from ``c`` and ``a``.
    """
    c, a = np.broadcast_arrays(_real_or_complex(c), _real_or_complex(a))
    if np.iscomplexobj(c):  # a complex step (derivatives): -1 < Re c < 1 where it moves
        th, s = np.arccos(c), np.sqrt(1.0 - c**2)
    else:
        th = np.arccos(np.clip(c, -1.0, 1.0))
        s = np.sqrt(np.clip(1.0 - c**2, 0.0, None))
    t = {}
    t["T1"] = -s * (2.0 + c**2) / 3.0 + c * th
    t["T2"] = c * (1.0 - c**2) - s * (1.0 + c**2) * th + c * th**2
    t["T3"] = (
        -(1.0 / 8.0 + c**2) * th**2
        + 0.25 * c * s * th * (7.0 + 2.0 * c**2)
        - (1.0 / 8.0) * (1.0 - c**2) * (5.0 * c**2 + 4.0)
    )
    t["T4"] = -th + c * s
    t["T5"] = -(1.0 - c**2) - th**2 + 2.0 * c * s * th
    t["T6"] = t["T2"]
    t["T7"] = -(1.0 / 8.0 + c**2) * th + (1.0 / 8.0) * c * s * (7.0 + 2.0 * c**2)
    t["T8"] = -s * (2.0 * c**2 + 1.0) / 3.0 + c * th
    t["T9"] = 0.5 * (s**3 / 3.0 + a * t["T4"])
    t["T10"] = s + th
    t["T11"] = th * (1.0 - 2.0 * c) + s * (2.0 - c)
    t["T12"] = s * (2.0 + c) - th * (2.0 * c + 1.0)
    t["T13"] = 0.5 * (-t["T7"] - (c - a) * t["T1"])
    t["T14"] = 1.0 / 16.0 + 0.5 * a * c
    return t


@dataclass(frozen=True)
class SectionAero:
    """Per-unit-density section coefficients for unknowns ``[w, phi, delta]``.

    Leading dimensions are those of the inputs (e.g. one entry per quadrature point).

    Attributes
    ----------
    Mnc : ndarray (..., 3, 3)
        Apparent mass [m^2, m^3, m^4 entries], multiplies rho * qdd on the left-hand side.
    Cnc : ndarray (..., 3, 3)
        Non-circulatory damping, multiplies rho * U * qd.
    Knc : ndarray (..., 3, 3)
        Non-circulatory stiffness, multiplies rho * U^2 * q.
    w : ndarray (..., 3)
        Distribution of the circulatory load: f_circ = rho U b w (C Q).
    r_q, r_d : ndarray (..., 3)
        Downwash weights: Q = U r_q.q + r_d.qd.
    b : ndarray (...)
        Semichord [m].
    """

    Mnc: np.ndarray
    Cnc: np.ndarray
    Knc: np.ndarray
    w: np.ndarray
    r_q: np.ndarray
    r_d: np.ndarray
    b: np.ndarray

    @property
    def Pq(self) -> np.ndarray:
        """Circulatory stiffness per unit C(k): ``b w r_q^T`` (multiplies rho U^2 C)."""
        return self.b[..., None, None] * self.w[..., :, None] * self.r_q[..., None, :]

    @property
    def Pd(self) -> np.ndarray:
        """Circulatory damping per unit C(k): ``b w r_d^T`` (multiplies rho U C)."""
        return self.b[..., None, None] * self.w[..., :, None] * self.r_d[..., None, :]


def section_aero(
    b: np.ndarray | float, a: np.ndarray | float, c: np.ndarray | float
) -> SectionAero:
    """Theodorsen section coefficients, flap terms included.

    Parameters
    ----------
    b : array_like
        Semichord [m].
    a : array_like
        Elastic axis, semichords aft of mid-chord [-].
    c : array_like
        Hinge line, semichords aft of mid-chord [-]; use c = 1 where there is no flap
        (all flap terms then vanish).

    Returns
    -------
    SectionAero
    """
    b, a, c = np.broadcast_arrays(_real_or_complex(b), _real_or_complex(a), _real_or_complex(c))
    T = t_functions(c, a)
    pi = np.pi
    z = np.zeros_like(b)
    b2 = b**2

    def mat(rows):
        return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)

    Mnc = b2[..., None, None] * mat(
        [
            [pi + z, pi * b * a, b * T["T1"]],
            [pi * a * b, pi * b2 * (1.0 / 8.0 + a**2), -(T["T7"] + (c - a) * T["T1"]) * b2],
            [T["T1"] * b, 2.0 * T["T13"] * b2, -(b2 / pi) * T["T3"]],
        ]
    )
    Cnc = b2[..., None, None] * mat(
        [
            [z, -pi + z, T["T4"]],
            [z, pi * (0.5 - a) * b, (T["T1"] - T["T8"] - (c - a) * T["T4"] + 0.5 * T["T11"]) * b],
            [
                z,
                (-2.0 * T["T9"] - T["T1"] + T["T4"] * (a - 0.5)) * b,
                -(b / (2 * pi)) * T["T4"] * T["T11"],
            ],
        ]
    )
    Knc = b2[..., None, None] * mat(
        [
            [z, z, z],
            [z, z, T["T4"] + T["T10"]],
            [z, z, (T["T5"] - T["T4"] * T["T10"]) / pi],
        ]
    )
    w = np.stack([2 * pi + z, 2 * pi * b * (a + 0.5), -b * T["T12"]], axis=-1)
    r_q = np.stack([z, 1.0 + z, T["T10"] / pi], axis=-1)
    r_d = np.stack([-1.0 + z, b * (0.5 - a), b * T["T11"] / (2 * pi)], axis=-1)
    return SectionAero(Mnc=Mnc, Cnc=Cnc, Knc=Knc, w=w, r_q=r_q, r_d=r_d, b=b)
