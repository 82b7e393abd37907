"""Where the branches cross the imaginary axis, decided on the full model.

The modal model's eigenvalues are accurate to about 1e-3 of their modulus, which is much
larger than the real part of a lightly damped mode. So wherever a branch is near the axis
(damping ratio below :data:`SIGN_ZETA`, or at an extremum below :data:`HUMP_ZETA`) its
eigenvalue is recomputed on the full model (:class:`Verifier`, inverse iteration from the
modal eigenpair), and every sign change and every
hump (a real part that rises towards zero and falls back between grid points) is found by root
finding on the full model's eigenvalue (:func:`sign_changes`, relative tolerance ``rtol``).
Crossings are only looked for where a branch is oscillatory at both ends of a grid interval:
real roots cross zero only at the static divergence speeds, found exactly elsewhere.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .branches import Branches, cluster, is_complex
from .brent import brentq
from .modal import ModalSystem
from .result import Crossing
from .tracking import EigenTracker, mac, subspace_share

__all__ = ["HUMP_ZETA", "SIGN_ZETA", "Verifier", "sign_changes", "branch_crossings"]

HUMP_ZETA = 0.05
"""Interior extrema of Re(lambda) with |damping ratio| below this are refined between grid
points (the step control keeps eigenvalue changes per step below 10 %, or 20 % for a branch
whose damping ratio is beyond 0.25 at both ends of the step, so a hump that crosses zero cannot
hide behind grid values further from zero than this)."""

SIGN_ZETA = 2e-3
"""Branch eigenvalues with |damping ratio| below this, or below 10 x the branch's measured
modal error (:func:`branch_crossings`), are recomputed on the full model before the sign of
their real part is trusted; so are the grid points around every near-axis extremum."""


CLUSTER_SHARE = 0.5
"""Least fraction of each full-model eigenvector of a cluster that must lie in the span of the
cluster's modal eigenvectors (the subspace form of the MAC test of a single branch)."""


class VerificationError(RuntimeError):
    """The full model has no eigenvalue matching a modal-model branch.

    Attributes
    ----------
    speed : float
        [m/s]
    eigenvalue : complex
        The modal eigenvalue that was not confirmed [1/s].
    above_band : bool
        A branch above the modal band nears the axis (the band must be widened to decide it).
    """

    def __init__(self, message: str, speed: float, eigenvalue: complex, above_band: bool = False):
        super().__init__(message)
        self.above_band = above_band
        self.speed = speed
        self.eigenvalue = eigenvalue


class Verifier:
    """Full-model eigenpairs of the modal branches, computed when first needed.

    Parameters
    ----------
    tracker : EigenTracker
        Corrector of the full model.
    modal : ModalSystem
    branches : Branches
    """

    def __init__(self, tracker: EigenTracker, modal: ModalSystem, branches: Branches):
        self.tracker = tracker
        self.modal = modal
        self.br = branches
        n, m = branches.eigenvalues.shape
        self.values = np.full((n, m), np.nan + 0j)
        self._vec: dict[tuple[int, int], np.ndarray] = {}
        self._followed: dict[tuple[int, int, float], complex] = {}

    @property
    def exact(self) -> np.ndarray:
        """Mask of the branch values computed on the full model."""
        return np.isfinite(self.values)

    def at(self, k: int, j: int) -> complex:
        """Full-model eigenvalue of branch j at grid point k (a branch in a cluster of nearly
        repeated eigenvalues is verified with its whole cluster, :func:`cluster`)."""
        if not np.isfinite(self.values[k, j]):
            group = cluster([self.br.eigenvalues[k]], j)
            if len(group) > 1:
                self._at_cluster(k, group)
                return complex(self.values[k, j])
            lam_r = complex(self.br.eigenvalues[k, j])
            x0 = self.modal.lift(self.br.vectors[k, :, j])
            lam, x, conv = self.tracker.correct(float(self.br.speeds[k]), lam_r, x0)
            n_q = self.tracker.n_q
            if not conv or mac(x0[:n_q, None], x[:n_q, None])[0] < 0.5:
                v = self.br.speeds[k]
                raise VerificationError(
                    f"the full model has no eigenvalue matching the modal branch {j + 1} at "
                    f"{v:.6g} m/s (modal {lam_r:.6g})",
                    float(v),
                    lam_r,
                )
            self.values[k, j] = lam
            self._vec[(k, j)] = x
        return complex(self.values[k, j])

    def _at_cluster(self, k: int, group: list[int]) -> None:
        """Verify a cluster of branches at grid point k as one invariant subspace: every full
        eigenvector found must lie mostly (:data:`CLUSTER_SHARE`) in the span of the cluster's
        modal eigenvectors."""
        v = float(self.br.speeds[k])
        lam_r = self.br.eigenvalues[k, group]
        X0 = self.modal.lift(self.br.vectors[k][:, group])
        lam, X = self._cluster_pairs(v, group, lam_r, X0, "has no eigenvalues matching")
        for i, g in enumerate(group):
            self.values[k, g] = lam[i]
            self._vec[(k, g)] = X[:, i]

    def _cluster_pairs(self, v: float, group: list[int], lam0, X0, failure: str) -> tuple:
        """The full-model eigenpairs of a cluster at speed v from ``(lam0, X0)``: every one
        converged, and every eigenvector mostly (:data:`CLUSTER_SHARE`) in the span of the
        starting ones; else :class:`VerificationError` ("the full model <failure> ...")."""
        lam, X, conv = self.tracker.correct_cluster(float(v), lam0, X0)
        n_q = self.tracker.n_q
        if not conv or subspace_share(X0[:n_q], X[:n_q]).min() < CLUSTER_SHARE:
            raise VerificationError(
                f"the full model {failure} the cluster of modal branches "
                f"{', '.join(str(i + 1) for i in group)} at {v:.6g} m/s (modal "
                f"{complex(lam0[0]):.6g} ...)",
                float(v),
                complex(lam0[0]),
            )
        return lam, X

    def vector(self, k: int, j: int) -> np.ndarray:
        """Full-model eigenvector of branch j at grid point k."""
        self.at(k, j)
        if (k, j) not in self._vec:  # the modal model is the full model
            self._vec[(k, j)] = self.modal.lift(self.br.vectors[k, :, j])
        return self._vec[(k, j)]

    def follow(self, j: int, k: int, v: float) -> complex:
        """Full-model eigenvalue of branch j at speed v, continued from grid point k (each
        ``(j, k, v)`` once: the crossing is re-read where the root finder ended)."""
        key = (j, k, float(v))
        if key not in self._followed:
            self._followed[key] = self._follow(j, k, v)
        return self._followed[key]

    def _follow(self, j: int, k: int, v: float) -> complex:
        V = self.br.speeds
        rows = [self.br.eigenvalues[kk] for kk in (k, k + 1) if kk < V.size]
        group = cluster(rows, j)
        lam_k = np.array([self.at(k, i) for i in group])
        guess = lam_k
        if k + 1 < V.size and np.isfinite(self.values[k + 1, group]).all():
            t = (v - V[k]) / (V[k + 1] - V[k])
            guess = lam_k + t * (self.values[k + 1, group] - lam_k)
        if len(group) == 1:
            return self.tracker.follow(v, complex(guess[0]), self.vector(k, j), float(V[k]))[0]
        X0 = np.column_stack([self.vector(k, i) for i in group])
        lam, _X = self._cluster_pairs(v, group, guess, X0, "cannot continue")
        for i, g in enumerate(group):
            self._followed.setdefault((g, k, float(v)), complex(lam[i]))
        return complex(lam[group.index(j)])

    def best(self, j: int | None = None) -> np.ndarray:
        """Branch j (default: every branch, as columns) on the grid: full-model values where
        computed, modal ones elsewhere."""
        if j is None:
            return np.where(self.exact, self.values, self.br.eigenvalues)
        values = self.values[:, j]
        return np.where(np.isfinite(values), values, self.br.eigenvalues[:, j])


def sign_changes(
    fun: Callable[[float, int], float],
    V: np.ndarray,
    g: np.ndarray,
    zeta: np.ndarray,
    rtol: float,
    first: int = 1,
) -> list[tuple[float, bool, int]]:
    """Roots in speed of a continuous stability measure known on a grid, humps included.

    Parameters
    ----------
    fun : callable
        ``fun(v, k)``: the measure (e.g. Re(lambda) [1/s]) at speed v inside grid interval k.
    V : ndarray
        Increasing grid speeds [m/s].
    g : ndarray
        The measure on the grid (negative: stable).
    zeta : ndarray
        Damping ratio on the grid; interior extrema with ``|zeta| < HUMP_ZETA`` that do not
        change sign on the grid are refined (a hump that crosses zero between grid points).
    rtol : float
        Relative tolerance on the roots.
    first : int
        Index of the first grid point used in the sign test (1 skips V = 0, where an undamped
        structure has Re = 0 exactly).

    Returns
    -------
    list of (speed, rising, k)
        Root [m/s], whether the measure goes from negative to positive, grid interval.
    """

    def root(k: int, a: float, b: float) -> float:
        return float(brentq(fun, a, b, args=(k,), xtol=rtol * b, rtol=1e-15))

    out = []
    neg = g < 0
    for k in (np.flatnonzero(neg[first:-1] != neg[first + 1 :]) + first).tolist():
        out.append((root(k, V[k], V[k + 1]), bool(neg[k]), k))
    # interior extrema of sgn * g below zero and near the axis: strictly above the left
    # neighbour, so that a flat top of two equal grid values (a hump symmetric about their
    # midpoint) is searched once, not twice
    near = np.abs(zeta) < HUMP_ZETA
    extrema = []
    for sgn in (1.0, -1.0):
        gk = sgn * g
        top = np.zeros(g.size, dtype=bool)
        top[1:-1] = (gk[1:-1] > gk[:-2]) & (gk[1:-1] >= gk[2:]) & (gk[1:-1] < 0) & near[1:-1]
        top[: first + 1] = False
        extrema += [(int(k), sgn) for k in np.flatnonzero(top)]
    for k, sgn in sorted(extrema, key=lambda e: (e[0], -e[1])):
        # search both grid intervals around the extreme, continuing from the left one
        from scipy.optimize import minimize_scalar  # only for a hump (rare)

        sol = minimize_scalar(
            lambda v, s=sgn, k=k: -s * fun(v, k - 1 if v < V[k] else k),
            bounds=(V[k - 1], V[k + 1]),
            method="bounded",
            options={"xatol": rtol * V[k + 1]},
        )
        if -sol.fun > 0:
            vpk = float(sol.x)
            kk = k - 1 if vpk < V[k] else k
            out.append((root(kk, V[kk], vpk), sgn > 0, kk))
            out.append((root(kk, vpk, V[kk + 1]), sgn < 0, kk))
    return sorted(out)


def _extrema(g: np.ndarray) -> np.ndarray:
    """Interior local maxima and minima of a grid function."""
    k = np.arange(1, g.size - 1)
    mx = (g[k] >= g[k - 1]) & (g[k] >= g[k + 1])
    mn = (g[k] <= g[k - 1]) & (g[k] <= g[k + 1])
    return k[mx | mn]


def _check_above_band(V, lam, above, zeta, trust: float, band_top: float) -> None:
    """Raise :class:`VerificationError` where a branch above the band nears the axis.

    A mode above the band is left undecided on the grounds that, alone, it keeps its
    aerodynamic damping (:func:`aeroservo.stability.certificate.truncated_modes`). Coupled
    with the modes in the band it may not: a branch whose damping ratio falls (after its low-
    speed rise) to within ``trust`` of the axis, or below it, must be decided, which the caller
    does by widening the band to it (a Goland wing with a store ahead of the axis: its 2nd
    bending, above the band, flutters 0.2 % above divergence).
    """
    k = np.flatnonzero(above)
    k = k[k >= 1]
    if k.size == 0:
        return
    z = zeta[k]
    falling = np.zeros(k.size, dtype=bool)
    falling[1:] = (z[1:] < z[:-1]) & (k[1:] == k[:-1] + 1)
    bad = (z < 0) | (falling & (z < trust))
    if bad.any():
        i = int(k[np.argmax(bad)])
        raise VerificationError(
            f"a mode above the band ({abs(lam[i].imag) / (2 * np.pi):.4g} Hz, band top "
            f"{band_top / (2 * np.pi):.4g} Hz) nears the axis at {V[i]:.4g} m/s (damping "
            f"ratio {zeta[i]:.2g})",
            float(V[i]),
            complex(lam[i]),
            above_band=True,
        )


def branch_crossings(
    ver: Verifier, j: int, rtol: float, error: float = 0.0, band_top: float = np.inf
) -> list[Crossing]:
    """Onsets and recoveries of branch j (full-model speeds and frequencies).

    Parameters
    ----------
    ver : Verifier
    j : int
        Branch.
    rtol : float
        Relative tolerance on the crossing speeds.
    error : float
        Measured error of the branch's modal eigenvalues relative to their modulus (the
        certificate's); signs are trusted where ``|zeta| > max(SIGN_ZETA, 10 error)``.
    band_top : float
        Top of the modal model's band [rad/s]: above it a branch is not decided here (the
        modes above the band are certified on their own, see
        :func:`aeroservo.stability.certificate.truncated_modes`).
    """
    br = ver.br
    V = br.speeds
    lam_r = br.eigenvalues[:, j]
    osc = is_complex(lam_r) & (np.abs(lam_r) <= band_top)
    zeta_r = -lam_r.real / np.maximum(np.abs(lam_r), 1e-300)
    trust = max(SIGN_ZETA, 10.0 * error)
    _check_above_band(V, lam_r, is_complex(lam_r) & ~osc, zeta_r, trust, band_top)
    todo = set(np.flatnonzero(osc & (np.abs(zeta_r) < trust)).tolist())
    for k in _extrema(lam_r.real):
        if osc[k - 1 : k + 2].all() and abs(zeta_r[k]) < HUMP_ZETA + trust:
            todo |= {int(k - 1), int(k), int(k + 1)}
    for k in sorted(todo):
        if k > 0:
            ver.at(int(k), j)
    out: list[Crossing] = []
    # runs of consecutive oscillatory grid points
    k = 0
    while k < V.size:
        if not osc[k]:
            k += 1
            continue
        a = k
        while k + 1 < V.size and osc[k + 1]:
            k += 1
        b = k
        k += 1
        if b - a < 1:
            continue
        idx = np.arange(a, b + 1)
        lam = ver.best(j)[idx]
        g = lam.real
        zeta = -g / np.maximum(np.abs(lam), 1e-300)

        def fun(v: float, kk: int, idx=idx) -> float:
            return float(ver.follow(j, int(idx[kk]), v).real)

        for v, rising, kk in sign_changes(fun, V[idx], g, zeta, rtol, first=1 if a == 0 else 0):
            lam_c = ver.follow(j, int(idx[kk]), v)
            kind = "onset" if rising else "recovery"
            out.append(Crossing(float(v), abs(lam_c.imag) / (2 * np.pi), j, kind))
    return out
