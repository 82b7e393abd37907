"""The stability engine on a synthetic system with closed-form eigenvalues.

Two uncoupled oscillators ``qdd + c(V) qd + k(V) q = 0``:

* mode A: k = 2500, c = (V - 5.5)^2 - 0.04, so Re(lambda) = -c/2 > 0 exactly on (5.3, 5.7):
  a hump mode that goes unstable and stable again, with frequency 50 rad/s at both crossings;
* mode B: k = 900 + 30 V^2, c = 2: its frequency crosses mode A's near V = 7.3 with a
  different damping (tracking must not swap the branches).
"""

import numpy as np
import pytest
import scipy.sparse as sp

import aeroservo as aes
from aeroservo.stability.branches import Branches
from aeroservo.stability.crossings import Verifier, branch_crossings
from aeroservo.stability.modal import ModalSystem
from aeroservo.stability.tracking import EigenTracker
from aeroservo.system import FirstOrderSystem


class Synthetic(FirstOrderSystem):
    def modes_at_rest(self, n_modes):
        lam, X = np.linalg.eig(self.state_matrix(0.0))
        keep = lam.imag > 0
        lam, X = lam[keep], X[:, keep]
        order = np.argsort(np.abs(lam.imag))[::-1]  # mode A (~50 rad/s) first, then B
        return lam[order][:n_modes], X[:, order][:, :n_modes]


def synthetic() -> Synthetic:
    K0, K2 = np.diag([2500.0, 900.0]), np.diag([0.0, 30.0])
    C0, C1, C2 = np.diag([30.21, 2.0]), np.diag([-11.0, 0.0]), np.diag([1.0, 0.0])
    Z, I = np.zeros((2, 2)), np.eye(2)

    def blk(a, b, c, d):
        return sp.csr_matrix(np.block([[a, b], [c, d]]))

    return Synthetic(
        E=sp.csr_matrix(np.eye(4)),
        A0=blk(Z, I, -K0, -C0),
        A1=blk(Z, Z, Z, -C1),
        A2=blk(Z, Z, -K2, -C2),
        n_q=2,
        state_labels=("qA", "qB", "qA_dot", "qB_dot"),
        density=1.0,
        Ks=sp.csr_matrix(K0),
        M=sp.csr_matrix(I),
        K_static=K2,
        lag_at_rest=sp.csr_matrix((0, 2)),
    )


def exact(V: float) -> tuple[complex, complex]:
    c = (V - 5.5) ** 2 - 0.04
    lam_a = -c / 2 + 1j * np.sqrt(2500 - c**2 / 4)
    lam_b = -1.0 + 1j * np.sqrt(900 + 30 * V**2 - 1)
    return lam_a, lam_b


def test_hump_found_on_the_adaptive_grid():
    r = aes.flutter_boundary(synthetic(), v_max=10.0)
    kinds = [(c.kind, c.mode) for c in r.crossings]
    assert kinds == [("onset", 0), ("recovery", 0)]
    assert r.crossings[0].speed == pytest.approx(5.3, rel=1e-7)
    assert r.crossings[1].speed == pytest.approx(5.7, rel=1e-7)
    assert r.crossings[0].frequency == pytest.approx(50 / (2 * np.pi), rel=1e-6)
    assert r.flutter_speed == pytest.approx(5.3, rel=1e-7)
    assert r.divergence_speed is None


def test_hump_between_grid_points_is_not_missed():
    """On an integer grid (5 and 6 bracket the hump, both stable) only the refinement finds it."""
    system = synthetic()
    tr = EigenTracker(system)
    lam0, X0 = system.modes_at_rest(2)
    speeds, lams, vecs = [0.0], [lam0], [X0]
    for v in range(1, 11):
        lam, X, conv = tr.correct_many(float(v), lams[-1], vecs[-1])
        assert conv.all()
        speeds.append(float(v))
        lams.append(lam)
        vecs.append(X)
    grid = Branches(np.array(speeds), np.array(lams), np.array(vecs), spectra=[])
    assert np.all(grid.eigenvalues[1:, 0].real < 0)  # the grid never sees the instability
    ver = Verifier(tr, ModalSystem(system, None, None, 0), grid)
    crossings = branch_crossings(ver, 0, rtol=1e-9)
    assert [c.kind for c in crossings] == ["onset", "recovery"]
    np.testing.assert_allclose([c.speed for c in crossings], [5.3, 5.7], rtol=1e-8)


def test_branches_do_not_swap_where_frequencies_cross():
    r = aes.flutter_boundary(synthetic(), v_max=10.0)
    for v, lam in zip(r.speeds, r.eigenvalues, strict=True):
        np.testing.assert_allclose(lam, exact(v), rtol=1e-8)
    f = r.frequencies
    assert (f[0, 0] > f[0, 1]) and (f[-1, 0] < f[-1, 1])  # the frequencies did cross


def test_eigen_sweep_keeps_branches_through_the_crossing():
    sweep = aes.eigen_sweep(synthetic(), np.linspace(0.0, 10.0, 41))
    lam = sweep.eigenvalues
    col_b = int(np.argmin(np.abs(lam[0] - exact(0.0)[1])))
    for v, row in zip(sweep.speeds, lam, strict=True):
        assert row[col_b] == pytest.approx(exact(v)[1], rel=1e-8)


def test_no_flutter_in_range():
    r = aes.flutter_boundary(synthetic(), v_max=5.0)
    assert r.flutter_speed is None and r.flutter_frequency is None
    assert "no flutter below 5 m/s" in r.summary()
    assert r.to_dict()["flutter_speed"] is None


def test_progress_callback_and_info(goland10):
    seen = []
    r = aes.flutter_boundary(goland10, 1.225, progress=seen.append)
    assert seen == list(r.speeds[1:])
    assert r.info["n_factorizations"] > 0


@pytest.mark.parametrize(
    "bad", [{"density": -1.0}, {"density": float("nan")}, {"v_max": 0.0}, {"n_modes": 0}]
)
def test_bad_arguments(goland10, bad):
    kw = {"density": 1.225} | bad
    with pytest.raises(aes.InputError, match=list(bad)[0]):
        aes.flutter_boundary(goland10, **kw)


def test_divergence_eigenvalues_kept_on_the_model_serve_every_density():
    """The density-independent divergence eigenvalues kept on the model give, at other
    densities and Mach numbers, the speeds of a fresh solve (and 1/sqrt(rho) scaling)."""
    from aeroservo.stability.divergence import divergence_speeds

    model = aes.AeroelasticModel(aes.examples.goland_aileron(), 8)
    for rho, mach in ((1.225, 0.0), (0.4, 0.0), (0.9, 0.5), (0.2, 0.5)):
        system = model.system(rho, mach)
        cached = divergence_speeds(system, model)
        np.testing.assert_array_equal(cached, divergence_speeds(system))
    v1 = divergence_speeds(model.system(1.0), model)
    np.testing.assert_allclose(divergence_speeds(model.system(0.25), model), 2.0 * v1, rtol=1e-12)
