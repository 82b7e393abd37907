"""The crossing search on a grid (:func:`aeroservo.stability.crossings.sign_changes`) against
closed-form roots: randomized polynomials with known real roots, and humps that cross zero
between two grid points (Gaussian bumps), on random grids."""

import numpy as np
import pytest

from aeroservo.stability.crossings import HUMP_ZETA, sign_changes

RTOL = 1e-10


def _grid(rng: np.random.Generator, n: int) -> np.ndarray:
    return np.sort(np.concatenate([[0.0, 100.0], rng.uniform(0.0, 100.0, n - 2)]))


@pytest.mark.parametrize("seed", range(20))
def test_roots_of_random_polynomials(seed):
    """g(v) = -c prod(v - r_i): every sign change on the grid is found to rtol, with its
    direction and grid interval; no root is reported twice."""
    rng = np.random.default_rng(seed)
    roots = np.sort(rng.uniform(3.0, 97.0, rng.integers(1, 5)))
    V = _grid(rng, int(rng.integers(15, 40)))
    c = 10.0 ** rng.uniform(-3, 0)

    def g(v):
        return -c * np.prod(v - roots) if np.ndim(v) == 0 else -c * np.prod(v[:, None] - roots, 1)

    gv = g(V)
    zeta = np.full(V.size, 1.0)  # far from the axis: no hump search
    found = sign_changes(lambda v, k: float(g(v)), V, gv, zeta, RTOL, first=0)
    k_of = np.searchsorted(V, roots) - 1  # grid interval of each root
    once = [np.sum(k_of == k) == 1 for k in k_of]  # alone in its interval: a sign change
    expect = [r for r, alone in zip(roots, once, strict=True) if alone]
    assert [v for v, _, _ in found] == pytest.approx(expect, rel=1e-8)
    for v, rising, k in found:
        assert V[k] <= v <= V[k + 1]
        assert rising == bool(gv[k] < 0)


@pytest.mark.parametrize("seed", range(20))
def test_humps_between_grid_points(seed):
    """g(v) = -d + A exp(-((v - v0) / w)^2) with every grid value negative: the hump is
    refined when its top grid value is near the axis and both of its roots are found; far
    from the axis (|zeta| >= HUMP_ZETA) it is not searched."""
    rng = np.random.default_rng(100 + seed)
    v0, w = rng.uniform(20.0, 80.0), rng.uniform(0.5, 1.5)
    d = 1e-3
    A = d * rng.uniform(1.5, 4.0)
    # grid points on both sides of the hump, none within its positive part
    half = w * np.sqrt(np.log(A / d))  # g > 0 for |v - v0| < half
    left = v0 - half - rng.uniform(0.05, 0.5)
    right = v0 + half + rng.uniform(0.05, 0.5)
    V = np.sort(np.concatenate([np.linspace(0.0, left, 12), np.linspace(right, 100.0, 12)]))

    def g(v):
        return -d + A * np.exp(-(((v - v0) / w) ** 2))

    gv = g(V)
    assert (gv < 0).all()
    roots = [v0 - half, v0 + half]
    found = sign_changes(lambda v, k: float(g(v)), V, gv, np.full(V.size, 0.1 * HUMP_ZETA), RTOL)
    assert [v for v, _, _ in found] == pytest.approx(roots, rel=1e-8)
    assert [r for _, r, _ in found] == [True, False]
    far = sign_changes(lambda v, k: float(g(v)), V, gv, np.full(V.size, HUMP_ZETA), RTOL)
    assert far == []
