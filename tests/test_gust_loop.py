"""Tuned discrete gusts (CS-25.341(a)) with a controller in the loop.

Independent references, all in this file:

* the sampled loop closed by hand: the plant discretized exactly between samples with the
  command held (zero-order hold) and the gust linear between samples (first-order hold, Van
  Loan's augmented exponential), a static output gain ``u_k = -K y_k`` applied at each sample;
  the package holds the gust at its mid-sample value instead (midpoint rule), so the two agree
  to second order in the sample period: ``(omega dt)^2 / 24`` with omega up to the 2nd torsion
  frequency (~40 Hz) at dt = 1 ms is 1e-4; the tolerance is 2e-4 of the peak;
* the open loop marched by the exact first-order hold (no controller) against the sampled march
  with a controller that commands nothing (same second-order bound);
* the tuning: every peak of a dense scan of gradients stays below the reported extreme.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

import aeroservo as aes
from aeroservo.aero.gust_rules import GRADIENT_RANGE
from aeroservo.design.interface import static_gain
from aeroservo.design.loop import ControlLoop
from aeroservo.design.plant import Limits, OpenLoop
from aeroservo.errors import InputError
from aeroservo.studies.gust.march import LoopGustMarch, profile
from aeroservo.studies.gust.tuned import tuned_gust_loads
from aeroservo.system.aeroelastic import AeroelasticModel

LOADS = ["root_shear", "root_bending_moment", "root_torque", "tip_twist", "aileron_deflection"]
CONTROL = "aileron_hinge_moment"
RATE = 1000.0  # Hz


@pytest.fixture(scope="module")
def plant():
    """Goland wing with aileron, 6 elements, sea level, 100 m/s (V_f = 137 m/s)."""
    model = AeroelasticModel(aes.examples.goland_aileron(), 6)
    loop = ControlLoop(model, 1.225, [CONTROL], ["tip_twist"], LOADS, design_modes=None)
    sys = loop.plant(100.0)
    sys.density = 1.225
    return sys


def _unit(h: float) -> float:
    return 10.0  # m/s true, every gradient


def _hand_loop(sys, K: float, h: float, amp: float, n: int, dt: float) -> np.ndarray:
    """Outputs at the samples of ``u_k = -K twist_k`` closed by hand (see the module doc)."""
    ins = list(sys.input_labels)
    A = np.asarray(sys.A)
    Bu = np.asarray(sys.B)[:, ins.index(CONTROL)]
    Bw = np.asarray(sys.B)[:, ins.index("gust")]
    C, D = np.asarray(sys.C), np.asarray(sys.D)
    Du, Dw = D[:, ins.index(CONTROL)], D[:, ins.index("gust")]
    k_tw = list(sys.output_labels).index("tip_twist")
    m = A.shape[0]
    M = np.zeros((m + 3, m + 3))
    M[:m, :m], M[:m, m], M[:m, m + 1] = A * dt, Bu * dt, Bw * dt
    M[m + 1, m + 2] = 1.0
    E = sla.expm(M)
    Phi, Gu, G0, G1 = E[:m, :m], E[:m, m], E[:m, m + 1], E[:m, m + 2]
    t = np.arange(n) * dt
    w = amp * profile(t, float(sys.speed), h)
    x = np.zeros(m)
    y = np.zeros((n, C.shape[0]))
    for k in range(n):
        # the sensor read before the command (sensor feedthrough of the command is zero)
        u = -K * (C[k_tw] @ x + Dw[k_tw] * w[k])
        y[k] = C @ x + Du * u + Dw * w[k]
        if k + 1 < n:
            x = Phi @ x + Gu * u + G0 * w[k] + G1 * (w[k + 1] - w[k])
    return y


@pytest.mark.parametrize("gain", [2e4, 4e4])
def test_sampled_loop_against_a_loop_closed_by_hand(plant, gain):
    assert abs(np.asarray(plant.D)[list(plant.output_labels).index("tip_twist")][0]) == 0.0
    ctrl = static_gain([[gain]], [CONTROL], sensors=["tip_twist"], sample_rate=RATE)
    march = LoopGustMarch(plant, ctrl)
    h, amp = 20.0, 8.0
    t, y, lim = march.response(h, amp, 0.6)
    ref = _hand_loop(plant, gain, h, amp, t.size, 1.0 / RATE)
    n_out = ref.shape[1]
    scale = np.abs(ref).max(axis=0)
    err = np.abs(y[:, :n_out] - ref).max(axis=0) / scale
    assert err.max() < 2e-4, dict(zip(plant.output_labels, err, strict=True))
    # the command applied is an output too (the actuator's hinge moment)
    twist = ref[:, list(plant.output_labels).index("tip_twist")]
    cmd = y[:, list(march.outputs).index(CONTROL)]
    assert np.abs(cmd + gain * twist).max() < 2e-4 * np.abs(gain * twist).max()
    assert lim == {CONTROL: 0.0}  # seconds at a limit


def test_a_loop_that_commands_nothing_is_the_open_loop(plant):
    ol = tuned_gust_loads(plant, 0.0, amplitude=_unit, n_gradients=6)
    cl = tuned_gust_loads(
        plant, 0.0, amplitude=_unit, n_gradients=6, controller=OpenLoop((CONTROL,), 1 / RATE)
    )
    # a linear law: the loop is odd, only the up gust is marched (the down gust mirrors it)
    assert cl.controller != "open loop" and cl.peaks_negative is None
    for name in LOADS:
        a, b = ol.extremes[name], cl.extremes[name]
        assert b.maximum == pytest.approx(a.maximum, rel=2e-4), name
        assert b.minimum == pytest.approx(a.minimum, rel=2e-4), name
        assert b.max_gradient == pytest.approx(a.max_gradient, rel=0.02), name
    assert cl.extremes[CONTROL].maximum == 0.0 and not cl.saturated


def test_saturation_is_reported_and_the_command_never_exceeds_its_limit(plant):
    ctrl = static_gain([[4e4]], [CONTROL], sensors=["tip_twist"], sample_rate=RATE)
    free = tuned_gust_loads(plant, 0.0, controller=ctrl, n_gradients=5)
    cap = 0.5 * free.extremes[CONTROL].maximum
    lim = Limits({CONTROL: cap})
    res = tuned_gust_loads(plant, 0.0, controller=ctrl, limits=lim, n_gradients=5)
    assert res.saturated and res.limited[CONTROL].max() > 0
    assert res.extremes[CONTROL].maximum == pytest.approx(cap, rel=1e-12)
    # time at the limit [s] (issue 38: not a share of a march whose length is arbitrary):
    # counted here from the applied command of one gust, samples at the cap x the period
    march = LoopGustMarch(plant, ctrl, lim)
    h = float(res.gradients[-1])
    t, y, at_limit = march.response(h, float(res.amplitudes[-1]), 2 * h / plant.speed + 1.0)
    u = y[:, list(march.outputs).index(CONTROL)]
    counted = np.count_nonzero(np.abs(u) >= cap * (1 - 1e-12)) * (t[1] - t[0])
    assert counted > 0 and at_limit[CONTROL] == pytest.approx(counted, rel=1e-12)
    assert res.limited[CONTROL][-1, 0] == pytest.approx(counted, rel=1e-12)
    longer = march.response(h, float(res.amplitudes[-1]), 2 * h / plant.speed + 3.0)[2]
    assert longer[CONTROL] == pytest.approx(counted, rel=1e-12)  # march length does not count
    assert not free.saturated
    # a symmetric limit keeps the loop odd: the down gust, marched here, is exactly minus the
    # up gust (bit for bit), so the search marches only the up gust (peaks_negative None)
    assert res.peaks_negative is None
    for k in (0, len(res.gradients) // 2, -1):
        h, amp = float(res.gradients[k]), float(res.amplitudes[k])
        _t, up, lim_up = march.response(h, amp, 2 * h / plant.speed + 1.0)
        _t, down, lim_down = march.response(h, -amp, 2 * h / plant.speed + 1.0)
        np.testing.assert_array_equal(down, -up)
        assert lim_down == lim_up
    # the correlated loads at the time of an extreme are the history at that time
    e = res.extremes["root_bending_moment"]
    t, gust, y = res.history("root_bending_moment", "max")
    assert y["root_bending_moment"].max() <= e.maximum * (1 + 1e-12)
    assert e.max_correlated["root_bending_moment"] == pytest.approx(e.maximum, rel=1e-3)
    assert np.max(np.abs(gust)) == pytest.approx(abs(res.amplitudes).max(), rel=0.05)


def test_tuned_closed_loop_extremes_bound_a_dense_scan(plant):
    ctrl = static_gain([[4e4]], [CONTROL], sensors=["tip_twist"], sample_rate=RATE)
    res = tuned_gust_loads(plant, 0.0, controller=ctrl, n_gradients=8)
    dense = tuned_gust_loads(plant, 0.0, controller=ctrl, n_gradients=40, refine=False)
    # the down gust is minus the up gust (bit for bit: the saturation test), both sides kept
    neg = -dense.peaks[:, :, ::-1]
    for i, name in enumerate(res.loads):
        e = res.extremes[name]
        hi = max(dense.peaks[:, i, 0].max(), neg[:, i, 0].max())
        lo = min(dense.peaks[:, i, 1].min(), neg[:, i, 1].min())
        assert e.maximum >= hi * (1 - 1e-9) - 1e-12, name
        assert e.minimum <= lo * (1 - 1e-9) + 1e-12, name
        assert GRADIENT_RANGE[0] <= e.max_gradient <= GRADIENT_RANGE[1]


def test_an_unstable_loop_is_refused(plant):
    ctrl = static_gain([[-5e6]], [CONTROL], sensors=["tip_twist"], sample_rate=RATE)
    with pytest.raises(InputError, match="closed loop at 100 m/s TAS is unstable"):
        tuned_gust_loads(plant, 0.0, controller=ctrl, n_gradients=4)


def test_the_open_loop_above_flutter_is_refused():
    model = AeroelasticModel(aes.examples.goland_aileron(), 6)
    loop = ControlLoop(model, 1.225, [CONTROL], ["tip_twist"], LOADS, design_modes=None)
    fast = loop.plant(150.0)
    fast.density = 1.225
    with pytest.raises(InputError, match="unstable or neutral pole"):
        tuned_gust_loads(fast, 0.0, n_gradients=4)
