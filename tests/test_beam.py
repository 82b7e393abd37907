"""Beam element checks: exact static solutions, uniform-cantilever frequencies, convergence,
and the Goland wing in vacuo."""

import numpy as np
import pytest
import scipy.linalg as sla
from conftest import reference

import aeroservo as aes
from aeroservo.structure import Segment, Wing

L, EI, GJ, M, I_EA = 5.0, 2.0e6, 3.0e5, 20.0, 1.5


def uniform_wing(x_alpha: float = 0.0) -> Wing:
    seg = Segment(0.0, L, 0.5, -0.2, M, x_alpha, I_EA, EI, GJ)
    return Wing(L, [seg])


def static(model: aes.AeroelasticModel, load: dict[int, float]) -> np.ndarray:
    f = np.zeros(model.n_dofs)
    for dof, value in load.items():
        f[dof] = value
    return np.linalg.solve(model.matrices.Ks.toarray(), f)


@pytest.mark.parametrize("n", [1, 3, 8])
def test_tip_load_exact(n):
    """Cantilever tip load P: w = P L^3/(3 EI), slope = P L^2/(2 EI); exact for Hermite cubics."""
    m = aes.AeroelasticModel(uniform_wing(), n)
    P = 1234.0
    q = static(m, {m.mesh.dof_w[-1]: P})
    assert q[m.mesh.dof_w[-1]] == pytest.approx(P * L**3 / (3 * EI), rel=1e-12)
    assert q[m.mesh.dof_theta[-1]] == pytest.approx(P * L**2 / (2 * EI), rel=1e-12)
    assert np.allclose(q[m.mesh.dof_phi[1:]], 0.0)


@pytest.mark.parametrize("n", [1, 4])
def test_tip_torque_exact(n):
    """Tip torque T: twist T L / GJ, linear along the span; exact for linear elements."""
    m = aes.AeroelasticModel(uniform_wing(), n)
    T = 321.0
    q = static(m, {m.mesh.dof_phi[-1]: T})
    phi = m.nodal_fields(q)["phi"]
    np.testing.assert_allclose(phi, T * m.mesh.nodes / GJ, rtol=1e-12, atol=1e-18)


def test_uniform_cantilever_frequencies():
    """Case beam_analytic_checks: bending (beta_n L)^2 sqrt(EI/(m L^4)), torsion
    (2n-1) pi/(2L) sqrt(GJ/I_EA); uncoupled section (x_alpha = 0), 40 elements."""
    betal = reference("beam_analytic_checks")["expected"]["bending_betaL"]
    m = aes.AeroelasticModel(uniform_wing(), 40)
    modes = m.natural_modes(6)
    w = 2 * np.pi * modes.frequencies
    bending = sorted(w[[lab.endswith("bending") for lab in modes.labels]])[:3]
    torsion = sorted(w[[lab.endswith("torsion") for lab in modes.labels]])[:2]
    for bl, wn in zip(betal, bending, strict=True):
        assert wn == pytest.approx(bl**2 * np.sqrt(EI / (M * L**4)), rel=2e-4)
    for k, wn in enumerate(torsion, start=1):
        assert wn == pytest.approx((2 * k - 1) * np.pi / (2 * L) * np.sqrt(GJ / I_EA), rel=1e-3)


def test_mesh_convergence_is_monotone_and_second_order():
    """Consistent-mass frequencies converge from above; linear torsion elements converge as h^2."""
    freqs = np.array(
        [
            aes.AeroelasticModel(aes.examples.goland(), n).natural_modes(4).frequencies
            for n in (5, 10, 20, 40)
        ]
    )
    assert np.all(np.diff(freqs, axis=0) <= 1e-12)
    err = np.abs(freqs[:-1] - freqs[-1])
    # halving h twice divides the error of the torsion-dominated mode by about 4 per halving
    assert err[0, 1] / err[1, 1] > 3.0


def test_goland_in_vacuo_same_model(goland10):
    """Case goland_clean_modes, 'GJ_0.99e6_10el_Hz': same discretization [C], rel 1e-4."""
    exp = reference("goland_clean_modes")["expected"]["GJ_0.99e6_10el_Hz"]
    np.testing.assert_allclose(goland10.natural_modes(4).frequencies, exp, rtol=1e-4)


def test_goland_in_vacuo_literature(goland40):
    """Issue acceptance: 1st bending, 1st torsion, 2nd mode within 0.5 % of 7.664 / 15.24 / 38.80 Hz
    (case goland_clean_modes; 40 elements, GJ = 0.99e6). With 10 elements the 38.8 Hz mode is
    0.77 % high (39.10 Hz, as the reference's own 10-element value), hence 40 elements here."""
    f = goland40.natural_modes(3).frequencies
    np.testing.assert_allclose(f, [7.664, 15.24, 38.80], rtol=5e-3)


def test_goland_in_vacuo_converged_sharpy_gj():
    """Case goland_clean_modes, GJ = 0.987581e6 (SHARPy), 80 elements, rel 1e-4 (four modes)."""
    exp = reference("goland_clean_modes")["expected"]["GJ_0.987581e6_converged_80el_Hz"]
    m = aes.AeroelasticModel(aes.examples.goland(GJ=0.987581e6), 80)
    np.testing.assert_allclose(m.natural_modes(4).frequencies, exp, rtol=1e-4)


def test_mode_labels_follow_strain_energy(goland40):
    """The 38.8 Hz mode stores 73 % of its strain energy in torsion: it is the 2nd torsion mode
    (the reference's labels '2nd bending / 2nd torsion' are marked [M], from memory)."""
    modes = goland40.natural_modes(4)
    assert modes.labels == ["1st bending", "1st torsion", "2nd torsion", "2nd bending"]
    q = modes.shapes[:, 2]
    parts = goland40.matrices.stiffness_parts
    e = {k: q @ (v @ q) for k, v in parts.items()}
    assert e["torsion"] / sum(e.values()) == pytest.approx(0.73, abs=0.02)


def test_inertial_coupling_lowers_bending_and_raises_torsion():
    """Bending-torsion inertial coupling (x_alpha > 0) separates the first two frequencies."""
    f0 = aes.AeroelasticModel(uniform_wing(0.0), 20).natural_modes(2).frequencies
    f1 = aes.AeroelasticModel(uniform_wing(0.3), 20).natural_modes(2).frequencies
    assert f1[0] < f0[0] and f1[1] > f0[1]


def test_mass_matrix_positive_definite(aileron10):
    ms = aileron10.matrices.Ms.toarray()
    np.testing.assert_allclose(ms, ms.T, atol=1e-12)
    assert sla.eigvalsh(ms).min() > 0
