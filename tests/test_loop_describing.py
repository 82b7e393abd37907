"""Describing-function limit cycles of a sampled control loop with nonlinear hinges
(:func:`aeroservo.design.hinge_describing.loop_describing_branches`, issue 28).

Case: the Goland wing with aileron, 10 elements, sea level, both aileron actuators with a
freeplay of 1 deg in total, under the LQR of ``controllers/lqr.toml`` designed at 1.1 x the
open-loop flutter speed and sampled at 1 kHz (``notebooks/09_freeplay_lco.ipynb``: a 22-29 Hz
buzz of about 0.62-0.67 gap from 130 m/s, an 11.4 Hz LCO of 1.3-2.3 gaps at 80-120 m/s).

1. A zero command: the sampled loop is ``expm(A dt)``, whose growth rates ``ln|mu| / dt`` are
   the real parts of the continuous roots, so the open-loop describing function is recovered.
2. The LQR loop's neutral speed at one amplitude against an independent spectral-radius scan of
   ``closed_loop_matrix`` of an equivalent plant built here (``loop_hinge_plant`` at each speed
   with the springs ``N(A)``, as in the notebook), by bisection.
3. The LQR loop's branches against marches of the nonlinear loop (``march_hinges``).
"""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.linalg as sla
from conftest import ROOT

import aeroservo as aes
from aeroservo.design import ControlLoop, closed_loop_matrix
from aeroservo.design.hinge_describing import loop_describing_branches
from aeroservo.design.hinge_loop import loop_hinge_plant
from aeroservo.design.interface import python_law, static_gain
from aeroservo.design.plant import OpenLoop
from aeroservo.errors import InputError
from aeroservo.files import load_controller
from aeroservo.simulate.hinges.march import march_hinges
from aeroservo.simulate.lco_detect import classify
from aeroservo.stability.describing_function import describing_branches
from aeroservo.structure.hinge_laws import Freeplay
from aeroservo.studies.lco.run import _describing
from aeroservo.studies.lco.study import LCOSetup, LCOSweep
from aeroservo.system.hinge_elements import NonlinearHinge, hinge_elements

RHO = 1.225
FP = np.radians(1.0)  # total freeplay of each aileron actuator [rad]
AILERON = [NonlinearHinge("aileron", Freeplay(FP))]
HM = "aileron_hinge_moment"
SENSORS = ["tip_le_accel", "tip_te_accel", "tip_twist"]


@pytest.fixture(scope="module")
def goland():
    """The wing, its loop and the LQR of controllers/lqr.toml at 1.1 x the flutter speed."""
    model = aes.AeroelasticModel(aes.examples.goland_aileron(), n_elements=10)
    loop = ControlLoop(model, RHO, [HM], SENSORS, ["tip_disp"])
    vf = aes.flutter_boundary(model, RHO).flutter_speed
    spec = load_controller(ROOT / "controllers" / "lqr.toml")
    return model, loop, loop.design_controller(spec, 1.1 * vf, 1000.0), spec


# 1. A zero command gives the open-loop describing function --------------------------------
@pytest.mark.parametrize("kind", ["open loop", "zero output feedback", "delayed zero feedback"])
@pytest.mark.slow
def test_zero_command_is_the_open_loop_describing_function(goland, kind):
    """Goland LCO window (134-139 m/s): the same points, speeds and frequencies to 1e-8
    (Brent's tolerance 1e-10 on both sides; the rates of ``expm(A dt)`` equal ``Re lambda`` to
    about 1e-11 1/s over slopes of order 0.1 1/s per m/s; measured 1.3e-11 and 3.3e-11), ratios
    to 1e-7 (both iterated to 1e-8; measured 5e-12). The output feedback keeps the held-input
    states of the sampled loop (roots at 0), the delayed one its pending commands too."""
    model, loop, _, _ = goland
    amps = FP / 2 * (1 + np.geomspace(2e-3, 12.0, 5))
    speeds = np.linspace(134.0, 139.0, 11)
    ref = describing_branches(
        model.system(RHO), hinge_elements(model, AILERON), amps, speeds=speeds
    )
    zero = (
        OpenLoop((HM,), 1e-3)
        if kind == "open loop"
        else static_gain(np.zeros((1, 3)), [HM], sensors=SENSORS, sample_rate=1000.0)
    )
    delay = kind.startswith("delayed")
    got = loop_describing_branches(loop, AILERON, zero, amps, speeds, delay=delay, tol=1e-10)
    assert ref.speed.size == amps.size  # one LCO per amplitude, between the flutter speeds
    assert got.speed.size == ref.speed.size
    np.testing.assert_array_equal(got.amplitude, ref.amplitude)
    np.testing.assert_allclose(got.speed, ref.speed, rtol=1e-8)
    np.testing.assert_allclose(got.frequency, ref.frequency, rtol=1e-8)
    np.testing.assert_allclose(got.ratios, ref.ratios, rtol=0, atol=1e-7)
    np.testing.assert_array_equal(got.stable, ref.stable)
    np.testing.assert_array_equal(got.others_stable, ref.others_stable)
    np.testing.assert_array_equal(got.branch, ref.branch)
    assert (got.element, got.names, got.gap) == (ref.element, ref.names, ref.gap)


# 2. The neutral speed against an independent spectral-radius scan --------------------------
def _equivalent_loop(loop, controller, v: float, amplitudes: np.ndarray):
    """Growth rate [1/s], critical root and its ratio actuator2/actuator1 of the sampled loop of
    ``loop_hinge_plant`` at ``v`` with the springs ``N`` of the element ``amplitudes`` [rad]."""
    nplant = loop_hinge_plant(loop, AILERON, v)
    p = nplant.plant
    k = nplant.elements.stiffness
    dk = np.diag(k - Freeplay(FP).describing_function(amplitudes, 1.0) * k)
    eq = control.StateSpace(
        np.asarray(p.A) + nplant.b_n @ dk @ nplant.c_n, p.B,
        np.asarray(p.C) + nplant.d_n @ dk @ nplant.c_n, p.D,
        states=list(p.state_labels), inputs=list(p.input_labels), outputs=list(p.output_labels),
    )  # fmt: skip
    eq.speed, eq.density = p.speed, p.density
    M, dt = closed_loop_matrix(eq, controller)
    w, x = sla.eig(M)
    i = int(np.argmax(np.abs(w)))
    s = np.abs(nplant.c_n @ x[: p.nstates, i])
    return np.log(abs(w[i])) / dt, w[i], s[1] / s[0]


def test_neutral_speed_matches_a_spectral_radius_scan(goland):
    """At 1.8 gaps (the 11.7 Hz LCO near 100 m/s, every other root damped) the speed where the
    spectral radius of the loop crosses 1, bisected to 1e-11: equal to 1e-8 relative (Brent's
    tolerance 1e-10 and the actuators' ratio, iterated to 1e-8, used here; measured 1.1e-9);
    the frequency ``arg(mu) / (2 pi dt)`` to 1e-7 (measured 1.5e-10) and the eigenvector's
    ratio of the two actuators to 1e-6 (measured 4e-13)."""
    _, loop, lqr, _ = goland
    a = 1.8 * FP
    b = loop_describing_branches(loop, AILERON, lqr, [a], np.linspace(90.0, 110.0, 5), tol=1e-10)
    assert b.speed.size == 1 and b.stable[0] and b.others_stable[0]
    ratio = b.ratios[0, 1]
    amps = a * np.array([1.0, ratio])
    lo, hi = 90.0, 110.0
    assert _equivalent_loop(loop, lqr, lo, amps)[0] < 0 < _equivalent_loop(loop, lqr, hi, amps)[0]
    while hi - lo > 1e-11 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _equivalent_loop(loop, lqr, mid, amps)[0] < 0 else (lo, mid)
    v = 0.5 * (lo + hi)
    _, mu, r = _equivalent_loop(loop, lqr, v, amps)
    assert b.speed[0] == pytest.approx(v, rel=1e-8)
    assert b.frequency[0] == pytest.approx(abs(np.angle(mu)) / (2 * np.pi * lqr.dt), rel=1e-7)
    assert ratio == pytest.approx(r, abs=1e-6)
    assert 100.0 < v < 101.0 and 11.5 < b.frequency[0] < 12.0


# 3. Against marches ------------------------------------------------------------------------
def _march(loop, lqr, spec, v: float, start: float):
    """Frequency [Hz], first-harmonic amplitude and half peak-to-peak [rad] of actuator1 over
    the last 2 s of a 6 s march of the loop with freeplay from ``start`` [rad]."""
    res = march_hinges(
        loop_hinge_plant(loop, AILERON, v), lqr, duration=6.0, rotation0=start, limits=spec.limits
    )
    s = res.rotations["actuator1"]
    verdict = classify(res.t, {"a1": s}, reference="a1", settle=0.5)
    assert verdict.kind == "lco"
    f = verdict.frequency
    n = int(2.0 * f)
    keep = res.t >= res.t[-1] - n / f  # whole cycles
    w = 2 * np.pi * f * res.t[keep]
    basis = np.column_stack([np.sin(w), np.cos(w), np.ones_like(w)])
    c = np.linalg.lstsq(basis, s[keep], rcond=None)[0]
    return f, float(np.hypot(c[0], c[1])), float(verdict.peak["a1"])


@pytest.mark.parametrize(
    ("v", "start", "gaps", "speeds"),
    [
        (150.0, 0.3, np.linspace(0.63, 0.655, 6), np.linspace(140.0, 160.0, 5)),  # the buzz
        (100.0, 2.0, np.linspace(1.6, 1.9, 4), np.linspace(90.0, 110.0, 5)),  # the 11 Hz LCO
    ],
)
def test_branches_against_marches(goland, v, start, gaps, speeds):
    """The branch through the march's speed (amplitude interpolated there) is a stable LCO
    with every other root damped; its frequency within 2 % of the march's and its amplitude
    within the march's departure from one harmonic: ``|A_DF - A_1| <= A_peak - A_1``
    (``A_1`` the first harmonic, ``A_peak`` half the peak-to-peak; the describing function keeps
    the first harmonic only). Measured: 150 m/s, buzz: DF 0.644 gap, 25.1 Hz; march
    A_1 0.628, A_peak 0.652, 25.16 Hz. 100 m/s: DF 1.785 gap, 11.72 Hz; march A_1 1.726,
    A_peak 1.899, 11.60 Hz. (A flat branch, as the buzz's, fixes the amplitude well at a speed
    and the speed badly at an amplitude: the comparison is at the march's speed.)"""
    _, loop, lqr, spec = goland
    f, a1, peak = _march(loop, lqr, spec, v, start * FP)
    b = loop_describing_branches(loop, AILERON, lqr, gaps * FP, speeds)
    near = np.abs(b.frequency / f - 1.0) < 0.1  # the branch of the marched oscillation
    assert near.sum() >= 3 and np.unique(b.branch[near]).size == 1
    assert b.stable[near].all() and b.others_stable[near].all()
    order = np.argsort(b.speed[near])
    vs = b.speed[near][order]
    assert vs[0] < v < vs[-1]
    a_df = np.interp(v, vs, b.amplitude[near][order])
    f_df = np.interp(v, vs, b.frequency[near][order])
    assert f_df == pytest.approx(f, rel=0.02)
    assert abs(a_df - a1) <= peak - a1
    assert 2 * f_df < 0.1 / lqr.dt  # far below the Nyquist frequency: no aliasing


# The limit-cycle study uses it --------------------------------------------------------------
@pytest.mark.slow
def test_lco_study_gives_the_loop_branches(goland):
    """``run_lco``'s describing function of a setup with a loop and a controller: the sampled
    loop's branches (the buzz at 140-150 m/s among them) instead of a note "open loop only"; a
    Python law has no linear loop: a note, no branches."""
    model, loop, lqr, spec = goland
    setup = LCOSetup(model, AILERON, RHO, loop=loop, controller=lqr, limits=spec.limits)
    sweep = LCOSweep(speeds=[140.0, 150.0], amplitudes=[FP], duration=1.0, history=0.5)
    b, note = _describing(setup, sweep)
    assert note == "describing function: of the sampled loop, actuator limits inactive"
    assert b.gap == FP and b.names == ("actuator1", "actuator2")
    buzz = (b.speed > 140.0) & (b.speed < 150.0) & (b.frequency > 22.0) & b.stable
    assert buzz.any() and np.all((b.amplitude[buzz] > 0.6 * FP) & (b.amplitude[buzz] < 0.67 * FP))
    law = python_law(lambda t, y: np.zeros(1), [HM], SENSORS, sample_rate=1000.0)
    b, note = _describing(LCOSetup(model, AILERON, RHO, loop=loop, controller=law), sweep)
    assert b is None and note.startswith("describing function: not computed (")
    with pytest.raises(InputError, match="is not linear"):
        loop_describing_branches(loop, AILERON, law, [FP], [140.0, 150.0])
