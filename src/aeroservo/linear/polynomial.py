"""Matrix polynomials in the airspeed: the state-space coefficients ``sum_k V^k c_k``."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["_Poly", "_dense"]


class _Poly:
    """Matrix polynomial ``sum_k V^k c[k]``."""

    __slots__ = ("c",)

    def __init__(self, c: np.ndarray):
        self.c = np.asarray(c, dtype=float)

    @classmethod
    def const(cls, m: np.ndarray) -> _Poly:
        return cls(np.asarray(m, dtype=float)[None])

    def __add__(self, other: _Poly) -> _Poly:
        k = max(self.c.shape[0], other.c.shape[0])
        out = np.zeros((k,) + self.c.shape[1:])
        out[: self.c.shape[0]] += self.c
        out[: other.c.shape[0]] += other.c
        return _Poly(out)

    def __matmul__(self, other: _Poly) -> _Poly:
        k = self.c.shape[0] + other.c.shape[0] - 1
        out = np.zeros((k, self.c.shape[1], other.c.shape[2]))
        for i in range(self.c.shape[0]):
            for j in range(other.c.shape[0]):
                out[i + j] += self.c[i] @ other.c[j]
        return _Poly(out)

    def left(self, m: np.ndarray) -> _Poly:
        """``m @ self`` for a constant matrix m."""
        return _Poly(np.einsum("ij,kjl->kil", m, self.c))

    def __call__(self, v: float) -> np.ndarray:
        out = self.c[-1].copy()
        for k in range(self.c.shape[0] - 2, -1, -1):
            out *= v
            out += self.c[k]
        return out


def _dense(m) -> np.ndarray:
    return m.toarray() if sp.issparse(m) else np.asarray(m, dtype=float)
