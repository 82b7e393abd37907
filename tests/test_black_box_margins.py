"""Loop margins at the actuator with the controller a black box, checked against loops built in
this file.

The field breaks a flight-control loop at the plant input (the actuator command) with the
controller a black box from sensors to commands: its estimator predicts with the command it
computed, and only the plant sees the perturbation (MIL-F-9490D, sec. 3.1.3.6: 6 dB gain margin
both ways and 45 deg phase margin there). Each test here closes the sampled loop itself, from the
continuous plant matrices (zero-order hold by ``scipy.linalg.expm`` of the augmented matrix; the
input held over the last interval as a state, for the sensors' feedthrough ``Du``) and the
controller's black-box matrices, inserts at the actuator the perturbation a margin claims to
bound, and reads the spectral radius of the perturbed loop:

* a real gain ``k`` (gain margins), a phase ``exp(j phi)`` (phase margin);
* a disk ``f = (2 + d) / (2 - d)``, ``|d| <= alpha`` (balanced disk margin; Seiler, Packard &
  Gahinet, "An introduction to disk margins", IEEE Control Systems 40(5), 2020), one input at a
  time or, for the simultaneous (multiloop) margin, a diagonal ``f_i`` at every input.

Nothing of :mod:`aeroservo.design.sampled_loop` is used to build these loops. python-control's
``stability_margins`` and ``disk_margins`` are a second method on low-order loops, and a user's
LQR gain and a python-control LQG equal to the built-in designs must give the same boundary,
margins and time history.
"""

from __future__ import annotations

import functools

import control
import numpy as np
import pytest
import scipy.linalg as sla
import scipy.optimize as so
from conftest import ROOT
from ideal_loops import ideal

import aeroservo as aes
from aeroservo.design.compensator import compensator_from_lti
from aeroservo.design.margin_channel import channel_margins
from aeroservo.design.margins import loop_margins
from aeroservo.files import load_scenario
from aeroservo.simulate import simulate
from aeroservo.stability.boundary import flutter_boundary

CONTROL = "aileron_hinge_moment"
DT = 1e-3  # the shipped scenarios sample at 1 kHz
AT = 1e-6  # "the spectral radius reaches 1": |rho - 1| below this at a reported margin
EDGE = 1e-6  # rho - 1 changes sign between (1 - EDGE) and (1 + EDGE) x a reported margin
INSIDE = 1e-3  # relative distance inside a reported margin of the sample points
SAME = 1e-9  # relative agreement of equivalent controllers

# ---------------------------------------------------------------------------------------------
# the sampled loop, built here


def zoh(A, B, dt):
    """Exact zero-order hold: ``expm([[A, B], [0, 0]] dt) = [[Phi, G], [0, I]]``."""
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n] = A
    M[:n, n:] = B
    E = sla.expm(M * dt)
    return E[:n, :n], E[:n, n:]


def plant_arrays(plant, inputs, outputs):
    """``(A, B, C, D)`` of a python-control plant for named inputs and outputs."""
    ii = [list(plant.input_labels).index(s) for s in inputs]
    oo = [list(plant.output_labels).index(s) for s in outputs]
    A, B, C, D = (np.asarray(x, dtype=float) for x in (plant.A, plant.B, plant.C, plant.D))
    return A, B[:, ii], C[oo], D[np.ix_(oo, ii)]


def broken_state_feedback(plant, controls, gain, dt=DT):
    """The loop ``c = -gain x`` broken at the actuator: ``(A, B, C)`` with the applied input
    ``w`` in, the command ``o`` out (``z+ = A z + B w``, ``o = C z``); closed by ``w = F o``."""
    A, B, _, _ = plant_arrays(plant, controls, [])
    Phi, G = zoh(A, B, dt)
    return Phi, G, -np.asarray(gain, dtype=float)


def broken_black_box(plant, controls, sensors, box, dt=DT):
    """A black box ``c = Ck s + Dk y``, ``s+ = Ak s + Bk y`` on the sensors
    ``y = C x + D h`` (``h`` the input held over the last interval), broken at the actuator.

    State ``[x, h, s]``: ``x+ = Phi x + G w``, ``h+ = w``, ``s+ = Ak s + Bk (C x + D h)``;
    ``o = Dk C x + Dk D h + Ck s``. The controller's state sees only the sensors: the
    perturbation ``w = F o`` reaches the plant alone."""
    Ak, Bk, Ck, Dk = (np.atleast_2d(np.asarray(x, dtype=float)) for x in box)
    A, B, C, D = plant_arrays(plant, controls, sensors)
    Phi, G = zoh(A, B, dt)
    n, m = G.shape
    ns = Ak.shape[0] if Ak.size else 0
    Ak, Bk, Ck = Ak.reshape(ns, ns), Bk.reshape(ns, len(sensors)), Ck.reshape(m, ns)
    N = n + m + ns
    Ao = np.zeros((N, N))
    Ao[:n, :n] = Phi
    Ao[n + m :, :n] = Bk @ C
    Ao[n + m :, n : n + m] = Bk @ D
    Ao[n + m :, n + m :] = Ak
    Bo = np.vstack([G, np.eye(m), np.zeros((ns, m))])
    Co = np.hstack([Dk @ C, Dk @ D, Ck])
    return Ao, Bo, Co


def broken_estimator(plant, controls, sensors, kf, K, dt=DT):
    """An LQG in filter form, its estimator predicting with the input *applied* (hardware that
    measures it), broken at the actuator: ``xi+ = M (y - Ca xi) + xi`` corrects the prior
    ``xi``, ``o = -K xi+``, and the prior moves on with ``Ad xi+ + Bu w``."""
    A, B, C, D = plant_arrays(plant, controls, sensors)
    Phi, G = zoh(A, B, dt)
    n, m = G.shape
    Ad, Bu, Ca, M = kf.Ad, kf.Bu, kf.Ca, kf.M
    ns = Ad.shape[0]
    F = np.eye(ns) - M @ Ca  # posterior = F xi + M y
    N = n + m + ns
    Ao = np.zeros((N, N))
    Ao[:n, :n] = Phi
    Ao[n + m :, :n] = Ad @ M @ C
    Ao[n + m :, n : n + m] = Ad @ M @ D
    Ao[n + m :, n + m :] = Ad @ F
    Bo = np.vstack([G, np.eye(m), Bu])
    Co = -K @ np.hstack([M @ C, M @ D, F])
    return Ao, Bo, Co


def perturbed(ol, f):
    """The loop closed through ``w = F o`` (``F = diag(f)``, or a scalar on every input)."""
    A, B, C = ol
    f = np.broadcast_to(np.asarray(f), (B.shape[1],))
    return A + (B * f[None, :]) @ C


def radius(M):
    return float(np.max(np.abs(np.linalg.eigvals(M))))


def nearest_circle(M):
    """The eigenvalue of M nearest the unit circle."""
    lam = np.linalg.eigvals(M)
    return lam[int(np.argmin(np.abs(np.abs(lam) - 1.0)))]


def return_ratio(ol, theta):
    """``L(exp(j theta)) = -C (zI - A)^-1 B`` (solves; one input)."""
    A, B, C = ol
    eye = np.eye(A.shape[0])
    return np.array([(-C @ np.linalg.solve(np.exp(1j * t) * eye - A, B)).item() for t in theta])


def one_channel(ol, j):
    """Input ``j`` broken, the other inputs closed."""
    A, B, C = ol
    others = [i for i in range(B.shape[1]) if i != j]
    return (A + B[:, others] @ C[others] if others else A), B[:, [j]], C[[j]]


def hz(angle, dt=DT):
    return abs(float(np.angle(angle))) / (2 * np.pi * dt)


def check_actuator_margins(ol, ch, dt=DT):
    """Every figure of one input channel ``ch`` against the loop ``ol`` built here.

    * gains: the spectral radius of the loop with a real gain ``k`` at the actuator is 1 at the
      reported ``k`` (to :data:`AT`), below 1 at sample gains between the two, crosses 1
      between ``(1 -+ EDGE) k`` (the margin to 1e-6), and the pole on the unit circle is at
      the reported frequency;
    * phase: 1 at ``exp(+-j PM)`` (both signs: ``L`` is real), below 1 for ``|phi| < PM``,
      crossing 1 between ``(1 -+ EDGE) PM``;
    * disk: below 1 for ``f = (2 + d) / (2 - d)`` on the circle ``|d| = alpha (1 - 1e-3)``; at
      the reported frequency the ``f`` with ``1 + f L = 0`` has ``|d| = alpha`` and puts a pole
      there (crossing between ``(1 -+ EDGE) d``); ``|S - 1/2|`` of the loop built here never
      exceeds ``1 / alpha`` on a grid;
    * the open-loop poles outside the unit circle, and the encirclements (Nyquist), match.
    """
    A, B, C = ol
    assert ch.stable and ch.nyquist_stable
    assert radius(perturbed(ol, 1.0)) < 1.0
    n_out = int(np.sum(np.abs(np.linalg.eigvals(A)) > 1.0))
    assert ch.open_loop_unstable == n_out
    assert ch.encirclements == pytest.approx(n_out, abs=1e-6)

    # gain margins (MIL-F-9490D: +-6 dB required; here only their values are checked)
    k_up = 10 ** (ch.gain_margin_db / 20)
    k_dn = 10 ** (ch.gain_reduction_margin_db / 20)
    f_dn, f_up = ch.gain_frequencies
    for k, f, side in ((k_up, f_up, 1), (k_dn, f_dn, -1)):  # side: where the outside is
        if not (np.isfinite(k) and k > 0):
            assert f is None
            continue
        M = perturbed(ol, k)
        assert radius(M) == pytest.approx(1.0, abs=AT)
        assert hz(nearest_circle(M), dt) == pytest.approx(f, rel=1e-6, abs=1e-6)
        ins, out = (perturbed(ol, k * (1 + e * side * EDGE)) for e in (-1, 1))
        assert radius(out) > 1.0 > radius(ins)
    lo = k_dn * (1 + INSIDE) if k_dn > 0 else 1e-3
    hi = k_up * (1 - INSIDE) if np.isfinite(k_up) else 1e3
    for k in np.geomspace(lo, hi, 7):
        assert radius(perturbed(ol, k)) < 1.0, k

    # phase margin (MIL-F-9490D: 45 deg)
    if np.isfinite(ch.phase_margin_deg):
        pm = np.radians(ch.phase_margin_deg)
        for s in (1, -1):
            M = perturbed(ol, np.exp(1j * s * pm))
            assert radius(M) == pytest.approx(1.0, abs=AT)
            assert hz(nearest_circle(M), dt) == pytest.approx(ch.phase_frequency, rel=1e-6)
            ins, out = (perturbed(ol, np.exp(1j * s * pm * (1 + e))) for e in (-EDGE, EDGE))
            assert radius(out) > 1.0 > radius(ins)
        for phi in np.linspace(-pm, pm, 9)[1:-1] * (1 - INSIDE):
            assert radius(perturbed(ol, np.exp(1j * phi))) < 1.0, phi

    # disk margin (Seiler, Packard & Gahinet 2020): f = (2 + d) / (2 - d), |d| < alpha
    alpha = ch.disk_margin
    assert 0 < alpha < 2
    for psi in np.linspace(0, 2 * np.pi, 17)[:-1]:
        d = alpha * (1 - INSIDE) * np.exp(1j * psi)
        assert radius(perturbed(ol, (2 + d) / (2 - d))) < 1.0, psi
    theta = 2 * np.pi * ch.disk_frequency * dt
    L = return_ratio(ol, [theta])[0]
    f = -1.0 / L
    d = 2 * (f - 1) / (f + 1)
    assert abs(d) == pytest.approx(alpha, rel=1e-6)
    M = perturbed(ol, f)
    assert np.min(np.abs(np.linalg.eigvals(M) - np.exp(1j * theta))) < 1e-6
    assert radius(M) == pytest.approx(1.0, abs=AT)
    ins, out = (perturbed(ol, (2 + x) / (2 - x)) for x in (d * (1 - EDGE), d * (1 + EDGE)))
    assert radius(out) > 1.0 > radius(ins)
    grid = np.unique(np.r_[np.geomspace(1e-4, np.pi, 300), np.linspace(0, np.pi, 301)])
    Lg = return_ratio(ol, grid)
    assert np.max(np.abs(1 / (1 + Lg) - 0.5)) <= (1 + 1e-6) / alpha


# ---------------------------------------------------------------------------------------------
# the shipped loops


@functools.cache
def shipped(kind: str):
    """``(loop, plant, controller as designed, spec, vf, speed)`` of a shipped scenario at
    1.1 x its open-loop flutter speed (a schedule is returned as it is)."""
    sc = ideal(load_scenario(ROOT / "scenarios" / f"goland_aileron_{kind}.toml"))
    model = sc.model()
    vf = flutter_boundary(model, sc.density).flutter_speed
    loop = sc.loop(model)
    speed = 1.1 * vf
    ctrl = loop.design_controller(sc.controller, speed, sc.sample_rate, vf)
    assert sc.sample_rate == 1 / DT
    return loop, loop.plant(speed), ctrl, sc.controller, vf, speed


STATIC_SENSORS = ("tip_twist", "tip_le_accel")
STATIC_K = np.array([[3.83e4, -2.14]])
"""A static output gain ``u = -K [twist, le accel]`` [N m/rad, N m/(m/s^2)] that stabilizes the
wing at 1.1 V_f (found by a search for the largest disk margin, about 0.26)."""


def case(kind: str):
    """``(plant, controller handed to loop_margins, loop broken here, measured_input)``."""
    if kind == "lqr":
        loop, plant, ctrl, *_ = shipped("lqr")
        return plant, ctrl, broken_state_feedback(plant, [CONTROL], ctrl.gain), False
    if kind in ("lqg", "lqg_measured"):
        loop, plant, sched, *_, speed = shipped("lqg")
        ctrl = sched.at(speed)
        if kind == "lqg_measured":  # the estimator's prediction input is the law's L = Bu
            assert np.array_equal(ctrl.law().L, ctrl.kf.Bu)
            ol = broken_estimator(plant, [CONTROL], ctrl.sensors, ctrl.kf, ctrl.K)
            return plant, sched, ol, True
        comp = ctrl.compensator
        assert list(comp.output_labels) == [CONTROL]
        box = (comp.A, comp.B, comp.C, comp.D)
        return plant, sched, broken_black_box(plant, [CONTROL], comp.input_labels, box), False
    if kind == "mpc":
        loop, plant, ctrl, *_ = shipped("mpc")
        law = ctrl.law()
        box = (law.A, law.B, law.C, law.D)
        return plant, ctrl, broken_black_box(plant, [CONTROL], law.sensors, box), False
    if kind == "hinf":
        loop, plant, ctrl, *_ = shipped("hinf")
        box = (ctrl.Ac, ctrl.Bc, ctrl.Cc, ctrl.Dc)
        return plant, ctrl, broken_black_box(plant, [CONTROL], ctrl.sensors, box), False
    if kind == "user_statespace":  # the H-infinity design changed a little, as a user brings it
        loop, plant, h, *_ = shipped("hinf")
        rng = np.random.default_rng(11)
        Bc = h.Bc * (1 + 0.02 * rng.standard_normal(h.Bc.shape))
        Cc = h.Cc * (1 + 0.02 * rng.standard_normal(h.Cc.shape))
        sys = control.ss(h.Ac, Bc, Cc, h.Dc, DT, inputs=list(h.sensors), outputs=[CONTROL])
        box = (h.Ac, Bc, Cc, h.Dc)
        return plant, sys, broken_black_box(plant, [CONTROL], h.sensors, box), False
    if kind == "user_gain":
        loop, plant, *_ = shipped("hinf")
        g = aes.design.static_gain(STATIC_K, [CONTROL], sensors=STATIC_SENSORS, sample_rate=1e3)
        box = (np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((1, 0)), -STATIC_K)
        return plant, g, broken_black_box(plant, [CONTROL], STATIC_SENSORS, box), False
    raise KeyError(kind)


KINDS = ["lqr", "lqg", "lqg_measured", "mpc", "hinf", "user_statespace", "user_gain"]


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.slow
def test_margins_against_loop_built_here(kind):
    """The margins at the hinge-moment input of every kind of controller (the built-in LQR,
    LQG, MPC without active constraints and H-infinity, a python-control ``StateSpace`` and a
    static output gain brought by a user) on the 98-state wing at 1.1 x its flutter speed, two
    open-loop poles outside the unit circle: each figure confirmed by the spectral radius of the
    loop built here with the perturbation at the actuator (:func:`check_actuator_margins`). The
    LQG is also broken where hardware measures the applied input and feeds it to the estimator
    (``measured_input=True``), against the estimator built here predicting with that input."""
    plant, ctrl, ol, measured = case(kind)
    m = loop_margins(plant, ctrl, measured_input=measured)
    assert m.measured_input is measured
    ch = m.channels[CONTROL]
    assert ch.open_loop_unstable >= 2  # the flutter pair, at least
    check_actuator_margins(ol, ch)
    # one input: the simultaneous disk margin is the channel's
    assert m.multiloop["disk_margin"] == ch.disk_margin
    d = m.to_dict()["channels"][CONTROL]
    assert d["gain_margin_db"] == pytest.approx(ch.gain_margin_db, rel=1e-12)
    assert d["disk_margin"] == pytest.approx(ch.disk_margin, rel=1e-12)


def test_black_box_and_measured_input_differ_for_the_lqg():
    """The two input break points of the LQG are different loops (in the black box the
    estimator predicts with its own, unperturbed command; with ``measured_input`` with the
    perturbed input applied), so their margins differ; the black box's margins are those of
    ``ctrl.compensator`` alone, brought as a python-control ``StateSpace`` (its law's ``L`` is
    then an anti-windup gain, not ``Bu``: it does not enter the black box's margins)."""
    plant, sched, *_ = case("lqg")
    box = loop_margins(plant, sched).channels[CONTROL]
    meas = loop_margins(plant, sched, measured_input=True).channels[CONTROL]
    assert abs(box.gain_margin_db - meas.gain_margin_db) > 1e-3
    comp = sched.at(plant.speed).compensator
    alone = loop_margins(plant, comp).channels[CONTROL]
    for key in ("gain_margin_db", "gain_reduction_margin_db", "phase_margin_deg", "disk_margin"):
        assert getattr(alone, key) == pytest.approx(getattr(box, key), rel=1e-9), key


# ---------------------------------------------------------------------------------------------
# a second method on low-order loops: python-control


def random_siso_loop(seed: int):
    """A random SISO sampled loop ``L = -C (zI - A)^-1 B`` (order 2 to 8, poles of radius 0.75
    to 1.06, so often some outside the unit circle) whose closed loop ``A + B C`` is stable."""
    rng = np.random.default_rng(1000 + seed)
    while True:
        n = int(rng.integers(2, 9))
        blocks = []
        while sum(b.shape[0] for b in blocks) < n - 1:
            r, th = rng.uniform(0.75, 1.06), rng.uniform(0.02, 3.0)
            a, b = r * np.cos(th), r * np.sin(th)
            blocks.append(np.array([[a, b], [-b, a]]))
        if sum(b.shape[0] for b in blocks) < n:
            blocks.append(np.array([[rng.uniform(-0.95, 1.05)]]))
        T = rng.standard_normal((n, n))
        if np.linalg.cond(T) > 1e3:
            continue
        A = T @ sla.block_diag(*blocks) @ np.linalg.inv(T)
        B = rng.standard_normal((n, 1))
        C = rng.standard_normal((1, n)) * rng.uniform(0.05, 1.0)
        if radius(A + B @ C) < 0.995:
            return A, B, C


def pc_disk_margin(sys, dt):
    """python-control's disk margin (``disk_margins`` on a grid, its minimum then refined by
    ``minimize_scalar`` between the grid neighbours) and the frequency [rad/s]."""
    w = np.unique(np.r_[np.geomspace(1e-5, np.pi, 3000), np.linspace(0, np.pi, 3000)]) / dt
    dm = control.disk_margins(sys, w, returnall=True)[0]
    i = int(np.argmin(dm))
    lo, hi = w[max(i - 1, 0)], w[min(i + 1, w.size - 1)]

    def at(x):
        return float(control.disk_margins(sys, np.array([x]), returnall=True)[0][0])

    res = so.minimize_scalar(at, bounds=(lo, hi), method="bounded", options={"xatol": 1e-10})
    return (res.fun, res.x) if res.fun < dm[i] else (dm[i], w[i])


@pytest.mark.parametrize("seed", range(16))
def test_low_order_loops_against_python_control(seed):
    """On random low-order sampled loops, :func:`channel_margins` agrees with python-control to
    1e-6: ``stability_margins`` (every gain and phase crossing; python-control leaves out the
    crossings at 0 and at the Nyquist frequency, added here from ``L(+-1)``) and
    ``disk_margins`` (Seiler, Packard & Gahinet 2020, balanced: ``skew = 0``), with the
    frequencies; and the disk's simultaneous gain and phase ranges lie inside the
    loop-at-a-time gain and phase margins (the figures MIL-F-9490D judges: 6 dB, 45 deg)."""
    A, B, C = random_siso_loop(seed)
    ch = channel_margins(A, B, C, "u", DT)
    sys = control.ss(A, B, -C, 0, DT)  # python-control's loop closes as 1 + L
    gm, pm, _sm, wpc, wgc, _wms = control.stability_margins(sys, returnall=True)
    gains = [(g, w * DT) for g, w in zip(np.atleast_1d(gm), np.atleast_1d(wpc), strict=True)]
    for th in (0.0, np.pi):  # python-control skips crossings at DC and at the Nyquist frequency
        end = return_ratio((A, B, C), [th])[0].real
        if end < 0 and not any(g == pytest.approx(-1 / end, rel=1e-6) for g, _ in gains):
            gains.append((-1 / end, th))
    up = min([(g, t) for g, t in gains if g > 1], default=(np.inf, None))
    down = max([(g, t) for g, t in gains if 0 < g < 1], default=(0.0, None))
    assert 10 ** (ch.gain_margin_db / 20) == pytest.approx(up[0], rel=1e-6)
    assert 10 ** (ch.gain_reduction_margin_db / 20) == pytest.approx(down[0], rel=1e-6, abs=1e-12)
    to_hz = 1 / (2 * np.pi * DT)
    for f, (_, t) in zip(ch.gain_frequencies, (down, up), strict=True):
        assert (f is None) == (t is None)
        if t is not None:
            assert f == pytest.approx(t * to_hz, rel=1e-6, abs=1e-9)
    pms = np.abs(np.atleast_1d(pm))
    if pms.size:
        i = int(np.argmin(pms))
        assert ch.phase_margin_deg == pytest.approx(pms[i], rel=1e-6)
        assert ch.phase_frequency == pytest.approx(np.atleast_1d(wgc)[i] / (2 * np.pi), rel=1e-6)
    else:
        assert ch.phase_margin_deg == np.inf
    dm, w_dm = pc_disk_margin(sys, DT)
    assert ch.disk_margin == pytest.approx(dm, rel=1e-6)
    assert ch.disk_frequency == pytest.approx(w_dm / (2 * np.pi), rel=1e-4, abs=1e-3)
    _, dgm, dpm = control.disk_margins(sys, np.array([w_dm]), returnall=True)
    assert ch.disk_gain_margin_db == pytest.approx(dgm[0], rel=1e-6)
    assert ch.disk_phase_margin_deg == pytest.approx(dpm[0], rel=1e-6)
    assert ch.disk_gain_margin_db <= ch.gain_margin_db + 1e-9
    assert -ch.disk_gain_margin_db >= ch.gain_reduction_margin_db - 1e-9
    assert ch.disk_phase_margin_deg <= ch.phase_margin_deg + 1e-9


# ---------------------------------------------------------------------------------------------
# equivalence: the built-in designs and the same controllers brought by a user


def python_control_lqg(loop, spec, speed, dt=DT):
    """The LQG of ``spec`` designed here with python-control on the design model of ``loop``
    at ``speed``: ``control.dlqr`` and ``control.dlqe`` on the sampled design model augmented
    with the held command (``xi = [x, h]``, ``y = C x + Du h``), the Kalman filter in filter
    form, returned as a discrete ``control.StateSpace`` from the sensors to the commands (the
    black box) and the estimator's input matrix ``Bu`` (it predicts with the input applied).
    """
    sys = loop.design(speed)
    controls, sensors = list(loop.controls), list(loop.sensors)
    A, B, Cs, Du = plant_arrays(sys, controls, sensors)
    _, Bg, _, _ = plant_arrays(sys, ["gust"], sensors)
    n, m = B.shape
    Phi, G = zoh(A, np.hstack([B, Bg]), dt)
    Ad = sla.block_diag(Phi, np.zeros((m, m)))
    Bu = np.vstack([G[:, :m], np.eye(m)])
    Bd = np.vstack([G[:, m:], np.zeros((m, 1))])
    Ca = np.hstack([Cs, Du])
    # Bryson's rule on the weighted outputs (with their feedthrough), a small weight on all states
    names = list(spec.bryson_outputs)
    _, _, Cz, Dz = plant_arrays(sys, controls, names)
    w = np.array([spec.bryson_outputs[k] ** -2.0 for k in names])
    Q = Cz.T @ (w[:, None] * Cz)
    Q = Q + spec.state_weight * np.trace(Q) / n * np.eye(n)
    R = Dz.T @ (w[:, None] * Dz) + np.diag([spec.bryson_inputs[c] ** -2.0 for c in controls])
    Qa = sla.block_diag(0.5 * (Q + Q.T), np.zeros((m, m)))
    Na = np.vstack([Cz.T @ (w[:, None] * Dz), np.zeros((m, m))])
    # control.dlqr on these coordinates gives the gain to only ~1e-7 (SLICOT's solver on a
    # poorly scaled structural model; scipy's ~2e-8): like the built-in design, solve it in
    # coordinates equilibrated by a diagonal similarity x = T x~ (K = K~ T^-1), where
    # python-control's gain agrees with the built-in one to rounding.
    _, (t, _) = sla.matrix_balance(Ad, permute=False, separate=True)
    At = Ad * (1 / t)[:, None] * t[None, :]
    Qt = Qa * t[:, None] * t[None, :]
    Kt, _, _ = control.dlqr(At, Bu / t[:, None], Qt * dt, R * dt, Na * t[:, None] * dt)
    K = np.asarray(Kt) / t[None, :]
    # Kalman filter: control.dlqe's a-priori covariance P; filter form M = P Ca' (Ca P Ca' + V)^-1
    # (gust noise, and the fictitious input noise of loop transfer recovery with Bu)
    W = np.diag([spec.process_noise["gust"]] + [spec.input_noise[c] for c in controls])
    V = np.diag([spec.sensor_noise[s] for s in sensors])
    _, P, _ = control.dlqe(Ad, np.hstack([Bd, Bu]), Ca, W, V)
    M = np.linalg.solve(Ca @ P @ Ca.T + V, Ca @ P).T
    # the compensator: c = -K xi+, xi+ = (I - M Ca) xi + M y, xi[k+1] = Ad xi+ + Bu c
    F = np.eye(n + m) - M @ Ca
    AK = Ad - Bu @ K
    comp = control.ss(AK @ F, AK @ M, -K @ F, -K @ M, dt, inputs=sensors, outputs=controls)
    return comp, Bu, K, M


PEAK_AT = {
    "disk_frequency",
    "frequency",
    "peak_sensitivity_frequency",
    "peak_complementary_sensitivity_frequency",
}
"""Frequencies where a smooth function peaks (the disk margin's, the sensitivities'): the place
of a maximum moves by ~sqrt(eps) when its values move by eps, so two controllers equal to 1e-12
put it at the same frequency to ~1e-6 only (the peak *values* agree to 1e-9)."""


def assert_same(a, b, rel=SAME, path="margins"):
    """Two ``to_dict()`` trees equal, numbers to ``rel`` (the controller's name aside; the
    frequencies of :data:`PEAK_AT` to 1e-6)."""
    if isinstance(a, dict):
        assert set(a) == set(b), path
        for k in a:
            if k != "law":
                assert_same(a[k], b[k], 1e-6 if k in PEAK_AT else rel, f"{path}.{k}")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same(x, y, rel, f"{path}[{i}]")
    elif isinstance(a, float) and b is not None:
        assert a == pytest.approx(b, rel=rel, abs=1e-12), path
    else:
        assert a == b, path


def equivalent(kind):
    """``(loop, spec, vf, speed, built-in controller, the same brought by a user)``."""
    loop, plant, ctrl, spec, vf, speed = shipped(kind)
    if kind == "lqr":
        states = list(plant.state_labels)
        user = aes.design.static_gain(ctrl.gain, [CONTROL], states=states, sample_rate=1e3)
        return loop, spec, vf, speed, ctrl, user
    ctrl = ctrl.at(speed)  # the scheduled LQG at its design speed 1.1 V_f: a fixed design
    comp, Bu, K, M = python_control_lqg(loop, spec, speed)
    # two Riccati solutions (python-control's and the package's): measured 4e-11 of the largest
    # gain with numpy 2.4 / scipy 1.17 (2e-13 before); the bound is the solutions' conditioning
    assert np.abs(K - ctrl.K).max() <= 1e-9 * np.abs(ctrl.K).max()
    assert np.abs(M - ctrl.kf.M).max() <= 1e-10 * np.abs(ctrl.kf.M).max()
    # brought with its estimator's prediction input (what it does when a limit cuts the command)
    user = compensator_from_lti(comp, sample_rate=1e3, anti_windup=Bu, source="python-control")
    return loop, spec, vf, speed, ctrl, user


@pytest.mark.parametrize("kind", ["lqr", "lqg"])
def test_user_controller_equals_built_in(kind):
    """A user's static state gain equal to the built-in LQR's (``static_gain(ctrl.gain,
    states=plant.state_labels)``), and an LQG designed with python-control's ``dlqr`` and
    ``dlqe`` on the same sampled augmented design model, brought as a ``StateSpace``, give the
    built-in design's closed-loop flutter boundary (up to 2 V_f), loop margins (every figure of
    every break point) and time history (0.3 s from a 1 cm tip deflection, with the
    scenario's actuator limits and with limits that cut the command) to 1e-9."""
    loop, spec, vf, speed, ctrl, user = equivalent(kind)
    plant = loop.plant(speed)

    b0, b1 = (
        aes.design.closed_loop_boundary(loop, c, 2 * vf, reference_speed=speed)
        for c in (ctrl, user)
    )
    g = np.abs(b0.abscissa).max()
    np.testing.assert_allclose(b1.abscissa, b0.abscissa, rtol=0, atol=SAME * g)
    assert b1.reference_abscissa == pytest.approx(b0.reference_abscissa, rel=SAME)
    assert b0.crossings and len(b1.crossings) == len(b0.crossings)
    for c0, c1 in zip(b0.crossings, b1.crossings, strict=True):
        assert (c1["kind"], c1["static"]) == (c0["kind"], c0["static"])
        assert c1["speed"] == pytest.approx(c0["speed"], rel=SAME)
        assert c1["frequency"] == pytest.approx(c0["frequency"], rel=SAME, abs=1e-9)
    assert b0.flutter is not None and b0.flutter["speed"] > speed

    m0, m1 = (loop_margins(plant, c).to_dict() for c in (ctrl, user))
    assert_same(m1, m0)

    # the scenario's limits, then limits tight enough to cut the command (the estimator then
    # predicts with the input applied: the brought LQG's anti-windup gain is its Bu)
    tight = aes.design.Limits(magnitude={CONTROL: 150.0}, rate={CONTROL: 2e4})
    for limits in (spec.limits, tight):
        run = {"duration": 0.3, "x0": loop.initial_state(0.01), "limits": limits}
        r0, r1 = simulate(plant, ctrl, **run), simulate(plant, user, **run)
        if limits is tight:
            assert r0.saturated_fraction[CONTROL] > 0.05
        for name in ("outputs", "commands", "applied"):
            s0, s1 = getattr(r0, name), getattr(r1, name)
            assert list(s1) == list(s0)
            for sig in s0:
                peak = np.abs(s0[sig]).max()
                assert peak > 0
                np.testing.assert_allclose(s1[sig], s0[sig], rtol=0, atol=SAME * peak, err_msg=sig)


# ---------------------------------------------------------------------------------------------
# two inputs: the simultaneous (multiloop) disk margin

TWO = ["u1", "u2"]
TWO_SENSORS = ["y1", "y2"]


def random_two_input_loop(seed: int):
    """A random continuous plant (5 states, two lightly damped or unstable modes and a real
    pole, at least one pole in the right half-plane) from two inputs to two sensors, ``y1``
    with a direct feedthrough (so the sensors read the held input), and a static output gain
    ``u = -K y`` that stabilizes the loop sampled at 1 kHz: ``(plant, K, loop broken here)``."""
    rng = np.random.default_rng(seed)
    while True:
        blocks = []
        for _ in range(2):
            w, z = rng.uniform(20, 300), rng.uniform(-0.05, 0.2)
            blocks.append(np.array([[-z * w, w], [-w, -z * w]]))
        blocks.append(np.array([[rng.uniform(-50, 20)]]))
        T = rng.standard_normal((5, 5))
        if np.linalg.cond(T) > 1e2:
            continue
        A = T @ sla.block_diag(*blocks) @ np.linalg.inv(T)
        if not np.any(np.linalg.eigvals(A).real > 0):
            continue
        B = 50 * rng.standard_normal((5, 2))
        C = rng.standard_normal((2, 5))
        D = 0.3 * np.array([rng.standard_normal(2), [0.0, 0.0]])
        states = [f"x{i}" for i in range(5)]
        plant = control.ss(A, B, C, D, inputs=TWO, outputs=TWO_SENSORS, states=states)
        for _ in range(200):
            K = rng.standard_normal((2, 2)) * rng.uniform(0.05, 3)
            box = (np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((2, 0)), -K)
            ol = broken_black_box(plant, TWO, TWO_SENSORS, box)
            if radius(perturbed(ol, 1.0)) < 1:
                return plant, K, ol


def mu_two_blocks(M):
    """The structured singular value of 2x2 matrices ``M`` (leading axis: frequency) for two
    complex scalar blocks, in closed form: ``inf_d sigma_max(diag(d, 1) M diag(1/d, 1))`` (the
    D-scaled upper bound, equal to mu when 2 S + F <= 3, here F = 2 full blocks: Doyle 1982;
    Packard & Doyle 1993) is reached at
    ``d^2 = |M21| / |M12|``, where ``sigma_max^2 = (t + sqrt(t^2 - 4 |det M|^2)) / 2`` with
    ``t = |M11|^2 + |M22|^2 + 2 |M12| |M21|``."""
    a, b, c, e = M[:, 0, 0], M[:, 0, 1], M[:, 1, 0], M[:, 1, 1]
    t = abs(a) ** 2 + abs(e) ** 2 + 2 * abs(b) * abs(c)
    det = abs(a * e - b * c)
    return np.sqrt((t + np.sqrt(np.maximum(t**2 - 4 * det**2, 0.0))) / 2)


def exact_two_input_disk_margin(ol):
    """The simultaneous disk margin of a two-input loop built here, ``1 / max mu(S - I/2)``
    (Seiler, Packard & Gahinet 2020, with :func:`mu_two_blocks`, exact), on a dense grid refined
    by Brent's method to 1e-14 rad: ``(alpha, theta)``."""
    A, B, C = ol
    eye = np.eye(A.shape[0])

    def mu(theta):
        L = np.array([-C @ np.linalg.solve(np.exp(1j * t) * eye - A, B) for t in theta])
        return mu_two_blocks(np.linalg.inv(np.eye(2)[None] + L) - 0.5 * np.eye(2)[None])

    grid = np.unique(np.r_[np.geomspace(1e-6, np.pi, 4000), np.linspace(0, np.pi, 4000)])
    vals = mu(grid)
    i = int(np.argmax(vals))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    res = so.minimize_scalar(
        lambda t: -mu([t])[0], bounds=(lo, hi), method="bounded", options={"xatol": 1e-14}
    )
    peak, theta = (-res.fun, res.x) if -res.fun > vals[i] else (vals[i], grid[i])
    return 1 / peak, theta


def worst_diagonal_perturbation(ol, theta):
    """The ``d = (d1, d2)`` of smallest ``max |d_i|`` whose ``f_i = (2 + d_i) / (2 - d_i)`` put a
    closed-loop pole at ``exp(j theta)``: ``det(I + L F) = 0`` solved for ``f1`` given ``d2``,
    ``max(|d1|, |d2|)`` minimized by Nelder-Mead from a ring of starts."""
    L = return_ratios(ol, theta)

    def d1_of(d2):
        f2 = (2 + d2) / (2 - d2)
        f1 = -(1 + L[1, 1] * f2) / (L[0, 0] * (1 + L[1, 1] * f2) - L[0, 1] * L[1, 0] * f2)
        return 2 * (f1 - 1) / (f1 + 1)

    def size(x):
        return max(abs(d1_of(complex(*x))), np.hypot(*x))

    scale = 1 / mu_two_blocks((np.linalg.inv(np.eye(2) + L) - 0.5 * np.eye(2))[None])[0]
    best = None
    for psi in np.linspace(0, 2 * np.pi, 25)[:-1]:
        x0 = scale * np.array([np.cos(psi), np.sin(psi)])
        opts = {"xatol": 1e-15, "fatol": 1e-16, "maxiter": 2000}
        res = so.minimize(size, x0, method="Nelder-Mead", options=opts)
        if best is None or res.fun < best.fun:
            best = res
    d2 = complex(*best.x)
    return np.array([d1_of(d2), d2])


def return_ratios(ol, theta):
    """The 2x2 return ratio ``L(exp(j theta))`` of a loop built here."""
    A, B, C = ol
    return -C @ np.linalg.solve(np.exp(1j * theta) * np.eye(A.shape[0]) - A, B)


def disk(d):
    return (2 + d) / (2 - d)


@pytest.mark.parametrize("seed", [0, 1, 3, 4])
@pytest.mark.slow
def test_simultaneous_disk_margin_two_inputs(seed):
    """The simultaneous disk margin at two plant inputs (``LoopMargins.multiloop``; Seiler,
    Packard & Gahinet 2020: independent ``f_i = (2 + d_i) / (2 - d_i)``, ``|d_i| <= alpha``, in
    every channel at once) of a static output gain on a random open-loop-unstable plant:

    * conservative: 300 random diagonal perturbations with ``|d_i| < alpha`` (most near the
      boundary) keep the loop built here stable;
    * tight: the exact margin of two blocks (:func:`exact_two_input_disk_margin`) agrees to
      1e-5, python-control's ``disk_margins`` (slycot ``ab13md``) to 1e-5, and the worst
      diagonal perturbation puts a pole on the unit circle at ``max |d_i| = alpha`` (stable
      just inside, unstable just outside);
    * each channel alone (the other closed) passes :func:`check_actuator_margins`, and its disk
      margin is at least the simultaneous one.
    """
    plant, K, ol = random_two_input_loop(seed)
    gain = aes.design.static_gain(K, TWO, sensors=TWO_SENSORS, sample_rate=1e3)
    m = loop_margins(plant, gain)
    alpha = m.multiloop["disk_margin"]
    assert "ab13md" in m.multiloop["method"] and 0 < alpha < 2
    for j, name in enumerate(TWO):
        check_actuator_margins(one_channel(ol, j), m.channels[name])
        assert m.channels[name].disk_margin >= alpha * (1 - 1e-9)

    rng = np.random.default_rng(100 + seed)
    for _ in range(300):
        r = alpha * (1 - 10 ** rng.uniform(-5, 0, 2))
        d = r * np.exp(2j * np.pi * rng.uniform(size=2))
        assert radius(perturbed(ol, disk(d))) < 1.0, d

    exact, theta = exact_two_input_disk_margin(ol)
    assert alpha == pytest.approx(exact, rel=1e-5)  # alpha <= exact: see the test below
    d = worst_diagonal_perturbation(ol, theta)
    assert np.max(np.abs(d)) == pytest.approx(exact, rel=1e-9)
    M = perturbed(ol, disk(d))
    assert np.min(np.abs(np.linalg.eigvals(M) - np.exp(1j * theta))) < 1e-8
    assert radius(perturbed(ol, disk(d * (1 + 1e-6)))) > 1.0
    assert radius(perturbed(ol, disk(d * (1 - 1e-6)))) < 1.0

    A, B, C = ol  # python-control: the loop closes as I + L, L = -C (zI - A)^-1 B
    sys = control.ss(A, B, -C, np.zeros((2, 2)), DT)
    assert pc_disk_margin(sys, DT)[0] == pytest.approx(exact, rel=1e-5)


def test_simultaneous_disk_margin_is_guaranteed_on_a_sharp_peak():
    """The multiloop margin is documented as a guaranteed (conservative) margin: on a loop with
    a sharp peak of ``mu(S - I/2)`` (random seed 2, ``alpha`` about 0.0039), the worst diagonal
    perturbation scaled to ``max |d_i| = (1 - 1e-8) alpha`` must leave the loop stable. (The
    peak's refinement used scipy's default tolerance, 1e-5 rad, and overestimated alpha by
    1.7e-6 here; it now refines to 1e-13 rad, as the single-channel margins do.)"""
    plant, K, ol = random_two_input_loop(2)
    gain = aes.design.static_gain(K, TWO, sensors=TWO_SENSORS, sample_rate=1e3)
    alpha = loop_margins(plant, gain, sensors=False).multiloop["disk_margin"]
    exact, theta = exact_two_input_disk_margin(ol)
    d = worst_diagonal_perturbation(ol, theta)
    d = d * (1 - 1e-8) * alpha / np.max(np.abs(d))
    assert radius(perturbed(ol, disk(d))) < 1.0
    assert alpha <= exact * (1 + 1e-9)
