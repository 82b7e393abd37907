"""Piecewise-linear hinges: the linear system of each region and exact motion through switches.

While every element stays on one piece of its law (a *region*), the plant is linear and affine,
``x' = A_r x + B u + g_r`` with ``A_r = A + B_n K_r C_n`` and ``g_r = B_n f_r``
(``phi = K_r s + f_r`` on the pieces). Between samples the input is held, so the motion is
known in closed form from the eigen-decomposition ``A_r = V diag(lambda) V^-1``:

    y(t) = exp(lambda t) y0 + (exp(lambda t) - 1) / lambda * gamma,   x = V y,

and the time a rotation reaches an edge of its piece is the root of a scalar function, located
by Newton's method (kept in its bracket) to rounding (``docs/freeplay.md``). Region matrices
are built once per region visited and cached.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ...design.plant import zoh
from ...errors import NumericalError
from .exact_motion import (
    FINE,
    GRID,
    crossing_time,
    exits,
    graze_index,
    modal_at,
    quick_bracket,
    rows_at,
    scan_rows,
    state_at,
)

__all__ = ["Regions", "piece_tables", "real_basis"]


def real_basis(lam: np.ndarray, V: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The modes kept for a real motion and their weights: ``(keep, weight)``.

    A real matrix's complex roots come in conjugate pairs (LAPACK returns each pair next to
    each other, the second root and its vector the exact conjugates of the first), and the
    modal coordinates of a real state are conjugate too, so ``Re(V y) = Re(V[:, keep] weight
    y[keep])`` with the first root of each pair (weight 2) and every real root (weight 1):
    about half the modes for the closed-form motion and its crossing search, the same motion
    to rounding. Without that structure (``keep`` all, weights 1) the full basis is used.
    """
    n = lam.size
    keep, weight, i = [], [], 0
    while i < n:
        if lam[i].imag == 0.0:
            keep.append(i)
            weight.append(1.0)
            i += 1
        elif (
            i + 1 < n
            and lam[i].imag > 0.0
            and lam[i + 1] == np.conj(lam[i])
            and np.array_equal(V[:, i + 1], np.conj(V[:, i]))
        ):
            keep.append(i)
            weight.append(2.0)
            i += 2
        else:
            return np.arange(n), np.ones(n)
    return np.array(keep), np.array(weight)


def piece_tables(elements) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per element ``(edges, K, f)`` with ``phi = K[i] s + f[i]`` on piece ``i``; pieces
    with the same moment on both sides of an edge are merged (a zero gap has no edge)."""
    out = []
    for k, law in zip(elements.stiffness, elements.laws, strict=True):
        edges, slopes, icpt = law.pieces(k)
        K, f = k - slopes, -icpt
        # drop empty pieces (a zero gap), then merge neighbours with the same moment
        keep = [0] + [
            i + 1 for i in range(edges.size) if i + 1 == edges.size or edges[i + 1] > edges[i]
        ]
        pieces = [p for p in range(K.size) if p in keep]
        keep_e, keep_p = [], [pieces[0]]
        for p in pieces[1:]:
            if K[p] == K[keep_p[-1]] and f[p] == f[keep_p[-1]]:
                continue
            keep_e.append(edges[p - 1])
            keep_p.append(p)
        out.append((np.array(keep_e), K[keep_p], f[keep_p]))
    return out


class Regions:
    """Region matrices of a nonlinear plant sampled at ``dt`` (cached per region)."""

    def __init__(self, nplant, B: np.ndarray, C: np.ndarray, D_d: np.ndarray, dt: float):
        self.np = nplant
        self.A = np.asarray(nplant.plant.A)
        self.B, self.C, self.dt = B, C, dt
        self.d_n = D_d  # feedthrough of phi to the outputs C reads
        self.tables = piece_tables(nplant.elements)
        self.scale = np.array([max(np.ptp(t[0]) if t[0].size else 0.0, 1e-6) for t in self.tables])
        self._sampled: dict = {}
        self._eigen: dict = {}
        self._edges: dict = {}

    def locate(self, s: np.ndarray) -> tuple:
        """The region (piece index per element) of the rotations ``s`` [rad]."""
        return tuple(
            int(np.searchsorted(t[0], v, side="right")) for t, v in zip(self.tables, s, strict=True)
        )

    def bounds(self, r: tuple) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper edges of region ``r`` per element (+-inf at the ends)."""
        lo = np.array(
            [t[0][i - 1] if i > 0 else -np.inf for t, i in zip(self.tables, r, strict=True)]
        )
        hi = np.array(
            [t[0][i] if i < t[0].size else np.inf for t, i in zip(self.tables, r, strict=True)]
        )
        return lo, hi

    def affine(self, r: tuple) -> tuple[np.ndarray, np.ndarray]:
        """``(K_r, f_r)``: ``phi = K_r s + f_r`` on region ``r``."""
        K = np.array([t[1][i] for t, i in zip(self.tables, r, strict=True)])
        f = np.array([t[2][i] for t, i in zip(self.tables, r, strict=True)])
        return K, f

    def system(self, r: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(A_r, g_r, C_r, e_r)``: state matrix, affine term, output matrix and output
        constant of region ``r`` (outputs ``C x + D_n phi``)."""
        K, f = self.affine(r)
        p = self.np
        A = self.A + (p.b_n * K) @ p.c_n
        C = self.C + (self.d_n * K) @ p.c_n
        return A, p.b_n @ f, C, self.d_n @ f

    def sampled(self, r: tuple):
        """``(Phi, Gu, g, C_r, e_r)`` of region ``r`` over one sample (zero-order hold)."""
        if r not in self._sampled:
            A, g, C, e = self.system(r)
            Phi, G = zoh(A, np.hstack([self.B, g[:, None]]), self.dt)
            self._sampled[r] = (Phi, G[:, :-1], G[:, -1], C, e)
        return self._sampled[r]

    def eigen(self, r: tuple):
        """``(lambda, V, V^-1, V^-1 [B g], C_n V, C_rate V, [C_n V; C_rate V])`` of region
        ``r`` on its real modal basis (:func:`real_basis`: one root of each conjugate pair,
        its columns of ``V`` doubled; every product with ``V`` is then the real part)."""
        if r not in self._eigen:
            A, g, _, _ = self.system(r)
            lam, V = sla.eig(A)
            Vi = np.linalg.inv(V)
            z = np.random.default_rng(0).standard_normal((A.shape[0], 2))  # a cheap residual
            err = np.abs(V @ (lam[:, None] * (Vi @ z)) - A @ z).max() / max(
                np.abs(A).sum(axis=1).max() * np.abs(z).max(), 1.0
            )
            if not err < 1e-8:
                raise NumericalError(
                    f"nonlinear march: the linear system of region {r} is defective (eigen-"
                    f"decomposition residual {err:.1e}); it cannot be marched exactly"
                )
            keep, weight = real_basis(lam, V)
            lam, V, Vi = lam[keep], V[:, keep] * weight, Vi[keep]
            G = Vi @ np.hstack([self.B, g[:, None]])
            W, Wd = self.np.c_n @ V, self.np.c_rate @ V
            self._eigen[r] = (lam, V, Vi, G, W, Wd, np.vstack([W, Wd]))
            lo, hi = self.bounds(r)
            tol = 1e-12 * self.scale
            self._edges[r] = (
                lo,
                hi,
                tol,
                (lo - tol).tolist(),
                (hi + tol).tolist(),
                G[:, :-1],
                G[:, -1],
                (lo - tol)[:, None],
                (hi + tol)[:, None],
            )
        return self._eigen[r]

    def interval(self, x: np.ndarray, r: tuple, u: np.ndarray, h: float, switches: list, t0: float):
        """March ``h`` [s] from ``x`` in region ``r`` with the input ``u`` held, through every
        edge crossing: ``(x_end, region_end)``; crossing times [s] (from ``t0``) are appended to
        ``switches``.

        The interval is scanned at :data:`SUB` points; a sub-interval where a rotation is
        beyond an edge of its piece, or where the cubic Hermite interpolant of the rotation and
        its rate predicts an excursion beyond it (a graze between two points), is scanned
        finer; the crossing is then located by Newton's method (kept in its bracket) on the
        closed-form rotation.
        """
        t = 0.0
        for _ in range(10_000):
            lam, V, Vi, G, W, Wd, WWd = self._eigen.get(r) or self.eigen(r)
            lo, hi, tol, lo_l, hi_l, Gu, gg, lo_c, hi_c = self._edges[r]
            y0 = Vi @ x
            gam = Gu @ u + gg if Gu.shape[1] else gg
            rest = h - t
            # just after a switch the rotation starts on an edge: scan (a return within the
            # sample would not show at its ends)
            bracket = False
            if t == 0.0:
                y1 = modal_at(lam, y0, gam, rest)
                v0, v1 = (WWd @ y0).real.tolist(), (WWd @ y1).real.tolist()
                bracket = quick_bracket(v0, v1, rest, lo_l, hi_l)
            ends = None
            if bracket is None:  # no edge reached: the end of the interval
                return (V @ y1).real, r
            if bracket:
                cands = [bracket]
                ends = (v0[bracket[2]], v1[bracket[2]])
            else:  # scan the interval
                taus = rest * GRID
                rows = scan_rows(WWd, lam, y0, gam, rest)  # rotations, then their rates
                s = rows[: W.shape[0]]
                cands = exits(s, taus, lo_c, hi_c)
                if not cands:
                    j = graze_index(s, rows[W.shape[0] :], taus, lo, hi, tol)
                    if j is not None:
                        fine = taus[j - 1] + (taus[j] - taus[j - 1]) * FINE
                        cands = exits(rows_at(W, lam, y0, gam, fine), fine, lo_c, hi_c)
                if not cands:
                    return state_at(V, lam, y0, gam, rest), r
            best = None  # the earliest crossing of every element out at the first exit
            for ta, tb, e, upper, *at_ends in cands:
                edge = hi[e] if upper else lo[e]
                ends = at_ends or ends  # the rotations at the bracket's ends, when known
                tc = crossing_time(W[e], lam, y0, gam, edge, ta, tb, tol[e], ends)
                if best is None or tc < best[0]:
                    best = (tc, e, upper)
            tc, e, upper = best
            x = state_at(V, lam, y0, gam, tc)
            t += tc
            switches.append(t0 + t)
            r = r[:e] + (r[e] + (1 if upper else -1),) + r[e + 1 :]
            if t >= h * (1.0 - 1e-14):
                return x, r
        raise NumericalError("nonlinear march: more than 10000 switches in one sample (chattering)")
