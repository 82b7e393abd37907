"""Describing-function (equivalent linearisation) prediction of limit-cycle oscillations.

Reference case: the freeplay section of Conner, Tang, Dowell & Virgin (1997), J. Fluids Struct.
11, 89-109 (``shared/reference/README.md`` "Freeplay section"; plunge inertia m_t, as in
:func:`aeroservo.system.section.conner_section`), total gap 4.24 deg. Gap closed: linear
flutter 23.74 m/s (R. T. Jones lag states, reference 23.73); flap free: 6.49 m/s. LCOs are
expected between these speeds.

The independent answers below never use the describing-function code: the equivalent system
at an amplitude is a typical section built with the hinge spring ``N(A)``, and its flutter
speed is found by a dense eigenvalue scan of the maximum real part refined by bisection.
"""

from __future__ import annotations

import dataclasses
import json
import re

import numpy as np
import pytest

from aeroservo.errors import InputError
from aeroservo.stability.describing_function import DescribingBranches, describing_branches
from aeroservo.structure.examples import goland_aileron
from aeroservo.structure.hinge_laws import Bilinear, Cubic, Freeplay
from aeroservo.system.aeroelastic import AeroelasticModel
from aeroservo.system.hinge_elements import NonlinearHinge, hinge_elements
from aeroservo.system.section import CONNER, conner_section

RHO = 1.225
GAP = CONNER["gap"]
U_F = 23.74  # gap closed, this model (reference README: 23.73 with Jones lag states)
U_FREE = 6.49  # flap free, k_beta = 0


def max_re(system, speeds: np.ndarray) -> np.ndarray:
    """Largest real part [1/s] of the state matrix's eigenvalues at each speed."""
    a0, a1, a2 = system.state_matrix_terms()
    s = np.asarray(speeds, dtype=float)[:, None, None]
    return np.linalg.eigvals(a0[None] + s * a1[None] + s * s * a2[None]).real.max(axis=1)


def first_flutter(system, lo: float, hi: float, n: int = 400, rtol: float = 1e-12) -> float:
    """Lowest speed [m/s] in [lo, hi] where the system becomes unstable: dense scan of the
    largest real part, then bisection of the bracketing grid interval to ``rtol``."""
    v = np.linspace(lo, hi, n)
    g = max_re(system, v)
    assert g[0] < 0, "unstable at the start of the scan"
    i = int(np.flatnonzero(g > 0)[0])
    a, b = v[i - 1], v[i]
    while b - a > rtol * b:
        m = 0.5 * (a + b)
        a, b = (m, b) if max_re(system, [m])[0] < 0 else (a, m)
    return 0.5 * (a + b)


def flap_dof(k_flap: float):
    return conner_section(k_flap=k_flap).system(RHO)


@pytest.fixture(scope="module")
def conner():
    """The Conner section with the 4.24 deg freeplay and its DF branches."""
    sec = conner_section()
    el = hinge_elements(sec, [NonlinearHinge("flap", Freeplay(GAP))])
    amps = GAP / 2 * (1 + np.logspace(-3, 1.5, 60))
    return sec.system(RHO), el, describing_branches(sec.system(RHO), el, amps)


# 1. N(A): quadrature against the closed forms -------------------------------------------
@pytest.mark.parametrize("inner", [0.0, 0.3])
def test_freeplay_quadrature_matches_closed_form(inner):
    """A gap off zero by 1e-12 rad goes through the Gauss quadrature; centred, the closed form
    ``1 - (2/pi)(asin u + u sqrt(1 - u^2))`` (Gelb & Vander Velde 1968): equal to rounding."""
    k = 3.9
    amps = GAP / 2 * np.array([0.3, 1.0, 1.0001, 1.2, 2.0, 10.0, 1e3])
    closed = Bilinear(GAP, inner_ratio=inner).describing_function(amps, k)
    quad = Bilinear(GAP, offset=1e-12, inner_ratio=inner).describing_function(amps, k)
    np.testing.assert_allclose(quad, closed, rtol=0, atol=1e-9 * k)
    assert closed[0] == pytest.approx(inner * k)  # inside the gap: the inner stiffness
    assert closed[-1] == pytest.approx(k * (1 - (1 - inner) * 4e-3 / np.pi), rel=1e-6)


@pytest.mark.parametrize("c", [2e3, -50.0])
def test_cubic_three_quarter_rule(c):
    """N(A) = k + 3/4 c A^2: the first harmonic of (k s + c s^3), s = A sin(theta), by the
    trapezoidal rule over one period (exact for trigonometric polynomials)."""
    k, amps = 3.9, np.array([0.01, 0.1, 0.3])
    th = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    law = Cubic(c)
    for a in amps:
        m = law.moment(a * np.sin(th), k)
        n_num = 2 * np.mean(m * np.sin(th)) / a
        assert law.describing_function(a, k) == pytest.approx(n_num, rel=1e-13)
        assert n_num == pytest.approx(k + 0.75 * c * a * a, rel=1e-13)


# 2. Neutral speed at an amplitude = flutter of a section with k_flap = N(A) --------------
@pytest.mark.parametrize("ratio", [0.75, 1.0, 1.5, 5.0])
def test_neutral_speed_is_flutter_of_equivalent_section(conner, ratio):
    system, el, _ = conner
    a = ratio * GAP
    n = float(Freeplay(GAP).describing_function(a, CONNER["k_beta"]))
    expected = first_flutter(flap_dof(n), 0.1, 40.0)
    br = describing_branches(system, el, [a])
    assert br.onset() == pytest.approx(expected, rel=1e-8)


# 3. Limits ------------------------------------------------------------------------------
def test_limits_gap_closed_and_flap_free(conner):
    """A -> infinity: the gap-closed flutter speed; A -> gap/2 from above: the flap-free one."""
    system, el, _ = conner
    closed = first_flutter(flap_dof(CONNER["k_beta"]), 1.0, 40.0)
    free = first_flutter(flap_dof(0.0), 1.0, 40.0)
    assert closed == pytest.approx(U_F, abs=0.01)  # 23.7345: 23.73-23.74
    assert free == pytest.approx(U_FREE, abs=0.01)
    big = describing_branches(system, el, [1e4 * GAP]).onset()
    small = describing_branches(system, el, [GAP / 2 * (1 + 1e-9)]).onset()
    assert big == pytest.approx(closed, rel=5e-3)
    assert small == pytest.approx(free, rel=5e-3)
    assert big == pytest.approx(U_F, rel=5e-3) and small == pytest.approx(U_FREE, rel=5e-3)
    assert big < closed and small < free  # both limits are approached from below


# 4. Homogeneity ---------------------------------------------------------------------------
def test_branches_scale_with_the_gap(conner):
    """N depends on A / gap only: doubling gap and amplitudes gives the same branches."""
    system, _, br1 = conner
    sec = conner_section()
    el2 = hinge_elements(sec, [NonlinearHinge("flap", Freeplay(2 * GAP))])
    amps = GAP / 2 * (1 + np.logspace(-3, 1.5, 60))
    br2 = describing_branches(system, el2, 2 * amps)
    np.testing.assert_allclose(br2.amplitude / br2.gap, br1.amplitude / br1.gap, rtol=1e-12)
    np.testing.assert_allclose(br2.speed, br1.speed, rtol=1e-9)
    np.testing.assert_allclose(br2.frequency, br1.frequency, rtol=1e-9)
    np.testing.assert_array_equal(br2.stable, br1.stable)
    np.testing.assert_array_equal(br2.branch, br1.branch)


# 5. Stability of the branch -------------------------------------------------------------
def test_stability_flag_against_independent_growth(conner):
    """Stable <=> the section with k_flap = N(A (1 + eps)) is stable at the LCO speed and the
    one with N(A (1 - eps)) unstable (checked where the other roots are all damped, so that the
    largest real part is the crossing root's)."""
    _, _, br = conner
    eps = 1e-4
    checked = 0
    for a, v, st, alone in zip(br.amplitude, br.speed, br.stable, br.others_stable, strict=True):
        if not alone:
            continue
        up, down = (
            max_re(flap_dof(float(Freeplay(GAP).describing_function(x, 3.9))), [v])[0]
            for x in (a * (1 + eps), a * (1 - eps))
        )
        assert (up < 0 < down) == st
        assert (up > 0 > down) == (not st)
        checked += 1
    assert checked >= 30


def test_conner_branch_shape(conner):
    """The LCO branch that reaches the gap-closed flutter speed at large amplitude: unstable
    below its fold (speed falling from the flap-free 6.49 m/s as A grows), stable and rising to
    23.74 m/s beyond it; no branch above the gap-closed flutter speed reaches large amplitudes."""
    _, _, br = conner
    top = br.branch[np.argmax(br.amplitude)]
    sel = br.branch == top
    v, st = br.speed[sel], br.stable[sel]
    fold = int(np.argmin(v))
    assert v[0] == pytest.approx(U_FREE, rel=2e-3)
    assert np.all(np.diff(v[: fold + 1]) < 0) and not st[:fold].any()
    assert np.all(np.diff(v[fold:]) > 0) and st[fold + 1 :].all()
    assert v[-1] < U_F and v[-1] == pytest.approx(U_F, rel=2e-3)
    assert br.onset() < U_FREE
    assert br.gap == GAP and br.element == "flap"
    rows = br.table()
    json.dumps(rows)
    assert rows[0]["amplitude_per_gap"] == pytest.approx(br.amplitude[0] / GAP)


# 6. Goland aileron, freeplay on both actuators --------------------------------------------
def test_goland_aileron_branch_between_free_and_closed():
    gap = np.radians(1.0)
    wing = goland_aileron()
    model = AeroelasticModel(wing)
    system = model.system(RHO)
    closed = first_flutter(system, 100.0, 200.0, n=51, rtol=1e-10)
    free = first_flutter(
        AeroelasticModel(goland_aileron(actuator_stiffness=1e-6)).system(RHO),
        100.0,
        200.0,
        n=51,
        rtol=1e-10,
    )
    assert free < closed
    el = hinge_elements(model, [NonlinearHinge("aileron", Freeplay(gap))])
    assert el.names == ("actuator1", "actuator2")
    amps = gap / 2 * (1 + np.array([1e-6, 0.1, 0.5, 2.0, 1e3]))
    br = describing_branches(system, el, amps, speeds=np.linspace(100.0, 200.0, 26))
    assert np.unique(br.branch).size == 1 and br.speed.size == amps.size
    assert np.all((br.speed > free * (1 - 1e-6)) & (br.speed < closed))
    assert br.speed[0] == pytest.approx(free, rel=1e-4)
    assert br.speed[-1] == pytest.approx(closed, rel=1e-3)
    assert np.all(np.diff(br.speed) > 0) and br.stable[1:].all()
    # the aileron is stiff in torsion: both actuators move alike (actuator2 a few % more)
    assert np.all(br.ratios[:, 0] == 1.0)
    assert np.all(np.abs(br.ratios[:, 1] - 1.0) < 0.06)
    # independent: the wing with actuator stiffnesses N_j(A r_j) flutters at the LCO speed,
    # and its flutter mode moves the actuators in the ratio found
    i = 2
    stiff = [
        float(Freeplay(gap).describing_function(br.amplitude[i] * r, k))
        for r, k in zip(br.ratios[i], el.stiffness, strict=True)
    ]
    cs = wing.control_surfaces[0]
    acts = tuple(
        dataclasses.replace(a, stiffness=n) for a, n in zip(cs.actuators, stiff, strict=True)
    )
    eq_wing = dataclasses.replace(wing, control_surfaces=(dataclasses.replace(cs, actuators=acts),))
    eq_model = AeroelasticModel(eq_wing)
    eq_sys = eq_model.system(RHO)
    v = first_flutter(eq_sys, 100.0, 200.0, n=51, rtol=1e-11)
    assert v == pytest.approx(br.speed[i], rel=1e-8)
    w, x = np.linalg.eig(eq_sys.state_matrix(v))
    j = int(np.argmin(np.abs(w.real) + 1e3 * (w.imag <= 0)))
    rot = np.abs(
        hinge_elements(eq_model, [NonlinearHinge("aileron", Freeplay(gap))]).rows
        @ x[: eq_sys.n_q, j]
    )
    assert rot[1] / rot[0] == pytest.approx(br.ratios[i, 1], rel=1e-6)


# 7. Cubic hardening ----------------------------------------------------------------------
def test_cubic_hardening_amplitude_follows_required_stiffness():
    """Above the linear flutter speed a hardening flap spring limits the motion where
    N(A) = k + 3/4 c A^2 equals the stiffness k_req(V) whose flutter speed is V."""
    k, c = CONNER["k_beta"], 1.0e3
    sec = conner_section()
    el = hinge_elements(sec, [NonlinearHinge("flap", Cubic(c))])

    def k_required(v: float) -> float:
        lo, hi = k, 40.0
        assert first_flutter(flap_dof(lo), 1.0, 40.0) < v < first_flutter(flap_dof(hi), 1.0, 40.0)
        while hi - lo > 1e-11 * hi:
            m = 0.5 * (lo + hi)
            lo, hi = (m, hi) if first_flutter(flap_dof(m), 1.0, 40.0) < v else (lo, m)
        return 0.5 * (lo + hi)

    targets = np.array([23.8, 23.9, 23.98])
    amps = np.sqrt((np.array([k_required(v) for v in targets]) - k) / (0.75 * c))
    br = describing_branches(sec.system(RHO), el, amps)
    assert br.gap is None and br.speed.size == targets.size
    np.testing.assert_allclose(br.speed, targets, rtol=1e-7)
    assert br.stable.all() and br.others_stable.all()


# 8. Bad input ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    "law, amps, words",
    [
        (Freeplay(GAP, offset=0.01), [0.1], ["flap", "centred", "march"]),
        (Freeplay(GAP), [], ["amplitudes", "non-empty"]),
        (Freeplay(GAP), [0.1, 0.05], ["amplitudes[1]", "increasing"]),
        (Freeplay(GAP), [0.1, 0.1], ["amplitudes[1]", "increasing"]),
        (Freeplay(GAP), [0.0, 0.1], ["amplitudes[0]", "positive"]),
    ],
)
def test_bad_input(law, amps, words):
    sec = conner_section()
    el = hinge_elements(sec, [NonlinearHinge("flap", law)])
    with pytest.raises(InputError, match=re.escape(words[0])) as exc:
        describing_branches(sec.system(RHO), el, amps)
    text = str(exc.value)
    assert "\n" not in text and all(w in text for w in words), text


def test_plot_describing(conner, tmp_path):
    from aeroservo.plots.lco import plot_describing

    _, _, br = conner
    ax = plot_describing(br)
    assert "airspeed [m/s]" in ax.get_xlabel() and "gap" in ax.get_ylabel()
    styles = {line.get_linestyle() for line in ax.get_lines()}
    assert {"-", "--"} <= styles
    ax.figure.savefig(tmp_path / "lco.png")
    empty = DescribingBranches(*(np.zeros(0),) * 4, np.zeros(0, int), np.zeros((0, 1)), GAP, "x")
    assert np.isnan(empty.onset())
    assert "deg" in plot_describing(empty, per_gap=False).get_ylabel()
