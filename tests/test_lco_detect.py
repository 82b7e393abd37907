"""LCO detection from a time history (issue 28): :func:`aeroservo.simulate.lco_detect.classify`
on signals whose answer is known in closed form.

Tolerances follow from the sample step ``dt``: the largest sample of a peak of curvature
``w**2 A`` lies within ``dt/2`` of it, so it is low by at most ``A (1 - cos(pi f dt))``;
cycle amplitudes carry at most that relative error, which moves a least-squares log-slope
over a window ``T`` by at most about ``3 eps / T`` (4 used).
"""

import json
import math
import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from aeroservo.errors import InputError
from aeroservo.simulate.lco_detect import LCOVerdict, classify


def whole_cycles(f, per_period, periods):
    """Times of a record whose window (its second half) holds exactly ``periods`` periods.

    ``2 periods per_period`` samples at ``dt = 1/(f per_period)``: with ``settle = 0.5`` the
    window starts at sample ``periods per_period`` (the cut lies half a step before it), so
    sums of ``cos(k w t)`` over the window vanish (discrete orthogonality, ``k < per_period``).
    """
    dt = 1.0 / (f * per_period)
    return np.arange(2 * periods * per_period) * dt, dt


# ---------------------------------------------------------------------------- settled LCOs


@pytest.mark.parametrize(
    "f, amp, offset, dt, duration",
    [(2.3, 1.5, 0.3, 1e-3, 40.0), (0.37, 0.02, -5.0, 0.01, 200.0), (11.0, 3.0, 1e3, 2e-4, 6.1)],
)
def test_sine_with_offset(f, amp, offset, dt, duration):
    t = np.arange(0.0, duration, dt)
    v = classify(t, offset + amp * np.sin(2 * np.pi * f * t + 0.4))
    assert (v.kind, v.confidence) == ("lco", "high"), v.reason
    t_w = v.window[1] - v.window[0]
    # peak: the samples miss the crest and trough by <= amp (1 - cos(pi f dt)) each
    eps = amp * (1 - math.cos(math.pi * f * dt))
    assert amp - eps - 1e-12 * amp <= v.peak["signal"] <= amp * (1 + 1e-12)
    # the window mean misses the offset by <= amp / (pi f T) (a non-integer number of cycles)
    bias = amp / (math.pi * f * t_w) + 2 * amp / (t_w / dt)
    assert abs(v.mean["signal"] - offset) <= bias + 1e-12 * abs(offset)
    # frequency: from the crest and trough times over whole cycles (span > T - 3/f), each off
    # by the vertex error of a parabola through 3 samples of a cosine, in steps
    # tan(phi) / (2 tan(a/2)) - phi/a for a crest phi (|phi| <= a/2) off a sample, a = w dt
    a = 2 * np.pi * f * dt
    phi = np.linspace(0.0, a / 2, 1001)
    delta = dt * np.max(np.abs(np.tan(phi) / (2 * np.tan(a / 2)) - phi / a))
    assert abs(v.frequency / f - 1) <= 2 * delta / (t_w - 3 / f) + 1e-12
    assert abs(v.growth) * t_w < 1e-6
    assert v.cycles == pytest.approx(f * t_w, rel=1e-6)
    assert "first 50 % of the record excluded as transient" in v.reason


@pytest.mark.parametrize("r", [0.05, 0.1, 1 / 9])
@pytest.mark.parametrize("offset", [0.0, -0.4])
def test_sine_with_third_harmonic(r, offset):
    """x = A (sin wt + r sin 3wt), flat-topped for 0 < r <= 1/9: crest A (1 - r) at wt = pi/2
    (x = A ((1 + 3r) s - 4 r s^3) with s = sin wt is monotone in s), RMS A sqrt((1 + r^2)/2)."""
    f, amp = 1.7, 2.0
    t, dt = whole_cycles(f, 997, 12)
    th = 2 * np.pi * f * t + 0.3
    v = classify(t, offset + amp * (np.sin(th) + r * np.sin(3 * th)))
    assert (v.kind, v.confidence) == ("lco", "high"), v.reason
    d = math.pi * f * dt  # the crest lies within half a step of a sample
    miss = amp * ((1 - r) - (math.cos(d) - r * math.cos(3 * d)))
    assert amp * (1 - r) - miss - 1e-12 <= v.peak["signal"] <= amp * (1 - r) + 1e-12
    assert v.rms["signal"] == pytest.approx(amp * math.sqrt((1 + r * r) / 2), rel=1e-11)
    crest = amp * (1 - r) / (amp * math.sqrt((1 + r * r) / 2))
    assert v.peak["signal"] / v.rms["signal"] == pytest.approx(crest, abs=miss / v.rms["signal"])
    assert v.mean["signal"] == pytest.approx(offset, abs=1e-12)
    assert v.frequency == pytest.approx(f, rel=1e-10)
    assert v.cycles == pytest.approx(12, abs=1e-6 * 12 + 1.0 / 997)


def test_van_der_pol_settles_into_its_limit_cycle():
    """x'' - mu (1 - x^2) x' + x = 0 from x = 0.1 grows (rate mu/2) into the cycle of
    amplitude 2 + O(mu^2) and angular frequency 1 - mu^2/16 + O(mu^4); the transient is gone
    (to exp(-mu (200 - 60))) by the window."""
    mu = 0.1
    t = np.arange(0.0, 400.0, 0.01)
    sol = solve_ivp(
        lambda _, y: [y[1], mu * (1 - y[0] ** 2) * y[1] - y[0]],
        (0.0, 400.0),
        [0.1, 0.0],
        t_eval=t,
        rtol=1e-10,
        atol=1e-12,
    )
    v = classify(t, {"x": sol.y[0], "v": sol.y[1]})
    assert (v.kind, v.confidence, v.reference) == ("lco", "high", "x"), v.reason
    assert v.peak["x"] == pytest.approx(2.0, rel=0.01)
    assert v.frequency == pytest.approx((1 - mu**2 / 16) / (2 * np.pi), rel=1e-3)
    assert v.window[0] == pytest.approx(200.0, abs=0.01)
    # the whole record is no LCO: its first half grows
    assert classify(t, sol.y[0], settle=0.0).kind != "lco"


def test_period_two_cycle_is_an_lco_at_the_subharmonic():
    """x = sin(2 pi t) (1 + 0.2 cos(pi t)): period 2 s, crests alternate."""
    t, _ = whole_cycles(0.5, 2000, 12)
    v = classify(t, np.sin(2 * np.pi * t) * (1 + 0.2 * np.cos(np.pi * t)))
    assert v.kind == "lco", v.reason
    assert v.frequency == pytest.approx(0.5, rel=1e-9)
    assert "period-2" in v.reason


def test_coarse_sampling_lowers_the_confidence():
    t = np.arange(0.0, 100.0, 1 / 8)
    v = classify(t, np.sin(2 * np.pi * t + 0.3))
    assert (v.kind, v.confidence) == ("lco", "medium"), v.reason
    assert "only 8 samples a cycle" in v.reason
    assert v.frequency == pytest.approx(1.0, rel=1e-9)  # 8 samples: the same phases each cycle


def test_several_signals_and_a_chosen_reference():
    f = 0.8
    t, _ = whole_cycles(f, 500, 10)
    th = 2 * np.pi * f * t
    sig = {"h": 0.5 + 2.0 * np.sin(th), "alpha": -0.1 + 0.3 * np.cos(th) + 0.05 * np.sin(2 * th)}
    v = classify(t, sig, reference="alpha")
    assert (v.kind, v.reference) == ("lco", "alpha")
    assert v.mean == pytest.approx({"h": 0.5, "alpha": -0.1}, abs=1e-12)
    rms = {"h": 2.0 / math.sqrt(2), "alpha": math.sqrt((0.3**2 + 0.05**2) / 2)}
    assert v.rms == pytest.approx(rms, rel=1e-11)
    # h: crest at a sample (500 samples a period, phase 0) -> exact
    assert v.peak["h"] == pytest.approx(2.0, rel=1e-12)
    assert v.frequency == pytest.approx(f, rel=1e-10)


# ---------------------------------------------------------------------------- growth, decay


@pytest.mark.parametrize("offset", [0.0, 0.7])
@pytest.mark.parametrize("zeta, fn", [(0.02, 1.5), (-0.005, 3.0), (0.001, 0.5)])
def test_damped_and_growing_sines(zeta, fn, offset):
    """x = c + exp(-zeta wn t) sin(wd t): the swing between successive extremes scales
    exactly as exp(-zeta wn t), whatever the level c the lobes are cut at."""
    dt, duration = 1e-3, 80.0 if abs(zeta) < 0.002 else 40.0
    t = np.arange(0.0, duration, dt)
    wn = 2 * np.pi * fn
    x = offset + np.exp(-zeta * wn * t) * np.sin(wn * math.sqrt(1 - zeta**2) * t)
    v = classify(t, x)
    t_w = v.window[1] - v.window[0]
    eps = 1.1 * (math.pi * fn * dt) ** 2 / 2  # x'' = -wn^2 x at an extreme; 10 % for O(dt^3)
    assert v.growth == pytest.approx(-zeta * wn, abs=4 * eps / t_w)
    change = math.expm1(-zeta * wn * t_w)
    kind = "lco" if abs(change) < 0.01 else "decay" if change < 0 else "divergence"
    assert v.kind == kind, v.reason
    assert v.confidence == "high", v.reason
    # extremes of a damped sine are pi / wd apart; each found within a step (span > T - 3/f)
    fd = fn * math.sqrt(1 - zeta**2)
    assert v.frequency == pytest.approx(fd, rel=2 * dt / (t_w - 3 / fd))


def test_tol_decides_between_slow_decay_and_lco():
    t = np.arange(0.0, 80.0, 1e-3)
    x = np.exp(-0.001 * 2 * np.pi * t) * np.sin(2 * np.pi * t)  # change -22 % over 40 s
    assert classify(t, x, tol=0.5).kind == "lco"
    assert classify(t, x, tol=0.01).kind == "decay"


@pytest.mark.parametrize(
    "change, kind",
    [(0.013, "undecided"), (-0.013, "undecided"), (0.03, "divergence"), (-0.03, "decay")],
)
def test_a_trend_must_stand_out_of_the_cycle_to_cycle_scatter(change, kind):
    """Cycle amplitudes (1 + change)^(t / 50 s) (1 + 0.8 % xi_k), xi_k equidistributed (golden
    ratio sequence, unit variance): amplitude scatter about 0.65 % < tol, so 3 scatters
    (about 2 %) decide whether the change over the window is a trend."""
    t = np.arange(0.0, 100.0, 1e-3)
    xi = ((t.astype(int) * (math.sqrt(5) - 1) / 2) % 1 - 0.5) * math.sqrt(12)
    amp = np.exp(np.log1p(change) * t / 50) * (1 + 0.008 * xi)
    v = classify(t, amp * np.sin(2 * np.pi * t))
    assert v.kind == kind, v.reason
    assert v.growth == pytest.approx(math.log1p(change) / 50, rel=0.25)


@pytest.mark.parametrize(
    "x, kind",
    [
        (lambda t: 1.0 + np.exp(-0.2 * t), "decay"),  # to a static offset
        (lambda t: np.exp(0.2 * t), "divergence"),  # static divergence
        (lambda t: np.full_like(t, 3.0), "decay"),  # at rest throughout
        (lambda t: 2.0 + np.exp(-t) * np.sin(2 * np.pi * t), "decay"),  # rest: 1e-9 of 1
    ],
)
def test_non_oscillating_and_resting_records(x, kind):
    t = np.arange(0.0, 40.0, 1e-3)
    v = classify(t, x(t))
    assert v.kind == kind, v.reason
    assert v.confidence in ("high", "medium")


def test_scale_sets_what_counts_as_rest():
    t = np.arange(0.0, 40.0, 1e-3)
    x = 1e-8 * np.sin(2 * np.pi * t)
    x[:100] += 1.0  # a kick: relative to the record the window is at rest
    assert classify(t, x).kind == "decay"
    assert classify(t, x, scale=1e-6).kind == "lco"  # a 1e-8 LCO matters for a 1e-6 gap


# ------------------------------------------------- sustained, not periodic (issue 40)
# A bounded, stationary motion is a sustained oscillation whatever its class; these were
# "aperiodic" (not settled) before issue 40. tests/test_lco_verdicts.py has randomized ones.


@pytest.mark.parametrize("r, ratio", [(0.6, 1 + (math.sqrt(5) - 1) / 8), (0.3, math.sqrt(2))])
def test_beating_of_incommensurate_sines_is_quasi_periodic(r, ratio):
    """sin(w1 t) + r sin(w2 t) with c = r w2 / w1 < 1: the extremes (zeros of
    cos(w1 t) + c cos(w2 t)) stay within asin(c) / w1 of those of sin(w1 t), so the mean
    cycle rate is f1 to 2 asin(c) / (w1 span), span > T - 3 / f1. Its spectrum is two lines:
    the carrier f1 (within a hundredth of a bin) and the modulation f2 - f1."""
    f1, t = 1.0, np.arange(0.0, 200.0, 1e-3)
    v = classify(t, np.sin(2 * np.pi * f1 * t) + r * np.sin(2 * np.pi * ratio * f1 * t))
    assert (v.kind, v.confidence) == ("quasi-periodic", "high"), v.reason
    assert v.sustained
    span = v.window[1] - v.window[0]
    assert v.frequency == pytest.approx(f1, abs=0.02 / span)
    assert v.modulation == pytest.approx((ratio - 1) * f1, abs=0.02 / span)
    assert v.broadband < 1e-6
    assert v.peak["signal"] <= 1 + r


@pytest.mark.parametrize("component", [0, 2])
def test_lorenz_attractor_is_chaotic(component):
    sol = solve_ivp(
        lambda _, y: [10 * (y[1] - y[0]), y[0] * (28 - y[2]) - y[1], y[0] * y[1] - 8 / 3 * y[2]],
        (0.0, 100.0),
        [1.0, 1.0, 1.0],
        t_eval=np.arange(0.0, 100.0, 0.01),
        rtol=1e-9,
        atol=1e-9,
    )
    v = classify(sol.t, sol.y[component])
    assert v.kind == "chaotic", v.reason
    assert v.confidence in ("high", "medium")
    assert v.broadband > 0.02 and math.isnan(v.modulation)


def test_logistic_map_driven_amplitudes_are_chaotic():
    """Cycle amplitudes from the logistic map at r = 4 (chaotic), one per period: a 1 Hz line
    on a continuous spectrum."""
    a = np.empty(60)
    a[0] = 0.3
    for k in range(59):
        a[k + 1] = 4 * a[k] * (1 - a[k])
    t = np.arange(0.0, 60.0, 1e-3)
    v = classify(t, (0.5 + a[t.astype(int)]) * np.sin(2 * np.pi * t))
    assert v.kind == "chaotic", v.reason
    assert v.frequency == pytest.approx(1.0, abs=0.02 / 30)


# ---------------------------------------------------------------------------- undecided, NaN


@pytest.mark.parametrize("periods", [1.5, 3.0])
def test_too_few_cycles_is_undecided(periods):
    t = np.arange(0.0, 2 * periods, 1e-3)  # the window holds `periods` cycles
    v = classify(t, np.sin(2 * np.pi * t))
    assert (v.kind, v.confidence) == ("undecided", "low"), v.reason
    assert "min_cycles = 4" in v.reason


def test_min_cycles_sets_the_cycles_needed():
    t = np.arange(0.0, 7.0, 1e-3)  # 3.5 cycles in the window
    assert classify(t, np.sin(2 * np.pi * t)).kind == "undecided"
    v = classify(t, np.sin(2 * np.pi * t), min_cycles=2)
    assert (v.kind, v.confidence) == ("lco", "medium"), v.reason


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_values_are_divergence(bad):
    t = np.arange(0.0, 40.0, 1e-2)
    x = np.exp(0.3 * t) * np.sin(2 * np.pi * t)
    y = np.cos(t)
    y[3000] = bad
    v = classify(t, {"x": x, "y": y})
    assert (v.kind, v.confidence) == ("divergence", "high")
    assert "non-finite values from t = 30 s (in 'y')" in v.reason
    assert v.window == pytest.approx((20.0, 30.0))
    assert v.peak["y"] == pytest.approx(0.5 * np.ptp(np.cos(t[2000:3000])))
    json.dumps(v.as_dict(), allow_nan=False)


def test_as_dict_is_json():
    t = np.arange(0.0, 40.0, 1e-3)
    v = classify(t, np.sin(2 * np.pi * t))
    assert isinstance(v, LCOVerdict)
    d = json.loads(json.dumps(v.as_dict(), allow_nan=False))
    assert d["kind"] == "lco" and d["window"] == list(v.window)
    assert set(d) == {
        "kind", "confidence", "reason", "frequency", "peak", "rms", "mean",
        "window", "cycles", "growth", "reference", "modulation", "broadband",
    }  # fmt: skip
    assert d["modulation"] is None and d["broadband"] is None  # a limit cycle has neither


# ---------------------------------------------------------------------------- bad input


T = np.arange(0.0, 10.0, 0.01)
X = np.sin(2 * np.pi * T)


@pytest.mark.parametrize(
    "args, kwargs, message",
    [
        ((T.reshape(2, -1), X), {}, "t has shape (2, 500): expected a 1-D array"),
        ((T, X[:-1]), {}, "signals['signal'] has 999 samples but t has 1000"),
        ((T, {"a": X, "b": X[:10]}), {}, "signals['b'] has 10 samples"),
        ((T, {"a": np.c_[X, X]}), {}, "signals['a'] has shape (1000, 2)"),
        ((T[::-1], X), {}, "t[1] = 9.98 after t[0] = 9.99: t must increase"),
        ((np.r_[T[:5], T[4:]], np.r_[X, 0.0]), {}, "t must increase"),
        ((T[:1], X[:1]), {}, "t has 1 samples: at least 2 are needed"),
        ((np.r_[T[:-1], np.nan], X), {}, "t[999] = nan: sample times must be finite"),
        ((T, {}), {}, "signals is empty"),
        ((T, {"a": ["x"] * 1000}), {}, "signals['a'] = "),
        ((T, X + 1j), {}, "expected real numbers"),
        ((T, {1: X}), {}, "signal name 1: must be a string"),
        ((T, X), {"reference": "theta"}, "reference = 'theta': not a signal"),
        ((T, X), {"settle": 1.0}, "settle = 1"),
        ((T, X), {"tol": 0.0}, "tol = 0"),
        ((T, X), {"min_cycles": 1}, "min_cycles = 1"),
        ((T, X), {"scale": -1.0}, "scale = -1"),
        ((T, X), {"scale": "big"}, "scale = 'big'"),
    ],
)
def test_bad_input_is_one_clear_line(args, kwargs, message):
    with pytest.raises(InputError, match=re.escape(message)) as err:
        classify(*args, **kwargs)
    assert message in str(err.value)
    assert "\n" not in str(err.value)
