"""First-order aeroelastic system ``E x' = (A0 + V A1 + V^2 A2) x`` from speed-independent matrices.

State ``x = [q, qdot, z]``: structural unknowns q, their rates, and the Wagner lag states z
(one per term and node, node-major). With ``M = Ms + rho Mnc``:

* ``qdot = v``
* ``M vdot = -(Ks + rho V^2 Ka) q - rho V Ca v + rho V^2 Dz z``
* ``Mz zdot = V Ez q + Fz v - V Lam z``

where ``Ca = Cnc - (1 - sum A) Pd``, ``Ka = Knc - (1 - sum A) Pq``, ``Dz = W1 (x) (A_i b_i)``,
``Mz = Mz1 (x) I``, ``Lam = Lz1 (x) diag(b_i)``, ``Ez = E1 (x) 1``, ``Fz = F1 (x) 1``. The lag
equations are first order, so the mass matrix is never inverted as a whole: ``E`` is
block-diagonal ``(I, M, Mz)`` and both blocks are positive definite.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..aero.indicial import IndicialSet
from .matrices import AeroMatrices

__all__ = ["FirstOrderSystem", "first_order"]


@dataclass
class FirstOrderSystem:
    """Descriptor system ``E x' = (A0 + V A1 + V^2 A2) x`` at one air density.

    Attributes
    ----------
    E, A0, A1, A2 : sparse (n, n)
        Speed-independent pencil matrices.
    n_q : int
        Structural unknowns; ``x[:n_q]`` are displacements, ``x[n_q:2 n_q]`` rates.
    state_labels : tuple of str
    density : float
        Air density [kg/m^3].
    Ks, M : sparse (n_q, n_q)
        Structural stiffness and total (structural + apparent) mass.
    K_static : ndarray (n_q, n_q)
        Steady aerodynamic stiffness per unit (rho V^2), lag states eliminated: divergence
        where ``Ks + rho V^2 K_static`` is singular.
    lag_at_rest : sparse (n_z, n_q)
        Lag states of a mode at V = 0: z = lag_at_rest @ q.
    semichord : float
        Reference semichord [m] (mean over the span), used for default speed ranges.
    """

    E: sp.csr_matrix
    A0: sp.csr_matrix
    A1: sp.csr_matrix
    A2: sp.csr_matrix
    n_q: int
    state_labels: tuple[str, ...]
    density: float
    Ks: sp.csr_matrix
    M: sp.csr_matrix
    K_static: np.ndarray
    lag_at_rest: sp.csr_matrix
    semichord: float = 1.0
    _dense: tuple | None = field(default=None, repr=False)

    @property
    def n_states(self) -> int:
        return self.E.shape[0]

    def pencil(self, speed: float) -> sp.csr_matrix:
        """Right-hand side ``A0 + V A1 + V^2 A2`` (sparse) at ``speed`` [m/s]."""
        return self.A0 + speed * self.A1 + (speed * speed) * self.A2

    def d_pencil(self, speed: float) -> sp.csr_matrix:
        """Derivative of the pencil with respect to speed [1/m]."""
        return self.A1 + (2.0 * speed) * self.A2

    def state_matrix_terms(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Dense ``(E^-1 A0, E^-1 A1, E^-1 A2)``, computed once and cached."""
        if self._dense is None:
            n_q = self.n_q
            einv = _block_inverse(self.E, n_q)
            self._dense = tuple(einv @ a.toarray() for a in (self.A0, self.A1, self.A2))
        return self._dense

    def state_matrix(self, speed: float) -> np.ndarray:
        """Dense state matrix ``A(V) = E^-1 (A0 + V A1 + V^2 A2)`` [1/s]."""
        a0, a1, a2 = self.state_matrix_terms()
        return a0 + speed * a1 + (speed * speed) * a2

    def modes_at_rest(self, n_modes: int) -> tuple[np.ndarray, np.ndarray]:
        """The ``n_modes`` lowest oscillatory eigenpairs at V = 0 (apparent mass included).

        Returns
        -------
        lam : ndarray (n_modes,) complex
            Eigenvalues i omega [1/s].
        X : ndarray (n_states, n_modes) complex
            State eigenvectors ``[q, i omega q, z]``, unit norm.
        """
        n_modes = min(int(n_modes), self.n_q)
        w2, phi = sla.eigh(self.Ks.toarray(), self.M.toarray(), subset_by_index=[0, n_modes - 1])
        omega = np.sqrt(np.clip(w2, 0.0, None))
        lam = 1j * omega
        z = self.lag_at_rest @ phi
        X = np.vstack([phi, phi * lam[None, :], z]).astype(complex)
        X /= np.linalg.norm(X, axis=0)
        return lam, X


def _block_inverse(E: sp.csr_matrix, n_q: int) -> np.ndarray:
    """Dense inverse of ``blkdiag(I, M, Mz)`` using Cholesky factors of the SPD blocks."""
    n = E.shape[0]
    out = np.zeros((n, n))
    out[:n_q, :n_q] = np.eye(n_q)
    for lo, hi in ((n_q, 2 * n_q), (2 * n_q, n)):
        if hi > lo:
            blk = E[lo:hi, lo:hi].toarray()
            out[lo:hi, lo:hi] = sla.cho_solve(sla.cho_factor(blk), np.eye(hi - lo))
    return out


def first_order(
    am: AeroMatrices, wagner: IndicialSet, density: float, semichord: float = 1.0
) -> FirstOrderSystem:
    """Assemble the first-order system of ``am`` with a Wagner set at air density ``density``.

    Parameters
    ----------
    am : AeroMatrices
    wagner : IndicialSet
        Wagner approximation; one lag state per term and node.
    density : float
        Air density [kg/m^3].
    semichord : float
        Reference semichord [m] stored on the result.

    Returns
    -------
    FirstOrderSystem
    """
    rho = float(density)
    n_q, n_n = am.n_q, am.n_nodes
    A = np.asarray(wagner.A)
    bt = np.asarray(wagner.b)
    T = A.size
    one_col = sp.csr_matrix(np.ones((T, 1)))
    scale = 1.0 - A.sum()

    M = (am.Ms + rho * am.Mnc).tocsr()
    Ca = am.Cnc - scale * am.Pd
    Ka = am.Knc - scale * am.Pq
    Mz = sp.kron(am.Mz1, sp.eye(T)).tocsr()
    Lam = sp.kron(am.Lz1, sp.diags(bt)).tocsr()
    Ez = sp.kron(am.E1, one_col).tocsr()
    Fz = sp.kron(am.F1, one_col).tocsr()
    Dz = sp.kron(am.W1, sp.csr_matrix((A * bt)[None, :])).tocsr()
    n_z = n_n * T

    I = sp.eye(n_q)
    Zqq = None
    A0 = sp.bmat([[Zqq, I, None], [-am.Ks, None, None], [None, Fz, sp.csr_matrix((n_z, n_z))]])
    A1 = sp.bmat(
        [[sp.csr_matrix((n_q, n_q)), None, None], [None, -rho * Ca, None], [Ez, None, -Lam]]
    )
    A2 = sp.bmat(
        [
            [sp.csr_matrix((n_q, n_q)), None, None],
            [-rho * Ka, sp.csr_matrix((n_q, n_q)), rho * Dz],
            [None, None, sp.csr_matrix((n_z, n_z))],
        ]
    )
    E = sp.block_diag([I, M, Mz]).tocsr()

    lam_dense = Lam.toarray()
    K_static = Ka.toarray() - Dz.toarray() @ np.linalg.solve(lam_dense, Ez.toarray())
    mz_dense = Mz.toarray()
    lag_at_rest = sp.csr_matrix(np.linalg.solve(mz_dense, Fz.toarray()))

    labels = (
        tuple(am.dof_labels)
        + tuple(f"{lab}_dot" for lab in am.dof_labels)
        + tuple(f"z{t + 1}_{node}" for node in am.lag_labels for t in range(T))
    )
    return FirstOrderSystem(
        E=E,
        A0=A0.tocsr(),
        A1=A1.tocsr(),
        A2=A2.tocsr(),
        n_q=n_q,
        state_labels=labels,
        density=rho,
        Ks=am.Ks.tocsr(),
        M=M,
        K_static=K_static,
        lag_at_rest=lag_at_rest,
        semichord=float(semichord),
    )
