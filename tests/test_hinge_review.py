"""Adversarial review of the march with nonlinear hinges and of the LCO study (issue 28).

Independent references, written here and never using the march's machinery (regions, modal
closed forms, switch location, sampled matrices, the controller's stepping):

* the Lur'e ODE ``x' = A x + B u + b_n phi(c_n x)`` of the plant's own matrices with the law's
  moment ``phi = k s - M(s)`` written here, integrated by scipy's DOP853 piece by piece (terminal
  events at the edges of the piece, restarted in the next one) over each sample with the input
  held; a smooth law (cubic) in one DOP853 call per sample;
* the sampled loop closed by hand: at sample k the sensors read
  ``y = C x + D u_{k-1} + D_n phi(c_n x)``, the command is computed from them (a gain, a Python
  function, or a linear law's matrices ``c = C s + D y``, ``s+ = A s + B y + L (u - c)``), then
  rate-limited against the last applied input and saturated.

Tolerances: the reference commits about its ``rtol`` (1e-12) per step; over ~100 samples and
~10 restarts of a lightly damped wing the global error is a few 1e-11 of each signal's peak
(measured at most 6e-11 for the piecewise-linear cases); loops that rate-limit amplify it a
little: 1e-8 allowed. The march of a smooth law runs DOP853 at rtol 1e-10 with one absolute
tolerance for all states: its own error sets the cubic tolerances (see each test).

Four tests reproduced defects found by this review (crossings taken in element order, grazes
missed within a sample and just after a switch, the record step changing the open loop, the
time of a divergence); they failed before the march was mended.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
from conftest import ROOT
from scipy.integrate import solve_ivp

import aeroservo as aes
from aeroservo.design import ControlLoop, Limits
from aeroservo.design.hinge_loop import loop_hinge_plant
from aeroservo.design.interface import python_law, static_gain
from aeroservo.design.sampled_loop import linear_law, plant_states
from aeroservo.errors import InputError
from aeroservo.files import load_controller
from aeroservo.linear.hinge_plant import nonlinear_plant, section_plant
from aeroservo.simulate.hinges.march import march_hinges
from aeroservo.structure.hinge_laws import Bilinear, Cubic, Freeplay
from aeroservo.studies.lco.result import _branch_at
from aeroservo.studies.lco.run import run_lco
from aeroservo.studies.lco.study import DIVERGED, LCOSetup, LCOSweep
from aeroservo.system.hinge_elements import NonlinearHinge
from aeroservo.system.section import CONNER, conner_section

RHO = 1.225
GAP = np.radians(1.0)  # rad, total, on the Goland aileron actuators (k = 8000 N m/rad)
SPEED = 120.0  # m/s, Goland with aileron (open-loop flutter 137.4 m/s)
DT = 1e-3  # s
REF_RTOL = 1e-12
TOL = 1e-8
"""Marches against the references, relative to each signal's peak (module docstring)."""
ACCEL_TOL = 1e-7
"""Accelerometers weigh the small, fast states heavily: there the reference's error (its
absolute tolerance is one for all states) shows, 3e-8 at most (1e-9 with rtol 1e-13)."""
AILERON = "aileron_hinge_moment"


# --- the independent reference ------------------------------------------------------------
def moment(law, k, s):
    """The law's restoring moment [N m] at the rotation ``s`` [rad], written from its
    definition: ``k_in (s - offset)`` in the band, ``k (s - edge) +- k_in gap/2`` beyond."""
    if isinstance(law, Cubic):
        return k * s + law.coefficient * s**3
    o, h, k_in = law.offset, 0.5 * law.gap, law.inner_ratio * k
    s = np.asarray(s, dtype=float)
    above, below = k * (s - o - h) + k_in * h, k * (s - o + h) - k_in * h
    return np.where(s > o + h, above, np.where(s < o - h, below, k_in * (s - o)))


def phi_of(elements, s):
    """``k s - M(s)`` per element."""
    return np.array(
        [
            k * v - moment(law, k, v)
            for law, k, v in zip(elements.laws, elements.stiffness, s, strict=True)
        ]
    )


def piece_of(law, s):
    """0 below the band, 1 in it, 2 above."""
    o, h = law.offset, 0.5 * law.gap
    return 0 if s < o - h else (2 if s > o + h else 1)


def affine(law, k, piece):
    """``phi = a s + c`` on a piece."""
    o, h, k_in = law.offset, 0.5 * law.gap, law.inner_ratio * k
    if piece == 1:
        return k - k_in, k_in * o
    if piece == 2:
        return 0.0, k * (o + h) - k_in * h
    return 0.0, k * (o - h) + k_in * h


def leaving_events(nplant, pieces):
    """Terminal events on the edges of the current pieces, in the direction that leaves them:
    ``(events, [(element, new piece)])``."""
    events, info = [], []
    for j, (law, p) in enumerate(zip(nplant.elements.laws, pieces, strict=True)):
        o, h = law.offset, 0.5 * law.gap
        cands = {0: [(o - h, 1, 1)], 1: [(o + h, 1, 2), (o - h, -1, 0)], 2: [(o + h, -1, 1)]}[p]
        for edge, direction, new in cands:

            def ev(_t, y, j=j, edge=edge):
                return nplant.c_n[j] @ y - edge

            ev.terminal, ev.direction = True, direction
            events.append(ev)
            info.append((j, new))
    return events, info


def reference_step(nplant, x, force, pieces, t0, switches, rtol=REF_RTOL):
    """``x`` after one sample with the constant forcing ``force`` (``B u``): DOP853 piece by
    piece (``pieces`` updated, crossing times appended to ``switches``), or in one call for
    smooth laws."""
    A, b_n, c_n, el = np.asarray(nplant.plant.A), nplant.b_n, nplant.c_n, nplant.elements
    atol = rtol * 1e-3 * max(np.abs(x).max(), 1e-30)
    if not el.piecewise_linear:
        sol = solve_ivp(
            lambda _t, y: A @ y + b_n @ phi_of(el, c_n @ y) + force, (0.0, DT), x,
            method="DOP853", rtol=rtol, atol=atol,
        )  # fmt: skip
        assert sol.success
        return sol.y[:, -1]
    t = 0.0
    while True:
        ac = [affine(law, k, p) for law, k, p in zip(el.laws, el.stiffness, pieces, strict=True)]
        a, c = np.array([v[0] for v in ac]), np.array([v[1] for v in ac])
        Ar, g = A + (b_n * a) @ c_n, b_n @ c + force
        events, info = leaving_events(nplant, pieces)
        sol = solve_ivp(
            lambda _t, y, Ar=Ar, g=g: Ar @ y + g, (t, DT), x, method="DOP853", rtol=rtol,
            atol=atol, events=events,
        )  # fmt: skip
        assert sol.success, sol.message
        x, t = sol.y[:, -1], sol.t[-1]
        if sol.status == 0:
            return x
        j, new = info[next(i for i, te in enumerate(sol.t_events) if te.size)]
        pieces[j] = new
        switches.append(t0 + t)


def hand_loop(nplant, x0, n_steps, controls=(), sensors=(), command=None, limits=None,
              delay=False, rtol=REF_RTOL):  # fmt: skip
    """The sampled loop closed by hand (module docstring): ``(X, U, Cmd, Y, seen, switches)``
    with ``Y`` every output of the plant and ``seen`` the sensor values at each sample.
    ``command(k, y, u_prev)`` gives the command from the sensors."""
    P = nplant.plant
    labels_in, labels_out = list(P.input_labels), list(P.output_labels)
    iu = [labels_in.index(c) for c in controls]
    isn = [labels_out.index(s) for s in sensors]
    C, D, Bu = np.asarray(P.C), np.asarray(P.D)[:, iu], np.asarray(P.B)[:, iu]
    m = len(iu)
    mag, rate = (limits or Limits()).arrays(list(controls))
    x = np.array(x0, dtype=float)
    pieces = [piece_of(law, v) if law.piecewise_linear else 0
              for law, v in zip(nplant.elements.laws, nplant.c_n @ x, strict=True)]  # fmt: skip
    out = {k: [] for k in ("X", "U", "Cmd", "Y", "seen")}
    h, pending, switches = np.zeros(m), np.zeros(m), []
    for k in range(n_steps + 1):
        y = C @ x + D @ h + nplant.d_n @ phi_of(nplant.elements, nplant.c_n @ x)
        c = np.asarray(command(k, y[isn], h), dtype=float) if m else np.zeros(0)
        if delay:
            c, pending = pending, c
        u = np.clip(np.clip(c, h - rate * DT, h + rate * DT), -mag, mag)
        for key, v in zip(out, (x.copy(), u, c, y, y[isn]), strict=True):
            out[key].append(v)
        if k == n_steps:
            break
        x = reference_step(nplant, x, Bu @ u, pieces, k * DT, switches, rtol)
        h = u
    return tuple(np.array(out[k]) for k in out) + (np.array(switches),)


def rel(a, b):
    """Largest error of ``a`` relative to the peak of ``b``."""
    return float(np.abs(np.asarray(a) - b).max() / np.abs(b).max())


def assert_same_march(res, ref, nplant, tol=TOL, controls=()):
    """States, outputs (accelerations to ``ACCEL_TOL`` or ``tol``), commands and inputs."""
    X, U, Cmd, Y = ref[:4]
    units = nplant.plant.signal_units
    assert rel(res.states, X) < tol
    for i, name in enumerate(nplant.plant.output_labels):
        t = max(tol, ACCEL_TOL) if units.get(name) == "m/s^2" else tol
        assert rel(res.outputs[name], Y[:, i]) < t, name
    for i, c in enumerate(controls):
        assert rel(res.commands[c], Cmd[:, i]) < tol, c
        assert rel(res.applied[c], U[:, i]) < tol, c


class Recorder:
    """A protocol controller ``c = -K y`` that keeps the sensor values it is given."""

    def __init__(self, K, controls, sensors):
        self.K, self.controls, self.sensors, self.dt = np.atleast_2d(K), controls, sensors, DT
        self.seen: list = []

    def reset(self):
        self.seen = []

    def command(self, y, x=None):
        self.seen.append(np.array(y, dtype=float))
        return -self.K @ y

    def update(self, y, u):
        pass


# --- fixtures -------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def goland():
    return aes.AeroelasticModel(aes.examples.goland_aileron())


@pytest.fixture(scope="module")
def raw_loop(goland):
    """Aileron moment in, unfiltered tip accelerometer and twist out: the accelerometer has a
    direct feedthrough of the actuators' nonlinear moments (``D_n``)."""
    return ControlLoop(
        goland, RHO, [AILERON], ["tip_le_accel", "tip_twist"], ["tip_disp"], sensor_filter=None
    )


# 1. Output feedback with a direct feedthrough of the nonlinear moment ----------------------
SENSORS = ["tip_le_accel", "tip_twist"]
K_OUT = np.array([[0.2, -100.0]])  # N m per m/s^2, N m per rad
LIMITS = Limits(magnitude={AILERON: 40.0}, rate={AILERON: 2e4})


@pytest.mark.parametrize("delay", [False, True])
@pytest.mark.slow
def test_accelerometer_feedback_reads_the_nonlinear_moment(raw_loop, delay):
    """A gain on the unfiltered tip accelerometer and twist, freeplay with a preload on
    actuator2 (90 % span), rate limit active: the sensor values a protocol controller is given,
    the commands of the same gain as a linear law, the states and every output equal the hand
    loop, whose sensors include ``D_n phi`` (which matters: a few % of the acceleration's
    peak, 1e5 times the tolerance)."""
    nplant = loop_hinge_plant(
        raw_loop, [NonlinearHinge("actuator2", Freeplay(GAP, offset=0.3 * GAP))], SPEED
    )
    assert np.abs(nplant.d_n[0]).max() > 0.0
    x0 = nplant.initial_state(2 * GAP)
    n = 100
    ref = hand_loop(
        nplant, x0, n, [AILERON], SENSORS, lambda k, y, h: -K_OUT @ y, LIMITS, delay, rtol=1e-13
    )  # the rate limit amplifies the reference's error (1e-8 at 1e-12)
    X, U, Cmd, Y, seen, switches = ref
    assert switches.size >= 4
    assert np.mean(np.abs(np.diff(U[:, 0])) >= 20.0 * (1 - 1e-9)) > 0.1  # rate-limited
    phi_part = (phi_of(nplant.elements, (X @ nplant.c_n.T).T).T @ nplant.d_n.T)[:, 0]
    assert np.abs(phi_part).max() > 1e-3 * np.abs(Y[:, 0]).max()
    rec = Recorder(K_OUT, (AILERON,), tuple(SENSORS))
    res = march_hinges(nplant, rec, duration=n * DT, x0=x0, limits=LIMITS, delay=delay)
    assert_same_march(res, ref, nplant, controls=[AILERON])
    assert rel(np.array(rec.seen), seen) < TOL
    np.testing.assert_allclose(res.switches, switches, rtol=0, atol=1e-9)
    gain = static_gain(K_OUT, [AILERON], sensors=SENSORS, sample_rate=1 / DT)
    lin = march_hinges(nplant, gain, duration=n * DT, x0=x0, limits=LIMITS, delay=delay)
    assert_same_march(lin, ref, nplant, controls=[AILERON])


@pytest.mark.slow
def test_lqg_on_filtered_accelerometers(goland):
    """LQG of ``controllers/lqg.toml`` (Kalman filter on the 30 Hz filtered accelerometers and
    the twist) on the loop's default plant with freeplay on actuator1, one sample of delay,
    saturation and rate limit: the march equals the hand loop run with the law's matrices."""
    loop = ControlLoop(goland, RHO, [AILERON], ["tip_le_accel", "tip_te_accel", "tip_twist"],
                       ["tip_disp"], design_modes=20)  # fmt: skip
    spec = load_controller(ROOT / "controllers" / "lqg.toml")
    ctrl = loop.design_controller(spec, SPEED, 1 / DT, flutter_speed=137.4)
    nplant = loop_hinge_plant(loop, [NonlinearHinge("actuator1", Freeplay(GAP))], SPEED)
    assert np.abs(nplant.b_n[-4:]).max() > 0.0  # the filters see the moment (no D_n left)
    from aeroservo.design.law import delayed

    law = delayed(linear_law(ctrl.at(SPEED), plant_states(nplant.plant)))
    state = {"s": np.zeros(law.n_states), "last": None}

    def command(k, y, h):
        if state["last"] is not None:
            yp, cp = state["last"]
            state["s"] = law.A @ state["s"] + law.B @ yp + law.L @ (h - cp)
        c = law.C @ state["s"] + law.D @ y
        state["last"] = (y, c)
        return c

    limits = Limits(magnitude={AILERON: 100.0}, rate={AILERON: 3e4})
    x0 = nplant.initial_state(2 * GAP)
    n = 120
    ref = hand_loop(nplant, x0, n, [AILERON], list(law.sensors), command, limits)
    assert np.abs(ref[1]).max() == pytest.approx(100.0)  # saturates
    res = march_hinges(nplant, ctrl, duration=n * DT, x0=x0, limits=limits, delay=True)
    assert_same_march(res, ref, nplant, controls=[AILERON])
    np.testing.assert_allclose(res.switches, ref[-1], rtol=0, atol=1e-9)


def test_python_law_with_two_controls_and_a_bilinear_spring(raw_loop, goland):
    """Two controls (the aileron moment and, as a second input, the gust) from a Python law,
    a bilinear spring with an offset, both limits active on the vector path of the march."""
    loop = ControlLoop(goland, RHO, [AILERON, "gust"], SENSORS, ["tip_disp"], sensor_filter=None)
    nplant = loop_hinge_plant(
        loop, [NonlinearHinge("actuator1", Bilinear(GAP, -0.2 * GAP, 0.1))], SPEED
    )
    K = np.array([[0.1, -100.0], [0.001, 0.5]])
    limits = Limits(magnitude={AILERON: 40.0, "gust": 0.25}, rate={AILERON: 2e4, "gust": 300.0})
    law = python_law(lambda t, y: -K @ y, [AILERON, "gust"], SENSORS, sample_rate=1 / DT)
    x0 = nplant.initial_state(2 * GAP)
    n = 80
    ref = hand_loop(nplant, x0, n, [AILERON, "gust"], SENSORS, lambda k, y, h: -K @ y, limits,
                    rtol=1e-13)  # fmt: skip
    assert np.abs(ref[1][:, 1]).max() == pytest.approx(0.25)
    res = march_hinges(nplant, law, duration=n * DT, x0=x0, limits=limits)
    assert_same_march(res, ref, nplant, controls=[AILERON, "gust"])


# 2. Two elements, edges, tiny and huge gaps -------------------------------------------------
MIXED = [
    NonlinearHinge("actuator1", Freeplay(GAP)),
    NonlinearHinge("actuator2", Bilinear(0.6 * GAP, offset=0.25 * GAP, inner_ratio=0.2)),
]


@pytest.fixture(scope="module")
def mixed(goland):
    return nonlinear_plant(goland, MIXED, SPEED, RHO)


def _start(nplant, case):
    if case == "lower-edges":  # both exactly on the lower edge of their band, at rest
        return nplant.initial_state([-0.5 * GAP, 0.25 * GAP - 0.3 * GAP])
    x = nplant.initial_state([0.3 * GAP, 0.1 * GAP])  # inside both bands, a rotation rate
    return x + 30.0 * nplant.c_rate[0] / (nplant.c_rate[0] @ nplant.c_rate[0])


@pytest.mark.parametrize("case", ["lower-edges", "inside-with-rate"])
@pytest.mark.slow
def test_two_elements_with_different_laws(mixed, case):
    """Freeplay on actuator1, a bilinear spring with an offset on actuator2, regions of both
    visited: states, outputs and switch times equal the reference; each element's moment is
    its law's ``M(s)`` (restoring: the sign of ``s - offset`` beyond the band) and its rotation
    the output ``<actuator>_rotation``."""
    x0 = _start(mixed, case)
    n = 100
    ref = hand_loop(mixed, x0, n)
    res = march_hinges(mixed, duration=n * DT, x0=x0)
    assert ref[-1].size >= 5
    assert_same_march(res, ref, mixed)
    np.testing.assert_allclose(res.switches, ref[-1], rtol=0, atol=1e-9)
    for name, law, k in zip(
        mixed.elements.names, mixed.elements.laws, mixed.elements.stiffness, strict=True
    ):
        s, M = res.rotations[name], res.hinge_moments[name]
        np.testing.assert_array_equal(s, res.outputs[f"{name}_rotation"])
        expected = moment(law, k, s)
        assert np.abs(M - expected).max() <= 1e-12 * np.abs(expected).max()
        beyond = np.abs(s - law.offset) > 0.5 * law.gap
        assert np.all(np.sign(M[beyond]) == np.sign(s[beyond] - law.offset))
    assert any(
        (np.abs(res.rotations[name] - law.offset) > 0.5 * law.gap).any()
        for name, law in zip(mixed.elements.names, mixed.elements.laws, strict=True)
    )


def test_tiny_and_huge_gaps(goland):
    """A gap of 1e-6 rad moves the motion by O(gap) from the gap closed (at most 3 gaps here);
    a gap of 0.5 rad never reached gives the march of the actuator-free wing (spring removed:
    ``phi = k s``) to the reference's accuracy, without a switch."""
    x0 = None
    runs = {}
    for gap in (0.0, 1e-6, 0.5):
        nplant = nonlinear_plant(goland, [NonlinearHinge("aileron", Freeplay(gap))], SPEED, RHO)
        x0 = nplant.initial_state(0.01) if x0 is None else x0
        runs[gap] = march_hinges(nplant, duration=0.2, x0=x0), nplant
    s0 = runs[0.0][0].rotations["actuator1"]
    s1 = runs[1e-6][0].rotations["actuator1"]
    assert runs[1e-6][0].switches.size > 10
    assert 0.0 < np.abs(s1 - s0).max() < 3e-6
    res, nplant = runs[0.5]
    assert res.switches.size == 0
    n = 50
    ref = hand_loop(nplant, x0, n)
    assert rel(res.states[: n + 1], ref[0]) < TOL


# 3. Defects: crossings missed or put in the wrong order -------------------------------------
def test_two_elements_crossing_close_together_in_time_order(goland):
    """Both aileron actuators, 2 gaps at rest, open loop: near 17.45 ms actuator2 crosses its
    edge 3.9 us before actuator1, both within one of the 24 sub-intervals of the sample. The
    march switches actuator1 first and then actuator2 at the same instant (0.01745153 twice;
    the reference: 0.01744768 then 0.01745153)."""
    nplant = nonlinear_plant(goland, [NonlinearHinge("aileron", Freeplay(GAP))], SPEED, RHO)
    x0 = nplant.initial_state(2 * GAP)
    n = 20
    ref = hand_loop(nplant, x0, n)
    res = march_hinges(nplant, duration=n * DT, x0=x0)
    assert res.switches.size == ref[-1].size
    np.testing.assert_allclose(res.switches, ref[-1], rtol=0, atol=1e-9)
    assert_same_march(res, ref, nplant)


PEAK = 5.644043386564631e-4
"""|s| [rad] at the first peak (t = 1.054 ms) of actuator1's rotation, freeplay open, released
from rest with a unit rotation rate (``x0 = c_rate / |c_rate|^2``) at 120 m/s: found with expm
steps of 1 us of the free system."""


@pytest.mark.parametrize("excess", [1e-5, 1e-2])
def test_a_graze_within_a_sample_is_found(goland, excess):
    """The gap set so that actuator1 just passes its edge, by ``excess`` x gap/2, near 1.05 ms
    and comes back: the reference crosses out, in, and out again (near 1.05 ms
    for 1e-5 (1e-6 was used until numpy 2.4 / scipy 1.17 moved the peak by more than that); 0.9161, 1.2759, 1.4300 ms for 1e-2). The march at 1 ms finds the first crossing
    only and keeps the spring engaged while the rotation is back in the gap (state error 1.5e-4
    and 1e-5 of the peak): for 1e-5 the return follows the switch within the sample (the test
    from the interval's ends, ``quick_bracket``, is trusted right after a switch); for 1e-2 the return
    and the exit fall in the next sample, whose ends-only Hermite test (``leaves``) misses
    them."""
    gap = 2 * PEAK / (1 + excess)
    nplant = nonlinear_plant(goland, [NonlinearHinge("actuator1", Freeplay(gap))], SPEED, RHO)
    x0 = nplant.c_rate[0] / (nplant.c_rate[0] @ nplant.c_rate[0])
    n = 10
    ref = hand_loop(nplant, x0, n)
    assert ref[-1].size == 3
    res = march_hinges(nplant, duration=n * DT, x0=x0)
    assert res.switches.size == 3
    assert_same_march(res, ref, nplant)


def test_the_record_step_does_not_change_the_open_loop(goland):
    """Open loop, both aileron actuators from 2 gaps at 120 m/s: ``dt`` is only where the
    states are recorded, so records at 1 ms and at 10 us agree at the common instants (to
    rounding). They differ by 1.5e-4 of the gap: the 1 ms march misses 4 of 18 crossings."""
    nplant = nonlinear_plant(goland, [NonlinearHinge("aileron", Freeplay(GAP))], SPEED, RHO)
    coarse = march_hinges(nplant, duration=0.5, dt=1e-3, rotation0=2 * GAP)
    fine = march_hinges(nplant, duration=0.5, dt=1e-5, rotation0=2 * GAP)
    assert coarse.switches.size == fine.switches.size
    s, s_fine = coarse.rotations["actuator1"], fine.rotations["actuator1"][::100]
    assert np.abs(s - s_fine).max() < 1e-9 * GAP


# 4. A modal plant -----------------------------------------------------------------------------
def test_modal_plant_converges_to_the_full_plant(goland):
    """``n_modes`` in-vacuo modes (spring closed) against the full plant, both actuators free to
    play: finite and switching alike; the rotation within 25 % with 6 modes (the modes of the
    closed spring describe the open gap poorly) and 1e-4 with 20."""
    hinges = [NonlinearHinge("aileron", Freeplay(GAP))]
    full = march_hinges(
        nonlinear_plant(goland, hinges, SPEED, RHO), duration=1.0, rotation0=2 * GAP
    )
    errors, worst, warned = {}, {}, {}
    for n_modes in (6, 20):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            nplant = nonlinear_plant(goland, hinges, SPEED, RHO, n_modes=n_modes)
        said = [str(w.message) for w in caught if "hinge compliance" in str(w.message)]
        warned[n_modes] = said
        np.testing.assert_allclose(nplant.c_n @ nplant.initial_state(GAP), [GAP, GAP], rtol=1e-12)
        res = march_hinges(nplant, duration=1.0, rotation0=2 * GAP)
        assert np.all(np.isfinite(res.states)) and res.switches.size > 5
        errors[n_modes] = rel(res.rotations["actuator1"], full.rotations["actuator1"])
        worst[n_modes] = max(rel(res.rotations[a], full.rotations[a]) for a in res.rotations)
    assert errors[6] < 0.25
    assert errors[20] < 1e-4
    # the truncation is said where it matters (issue 40): 6 modes warn with a compliance error
    # that bounds the march's rotation error (23 % statically, 6.5 % in the march); 20 modes
    # (converged) say nothing
    assert len(warned[6]) == 1 and not warned[20], warned
    pct = float(re.search(r"([\d.]+)% off the full model", warned[6][0]).group(1)) / 100
    assert worst[6] <= pct < 5.0 * worst[6], (pct, worst[6])


# 5. Cubic springs -------------------------------------------------------------------------------
def test_softening_cubic_beyond_its_limit_is_an_input_error():
    """A softening spring started beyond its stiffness limit (0.114 rad) blows up within 7 ms:
    open and closed loop end in one InputError that says so."""
    nplant = section_plant(conner_section(), [NonlinearHinge("flap", Cubic(-100.0))], 10.0, RHO)
    with pytest.raises(InputError, match="softening spring beyond its stiffness limit"):
        march_hinges(nplant, duration=5.0, rotation0=0.5)
    law = python_law(lambda t, y: [0.0], ["flap_hinge_moment"], ["flap_rotation"], sample_rate=1e3)
    with pytest.raises(InputError, match="softening spring beyond its stiffness limit"):
        march_hinges(nplant, law, duration=5.0, rotation0=0.5)


def test_softening_cubic_error_names_when_it_diverged():
    nplant = section_plant(conner_section(), [NonlinearHinge("flap", Cubic(-100.0))], 10.0, RHO)
    with pytest.raises(InputError, match=r"after t = [0-9.e+-]+ s") as info:
        march_hinges(nplant, duration=5.0, rotation0=0.5)
    t = float(re.search(r"after t = ([0-9.e+-]+) s", str(info.value)).group(1))
    assert 1e-3 < t < 1e-2  # the blow-up is at 6.5 ms


def test_cubic_closed_loop_section():
    """Hardening cubic flap of a soft-flap Conner section (unstable linear section at 10 m/s),
    a Python law on the three rotations with one sample of delay, saturated: the march equals
    the hand loop with one DOP853 per sample (rtol 1e-12) to 1e-8 (the march's own rtol 1e-10
    over 300 samples)."""
    section = conner_section(k_flap=0.8)
    nplant = section_plant(section, [NonlinearHinge("flap", Cubic(427.0))], 10.0, RHO)
    sensors = ["plunge", "pitch", "flap_rotation"]
    K = np.array([[0.0, 1.5, 0.3]])
    limits = Limits(magnitude={"flap_hinge_moment": 0.01}, rate={"flap_hinge_moment": 20.0})
    law = python_law(lambda t, y: -K @ y, ["flap_hinge_moment"], sensors, sample_rate=1 / DT)
    x0 = nplant.initial_state(0.05)
    n = 300
    ref = hand_loop(nplant, x0, n, ["flap_hinge_moment"], sensors, lambda k, y, h: -K @ y,
                    limits, delay=True)  # fmt: skip
    assert np.abs(ref[1]).max() == pytest.approx(0.01)
    res = march_hinges(nplant, law, duration=n * DT, x0=x0, limits=limits, delay=True)
    assert_same_march(res, ref, nplant, controls=["flap_hinge_moment"])
    np.testing.assert_allclose(
        res.hinge_moments["flap"],
        0.8 * res.rotations["flap"] + 427.0 * res.rotations["flap"] ** 3,
        rtol=1e-12,
    )


def test_cubic_closed_loop_wing_with_feedthrough(raw_loop):
    """Softening cubic on actuator1 (inside its limit), the gain on the unfiltered accelerometer
    (``D_n phi`` in the sensor) and twist, rate-limited: the march equals the hand loop. 2e-6:
    the accelerometer weighs the small, fast states heavily and the march's absolute tolerance
    (1e-12 x the largest initial state, the same for every state) leaves ~4e-7 there."""
    nplant = loop_hinge_plant(raw_loop, [NonlinearHinge("actuator1", Cubic(-4e4))], SPEED)
    x0 = nplant.initial_state(0.1)
    n = 30
    ref = hand_loop(nplant, x0, n, [AILERON], SENSORS, lambda k, y, h: -K_OUT @ y, LIMITS)
    gain = static_gain(K_OUT, [AILERON], sensors=SENSORS, sample_rate=1 / DT)
    res = march_hinges(nplant, gain, duration=n * DT, x0=x0, limits=LIMITS)
    assert_same_march(res, ref, nplant, tol=2e-6, controls=[AILERON])
    assert rel(res.rotations["actuator1"], ref[0] @ nplant.c_n[0]) < 2e-7


# 6. The LCO study -------------------------------------------------------------------------------
CGAP = CONNER["gap"]
SPEEDS = [5.0, 7.0, 14.0, 26.0]  # m/s: flap-free flutter 6.49, gap closed 23.74


@pytest.fixture(scope="module")
def study():
    setup = LCOSetup(conner_section(), [NonlinearHinge("flap", Freeplay(CGAP))], RHO)
    sweep = LCOSweep(SPEEDS, [0.3 * CGAP, 2.0 * CGAP], duration=3.0, continuation=True,
                     history=3.0)  # fmt: skip
    return run_lco(setup, sweep)


def test_continuation_carries_the_last_state(study):
    """The up sweep starts from the smallest rotation at the lowest speed, the down sweep from
    the largest at the top speed; each march of a sweep starts where the one before ended
    (the whole march is kept: ``history`` = duration), except after a divergence, which
    restarts from rest with the sweep's rotation and equals that point march exactly."""
    rows = {k: [r for r in study.rows if r["start"] == k] for k in ("point", "up", "down")}
    up, down = rows["up"], rows["down"]
    assert [r["speed"] for r in up] == SPEEDS and [r["speed"] for r in down] == SPEEDS[::-1]

    def rot(r):
        return np.asarray(r["history"]["flap_rotation"])

    assert rot(up[0])[0] == pytest.approx(0.3 * CGAP, rel=1e-12)
    assert rot(down[0])[0] == pytest.approx(2.0 * CGAP, rel=1e-12)
    for sweep in (up, down):
        for before, row in zip(sweep[:-1], sweep[1:], strict=True):
            if before["kind"] == "divergence":
                assert rot(row)[0] == pytest.approx(row["initial"], rel=1e-12)
                point = next(p for p in rows["point"] if p["speed"] == row["speed"]
                             and p["initial"] == row["initial"])  # fmt: skip
                np.testing.assert_array_equal(rot(row), rot(point))
            else:
                assert rot(row)[0] == rot(before)[-1]
    assert down[0]["kind"] == "divergence" and up[-1]["kind"] == "divergence"


def test_growing_is_a_moderate_divergence(study):
    """``growing`` replaces a divergence verdict while the rotation stays below ``DIVERGED``
    gaps ("inside the gap" when it never left it), and only then; every divergence went beyond
    that."""
    kinds = {r["kind"] for r in study.rows}
    assert "growing" in kinds and "divergence" in kinds
    inside = 0
    for r in study.rows:
        reach = np.abs(np.asarray(r["history"]["flap_rotation"])).max()
        if r["kind"] == "growing":
            assert reach < DIVERGED * CGAP and r["growth"] > 0
            assert "grows, largest rotation" in r["reason"] and "; divergence: " in r["reason"]
            assert ("inside the gap" in r["reason"]) == (reach < 0.5 * CGAP)
            inside += reach < 0.5 * CGAP
        if r["kind"] == "divergence":
            assert reach >= DIVERGED * CGAP
    assert inside > 0


def test_summary_numbers_are_the_rows(study):
    """The summary's range of sustained oscillations (issue 40: every class, each named; here
    periodic only), amplitudes and RMS per gap, frequencies, divergence speed and the
    describing-function comparison are computed from the rows (and the branches)."""
    text = study.summary()
    lco = study.lco_rows()
    assert lco and study.sustained_rows() == lco
    v = [r["speed"] for r in lco]
    a = [r["amplitude_per_gap"] for r in lco]
    rms = [r["rms_per_gap"] for r in lco]
    f = [r["frequency"] for r in lco]
    assert len(set(v)) == 1  # one speed: said once
    assert (
        f"sustained oscillations at {v[0]:.4g} m/s (half peak-to-peak and RMS of flap):\n"
        f"  periodic at {v[0]:.4g} m/s: amplitude {min(a):.3g} to {max(a):.3g} x gap, RMS "
        f"{min(rms):.3g} to {max(rms):.3g} x gap, {min(f):.3g} Hz\n" in text
    )
    div = [r["speed"] for r in study.rows if r["kind"] == "divergence"]
    assert f"divergent motion from {min(div):.4g} m/s" in text
    b = study.branches
    seen = b.stable & b.others_stable
    errs = []
    for r in lco:
        hit = _branch_at(b, seen, r["speed"], r["frequency"])
        if hit is not None:
            errs.append((hit[0] / r["amplitude"] - 1.0, hit[1] / r["frequency"] - 1.0))
    e = 100 * np.array(errs)
    assert (
        f"against the {len(errs)} settled marches on such a branch (interpolated at their "
        f"speed, frequency within 20 %): amplitude {e[:, 0].min():+.1f} to {e[:, 0].max():+.1f} "
        f"%, frequency {e[:, 1].min():+.1f} to {e[:, 1].max():+.1f} %" in text
    )
    assert np.abs(e).max() < 6.0  # the DF's first harmonic, within the harmonics' spread
