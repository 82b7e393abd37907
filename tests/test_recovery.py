"""The recoverable set with and without anti-windup (issue 38, item 4).

The study's marches are checked against a loop marched here, sample by sample, from the
plant's matrices (exact zero-order hold by the matrix exponential), the compensator's own
matrices and a clipped command: ``m_k = C_s x_k + D_s u_{k-1}``, ``c_k = Cc s_k + Dc m_k``,
``u_k = clip(c_k)``, ``s_{k+1} = Ac s_k + Bc m_k + L (u_k - c_k)``, ``x_{k+1} = Phi x_k + G u_k``
(``L`` the observer-form gain with anti-windup, 0 without: Astrom & Rundqwist, ACC 1989).
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
import scipy.linalg as sla
from conftest import ROOT
from ideal_loops import ideal

import aeroservo as aes
from aeroservo.design.anti_windup import has_anti_windup, with_anti_windup
from aeroservo.design.spec import ANTI_WINDUP_DEFAULTS
from aeroservo.files import load_scenario
from aeroservo.files.controller_file import controller_from_dict
from aeroservo.stability.boundary import flutter_boundary
from aeroservo.studies.recovery import SETTLE, THRESHOLD, recoverable_set

HM = "aileron_hinge_moment"


@functools.cache
def hinf_loop():
    sc = ideal(load_scenario(ROOT / "scenarios" / "goland_aileron_hinf.toml"))
    model = sc.model()
    vf = flutter_boundary(model, sc.density).flutter_speed
    loop = sc.loop(model)
    v = sc.speed_factor * vf
    return loop, loop.design_controller(sc.controller, v, sc.sample_rate, vf), v


def _march_by_hand(loop, ctrl, speed, tip, limit, duration):
    plant = loop.plant(speed)
    A, B = np.asarray(plant.A), np.asarray(plant.B)
    C, D = np.asarray(plant.C), np.asarray(plant.D)
    j = list(plant.input_labels).index(HM)
    rows = [list(plant.output_labels).index(s) for s in ctrl.sensors]
    dt = ctrl.dt
    n = A.shape[0]
    big = np.zeros((n + 1, n + 1))
    big[:n, :n], big[:n, n] = A * dt, B[:, j] * dt
    e = sla.expm(big)
    phi, gam = e[:n, :n], e[:n, n]
    Ac, Bc, Cc, Dc, L = ctrl.Ac, ctrl.Bc, ctrl.Cc, ctrl.Dc, ctrl.anti_windup
    x, s, u_prev = loop.initial_state(tip), np.zeros(Ac.shape[0]), 0.0
    sizes = []
    for _ in range(int(round(duration / dt)) + 1):
        sizes.append(np.linalg.norm(x))
        m = C[rows] @ x + D[rows, j] * u_prev
        c = float((Cc @ s + Dc @ m)[0])
        u = min(max(c, -limit), limit)
        s = Ac @ s + Bc @ m + L[:, 0] * (u - c)
        x = phi @ x + gam * u
        u_prev = u
    sizes = np.array(sizes)
    start = max(int((1.0 - SETTLE) * sizes.size), 1)
    return sizes[start:].max() / sizes[0]


@pytest.mark.slow
def test_study_against_a_loop_marched_by_hand():
    """The H-infinity loop at 1.1 V_f from a 5 cm tip deflection with a 600 N m limit: lost
    with anti-windup, recovered without (the issue's finding), as the hand march says."""
    loop, ctrl, v = hinf_loop()
    res = recoverable_set(loop, ctrl, v, [0.02, 0.05], [300.0, 600.0], duration=3.0)
    for on in (True, False):
        c = with_anti_windup(ctrl, on)
        for i, tip in enumerate(res.deflections):
            for k, lim in enumerate(res.magnitudes):
                ref = _march_by_hand(loop, c, v, tip, lim, 3.0)
                got = res.final[on][i, k]
                assert got == pytest.approx(ref, rel=1e-6, abs=1e-9), (on, tip, lim)
                assert res.recovered[on][i, k] == (ref <= THRESHOLD)
    assert not res.recovered[True][1, 1] and res.recovered[False][1, 1]
    assert res.anti_windup_helps is False
    assert "tip 0.05 m, limit 600: recovered only with anti-windup off" in res.summary()
    fig = res.plot()
    assert len(fig.axes) == 2


def test_the_switch_changes_only_the_use_of_the_applied_input():
    """Anti-windup on or off, the law is the same while no limit acts (A, B, C, D equal), so
    every linear analysis is; only L differs."""
    _loop, ctrl, _v = hinf_loop()
    on, off = with_anti_windup(ctrl, True).law(), with_anti_windup(ctrl, False).law()
    for k in "ABCD":
        np.testing.assert_array_equal(getattr(on, k), getattr(off, k))
    assert np.any(on.L) and not np.any(off.L)
    assert has_anti_windup(with_anti_windup(ctrl, True)) is True
    with pytest.raises(aes.InputError, match="not a switch of"):
        with_anti_windup(aes.design.OpenLoop(("u",), 0.001), True)


def test_defaults_per_type_and_the_file_switch():
    """The measured defaults: a compensator off, an LQG on; every type with a state has the
    switch in its file, the others say why not."""
    assert ANTI_WINDUP_DEFAULTS == {"lqg": True, "hinf": False, "linear": False}
    _loop, ctrl, _v = hinf_loop()  # the shipped scenario's H-infinity, default: off
    assert has_anti_windup(ctrl) is False
    base = {
        "type": "hinf",
        "weights": {"inputs": {HM: 1000.0}, "sensors": {"tip_twist": 0.01}},
    }
    assert controller_from_dict(base).uses_applied_input is False
    assert controller_from_dict(base | {"anti_windup": True}).uses_applied_input is True
    import tomllib

    def shipped(name):
        return tomllib.loads((ROOT / "controllers" / f"{name}.toml").read_text())

    lqg = shipped("lqg")
    assert controller_from_dict(lqg).uses_applied_input is True
    assert controller_from_dict(lqg | {"anti_windup": False}).uses_applied_input is False
    with pytest.raises(aes.InputError, match="no state to wind up"):
        controller_from_dict(shipped("lqr") | {"anti_windup": True})
    with pytest.raises(aes.InputError, match="plans within its limits"):
        controller_from_dict(shipped("mpc") | {"anti_windup": True})
