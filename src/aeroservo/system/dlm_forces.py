"""Doublet-lattice generalized aerodynamic forces (GAFs) of a wing model and their rational
approximation, per Mach number (``docs/dlm.md``).

**Modal.** As in Nastran's SOL 145/146 and ZAERO, the doublet-lattice model is written on the
in-vacuo modes: the lowest ``n_a`` mass-normalized modes ``Phi_a`` (the *aerodynamic basis*;
default as many as there are spanwise strips, at least 12: a lattice cannot resolve mode shapes
with more spanwise waves than it has strips, and motions it cannot see would have no
aerodynamic damping at all).

With the box rows of the beam spline (:mod:`aeroservo.system.beam_spline`) at the load points
``T_k`` and at the downwash points ``Z_j`` (displacement) and ``Zy_j`` (streamwise slope), the
normalwash angle of a harmonic motion ``eta e^{i omega t}`` is ``w / V = -(Zy_j + i (omega / V)
Z_j) Phi_a eta`` and the box loads ``q_dyn A dcp`` do the virtual work ``T_k^T``: the
generalized forces are ``q_dyn Q(ik) eta`` with

``Q(ik) = -R^T diag(A) Q_jj(k) (Zy_j + i (k / b_ref) Z_j) Phi_a``,  ``R = T_k [Phi_a, U]``,

on the modes and, in three more rows, on the wing's rigid-body motions ``U`` that move the
clamped root by a unit ``w, theta, phi``: the aerodynamic part of the root loads by force
summation (the sum of the box loads over the whole wing; the inertia part is ``U^T Ms``).

A vertical gust ``w_g`` (up) that reaches the most forward leading-edge point at t = 0 and
travels with the stream gives ``q_dyn Q_g(ik) w_g / V`` with
``Q_g(ik) = R^T diag(A) Q_jj(k) exp(-i (k / b_ref) (y_j - y_0))``: each box sees it when it
arrives, chordwise and spanwise (a swept wing's tip later).

The GAFs are fitted by a rational function in ``p = s b_ref / V`` (:mod:`aeroservo.aero.rfa`):
the modal columns by Roger's or the minimum-state form, with a dissipative apparent mass and
damping on the modes, the gust column by the lag-only form with :data:`GUST_LAG_FACTOR` times as
many roots (``1.7 k_max (j / (n + 1))^2``): the travel of the gust over a swept wing is a delay
that four roots fit to 9 % only (the illustrative swept Goland wing; 2.4 % with eight), and a
gust root costs one state.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline

from .._threads import blas_limited
from ..aero.dlm import DLM_MACH_WARN, aics, check_dlm_mach
from ..aero.dlm_settings import DoubletLattice
from ..aero.rfa import RationalFit, fit_lags, fit_minimum_state, fit_roger, lag_roots
from ..structure.mesh import Mesh
from ..structure.wing import Wing
from .beam_spline import spline_rows
from .panel_grid import PanelGrid, panel_grid

__all__ = [
    "DLMAerodynamics",
    "DLMFit",
    "RFA_WARN",
    "GUST_LAG_FACTOR",
    "fit_errors",
    "MIN_AERO_MODES",
]

RFA_WARN = 0.05
"""A fit error (:func:`fit_errors`) above this gets a warning."""

GUST_LAG_FACTOR = 2
"""The gust column's lag roots per lag root of the modal forces."""

MIN_AERO_MODES = 12
"""Fewest modes of the default aerodynamic basis (or every mode, if the model has fewer)."""


def fit_errors(exact: np.ndarray, fitted: np.ndarray) -> np.ndarray:
    """Largest error of each element over the frequencies, relative to the geometric mean of the
    largest diagonal values of its row and column, ``max_k |dQ_ij| / sqrt(max|Q_ii| max|Q_jj|)``,
    for a square (n_k, n, n) set of modal forces."""
    diag = np.abs(np.einsum("kii->ki", exact)).max(axis=0)
    scale = np.sqrt(np.outer(diag, diag))
    scale[scale == 0] = 1.0
    return np.abs(fitted - exact).max(axis=0) / scale


@dataclass
class DLMFit:
    """The rational approximation of a model's GAFs at one Mach number.

    Attributes
    ----------
    mach : float
    k : ndarray (n_k,)
        Tabulated reduced frequencies [-].
    forces : RationalFit
        Modal columns: rows ``n_a + 3`` (modes, root loads), columns ``n_a``.
    gust : RationalFit
        The gust column (lag-only form), rows ``n_a + 3``, one column.
    error : ndarray (n_a, n_a)
        Fit error of the modal forces (:func:`fit_errors`).
    gust_error : ndarray (n_a,)
        Largest error of each modal gust force over k, relative to its largest value (0 for
        forces below 1e-3 of the largest).
    warnings : list of str
    """

    mach: float
    k: np.ndarray
    forces: RationalFit
    gust: RationalFit
    error: np.ndarray
    gust_error: np.ndarray
    warnings: list = field(default_factory=list)

    def summary(self) -> dict:
        """The fit as plain values for reports."""
        return {
            "mach": self.mach,
            "rfa": self.forces.kind,
            "lag_roots": [float(g) for g in self.forces.roots],
            "gust_lag_roots": [float(g) for g in self.gust.roots],
            "k_max": float(self.k.max()),
            "n_k": int(self.k.size),
            "n_modes": int(self.error.shape[0]),
            "lag_states": self.forces.n_lag_states,
            "gust_lag_states": self.gust.n_lag_states,
            "max_error": float(self.error.max()) if self.error.size else 0.0,
            "max_gust_error": float(self.gust_error.max()) if self.gust_error.size else 0.0,
        }


class DLMAerodynamics:
    """The doublet-lattice aerodynamics of a wing model: boxes, splines, GAFs and their fits.

    Parameters
    ----------
    wing : Wing
    mesh : Mesh
    settings : DoubletLattice
    b_ref : float
        Reference semichord of the reduced frequency [m].
    modes : ndarray (n_q, n)
        Every in-vacuo mode, mass-normalized, by increasing frequency; the lowest ``n_a`` are
        the aerodynamic basis.
    rigid : ndarray (n_q + 3, 3)
        The rigid-body motions of the wing that move its root by a unit ``w, theta, phi``
        (:meth:`AeroelasticModel.rigid_motions`): the three root rows of the GAFs are the box
        loads' work on them, so that the root loads are the sum of the loads on the whole
        wing (force summation), not the modal model's elastic forces at the root, which miss
        the truncated modes' share (7 % of the root shear of a gust on a stiff Goland wing).
    """

    def __init__(
        self,
        wing: Wing,
        mesh: Mesh,
        settings: DoubletLattice,
        b_ref: float,
        modes: np.ndarray,
        rigid: np.ndarray,
    ):
        self.settings = settings
        self.b_ref = float(b_ref)
        self.grid: PanelGrid = panel_grid(wing, settings)
        lat = self.grid.lattice
        n_q = mesh.n_dofs
        n_strips = int(lat.strip.max()) + 1
        n_a = settings.modes if settings.modes is not None else max(MIN_AERO_MODES, n_strips)
        self.n_a = int(min(n_a, n_q))
        self.basis = modes[:, : self.n_a]
        seg, surf = self.grid.segment, self.grid.surface
        Tk = spline_rows(wing, mesh, lat.load_points, seg, surf)[0]
        Zj, Zjy = spline_rows(wing, mesh, lat.downwash_points, seg, surf)
        self.rigid = rigid
        self.rows = np.hstack([Tk[:, :n_q] @ self.basis, Tk @ rigid])  # (n_b, n_a + 3)
        self.Z_j = Zj[:, :n_q] @ self.basis
        self.Zy_j = Zjy[:, :n_q] @ self.basis
        self.area = lat.areas
        self.delay = lat.downwash_points[:, 1] - self.grid.reference_y  # [m] behind the front
        self._gafs: dict = {}
        self._fits: dict = {}
        self._splines: dict = {}

    @property
    def n_boxes(self) -> int:
        return self.grid.n_boxes

    @blas_limited
    def gafs(self, mach: float, progress=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """GAFs at the tabulated reduced frequencies, cached per Mach number.

        Returns
        -------
        k : ndarray (n_k,)
        Q : ndarray (n_k, n_a + 3, n_a) complex
            Per unit dynamic pressure [N m per unit modal coordinate, per Pa].
        Q_g : ndarray (n_k, n_a + 3) complex
            Gust forces per unit ``q_dyn w_g / V`` [per Pa].
        """
        mach = check_dlm_mach(mach)
        if mach not in self._gafs:
            k = self.settings.k_values
            kk = k / self.b_ref
            Qjj = aics(self.grid.lattice, mach, kk, kernel=self.settings.kernel, progress=progress)
            RA = self.rows.T * self.area[None, :]
            w = self.Zy_j[None] + 1j * kk[:, None, None] * self.Z_j[None]
            Q = -np.einsum("rb,kbc,kcq->krq", RA, Qjj, w, optimize=True)
            g = np.exp(-1j * kk[:, None] * self.delay[None, :])
            Qg = np.einsum("rb,kbc,kc->kr", RA, Qjj, g, optimize=True)
            self._gafs[mach] = (k, Q, Qg)
        return self._gafs[mach]

    @blas_limited
    def steady(self, mach: float) -> np.ndarray:
        """Steady modal forces ``Q(0)`` on the aerodynamic basis at a Mach number (vortex
        lattice only; cached with the AICs), (n_a, n_a) per unit dynamic pressure."""
        mach = check_dlm_mach(mach)
        if mach in self._gafs:
            k, Q, _ = self._gafs[mach]
            return Q[int(np.argmin(k)), : self.n_a].real
        Qjj = aics(self.grid.lattice, mach, np.zeros(1), kernel=self.settings.kernel)[0]
        RA = self.rows[:, : self.n_a].T * self.area[None, :]
        return -(RA @ Qjj @ self.Zy_j).real

    @blas_limited
    def fit(self, mach: float) -> DLMFit:
        """The rational approximation at a Mach number (cached)."""
        mach = check_dlm_mach(mach)
        if mach not in self._fits:
            k, Q, Qg = self.gafs(mach)
            s = self.settings
            roots = s.roots
            n = self.n_a
            if s.rfa == "roger":
                forces = fit_roger(k, Q, roots, dissipative=n)
            else:
                forces = fit_minimum_state(k, Q, roots, dissipative=n)
            gust_roots = lag_roots(float(k.max()), GUST_LAG_FACTOR * roots.size)
            gust = fit_lags(k, Qg[:, :, None], gust_roots)
            error = fit_errors(Q[:, :n], forces(k)[:, :n])
            ge, gf = Qg[:, :n], gust(k)[:, :n, 0]
            top = np.abs(ge).max(axis=0)
            gust_error = np.abs(gf - ge).max(axis=0) / np.where(top > 0, top, 1.0)
            gust_error[top < 1e-3 * max(top.max(), 1e-300)] = 0.0
            warnings = []
            if error.max() > RFA_WARN or gust_error.max() > RFA_WARN:
                warnings.append(
                    f"rational-function approximation at Mach {mach:g}: largest fit error "
                    f"{error.max():.3g} on the modal forces, {gust_error.max():.3g} on the "
                    f"gust forces (bound {RFA_WARN:g}); more lag roots or a narrower k range"
                )
            if mach >= DLM_MACH_WARN:
                warnings.append(
                    f"Mach {mach:g}: the doublet-lattice method is linear and subsonic; "
                    "transonic flow has shocks it does not have"
                )
            self._fits[mach] = DLMFit(mach, k, forces, gust, error, gust_error, warnings)
        return self._fits[mach]

    def exact(self, mach: float, k: np.ndarray, coords: np.ndarray) -> np.ndarray:
        """Modal GAFs ``C^T Q C`` at any reduced frequencies, ``coords`` C (n_a, m) giving the
        modes in the aerodynamic basis: the tabulated values' cubic spline inside the range, and
        beyond ``k_max`` the value at ``k_max`` plus the rational approximation's change.

        Returns ndarray (len(k), m, m) complex.
        """
        k_tab, Q, _ = self.gafs(mach)
        key = (mach, coords.shape, coords.tobytes())
        if key not in self._splines:
            n = self.n_a
            Qm = np.einsum("qi,kqr,rj->kij", coords, Q[:, :n], coords)
            self._splines[key] = CubicSpline(k_tab, Qm, axis=0)
        spline = self._splines[key]
        k = np.atleast_1d(np.asarray(k, dtype=float))
        k_max = k_tab[-1]
        out = spline(np.clip(k, 0.0, k_max))
        above = k > k_max
        if np.any(above):
            rfa = self.modal_fit(mach, coords)
            out[above] += rfa(k[above]) - rfa(np.full(int(above.sum()), k_max))
        return out

    def modal_fit(self, mach: float, coords: np.ndarray) -> RationalFit:
        """The fit of the modal forces on ``coords`` (n_a, m), both sides (root rows dropped)."""
        return self.fit(mach).forces.project(_rows(coords, 3), coords)

    def diagonal(self, mach: float, k: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Diagonal modal GAFs ``Q_jj`` of the aerodynamic-basis modes ``cols`` (each mode alone)
        at the reduced frequencies ``k[:, j]`` (as :meth:`exact`).

        Returns ndarray like ``k`` complex.
        """
        k_tab, Q, _ = self.gafs(mach)
        cols = np.asarray(cols, dtype=int)
        spline = CubicSpline(k_tab, Q[:, cols, cols], axis=0)
        k = np.asarray(k, dtype=float)
        k_max = k_tab[-1]
        idx = np.arange(cols.size)
        out = spline(np.clip(k, 0.0, k_max))[..., idx, idx]
        if np.any(k > k_max):
            fit = self.fit(mach).forces

            def rational(kk):
                p = 1j * kk
                r = fit.A0[cols, cols] + p * fit.A1[cols, cols] + p * p * fit.A2[cols, cols]
                if fit.B is not None:
                    for g, b in zip(fit.roots, fit.B, strict=True):
                        r = r + p / (p + g) * b[cols, cols]
                if fit.D is not None:
                    for a, g in enumerate(fit.roots):
                        r = r + p / (p + g) * fit.D[cols, a] * fit.E[a, cols]
                return r

            out = out + np.where(k > k_max, rational(k) - rational(np.full_like(k, k_max)), 0.0)
        return out


def _rows(coords: np.ndarray, extra: int) -> np.ndarray:
    """``coords`` with ``extra`` zero rows appended (the root-reaction rows of a fit)."""
    return np.vstack([coords, np.zeros((extra, coords.shape[1]))])
