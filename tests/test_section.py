"""Typical sections built on the same aerodynamic code: Hodges & Pierce (2-DOF) and the 3-DOF
Karpel section with a trailing-edge flap, exact-C(k) (p-k) and Wagner values."""

import numpy as np
import pytest
from conftest import reference

import aeroservo as aes
from aeroservo.stability import pk_flutter
from aeroservo.system import TypicalSection

RHO = 1.225
B, W_ALPHA = 0.5, 50.0  # HP-1 is non-dimensional: any semichord and pitch frequency


def hp1(wagner="rt_jones") -> TypicalSection:
    inp = reference("typical_section_HP1")["inputs"]
    return TypicalSection.from_nondimensional(
        semichord=B,
        a=inp["a"],
        mu=inp["mu"],
        x_alpha=inp["x_alpha"],
        r_alpha2=inp["r_alpha2"],
        omega_h=inp["sigma_omega_h_over_omega_alpha"] * W_ALPHA,
        omega_alpha=W_ALPHA,
        density=RHO,
        wagner=wagner,
    )


def karpel(with_flap=True, wagner="rt_jones") -> TypicalSection:
    inp = reference("typical_section_3dof_Karpel")["inputs"]
    flap = (
        {
            "hinge": inp["c_h"],
            "x_beta": inp["x_beta"],
            "r_beta2": inp["r_beta2"],
            "omega_beta": inp["omega_beta"],
        }
        if with_flap
        else {}
    )
    return TypicalSection.from_nondimensional(
        semichord=inp["b_m"],
        a=inp["a"],
        mu=inp["mu"],
        x_alpha=inp["x_alpha"],
        r_alpha2=inp["r_alpha2"],
        omega_h=inp["omega_h"],
        omega_alpha=inp["omega_alpha"],
        density=inp["rho"],
        wagner=wagner,
        **flap,
    )


@pytest.mark.parametrize(
    "wagner,key",
    [("rt_jones", "RTJones"), ("wp_jones", "WPJones_0.041_0.32"), ("fit4", "Wagner_4term_fit")],
)
def test_hp1_wagner(wagner, key):
    """Case typical_section_HP1 (Hodges & Pierce problem 5.5 data) [C], same model: rel 0.2 %."""
    exp = reference("typical_section_HP1")["expected"][key]
    r = aes.flutter_boundary(hp1(wagner), RHO)
    assert r.flutter_speed / (B * W_ALPHA) == pytest.approx(exp["U_F_over_b_omega_alpha"], rel=2e-3)
    assert 2 * np.pi * r.flutter_frequency / W_ALPHA == pytest.approx(
        exp["omega_F_over_omega_alpha"], rel=2e-3
    )


def test_hp1_exact():
    """Case typical_section_HP1, exact Theodorsen (two independent formulations agree) [C]."""
    exp = reference("typical_section_HP1")["expected"]["exact_Theodorsen"]
    r = pk_flutter(hp1(), RHO)
    assert r.flutter_speed / (B * W_ALPHA) == pytest.approx(exp["U_F_over_b_omega_alpha"], rel=2e-3)
    assert 2 * np.pi * r.flutter_frequency / W_ALPHA == pytest.approx(
        exp["omega_F_over_omega_alpha"], rel=2e-3
    )
    k_f = 2 * np.pi * r.flutter_frequency * B / r.flutter_speed
    assert k_f == pytest.approx(exp["k_F"], rel=2e-3)


def test_hp1_divergence_closed_form():
    """U_D / (b omega_alpha) = sqrt(mu r^2 / (2 (1/2 + a))) (case typical_section_HP1)."""
    case = reference("typical_section_HP1")
    inp = case["inputs"]
    closed = np.sqrt(inp["mu"] * inp["r_alpha2"] / (2 * (0.5 + inp["a"])))
    assert closed == pytest.approx(
        case["expected"]["divergence"]["U_D_over_b_omega_alpha"], abs=1e-4
    )
    r = aes.flutter_boundary(hp1(), RHO)
    assert r.divergence_speed / (B * W_ALPHA) == pytest.approx(closed, rel=1e-10)


def test_karpel_in_vacuo():
    """Case typical_section_3dof_Karpel: coupled in-vacuo frequencies 48.712, 110.803, 348.754."""
    s = karpel()
    w2 = np.linalg.eigvals(np.linalg.solve(s.mass_matrix(), s.matrices.Ks.toarray())).real
    np.testing.assert_allclose(np.sqrt(np.sort(w2)), [48.712, 110.803, 348.754], rtol=1e-4)


@pytest.mark.parametrize(
    "with_flap,method,key",
    [
        (True, "wagner", "RTJones"),
        (True, "pk", "exact_Theodorsen"),
        (False, "wagner", "flap_locked_RTJones"),
        (False, "pk", "flap_locked_exact"),
    ],
)
def test_karpel_flutter(with_flap, method, key):
    """Case typical_section_3dof_Karpel (parameters as coded in Ssp24-1/Linear-Flutter-Analysis)
    [C], same model: rel 0.3 % (the case's stated tolerance); exact values via p-k."""
    exp = reference("typical_section_3dof_Karpel")["expected"][key]
    s = karpel(with_flap)
    r = aes.flutter_boundary(s, RHO) if method == "wagner" else pk_flutter(s, RHO)
    assert r.flutter_speed == pytest.approx(exp["U_F_m_s"], rel=3e-3)
    assert 2 * np.pi * r.flutter_frequency == pytest.approx(exp["omega_F_rad_s"], rel=3e-3)


def test_karpel_divergence():
    """Case typical_section_3dof_Karpel: divergence about 635 m/s (R. T. Jones state space)."""
    exp = reference("typical_section_3dof_Karpel")["expected"]["divergence_RTJones_m_s"]
    assert aes.flutter_boundary(karpel(), RHO).divergence_speed == pytest.approx(exp, rel=5e-3)


def test_section_rejects_bad_input():
    with pytest.raises(aes.InputError, match="section.k_pitch"):
        TypicalSection(1.0, -0.2, 10.0, 0.1, 3.0, 100.0, -5.0)
