"""The numpy-free helpers that keep ``scipy.optimize`` out of a flutter run (issue 17):
Brent's root finder and the minimum-cost assignment, each against scipy on random inputs."""

import numpy as np
import pytest
from scipy.optimize import brentq as scipy_brentq
from scipy.optimize import linear_sum_assignment

from aeroservo.stability.assignment import min_cost_assignment
from aeroservo.stability.brent import BracketError, brentq


def _random_function(rng):
    """A smooth function with a sign change on [a, b]: a random cubic plus a sine."""
    c = rng.normal(size=4)
    w = rng.uniform(0.1, 5)
    root = rng.uniform(-1, 1)

    def f(x, s=1.0):
        return s * (
            (x - root) * (1 + c[0] ** 2 + c[1] ** 2 * (x - c[2]) ** 2)
            + 0.3 * np.sin(w * (x - root)) * np.exp(-(c[3] ** 2))
        )

    return f, root


@pytest.mark.parametrize("seed", range(40))
def test_brentq_matches_scipy_step_for_step(seed):
    rng = np.random.default_rng(seed)
    f, root = _random_function(rng)
    a, b = root - rng.uniform(0.01, 3), root + rng.uniform(0.01, 3)
    for xtol, rtol in ((2e-12, 8.881784197001252e-16), (1e-6, 1e-15), (1e-3 * b, 1e-15)):
        xtol = abs(xtol)
        ours = brentq(f, a, b, args=(1.0,), xtol=xtol, rtol=rtol)
        theirs = scipy_brentq(f, a, b, args=(1.0,), xtol=xtol, rtol=rtol)
        assert ours == theirs  # the same iteration gives the same floating-point root
        assert abs(ours - root) <= 4 * (xtol + rtol * abs(root)) + 1e-12


def test_brentq_errors_and_exact_ends():
    assert brentq(lambda x: x, 0.0, 1.0) == 0.0
    assert brentq(lambda x: x - 1.0, 0.0, 1.0) == 1.0
    with pytest.raises(BracketError, match="different signs"):
        brentq(lambda x: x * x + 1, -1.0, 1.0)
    with pytest.raises(BracketError, match="not finite"):
        brentq(lambda x: np.nan, -1.0, 1.0)
    with pytest.raises(BracketError, match="no convergence"):
        brentq(lambda x: np.tanh(5 * x) - 0.3, -1.0, 2.0, maxiter=2)


@pytest.mark.parametrize("shape", [(1, 1), (3, 3), (5, 8), (8, 5), (12, 12), (20, 30)])
@pytest.mark.parametrize("seed", range(10))
def test_min_cost_assignment_matches_scipy(shape, seed):
    """Random costs (conflicts between rows are frequent) and near-diagonal costs (the fast
    path): the total cost equals scipy's optimum."""
    rng = np.random.default_rng(seed)
    for cost in (
        rng.uniform(size=shape),
        np.abs(rng.normal(size=shape)) + 10 * (1 - np.eye(*shape)),
    ):
        rows, cols = min_cost_assignment(cost)
        r2, c2 = linear_sum_assignment(cost)
        assert rows.size == min(shape) and np.unique(cols).size == cols.size
        assert np.all(np.diff(rows) > 0)
        assert cost[rows, cols].sum() == pytest.approx(cost[r2, c2].sum(), rel=1e-14)
