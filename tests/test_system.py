"""The first-order form: A(V) assembled from speed-independent matrices, lag-state consistency."""

import numpy as np
import pytest
import scipy.linalg as sla

import aeroservo as aes


def test_state_matrix_is_quadratic_in_speed(aileron10):
    """A(V) = A0 + V A1 + V^2 A2 (checked against the pencil solved directly)."""
    system = aileron10.system(1.225)
    E = system.E.toarray()
    for v in (0.0, 37.0, 151.3):
        direct = np.linalg.solve(E, system.pencil(v).toarray())
        np.testing.assert_allclose(aileron10.state_matrix(v, 1.225), direct, rtol=1e-10, atol=1e-8)


def test_system_cached_per_density(goland10):
    assert goland10.system(1.225) is goland10.system(1.225)
    assert goland10.system(1.0) is not goland10.system(1.225)


def test_rest_eigenvalues(goland10):
    """At V = 0 the structure vibrates in still air (apparent mass added, no damping) and each lag
    state is a pure integrator (eigenvalue 0)."""
    system = goland10.system(1.225)
    ev = sla.eigvals(goland10.state_matrix(0.0, 1.225))
    lam, X = system.modes_at_rest(4)
    for l in lam:
        assert np.min(np.abs(ev - l)) < 1e-8 * abs(l)
    n_lag = goland10.wagner.n_terms * goland10.mesh.n_nodes
    assert np.sum(np.abs(ev) < 1e-8) == n_lag
    # the eigenvectors satisfy the pencil
    A0 = system.pencil(0.0).toarray()
    E = system.E.toarray()
    np.testing.assert_allclose(A0 @ X, E @ X * lam, atol=1e-8 * np.abs(lam).max())
    # added mass lowers the frequencies below the in-vacuo ones
    assert np.all(np.abs(lam) / (2 * np.pi) < goland10.natural_modes(4).frequencies)


def test_steady_lag_states_recover_quasi_steady_aerodynamics(goland10):
    """For a uniform wing without flaps, eliminating the lag states at steady state gives exactly
    the C = 1 aerodynamic stiffness (the lag fields represent the twist exactly)."""
    system = goland10.system(1.225)
    am = goland10.matrices
    np.testing.assert_allclose(
        system.K_static, (am.Knc - am.Pq).toarray(), rtol=1e-10, atol=1e-10 * np.abs(am.Pq).max()
    )


@pytest.mark.parametrize("wagner,n_terms", [("rt_jones", 2), ("one_term", 1), ("fit4", 4)])
def test_state_count(wagner, n_terms):
    m = aes.AeroelasticModel(aes.examples.goland(), 10, wagner=wagner)
    assert m.n_states == 2 * 30 + n_terms * 11
    assert m.system(1.225).n_states == m.n_states
    assert len(m.system(1.225).state_labels) == m.n_states


def test_speed_independent_matrices_built_once(aileron10, monkeypatch):
    """Sweeping speeds never re-assembles: assembly is not called after construction."""
    import aeroservo.system.aeroelastic as mod

    def boom(*a, **k):
        raise AssertionError("re-assembled")

    monkeypatch.setattr(mod, "assemble", boom)
    aes.flutter_boundary(aileron10, 1.1)
