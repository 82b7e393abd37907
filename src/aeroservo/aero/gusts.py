"""Vertical gust disturbances for closed-loop simulation (velocity positive up, m/s).

* :class:`OneMinusCosine` - discrete 1-cos gust of given length and amplitude;
* :class:`Turbulence` - Dryden or von Karman continuous turbulence, synthesized from the exact
  one-dimensional spectrum by inverse FFT with random phases from a seeded generator (same seed,
  same signal);
* :class:`GustSeries` - a user time series, linearly interpolated.

Each is a callable ``w(t, speed)`` returning the gust velocity [m/s] at times ``t`` [s] for an
aircraft flying at ``speed`` [m/s].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import RANGES, InputError, check_int, check_number

__all__ = ["OneMinusCosine", "Turbulence", "GustSeries", "dryden_psd", "von_karman_psd"]

LENGTHS = (RANGES["gust_length"].lo, RANGES["gust_length"].hi)
"""Allowed gust lengths and turbulence scales [m]."""
VELOCITIES = (RANGES["gust_velocity"].lo, RANGES["gust_velocity"].hi)
"""Allowed gust velocities [m/s] (amplitudes and series values)."""
TIMES = (RANGES["time"].lo, RANGES["time"].hi)
"""Allowed gust times [s] (start, series times)."""
MAX_SIGMA = 30.0
"""Largest RMS turbulence velocity [m/s]."""


@dataclass(frozen=True)
class OneMinusCosine:
    """Discrete gust ``w = (amplitude/2) (1 - cos(2 pi V (t - start)/length))``.

    Parameters
    ----------
    length : float
        Gust length (distance flown through it) [m], in [0.01, 1e5].
    amplitude : float
        Peak vertical velocity [m/s], positive up, in [-50, 50].
    start : float
        Time the gust starts [s], in [0, 600].
    """

    length: float
    amplitude: float
    start: float = 0.0

    def __post_init__(self) -> None:
        check_number("gust.length", self.length, unit="m", lo=LENGTHS[0], hi=LENGTHS[1])
        check_number(
            "gust.amplitude", self.amplitude, unit="m/s", lo=VELOCITIES[0], hi=VELOCITIES[1]
        )
        check_number("gust.start", self.start, unit="s", lo=TIMES[0], hi=TIMES[1])

    def __call__(self, t: np.ndarray, speed: float) -> np.ndarray:
        speed = check_number("speed", speed, unit="m/s", lo=0.0)
        t = np.asarray(t, dtype=float)
        s = (t - self.start) * speed / self.length
        inside = (s >= 0) & (s <= 1)
        return np.where(inside, 0.5 * self.amplitude * (1 - np.cos(2 * np.pi * s)), 0.0)


def dryden_psd(omega: np.ndarray, speed: float, sigma: float, scale: float) -> np.ndarray:
    """One-sided Dryden vertical-gust PSD [(m/s)^2 / (rad/s)] at frequency ``omega`` [rad/s].

    ``Phi(w) = sigma^2 L/(pi V) (1 + 3 (L w/V)^2) / (1 + (L w/V)^2)^2``; integrates to sigma^2.
    """
    x = scale * np.asarray(omega) / speed
    return sigma**2 * scale / (np.pi * speed) * (1 + 3 * x**2) / (1 + x**2) ** 2


def von_karman_psd(omega: np.ndarray, speed: float, sigma: float, scale: float) -> np.ndarray:
    """One-sided von Karman vertical-gust PSD [(m/s)^2 / (rad/s)].

    ``Phi(w) = sigma^2 L/(pi V) (1 + 8/3 (1.339 L w/V)^2) / (1 + (1.339 L w/V)^2)^(11/6)``.
    """
    x = 1.339 * scale * np.asarray(omega) / speed
    return sigma**2 * scale / (np.pi * speed) * (1 + 8.0 / 3.0 * x**2) / (1 + x**2) ** (11.0 / 6.0)


@dataclass(frozen=True)
class Turbulence:
    """Continuous vertical turbulence.

    Parameters
    ----------
    sigma : float
        RMS gust velocity [m/s], in [0, 30].
    scale : float
        Turbulence scale length L [m] (e.g. 533 m above 2000 ft for MIL-F-8785C von Karman), in
        (0, 1e5].
    model : {"von_karman", "dryden"}
    seed : int
        Random seed: the same seed gives the same signal.
    """

    sigma: float
    scale: float = 533.0
    model: str = "von_karman"
    seed: int = 0

    def __post_init__(self) -> None:
        check_number("turbulence.sigma", self.sigma, unit="m/s", lo=0.0, hi=MAX_SIGMA)
        check_number("turbulence.scale", self.scale, unit="m", lo=0.0, lo_open=True, hi=LENGTHS[1])
        check_int("turbulence.seed", self.seed, lo=0)
        if not isinstance(self.model, str) or self.model not in ("von_karman", "dryden"):
            raise InputError(
                f"turbulence.model = {self.model!r}: allowed values are 'von_karman', 'dryden'"
            )

    def __call__(self, t: np.ndarray, speed: float) -> np.ndarray:
        """Signal on a uniform time grid ``t`` [s] (random phases, exact spectral amplitudes)."""
        speed = check_number("speed", speed, unit="m/s", lo=0.0, lo_open=True)
        t = np.asarray(t, dtype=float)
        n = t.size
        if n < 2:
            return np.zeros(n)
        dt = t[1] - t[0]
        if not np.allclose(np.diff(t), dt, rtol=1e-9, atol=1e-12):
            raise InputError("turbulence: the time grid must be uniform")
        n_fft = 1 << int(np.ceil(np.log2(2 * n)))
        omega = 2 * np.pi * np.fft.rfftfreq(n_fft, dt)
        psd = (von_karman_psd if self.model == "von_karman" else dryden_psd)(
            omega, speed, self.sigma, self.scale
        )
        d_omega = 2 * np.pi / (n_fft * dt)
        # x(t) = sum_k a_k cos(w_k t + p_k), a_k = sqrt(2 Phi(w_k) dw): variance sum Phi dw
        a = np.sqrt(2.0 * psd * d_omega)
        a[0] = 0.0
        rng = np.random.default_rng(self.seed)
        phase = rng.uniform(0.0, 2 * np.pi, omega.size)
        spec = a * np.exp(1j * phase) * (n_fft / 2.0)  # irfft divides by n_fft
        return np.fft.irfft(spec, n_fft)[:n]


@dataclass(frozen=True)
class GustSeries:
    """User gust time series, linearly interpolated (zero outside the given times).

    Parameters
    ----------
    time : array_like
        Increasing times [s], in [0, 600].
    velocity : array_like
        Vertical gust velocity [m/s] at those times, in [-50, 50].
    """

    time: tuple
    velocity: tuple

    def __post_init__(self) -> None:
        t, w = (
            _series("gust series: time", self.time),
            _series("gust series: velocity", self.velocity),
        )
        if t.ndim != 1 or t.shape != w.shape or t.size < 2:
            raise InputError(
                "gust series: time and velocity must be 1-D arrays of the same length >= 2 "
                f"(got shapes {t.shape} and {w.shape})"
            )
        for name, a, (lo, hi), unit in (
            ("time", t, TIMES, "s"),
            ("velocity", w, VELOCITIES, "m/s"),
        ):
            for i in np.flatnonzero(~np.isfinite(a) | (a < lo) | (a > hi))[:1]:
                check_number(f"gust series: {name}[{i}]", float(a[i]), unit=unit, lo=lo, hi=hi)
        for i in np.flatnonzero(np.diff(t) <= 0)[:1]:
            raise InputError(
                f"gust series: time[{i + 1}] = {t[i + 1]:g}: time must increase "
                f"(time[{i}] = {t[i]:g}) [s]"
            )
        object.__setattr__(self, "time", tuple(t))
        object.__setattr__(self, "velocity", tuple(w))

    def __call__(self, t: np.ndarray, speed: float) -> np.ndarray:
        return np.interp(np.asarray(t, dtype=float), self.time, self.velocity, left=0.0, right=0.0)


def _series(field: str, value: object) -> np.ndarray:
    """A real numeric array (a list, tuple or array of numbers), or InputError."""
    try:
        a = None if isinstance(value, (str, bytes)) else np.asarray(value)
    except ValueError:  # ragged nesting
        raise InputError(f"{field}: expected a flat list of numbers") from None
    if a is None or a.ndim == 0:
        raise InputError(f"{field} = {value!r}: expected a list of numbers")
    if a.dtype.kind not in "iuf":
        raise InputError(f"{field}: expected real numbers, got {a.dtype} values")
    return a.astype(float)
