"""Flap path: unknowns only where a surface is, actuators as Dirac deltas between nodes, a stiff
hinge reproduces the clean wing, a leading-edge hinge reproduces pitch aerodynamics."""

import dataclasses

import numpy as np
import pytest

import aeroservo as aes
from aeroservo.structure import Actuator, ControlSurface, Segment, Wing


def test_flap_unknowns_only_on_the_surface(aileron10):
    mesh = aileron10.mesh
    x = mesh.nodes
    cs = aileron10.wing.control_surfaces[0]
    has = mesh.dof_delta[0] >= 0
    np.testing.assert_array_equal(has, (x >= cs.start - 1e-9) & (x <= cs.end + 1e-9))
    assert has.sum() == 5  # 60 % span to the tip with 10 elements: nodes 6..10
    off = mesh.surface < 0
    assert np.all(mesh.element_dofs[off, 6:] == -1)
    assert aileron10.n_dofs == 30 + 5


def test_actuator_is_a_point_spring_between_nodes():
    """q^T K_act q = k_act delta(x_a)^2 for a linear flap field, with x_a not a mesh node."""
    seg = Segment(0.0, 4.0, 0.5, -0.3, 10.0, 0.1, 1.0, 1e6, 1e5)
    k_act, x_a = 2.5e3, 3.37

    def wing(actuators):
        cs = ControlSurface(
            "flap", 2.0, 4.0, 0.5, 0.05, 0.02, hinge_stiffness=10.0, actuators=actuators
        )
        return Wing(4.0, [seg], [cs])

    m1 = aes.AeroelasticModel(wing((Actuator(x_a, k_act),)), 7)
    m0 = aes.AeroelasticModel(wing(()), 7)
    assert not np.any(np.isclose(m1.mesh.nodes, x_a))
    d = m1.mesh.dof_delta[0]
    q = np.zeros(m1.n_dofs)
    q[d[d >= 0]] = 0.3 + 0.2 * m1.mesh.nodes[d >= 0]  # delta(x) = 0.3 + 0.2 x
    dk = (m1.matrices.Ks - m0.matrices.Ks).toarray()
    assert q @ dk @ q == pytest.approx(k_act * (0.3 + 0.2 * x_a) ** 2, rel=1e-12)


def test_stiff_hinge_reproduces_clean_wing(goland10_flutter):
    """Reference sec. 3, check 1: hinge stiffness -> infinity recovers the clean Goland wing."""
    wing = aes.examples.goland_aileron(actuator_stiffness=1e10, hinge_stiffness=1e10)
    r = aes.flutter_boundary(aes.AeroelasticModel(wing, 10), 1.225)
    assert r.flutter_speed == pytest.approx(goland10_flutter.flutter_speed, rel=1e-4)
    assert r.flutter_frequency == pytest.approx(goland10_flutter.flutter_frequency, rel=1e-4)


def test_leading_edge_hinge_equals_pitch_on_the_wing():
    """Reference sec. 3, check 3 at the assembled level: with a = c = -1 over the whole span, a
    flap field equal to a twist field produces identical aerodynamic loads and downwash."""
    seg = Segment(0.0, 3.0, 0.4, -1.0, 12.0, 0.3, 2.0, 5e5, 5e4)
    cs = ControlSurface("le", 0.0, 3.0, -1.0, 0.1, 0.1, hinge_stiffness=100.0)
    m = aes.AeroelasticModel(Wing(3.0, [seg], [cs]), 6)
    mesh, am = m.mesh, m.matrices
    f = np.sin(mesh.nodes)  # zero at the clamped root
    q_phi = np.zeros(m.n_dofs)
    q_phi[mesh.dof_phi[1:]] = f[1:]
    q_del = np.zeros(m.n_dofs)
    q_del[mesh.dof_delta[0]] = f
    for mat in (am.Mnc, am.Cnc, am.Knc, am.Pq, am.Pd, am.E1, am.F1):
        np.testing.assert_allclose(mat @ q_phi, mat @ q_del, rtol=1e-12, atol=1e-12)


def test_surface_position_is_free():
    """Two surfaces anywhere on the span, with edges off the uniform grid; the mesh puts nodes at
    every edge and keeps separate flap unknowns at a shared node."""
    seg = Segment(0.0, 5.0, 0.5, -0.3, 10.0, 0.1, 1.0, 1e6, 1e5)
    a = ControlSurface("inboard", 0.7, 2.3, 0.5, 0.05, 0.02, hinge_stiffness=100.0)
    b = ControlSurface("outboard", 2.3, 4.1, 0.5, 0.05, 0.02, hinge_stiffness=100.0)
    m = aes.AeroelasticModel(Wing(5.0, [seg], [a, b]), 12)
    for x in (0.7, 2.3, 4.1):
        assert np.any(np.isclose(m.mesh.nodes, x))
    i = int(np.argmin(np.abs(m.mesh.nodes - 2.3)))
    assert m.mesh.dof_delta[0, i] >= 0 and m.mesh.dof_delta[1, i] >= 0
    assert m.mesh.dof_delta[0, i] != m.mesh.dof_delta[1, i]
    r = aes.flutter_boundary(m, 1.225)
    assert r.n_states == m.n_states


def test_wing_file_roundtrip_changes_nothing(aileron10):
    """dataclasses.replace with the same values gives bit-identical matrices (no hidden state)."""
    w2 = dataclasses.replace(aileron10.wing)
    m2 = aes.AeroelasticModel(w2, 10)
    assert (m2.matrices.Ks != aileron10.matrices.Ks).nnz == 0
