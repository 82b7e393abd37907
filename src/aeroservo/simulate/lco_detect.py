"""Limit-cycle detection: judge a time history as a sustained oscillation (periodic,
quasi-periodic or chaotic), a decay, a divergence, or a motion not yet settled.

The rules (:func:`classify` applies them in this order):

* **Transient.** The first ``settle`` fraction of the record's duration is the transient and is
  excluded; the verdict is on the rest, the *window*. Everything is measured about the
  window mean, so a static offset (a biased freeplay LCO) does not matter.
* **Non-finite** values anywhere in the record: divergence.
* **At rest.** The reference's half peak-to-peak in the window is at most :data:`REST` times
  ``scale`` (default: its half peak-to-peak over the whole record): decay. **Absurd size:**
  with ``scale`` given, more than :data:`ABSURD` times it: divergence.
* **Cycles.** The zero crossings of the reference (about the window mean, with a hysteresis of
  :data:`HYSTERESIS` times its window amplitude) cut it into lobes; each full lobe's extreme
  is refined by a parabola through three samples. Two lobes make a cycle. The frequency
  comes from the extremes over whole cycles (exact for a damped sine, unlike crossings about
  a mean), the period scatter from the upward crossings (sharp where crests are flat).
  Fewer than ``min_cycles`` in the window: divergence when the RMS of the window's second half
  is more than :data:`FEW_GROWS` times its first's, else undecided, unless the window is
  non-oscillatory (monotone), where the log-slope of the rate of change decides decay or
  divergence (:mod:`.lco_cycles`).
* **Cycle amplitude** is half of each max-min swing between successive extremes. ``growth``
  [1/s] is the slope of log(cycle amplitude) against time; the amplitude change over the
  window is ``exp(growth T) - 1``; the amplitude scatter is the std of log(cycle amplitude)
  about that trend (about std/mean); the period scatter is std/mean of the crossing periods.
  An LCO period made of up to :data:`~.lco_cycles.MAX_SUBHARMONIC` such cycles (a period-2 LCO)
  is allowed: the trend and scatters are then taken about the repeating pattern, which must
  leave at most :data:`PATTERN` of the single cycles' scatter (it explains their modulation;
  else the motion is a modulated one: quasi-periodic at its carrier frequency).
* **Divergence / decay:** amplitude change beyond ``+tol`` / ``-tol`` and a trend significant
  against the scatter (``|growth| T >`` :data:`SIGNIFICANCE` x amplitude scatter); or, whatever
  the scatter of single cycles, an RMS that grows by more than :data:`GROWS` over the window
  (fitted to the RMS of segments of it, by more than :data:`SIGNIFICANCE` standard errors:
  :func:`~.lco_spectrum.rms_trend`).
  **LCO** (periodic): amplitude change, amplitude scatter and period scatter all within ``tol``.
* **Irregular cycles** (bounded, no significant trend, amplitudes or periods scattered beyond
  ``tol``): with fewer than :data:`IRREGULAR_CYCLES` cycles undecided; when the RMS of the
  window's halves differ by more than :data:`STATIONARY`, or their means by more than
  :data:`DRIFT` RMS, *unsettled* (march longer); otherwise a **sustained oscillation** that is
  not periodic, told apart by its spectrum (:mod:`.lco_spectrum`): **quasi-periodic** (a line
  spectrum; its frequency the strongest line, the carrier, and its modulation the distance of
  the strongest other line from the carrier's nearest harmonic) or **chaotic** (a continuous
  spectrum: more than :data:`~.lco_spectrum.BROADBAND` of its power broadband).

Confidence is high with at least :data:`MANY_CYCLES` cycles and every criterion met with a
factor :data:`MARGIN` to spare, medium with one of the two, low otherwise; an FFT peak that
disagrees with that frequency, or fewer than :data:`MIN_SAMPLES` samples a cycle (crests
too coarse for the parabola), lowers it one step each. Of a sustained irregular oscillation:
high with twice :data:`IRREGULAR_CYCLES` cycles (of its lobes or its carrier) and halves within
half of :data:`STATIONARY` and a broadband share a factor :data:`MARGIN` from the threshold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import check_number
from .lco_cycles import cycle_frequency, lobes, monotone, periodicity
from .lco_record import HUGE, checked_record, window_stats
from .lco_spectrum import BROADBAND, SEGMENTS, fft_peak, halves, rms_trend, window_spectrum

__all__ = ["LCOVerdict", "classify", "SUSTAINED"]

SUSTAINED = {"lco": "periodic", "quasi-periodic": "quasi-periodic", "chaotic": "chaotic"}
"""The verdicts of a sustained oscillation (bounded and stationary) and the class of motion
each names."""
REST = 1e-6
"""Window half peak-to-peak, as a fraction of ``scale``, at or below which the motion is at rest."""
ABSURD = 1e3
"""Window half peak-to-peak, as a multiple of a given ``scale``, beyond which it diverges."""
HYSTERESIS = 1e-3
"""Zero-crossing hysteresis as a fraction of the window half peak-to-peak (rejects chatter)."""
SIGNIFICANCE = 3.0
"""A trend counts when its log-amplitude change over the window exceeds this many scatters."""
GROWS = 1.0
"""Growth of the RMS over the window (fitted to segments of it) beyond which the motion
diverges, whatever the scatter of its cycles: 100 %."""
FEW_GROWS = 10.0
"""With fewer than ``min_cycles`` cycles, the ratio of the RMS of the window's halves beyond
which the motion diverges (a sine's halves differ by less over any part of a cycle)."""
PATTERN = 0.1
"""Largest scatter of a period-p pattern (p > 1), as a share of the single cycles', for a
period-p limit cycle (the pattern explains 99 % of their variance)."""
STATIONARY = 0.15
"""Largest relative difference of the RMS of the window's halves of a sustained irregular
oscillation (the freeplay section's chaotic motion: 0.2 to 6 %; the Lorenz system: 8-11 %)."""
DRIFT = 0.5
"""Largest shift of the mean between the window's halves, per RMS, of a sustained irregular
oscillation (the Lorenz system's x over 25 s halves: 0.36; the freeplay section: up to 0.11)."""
IRREGULAR_CYCLES = 20
"""Fewest cycles in the window for a verdict on an irregular motion (10 in each half)."""
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
        A sustained oscillation: ``"lco"`` (periodic, a limit cycle), ``"quasi-periodic"``
        (bounded and stationary, a line spectrum: a modulated cycle or incommensurate ones) or
        ``"chaotic"`` (bounded and stationary, a broadband spectrum) (:data:`SUSTAINED`);
        otherwise ``"decay"`` (to rest or to a static offset), ``"divergence"``,
        ``"unsettled"`` (bounded, irregular, its statistics still changing) or
        ``"undecided"`` (too few cycles, or a change not significant against the scatter).
    confidence : str
        ``"high"``, ``"medium"`` or ``"low"``; ``reason`` says why.
    reason : str
        One line with the criteria and their numbers.
    frequency : float
        Fundamental frequency over the window [Hz] (nan if none); of a quasi-periodic or
        chaotic oscillation the frequency of its spectrum's strongest line (the carrier).
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
    modulation : float
        Of a quasi-periodic oscillation, the distance [Hz] of its strongest line other than
        the carrier's harmonics from the nearest of them (nan otherwise or if none).
    broadband : float
        Of a sustained irregular oscillation, the share of its spectrum's power that is
        broadband (:mod:`.lco_spectrum`; nan otherwise).
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
    modulation: float = math.nan
    broadband: float = math.nan

    @property
    def sustained(self) -> bool:
        """Whether the motion is a sustained oscillation (periodic, quasi-periodic or
        chaotic)."""
        return self.kind in SUSTAINED

    def as_dict(self) -> dict:
        """The verdict as JSON-able data (non-finite numbers become ``None``)."""

        def num(v):
            return float(v) if math.isfinite(v) else None

        out = dict(vars(self), window=[num(v) for v in self.window])
        for k in ("frequency", "cycles", "growth", "modulation", "broadband"):
            out[k] = num(out[k])
        for k in ("peak", "rms", "mean"):
            out[k] = {name: num(v) for name, v in out[k].items()}
        return out


def classify(
    t, signals, *, reference=None, settle=0.5, tol=0.01, min_cycles=4, scale=None
) -> LCOVerdict:
    """Judge a time history: a sustained oscillation (periodic: an LCO; quasi-periodic;
    chaotic), decay, divergence, unsettled or undecided.

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
        rest below ``REST * scale`` and diverges beyond ``ABSURD * scale``. Default: the
        reference's half peak-to-peak over the record.

    Returns
    -------
    LCOVerdict

    Raises
    ------
    InputError
        On bad shapes, non-increasing or non-finite ``t``, fewer than 2 samples, an unknown
        reference or an option out of range.
    """
    t, sig, ref = checked_record(t, signals, reference)
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
        stats = window_stats({k: s[i0:end] for k, s in sig.items()})
        why = f"non-finite values from t = {t[end]:.6g} s (in {name!r})"
        window = (float(t[i0]), float(t[end]))
        return LCOVerdict("divergence", "high", why, math.nan, *stats, window, **base)
    tw, x = t[i0:], sig[ref][i0:]
    stats = window_stats({k: s[i0:] for k, s in sig.items()})
    base.update(zip(("peak", "rms", "mean"), stats, strict=True))
    base["window"] = (float(tw[0]), float(tw[-1]))
    span = float(tw[-1] - tw[0])
    amp = stats[0][ref]
    ref_scale = (
        scale if scale is not None else 0.5 * float(sig[ref].max()) - 0.5 * float(sig[ref].min())
    )
    if tw.size < 3:
        why = f"only {tw.size} samples in the window"
        return LCOVerdict("undecided", "low", f"{why}; {cut}", math.nan, **base)
    if amp <= REST * ref_scale:
        why = f"at rest: window half peak-to-peak {amp:.3g} <= {REST:g} x scale {ref_scale:.3g}"
        return LCOVerdict("decay", "high", f"{why}; {cut}", math.nan, **base)
    if scale is not None and amp > ABSURD * scale:
        why = f"divergence: window half peak-to-peak {amp:.3g} > {ABSURD:g} x scale {scale:.3g}"
        return LCOVerdict("divergence", "high", f"{why}; {cut}", math.nan, **base)
    x = x - stats[2][ref]
    big = float(np.max(np.abs(x)))
    if big > HUGE:  # a power of two: exact, and the sums of the analysis do not overflow
        x = np.ldexp(x, -math.frexp(big)[1])
        amp = 0.5 * float(np.ptp(x))
    r1, r2, m1, m2 = halves(x)
    ext, t_ext, t_up = lobes(tw, x, HYSTERESIS * amp)
    f0 = cycle_frequency(t_ext, 1)
    cycles = span * f0 if ext.size >= 3 else 0.0
    if ext.size < 5 or t_up.size < 3 or cycles < min_cycles:
        ratio = r2 / r1 if r1 > 0.0 else math.inf
        if ratio > FEW_GROWS:
            why = (
                f"divergence: {cycles:.3g} cycles in the window, its second half's RMS "
                f"{ratio:.3g} x its first's (> {FEW_GROWS:g})"
            )
            conf = "high" if ratio >= MARGIN * FEW_GROWS else "medium"
            return LCOVerdict("divergence", conf, f"{why}; {cut}", f0, **base)
        return _few_cycles(tw, x, tol, (min_cycles, (ext.size - 1) // 2), cycles, f0, cut, base)
    grown, sig_rms = rms_trend(tw, x)
    a, ta = 0.5 * (ext[:-1] + ext[1:]), 0.5 * (t_ext[:-1] + t_ext[1:])
    la, periods = np.log(a), np.diff(t_up)
    p, g, a_sc, p_sc, sc1 = periodicity(ta, la, periods, cycles, min_cycles, tol)
    freq = cycle_frequency(t_ext, p)
    cycles = span * freq
    change = math.expm1(min(g * span, 700.0))
    trend = abs(g) * span > SIGNIFICANCE * a_sc
    f_fft = fft_peak(tw, x)
    k = max(1, min(p, round(f_fft / freq)))
    fft_ok = abs(f_fft - k * freq) <= 1.0 / span
    many = cycles >= MANY_CYCLES
    nums = (
        f"amplitude change {_pc(change)} over {cycles:.3g} cycles (tol {_pc(tol)}), "
        f"growth {g:.3g} 1/s, amplitude scatter {_pc(a_sc)}, period scatter {_pc(p_sc)}"
    )
    regular = max(a_sc, p_sc) <= tol
    explained = p == 1 or max(a_sc, p_sc) <= PATTERN * sc1
    if p > 1:
        nums += f", period-{p} cycle"
    if abs(change) > tol and trend:
        kind = "divergence" if change > 0 else "decay"
        margin = abs(change) >= MARGIN * tol and abs(g) * span >= MARGIN * SIGNIFICANCE * a_sc
    elif grown > GROWS and sig_rms > SIGNIFICANCE:
        kind, margin = "divergence", grown >= MARGIN * GROWS
        nums += (
            f"; but the RMS grows {_pc(grown)} over the window (> {_pc(GROWS)}; fitted to "
            f"{SEGMENTS} segments, {sig_rms:.3g} standard errors)"
        )
    elif regular and explained and abs(change) <= tol:
        kind, margin = "lco", max(abs(change), a_sc, p_sc) <= tol / MARGIN
    elif regular and explained:
        kind, margin, many = "undecided", False, False
        nums += " (change beyond tol but not significant against the scatter)"
    else:
        if p > 1:
            nums += (
                f" leaving {_pc(max(a_sc, p_sc) / sc1)} of the single cycles' scatter "
                f"(> {_pc(PATTERN)}: a modulation, not a period-{p} limit cycle)"
            )
        return _irregular(tw, x, (r1, r2, m1, m2), span * f0, f0, nums, cut, base, growth=g)
    spc = (tw.size - 1) / (span * f0)
    level = int(many) + int(margin) - int(not fft_ok) - int(spc < MIN_SAMPLES)
    if not fft_ok:
        nums += f"; FFT peak at {f_fft:.4g} Hz disagrees with {freq:.4g} Hz"
    if spc < MIN_SAMPLES:
        nums += f"; only {spc:.3g} samples a cycle"
    conf = _LEVELS[max(level, 0)]
    return LCOVerdict(kind, conf, f"{kind}: {nums}; {cut}", freq, cycles=cycles, growth=g, **base)


def _irregular(tw, x, half, cycles, f0, nums, cut, base, growth) -> LCOVerdict:
    """Verdict on a bounded window whose cycles are irregular and show no trend: sustained
    (stationary halves; ``"quasi-periodic"`` or ``"chaotic"`` by its spectrum), ``"unsettled"``
    (the halves differ) or ``"undecided"`` (too few cycles to tell)."""
    r1, r2, m1, m2 = half
    rms = math.sqrt(0.5 * (r1 * r1 + r2 * r2))
    drift = abs(r2 / r1 - 1.0) if r1 > 0 else math.inf
    shift = abs(m2 - m1) / rms
    halves_text = (
        f"the window's halves: RMS {r1:.4g} and {r2:.4g}, {_pc(drift)} apart (tol "
        f"{_pc(STATIONARY)}), means {shift:.2g} RMS apart (tol {DRIFT:g})"
    )
    spc = (tw.size - 1) / (tw[-1] - tw[0]) / f0 if f0 > 0 else math.inf
    coarse = -int(spc < MIN_SAMPLES)
    tail = f"; only {spc:.3g} samples a cycle" if spc < MIN_SAMPLES else ""
    kw = dict(cycles=float(cycles), growth=growth, **base)
    if cycles < IRREGULAR_CYCLES:
        why = (
            f"undecided: irregular cycles ({nums}), {cycles:.3g} in the window: at least "
            f"{IRREGULAR_CYCLES} are needed to judge an irregular motion{tail}; {cut}"
        )
        return LCOVerdict("undecided", "low", why, f0, **kw)
    if drift > STATIONARY or shift > DRIFT:
        level = 1 + int(drift >= 2.0 * STATIONARY or shift >= 2.0 * DRIFT) + coarse
        why = f"unsettled: bounded, irregular ({nums}), not stationary: {halves_text}"
        why += f": march longer{tail}; {cut}"
        return LCOVerdict("unsettled", _LEVELS[max(level, 0)], why, f0, **kw)
    spec = window_spectrum(tw, x)
    share, carrier = spec.broadband, spec.peak
    chaotic = share > BROADBAND
    clear = share >= MARGIN * BROADBAND if chaotic else share <= BROADBAND / MARGIN
    many = max(cycles, (tw[-1] - tw[0]) * carrier) >= 2 * IRREGULAR_CYCLES  # lobes or carrier
    level = int(many) + int(clear and drift <= STATIONARY / 2) + coarse
    spectrum = f"{_pc(share)} of its spectrum's power is broadband (tol {_pc(BROADBAND)})"
    if chaotic:
        kind = "chaotic"
        what = f"broadband spectrum: {spectrum}; strongest line {carrier:.4g} Hz"
        mod = math.nan
    else:
        kind = "quasi-periodic"
        line, mod = spec.modulation(carrier)
        what = f"line spectrum: {spectrum}; carrier {carrier:.4g} Hz"
        if math.isfinite(mod):
            what += f", modulation {mod:.4g} Hz (its strongest other line at {line:.4g} Hz)"
    why = (
        f"{kind}: a sustained oscillation, bounded and stationary ({halves_text}), irregular "
        f"cycles ({nums}), {what}{tail}; {cut}"
    )
    conf = _LEVELS[max(min(level, 2), 0)]
    kw["cycles"] = float((tw[-1] - tw[0]) * carrier)
    return LCOVerdict(kind, conf, why, carrier, modulation=mod, broadband=share, **kw)


def _few_cycles(tw, x, tol, counts, cycles, f0, cut, base):
    """Verdict on a window with too few cycles: monotone motion or undecided.

    ``counts`` is ``(min_cycles, full cycles between lobe extremes)``.
    """
    mono = monotone(tw, x, tol, MARGIN)
    if mono is not None:
        kind, conf, change, g = mono
        why = f"{kind}: non-oscillatory, rate of change {_pc(change)} over the window"
        why = f"{why} (tol {_pc(tol)}), growth {g:.3g} 1/s; {cut}"
        return LCOVerdict(kind, conf, why, math.nan, growth=g, **base)
    why = f"undecided: {cycles:.3g} cycles in the window, {max(counts[1], 0)} full ones"
    why += f" (min_cycles = {counts[0]:g}; 2 full ones needed)"
    return LCOVerdict("undecided", "low", f"{why}; {cut}", f0, cycles=float(cycles), **base)


def _pc(v: float) -> str:
    """A fraction as a percentage with 2 significant digits."""
    return f"{100 * v:.2g} %"
