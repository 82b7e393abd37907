"""The frozen-aerodynamics eigenproblem of the p-k method (:mod:`aeroservo.stability.pk`).

At a speed V and a trial frequency w the aerodynamic forces are those of harmonic motion at w,
split into a real stiffness and a real damping, and the quadratic eigenproblem
``(M p^2 + C(w) p + K(w)) q = 0`` is solved by Newton's method; the p-k iteration repeats this
until ``Im p = w``. Two sources of the forces: strip theory with the exact Theodorsen function
(:class:`_PK`) and the doublet lattice's generalized aerodynamic forces interpolated over the
reduced frequency (:class:`_PKDLM`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from ..aero.dlm import check_dlm_mach
from ..aero.theodorsen import theodorsen_function
from ..system.first_order import compressibility_factors
from ..system.matrices import AeroMatrices
from .divergence import static_speeds
from .tracking import mac

__all__ = ["PKConvergenceError"]


@dataclass
class _PK:
    M: np.ndarray
    Ks: np.ndarray
    Knc: np.ndarray
    Cnc: np.ndarray
    groups: list
    rho: float
    Cs: np.ndarray | None = None
    cf: float = 1.0
    beta2: float = 1.0

    def frozen(self, V: float, w: float) -> tuple[np.ndarray, np.ndarray]:
        """Stiffness and damping with the aerodynamics frozen at frequency ``w`` [rad/s]."""
        rho = self.rho
        K = self.Ks + rho * V * V * self.Knc
        C = rho * V * self.Cnc
        if self.Cs is not None:
            C = C + self.Cs
        if V > 0:
            w_eff = max(w, 1e-9)
            for b, Pq, Pd in self.groups:
                c = theodorsen_function(max(w_eff * b / (V * self.beta2), 1e-9)) * self.cf
                F, G = c.real, c.imag
                K = K + rho * (-V * V * F * Pq + w_eff * V * G * Pd)
                C = C + rho * (-V * F * Pd - (V * V * G / w_eff) * Pq)
        return K, C

    def newton(
        self, K: np.ndarray, C: np.ndarray, p: complex, q: np.ndarray
    ) -> tuple[complex, np.ndarray]:
        """Eigenpair of ``(M p^2 + C p + K) q = 0`` nearest to ``(p, q)`` by Newton's method."""
        M = self.M
        n = M.shape[0]
        c = q / np.vdot(q, q)
        J = np.zeros((n + 1, n + 1), dtype=complex)
        J[n, :n] = np.conj(c)
        for _ in range(30):
            T = M * (p * p) + C * p + K
            r = T @ q
            scale = (
                np.linalg.norm(K @ q)
                + abs(p) * np.linalg.norm(C @ q)
                + abs(p) ** 2 * np.linalg.norm(M @ q)
            )
            if np.linalg.norm(r) <= 1e-12 * scale:
                return p, q
            J[:n, :n] = T
            J[:n, n] = (2.0 * p * M + C) @ q
            step = np.linalg.solve(J, np.r_[-r, 1.0 - np.vdot(c, q)])
            q = q + step[:n]
            p = p + step[n]
            if abs(step[n]) <= 1e-12 * abs(p) and np.linalg.norm(r) <= 1e-8 * scale:
                return p, q  # converged to round-off
        raise PKConvergenceError("Newton iteration on the frozen p-k problem did not converge")

    def converge(self, V: float, p0: complex, q0: np.ndarray) -> tuple[complex, np.ndarray]:
        """p-k iteration for the branch continuing (p0, q0) at speed V.

        Fixed-point iteration on omega = Im p(omega), switching to the secant method on
        f(omega) = Im p(omega) - omega when the fixed point is slow or oscillates (heavily
        damped branches).

        Raises
        ------
        PKConvergenceError
        """
        w = abs(p0.imag)
        p, q = complex(p0.real, w), q0.astype(complex)
        hist: list[tuple[float, float]] = []
        for it in range(60):
            K, C = self.frozen(V, w)
            p, q = self.newton(K, C, p, q)
            if p.imag < 0:
                p, q = np.conj(p), np.conj(q)
            f = p.imag - w
            if abs(f) <= 1e-9 * max(w, 1e-9):
                if mac(q0[:, None], q[:, None])[0] < 0.5:
                    raise PKConvergenceError(f"p-k branch lost its shape at V = {V:.6g} m/s")
                return p, q / np.linalg.norm(q)
            hist.append((w, f))
            if it >= 4 and hist[-1][1] != hist[-2][1]:
                (w1, f1), (w2, f2) = hist[-2], hist[-1]
                w_new = w2 - f2 * (w2 - w1) / (f2 - f1)
                w = w_new if w_new > 0 else 0.5 * w2
            else:
                w = p.imag
        raise PKConvergenceError(f"p-k iteration did not converge at V = {V:.6g} m/s")


class PKConvergenceError(RuntimeError):
    """The p-k iteration found no consistent frequency for a branch."""


def _setup(am: AeroMatrices, rho: float, mach: float = 0.0) -> tuple[_PK, np.ndarray]:
    """p-k matrices in the complete basis of in-vacuo modes (an exact change of variables that
    makes the stiffness diagonal and keeps round-off relative to each mode's own scale)."""
    _, phi = sla.eigh(am.Ks.toarray(), am.Ms.toarray())
    cf, beta2 = compressibility_factors(mach)

    def modal(a):
        return phi.T @ (a.toarray() @ phi)

    pk = _PK(
        M=modal(am.Ms) + rho * modal(am.Mnc),
        Ks=modal(am.Ks),
        Knc=modal(am.Knc),
        Cnc=modal(am.Cnc),
        groups=[(g.b, modal(g.Pq), modal(g.Pd)) for g in am.circ_groups],
        rho=rho,
        Cs=None if am.Cs is None else modal(am.Cs),
        cf=cf,
        beta2=beta2,
    )
    return pk, phi


def _reference_semichord(model) -> float:
    """The model's reference semichord [m] (the mean of its strip groups for a bare section)."""
    b = getattr(model, "semichord", None)
    if b is not None:
        return float(b)
    return float(np.mean([g.b for g in model.matrices.circ_groups]))


class _PKDLM(_PK):
    """The p-k problem with the doublet-lattice GAFs (interpolated over k) on the modes of a
    doublet-lattice model's aerodynamic basis: ``K(w) = Ks - q Re Q(ik)``, ``C(w) = Cs - q Im
    Q(ik) / w`` at ``k = w b / V``."""

    def __init__(self, model, rho: float, mach: float, **kw):
        super().__init__(Knc=None, Cnc=None, groups=[], rho=rho, **kw)
        self.model = model
        self.mach = mach
        self.coords = np.eye(model.dlm.n_a)

    def frozen(self, V: float, w: float) -> tuple[np.ndarray, np.ndarray]:
        K = self.Ks
        C = np.zeros_like(K) if self.Cs is None else self.Cs
        if V > 0:
            w_eff = max(w, 1e-9)
            dlm = self.model.dlm
            Q = dlm.exact(self.mach, [w_eff * dlm.b_ref / V], self.coords)[0]
            q = 0.5 * self.rho * V * V
            K = K - q * Q.real
            C = C - (q / w_eff) * Q.imag
        return K, C


def _setup_dlm(model, rho: float, mach: float) -> tuple:
    """The p-k problem of a doublet-lattice model (modal: the basis is its aerodynamic basis),
    and its exact steady divergence speeds (from ``Q(0)``)."""
    mach = check_dlm_mach(mach)
    dlm = model.dlm
    am = model.matrices
    phi = dlm.basis

    def both(a):
        return phi.T @ (a.toarray() @ phi)

    Ks = both(am.Ks)
    pk = _PKDLM(model, rho, mach, M=both(am.Ms), Ks=Ks, Cs=None if am.Cs is None else both(am.Cs))
    k, Q, _ = dlm.gafs(mach)
    q0 = Q[int(np.argmin(k)), : dlm.n_a].real
    return pk, phi, static_speeds(Ks, -0.5 * q0, rho)
