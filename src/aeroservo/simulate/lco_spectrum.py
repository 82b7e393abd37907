"""The spectrum of a judged window and the statistics of its halves: what tells a sustained
oscillation that is not periodic apart from one that is still changing, and a quasi-periodic
one from a chaotic one (:func:`aeroservo.simulate.lco_detect.classify` applies them).

* **Halves.** The RMS (about its own mean) and the mean of each half of the window. A bounded
  motion is *stationary* when both halves have the same RMS and mean to within a tolerance.
* **RMS trend.** The logarithm of the RMS of :data:`SEGMENTS` equal segments of the window,
  fitted by a straight line against time: its growth over the window and the slope over its
  standard error. This measures growth without cutting the motion into cycles, and averages
  the scatter of single cycles within each segment (an irregular motion whose cycles scatter
  by 84 % still shows a growth of 430 % at 87 standard errors).
* **Spectrum.** The Hann-windowed periodogram of the window (about its mean; the lobe of the
  window at zero frequency removed). Its *floor* is the running 25th percentile of the power
  over :data:`FLOOR_BINS` bins on either side: between lines the power itself (the continuous
  part of the spectrum), under a line the level around it. The *broadband share* is the
  power at or below the floor over the total. A periodic or quasi-periodic motion has a line
  spectrum (its power in peaks as narrow as the window's main lobe, 4 bins wide): its share is
  the leakage of the Hann window, 1e-12 for a sine and 1e-7 to 1e-5 for sums of sines and the
  marched freeplay section's torus; a chaotic motion has a continuous spectrum, a share of 1 %
  and more (the freeplay section at 7-9 m/s, a sine whose amplitudes follow the logistic map,
  the Lorenz system: 1.3 % to 14 %). :data:`BROADBAND` lies between, a factor 10 from each.
* **Lines.** The strongest line (its frequency refined by a parabola through the logarithms of
  three bins, exact for a Gaussian and within a few hundredths of a bin for the Hann window's
  lobe) is the carrier; the strongest line that is not a harmonic of it names the modulation:
  its distance from the nearest harmonic (or from zero).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import fft as sfft
from scipy import ndimage

__all__ = [
    "BROADBAND", "FLOOR_BINS", "SEGMENTS", "Spectrum", "window_spectrum", "halves", "rms_trend",
    "fft_peak",
]  # fmt: skip

BROADBAND = 1e-3
"""Broadband share above which a sustained oscillation is chaotic (below: quasi-periodic)."""
FLOOR_BINS = 15
"""Half width [bins] of the running percentile that estimates the continuous spectrum."""
FLOOR_PERCENTILE = 25.0
"""Percentile of the power over the running window taken as the floor."""
LINE_BINS = 3
"""Half width [bins] of a line of the Hann window (its main lobe is 2 bins on either side)."""
LINE_HEIGHT = 10.0
"""A peak is a line when its power is at least this many times the floor under it."""
SEGMENTS = 8
"""Equal segments of the window whose RMS :func:`rms_trend` fits."""


@dataclass(frozen=True)
class Spectrum:
    """The Hann-windowed periodogram of a window.

    Attributes
    ----------
    df : float
        Bin width [Hz].
    power : ndarray
        Power per bin [signal unit^2, arbitrary scale], the bins of the window's lobe at zero
        frequency set to zero.
    floor : ndarray
        The running :data:`FLOOR_PERCENTILE` percentile of ``power`` over
        ``2 FLOOR_BINS + 1`` bins.
    """

    df: float
    power: np.ndarray
    floor: np.ndarray

    @property
    def broadband(self) -> float:
        """Share of the power at or below the floor (0 to 1; nan without power)."""
        total = float(self.power.sum())
        if not total > 0.0:
            return math.nan
        return float(np.minimum(self.power, self.floor).sum()) / total

    def _refined(self, k: int) -> float:
        """Frequency [Hz] of the peak at bin ``k``, refined by a parabola through the
        logarithms of the power at ``k - 1``, ``k``, ``k + 1``."""
        p = self.power
        if 0 < k < p.size - 1 and p[k - 1] > 0.0 and p[k + 1] > 0.0:
            a, b, c = math.log(p[k - 1]), math.log(p[k]), math.log(p[k + 1])
            den = a - 2.0 * b + c
            if den < 0.0:
                return (k + 0.5 * (a - c) / den) * self.df
        return k * self.df

    @property
    def peak(self) -> float:
        """Frequency [Hz] of the strongest line (nan without power)."""
        if not self.power.max(initial=0.0) > 0.0:
            return math.nan
        return self._refined(int(np.argmax(self.power)))

    def modulation(self, carrier: float) -> tuple[float, float]:
        """``(line, modulation)`` [Hz]: the strongest line that is not a harmonic of
        ``carrier`` (more than :data:`LINE_BINS` bins from each) and its distance from the
        nearest harmonic or from zero; ``(nan, nan)`` if there is none."""
        p, fl = self.power, self.floor
        if p.size < 3 or not carrier > 0.0:
            return math.nan, math.nan
        k = np.flatnonzero(
            (p[1:-1] >= p[:-2]) & (p[1:-1] > p[2:]) & (p[1:-1] >= LINE_HEIGHT * fl[1:-1])
        )
        k += 1
        kc = carrier / self.df
        n = np.rint(k / kc)
        k = k[(n < 1) | (np.abs(k - n * kc) > LINE_BINS)]
        if not k.size:
            return math.nan, math.nan
        line = self._refined(int(k[np.argmax(p[k])]))
        return line, abs(line - round(line / carrier) * carrier)


def window_spectrum(t: np.ndarray, x: np.ndarray) -> Spectrum:
    """The :class:`Spectrum` of ``x`` (about its mean) sampled at ``t`` [s] (a record that is
    not uniformly sampled is interpolated onto a uniform grid of as many samples)."""
    n = x.size
    steps = np.diff(t)
    if steps.max() - steps.min() > 1e-6 * steps.mean():
        x = np.interp(np.linspace(t[0], t[-1], n), t, x)
    s = float(np.max(np.abs(x)))
    y = x / s if s > 0.0 else x
    y = y - y.mean()
    m = sfft.next_fast_len(n, real=True)
    power = np.abs(sfft.rfft(y * np.hanning(n), m)) ** 2
    power[: int(math.ceil(2.0 * m / n)) + 1] = 0.0  # the lobe of the Hann window at zero
    floor = ndimage.percentile_filter(
        power, FLOOR_PERCENTILE, size=2 * FLOOR_BINS + 1, mode="nearest"
    )
    return Spectrum(1.0 / (m * (t[-1] - t[0]) / (n - 1)), power, floor)


def halves(x: np.ndarray) -> tuple[float, float, float, float]:
    """``(rms1, rms2, mean1, mean2)``: the RMS about its own mean and the mean of each half of
    ``x`` [signal unit] (each half scaled by its largest magnitude first: no overflow or
    underflow in the sums, whatever the size of ``x``)."""
    h = x.size // 2
    out = []
    for part in (x[:h], x[h:]):
        s = float(np.max(np.abs(part), initial=0.0))
        if not s > 0.0:
            out.append((0.0, 0.0))
            continue
        y = part / s
        m = float(y.mean())
        d = y - m
        e = float(np.max(np.abs(d)))
        r = e * math.sqrt(float(np.mean((d / e) ** 2))) if e > 0.0 else 0.0
        out.append((r * s, m * s))
    (r1, m1), (r2, m2) = out
    return r1, r2, m1, m2


def fft_peak(t, x) -> float:
    """Frequency [Hz] of the largest peak of the Hann-windowed spectrum of ``x``."""
    n = x.size
    steps = np.diff(t)
    if steps.max() - steps.min() > 1e-6 * steps.mean():
        x = np.interp(np.linspace(t[0], t[-1], n), t, x)
    m = sfft.next_fast_len(n, real=True)
    spec = np.abs(sfft.rfft(x * np.hanning(n), m))
    spec[: int(math.ceil(2.0 * m / n)) + 1] = 0.0  # the DC lobe of the Hann window
    return float(np.argmax(spec)) / (m * (t[-1] - t[0]) / (n - 1))


def rms_trend(t: np.ndarray, x: np.ndarray) -> tuple[float, float]:
    """``(growth, significance)``: the change of the RMS over the window [-] of an exponential
    fitted to the RMS of :data:`SEGMENTS` equal segments of ``x`` (each about its own mean),
    and the fitted slope over its standard error (``inf`` for an exact fit; ``(nan, 0)``
    with a segment at rest)."""
    m = x.size // SEGMENTS
    if m < 2:
        return math.nan, 0.0
    ts, ys = np.empty(SEGMENTS), np.empty(SEGMENTS)
    for i in range(SEGMENTS):
        part = x[i * m : (i + 1) * m]
        r = halves(np.concatenate([part, part]))[0]  # its RMS, without overflow
        if not r > 0.0:
            return math.nan, 0.0
        ts[i], ys[i] = float(t[i * m : (i + 1) * m].mean()), math.log(r)
    dt, dy = ts - ts.mean(), ys - ys.mean()
    sxx = float(dt @ dt)
    slope = float(dt @ dy) / sxx
    res = dy - slope * dt
    se = math.sqrt(float(res @ res) / (SEGMENTS - 2) / sxx)
    growth = math.expm1(min(slope * float(t[-1] - t[0]), 700.0))
    return growth, (abs(slope) / se if se > 0.0 else math.inf)
