"""The discrete Riccati solver (structured doubling, design/riccati.py) against SciPy's
``solve_discrete_are`` (an independent Schur/QZ method) on random pairs; a pair that cannot be
stabilised raises a numerical error instead of returning a huge X (found by issue 39's error
tests: before, an unstable uncontrollable mode gave X ~ 6e307 and no error)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

from aeroservo.design.riccati import solve_dare
from aeroservo.errors import NumericalError


@pytest.mark.parametrize("seed", range(40))
def test_doubling_matches_scipy_on_random_pairs(seed):
    rng = np.random.default_rng(seed)
    n, m = int(rng.integers(2, 9)), int(rng.integers(1, 3))
    A = rng.standard_normal((n, n))
    A *= rng.uniform(0.5, 1.5) / np.abs(np.linalg.eigvals(A)).max()  # some unstable
    B = rng.standard_normal((n, m))
    Q = np.diag(rng.uniform(0.1, 10.0, n))
    R = np.diag(rng.uniform(0.1, 10.0, m))
    X = solve_dare(A, B, Q, R)
    Xr = sla.solve_discrete_are(A, B, Q, R)
    # the solutions' conditioning: relative to the largest entry
    np.testing.assert_allclose(X, Xr, rtol=1e-7, atol=1e-9 * np.abs(Xr).max())
    K = np.linalg.solve(R + B.T @ X @ B, B.T @ X @ A)
    assert np.abs(np.linalg.eigvals(A - B @ K)).max() < 1.0


@pytest.mark.parametrize("unstable", [1.0001, 2.0, 50.0])
def test_a_pair_that_cannot_be_stabilised_is_a_numerical_error(unstable):
    A = np.diag([unstable, 0.5, 0.3])
    B = np.array([[0.0], [1.0], [1.0]])  # the first mode is unstable and not controllable
    with pytest.raises(NumericalError, match="(no stabilising solution|did not converge)"):
        with np.errstate(all="ignore"):
            solve_dare(A, B, np.eye(3), np.eye(1))
