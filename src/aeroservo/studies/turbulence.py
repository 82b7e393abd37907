"""Continuous turbulence loads (CS-25.341(b) / 14 CFR 25.341(b)) on an exported state space.

The vertical gust is a stationary random process with the one-sided von Karman spectrum
(L = 762 m, Omega in rad/m)::

    Phi(Omega) = sigma^2 (L/pi) [1 + (8/3)(1.339 L Omega)^2] / [1 + (1.339 L Omega)^2]^(11/6)

seen at true airspeed V as ``Phi_t(omega) = Phi(omega / V) / V`` (omega in rad/s). For each
output y of a stable linear model with gust input, ``H(j omega)`` its frequency response:

* ``A_bar^2 = int_0^inf |H|^2 Phi_t d omega / sigma^2`` (RMS of y per unit gust RMS),
* ``N0 = (1/2pi) sqrt(int omega^2 |H|^2 Phi_t / int |H|^2 Phi_t)`` [1/s], the rate of
  zero crossings with positive slope;
* the design load increment is ``U_sigma A_bar``, with ``U_sigma`` from the rule's table.

The integrals are computed by adaptive Gauss-Legendre quadrature in ``ln omega`` on panels whose
ends include the damped frequencies of the poles +- multiples of their decay rates (so each
resonance peak is resolved), from 0 to ``omega_hi = 1000 x`` the spectral radius of A; beyond
it the spectrum is its power-law asymptote ``c omega^-p`` and ``|H|^2`` its expansion in the
Markov parameters ``C A^k B`` (``|H|^2 = D^2 + (m0^2 - 2 D m1)/omega^2 + ...``), integrated in
closed form. An output with a direct feedthrough from the gust (``D != 0``) has an infinite
``N0`` for any spectrum decaying like ``omega^-p`` with ``p <= 3`` (von Karman: 5/3): it is
returned as ``inf``. ``N0`` of accelerations and root loads counts every structural mode of the
model up to the highest finite-element frequency: the strip model's high modes are not physical,
so it depends on the mesh.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, check_number

__all__ = [
    "Spectrum",
    "von_karman",
    "dryden",
    "u_sigma",
    "TurbulenceResult",
    "turbulence_response",
    "FT",
    "L_TURBULENCE",
]

FT = 0.3048
"""One foot [m]."""

L_TURBULENCE = 762.0
"""Scale of turbulence of CS-25.341(b): 2500 ft [m]."""

DEFAULT_LOADS = (
    "root_shear",
    "root_bending_moment",
    "root_torque",
    "tip_le_accel",
    "tip_te_accel",
)


@dataclass(frozen=True)
class Spectrum:
    """A one-sided gust spectrum per unit variance, in spatial frequency.

    Parameters
    ----------
    name : str
        Label.
    psd : callable
        ``psd(Omega)`` [m^2/s^2 per rad/m per (m/s)^2], Omega [rad/m] an array; integrates to 1
        over ``[0, inf)``.
    tail_coefficient, tail_exponent : float
        Asymptote ``psd(Omega) ~ c Omega^-p`` for large Omega (``p > 1``).
    """

    name: str
    psd: Callable[[np.ndarray], np.ndarray]
    tail_coefficient: float
    tail_exponent: float

    def time_psd(self, omega: np.ndarray, speed: float) -> np.ndarray:
        """``Phi_t(omega) = Phi(omega / V) / V`` [per rad/s], omega [rad/s], V [m/s]."""
        return self.psd(np.asarray(omega) / speed) / speed


def von_karman(scale: float = L_TURBULENCE) -> Spectrum:
    """The von Karman vertical-gust spectrum of CS-25.341(b) (unit variance), scale [m]."""
    scale = check_number("turbulence scale", scale, unit="m", lo=0.0, lo_open=True)

    def psd(om):
        a2 = (1.339 * scale * np.asarray(om, dtype=float)) ** 2
        return (scale / math.pi) * (1.0 + (8.0 / 3.0) * a2) / (1.0 + a2) ** (11.0 / 6.0)

    c = (scale / math.pi) * (8.0 / 3.0) * (1.339 * scale) ** (-5.0 / 3.0)
    return Spectrum(f"von Karman L={scale:g} m", psd, c, 5.0 / 3.0)


def dryden(scale: float = L_TURBULENCE) -> Spectrum:
    """The Dryden vertical-gust spectrum (unit variance), scale [m]: rational, so a shaping
    filter ``(1 + sqrt(3) tau s) / (1 + tau s)^2``, ``tau = L / V``, reproduces it exactly."""
    scale = check_number("turbulence scale", scale, unit="m", lo=0.0, lo_open=True)

    def psd(om):
        a2 = (scale * np.asarray(om, dtype=float)) ** 2
        return (scale / math.pi) * (1.0 + 3.0 * a2) / (1.0 + a2) ** 2

    return Spectrum(f"Dryden L={scale:g} m", psd, 3.0 / (math.pi * scale), 2.0)


def u_sigma(altitude: float, f_g: float = 1.0, *, at_vd: bool = False) -> float:
    """Design gust RMS ``U_sigma`` of CS-25.341(b)(3) [m/s TAS].

    ``U_sigma,ref`` is 90 ft/s at sea level, falling linearly to 79 ft/s at 24 000 ft and
    constant above; times the flight profile alleviation factor ``f_g`` (in (0, 1]); one half
    at V_D (``at_vd``). ``altitude`` [m].
    """
    h = check_number("altitude", altitude, unit="m", lo=0.0) / FT
    check_number("f_g", f_g, lo=0.0, hi=1.0, lo_open=True)
    ref = 90.0 - 11.0 * min(h, 24000.0) / 24000.0
    return ref * FT * f_g * (0.5 if at_vd else 1.0)


@dataclass
class TurbulenceResult:
    """RMS per unit gust RMS and zero-crossing rates of each output.

    ``a_bar[name]`` [output unit per m/s], ``n0[name]`` [1/s] (``inf`` with a gust
    feedthrough), ``units[name]``, ``speed`` [m/s], ``spectrum`` name, ``omega_hi`` [rad/s]
    the start of the analytic tail and ``tail_fraction[name]`` the share of ``A_bar^2`` it
    carries.
    """

    a_bar: dict[str, float]
    n0: dict[str, float]
    units: dict[str, str]
    speed: float
    spectrum: str
    omega_hi: float
    tail_fraction: dict[str, float] = field(default_factory=dict)

    def design_loads(self, u_sigma_value: float) -> dict[str, float]:
        """``U_sigma A_bar`` per output [output unit], ``u_sigma_value`` [m/s TAS]."""
        check_number("u_sigma", u_sigma_value, unit="m/s", lo=0.0)
        return {k: u_sigma_value * v for k, v in self.a_bar.items()}


# -- frequency response ------------------------------------------------------------------------


class _Response:
    """``H(j omega)`` of selected outputs to one input, by the eigendecomposition of A (checked
    against a direct solve; a direct solve per frequency when the check fails)."""

    def __init__(self, a, b, c, d):
        self.a, self.b, self.c, self.d = a, b, c, d
        self.lam, vecs = np.linalg.eig(a)
        self.bt = np.linalg.solve(vecs, b)
        self.ct = c @ vecs
        probe = np.unique(np.abs(self.lam.imag[self.lam.imag > 0]))[:20]
        probe = np.concatenate([probe, [1.0, float(np.max(np.abs(self.lam)))]])
        ref = np.array([self._direct(w) for w in probe])
        got = self._modal(probe)
        scale = np.max(np.abs(ref), axis=0) + 1e-300
        self.modal_ok = bool(np.all(np.abs(got - ref) <= 1e-8 * scale))

    def _direct(self, w: float) -> np.ndarray:
        n = self.a.shape[0]
        return self.c @ np.linalg.solve(1j * w * np.eye(n) - self.a, self.b) + self.d

    def _modal(self, w: np.ndarray) -> np.ndarray:
        r = self.bt[None, :] / (1j * w[:, None] - self.lam[None, :])
        return r @ self.ct.T + self.d[None, :]

    def __call__(self, w: np.ndarray) -> np.ndarray:
        if self.modal_ok:
            return self._modal(w)
        return np.array([self._direct(x) for x in w]).reshape(w.size, -1)


_GL_X, _GL_W = np.polynomial.legendre.leggauss(12)


def _panel_integrals(resp, psd, lo: np.ndarray, hi: np.ndarray, log: np.ndarray):
    """Gauss-Legendre integrals of ``|H|^2 Phi_t`` and ``omega^2 |H|^2 Phi_t`` on panels.

    Returns two arrays (panels, outputs). ``log`` panels integrate in ``ln omega``.
    """
    a = np.where(log, np.log(np.where(log, lo, 1.0)), lo)
    b = np.where(log, np.log(np.where(log, hi, 1.0)), hi)
    mid, half = (a + b) / 2, (b - a) / 2
    u = mid[:, None] + half[:, None] * _GL_X[None, :]
    w = np.where(log[:, None], np.exp(u), u)
    jac = half[:, None] * _GL_W[None, :] * np.where(log[:, None], w, 1.0)
    flat = w.ravel()
    h2 = np.abs(resp(flat)) ** 2  # (m, outputs)
    f = h2 * psd(flat)[:, None]
    f = f.reshape(w.shape + (h2.shape[1],)) * jac[..., None]
    m0 = f.sum(axis=1)
    m2 = (f * (w**2)[..., None]).sum(axis=1)
    return m0, m2


def _breakpoints(lam: np.ndarray, speed: float, scale: float, w_hi: float) -> np.ndarray:
    w_lo = 1e-4 * min(speed / (1.339 * scale), np.min(np.abs(lam)))
    decades = math.log10(w_hi / w_lo)
    pts = [np.logspace(math.log10(w_lo), math.log10(w_hi), int(8 * decades) + 1)]
    osc = lam[lam.imag > 0]
    k = np.array([-16, -8, -4, -2, -1, -0.5, 0, 0.5, 1, 2, 4, 8, 16])
    for z in osc:
        pts.append(z.imag + k * abs(z.real))
    p = np.concatenate(pts)
    p = np.unique(np.concatenate([p[(p > w_lo) & (p < w_hi)], [w_lo, w_hi]]))
    return np.concatenate([[0.0], p])  # ends exactly at w_hi, where the closed-form tail starts


def _tail(resp: _Response, spec: Spectrum, speed: float, w_hi: float):
    """Closed-form integrals beyond ``w_hi``: Markov expansion of |H|^2 times ``K w^-p``."""
    a, b, c, d = resp.a, resp.b, resp.c, resp.d
    m, v = [], b.copy()
    for _ in range(4):
        m.append(c @ v)
        v = a @ v
    m0, m1, m2, m3 = m
    coef = [d**2, m0**2 - 2 * d * m1, m1**2 + 2 * d * m3 - 2 * m0 * m2]  # of w^0, w^-2, w^-4
    p = spec.tail_exponent
    k_t = spec.tail_coefficient * speed ** (p - 1.0)  # Phi_t ~ k_t w^-p
    t0 = np.zeros_like(d, dtype=float)
    t2 = np.zeros_like(d, dtype=float)
    for j, cj in enumerate(coef):
        e0 = p + 2 * j - 1.0  # int_w_hi^inf w^-(p+2j) = w_hi^-e0 / e0
        t0 = t0 + cj * k_t * w_hi ** (-e0) / e0
        e2 = p + 2 * j - 3.0
        if e2 > 0:
            t2 = t2 + cj * k_t * w_hi ** (-e2) / e2
        else:
            t2 = np.where(np.abs(cj) > 0, np.inf, t2)
    return t0, t2


def turbulence_response(
    sys,
    outputs: Sequence[str] | None = None,
    *,
    spectrum: Spectrum | None = None,
    speed: float | None = None,
    gust_input: str = "gust",
    rtol: float = 1e-9,
    omega_hi: float | None = None,
) -> TurbulenceResult:
    """A_bar and N0 of outputs of a linear model under continuous turbulence.

    Parameters
    ----------
    sys : control.StateSpace
        Stable model from :func:`aeroservo.statespace` with a gust input [m/s].
    outputs : list of str, optional
        Output names (default: root shear, bending moment, torque and the tip accelerations
        present in ``sys``).
    spectrum : Spectrum, optional
        Default: :func:`von_karman` with L = 762 m.
    speed : float, optional
        True airspeed [m/s]; default ``sys.speed``.
    gust_input : str
        Name of the gust input.
    rtol : float
        Relative accuracy asked of each integral.
    omega_hi : float, optional
        Start of the closed-form tail [rad/s]; default 1000 x the larger of the spectral
        radius of A and V / L. Must exceed 10 x the spectral radius (Markov series).

    Returns
    -------
    TurbulenceResult
    """
    spec = spectrum if spectrum is not None else von_karman()
    v = speed if speed is not None else getattr(sys, "speed", None)
    v = check_number("speed", v, unit="m/s", lo=0.0, lo_open=True)
    check_number("rtol", rtol, lo=1e-14, hi=1e-2)
    inputs = list(sys.input_labels)
    if gust_input not in inputs:
        raise InputError(f"gust_input = {gust_input!r}: not an input of the model ({inputs})")
    names = list(sys.output_labels)
    if outputs is None:
        outputs = [n for n in DEFAULT_LOADS if n in names]
    for n in outputs:
        if n not in names:
            raise InputError(f"output {n!r}: not an output of the model ({names})")
    if not outputs:
        raise InputError("outputs: the model has none of the default loads; name them")
    iu = inputs.index(gust_input)
    rows = [names.index(n) for n in outputs]
    a = np.asarray(sys.A, dtype=float)
    resp = _Response(
        a,
        np.asarray(sys.B, dtype=float)[:, iu],
        np.asarray(sys.C, dtype=float)[rows],
        np.asarray(sys.D, dtype=float)[rows, iu],
    )
    if np.max(resp.lam.real) >= 0:
        raise InputError(
            f"speed = {v:g} m/s: the model is unstable (max Re(eig) = "
            f"{np.max(resp.lam.real):.3g} 1/s); turbulence RMS is defined for stable models only"
        )
    scale = float(spec.psd(np.array([0.0]))[0]) * math.pi  # L from Phi(0) = L / pi
    rho = float(np.max(np.abs(resp.lam)))
    w_hi = 1000.0 * max(rho, v / scale)
    if omega_hi is not None:
        w_hi = check_number("omega_hi", omega_hi, unit="rad/s", lo=10.0 * max(rho, v / scale))

    def psd(w):
        return spec.time_psd(w, v)

    pts = _breakpoints(resp.lam, v, scale, w_hi)
    lo, hi = pts[:-1], pts[1:]
    tail0, tail2 = _tail(resp, spec, v, w_hi)
    done0 = np.zeros(len(rows))
    done2 = np.zeros(len(rows))
    for _ in range(40):
        log = lo > 0
        c0, c2 = _panel_integrals(resp, psd, lo, hi, log)
        mid = np.where(log, np.sqrt(lo * np.where(log, hi, 1.0)), (lo + hi) / 2)
        l0, l2 = _panel_integrals(resp, psd, lo, mid, log)
        r0, r2 = _panel_integrals(resp, psd, mid, hi, log)
        f0, f2 = l0 + r0, l2 + r2
        tot0 = done0 + f0.sum(axis=0) + tail0
        tot2 = done2 + f2.sum(axis=0) + np.where(np.isfinite(tail2), tail2, 0.0)
        err = np.maximum(
            np.max(np.abs(f0 - c0) / tot0, axis=1), np.max(np.abs(f2 - c2) / tot2, axis=1)
        )
        bad = err > 0.1 * rtol
        done0 += f0[~bad].sum(axis=0)
        done2 += f2[~bad].sum(axis=0)
        if not bad.any():
            break
        lo = np.concatenate([lo[bad], mid[bad]])
        hi = np.concatenate([mid[bad], hi[bad]])
    else:
        raise RuntimeError("turbulence quadrature did not converge in 40 refinements")
    var = done0 + tail0
    second = done2 + tail2
    a_bar = np.sqrt(var)
    n0 = np.sqrt(second / var) / (2 * math.pi)
    units = getattr(sys, "signal_units", {}) or {}
    return TurbulenceResult(
        a_bar={n: float(x) for n, x in zip(outputs, a_bar, strict=True)},
        n0={n: float(x) for n, x in zip(outputs, n0, strict=True)},
        units={n: f"{units.get(n, '?')} per m/s" for n in outputs},
        speed=v,
        spectrum=spec.name,
        omega_hi=w_hi,
        tail_fraction={n: float(t / x) for n, t, x in zip(outputs, tail0, var, strict=True)},
    )
