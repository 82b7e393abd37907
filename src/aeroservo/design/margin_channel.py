"""The margins of one loop broken at one point: gain, phase and disk margins of a SISO return
ratio of the sampled loop, and the Nyquist count that certifies them.

With ``L(z)`` the return ratio at the break point (the loop closes as ``1 + L``), on the unit
circle ``z = exp(j w dt)`` from 0 to the Nyquist frequency:

* **Nyquist criterion.** With ``P`` poles of the broken loop outside the unit circle (the
  flutter modes above the open-loop flutter speed), the closed loop is stable iff ``1 + L``
  winds ``P`` times counterclockwise around the origin over the whole circle. The winding is
  counted on a frequency grid refined until the phase of ``1 + L`` moves by less than 0.2 rad
  between neighbours, and compared with the eigenvalues of the loop matrix.
* **Gain margins.** ``k L`` has a closed-loop pole on the unit circle where ``L`` is real and
  negative, at ``k = -1 / L``; the stable interval of gains around ``k = 1`` is bounded by the
  nearest such gains. An open-loop-unstable loop has a *gain-reduction* margin (< 0 dB) as well
  as the usual increase margin.
* **Phase margin.** Where ``|L| = 1``, the phase change ``exp(j phi)`` that puts a pole on the
  circle; the margin is the smallest ``|phi|``.
* **Disk margin** (balanced, Seiler, Packard and Gahinet 2020): ``alpha = 1 / max |S - 1/2|``
  with ``S = 1 / (1 + L)``; the loop tolerates simultaneous gain changes within
  ``[(2 - alpha) / (2 + alpha), (2 + alpha) / (2 - alpha)]`` and phase changes within
  ``+-2 atan(alpha / 2)``.

(python-control's ``stability_margins`` overflows on loops of this order; this module uses the
frequency response on a grid, roots refined by Brent's method.) Requirements default to
MIL-F-9490D: 6 dB gain margin both ways and 45 deg phase margin.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.optimize as so

from .margin_requirement import BREAK_POINT_KEYS, MarginRequirement

__all__ = [
    "MarginRequirement",
    "ChannelMargins",
    "channel_margins",
    "frequency_response",
    "BREAK_POINT_KEYS",
]

PHASE_STEP = 0.2
"""Largest change [rad] of the phase (and log-magnitude) of ``1 + L`` between grid points."""

MAX_POINTS = 200_000
"""Cap on the refined frequency grid."""


@dataclass
class ChannelMargins:
    """Margins of one loop-at-a-time break point (the other loops closed); frequencies in Hz.

    Attributes
    ----------
    name : str
        The control (a break at the plant input) or the sensor (at the plant output).
    stable : bool
        Closed loop stable (eigenvalues of the loop matrix).
    nyquist_stable : bool
        Stable by the Nyquist criterion (the winding equals ``open_loop_unstable``).
    open_loop_unstable : int
        Poles of the broken loop outside the unit circle.
    encirclements : float
        Counterclockwise encirclements of -1 by ``L`` over the unit circle.
    gain_margin_db, gain_reduction_margin_db : float
        Gain increase (>= 0, inf if none) and reduction (<= 0, -inf if none) margins [dB].
    gain_frequencies : tuple
        Frequencies [Hz] of the two critical gains (None where there is none).
    phase_margin_deg : float
        [deg] (inf if ``|L|`` never crosses 1), at ``phase_frequency`` [Hz].
    disk_margin : float
        Balanced disk margin ``alpha`` (0 if the closed loop is unstable), at
        ``disk_frequency`` [Hz]; ``disk_gain_margin_db`` and ``disk_phase_margin_deg`` are the
        simultaneous gain and phase variations it tolerates.
    delay_margin : float
        [s] the smallest pure time delay that puts a closed-loop pole on the unit circle:
        at each gain crossover (``|L| = 1``, angular frequency w) the lag that takes ``L`` to
        -1, ``((arg L + pi) mod 2 pi) / w``, the least of them (inf without a crossover), at
        ``delay_frequency`` [Hz]; a delay of k samples is ``z^-k``, so the loop with any
        integer number of extra samples below it stays stable.
    dt : float
        The loop's sample period [s].
    omega : ndarray
        Refined grid [rad/s] from 0 to the Nyquist frequency; ``response`` is ``L`` on it.
    """

    name: str
    stable: bool
    nyquist_stable: bool
    open_loop_unstable: int
    encirclements: float
    gain_margin_db: float
    gain_reduction_margin_db: float
    gain_frequencies: tuple
    phase_margin_deg: float
    phase_frequency: float | None
    disk_margin: float
    disk_gain_margin_db: float
    disk_phase_margin_deg: float
    disk_frequency: float | None
    delay_margin: float = np.inf
    delay_frequency: float | None = None
    dt: float = 0.0
    omega: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))
    response: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))

    @property
    def control(self) -> str:
        """The break point's name (kept for the control channels' readers)."""
        return self.name

    def violations(self, req: MarginRequirement) -> list[str]:
        """What this channel misses of ``req`` (empty: it meets it); the disk requirement is
        judged on the simultaneous margin, not here."""
        if not self.stable:
            return [f"{self.name}: closed loop unstable"]
        out = []
        if req.disk_alpha is not None:
            return out + self.delay_violations(req)
        if self.gain_margin_db < req.gain_db:
            out.append(f"{self.name}: gain margin {self.gain_margin_db:.3g} dB < {req.gain_db}")
        if self.gain_reduction_margin_db > -req.gain_db:
            out.append(
                f"{self.name}: gain-reduction margin {self.gain_reduction_margin_db:.3g} dB "
                f"> -{req.gain_db}"
            )
        if self.phase_margin_deg < req.phase_deg:
            out.append(
                f"{self.name}: phase margin {self.phase_margin_deg:.3g} deg < {req.phase_deg}"
            )
        return out + self.delay_violations(req)

    def delay_violations(self, req: MarginRequirement) -> list[str]:
        """The delay requirement, if any."""
        if req.delay_ms is None or not self.stable or self.delay_margin * 1e3 >= req.delay_ms:
            return []
        return [f"{self.name}: delay margin {self.delay_margin * 1e3:.3g} ms < {req.delay_ms:g}"]

    def to_dict(self) -> dict:
        """JSON-ready (dB, deg, Hz, s; infinite margins as null). An unstable closed loop has
        no margins: they are null and ``stable`` is false."""

        def fin(x):
            return None if x is None or not self.stable or not np.isfinite(x) else float(x)

        delay = fin(self.delay_margin)
        return {
            "stable": self.stable,
            "nyquist_stable": self.nyquist_stable,
            "open_loop_unstable_poles": self.open_loop_unstable,
            "encirclements": float(self.encirclements),
            "gain_margin_db": fin(self.gain_margin_db),
            "gain_increase_frequency": fin(self.gain_frequencies[1]),
            "gain_reduction_margin_db": fin(self.gain_reduction_margin_db),
            "gain_reduction_frequency": fin(self.gain_frequencies[0]),
            "phase_margin_deg": fin(self.phase_margin_deg),
            "phase_frequency": fin(self.phase_frequency),
            "delay_margin_s": delay,
            "delay_margin_samples": None if delay is None or not self.dt else delay / self.dt,
            "delay_frequency": fin(self.delay_frequency),
            "disk_margin": fin(self.disk_margin),
            "disk_gain_margin_db": fin(self.disk_gain_margin_db),
            "disk_phase_margin_deg": fin(self.disk_phase_margin_deg),
            "disk_frequency": fin(self.disk_frequency),
        }


def frequency_response(A: np.ndarray, B: np.ndarray, C: np.ndarray):
    """``theta -> L(exp(j theta)) = -C (zI - A)^-1 B``, shape ``(n_theta, p, m)``, by a
    verified eigen-expansion (linear in the grid size) or, for a badly conditioned eigenbasis,
    by direct solves."""
    n = A.shape[0]

    def direct(theta: np.ndarray) -> np.ndarray:
        theta = np.atleast_1d(np.asarray(theta, dtype=float))
        out = np.empty((theta.size, C.shape[0], B.shape[1]), dtype=complex)
        eye = np.eye(n)
        for k, z in enumerate(np.exp(1j * theta)):
            out[k] = -C @ np.linalg.solve(z * eye - A, B)
        return out

    lam, V = np.linalg.eig(A)
    try:
        bv = np.linalg.solve(V, B)
    except np.linalg.LinAlgError:
        return direct
    cv = C @ V
    r = (cv[0] * bv[:, 0]) if cv.shape[0] == 1 and bv.shape[1] == 1 else None

    def modal(theta: np.ndarray) -> np.ndarray:
        z = np.exp(1j * np.atleast_1d(np.asarray(theta, dtype=float)))
        w = 1.0 / (z[:, None] - lam[None, :])
        if r is not None:  # SISO: one product
            return -(w @ r)[:, None, None]
        return -np.einsum("pk,tk,km->tpm", cv, w, bv)

    probe = np.linspace(0.0, np.pi, 9)[1:-1] + 0.01
    ref = direct(probe)
    if np.all(np.abs(modal(probe) - ref) <= 1e-9 * (1.0 + np.abs(ref))):
        return modal
    return direct


def _response(A: np.ndarray, B: np.ndarray, C: np.ndarray):
    """``theta -> L(exp(j theta))`` of a SISO loop (:func:`frequency_response`)."""
    F = frequency_response(A, B, C)
    return lambda theta: F(theta)[:, 0, 0]


def _grid(L, poles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Refined grid on [0, pi] and ``L`` on it: log-spaced, dense near the poles, then bisected
    until the phase and log-magnitude of ``1 + L`` change by less than :data:`PHASE_STEP`."""
    th = [np.pi * np.geomspace(1e-6, 1.0, 1500), [0.0, np.pi]]
    for p in poles:
        ang, d = abs(np.angle(p)), max(abs(1.0 - abs(p)), 1e-7)
        if abs(p) > 0.2:
            th.append(ang + d * np.linspace(-8.0, 8.0, 33))
    theta = np.unique(np.clip(np.concatenate(th), 0.0, np.pi))
    vals = L(theta)
    for _ in range(40):
        f = 1.0 + vals
        step = np.abs(np.angle(f[1:] / f[:-1])) + np.abs(np.log(np.abs(f[1:] / f[:-1])))
        bad = np.flatnonzero((step > PHASE_STEP) & (np.diff(theta) > 1e-13))
        if bad.size == 0 or theta.size > MAX_POINTS:
            break
        mid = 0.5 * (theta[bad] + theta[bad + 1])
        theta = np.concatenate([theta, mid])
        vals = np.concatenate([vals, L(mid)])
        order = np.argsort(theta)
        theta, vals = theta[order], vals[order]
    return theta, vals


def _roots(fun, theta: np.ndarray, values: np.ndarray) -> list[float]:
    """Roots of a real function of theta bracketed by sign changes on the grid (Brent).

    The ends of each bracket are evaluated again by ``fun``: a value that is zero, or whose
    sign differs from the grid's in the last bits (a root on a grid point), ends the search
    there instead of handing Brent's method a bracket without a sign change.
    """
    out = []
    for i in np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0):
        a, b = theta[i], theta[i + 1]
        fa, fb = fun(a), fun(b)
        if fa == 0.0 or fb == 0.0 or np.sign(fa) == np.sign(fb):
            out.append(float(a if abs(fa) <= abs(fb) else b))
        else:
            out.append(so.brentq(fun, a, b, xtol=1e-14))
    return out


def channel_margins(A, B, C, name: str, dt: float) -> ChannelMargins:
    """Margins of the SISO loop ``1 + L``, ``L = -C (zI - A)^-1 B`` (a loop at sample period
    ``dt`` [s], broken at the point ``name``)."""
    L = _response(A, B, C)
    poles = np.linalg.eigvals(A)
    closed = np.linalg.eigvals(A + B @ C)
    stable = bool(np.max(np.abs(closed)) < 1.0)
    n_unstable = int(np.sum(np.abs(poles) > 1.0))
    theta, vals = _grid(L, np.concatenate([poles, closed]))
    f = 1.0 + vals
    winding = float(np.sum(np.angle(f[1:] / f[:-1])) / np.pi)
    nyquist_stable = bool(abs(winding - n_unstable) < 0.25)
    hz = 1.0 / (2 * np.pi * dt)

    # critical gains: L real and negative (endpoints 0 and pi are real by symmetry)
    cand = _roots(lambda t: float(L(np.array([t]))[0].imag), theta, vals.imag)
    ends = [t for t in cand + [0.0, np.pi]]
    real = L(np.array(ends)).real
    ks = [(-1.0 / r, t) for r, t in zip(real, ends, strict=True) if r < 0]
    up = [(k, t) for k, t in ks if k > 1.0]
    down = [(k, t) for k, t in ks if 0.0 < k < 1.0]
    k_up = min(up, default=(np.inf, None))
    k_dn = max(down, default=(0.0, None))
    gm_up = 20 * np.log10(k_up[0]) if np.isfinite(k_up[0]) else np.inf
    gm_dn = 20 * np.log10(k_dn[0]) if k_dn[0] > 0 else -np.inf

    # phase margin: |L| = 1
    lm = np.log(np.maximum(np.abs(vals), 1e-300))
    cross = _roots(lambda t: float(np.log(abs(L(np.array([t]))[0]))), theta, lm)
    pm, pm_t = np.inf, None
    tau, tau_t = np.inf, None
    for t in cross:
        v = L(np.array([t]))[0]
        phi = float(np.degrees(abs(np.angle(-1.0 / v))))
        if phi < pm:
            pm, pm_t = phi, t
        lag = float(np.mod(np.angle(v) + np.pi, 2 * np.pi))  # the lag that takes L to -1
        d = lag / t * dt if t > 0 else (0.0 if lag == 0.0 else np.inf)
        if d < tau:
            tau, tau_t = d, t

    # balanced disk margin
    alpha, disk_t = 0.0, None
    if stable:
        dist = np.abs((1.0 - vals) / (2.0 * f))
        i = int(np.argmax(dist))
        lo, hi = theta[max(i - 1, 0)], theta[min(i + 1, theta.size - 1)]

        def neg(t):
            v = L(np.array([t]))[0]
            return -abs((1.0 - v) / (2.0 * (1.0 + v)))

        peak, disk_t = dist[i], theta[i]
        if hi > lo:
            res = so.minimize_scalar(
                neg, bounds=(lo, hi), method="bounded", options={"xatol": 1e-13}
            )
            if -res.fun > peak:
                peak, disk_t = -res.fun, float(res.x)
        alpha = float(1.0 / peak)
    disk_gm = 20 * np.log10((2 + alpha) / (2 - alpha)) if alpha < 2 else np.inf
    disk_pm = float(np.degrees(2 * np.arctan(alpha / 2))) if alpha > 0 else 0.0

    def freq(t):
        return None if t is None else float(t * hz)

    return ChannelMargins(
        name=name,
        stable=stable,
        nyquist_stable=nyquist_stable,
        open_loop_unstable=n_unstable,
        encirclements=winding,
        gain_margin_db=float(gm_up),
        gain_reduction_margin_db=float(gm_dn),
        gain_frequencies=(freq(k_dn[1]), freq(k_up[1])),
        phase_margin_deg=pm,
        phase_frequency=freq(pm_t),
        disk_margin=alpha,
        disk_gain_margin_db=float(disk_gm),
        disk_phase_margin_deg=disk_pm,
        disk_frequency=freq(disk_t),
        delay_margin=float(tau) if stable else 0.0,
        delay_frequency=freq(tau_t),
        dt=float(dt),
        omega=theta / dt,
        response=vals,
    )
