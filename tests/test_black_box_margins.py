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
INSIDE = 1e-3  # relative step inside (and outside) a reported margin for the sample points
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
      reported ``k`` (to :data:`AT`), below 1 between the two, above 1 just outside, and the
      pole on the unit circle is at the reported frequency;
    * phase: 1 at ``exp(+-j PM)`` (both signs: ``L`` is real), below 1 for ``|phi| < PM``;
    * disk: below 1 for ``f = (2 + d) / (2 - d)`` on the circle ``|d| = alpha (1 - 1e-3)``; at
      the reported frequency the ``f`` with ``1 + f L = 0`` has ``|d| = alpha`` and puts a pole
      there; ``|S - 1/2|`` of the loop built here never exceeds ``1 / alpha`` on a grid;
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
    for k, f, out in ((k_up, f_up, 1 + INSIDE), (k_dn, f_dn, 1 - INSIDE)):
        if not (np.isfinite(k) and k > 0):
            assert f is None
            continue
        M = perturbed(ol, k)
        assert radius(M) == pytest.approx(1.0, abs=AT)
        assert hz(nearest_circle(M), dt) == pytest.approx(f, rel=1e-6, abs=1e-6)
        assert radius(perturbed(ol, k * out)) > 1.0
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
    grid = np.unique(np.r_[np.geomspace(1e-4, np.pi, 300), np.linspace(0, np.pi, 301)])
    Lg = return_ratio(ol, grid)
    assert np.max(np.abs(1 / (1 + Lg) - 0.5)) <= (1 + 1e-6) / alpha
    return {"k_up": k_up, "k_dn": k_dn, "alpha": alpha}


# ---------------------------------------------------------------------------------------------
# the shipped loops


@functools.lru_cache(maxsize=None)
def shipped(kind: str):
    """``(loop, plant, controller as designed, spec, vf, speed)`` of a shipped scenario at
    1.1 x its open-loop flutter speed (a schedule is returned as it is)."""
    sc = load_scenario(ROOT / "scenarios" / f"goland_aileron_{kind}.toml")
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
    """The two break points of the LQG are different loops (the estimator's prediction input
    closes a loop of its own in the black box), so their margins differ; the margins of the
    black box are those of ``ctrl.compensator`` alone, whatever the law's ``L``."""
    plant, sched, *_ = case("lqg")
    box = loop_margins(plant, sched).channels[CONTROL]
    meas = loop_margins(plant, sched, measured_input=True).channels[CONTROL]
    assert abs(box.gain_margin_db - meas.gain_margin_db) > 1e-3
    comp = sched.at(plant.speed).compensator
    alone = loop_margins(plant, comp).channels[CONTROL]
    for key in ("gain_margin_db", "gain_reduction_margin_db", "phase_margin_deg", "disk_margin"):
        assert getattr(alone, key) == pytest.approx(getattr(box, key), rel=1e-9), key
