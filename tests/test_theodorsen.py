"""Theodorsen's function, flap T-functions and section coefficients."""

import numpy as np
import pytest
from conftest import reference

from aeroservo.aero import section_aero, theodorsen_function
from aeroservo.aero.theodorsen import t_functions


def test_theodorsen_function_table():
    """Case theodorsen_function_values (shared/reference sec. 6.1, classical tables), abs 2e-5."""
    case = reference("theodorsen_function_values")
    exp = case["expected"]
    c = theodorsen_function(np.array(exp["k"]))
    tol = case["tolerance"]["abs"]
    np.testing.assert_allclose(c.real, exp["F"], atol=tol)
    np.testing.assert_allclose(c.imag, exp["G"], atol=tol)


@pytest.mark.parametrize(
    "lo,hi", [(1e-9, 1e-3), (1e-3, 1.0), (1.0, 12.0), (12.0, 14.0), (14.0, 1e5)]
)
def test_theodorsen_function_against_scipy_hankel(lo, hi):
    """The numpy Hankel series and asymptotic expansion against scipy.special.hankel2 (AMOS),
    on random reduced frequencies in each range, the series/asymptotic switch included."""
    from scipy.special import hankel2

    rng = np.random.default_rng(int(hi * 1000) % 2**31)
    k = np.exp(rng.uniform(np.log(lo), np.log(hi), 4000))
    h1, h0 = hankel2(1, k), hankel2(0, k)
    exact = h1 / (h1 + 1j * h0)
    c = theodorsen_function(k)
    # the power series of Y0, Y1 loses digits as e^k / k near the switch: 2e-11 is that bound
    assert np.max(np.abs(c - exact) / np.abs(exact)) < 5e-11


def test_theodorsen_limits():
    assert theodorsen_function(0.0) == 1.0
    assert abs(theodorsen_function(1e4) - 0.5) < 1e-4  # C -> 1/2 at high frequency
    with pytest.raises(ValueError, match="reduced frequency"):
        theodorsen_function(-0.1)


@pytest.mark.parametrize("key,c,a", [("c_h_0.6_a_-0.4", 0.6, -0.4), ("c_h_0.5_a_-0.5", 0.5, -0.5)])
def test_t_functions_table(key, c, a):
    """Case theodorsen_T_functions (Theodorsen 1935; AeroBeams theodorsen_flap_constants)."""
    case = reference("theodorsen_T_functions")
    T = t_functions(c, a)
    for name, value in case["expected"][key].items():
        assert T[name] == pytest.approx(value, abs=case["tolerance"]["abs"]), name


@pytest.mark.parametrize("c", [-0.5, 0.0, 0.5, 0.8])
def test_steady_flap_loads_match_thin_airfoil_theory(c):
    """Closed forms of thin-airfoil theory (Glauert), with cos(theta_h) = -c:
    dCL/ddelta = 2 (pi - theta_h + sin theta_h) and, about the quarter chord,
    dCm/ddelta = -sin(theta_h) (1 - cos(theta_h)) / 2."""
    b, U, rho = 0.7, 30.0, 1.2
    s = section_aero(b, -0.5, c)  # elastic axis at the quarter chord
    th = np.arccos(-c)
    # steady loads per unit delta: f = rho U b w (U r_q) - rho U^2 Knc (C = 1)
    f = rho * U**2 * (b * s.w * s.r_q[2] - s.Knc[:, 2])
    q_c = 0.5 * rho * U**2 * 2 * b
    assert f[0] / q_c == pytest.approx(2 * (np.pi - th + np.sin(th)), rel=1e-12)
    assert f[1] / (q_c * 2 * b) == pytest.approx(-np.sin(th) * (1 - np.cos(th)) / 2, rel=1e-12)


def test_apparent_mass_symmetric():
    s = section_aero(np.array([0.5, 1.0]), np.array([-0.3, 0.1]), np.array([0.6, 0.4]))
    np.testing.assert_allclose(s.Mnc, np.swapaxes(s.Mnc, -1, -2), rtol=1e-14, atol=1e-15)
    assert np.all(np.linalg.eigvalsh(s.Mnc) > 0)


def test_leading_edge_hinge_makes_flap_identical_to_pitch():
    """Reference sec. 3, check 3: hinge and elastic axis at the leading edge (c = a = -1) make
    the delta rows/columns of every aerodynamic matrix equal to the phi ones."""
    s = section_aero(0.8, -1.0, -1.0)
    for m in (s.Mnc, s.Cnc, s.Knc, s.Pq, s.Pd):
        np.testing.assert_allclose(m[:, 2], m[:, 1], rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(m[2, :], m[1, :], rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(s.r_q[2], s.r_q[1], rtol=1e-12)
    np.testing.assert_allclose(s.r_d[2], s.r_d[1], rtol=1e-12)
    np.testing.assert_allclose(s.w[2], s.w[1], rtol=1e-12)


def test_zero_chord_flap_has_no_aerodynamics():
    s = section_aero(0.8, -0.3, 1.0)
    for m in (s.Mnc, s.Cnc, s.Knc, s.Pq, s.Pd):
        assert np.all(m[:, 2] == 0) and np.all(m[2, :] == 0)


def test_theodorsen_at_huge_reduced_frequency_quietly_one_half():
    """C(k) -> 1/2 - i/(8k) for large k (A&S 9.2.7-8), without overflow warnings."""
    import warnings

    k = np.array([1e6, 1e10, 1e300])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        c = theodorsen_function(k)
    np.testing.assert_allclose(c.real, 0.5, rtol=1e-12)
    np.testing.assert_allclose(c.imag, -1.0 / (8.0 * k), rtol=1e-6)
