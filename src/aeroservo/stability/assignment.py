"""Minimum-cost assignment of one set of eigenvalues to another.

Branch pairing and the certificate match eigenvalues by the assignment of least total cost.
Almost always every row's cheapest column is a different column; that assignment is then
optimal (it reaches the lower bound, the sum of the row minima) and costs one ``argmin``.
Only when two rows want the same column is ``scipy.optimize.linear_sum_assignment`` imported
and called, which keeps ``scipy.optimize`` (0.3 s) out of a plain flutter run (issue 17).
"""

from __future__ import annotations

import numpy as np


def min_cost_assignment(cost: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns of the least-cost assignment (as ``linear_sum_assignment``).

    Parameters
    ----------
    cost : ndarray, shape (m, n)
        Finite cost of assigning row i to column j.

    Returns
    -------
    rows, cols : ndarray of int
        ``min(m, n)`` pairs, rows increasing.
    """
    cost = np.asarray(cost, dtype=float)
    m, n = cost.shape
    if m <= n:
        cols = np.argmin(cost, axis=1)
        if len(set(cols.tolist())) == m:
            return np.arange(m), cols
    else:
        rows = np.argmin(cost, axis=0)
        if len(set(rows.tolist())) == n:
            order = np.argsort(rows)
            return rows[order], np.arange(n)[order]
    from scipy.optimize import linear_sum_assignment

    return linear_sum_assignment(cost)
