"""Continuous turbulence through a sampled controller, and load covariances, checked against
computations independent of the quadrature:

* the response at the sample instants is the one :func:`aeroservo.simulate.simulate` marches
  (a sine gust generated inside the plant, so the march is exact, against ``H_s``);
* A-bar and the covariance of the loads equal, with the Dryden spectrum, the discrete Lyapunov
  covariance of the Dryden filter + plant discretised exactly at the sample period (Van Loan
  for the noise), closed by the controller's law, for LQR (state feedback), LQG (output
  feedback, with and without delay) and random static output gains, below and above the
  open-loop flutter speed, at 1000 Hz and at 100 Hz (where the aliases carry 2e-6 to 3e-5 of
  A-bar^2 of the root loads);
* A-bar, N0 and the cross terms of an oscillator under a sampled gain against a brute-force
  quadrature period by period (the period averages beyond ``w_a`` and their Euler-Maclaurin
  terms); the open-loop covariance against the continuous Lyapunov equation.
"""

import math

import control
import numpy as np
import pytest
import scipy.linalg as sla
from conftest import ROOT

import aeroservo as aes
from aeroservo.design import ControlLoop, OpenLoop, python_law, static_gain
from aeroservo.design.closed_loop import linear_controller
from aeroservo.design.interface import controller_at
from aeroservo.design.law import delayed
from aeroservo.design.sampled_loop import linear_law, plant_states
from aeroservo.errors import InputError
from aeroservo.files import load_controller
from aeroservo.simulate import simulate
from aeroservo.studies.gust.turbulence import _sampled_loop, dryden, turbulence_response, von_karman
from aeroservo.studies.gust.turbulence_loop import (
    ModalResponse,
    adaptive,
    breakpoints,
    columns,
    diagonal,
    loop_points,
    outer,
)

RHO, L = 1.225, 762.0
CONTROL = "aileron_hinge_moment"
SENSORS = ["tip_le_accel", "tip_te_accel", "tip_twist"]
LOADS = ["root_shear", "root_bending_moment", "root_torque", "tip_twist"]
TOL = 1e-8
"""A-bar against the Lyapunov covariance. The quadrature asks rtol = 1e-9 of each variance
(5e-10 of A-bar); the reference itself is good to a few 1e-9 for the root shear and torque (its
C P C' cancels: scipy's solve_discrete_lyapunov and Smith's doubling differ by 3e-9 on the
6-element loops), so 1e-8. Measured: at most 2.2e-9."""


def dryden_filter(speed, scale):
    """The unit-variance Dryden shaping filter of tests/test_turbulence.py (one-sided white
    noise of PSD 1): sqrt(L/(pi V)) (1 + sqrt(3) tau s) / (1 + tau s)^2, tau = L / V."""
    tau = scale / speed
    k = math.sqrt(scale / (math.pi * speed))
    return control.tf([k * math.sqrt(3) * tau, k], [tau**2, 2 * tau, 1.0])


def noise_covariance(a, q, dt):
    """``int_0^dt e^{As} q e^{A's} ds``: Van Loan's exponential at ``dt / 2^k`` (``|A| h <=
    1/2``, where it is accurate for this stiff A), then k doublings ``Q(2h) = Phi Q Phi' + Q``."""
    n = a.shape[0]
    k = max(0, math.ceil(math.log2(max(np.linalg.norm(a, 1) * dt / 0.5, 1.0))))
    e = sla.expm(np.block([[-a, q], [np.zeros((n, n)), a.T]]) * (dt / 2**k))
    phi = e[n:, n:].T
    qd = phi @ e[:n, n:]
    for _ in range(k):
        qd = phi @ qd @ phi.T + qd
        phi = phi @ phi
    return (qd + qd.T) / 2


def dlyap(a, q):
    """``P = A P A' + Q``: scipy's solver, its residual removed by Smith's doubling."""
    p = sla.solve_discrete_lyapunov(a, q)
    e, ak = a @ p @ a.T - p + q, a.copy()
    for _ in range(40):  # sum_k A^k R A'^k by doubling; |eig(A)|^(2^40) underflows
        e, ak = e + ak @ e @ ak.T, ak @ ak
    return p + e


def lyapunov_covariance(plant, controller, outputs, delay=False):
    """Covariance of ``outputs`` at the samples under Dryden turbulence (unit variance): the
    filter and the plant discretised exactly (zero-order hold on the command, exact noise
    covariance), the controller's law ``c = C s + D m, s+ = A s + B m`` closed (measurement
    ``m = Cm x + Dmw w + Dmu u[k-1]``, or the plant state), discrete Lyapunov."""
    law = linear_law(
        controller_at(linear_controller(controller, "test"), plant.speed), plant_states(plant)
    )
    law = delayed(law) if delay else law
    f = control.ss(dryden_filter(plant.speed, L))
    A, B, C, D = (np.asarray(x, float) for x in (plant.A, plant.B, plant.C, plant.D))
    ins, outs = list(plant.input_labels), list(plant.output_labels)
    iu, iw = [ins.index(c) for c in law.controls], ins.index("gust")
    n, nf, m, ns = A.shape[0], f.nstates, len(iu), law.A.shape[0]
    Af, Bf, Cf = (np.asarray(x, float) for x in (f.A, f.B, f.C))
    N = n + nf
    Aa = np.block([[A, B[:, [iw]] @ Cf], [np.zeros((nf, n)), Af]])
    E = sla.expm(
        np.block([[Aa, np.vstack([B[:, iu], np.zeros((nf, m))])], [np.zeros((m, N + m))]]) * law.dt
    )
    Phi, Gu = E[:N, :N], E[:N, N:]
    xi = np.vstack([np.zeros((n, 1)), Bf])
    Qd = noise_covariance(Aa, math.pi * xi @ xi.T, law.dt)  # one-sided PSD 1: intensity pi
    if law.state_feedback:
        Cm, Dmu = np.hstack([np.eye(n), np.zeros((n, nf))]), np.zeros((n, m))
    else:
        r = [outs.index(s) for s in law.sensors]
        Cm, Dmu = np.hstack([C[r], D[r][:, [iw]] @ Cf]), D[r][:, iu]
    ry = [outs.index(o) for o in outputs]
    Cz = np.hstack([C[ry], D[ry][:, [iw]] @ Cf, D[ry][:, iu], np.zeros((len(ry), ns))])
    As, Bs, Cs, Ds = law.A, law.B, law.C, law.D
    Acl = np.block(
        [  # [x, filter; u[k-1]; s]
            [Phi + Gu @ Ds @ Cm, Gu @ Ds @ Dmu, Gu @ Cs],
            [Ds @ Cm, Ds @ Dmu, Cs],
            [Bs @ Cm, Bs @ Dmu, As],
        ]
    )
    assert np.max(np.abs(np.linalg.eigvals(Acl))) < 1.0
    Q = np.zeros_like(Acl)
    Q[:N, :N] = Qd
    return Cz @ dlyap(Acl, Q) @ Cz.T


@pytest.fixture(scope="module")
def wing6():
    model = aes.AeroelasticModel(aes.examples.goland_aileron(), 6)
    vf = aes.flutter_boundary(model, RHO).flutter_speed
    outputs = ["tip_disp", "root_bending_moment", "root_torque", "root_shear"]
    loop = ControlLoop(model, RHO, [CONTROL], SENSORS, outputs, design_modes=8)
    bare = ControlLoop(model, RHO, [CONTROL], SENSORS, outputs, design_modes=8, sensor_filter=None)
    return vf, loop, bare


def design(wing6, kind, rate):
    vf, loop, _ = wing6
    return loop.design_controller(
        load_controller(ROOT / "controllers" / f"{kind}.toml"), 1.1 * vf, rate, vf
    )


def check_against_lyapunov(plant, ctrl, delay=False):
    res = turbulence_response(plant, LOADS, spectrum=dryden(L), controller=ctrl, delay=delay)
    cov = lyapunov_covariance(plant, ctrl, LOADS, delay)
    for i, n in enumerate(LOADS):
        assert res.a_bar[n] == pytest.approx(math.sqrt(cov[i, i]), rel=TOL), n
    scale = np.sqrt(np.outer(np.diag(cov), np.diag(cov)))
    assert np.max(np.abs(res.covariance - cov) / scale) < 2 * TOL
    return res


@pytest.mark.parametrize(
    "kind, rate, factor, delay",
    [
        ("lqr", 1000.0, 0.9, False),
        ("lqr", 1000.0, 1.1, False),
        ("lqr", 100.0, 0.9, False),
        ("lqr", 100.0, 1.1, True),
        ("lqg", 1000.0, 0.9, True),
        ("lqg", 1000.0, 1.1, False),
    ],
)
def test_dryden_equals_the_discrete_lyapunov_covariance(wing6, kind, rate, factor, delay):
    vf, loop, _ = wing6
    plant = loop.plant(factor * vf)
    if factor > 1:  # the loop is the flutter suppressor: open loop unstable, allowed
        assert np.max(np.linalg.eigvals(plant.A).real) > 0
    ctrl = design(wing6, kind, rate)
    res = check_against_lyapunov(plant, ctrl, delay)
    assert res.sample_rate == pytest.approx(rate) and res.controller.startswith(kind.upper())
    if rate == 100.0:  # the aliases matter: the band below Nyquist alone misses > 100 x TOL
        rows = [list(plant.output_labels).index(n) for n in LOADS]
        resp, zeta, _, _ = _sampled_loop(plant, ctrl, delay, None, rows, 1, plant.speed)
        half = math.pi * rate
        pts = np.unique(
            np.concatenate(
                [breakpoints(resp.ol.lam, plant.speed, L, half), loop_points(zeta, resp.dt, half)]
            )
        )
        spec = dryden(L)
        base = adaptive(
            lambda w: columns(outer(resp(w)), w, spec.time_psd(w, plant.speed)),
            pts,
            1e-10,
            diagonal(4),
            0.0,
        )
        share = 1 - base[diagonal(4)[:4]] / np.diag(res.covariance)
        assert np.all(share[:3] > 100 * TOL), share


def test_random_static_output_gains(wing6):
    # seeded gains on the unfiltered accelerometers (their direct feedthrough of the hinge
    # moment, read as u[k-1]) and the twist, redrawn until the loop is stable
    vf, _, bare = wing6
    plant = bare.plant(0.9 * vf)
    rng = np.random.default_rng(7)
    done = 0
    while done < 3:
        k = rng.uniform(-1, 1, 3) * [0.3, 0.3, 3e3]
        ctrl = static_gain([k], [CONTROL], sensors=SENSORS, sample_rate=1000.0)
        try:
            check_against_lyapunov(plant, ctrl)
        except InputError as exc:
            assert "unstable" in str(exc)
            continue
        done += 1


@pytest.mark.parametrize("kind", ["lqr", "gain"])
def test_response_is_the_marched_loop(aileron10, kind):
    # gust cos(w0 t) generated by an oscillator inside the plant, so the simulator marches it
    # exactly; after 29 s (the slowest closed-loop mode decays like exp(-0.75 t)) the outputs
    # at the samples are Re(H_s(w0) e^{j w0 t_k}) to 1e-9. LQR with a one-sample delay; a
    # static output gain on unfiltered accelerometers (feedthrough of u[k-1]).
    vf = aes.flutter_boundary(aileron10, RHO).flutter_speed
    loop = ControlLoop(
        aileron10,
        RHO,
        [CONTROL],
        SENSORS,
        ["tip_disp", "root_shear", "root_torque"],
        sensor_filter=None if kind == "gain" else 30.0,
    )
    if kind == "lqr":
        ctrl, delay = (
            loop.design_controller(
                load_controller(ROOT / "controllers/lqr.toml"), 1.1 * vf, 1000.0, vf
            ),
            True,
        )
    else:
        ctrl, delay = (
            static_gain([[-0.01, 0.0, 2e3]], [CONTROL], sensors=SENSORS, sample_rate=1000.0),
            False,
        )
    p = loop.plant(0.9 * vf)
    outs = ["root_shear", "root_torque", "tip_le_accel"]
    rows = [list(p.output_labels).index(o) for o in outs]
    iw = list(p.input_labels).index("gust")
    resp = _sampled_loop(p, ctrl, delay, None, rows, iw, p.speed)[0]
    w0 = 2 * math.pi * 37.0
    H = resp(np.array([w0]))[0]
    A, B, C, D = (np.asarray(x) for x in (p.A, p.B, p.C, p.D))
    n = A.shape[0]
    osc = np.array([[0.0, w0], [-w0, 0.0]])
    Aa = np.block([[A, np.outer(B[:, iw], [1.0, 0.0])], [np.zeros((2, n)), osc]])
    Ca = np.hstack([C, np.outer(D[:, iw], [1.0, 0.0])])
    iu = [list(p.input_labels).index(CONTROL)]
    pa = control.ss(
        Aa,
        np.vstack([B[:, iu], [[0.0], [0.0]]]),
        Ca,
        D[:, iu],
        inputs=[CONTROL],
        outputs=list(p.output_labels),
        states=list(p.state_labels) + ["g1", "g2"],
    )
    pa.speed = p.speed
    x0 = np.zeros(n + 2)
    x0[n] = 1.0
    res = simulate(pa, ctrl, duration=30.0, x0=x0, outputs=outs, delay=delay)
    k = res.t > 29.0
    for i, o in enumerate(outs):
        want = (H[i] * np.exp(1j * w0 * res.t[k])).real
        assert np.max(np.abs(res.outputs[o][k] - want)) < 1e-9 * np.max(np.abs(want)), o


def test_zero_gain_and_open_loop_controller_give_the_open_loop(wing6):
    vf, loop, _ = wing6
    plant = loop.plant(0.9 * vf)
    ref = turbulence_response(plant, LOADS)
    assert ref.controller == "open loop" and ref.sample_rate is None
    zero = static_gain(np.zeros((1, 3)), [CONTROL], sensors=SENSORS, sample_rate=100.0)
    rows = [list(plant.output_labels).index(n) for n in LOADS]
    resp = _sampled_loop(plant, zero, False, None, rows, 1, plant.speed)[0]
    ol = ModalResponse(
        *(np.asarray(x) for x in (plant.A, plant.B[:, 1], plant.C[rows], plant.D[rows, 1]))
    )
    w = np.logspace(-2, 6, 200)  # aliases included: H_s is H(j w) exactly
    assert np.max(np.abs(resp(w) - ol(w)) / np.abs(ol(w))) < 1e-10
    res = turbulence_response(plant, LOADS, controller=zero)  # the closed-loop quadrature
    assert res.controller == "static output gain" and res.sample_rate == pytest.approx(100.0)
    for n in LOADS:
        assert res.a_bar[n] == pytest.approx(ref.a_bar[n], rel=1e-9), n
        assert res.n0[n] == pytest.approx(ref.n0[n], rel=1e-8), n
    assert np.allclose(res.covariance, ref.covariance, rtol=1e-8, atol=0)
    same = turbulence_response(plant, LOADS, controller=OpenLoop((CONTROL,), 1e-3))
    assert same.a_bar == ref.a_bar and same.controller == "open loop"


def test_nonlinear_controller_unstable_loop_and_delay_one_line(wing6):
    vf, loop, _ = wing6
    plant = loop.plant(0.9 * vf)
    law = python_law(lambda t, y: [0.0], [CONTROL], SENSORS, sample_rate=1000.0, name="my law")
    with pytest.raises(
        InputError, match="turbulence_response: controller = my law is not linear"
    ) as e:
        turbulence_response(plant, LOADS, controller=law)
    assert "\n" not in str(e.value)
    hot = static_gain([[-100.0, 0.0, 0.0]], [CONTROL], sensors=SENSORS, sample_rate=1000.0)
    with pytest.raises(
        InputError,
        match=r"speed = 124\.\d+ m/s: the sampled loop .* unstable \(spectral radius 1\.\d+ >= 1\)",
    ) as e:
        turbulence_response(plant, LOADS, controller=hot)
    assert "\n" not in str(e.value)
    with pytest.raises(InputError, match="delay = 1"):
        turbulence_response(plant, LOADS, controller=hot, delay=1)
    with pytest.raises(InputError, match="unstable"):  # open loop above V_f without controller
        turbulence_response(loop.plant(1.1 * vf), LOADS)


def test_open_loop_covariance_against_continuous_lyapunov():
    # the cascade of tests/test_turbulence.py (Dryden filter then the 12-mode wing): cross terms
    # C P C' equal the quadrature to 1e-9 of sqrt(var_i var_j) (as its diagonal, measured ~1e-10)
    wing = aes.examples.goland_aileron()
    loads = ["root_shear", "root_bending_moment", "root_torque", "tip_le_accel", "tip_te_accel"]
    g = aes.statespace(wing, speed=120.0, density=RHO, inputs=["gust"], outputs=loads, n_modes=12)
    f = control.ss(dryden_filter(120.0, L))
    a = np.block([[f.A, np.zeros((f.nstates, g.nstates))], [g.B @ f.C, g.A]])
    b = np.vstack([f.B, g.B @ f.D])
    c = np.hstack([g.D @ f.C, g.C])
    cov = c @ sla.solve_continuous_lyapunov(a, -math.pi * (b @ b.T)) @ c.T
    res = turbulence_response(g, loads, spectrum=dryden(L))
    assert res.outputs == tuple(loads)
    scale = np.sqrt(np.outer(np.diag(cov), np.diag(cov)))
    assert np.max(np.abs(res.covariance - cov) / scale) < 1e-9
    assert np.allclose(res.covariance, res.covariance.T, rtol=0, atol=0)
    for x in loads:
        assert res.correlation(x, x) == pytest.approx(1.0)
        for y in loads:
            rho = res.correlation(x, y)
            assert -1.0 <= rho <= 1.0 and rho == res.correlation(y, x)
            i, j = loads.index(x), loads.index(y)
            assert rho == pytest.approx(cov[i, j] / scale[i, j], abs=1e-9)
    with pytest.raises(InputError, match="output 'nope'"):
        res.correlation("nope", "root_shear")


def test_oscillator_under_a_sampled_gain_against_brute_force():
    # x'' + 2 z wn x' + wn^2 x = wn^2 (gust + u), u = -g x' sampled at 100 Hz, von Karman.
    # Brute force, written out here: H_s from 2x2 algebra, 12-point Gauss on 200 panels per
    # period up to 1600 periods (1e6 rad/s), beyond the period average of the leading term
    # (its error ~ 1e-3 share x 1e-4). A-bar to 1e-9, N0 and the cross term to 1e-7: this
    # checks the period averages beyond w_a = 20 P and their Euler-Maclaurin terms.
    wn, zeta, rate, g, v = 50.0, 0.05, 100.0, 0.01, 120.0
    a = np.array([[0.0, 1.0], [-(wn**2), -2 * zeta * wn]])
    b = np.array([[0.0, 0.0], [wn**2, wn**2]])
    sys = control.ss(a, b, np.eye(2), np.zeros((2, 2)), inputs=["gust", "u"], outputs=["x", "v"])
    sys.speed = v
    res = turbulence_response(
        sys, ["x", "v"], controller=static_gain([[g]], ["u"], sensors=["v"], sample_rate=rate)
    )
    dt = 1 / rate
    period = 2 * math.pi / dt
    e = sla.expm(np.block([[a, b[:, [1]]], [np.zeros((1, 3))]]) * dt)
    phi, gu = e[:2, :2], e[:2, 2]

    def inv2(m):
        det = m[:, 0, 0] * m[:, 1, 1] - m[:, 0, 1] * m[:, 1, 0]
        adj = np.stack(
            [np.stack([m[:, 1, 1], -m[:, 0, 1]], -1), np.stack([-m[:, 1, 0], m[:, 0, 0]], -1)], -2
        )
        return adj / det[:, None, None]

    def hs(w):
        s, z = 1j * w, np.exp(1j * w * dt)
        x_ol = inv2(s[:, None, None] * np.eye(2) - a) @ b[:, 0]
        x_u = inv2(z[:, None, None] * np.eye(2) - phi) @ gu
        u = -g * x_ol[:, 1] / (1 + g * x_u[:, 1])
        return x_ol + x_u * u[:, None]

    spec = von_karman(L)
    gx, gw = np.polynomial.legendre.leggauss(12)

    def moments(w, wt):
        h = hs(w)
        f = spec.time_psd(w, v) * wt
        prod = [abs(h[:, 0]) ** 2, abs(h[:, 1]) ** 2, (h[:, 0] * h[:, 1].conj()).real]
        return np.array([np.sum(p * f) for p in prod] + [np.sum(w**2 * p * f) for p in prod[:2]])

    def gauss(edges):
        mid, half = (edges[1:] + edges[:-1]) / 2, (edges[1:] - edges[:-1]) / 2
        return (mid[:, None] + half[:, None] * gx).ravel(), (half[:, None] * gw).ravel()

    acc = moments(*gauss(np.concatenate([[0.0], np.logspace(-6, math.log10(period), 800)])))
    t, wt = gauss(np.linspace(0.0, period, 201))
    n_per = 1600
    for k in range(1, n_per, 100):
        ks = np.arange(k, min(k + 100, n_per))
        acc += moments((ks[:, None] * period + t).ravel(), np.tile(wt, ks.size))
    top = n_per * period
    th = top + np.linspace(0.0, period, 20001)[:-1]
    h1 = hs(th) * (1j * th)[:, None]
    avg = [
        np.mean(abs(h1[:, 0]) ** 2),
        np.mean(abs(h1[:, 1]) ** 2),
        np.mean((h1[:, 0] * h1[:, 1].conj()).real),
    ]
    kt, p = spec.tail_coefficient * v ** (2 / 3), 5 / 3
    acc += (
        np.array(avg + avg[:2])
        * kt
        * top ** (-np.array([p + 1] * 3 + [p - 1] * 2))
        / np.array([p + 1] * 3 + [p - 1] * 2)
    )
    n0 = np.sqrt(acc[3:] / acc[:2]) / (2 * math.pi)
    for i, n in enumerate(["x", "v"]):
        assert res.a_bar[n] == pytest.approx(math.sqrt(acc[i]), rel=1e-9), n
        assert res.n0[n] == pytest.approx(n0[i], rel=1e-7), n
    assert res.covariance[0, 1] == pytest.approx(acc[2], rel=1e-7)


def test_von_karman_closed_loop_converged(wing6):
    # refining rtol (1e-7 -> 1e-11) or moving the closed-form tail (10 x or 1e5 x the spectral
    # radius of A instead of 1000 x) changes A-bar and N0 of the LQR loop above V_f < 1e-9
    vf, loop, _ = wing6
    plant = loop.plant(1.1 * vf)
    ctrl = design(wing6, "lqr", 1000.0)
    outs = LOADS + ["tip_le_accel"]
    ref = turbulence_response(plant, outs, controller=ctrl, rtol=1e-11)
    rho = np.max(np.abs(np.linalg.eigvals(plant.A)))
    for kw in ({"rtol": 1e-7}, {"omega_hi": 10 * rho}, {"omega_hi": 1e5 * rho}):
        r = turbulence_response(plant, outs, controller=ctrl, **kw)
        for n in outs:
            assert r.a_bar[n] == pytest.approx(ref.a_bar[n], rel=1e-9), (kw, n)
            assert r.n0[n] == pytest.approx(ref.n0[n], rel=1e-9), (kw, n)
