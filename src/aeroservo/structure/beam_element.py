"""The aeroelastic beam element: shape functions and Gauss quadrature (seed eq. 4-6).

Within an element of length L with local coordinate xi = (x - x_i)/L in [0, 1]:

* bending w(x): cubic Hermite in ``[w_i, theta_i, w_j, theta_j]`` (theta = dw/dx);
* twist phi(x) and flap rotation delta(x): linear in ``[phi_i, phi_j]`` and ``[delta_i, delta_j]``;
* each aerodynamic lag field z(x): linear in its two nodal values (the seed's x-bar).

Element matrices ``int_0^L N^T S N dx`` are computed for all elements at once with a 4-point
Gauss rule (exact for the degree-6 products of Hermite cubics).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "gauss_rule",
    "field_shapes",
    "lag_shapes",
    "integrate",
    "point_shapes",
    "pointwise_shapes",
]

N_GAUSS = 4


def gauss_rule(n: int = N_GAUSS) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points and weights on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


def _hermite(xi: np.ndarray, L: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hermite cubics (values, d/dx, d2/dx2), shape (len(L), len(xi), 4)."""
    xi = xi[None, :]
    L = L[:, None]
    one = np.ones_like(xi * L)
    h = np.stack(
        [
            (1 - 3 * xi**2 + 2 * xi**3) * one,
            L * (xi - 2 * xi**2 + xi**3),
            (3 * xi**2 - 2 * xi**3) * one,
            L * (-(xi**2) + xi**3),
        ],
        axis=-1,
    )
    dh = np.stack(
        [
            (-6 * xi + 6 * xi**2) / L,
            (1 - 4 * xi + 3 * xi**2) * one,
            (6 * xi - 6 * xi**2) / L,
            (-2 * xi + 3 * xi**2) * one,
        ],
        axis=-1,
    )
    d2h = np.stack(
        [
            (-6 + 12 * xi) / L**2,
            (-4 + 6 * xi) / L,
            (6 - 12 * xi) / L**2,
            (-2 + 6 * xi) / L,
        ],
        axis=-1,
    )
    return h, dh, d2h


def field_shapes(L: np.ndarray, xi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Shape matrices of the section fields at local points ``xi`` of elements of length ``L``.

    Returns
    -------
    N : ndarray (n_el, n_xi, 3, 8)
        Values of ``[w, phi, delta]`` per unit local unknown (order of ``mesh.LOCAL_DOFS``).
    D : ndarray (n_el, n_xi, 3, 8)
        ``[w'', phi', delta']``, the strain measures of the stiffness operator.
    S : ndarray (n_el, n_xi, 8)
        Bending slope w' (used by sensors and loads).
    """
    L = np.atleast_1d(np.asarray(L, dtype=float))
    xi = np.atleast_1d(np.asarray(xi, dtype=float))
    h, dh, d2h = _hermite(xi, L)
    n_el, n_xi = L.size, xi.size
    lin = np.stack([1 - xi, xi], axis=-1)[None].repeat(n_el, axis=0)
    dlin = np.stack([-np.ones_like(xi), np.ones_like(xi)], axis=-1)[None] / L[:, None, None]
    dlin = np.broadcast_to(dlin, (n_el, n_xi, 2))
    N = np.zeros((n_el, n_xi, 3, 8))
    D = np.zeros((n_el, n_xi, 3, 8))
    N[..., 0, 0:4] = h
    N[..., 1, 4:6] = lin
    N[..., 2, 6:8] = lin
    D[..., 0, 0:4] = d2h
    D[..., 1, 4:6] = dlin
    D[..., 2, 6:8] = dlin
    S = np.zeros((n_el, n_xi, 8))
    S[..., 0:4] = dh
    return N, D, S


def lag_shapes(xi: np.ndarray) -> np.ndarray:
    """Linear shape functions of a lag field, shape (n_xi, 2)."""
    xi = np.atleast_1d(np.asarray(xi, dtype=float))
    return np.stack([1 - xi, xi], axis=-1)


def integrate(
    L: np.ndarray, weights: np.ndarray, left: np.ndarray, coef: np.ndarray, right: np.ndarray
) -> np.ndarray:
    """Element integrals ``int_0^L left^T coef right dx`` for all elements.

    Parameters
    ----------
    L : ndarray (n_el,)
        Element lengths [m].
    weights : ndarray (n_g,)
        Gauss weights on [0, 1].
    left : ndarray (n_el, n_g, r, p)
    coef : ndarray broadcastable to (n_el, n_g, r, s)
    right : ndarray (n_el, n_g, s, q)

    Returns
    -------
    ndarray (n_el, p, q)
    """
    coef = np.broadcast_to(coef, left.shape[:2] + (left.shape[2], right.shape[2]))
    return np.einsum("eg,egrp,egrs,egsq->epq", L[:, None] * weights[None, :], left, coef, right)


def point_shapes(L: float, xi: float) -> tuple[np.ndarray, np.ndarray]:
    """Field values and bending slope at one point: ``N`` (3, 8) and ``S`` (8,)."""
    N, _, S = field_shapes(np.array([L]), np.array([xi]))
    return N[0, 0], S[0, 0]


def pointwise_shapes(L: np.ndarray, xi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Field shapes at one local point per entry: element lengths ``L`` and points ``xi``
    paired (both (n,)), as :func:`field_shapes` gives them for every pair.

    Returns ``N`` (n, 3, 8), ``D`` (n, 3, 8) and ``S`` (n, 8): values of ``[w, phi, delta]``,
    ``[w'', phi', delta']`` and the bending slope ``w'``.
    """
    L = np.atleast_1d(np.asarray(L, dtype=float))
    xi = np.atleast_1d(np.asarray(xi, dtype=float))
    n = L.size
    N = np.zeros((n, 3, 8))
    D = np.zeros((n, 3, 8))
    S = np.zeros((n, 8))
    for i0 in range(0, n, 256):  # the Hermite table is (chunk, chunk): keep it small
        sl = slice(i0, min(n, i0 + 256))
        h, dh, d2h = _hermite(xi[sl], L[sl])
        idx = np.arange(sl.stop - sl.start)
        h, dh, d2h = h[idx, idx], dh[idx, idx], d2h[idx, idx]
        x, ll = xi[sl], L[sl]
        N[sl, 0, 0:4] = h
        N[sl, 1, 4:6] = N[sl, 2, 6:8] = np.stack([1 - x, x], axis=-1)
        D[sl, 0, 0:4] = d2h
        D[sl, 1, 4:6] = D[sl, 2, 6:8] = np.stack([-1 / ll, 1 / ll], axis=-1)
        S[sl, 0:4] = dh
    return N, D, S
