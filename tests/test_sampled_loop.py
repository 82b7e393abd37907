"""The loop analysed is the loop simulated: the closed-loop matrix rebuilt against the time march.

For LQR, LQG, H-infinity and MPC (limits far away, so its QP is unconstrained: an LQG), with and
without a one-sample delay, the plant states marched by :func:`aeroservo.simulate.simulate`
equal the powers of :func:`aeroservo.design.closed_loop_matrix` applied to the same initial state,
sample by sample, and the spectral radii agree. Before the shared loop description
(:mod:`aeroservo.design.sampled_loop`) the LQG loop matrix with a delay predicted with its own
command while the simulator predicted with the delayed one (spectral radius 1.02 against a
decaying simulation).
"""

import dataclasses

import numpy as np
import pytest
from conftest import ROOT

import aeroservo as aes
from aeroservo.design import ControlLoop, closed_loop_boundary, closed_loop_matrix
from aeroservo.files import load_controller
from aeroservo.linear.models import tip_deflection_state
from aeroservo.simulate import simulate

RHO = 1.225
CONTROL = "aileron_hinge_moment"
SENSORS = ["tip_le_accel", "tip_te_accel", "tip_twist"]
FAR = aes.design.Limits(magnitude={CONTROL: 1e12}, rate={CONTROL: 1e15})


@pytest.fixture(scope="module")
def setup():
    model = aes.AeroelasticModel(aes.examples.goland_aileron(), 10)
    vf = aes.flutter_boundary(model, RHO).flutter_speed
    loop = ControlLoop(model, RHO, [CONTROL], SENSORS, ["tip_disp"], design_modes=20)
    return model, vf, loop


def controller(setup, kind: str):
    _model, vf, loop = setup
    spec = load_controller(ROOT / "controllers" / f"{kind}.toml")
    if kind == "mpc":
        spec = dataclasses.replace(spec, limits=FAR, soft_outputs={})
    return loop.design_controller(spec, 1.1 * vf, 1000.0, vf)


@pytest.mark.parametrize("delay", [False, True], ids=["no_delay", "delay"])
@pytest.mark.parametrize("kind", ["lqr", "lqg", "mpc", "hinf"])
@pytest.mark.slow
def test_loop_matrix_marches_like_the_simulator(setup, kind, delay):
    model, vf, loop = setup
    ctrl = controller(setup, kind)
    plant = loop.plant(1.1 * vf)
    A, dt = closed_loop_matrix(plant, ctrl, delay=delay)
    n = plant.nstates
    x0 = np.r_[
        tip_deflection_state(loop.plant_builder, 1e-3), np.zeros(n - loop.plant_builder.n_states)
    ]
    steps = 400
    res = simulate(
        plant, ctrl, duration=steps * dt, x0=x0, limits=FAR, delay=delay, record_states=True
    )
    s = np.zeros(A.shape[0])
    s[:n] = x0
    scale = np.abs(res.states).max()
    for k in range(steps + 1):
        assert np.abs(res.states[k] - s[:n]).max() <= 1e-9 * scale, (kind, delay, k)
        s = A @ s
    rho = np.abs(np.linalg.eigvals(A)).max()
    assert rho < 1.0  # these designs are stable at 1.1 V_f, with and without the delay


def test_boundary_with_delay_finds_a_stable_interval(setup):
    """closed_loop_boundary(delay=True) used to find no stable interval for the LQG."""
    _model, vf, loop = setup
    ctrl = controller(setup, "lqg")
    b = closed_loop_boundary(loop.plant, ctrl, 1.6 * vf, n_grid=17, delay=True)
    assert b.stable_at_reference
    assert any(a < 1.1 * vf < c for a, c in b.stable_intervals)


@pytest.mark.slow
def test_scenario_delay_reaches_the_boundary(tmp_path):
    """A scenario with delay = true analyses the delayed loop (the boundary moves)."""
    from aeroservo.files import load_scenario
    from aeroservo.studies import quick
    from aeroservo.studies.runs import run_simulation

    sc = quick(load_scenario(ROOT / "scenarios" / "goland_aileron_lqg.toml"))
    assert sc.delay is True  # the default (issue 38)
    sc = dataclasses.replace(sc, delay=False)
    plain = run_simulation(sc).summary["closed_loop"]
    delayed = run_simulation(dataclasses.replace(sc, delay=True)).summary["closed_loop"]
    assert delayed["delay"] is True and plain["delay"] is False
    assert delayed["closed_loop_flutter_speed"] != plain["closed_loop_flutter_speed"]


def test_stable_intervals_follow_the_crossings():
    """A short unstable interval between two grid points (onset and recovery refined by the root
    finder) is not stable because the grid's interpolated measure is negative there: the
    quick-grid H-infinity boundary reported [106.5, 113.6] m/s as stable."""
    from aeroservo.design.closed_loop import ClosedLoopBoundary

    b = ClosedLoopBoundary(
        speeds=np.array([0.0, 10.0, 20.0]),
        abscissa=np.array([-1.0, -1.0, -1.0]),
        frequencies=np.zeros(3),
        crossings=[
            {"speed": 12.0, "frequency": 6.0, "kind": "onset", "static": False},
            {"speed": 14.0, "frequency": 6.0, "kind": "recovery", "static": False},
        ],
        sampled=True,
        reference_speed=5.0,
    )
    assert b.stable_intervals == [(0.0, 12.0), (14.0, 20.0)]
    b.crossings = [{"speed": 5.0, "frequency": 1.0, "kind": "recovery", "static": False}]
    assert b.stable_intervals == [(5.0, 20.0)]
