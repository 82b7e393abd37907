"""The record a limit-cycle verdict judges: its times and signals checked, and the statistics
of each signal over the window (:func:`aeroservo.simulate.lco_detect.classify`)."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ..errors import InputError, show_value

__all__ = ["checked_record", "window_stats", "HUGE"]

HUGE = 1e150
"""A signal larger than this is scaled by a power of two before its sums (no overflow)."""


def checked_record(t, signals, reference):
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


def window_stats(sig):
    """Half peak-to-peak, RMS about the mean and mean of each signal (nan when empty)."""
    peak, rms, mean = {}, {}, {}
    for k, s in sig.items():
        if s.size == 0:
            peak[k] = rms[k] = mean[k] = math.nan
            continue
        big = float(np.max(np.abs(s)))
        e = math.frexp(big)[1] if big > HUGE else 0  # scaled by 2^-e: no overflow in the sums
        y = np.ldexp(s, -e) if e else s
        m = float(np.mean(y))
        r = math.sqrt(np.mean((y - m) ** 2))
        half = 0.5 * float(np.ptp(y)) if not e else 0.5 * float(y.max()) - 0.5 * float(y.min())
        peak[k], rms[k], mean[k] = math.ldexp(half, e), math.ldexp(r, e), math.ldexp(m, e)
    return peak, rms, mean
