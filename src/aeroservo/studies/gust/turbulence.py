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
closed form; the cross terms ``Re(H_i conj H_j)`` give the covariance of the loads (turbulence
ellipses of correlated loads). An output with a direct feedthrough from the gust (``D != 0``)
has an infinite ``N0`` for any spectrum decaying like ``omega^-p`` with ``p <= 3`` (von
Karman: 5/3): it is returned as ``inf``. ``N0`` of accelerations and root loads counts every
structural mode of the model up to the highest finite-element frequency: the strip model's high
modes are not physical, so it depends on the mesh.

With a sampled linear controller ``H`` is the response at the sample instants of the loop the
simulator marches, ``H_s`` (:mod:`.turbulence_loop`): ``A_bar^2`` is the exact variance of the
sampled outputs, ``N0`` the zero-crossing rate of a stationary process with their spectrum.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, check_number
from .turbulence_loop import (
    ModalResponse,
    SampledResponse,
    adaptive,
    alias_start,
    breakpoints,
    columns,
    diagonal,
    loop_moments,
    markov_tail,
    outer,
    pack,
    unpack,
)

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
    """RMS per unit gust RMS, zero-crossing rates and covariances of outputs.

    ``a_bar[name]`` [output unit per m/s], ``n0[name]`` [1/s] (``inf`` with a gust
    feedthrough), ``units[name]``, ``speed`` [m/s], ``spectrum`` name, ``omega_hi`` [rad/s]
    the start of the analytic tail and ``tail_fraction[name]`` the share of ``A_bar^2`` it
    carries; ``covariance`` (n, n) per unit gust variance in the order of ``outputs`` (its
    diagonal is ``A_bar^2``); ``controller`` the loop's label (``"open loop"``) and
    ``sample_rate`` [Hz] (None in open loop: the continuous response).
    """

    a_bar: dict[str, float]
    n0: dict[str, float]
    units: dict[str, str]
    speed: float
    spectrum: str
    omega_hi: float
    tail_fraction: dict[str, float] = field(default_factory=dict)
    covariance: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    outputs: tuple = ()
    controller: str = "open loop"
    sample_rate: float | None = None

    def design_loads(self, u_sigma_value: float) -> dict[str, float]:
        """``U_sigma A_bar`` per output [output unit], ``u_sigma_value`` [m/s TAS]."""
        check_number("u_sigma", u_sigma_value, unit="m/s", lo=0.0)
        return {k: u_sigma_value * v for k, v in self.a_bar.items()}

    def correlation(self, a: str, b: str) -> float:
        """Correlation coefficient of outputs ``a`` and ``b`` (in [-1, 1]; the turbulence
        ellipse of two loads is ``(x/A_a)^2 - 2 rho x y/(A_a A_b) + (y/A_b)^2 = 1 - rho^2``)."""
        idx = []
        for n in (a, b):
            if n not in self.outputs:
                raise InputError(f"output {n!r}: not in the result ({list(self.outputs)})")
            idx.append(self.outputs.index(n))
        i, j = idx
        c = self.covariance
        den = math.sqrt(c[i, i] * c[j, j])
        return float(np.clip(c[i, j] / den, -1.0, 1.0)) if den > 0 else 0.0


def _open_moments(
    resp: ModalResponse, spec: Spectrum, v: float, scale: float, w_hi: float, rtol: float
) -> tuple[np.ndarray, np.ndarray]:
    """Covariance and second-moment columns of the continuous response, and of their tail."""
    ny = resp.ct.shape[0]
    p = spec.tail_exponent
    tail = pack(*markov_tail(resp.markov(5), ny, spec.tail_coefficient * v ** (p - 1), p, w_hi))

    def f(w):
        return columns(outer(resp(w)), w, spec.time_psd(w, v))

    pts = breakpoints(resp.lam, v, scale, w_hi)
    done = adaptive(f, pts, rtol, diagonal(ny), np.where(np.isfinite(tail), tail, 0.0))
    return done + tail, tail


def _sampled_loop(sys, controller, delay: bool, sample_rate, rows: list, iw: int, v: float):
    """``(SampledResponse, closed-loop eigenvalues, label, rate)``, or None for an open loop."""
    from ...design.closed_loop import linear_controller
    from ...design.interface import controller_at
    from ...design.law import delayed
    from ...design.plant import SampledPlant
    from ...design.sampled_loop import LoopBlocks, linear_law, plant_states

    if not isinstance(delay, (bool, np.bool_)):
        raise InputError(f"delay = {delay!r}: expected True or False")
    ctrl = linear_controller(controller, "turbulence_response", sample_rate)
    ctrl = controller_at(ctrl, float(getattr(sys, "speed", v)))
    law = linear_law(ctrl, plant_states(sys))
    if law.kind == "open":
        return None
    law = delayed(law) if delay else law
    label = (law.source or type(ctrl).__name__) + (", one-sample delay" if delay else "")
    arrays = tuple(np.asarray(x, dtype=float) for x in (sys.A, sys.B, sys.C, sys.D))
    labels = (list(sys.input_labels), list(sys.output_labels))
    sp = SampledPlant.from_arrays(arrays, labels, law.dt, law.controls, (), law.sensors)
    zeta = np.linalg.eigvals(LoopBlocks(sp, law).closed())
    radius = float(np.max(np.abs(zeta)))
    if radius >= 1.0:
        raise InputError(
            f"speed = {v:g} m/s: the sampled loop with {label} is unstable (spectral radius "
            f"{radius:.6g} >= 1); turbulence RMS is defined for stable loops only"
        )
    iu = [labels[0].index(c) for c in law.controls]
    srows = None if law.state_feedback else [labels[1].index(s) for s in law.sensors]
    resp = SampledResponse(*arrays, iu, iw, rows, srows, law, sp.Phi, sp.Gu)
    return resp, zeta, label, 1.0 / law.dt


def turbulence_response(
    sys,
    outputs: Sequence[str] | None = None,
    *,
    spectrum: Spectrum | None = None,
    speed: float | None = None,
    gust_input: str = "gust",
    rtol: float = 1e-9,
    omega_hi: float | None = None,
    controller=None,
    delay: bool = False,
    sample_rate: float | None = None,
) -> TurbulenceResult:
    """A_bar, N0 and covariances of outputs of a linear model under continuous turbulence.

    Open loop, the continuous response ``H(j omega)``; with a linear ``controller``, the
    stationary response at the sample instants of the loop :func:`aeroservo.simulate.simulate`
    marches (zero-order hold on the commands, the plant exact between samples, limits
    inactive), ``H_s(omega)`` of :mod:`.turbulence_loop`: ``A_bar^2 = int |H_s|^2 Phi_t`` is
    then the exact variance of the sampled outputs (the integral over every omega folds the
    aliases) and ``N0 = (1/2pi) sqrt(int omega^2 |H_s|^2 Phi_t / A_bar^2)`` the zero-crossing
    rate of the stationary process with the spectrum of the sampled response.

    Parameters
    ----------
    sys : control.StateSpace
        Model from :func:`aeroservo.statespace` with a gust input [m/s] (and the controller's
        controls and sensors); stable, or stable in closed loop with a controller.
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
        radius of A and V / L (in closed loop at least 100 x the start ``omega_a`` of the
        period averages). Must exceed 10 x the spectral radius (Markov series) and, in closed
        loop, 2 ``omega_a``.
    controller : optional
        Anything :func:`aeroservo.design.as_controller` accepts with a linear law (a gain
        schedule is evaluated at ``sys.speed``; an MPC gives its law without active
        constraints); :class:`aeroservo.design.OpenLoop` is the open loop.
    delay : bool
        One-sample computational delay.
    sample_rate : float, optional
        [Hz], to discretise a continuous python-control compensator.

    Returns
    -------
    TurbulenceResult

    Raises
    ------
    InputError
        Unknown names, an unstable model (open loop) or loop (spectral radius >= 1), a
        controller without a linear law.
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
    iw = inputs.index(gust_input)
    rows = [names.index(n) for n in outputs]
    loop = None
    if controller is not None:
        loop = _sampled_loop(sys, controller, delay, sample_rate, rows, iw, v)
    a = np.asarray(sys.A, dtype=float)
    scale = float(spec.psd(np.array([0.0]))[0]) * math.pi  # L from Phi(0) = L / pi
    if loop is None:
        resp = ModalResponse(
            a,
            np.asarray(sys.B, dtype=float)[:, iw],
            np.asarray(sys.C, dtype=float)[rows],
            np.asarray(sys.D, dtype=float)[rows, iw],
        )
        if np.max(resp.lam.real) >= 0:
            raise InputError(
                f"speed = {v:g} m/s: the model is unstable (max Re(eig) = "
                f"{np.max(resp.lam.real):.3g} 1/s); turbulence RMS is defined for stable "
                "models only (or give the controller that stabilises it)"
            )
        lam = resp.lam
    else:
        lam = loop[0].ol.lam
    rho = float(np.max(np.abs(lam)))
    lo = 10.0 * max(rho, v / scale)
    w_hi = 1000.0 * max(rho, v / scale)
    if loop is not None:
        w_a = alias_start(rho, loop[0].dt)
        lo, w_hi = max(lo, 2.0 * w_a), max(w_hi, 100.0 * w_a)
    if omega_hi is not None:
        w_hi = check_number("omega_hi", omega_hi, unit="rad/s", lo=lo)
    if loop is None:
        total, tail = _open_moments(resp, spec, v, scale, w_hi, rtol)
    else:
        total, tail = loop_moments(loop[0], loop[1], spec, v, scale, w_a, w_hi, rtol)
    cov, second = unpack(total, len(rows))
    var = np.diag(cov)
    a_bar = np.sqrt(var)
    n0 = np.sqrt(second / var) / (2 * math.pi)
    tail_var = np.diag(unpack(tail, len(rows))[0])
    units = getattr(sys, "signal_units", {}) or {}
    return TurbulenceResult(
        a_bar={n: float(x) for n, x in zip(outputs, a_bar, strict=True)},
        n0={n: float(x) for n, x in zip(outputs, n0, strict=True)},
        units={n: f"{units.get(n, '?')} per m/s" for n in outputs},
        speed=v,
        spectrum=spec.name,
        omega_hi=w_hi,
        tail_fraction={n: float(t / x) for n, t, x in zip(outputs, tail_var, var, strict=True)},
        covariance=cov,
        outputs=tuple(outputs),
        controller="open loop" if loop is None else loop[2],
        sample_rate=None if loop is None else loop[3],
    )
