"""Per-DOF viscous damping (``StructuralDamping.per_dof``) and the damped freeplay section of
Conner, Tang, Dowell & Virgin (1997), J. Fluids Struct. 11, 89-109, against the reference and
the experiment.

Reference case ``freeplay_section_Conner1997`` (``shared/reference/cases.json`` and README
"Freeplay section"; parameters as coded in the public ``samayala22/tinyvlm``,
``scripts/dof3.py``): ratios zeta_h, zeta_alpha, zeta_beta = 0.0113, 0.01626, 0.0115, dampers
``2 zeta_i sqrt(k_i m_i)`` with the wing mass m = 1.558 kg/m in the plunge's (that script's
``omega_h = sqrt(k_h / m)``), the plunge inertia m_t = 3.3843 kg/m. Linear flutter with
R. T. Jones's lag states [C]: 23.84 m/s damped (23.73 undamped) with the gap closed, 6.65 m/s
damped (6.49 undamped) with the flap free.

The measured limit cycles are the RMS of the flap, pitch and plunge against U / U_F of the
paper's experiment, digitized from its figure in the same public repository
(``scripts/conner_beta.csv``, ``scripts/misc/conner_alpha.csv``, ``scripts/misc/conner_h.csv``;
U_F = 23.9 m/s, the normalisation of its ``scripts/dof3_exp.py``; rotations per total gap of
4.24 deg, plunge in cm). Digitized points carry the figure's reading error (about 0.005 in x and
0.01 in y) besides the experiment's scatter.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
import scipy.sparse as sp

import aeroservo as aes
from aeroservo.aero.indicial import wagner_set
from aeroservo.errors import InputError
from aeroservo.files.wing_file import damping_from_dict
from aeroservo.stability.describing_function import describing_branches
from aeroservo.structure.examples import goland, goland_aileron
from aeroservo.structure.hinge_laws import Freeplay
from aeroservo.studies.lco.run import run_lco
from aeroservo.studies.lco.study import LCOSetup, LCOSweep
from aeroservo.system.damping import StructuralDamping, damping_derivatives, damping_matrix
from aeroservo.system.first_order import first_order
from aeroservo.system.hinge_elements import NonlinearHinge, hinge_elements
from aeroservo.system.section import CONNER, TypicalSection, conner_section

RHO = 1.225
GAP = CONNER["gap"]
# freeplay_section_Conner1997, shared/reference/cases.json (SI, per unit span)
REF = {
    "m": 1.558,
    "m_t": 3.3843,
    "I_alpha": 0.01347,
    "I_beta": 0.0003264,
    "k_h": 2818.8,
    "k_alpha": 37.34,
    "k_beta": 3.9,
    "zeta": (0.0113, 0.01626, 0.0115),
}
U_F_DAMPED = 23.84  # gap closed, Jones lag states, damped [C]
U_FREE_DAMPED = 6.65  # flap free, Jones lag states, damped [C]
U_F_PAPER = 23.9  # m/s, the normalisation of the measured points

# Measured RMS against U / U_F (Conner et al. 1997, digitized: samayala22/tinyvlm, see above)
MEASURED_FLAP = np.array(  # RMS(beta) / total gap
    [
        [0.2341, 0.2720],
        [0.2680, 0.3560],
        [0.3082, 0.3571],
        [0.3683, 0.3922],
        [0.4401, 0.3991],
        [0.4966, 0.4013],
        [0.5567, 0.4183],
        [0.5798, 0.5017],
        [0.6245, 0.5096],
        [0.6756, 0.5369],
        [0.7302, 0.5595],
        [0.7939, 0.5783],
        [0.8762, 0.6009],
        [0.9173, 0.6106],
    ]
)
MEASURED_PITCH = np.array(  # RMS(alpha) / total gap
    [
        [0.2294, 0.0320],
        [0.2656, 0.0176],
        [0.3062, 0.0276],
        [0.3643, 0.0605],
        [0.4392, 0.0744],
        [0.4907, 0.0671],
        [0.5532, 0.0640],
        [0.5799, 0.0626],
        [0.6776, 0.0604],
        [0.7306, 0.0599],
        [0.7964, 0.0658],
        [0.8779, 0.0754],
        [0.9218, 0.0829],
    ]
)
MEASURED_PLUNGE = np.array(  # RMS(h) [cm]
    [
        [0.2325, 0.0377],
        [0.2686, 0.0364],
        [0.3076, 0.0515],
        [0.3666, 0.0935],
        [0.4412, 0.1194],
        [0.4943, 0.1200],
        [0.5561, 0.1231],
        [0.5789, 0.0159],
        [0.6261, 0.0136],
        [0.6769, 0.0153],
        [0.7336, 0.0162],
        [0.7977, 0.0155],
        [0.8792, 0.0144],
        [0.9236, 0.0129],
    ]
)


def paper_damping_matrix(k_beta: float = REF["k_beta"]) -> np.ndarray:
    """The dampers of the reference, written out: ``2 zeta_i sqrt(k_i m_i)``, m the wing mass
    in the plunge's; the flap's with the hinge spring ``k_beta``."""
    z = REF["zeta"]
    return np.diag(
        [
            2 * z[0] * np.sqrt(REF["k_h"] * REF["m"]),
            2 * z[1] * np.sqrt(REF["k_alpha"] * REF["I_alpha"]),
            2 * z[2] * np.sqrt(k_beta * REF["I_beta"]),
        ]
    )


def with_damping(section: TypicalSection, cs: np.ndarray):
    """The first-order system of ``section`` with the damping matrix ``cs`` put in by hand."""
    am = dataclasses.replace(section.matrices, Cs=sp.csr_matrix(cs))
    return first_order(am, wagner_set(section.wagner), RHO, section.semichord)


def first_flutter(system, lo: float, hi: float, n: int = 400, rtol: float = 1e-10) -> float:
    """Lowest speed [m/s] in [lo, hi] with an unstable root: a dense scan of the largest real
    part of the state matrix's eigenvalues, then bisection."""
    a0, a1, a2 = system.state_matrix_terms()

    def top(v):
        return np.linalg.eigvals(a0 + v * a1 + v * v * a2).real.max()

    v = np.linspace(lo, hi, n)
    g = np.array([top(x) for x in v])
    assert g[0] < 0, "unstable at the start of the scan"
    i = int(np.flatnonzero(g > 0)[0])
    a, b = v[i - 1], v[i]
    while b - a > rtol * b:
        m = 0.5 * (a + b)
        a, b = (m, b) if top(m) < 0 else (a, m)
    return 0.5 * (a + b)


# 1. The damping matrix ----------------------------------------------------------------------
def test_section_damping_matrix_by_hand():
    """conner_section(damped="per_dof") carries the reference's dampers, written out from the
    case's numbers (and not from the section's mass matrix, whose plunge term is m_t)."""
    cs = conner_section(damped="per_dof").matrices.Cs.toarray()
    np.testing.assert_allclose(cs, paper_damping_matrix(), rtol=1e-13, atol=0)
    assert cs[0, 0] == pytest.approx(1.4977, abs=1e-4)  # N s/m per m


@pytest.mark.parametrize("seed", range(4))
def test_random_section_dampers_use_its_own_diagonal(seed):
    """Without plunge_mass every damper is ``2 zeta_i sqrt(K_ii M_ii)`` of the section's own
    matrices; one ratio applies to every degree of freedom; the matrix is diagonal however
    coupled the mass matrix is."""
    rng = np.random.default_rng(seed)
    b, m = rng.uniform(0.1, 1.0), rng.uniform(1.0, 50.0)
    kw = dict(
        semichord=b,
        a=rng.uniform(-0.6, 0.0),
        mass=m,
        x_alpha=rng.uniform(0.0, 0.2),
        inertia=m * b * b * rng.uniform(0.2, 0.4),
        k_plunge=rng.uniform(1e2, 1e5),
        k_pitch=rng.uniform(1.0, 1e3),
        hinge=0.6,
        flap_static_moment=m * b * rng.uniform(0.0, 0.01),
        flap_inertia=m * b * b * rng.uniform(0.002, 0.006),
        k_flap=rng.uniform(0.1, 50.0),
    )
    zeta = rng.uniform(0.001, 0.08, 3)
    for ratios in (zeta, zeta[:1]):
        sec = TypicalSection(**kw, damping=StructuralDamping.per_dof(list(ratios)))
        z = np.broadcast_to(ratios, 3)
        k = [kw["k_plunge"], kw["k_pitch"], kw["k_flap"]]
        mii = [m, kw["inertia"], kw["flap_inertia"]]
        expected = np.diag([2 * z[i] * np.sqrt(k[i] * mii[i]) for i in range(3)])
        np.testing.assert_allclose(sec.matrices.Cs.toarray(), expected, rtol=1e-12, atol=0)


# 2. Linear flutter against the reference ------------------------------------------------------
def test_damped_flutter_speed_gap_closed():
    """23.84 m/s (reference [C], Jones lag states): this model 23.840; the same with the
    dampers written out by hand in an independently built damping matrix; modal damping of the
    same ratios (``damped=True``) is not the paper's: 23.97."""
    sec = conner_section(damped="per_dof")
    by_hand = first_flutter(with_damping(conner_section(), paper_damping_matrix()), 10.0, 30.0)
    assert by_hand == pytest.approx(U_F_DAMPED, abs=0.005)
    assert aes.flutter_boundary(sec, RHO).flutter_speed == pytest.approx(by_hand, rel=1e-7)
    modal = aes.flutter_boundary(conner_section(damped=True), RHO).flutter_speed
    assert modal == pytest.approx(23.97, abs=0.01) and abs(modal - U_F_DAMPED) > 0.1


def test_damped_flutter_speed_flap_free():
    """6.65 m/s (reference [C]): the flap free keeps the hinge damper of the 3.9 N m/rad spring.
    The hand-built section (k_beta = 0, that damper) gives 6.648; the describing function of the
    damped freeplay section (spring 3.9 and its damper, the law removing the spring in the gap)
    tends to it at amplitudes just beyond the gap; ``conner_section(0, damped="per_dof")``
    damps the flap on its own zero spring: 6.90."""
    free = first_flutter(with_damping(conner_section(0.0), paper_damping_matrix()), 3.0, 12.0)
    assert free == pytest.approx(U_FREE_DAMPED, abs=0.005)
    sec = conner_section(damped="per_dof")
    el = hinge_elements(sec, [NonlinearHinge("flap", Freeplay(GAP))])
    onset = describing_branches(sec.system(RHO), el, [GAP / 2 * (1 + 1e-9)]).onset()
    assert onset == pytest.approx(free, rel=1e-6)
    own = aes.flutter_boundary(conner_section(0.0, damped="per_dof"), RHO).flutter_speed
    assert own == pytest.approx(6.90, abs=0.01)


# 3. One degree of freedom: the closed-form damped oscillator ---------------------------------
@pytest.mark.parametrize("seed", range(6))
def test_uncoupled_section_decays_as_damped_oscillators(seed):
    """A 2-DOF section with the CG on the elastic axis (no coupling) in still air of negligible
    density: each degree of freedom is a damped oscillator, ``lambda = -zeta omega_n +- i
    omega_n sqrt(1 - zeta^2)`` with ``omega_n = sqrt(k / m)``; with ``plunge_mass`` m_p the
    plunge's ratio is ``zeta sqrt(m_p / m)`` (its damper ``2 zeta sqrt(k m_p)``)."""
    rng = np.random.default_rng(100 + seed)
    b, m = rng.uniform(0.1, 1.0), rng.uniform(1.0, 50.0)
    sec_kw = dict(
        semichord=b,
        a=rng.uniform(-0.6, 0.2),
        mass=m,
        x_alpha=0.0,
        inertia=m * b * b * rng.uniform(0.1, 0.5),
        k_plunge=rng.uniform(1e2, 1e5),
        k_pitch=rng.uniform(1.0, 1e4),
    )
    zeta = rng.uniform(0.005, 0.3, 2)
    m_p = m * rng.uniform(0.3, 1.5) if seed % 2 else None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # ratios above 0.1 warn (a percentage typed?)
        damping = StructuralDamping.per_dof(list(zeta), plunge_mass=m_p)
    sec = TypicalSection(**sec_kw, damping=damping)
    lam = np.linalg.eigvals(sec.system(1e-12).state_matrix(0.0))
    lam = np.sort_complex(lam[lam.imag > 1e-6])
    z_h = zeta[0] * np.sqrt((m_p or m) / m)
    expected = []
    w_h, w_a = np.sqrt(sec_kw["k_plunge"] / m), np.sqrt(sec_kw["k_pitch"] / sec_kw["inertia"])
    for z, wn in ((z_h, w_h), (zeta[1], w_a)):
        expected.append(complex(-z * wn, wn * np.sqrt(1 - z * z)))
    np.testing.assert_allclose(lam, np.sort_complex(np.array(expected)), rtol=1e-8)


# 4. Beams: the uncoupled bending, torsion and control-rotation motions ------------------------
def _modal_ratios(model) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies [rad/s] and diagonal damping ratios ``(Phi^T C Phi)_jj / (2 omega_j)`` of
    the in-vacuo modes (mass-normalised, dense eigenproblem written here)."""
    import scipy.linalg as sla

    am = model.matrices
    w2, phi = sla.eigh(am.Ks.toarray(), am.Ms.toarray())
    w = np.sqrt(w2)
    return w, np.diag(phi.T @ am.Cs.toarray() @ phi) / (2 * w)


def test_beam_without_coupling_gets_its_ratio_per_kind():
    """The Goland wing with its CG moved onto the elastic axis: bending and torsion uncouple,
    every in-vacuo mode is a mode of one block, and per-DOF damping gives each exactly its
    kind's ratio (and no cross-damping between modes)."""
    wing = goland()
    wing = dataclasses.replace(wing, segments=[dataclasses.replace(wing.segments[0], x_alpha=0.0)])
    model = aes.AeroelasticModel(wing, 10, damping=StructuralDamping.per_dof([0.02, 0.035]))
    import scipy.linalg as sla

    am = model.matrices
    w2, phi = sla.eigh(am.Ks.toarray(), am.Ms.toarray())
    modal = phi.T @ am.Cs.toarray() @ phi
    torsion = np.array([np.abs(p[2::3]).sum() > np.abs(p[0::3]).sum() for p in phi.T])
    ratios = np.diag(modal) / (2 * np.sqrt(w2))
    np.testing.assert_allclose(ratios, np.where(torsion, 0.035, 0.02), rtol=1e-9)
    off = modal - np.diag(np.diag(modal))
    assert np.abs(off).max() < 1e-9 * np.abs(modal).max()


def test_beam_damping_converges_with_the_mesh():
    """On the coupled Goland wing the lowest modes' ratios converge with the number of elements
    (10 to 40: 0.7 %, 20 to 40: 0.1 %); with one ratio for every kind the coupled modes keep it
    within 20 % (0.0179-0.0231 for 0.02). A damper ``2 zeta sqrt(K_ii M_ii)`` on each nodal
    unknown, written here, does not converge: the first mode's ratio grows as the square of the
    number of elements (0.58 at 5 elements, 35 at 40, for zeta = 0.02)."""
    import scipy.linalg as sla

    out, nodal = {}, {}
    for n in (10, 20, 40):
        model = aes.AeroelasticModel(goland(), n, damping=StructuralDamping.per_dof([0.02, 0.03]))
        out[n] = _modal_ratios(model)[1][:4]
        M, K = model.matrices.Ms.toarray(), model.matrices.Ks.toarray()
        w2, phi = sla.eigh(K, M)
        c = np.diag(2 * 0.02 * np.sqrt(np.diag(K) * np.diag(M)))
        nodal[n] = (phi[:, 0] @ c @ phi[:, 0]) / (2 * np.sqrt(w2[0]))
    np.testing.assert_allclose(out[20], out[40], rtol=2e-3)
    np.testing.assert_allclose(out[10], out[40], rtol=1e-2)
    model = aes.AeroelasticModel(goland(), 20, damping=StructuralDamping.per_dof(0.02))
    assert np.all(np.abs(_modal_ratios(model)[1][:4] / 0.02 - 1) < 0.2)
    assert nodal[20] / nodal[10] > 3.5 and nodal[40] / nodal[20] > 3.5


def test_beam_with_aileron_and_errors():
    """Three kinds on a wing with an aileron; two ratios for it, plunge_mass on a wing, more
    than three ratios, plunge_mass without dof_ratio: one clear line each."""
    wing = goland_aileron()
    model = aes.AeroelasticModel(wing, 10, damping=StructuralDamping.per_dof([0.02, 0.03, 0.05]))
    labels = model.matrices.dof_labels
    cs = model.matrices.Cs.toarray()
    bend = [i for i, s in enumerate(labels) if s[0] in "wt"]
    flap = [i for i, s in enumerate(labels) if s.startswith("delta")]
    assert flap and np.abs(cs[np.ix_(bend, flap)]).max() == 0.0
    with pytest.raises(InputError, match=r"damping\.dof_ratio = \[0\.02, 0\.03\].*give 3"):
        aes.AeroelasticModel(wing, 10, damping=StructuralDamping.per_dof([0.02, 0.03]))
    with pytest.raises(InputError, match=r"damping\.plunge_mass = 1\.0: only for a typical"):
        aes.AeroelasticModel(wing, 10, damping=StructuralDamping.per_dof(0.02, plunge_mass=1.0))
    with pytest.raises(InputError, match=r"damping\.dof_ratio = .*at most 3"):
        StructuralDamping.per_dof([0.01] * 4)
    with pytest.raises(InputError, match=r"damping\.plunge_mass = 1\.0: only with per-DOF"):
        StructuralDamping("modal", ratios=(0.01,), plunge_mass=1.0)
    with pytest.raises(InputError, match=r"damping\.plunge_mass = 2: only with dof_ratio"):
        damping_from_dict({"ratio": 0.01, "plunge_mass": 2})
    with pytest.raises(InputError, match=r"give one of ratio, g, dof_ratio"):
        damping_from_dict({"ratio": 0.01, "dof_ratio": [0.01]})
    d = damping_from_dict({"dof_ratio": [0.0113, 0.01626, 0.0115], "plunge_mass": 1.558})
    assert d == conner_section(damped="per_dof").damping
    assert d.describe() == "zeta per DOF = 0.0113, 0.01626, 0.0115, plunge mass 1.558 kg/m"
    assert d.to_dict() == {
        "kind": "per_dof",
        "dof_ratio": [0.0113, 0.01626, 0.0115],
        "plunge_mass": 1.558,
    }


# 5. Derivatives (sensitivities) ---------------------------------------------------------------
@pytest.mark.parametrize("case", ["section", "wing"])
def test_per_dof_derivatives_against_central_differences(case):
    """``damping_derivatives``: a move of the structural matrices (a parameter's direction: the
    section's springs and masses, the wing's stiffness, actuator and hinge springs together) and each own
    ratio, against central differences of ``damping_matrix`` (relative step 1e-6)."""
    if case == "section":
        sec = conner_section(damped="per_dof")
        am, damping = sec.matrices, sec.damping
        dm = np.diag([0.3, 1e-3, 2e-5]) + np.array([[0, 0.01, 0], [0.01, 0, 1e-5], [0, 1e-5, 0]])
        dk = np.diag([100.0, 2.0, 0.5])
    else:
        damping = StructuralDamping.per_dof([0.02, 0.03, 0.05])
        am = aes.AeroelasticModel(goland_aileron(), 6, damping=damping).matrices
        stiffer = aes.AeroelasticModel(goland_aileron(9000.0, 600.0), 6).matrices
        dk = (stiffer.Ks - am.Ks).toarray() + 0.01 * am.Ks.toarray()
        dm = 0.02 * am.Ms.toarray()
    Ms, Ks, labels = am.Ms.toarray(), am.Ks.toarray(), am.dof_labels
    d_structure, d_own = damping_derivatives(damping, Ms, Ks, labels)
    h = 1e-6
    fd = (
        damping_matrix(damping, Ms + h * dm, Ks + h * dk, labels)
        - damping_matrix(damping, Ms - h * dm, Ks - h * dk, labels)
    ).toarray() / (2 * h)
    exact = d_structure(dm, dk).toarray()
    assert np.abs(exact - fd).max() <= 1e-6 * np.abs(exact).max()
    for i, z in enumerate(damping.ratios):
        r = list(damping.ratios)
        r[i] = z * (1 + 1e-3)
        up = StructuralDamping.per_dof(r, damping.plunge_mass)
        fd = (damping_matrix(up, Ms, Ks, labels) - damping_matrix(damping, Ms, Ks, labels)) / (
            1e-3 * z
        )
        np.testing.assert_allclose(
            d_own(f"damping.dof_ratio[{i}]").toarray(), fd.toarray(), rtol=1e-6, atol=1e-12
        )


# 6. Limit cycles against the experiment ------------------------------------------------------
@pytest.fixture(scope="module")
def damped_study():
    """The damped freeplay section marched at the measured speeds: from rest at 2 gaps, and
    swept up and down (continuation), 30 s each."""
    speeds = np.round(np.sort(MEASURED_FLAP[:, 0]) * U_F_PAPER, 3)
    setup = LCOSetup(
        conner_section(damped="per_dof"), [NonlinearHinge("flap", Freeplay(GAP))], RHO, name="c"
    )
    sweep = LCOSweep(speeds=tuple(speeds), amplitudes=(2 * GAP,), duration=30.0, dt=2e-3)
    res = run_lco(setup, sweep, describing=False)
    return speeds, {
        s: {r["speed"]: r for r in res.rows if r["start"] == s} for s in ("point", "up", "down")
    }


@pytest.mark.slow
def test_lco_against_the_measured_rms(damped_study):
    """The paper's damping against the experiment (module notes for the data; the numbers
    are those of docs/freeplay.md, "Against the experiment").

    * Upper branch (the 11 Hz flap LCO, measured from 0.58 U_F; down sweep): the flap RMS
      within 16 % of the measured (this model +1 to +15 % at the 7 measured speeds, +8 % on
      average); undamped the same marches are +9 to +29 %.
    * The branch jump: measured between 0.557 and 0.580 U_F (the plunge RMS falls eightfold);
      the up sweep here jumps between 0.497 and 0.557 U_F (0.52-0.53 on a finer grid),
      undamped between 0.31 and 0.37.
    * The low branch (4.7-5.1 Hz) persists on deceleration down to the lowest measured speed,
      0.234 U_F = 5.6 m/s, a limit cycle there; its flap RMS within 40 % of the measured
      (+0 to +10 % from 0.27 to 0.50 U_F, +39 % at 0.234 U_F).
    * Pitch and plunge, loosely bounded: the upper branch's pitch RMS within 25 % (+3 to
      +20 %), its plunge RMS 1.3 to 3.2 times the measured (rising with speed where the
      measured falls).
    """
    speeds, rows = damped_study
    ratio = speeds / U_F_PAPER
    upper = ratio >= 0.575
    flap = np.array([rows["down"][v]["rms_per_gap"] for v in speeds])
    measured = np.interp(ratio, MEASURED_FLAP[:, 0], MEASURED_FLAP[:, 1])
    err = flap / measured - 1
    assert np.all(np.abs(err[upper]) <= 0.16), err[upper]
    assert abs(err[upper].mean()) <= 0.10
    freq_up = np.array([rows["up"][v]["frequency"] for v in speeds])
    assert np.all(freq_up[ratio >= 0.58] > 9.0)
    assert np.all(freq_up[(ratio > 0.36) & (ratio < 0.5)] < 6.0)
    for v in speeds[ratio < 0.5]:
        r = rows["down"][v]
        # a limit cycle, or near 0.44 U_F a biased one modulated at 1.5 Hz (issue 40: not
        # 'aperiodic', a sustained quasi-periodic oscillation reported at its 4.9 Hz carrier)
        assert r["kind"] in ("lco", "quasi-periodic") and 4.5 < r["frequency"] < 5.5, r
    assert rows["down"][speeds[0]]["kind"] == "lco"
    assert np.all(np.abs(err[ratio < 0.5]) <= 0.40), err
    pitch = np.array([rows["down"][v]["rmss"]["pitch"] / GAP for v in speeds])
    m_pitch = np.interp(ratio, MEASURED_PITCH[:, 0], MEASURED_PITCH[:, 1])
    assert np.all(np.abs(pitch[upper] / m_pitch[upper] - 1) <= 0.25)
    plunge = np.array([100 * rows["down"][v]["rmss"]["plunge"] for v in speeds])
    m_plunge = np.interp(ratio[upper], MEASURED_PLUNGE[:, 0], MEASURED_PLUNGE[:, 1])
    assert np.all((plunge[upper] / m_plunge > 1.0) & (plunge[upper] / m_plunge < 3.5))


def test_shipped_damped_scenario():
    """``scenarios/conner_freeplay_lco_damped.toml``: the builtin section with the paper's
    dampers from its ``[damping]`` table, named in the run's model line."""
    from pathlib import Path

    from aeroservo.files.scenario_file import load_scenario

    path = Path(__file__).resolve().parent.parent / "scenarios" / "conner_freeplay_lco_damped.toml"
    s = load_scenario(path)
    assert s.section.damping == conner_section(damped="per_dof").damping
    np.testing.assert_array_equal(
        s.section.matrices.Cs.toarray(), conner_section(damped="per_dof").matrices.Cs.toarray()
    )
    assert s.wing_source == (
        "builtin section conner (damping zeta per DOF = 0.0113, 0.01626, 0.0115, "
        "plunge mass 1.558 kg/m)"
    )
