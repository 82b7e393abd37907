"""Limit-cycle detection: judge a time history as a settled LCO, decay, divergence or aperiodic.

The rules (:func:`classify` applies them in this order):

* **Transient.** The first ``settle`` fraction of the record's duration is the transient and is
  excluded; the verdict is on the rest, the *window*. Everything is measured about the
  window mean, so a static offset (a biased freeplay LCO) does not matter.
* **Non-finite** values anywhere in the record: divergence.
* **At rest.** The reference's half peak-to-peak in the window is at most :data:`REST` times
  ``scale`` (default: its half peak-to-peak over the whole record): decay.
* **Cycles.** The zero crossings of the reference (about the window mean, with a hysteresis of
  :data:`HYSTERESIS` times its window amplitude) cut it into lobes; each full lobe's extreme
  is refined by a parabola through three samples. Two lobes make a cycle. The frequency
  comes from the extremes over whole cycles (exact for a damped sine, unlike crossings about
  a mean), the period scatter from the upward crossings (sharp where crests are flat).
  Fewer than ``min_cycles`` in the window: undecided, unless the window is non-oscillatory
  (monotone), where the log-slope of the rate of change decides decay or divergence.
* **Cycle amplitude** is half of each max-min swing between successive extremes. ``growth``
  [1/s] is the slope of log(cycle amplitude) against time; the amplitude change over the
  window is ``exp(growth T) - 1``; the amplitude scatter is the std of log(cycle amplitude)
  about that trend (about std/mean); the period scatter is std/mean of the crossing periods.
  An LCO period made of up to :data:`MAX_SUBHARMONIC` such cycles (a period-2 LCO) is
  allowed: the trend and scatters are then taken about the repeating pattern.
* **Divergence / decay:** amplitude change beyond ``+tol`` / ``-tol`` and a trend significant
  against the scatter (``|growth| T >`` :data:`SIGNIFICANCE` x amplitude scatter).
  **LCO:** amplitude change, amplitude scatter and period scatter all within ``tol``.
  **Aperiodic:** bounded, no significant trend, irregular amplitudes or periods.

Confidence is high with at least :data:`MANY_CYCLES` cycles and every criterion met with a
factor :data:`MARGIN` to spare, medium with one of the two, low otherwise; an FFT peak that
disagrees with that frequency, or fewer than :data:`MIN_SAMPLES` samples a cycle (crests
too coarse for the parabola), lowers it one step each.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from scipy import fft as sfft

from ..errors import InputError, check_number, show_value

__all__ = ["LCOVerdict", "classify"]

REST = 1e-6
"""Window half peak-to-peak, as a fraction of ``scale``, at or below which the motion is at rest."""
HYSTERESIS = 1e-3
"""Zero-crossing hysteresis as a fraction of the window half peak-to-peak (rejects chatter)."""
MAX_SUBHARMONIC = 4
"""Most zero-crossing cycles one LCO period may hold (period-p limit cycles)."""
SIGNIFICANCE = 3.0
"""A trend counts when its log-amplitude change over the window exceeds this many scatters."""
MARGIN = 5.0
"""Factor by which criteria must be met for a high confidence."""
MANY_CYCLES = 10
"""Cycles in the window needed for a high confidence."""
MIN_SAMPLES = 10
"""Samples a cycle below which the confidence drops one step."""
_LEVELS = ("low", "medium", "high")


@dataclass(frozen=True)
class LCOVerdict:
    """The judgement of one time history (see the module docstring for the rules).

    Attributes
    ----------
    kind : str
        ``"lco"``, ``"decay"`` (to rest or to a static offset), ``"divergence"``,
        ``"aperiodic"`` (bounded, not settled or periodic) or ``"undecided"`` (too few cycles).
    confidence : str
        ``"high"``, ``"medium"`` or ``"low"``; ``reason`` says why.
    reason : str
        One line with the criteria and their numbers.
    frequency : float
        Fundamental frequency over the window [Hz] (nan if none).
    peak, rms, mean : dict
        Per signal over the window: half the peak-to-peak (of the samples), the RMS about the
        window mean, and the mean [signal unit].
    window : tuple
        ``(t_start, t_end)`` analysed [s].
    cycles : float
        Cycles of the fundamental in the window.
    growth : float
        Slope of the reference's log cycle amplitude [1/s] (0 for a settled LCO).
    reference : str
        The signal judged.
    """

    kind: str
    confidence: str
    reason: str
    frequency: float
    peak: dict = field(default_factory=dict)
    rms: dict = field(default_factory=dict)
    mean: dict = field(default_factory=dict)
    window: tuple = (math.nan, math.nan)
    cycles: float = 0.0
    growth: float = math.nan
    reference: str = "signal"

    def as_dict(self) -> dict:
        """The verdict as JSON-able data (non-finite numbers become ``None``)."""

        def num(v):
            return float(v) if math.isfinite(v) else None

        out = dict(vars(self), window=[num(v) for v in self.window])
        for k in ("frequency", "cycles", "growth"):
            out[k] = num(out[k])
        for k in ("peak", "rms", "mean"):
            out[k] = {name: num(v) for name, v in out[k].items()}
        return out


def classify(
    t, signals, *, reference=None, settle=0.5, tol=0.01, min_cycles=4, scale=None
) -> LCOVerdict:
    """Judge a time history: settled LCO, decay, divergence, aperiodic or undecided.

    The first ``settle`` fraction of the record is the transient and is excluded; the verdict
    is on the rest (the window), about the window mean. See the module docstring for the rules.

    Parameters
    ----------
    t : array_like
        Sample times [s], 1-D, strictly increasing, at least 2 (uniform sampling is assumed by
        the FFT check only; other records are interpolated for it).
    signals : mapping or array_like
        Name -> 1-D array as long as ``t``, or one array (named ``"signal"``) [any unit].
    reference : str, optional
        The signal judged (default the first).
    settle : float
        Fraction of the record's duration excluded as the transient, in [0, 1).
    tol : float
        Largest relative amplitude change over the window, amplitude scatter and period
        scatter of a settled LCO, in (0, 1).
    min_cycles : float
        Fewest cycles in the window for a verdict on an oscillation (>= 2).
    scale : float, optional
        Size of motion that matters [reference unit] (e.g. a freeplay gap); the motion is at
        rest below ``REST * scale``. Default: the reference's half peak-to-peak over the record.

    Returns
    -------
    LCOVerdict

    Raises
    ------
    InputError
        On bad shapes, non-increasing or non-finite ``t``, fewer than 2 samples, an unknown
        reference or an option out of range.
    """
    t, sig, ref = _check(t, signals, reference)
    settle = check_number("settle", settle, lo=0.0, hi=1.0, hi_open=True)
    tol = check_number("tol", tol, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
    min_cycles = check_number("min_cycles", min_cycles, lo=2.0)
    if scale is not None:
        scale = check_number("scale", scale, lo=0.0, lo_open=True)
    t_cut = t[0] + settle * (t[-1] - t[0])
    cut = f"first {100 * settle:.3g} % of the record excluded as transient (t < {t_cut:.4g} s)"
    bad = {k: np.flatnonzero(~np.isfinite(s)) for k, s in sig.items()}
    end = min(b[0] if b.size else t.size for b in bad.values())
    i0 = int(np.searchsorted(t, t_cut))
    base = dict(reference=ref)
    if end < t.size:  # stats over the finite samples before the first bad one
        name = next(k for k, b in bad.items() if b.size and b[0] == end)
        i0 = i0 if i0 < end else 0
        stats = _stats({k: s[i0:end] for k, s in sig.items()})
        why = f"non-finite values from t = {t[end]:.6g} s (in {name!r})"
        window = (float(t[i0]), float(t[end]))
        return LCOVerdict("divergence", "high", why, math.nan, *stats, window, **base)
    tw, x = t[i0:], sig[ref][i0:]
    stats = _stats({k: s[i0:] for k, s in sig.items()})
    base.update(zip(("peak", "rms", "mean"), stats, strict=True))
    base["window"] = (float(tw[0]), float(tw[-1]))
    span = float(tw[-1] - tw[0])
    amp = stats[0][ref]
    ref_scale = scale if scale is not None else 0.5 * float(np.ptp(sig[ref]))
    if tw.size < 3:
        why = f"only {tw.size} samples in the window"
        return LCOVerdict("undecided", "low", f"{why}; {cut}", math.nan, **base)
    if amp <= REST * ref_scale:
        why = f"at rest: window half peak-to-peak {amp:.3g} <= {REST:g} x scale {ref_scale:.3g}"
        return LCOVerdict("decay", "high", f"{why}; {cut}", math.nan, **base)
    x = x - stats[2][ref]
    ext, t_ext, t_up = _lobes(tw, x, HYSTERESIS * amp)
    f0 = _frequency(t_ext, 1)
    cycles = span * f0 if ext.size >= 3 else 0.0
    if ext.size < 5 or t_up.size < 3 or cycles < min_cycles:
        return _few_cycles(tw, x, tol, (min_cycles, (ext.size - 1) // 2), cycles, f0, cut, base)
    a, ta = 0.5 * (ext[:-1] + ext[1:]), 0.5 * (t_ext[:-1] + t_ext[1:])
    la, periods = np.log(a), np.diff(t_up)
    p, g, a_sc, p_sc = _periodicity(ta, la, periods, cycles, min_cycles, tol)
    freq = _frequency(t_ext, p)
    cycles = span * freq
    change = math.expm1(min(g * span, 700.0))
    trend = abs(g) * span > SIGNIFICANCE * a_sc
    f_fft = _fft_peak(tw, x)
    k = max(1, min(p, round(f_fft / freq)))
    fft_ok = abs(f_fft - k * freq) <= 1.0 / span
    many = cycles >= MANY_CYCLES
    nums = (
        f"amplitude change {_pc(change)} over {cycles:.3g} cycles (tol {_pc(tol)}), "
        f"growth {g:.3g} 1/s, amplitude scatter {_pc(a_sc)}, period scatter {_pc(p_sc)}"
    )
    if p > 1:
        nums += f", period-{p} cycle"
    if abs(change) > tol and trend:
        kind = "divergence" if change > 0 else "decay"
        margin = abs(change) >= MARGIN * tol and abs(g) * span >= MARGIN * SIGNIFICANCE * a_sc
    elif max(a_sc, p_sc) <= tol and abs(change) <= tol:
        kind, margin = "lco", max(abs(change), a_sc, p_sc) <= tol / MARGIN
    elif max(a_sc, p_sc) <= tol:
        kind, margin, many = "undecided", False, False
        nums += " (change beyond tol but not significant against the scatter)"
    else:
        kind, margin = "aperiodic", max(a_sc, p_sc) >= MARGIN * tol
    spc = (tw.size - 1) / (span * f0)
    level = int(many) + int(margin) - int(not fft_ok) - int(spc < MIN_SAMPLES)
    if not fft_ok:
        nums += f"; FFT peak at {f_fft:.4g} Hz disagrees with {freq:.4g} Hz"
    if spc < MIN_SAMPLES:
        nums += f"; only {spc:.3g} samples a cycle"
    conf = _LEVELS[max(level, 0)]
    return LCOVerdict(kind, conf, f"{kind}: {nums}; {cut}", freq, cycles=cycles, growth=g, **base)


def _check(t, signals, reference):
    """Validate the record; return float arrays and the reference name."""
    t = _array("t", t)
    if t.size < 2:
        raise InputError(f"t has {t.size} samples: at least 2 are needed")
    if not np.all(np.isfinite(t)):
        i = int(np.argmax(~np.isfinite(t)))
        raise InputError(f"t[{i}] = {float(t[i])!r}: sample times must be finite")
    steps = np.diff(t)
    if not np.all(steps > 0):
        i = int(np.argmax(steps <= 0))
        raise InputError(f"t[{i + 1}] = {t[i + 1]:g} after t[{i}] = {t[i]:g}: t must increase")
    if not isinstance(signals, Mapping):
        signals = {"signal": signals}
    if not signals:
        raise InputError("signals is empty: give at least one signal")
    sig = {}
    for name, s in signals.items():
        if not isinstance(name, str):
            raise InputError(f"signal name {show_value(name)}: must be a string")
        sig[name] = _array(f"signals[{name!r}]", s)
        if sig[name].size != t.size:
            raise InputError(f"signals[{name!r}] has {sig[name].size} samples but t has {t.size}")
    if reference is None:
        reference = next(iter(sig))
    if reference not in sig:
        raise InputError(f"reference = {show_value(reference)}: not a signal (have {list(sig)})")
    return t, sig, reference


def _array(name, value) -> np.ndarray:
    """``value`` as a 1-D float array, or an InputError naming ``name``."""
    try:
        arr = np.asarray(value)
        if arr.dtype.kind not in "biuf":
            raise TypeError
        arr = arr.astype(float)
    except (TypeError, ValueError):
        raise InputError(f"{name} = {show_value(value)}: expected real numbers") from None
    if arr.ndim != 1:
        raise InputError(f"{name} has shape {arr.shape}: expected a 1-D array")
    return arr


def _stats(sig):
    """Half peak-to-peak, RMS about the mean and mean of each signal (nan when empty)."""
    peak, rms, mean = {}, {}, {}
    for k, s in sig.items():
        if s.size == 0:
            peak[k] = rms[k] = mean[k] = math.nan
            continue
        m = float(np.mean(s))
        peak[k], rms[k], mean[k] = 0.5 * float(np.ptp(s)), math.sqrt(np.mean((s - m) ** 2)), m
    return peak, rms, mean


def _lobes(t, x, h):
    """Extremes of the lobes of ``x`` (about zero) cut by zero crossings with hysteresis ``h``.

    A lobe runs between two successive changes of the state (``x > h``: +1, ``x < -h``: -1);
    only full lobes count. Returns the lobes' absolute extremes (refined by a parabola
    through three samples), their times [s] and the upward zero-crossing times [s] (linear
    interpolation across the last sign change before each turn to +1).
    """
    n = x.size
    idx = np.arange(n)
    hit = np.where(x > h, 1, np.where(x < -h, -1, 0)).astype(np.int8)
    last = np.maximum.accumulate(np.where(hit != 0, idx, -1))
    state = np.where(last >= 0, hit[np.maximum(last, 0)], 0)
    flips = np.flatnonzero((state[1:] != state[:-1]) & (state[:-1] != 0)) + 1
    up = flips[state[flips] > 0]
    j = np.maximum.accumulate(np.where(x <= 0, idx, -1))[up]
    t_up = t[j] - x[j] / (x[j + 1] - x[j]) * (t[j + 1] - t[j])
    if flips.size < 2:
        return np.empty(0), np.empty(0), t_up
    lengths = np.diff(flips)
    sign = state[flips[:-1]].astype(float)
    seg = np.repeat(np.arange(sign.size), lengths)
    y = x[flips[0] : flips[-1]] * sign[seg]
    ymax = np.maximum.reduceat(y, flips[:-1] - flips[0])
    at = np.flatnonzero(y == ymax[seg])
    first = np.flatnonzero(np.diff(seg[at], prepend=-1) != 0)
    k = at[first] + flips[0]  # index of each lobe's extreme, 1 <= k <= n - 2
    v0, v1, v2 = x[k - 1] * sign, x[k] * sign, x[k + 1] * sign
    curv = v0 - 2.0 * v1 + v2
    off = np.divide(0.5 * (v0 - v2), curv, out=np.zeros_like(curv), where=curv < 0)
    ext = v1 - 0.25 * (v0 - v2) * off
    t_ext = t[k] + off * 0.5 * (t[k + 1] - t[k - 1])
    return ext, t_ext, t_up


def _trend(ts, y, phases):
    """Slope of ``y`` against ``ts`` with one offset per phase (index mod ``phases``).

    Returns the slope and the residual standard deviation (``ts`` all equal: the scatter
    about the phase means).
    """
    ph = np.arange(y.size) % phases
    cnt = np.bincount(ph, minlength=phases)
    dt = ts - (np.bincount(ph, ts, phases) / cnt)[ph]
    dy = y - (np.bincount(ph, y, phases) / cnt)[ph]
    sxx = float(dt @ dt)
    slope = float(dt @ dy) / sxx if sxx > 0 else 0.0
    res = dy - slope * dt
    return slope, math.sqrt(float(res @ res) / max(y.size - phases - 1, 1))


def _frequency(t_ext, p) -> float:
    """Frequency [Hz] of period-``p`` cycles over the most whole ones between lobe extremes."""
    m = (t_ext.size - 1) // (2 * p)
    return m / float(t_ext[2 * p * m] - t_ext[0]) if m > 0 else math.nan


def _periodicity(ta, la, periods, cycles, min_cycles, tol):
    """Smallest period-p pattern within ``tol`` (p = 1 if none).

    Returns p, the growth [1/s], the amplitude scatter and the period scatter.
    """
    first = None
    for p in range(1, MAX_SUBHARMONIC + 1):
        if p > 1 and (periods.size < 3 * p or la.size < 6 * p or cycles / p < min_cycles):
            break
        g, a_sc = _trend(ta, la, 2 * p)
        p_sc = _trend(np.zeros_like(periods), periods, p)[1] / float(periods.mean())
        first = first or (p, g, a_sc, p_sc)
        if max(a_sc, p_sc) <= tol:
            return p, g, a_sc, p_sc
    return first


def _fft_peak(t, x) -> float:
    """Frequency [Hz] of the largest peak of the Hann-windowed spectrum of ``x``."""
    n = x.size
    steps = np.diff(t)
    if steps.max() - steps.min() > 1e-6 * steps.mean():
        x = np.interp(np.linspace(t[0], t[-1], n), t, x)
    m = sfft.next_fast_len(n, real=True)
    spec = np.abs(sfft.rfft(x * np.hanning(n), m))
    spec[: int(math.ceil(2.0 * m / n)) + 1] = 0.0  # the DC lobe of the Hann window
    return float(np.argmax(spec)) / (m * (t[-1] - t[0]) / (n - 1))


def _few_cycles(tw, x, tol, counts, cycles, f0, cut, base):
    """Verdict on a window with too few cycles: monotone motion or undecided.

    ``counts`` is ``(min_cycles, full cycles between lobe extremes)``.
    """
    d = np.diff(x)
    if (np.all(d >= 0) or np.all(d <= 0)) and np.count_nonzero(d) >= 3:
        nz = d != 0
        tm = 0.5 * (tw[1:] + tw[:-1])[nz]
        g, _ = _trend(tm, np.log(np.abs(d[nz])), 1)
        change = math.expm1(min(g * (tw[-1] - tw[0]), 700.0))
        kind = "decay" if change < -tol else "divergence" if change > tol else "undecided"
        conf = "medium" if abs(change) >= MARGIN * tol and kind != "undecided" else "low"
        why = f"{kind}: non-oscillatory, rate of change {_pc(change)} over the window"
        why = f"{why} (tol {_pc(tol)}), growth {g:.3g} 1/s; {cut}"
        return LCOVerdict(kind, conf, why, math.nan, growth=g, **base)
    why = f"undecided: {cycles:.3g} cycles in the window, {max(counts[1], 0)} full ones"
    why += f" (min_cycles = {counts[0]:g}; 2 full ones needed)"
    return LCOVerdict("undecided", "low", f"{why}; {cut}", f0, cycles=float(cycles), **base)


def _pc(v: float) -> str:
    """A fraction as a percentage with 2 significant digits."""
    return f"{100 * v:.2g} %"
