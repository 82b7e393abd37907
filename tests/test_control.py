"""Flutter-suppression controllers and closed-loop time marching (issue: LQR, LQG, MPC).

Case: the Goland wing with the illustrative aileron (``aes.examples.goland_aileron``), 10
elements, sea-level density, at 1.10 x its open-loop flutter speed. Reference numbers are the
closed-loop eigenvalues of the same loops (a second, independent computation) and
python-control's ``forced_response`` on the interconnected discrete system.
"""

from dataclasses import dataclass

import control
import numpy as np
import pytest

import aeroservo as aes
from aeroservo.aero import OneMinusCosine, Turbulence
from aeroservo.design import (
    Bryson,
    Limits,
    OpenLoop,
    SampledPlant,
    closed_loop_boundary,
    closed_loop_matrix,
    lqg,
    lqr_controller,
    mpc,
    schedule,
    state_map,
    with_sensor_filters,
)
from aeroservo.errors import InputError
from aeroservo.linear.models import tip_deflection_state
from aeroservo.simulate import simulate

RHO = 1.225
HM = "aileron_hinge_moment"
CONTROLS = [HM]
SENSORS = ["tip_le_accel", "tip_te_accel", "tip_twist"]
ACCELS = SENSORS[:2]
NOISE = {"tip_le_accel": 10.0, "tip_te_accel": 10.0, "tip_twist": 1e-6}
FILTER_HZ = 30.0
BRYSON = Bryson(outputs={"tip_disp": 0.05, "tip_twist": 0.02}, inputs={HM: 500.0})
LIMITS = Limits(magnitude={HM: 2000.0}, rate={HM: 2.0e5})


@dataclass
class Case:
    vf: float
    V: float
    pb: aes.StateSpaceBuilder
    db: aes.StateSpaceBuilder
    T: np.ndarray

    def plant(self, v=None, filtered=False):
        p = self.pb.at(self.V if v is None else v)
        return with_sensor_filters(p, ACCELS, FILTER_HZ) if filtered else p

    def design(self, v=None, filtered=False):
        d = self.db.at(self.V if v is None else v)
        return with_sensor_filters(d, ACCELS, FILTER_HZ) if filtered else d

    def x0(self, tip=0.01, filtered=False):
        x = tip_deflection_state(self.pb, tip)
        n_extra = self.plant(filtered=True).nstates - x.size if filtered else 0
        return np.r_[x, np.zeros(n_extra)]


@pytest.fixture(scope="module")
def case(aileron10):
    vf = aes.flutter_boundary(aileron10, RHO).flutter_speed
    ins = [HM, "gust"]
    outs = SENSORS + ["tip_disp", "aileron_deflection"]
    pb = aes.StateSpaceBuilder(aileron10, RHO, ins, outs)
    db = aes.StateSpaceBuilder(aileron10, RHO, ins, outs, n_modes=8)
    return Case(vf, 1.1 * vf, pb, db, state_map(pb, db))


@pytest.fixture(scope="module")
def K(case):
    return lqr_controller(case.design(), CONTROLS, bryson=BRYSON, state_map=case.T)


@pytest.fixture(scope="module")
def G(case):
    return lqg(
        case.design(filtered=True),
        CONTROLS,
        SENSORS,
        process_noise={"gust": 1.0},
        sensor_noise=NOISE,
        bryson=BRYSON,
    )


def make_mpc(case, limits=LIMITS, **kw):
    kw.setdefault("bryson", BRYSON)
    return mpc(
        case.design(filtered=True),
        CONTROLS,
        SENSORS,
        limits=limits,
        process_noise={"gust": 1.0},
        sensor_noise=NOISE,
        **kw,
    )


def envelope_ratio(y, frac=0.2):
    """max |y| over the last ``frac`` of the record / max |y| over the first ``frac``."""
    n = max(1, int(frac * y.size))
    return np.abs(y[-n:]).max() / np.abs(y[:n]).max()


def modal_prediction(A, x0, C, n_steps):
    """Outputs ``C A^k x0`` from the eigen-decomposition of A (no time stepping)."""
    lam, V = np.linalg.eig(A)
    c = np.linalg.solve(V, x0.astype(complex))
    k = np.arange(n_steps + 1)
    return np.real((C @ V) @ (c[:, None] * lam[:, None] ** k[None, :])), lam, V, c


# -- open loop and the three controllers at 1.1 V_f --------------------------------------------


def test_open_loop_grows(case):
    r = simulate(case.plant(), OpenLoop((HM,), 1e-3), duration=2.0, x0=case.x0())
    assert envelope_ratio(r.outputs["tip_disp"]) > 10.0
    assert np.all(r.applied[HM] == 0)


def test_lqr_decays_at_the_rate_of_its_closed_loop_eigenvalues(case, K):
    """Acceptance: LQR decays; decay rate and peak hinge moment from the closed-loop
    eigenvalues (modal solution of the sampled loop, no time stepping)."""
    P = case.plant()
    r = simulate(P, K, duration=3.0, x0=case.x0(), limits=LIMITS)
    assert envelope_ratio(r.outputs["tip_disp"]) < 1e-3
    # the linear loop (no actuator limits) against its eigenvalues
    r = simulate(P, K, duration=3.0, x0=case.x0())
    tip = r.outputs["tip_disp"]
    A, dt = closed_loop_matrix(P, K)
    n = r.t.size - 1
    i_tip = P.output_labels.index("tip_disp")
    Cz = np.vstack([np.asarray(P.C)[i_tip], -K.gain])  # tip displacement and hinge moment
    pred, lam, V, c = modal_prediction(A, case.x0(), Cz, n)
    assert np.max(np.abs(pred[0] - tip)) < 1e-8 * np.abs(tip).max()
    peak = np.abs(r.applied[HM]).max()
    assert abs(np.abs(pred[1]).max() - peak) < 1e-8 * peak
    # decay: in 0.3-1.2 s the tip motion is the controlled flutter mode (the model has no
    # structural damping, so lightly damped high-frequency modes dominate much later)
    t1, t2 = 300, 1200
    contrib = np.abs(Cz[0] @ V) * np.abs(c) * np.abs(lam) ** ((t1 + t2) // 2)
    order = np.argsort(-contrib)
    assert contrib[order[0]] > 10 * contrib[order[2]]  # one complex pair dominates
    dominant = np.abs(lam[order[0]])
    assert abs(np.angle(lam[order[0]])) / dt / (2 * np.pi) == pytest.approx(11.0, rel=0.1)
    seg = lambda a: np.abs(tip[a - 100 : a]).max()  # noqa: E731
    measured = np.log(seg(t2) / seg(t1)) / ((t2 - t1) * dt)
    assert measured == pytest.approx(np.log(dominant) / dt, rel=0.05)


def test_lqg_decays_and_matches_its_closed_loop_eigenvalues(case, G):
    P = case.plant(filtered=True)
    x0 = case.x0(filtered=True)
    r = simulate(P, G, duration=6.0, x0=x0, limits=LIMITS)
    assert envelope_ratio(r.outputs["tip_disp"]) < 0.05
    r = simulate(P, G, duration=6.0, x0=x0)  # linear loop
    tip = r.outputs["tip_disp"]
    A, dt = closed_loop_matrix(P, G)
    rho = np.max(np.abs(np.linalg.eigvals(A)))
    assert rho < 1.0
    # the sampled loop: plant [x, h] then compensator state (zero initial estimate)
    xcl = np.r_[x0, np.zeros(A.shape[0] - x0.size)]
    sp = SampledPlant.from_statespace(P, G.dt, CONTROLS, (), ["tip_disp"])
    Cz = np.hstack([sp.augmented()[3], np.zeros((1, A.shape[0] - x0.size - 1))])
    pred, *_ = modal_prediction(A, xcl, Cz, r.t.size - 1)
    assert np.max(np.abs(pred[0] - tip)) < 1e-7 * np.abs(tip).max()


def test_lqg_compensator_is_an_inspectable_statespace(G):
    comp = G.compensator
    assert isinstance(comp, control.StateSpace) and comp.dt == G.dt
    assert comp.input_labels == SENSORS and comp.output_labels == CONTROLS
    cc = G.compensator_continuous
    assert cc.isctime() and cc.nstates == G.continuous["A"].shape[0]
    mag, phase, omega = control.frequency_response(cc, [2 * np.pi * 11.0])
    assert np.all(np.isfinite(mag))


def test_mpc_decays_within_limits_and_reports_every_step(case):
    M = make_mpc(case, horizon=20)
    P = case.plant(filtered=True)
    r = simulate(P, M, duration=3.0, x0=case.x0(filtered=True), limits=LIMITS)
    assert envelope_ratio(r.outputs["tip_disp"]) < 0.05
    n = r.t.size
    assert len(r.status) == n and M.fallbacks == 0
    assert all(s["status"] and not s["fallback"] for s in r.status)
    # the optimizer's own commands respect the hard limits (not just the clipped ones)
    u = r.commands[HM]
    assert np.all(np.abs(u) <= LIMITS.magnitude[HM] * (1 + 1e-6))
    du = np.diff(np.r_[0.0, u]) / M.dt
    assert np.all(np.abs(du) <= LIMITS.rate[HM] * (1 + 1e-6))


def test_mpc_failed_solve_falls_back_and_carries_on(case):
    M = make_mpc(case, horizon=10)

    def failing():
        M._out["x"][:] = np.nan
        return False, "forced failure"

    M._solve = failing

    r = simulate(
        case.plant(filtered=True), M, duration=0.05, x0=case.x0(filtered=True), limits=LIMITS
    )
    assert M.fallbacks == r.t.size
    assert all(s["fallback"] and s["status"] == "forced failure" for s in r.status)
    assert np.all(np.isfinite(r.applied[HM]))
    assert np.all(np.abs(np.diff(np.r_[0.0, r.applied[HM]])) <= LIMITS.rate[HM] * M.dt * (1 + 1e-9))


def test_saturated_lqr_loses_stability_where_mpc_keeps_it(case):
    """Acceptance: same weights, same 300 N m hinge-moment limit, same 3.1 cm initial tip
    deflection: the saturated LQR (full state!) diverges, MPC (estimated state) recovers.

    Thresholds measured by bisection on the initial deflection (3 s runs): saturated LQR
    about 2.8 cm, MPC about 3.5 cm, at 250 Hz with a 40-step (160 ms) horizon.
    """
    br = Bryson(outputs={"tip_disp": 0.05, "tip_twist": 0.02}, inputs={HM: 5000.0})
    lim = Limits(magnitude={HM: 300.0}, rate={HM: 1e5})
    rate = 250.0
    Kx = lqr_controller(case.design(), CONTROLS, bryson=br, state_map=case.T, sample_rate=rate)
    with pytest.warns(RuntimeWarning, match="run away while the actuator saturates"):
        r_lqr = simulate(case.plant(), Kx, duration=3.0, x0=case.x0(0.031), limits=lim)
    assert r_lqr.windup()  # issue 24: the diverging saturated loop is reported
    M = make_mpc(case, limits=lim, bryson=br, horizon=40, sample_rate=rate)
    r_mpc = simulate(
        case.plant(filtered=True), M, duration=3.0, x0=case.x0(0.031, True), limits=lim
    )
    assert envelope_ratio(r_lqr.outputs["tip_disp"]) > 10.0
    assert r_lqr.saturated_fraction[HM] > 0.5
    assert envelope_ratio(r_mpc.outputs["tip_disp"]) < 0.1
    assert np.all(np.abs(r_mpc.commands[HM]) <= 300.0 * (1 + 1e-6))
    # without the limit the same LQR is fine: the loss is due to saturation
    r_free = simulate(case.plant(), Kx, duration=3.0, x0=case.x0(0.031))
    assert envelope_ratio(r_free.outputs["tip_disp"]) < 1e-2


# -- closed-loop flutter boundary --------------------------------------------------------------


@pytest.fixture(scope="module")
def lqr_boundary(case, K):
    return closed_loop_boundary(case.pb, K, 2.0 * case.vf)


def test_closed_loop_flutter_speed_above_design_speed(case, K, lqr_boundary):
    """Acceptance: the LQR designed at 1.1 V_f keeps the loop stable beyond 1.1 V_f."""
    b = lqr_boundary
    assert b.reference_speed == pytest.approx(case.V)
    assert b.stable_at_reference
    assert b.flutter_speed > 1.1 * case.vf
    print(
        f"open-loop V_f {case.vf:.2f} m/s; LQR at 1.1 V_f: closed-loop flutter "
        f"{b.flutter_speed:.2f} m/s ({b.flutter_speed / case.vf:.3f} V_f)"
    )
    # root found to the stated tolerance: stable just below, unstable just above
    for f, sign in ((1 - 1e-5, -1), (1 + 1e-5, 1)):
        A, dt = closed_loop_matrix(case.plant(b.flutter_speed * f), K)
        assert sign * (np.max(np.abs(np.linalg.eigvals(A))) - 1.0) > 0


def test_closed_loop_boundary_agrees_with_time_marching(case, K, lqr_boundary):
    vc = lqr_boundary.flutter_speed
    x0 = case.x0()
    grow = []
    for f in (0.97, 1.03):
        r = simulate(case.plant(f * vc), K, duration=8.0, x0=x0, outputs=["tip_disp"])
        grow.append(envelope_ratio(r.outputs["tip_disp"], 0.1))
    assert grow[0] < 1.0 < grow[1]


def test_continuous_and_sampled_boundaries_agree(case, K, lqr_boundary):
    bc = closed_loop_boundary(case.pb, K, 2.0 * case.vf, sampled=False)
    assert bc.flutter_speed == pytest.approx(lqr_boundary.flutter_speed, rel=0.01)


def test_gain_schedule_widens_the_stable_range(case, K, lqr_boundary):
    speeds = np.linspace(0.5, 1.7, 13) * case.vf
    S = schedule(
        lambda v: lqr_controller(case.design(v), CONTROLS, bryson=BRYSON, state_map=case.T), speeds
    )
    at = S.at(speeds[3])
    np.testing.assert_array_equal(at.Kd, S.controllers[3].Kd)
    mid = S.at(0.5 * (speeds[3] + speeds[4]))
    np.testing.assert_allclose(mid.K, 0.5 * (S.controllers[3].K + S.controllers[4].K))
    b = closed_loop_boundary(case.pb, S, 2.0 * case.vf, reference_speed=case.V)
    ((lo_fixed, hi_fixed),) = [
        iv for iv in lqr_boundary.stable_intervals if iv[0] <= case.V <= iv[1]
    ]
    ((lo, hi),) = [iv for iv in b.stable_intervals if iv[0] <= case.V <= iv[1]]
    assert lo < lo_fixed and hi > hi_fixed


def test_lqg_closed_loop_boundary(case, G):
    b = closed_loop_boundary(lambda v: case.plant(v, filtered=True), G, 1.6 * case.vf, n_grid=17)
    assert b.stable_at_reference and b.flutter_speed > 1.1 * case.vf


def test_mpc_boundary_is_that_of_its_law_and_a_python_law_is_refused(case):
    """An MPC's closed-loop boundary is that of its law without active constraints (the LQG
    whose gain is its first unconstrained move), built here as a plain compensator from the
    law's matrices; a Python law has no linear boundary and is refused, never treated as open
    loop."""
    from aeroservo.design import DiscreteCompensator, python_law

    m = make_mpc(case, horizon=5)
    plant = lambda v: case.plant(v, filtered=True)  # noqa: E731
    b = closed_loop_boundary(plant, m, 1.6 * case.vf, n_grid=9)
    law = m.law()
    bb = DiscreteCompensator(law.A, law.B, law.C, law.D, law.controls, law.sensors, law.dt)
    b2 = closed_loop_boundary(plant, bb, 1.6 * case.vf, n_grid=9)
    assert "MPC without active constraints" in b.info["law"]
    assert [c["speed"] for c in b.crossings] == pytest.approx([c["speed"] for c in b2.crossings])
    assert np.allclose(b.abscissa, b2.abscissa, rtol=1e-9, atol=1e-9)
    law_fn = python_law(lambda t, y: [0.0], CONTROLS, SENSORS, sample_rate=1000.0)
    with pytest.raises(InputError, match="not linear"):
        closed_loop_boundary(case.pb, law_fn, 200.0)


# -- time marching against python-control, determinism, disturbances --------------------------


def test_time_marching_matches_forced_response_of_the_interconnection(case, G):
    """Acceptance: LQG loop with a 1-cos gust, against ``control.forced_response`` on the
    interconnected discrete system (plant sampled with zero-order hold + compensator)."""
    P = case.plant(filtered=True)
    gust = OneMinusCosine(length=25.0, amplitude=1.0, start=0.05)
    r = simulate(P, G, duration=1.0, x0=case.x0(filtered=True), disturbance=gust)
    sp = SampledPlant.from_statespace(P, G.dt, CONTROLS, ["gust"], list(P.output_labels))
    Pd = sp.as_statespace()
    # interconnection: controls come from the compensator, the gust is the external input
    comp = G.compensator
    loop = control.interconnect(
        [Pd, comp],
        inplist=["gust"],
        outlist=list(P.output_labels) + CONTROLS,
        connections=[[f"{Pd.name}.{HM}", f"{comp.name}.{HM}"]]
        + [[f"{comp.name}.{s}", f"{Pd.name}.{s}"] for s in SENSORS],
    )
    x0 = np.zeros(loop.nstates)
    x0[: case.x0(filtered=True).size] = case.x0(filtered=True)
    resp = control.forced_response(loop, T=r.t, U=r.disturbance["gust"][None, :], X0=x0)
    y = np.asarray(resp.outputs)
    for i, name in enumerate(P.output_labels):
        scale = np.abs(r.outputs[name]).max()
        assert np.max(np.abs(y[i] - r.outputs[name])) < 1e-9 * scale, name
    assert np.max(np.abs(y[-1] - r.applied[HM])) < 1e-9 * np.abs(r.applied[HM]).max()


def test_same_seed_same_result(case, G):
    P = case.plant(filtered=True)
    turb = Turbulence(sigma=1.0, scale=533.0, seed=7)
    runs = [
        simulate(P, G, duration=0.5, disturbance=turb, sensor_noise={"tip_twist": 1e-4}, seed=s)
        for s in (3, 3, 4)
    ]
    np.testing.assert_array_equal(runs[0].outputs["tip_disp"], runs[1].outputs["tip_disp"])
    assert not np.array_equal(runs[0].applied[HM], runs[2].applied[HM])


def test_computational_delay_matches_its_closed_loop(case, K):
    P = case.plant()
    r = simulate(P, K, duration=1.0, x0=case.x0(), delay=True)
    A, _ = closed_loop_matrix(P, K, delay=True)
    i = P.output_labels.index("tip_disp")
    x = np.r_[case.x0(), 0.0]
    Cz = np.r_[np.asarray(P.C)[i], 0.0][None, :]
    pred, *_ = modal_prediction(A, x, Cz, r.t.size - 1)
    tip = r.outputs["tip_disp"]
    assert np.max(np.abs(pred[0] - tip)) < 1e-8 * np.abs(tip).max()
    assert r.applied[HM][0] == 0.0  # the first command is applied one sample late


def test_bad_controller_inputs(case):
    with pytest.raises(InputError, match="Q and R, or bryson"):
        lqr_controller(case.design(), CONTROLS)
    with pytest.raises(InputError, match="not a signal"):
        lqr_controller(case.design(), ["elevator_hinge_moment"], bryson=BRYSON)
    with pytest.raises(InputError, match="missing"):
        lqg(
            case.design(),
            CONTROLS,
            SENSORS,
            process_noise={"gust": 1.0},
            sensor_noise={"tip_twist": 1.0},
            bryson=BRYSON,
        )
    with pytest.raises(InputError, match="magnitude and a rate"):
        make_mpc(case, limits=Limits(magnitude={HM: 100.0}))
    with pytest.raises(InputError, match=r"limits.magnitude\['aileron_hinge_moment'\]"):
        Limits(magnitude={HM: -1.0})
    with pytest.raises(InputError, match="solver"):
        make_mpc(case, solver="cplex")
