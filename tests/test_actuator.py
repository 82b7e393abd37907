"""Actuator dynamics in the loop (issue 38 item 1): a transfer function of order 1 to 3 in series
with each control, position and rate limits on its output, a one-sample computational delay by
default in scenario files.

Independent checks written here:

* the plant with actuators against the bare plant times the transfer functions written out in
  this file (the form of Waszak & Fung, NASA TM-1998-208452, for order 3), at random
  frequencies and random actuators;
* the margins of a loop closed around that plant against those of the same loop built with
  python-control's ``series`` from ``tf2ss`` of the same transfer function;
* the limited march against a march written here: the whole plant advanced in steps of
  ``dt / 100`` by its exact exponential, the actuator clamped after each step (rate, then
  position), the command held over each sample.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import control
import numpy as np
import pytest
import scipy.linalg as sla

from aeroservo.design import static_gain
from aeroservo.design.actuator import ActuatorDynamics
from aeroservo.design.loop import ControlLoop
from aeroservo.design.margins import loop_margins
from aeroservo.design.plant import Limits
from aeroservo.errors import InputError
from aeroservo.simulate import simulate
from aeroservo.structure.examples import goland_aileron
from aeroservo.system.aeroelastic import AeroelasticModel

ROOT = Path(__file__).resolve().parents[1]
HM = "aileron_hinge_moment"
TWO_PI = 2.0 * np.pi


@pytest.fixture(scope="module")
def model():
    return AeroelasticModel(goland_aileron(), 4)


def _loop(model, actuator, sensors=("tip_twist",), sensor_filter=None):
    return ControlLoop(model, 1.225, [HM], list(sensors), ["tip_disp"], actuator=actuator,
                       sensor_filter=sensor_filter)  # fmt: skip


def _tf(act: ActuatorDynamics, s):
    """The actuator's transfer function, written out."""
    w, z = act.bandwidth, act.damping
    if act.order == 1:
        return w / (s + w)
    pair = w * w / (s * s + 2 * z * w * s + w * w)
    return pair if act.order == 2 else pair * act.pole / (s + act.pole)


def _random_actuators(seed: int, n: int) -> list[ActuatorDynamics]:
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        order = 1 + k % 3
        w = TWO_PI * rng.uniform(8.0, 80.0)
        out.append(ActuatorDynamics(order, w, rng.uniform(0.3, 1.2),
                            TWO_PI * rng.uniform(10.0, 120.0) if order == 3 else None))  # fmt: skip
    return out


@pytest.mark.parametrize("act", _random_actuators(38, 6), ids=lambda a: a.text())
def test_plant_is_bare_plant_times_the_transfer_function(model, act):
    bare = _loop(model, None, sensor_filter=30.0, sensors=("tip_le_accel", "tip_twist")).plant(
        120.0
    )
    with_act = _loop(model, act, sensor_filter=30.0, sensors=("tip_le_accel", "tip_twist"))
    P = with_act.plant(120.0)
    i = list(P.input_labels).index(HM)
    rng = np.random.default_rng(1)
    for f in rng.uniform(0.2, 200.0, 5):
        s = 1j * TWO_PI * f
        G0, G = bare(s), P(s)
        for out in ("tip_le_accel", "tip_twist", "tip_disp"):
            a, b = G[P.output_labels.index(out), i], G0[bare.output_labels.index(out), i]
            assert abs(a - b * _tf(act, s)) <= 1e-9 * abs(b * _tf(act, s))
        # the actuator's own outputs: its position and its rate
        pos = G[P.output_labels.index(f"{HM}_actuator"), i]
        rate = G[P.output_labels.index(f"{HM}_actuator_rate"), i]
        assert abs(pos - _tf(act, s)) <= 1e-12 * abs(_tf(act, s))
        assert abs(rate - s * _tf(act, s)) <= 1e-9 * abs(s * _tf(act, s))
    # gust input unchanged, actuator states appended last, units named
    assert P.state_labels[-act.order :] == [f"{HM}{x}" for x in
                                           ("_actuator", "_actuator_rate", "_actuator_lag")][: act.order]  # fmt: skip
    assert P.signal_units[f"{HM}_actuator_rate"] == "N m/s"
    assert with_act.n_plant_states == P.nstates == len(with_act.state_labels)


def test_margins_match_a_series_built_by_python_control(model):
    """Margins broken at the actuator command: the toolkit's augmented plant and a plant built
    here with ``control.series`` give the same figures (the actuator is inside the loop)."""
    act = ActuatorDynamics(3, TWO_PI * 25.0, 0.7, TWO_PI * 40.0)
    bare = _loop(model, None).plant(130.0)
    num = [act.pole * act.bandwidth**2]
    den = np.polymul([1.0, act.pole], [1.0, 2 * act.damping * act.bandwidth, act.bandwidth**2])
    a_ss = control.tf2ss(num, den)
    a_ss = control.ss(a_ss.A, a_ss.B, a_ss.C, a_ss.D, inputs=[HM], outputs=["y_act"])
    bare_in = control.ss(bare.A, bare.B, bare.C, bare.D, inputs=["y_act", "gust"],
                         outputs=list(bare.output_labels))  # fmt: skip
    hand = control.interconnect([a_ss, bare_in], inplist=[HM, "gust"], inputs=[HM, "gust"],
                                outlist=list(bare.output_labels),
                                outputs=list(bare.output_labels))  # fmt: skip
    hand.speed = 130.0
    mine = _loop(model, act).plant(130.0)
    K = static_gain(np.array([[-2e4]]), [HM], sensors=["tip_twist"], sample_rate=1000.0, sign=-1)
    for delay in (False, True):
        ma, mb = loop_margins(mine, K, delay=delay), loop_margins(hand, K, delay=delay)
        pairs = [(ma.channels[HM], mb.channels[HM])]  # at the actuator command
        pairs += [(ma.sensors[s], mb.sensors[s]) for s in mb.sensors]  # and at the sensor
        assert len(pairs) == 2
        for a, b in pairs:
            assert a.stable == b.stable
            for key in ("gain_margin_db", "gain_reduction_margin_db", "phase_margin_deg"):
                x, y = getattr(a, key), getattr(b, key)
                assert x == pytest.approx(y, rel=1e-6, abs=1e-6), key
            assert a.delay_margin == pytest.approx(b.delay_margin, rel=1e-6)


def _reference_march(P, x0, K, mag, rate, duration, dt=1e-3, sub=100):
    """Independent limited march: the whole plant advanced in ``sub`` exact steps per sample,
    the actuator clamped after each (rate then position), command ``c = -K y`` clipped to the
    position limit (the computer's authority) and held."""
    A, B, C = (np.asarray(x) for x in (P.A, P.B, P.C))
    st = list(P.state_labels)
    i_u = list(P.input_labels).index(HM)
    i_y = list(P.output_labels).index("tip_twist")
    ia = [
        st.index(HM + s) for s in ("_actuator", "_actuator_rate", "_actuator_lag") if HM + s in st
    ]
    h = dt / sub
    n = A.shape[0]
    E = sla.expm(np.block([[A, B[:, [i_u]]], [np.zeros((1, n + 1))]]) * h)
    Phi, G = E[:n, :n], E[:n, n]
    order = len(ia)
    x = np.array(x0, float)
    out = []
    for _k in range(int(round(duration / dt)) + 1):
        out.append(x.copy())
        c = np.clip(-K * (C[i_y] @ x), -mag, mag)
        for _ in range(sub):
            y0 = x[ia[0]]
            x = Phi @ x + G * c
            if order == 1:
                x[ia[0]] = np.clip(x[ia[0]], y0 - rate * h, y0 + rate * h)
            else:
                x[ia[1]] = np.clip(x[ia[1]], -rate, rate)
            if abs(x[ia[0]]) > mag:
                x[ia[0]] = np.sign(x[ia[0]]) * mag
                if order > 1 and x[ia[1]] * x[ia[0]] > 0:
                    x[ia[1]] = 0.0
    return np.array(out), ia


CASES = [  # (order, position limit [N m], rate limit [N m/s], tolerance on tip and actuator)
    (1, 400.0, 1e9, 1e-4), (2, 400.0, 1e9, 1e-5), (3, 400.0, 1e9, 1e-5),
    (1, 1e9, 2e4, 5e-4), (2, 1e9, 2e4, 3e-3), (3, 1e9, 2e4, 3e-3),
    (2, 500.0, 2.5e4, 3e-3),
]  # fmt: skip


@pytest.mark.parametrize("order, mag, rate, tol", CASES)
def test_limited_march_against_a_fine_march(model, order, mag, rate, tol):
    act = ActuatorDynamics(order, TWO_PI * 20.0, 0.7, TWO_PI * 30.0 if order == 3 else None)
    loop = _loop(model, act)
    P = loop.plant(100.0)
    Kg = -5e4  # a stabilising twist feedback that saturates from a 5 cm tip deflection
    K = static_gain(np.array([[Kg]]), [HM], sensors=["tip_twist"], sample_rate=1000.0, sign=-1)
    x0 = loop.initial_state(0.05)
    lim = Limits({HM: mag} if mag < 1e8 else {}, {HM: rate} if rate < 1e8 else {})
    r = simulate(P, K, duration=0.3, x0=x0, limits=lim)
    X, ia = _reference_march(P, x0, Kg, mag, rate, 0.3)
    free = simulate(P, K, duration=0.3, x0=x0)
    y_free = free.outputs[f"{HM}_actuator"]
    assert np.max(np.abs(y_free)) > 1.3 * min(mag, 1e30) or np.max(
        np.abs(free.outputs[f"{HM}_actuator_rate"])) > 1.3 * min(rate, 1e30)  # fmt: skip
    C = np.asarray(P.C)
    tip_ref = X @ C[list(P.output_labels).index("tip_disp")]
    tip = r.outputs["tip_disp"]
    assert np.max(np.abs(tip - tip_ref)) <= tol * np.max(np.abs(tip_ref))
    y = r.outputs[f"{HM}_actuator"]
    assert np.max(np.abs(y - X[:, ia[0]])) <= max(tol * 10, 1e-6) * np.max(np.abs(X[:, ia[0]]))
    # the limits hold on what the plant receives, and its rate
    assert np.max(np.abs(y)) <= mag * (1 + 1e-12)
    assert np.max(np.abs(r.outputs[f"{HM}_actuator_rate"])) <= rate * (1 + 1e-9)
    # the command keeps its magnitude limit only (the rate limit bounds the actuator output)
    assert np.array_equal(np.clip(r.commands[HM], -mag, mag), r.applied[HM])


def test_unreached_limits_leave_the_march_exact(model):
    act = ActuatorDynamics(3, TWO_PI * 25.0, 0.7, TWO_PI * 40.0)
    loop = _loop(model, act)
    P = loop.plant(100.0)
    K = static_gain(np.array([[-2e4]]), [HM], sensors=["tip_twist"], sample_rate=1000.0, sign=-1)
    x0 = loop.initial_state(0.01)
    free = simulate(P, K, duration=0.5, x0=x0)
    peak = max(np.max(np.abs(free.outputs[f"{HM}_actuator"])), np.max(np.abs(free.commands[HM])))
    lim = simulate(P, K, duration=0.5, x0=x0, limits=Limits({HM: 1.01 * peak}, {}))
    assert np.array_equal(lim.outputs["tip_disp"], free.outputs["tip_disp"])


def test_actuator_inputs_are_checked():
    with pytest.raises(InputError, match=r"actuator.order = 4"):
        ActuatorDynamics(4, 100.0)
    with pytest.raises(InputError, match=r"actuator.pole .*only an order-3"):
        ActuatorDynamics(2, 100.0, pole=50.0)
    with pytest.raises(InputError, match=r"actuator.bandwidth = -1"):
        ActuatorDynamics(1, -1.0)


def _scenario(tmp_path, table: str, kind_file="goland_aileron_lqr.toml"):
    from aeroservo.files.scenario_file import load_scenario

    text = (ROOT / "scenarios" / kind_file).read_text()
    start = text.index("[actuator]")
    end = text.index("\n[", start + 1) + 1
    text = text[:start] + table + text[end:]
    text = text.replace(
        'file = "goland_aileron.toml"', f'file = "{ROOT}/scenarios/goland_aileron.toml"'
    )
    text = text.replace('spec = "../controllers/', f'spec = "{ROOT}/controllers/')
    p = tmp_path / "s.toml"
    p.write_text(text)
    return load_scenario(p), p


@pytest.mark.parametrize(
    "table, match",
    [
        ("[actuator]\norder = 4\nbandwidth_hz = 20.0\n", r"actuator.order = 4: allowed range"),
        ("[actuator]\norder = 2\nbandwidth_hz = 20.0\npole_hz = 30.0\n", r"actuator.pole_hz = 30"),
        ("[actuator]\norder = 2\nbandwidth_hz = -20.0\n", r"actuator.bandwidth_hz = -20"),
        ("[actuator]\norder = 2\n", r"actuator.bandwidth_hz: missing required key"),
        (
            "[actuator]\norder = 2\nbandwidth_hz = 20.0\nspeed = 3\n",
            r"actuator.speed = 3: unknown key",
        ),
        (
            "[actuator.flap_hinge_moment]\norder = 2\nbandwidth_hz = 20.0\n",
            r"actuator.flap_hinge_moment = .*not a control of this scenario",
        ),
    ],
)
def test_bad_actuator_tables_name_file_and_key(tmp_path, table, match):
    with pytest.raises(InputError, match=r"s\.toml: " + match):
        _scenario(tmp_path, table)


def test_shipped_scenarios_have_an_actuator_and_the_delay(tmp_path):
    s, _ = _scenario(tmp_path, "[actuator]\norder = 1\nbandwidth_hz = 30.0\n")
    assert s.actuator[HM].order == 1 and s.actuator[HM].bandwidth == pytest.approx(TWO_PI * 30)
    s, _ = _scenario(tmp_path, f"[actuator.{HM}]\norder = 3\nbandwidth_hz = 25.0\npole_hz = 40.0\n")
    assert s.actuator[HM].pole == pytest.approx(TWO_PI * 40.0)
    from aeroservo.files.scenario_file import load_scenario

    for name in ("lqr", "lqg", "hinf", "mpc", "gust", "gust_loads"):
        sc = load_scenario(ROOT / "scenarios" / f"goland_aileron_{name}.toml")
        assert sc.delay is True
        assert sc.actuator[HM].order == 3
        assert sc.actuator[HM].bandwidth == pytest.approx(TWO_PI * 25.0)


SERVO_TABLE = "\n[actuator]\norder = 2\nbandwidth_hz = 20.0\n"


def _shipped_copy(tmp_path, stem: str, extra: str = ""):
    """A shipped scenario written to ``tmp_path/t.toml`` with absolute paths and ``extra``."""
    text = (ROOT / "scenarios" / f"{stem}.toml").read_text()
    text = text.replace(
        'file = "goland_aileron.toml"', f'file = "{ROOT}/scenarios/goland_aileron.toml"'
    )
    p = tmp_path / "t.toml"
    p.write_text(text.replace('"../controllers/', f'"{ROOT}/controllers/') + extra)
    return p


def test_actuator_refused_where_not_modelled(tmp_path):
    """Limit-cycle studies march their own hinge plant: no actuator dynamics there yet."""
    from aeroservo.files.scenario_file import load_scenario

    p = _shipped_copy(tmp_path, "goland_aileron_freeplay_lqr", SERVO_TABLE)
    with pytest.raises(
        InputError, match=r"t\.toml: actuator = .*not used by a scenario of kind 'lco'"
    ):
        load_scenario(p)


def test_trade_study_carries_the_actuator_and_the_delay(tmp_path):
    from aeroservo.files.scenario_file import load_scenario
    from aeroservo.studies.runs import study_from_scenario
    from aeroservo.studies.trade.grid import case_id

    plain = study_from_scenario(load_scenario(_shipped_copy(tmp_path, "trade_aileron")))
    act = study_from_scenario(load_scenario(_shipped_copy(tmp_path, "trade_aileron", SERVO_TABLE)))
    assert plain.delay is True and plain.actuator is None
    assert act.actuator[HM].order == 2
    assert case_id(plain, {}) != case_id(act, {})  # new settings, new case files
    one = dataclasses.replace(plain, actuator=ActuatorDynamics(1, 100.0))  # one for all
    assert one.actuator == {HM: ActuatorDynamics(1, 100.0)} and case_id(one, {})


def test_hinge_march_refuses_a_loop_with_an_actuator(model):
    from aeroservo.design.hinge_loop import loop_hinge_plant
    from aeroservo.structure.hinge_laws import Freeplay
    from aeroservo.system.hinge_elements import NonlinearHinge

    loop = _loop(model, ActuatorDynamics(2, TWO_PI * 20.0))
    with pytest.raises(InputError, match=r"loop_hinge_plant: the loop has actuator dynamics"):
        loop_hinge_plant(loop, [NonlinearHinge("aileron", Freeplay(0.01))], 100.0)
