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

from ..errors import InputError, check_int, check_number

__all__ = ["OneMinusCosine", "Turbulence", "GustSeries", "dryden_psd", "von_karman_psd"]


@dataclass(frozen=True)
class OneMinusCosine:
    """Discrete gust ``w = (amplitude/2) (1 - cos(2 pi V (t - start)/length))``.

    Parameters
    ----------
    length : float
        Gust length (distance flown through it) [m].
    amplitude : float
        Peak vertical velocity [m/s], positive up.
    start : float
        Time the gust starts [s].
    """

    length: float
    amplitude: float
    start: float = 0.0

    def __post_init__(self) -> None:
        check_number("gust.length", self.length, unit="m", lo=0.0, lo_open=True)
        check_number("gust.amplitude", self.amplitude, unit="m/s")
        check_number("gust.start", self.start, unit="s", lo=0.0)

    def __call__(self, t: np.ndarray, speed: float) -> np.ndarray:
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
        RMS gust velocity [m/s].
    scale : float
        Turbulence scale length L [m] (e.g. 533 m above 2000 ft for MIL-F-8785C von Karman).
    model : {"von_karman", "dryden"}
    seed : int
        Random seed: the same seed gives the same signal.
    """

    sigma: float
    scale: float = 533.0
    model: str = "von_karman"
    seed: int = 0

    def __post_init__(self) -> None:
        check_number("turbulence.sigma", self.sigma, unit="m/s", lo=0.0)
        check_number("turbulence.scale", self.scale, unit="m", lo=0.0, lo_open=True)
        check_int("turbulence.seed", self.seed, lo=0)
        if self.model not in ("von_karman", "dryden"):
            raise InputError(
                f"turbulence.model = {self.model!r}: allowed values are 'von_karman', 'dryden'"
            )

    def __call__(self, t: np.ndarray, speed: float) -> np.ndarray:
        """Signal on a uniform time grid ``t`` [s] (random phases, exact spectral amplitudes)."""
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
        Increasing times [s].
    velocity : array_like
        Vertical gust velocity [m/s] at those times.
    """

    time: tuple
    velocity: tuple

    def __post_init__(self) -> None:
        t = np.asarray(self.time, dtype=float)
        w = np.asarray(self.velocity, dtype=float)
        if t.ndim != 1 or t.shape != w.shape or t.size < 2:
            raise InputError(
                "gust series: time and velocity must be 1-D arrays of the same length >= 2"
            )
        if np.any(np.diff(t) <= 0) or not np.all(np.isfinite(w)) or not np.all(np.isfinite(t)):
            raise InputError("gust series: time must increase and all values must be finite")
        object.__setattr__(self, "time", tuple(t))
        object.__setattr__(self, "velocity", tuple(w))

    def __call__(self, t: np.ndarray, speed: float) -> np.ndarray:
        return np.interp(np.asarray(t, dtype=float), self.time, self.velocity, left=0.0, right=0.0)
