"""First-order aeroelastic system ``E x' = (A0 + V A1 + V^2 A2) x`` from speed-independent matrices.

State ``x = [q, qdot, z]``: structural unknowns q, their rates, and the Wagner lag states z
(one per term and node, node-major). With ``M = Ms + rho Mnc``:

* ``qdot = v``
* ``M vdot = -(Ks + rho V^2 Ka) q - (Cs + rho V Ca) v + rho V^2 Dz z``
* ``Mz zdot = V Ez q + Fz v - V Lam z``

where ``Ca = Cnc - c (1 - sum A) Pd``, ``Ka = Knc - c (1 - sum A) Pq``,
``Dz = W1 (x) (c A_i b_i beta^2)``, ``Mz = Mz1 (x) I``, ``Lam = Lz1 (x) diag(b_i beta^2)``,
``Ez = E1 (x) 1``, ``Fz = F1 (x) 1``, and ``Cs`` the structural damping. The lag equations are
first order, so the mass matrix is never inverted as a whole: ``E`` is block-diagonal
``(I, M, Mz)`` and both blocks are positive definite.

**Compressibility (optional).** At a Mach number M the Prandtl-Glauert correction scales the
circulatory loads by ``c = 1 / beta``, ``beta = sqrt(1 - M^2)`` (lift slope ``2 pi / beta``)
and the lag rates by ``beta^2`` (the indicial functions run ``beta^2`` times slower in reduced
time): ``C(k) -> C(k / beta^2) / beta``. The apparent-mass terms are left incompressible. The
Mach number is a parameter of the system, like the density; a matched point (Mach = V / a at
the flutter speed) is found by iteration (:mod:`aeroservo.stability.matched`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..aero.indicial import IndicialSet
from ..errors import InputError, check_number
from .matrices import AeroMatrices

__all__ = [
    "FirstOrderSystem",
    "first_order",
    "pencil_blocks",
    "lag_factors",
    "check_mach",
    "MACH_LIMIT",
    "MACH_APPROXIMATE",
]


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
    mach : float
        Mach number of the compressibility correction (0: incompressible).
    Cs : sparse (n_q, n_q) or None
        Structural damping (None: undamped).


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
    mach: float = 0.0
    Cs: sp.csr_matrix | None = None
    _dense: tuple | None = field(default=None, repr=False)
    _pencil_dense: tuple | None = field(default=None, repr=False)

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

    def dense_pencil(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Dense ``(E, A0, A1, A2)``, computed once and cached."""
        if self._pencil_dense is None:
            self._pencil_dense = tuple(a.toarray() for a in (self.E, self.A0, self.A1, self.A2))
        return self._pencil_dense

    def state_matrix(self, speed: float) -> np.ndarray:
        """Dense state matrix ``A(V) = E^-1 (A0 + V A1 + V^2 A2)`` [1/s]."""
        a0, a1, a2 = self.state_matrix_terms()
        return a0 + speed * a1 + (speed * speed) * a2

    def modes_at_rest(self, n_modes: int) -> tuple[np.ndarray, np.ndarray]:
        """The ``n_modes`` lowest oscillatory eigenpairs at V = 0 (apparent mass included).

        With structural damping each undamped pair ``i omega`` is corrected to the damped root
        of ``(lam^2 M + lam Cs + Ks) q = 0`` by nonlinear Rayleigh-quotient iteration.

        Returns
        -------
        lam : ndarray (n_modes,) complex
            Eigenvalues [1/s] (``i omega`` without structural damping).
        X : ndarray (n_states, n_modes) complex
            State eigenvectors ``[q, lam q, z]``, unit norm.
        """
        n_modes = min(int(n_modes), self.n_q)
        K, M = self.Ks.toarray(), self.M.toarray()
        if _symmetric(M):
            w2, phi = sla.eigh(K, M, subset_by_index=[0, n_modes - 1])
        else:  # a fitted apparent mass (doublet lattice): K, M not both symmetric
            w2, phi = sla.eig(K, M)
            order = np.argsort(w2.real)[:n_modes]
            w2, phi = w2.real[order], phi[:, order].real
            phi = phi / np.linalg.norm(phi, axis=0)
        omega = np.sqrt(np.clip(w2, 0.0, None))
        lam = 1j * omega
        phi = phi.astype(complex)
        if self.Cs is not None:
            C = self.Cs.toarray()
            for j in range(n_modes):
                lam[j], phi[:, j] = _damped_pair(K, C, M, lam[j], phi[:, j])
        z = self.lag_at_rest @ phi
        X = np.vstack([phi, phi * lam[None, :], z]).astype(complex)
        X /= np.linalg.norm(X, axis=0)
        return lam, X


def _damped_pair(K, C, M, lam: complex, q: np.ndarray) -> tuple[complex, np.ndarray]:
    """Root of ``(lam^2 M + lam C + K) q = 0`` near ``(lam, q)`` (nonlinear Rayleigh quotient
    iteration: the scalar quadratic ``q^H T(lam) q = 0`` for lam, then ``T(lam)^-1 T'(lam) q``)."""
    for _ in range(20):
        m, c, k = (np.vdot(q, A @ q) for A in (M, C, K))
        roots = np.roots([m, c, k])
        new = complex(roots[np.argmin(np.abs(roots - lam))])
        if new.imag < 0:
            new = new.conjugate()
        done = abs(new - lam) <= 1e-13 * abs(new)
        lam = new
        if done:
            break
        T = lam * lam * M + lam * C + K
        try:
            y = np.linalg.solve(T, (2 * lam * M + C) @ q)
        except np.linalg.LinAlgError:  # lam is an eigenvalue to rounding: its null vector
            q = sla.svd(T)[2][-1].conj()
            break
        q = y / np.linalg.norm(y)
    return lam, q


def _symmetric(a: np.ndarray) -> bool:
    return bool(np.array_equal(a, a.T))


def _block_inverse(E: sp.csr_matrix, n_q: int) -> np.ndarray:
    """Dense inverse of ``blkdiag(I, M, Mz)``: Cholesky factors of the SPD blocks (an LU
    factorization for a block that is not symmetric: a fitted apparent mass)."""
    n = E.shape[0]
    out = np.zeros((n, n))
    out[:n_q, :n_q] = np.eye(n_q)
    for lo, hi in ((n_q, 2 * n_q), (2 * n_q, n)):
        if hi > lo:
            blk = E[lo:hi, lo:hi].toarray()
            if _symmetric(blk):
                out[lo:hi, lo:hi] = sla.cho_solve(sla.cho_factor(blk), np.eye(hi - lo))
            else:
                out[lo:hi, lo:hi] = sla.lu_solve(sla.lu_factor(blk), np.eye(hi - lo))
    return out


MACH_LIMIT = 0.9
"""The Prandtl-Glauert correction is refused at and above this Mach number (transonic flow)."""

MACH_APPROXIMATE = 0.7
"""Above this Mach number results with the correction are flagged as approximate."""


def mach_note(what: str, speed: float, speed_of_sound: float, assumed: bool = False) -> str | None:
    """The warning for a speed [m/s] whose Mach number exceeds :data:`MACH_APPROXIMATE` with
    incompressible aerodynamics, or None.

    Parameters
    ----------
    what : str
        What is at that speed (``"flutter"``, ``"the model"``).
    speed, speed_of_sound : float
        [m/s].
    assumed : bool
        Whether the speed of sound is the standard atmosphere's at the density (no altitude
        given).
    """
    m = speed / speed_of_sound
    if m <= MACH_APPROXIMATE:
        return None
    where = f" (speed of sound {speed_of_sound:.4g} m/s, standard atmosphere at this density)"
    text = f"{what} at Mach {m:.3f}{where if assumed else ''} with incompressible aerodynamics: "
    if m >= MACH_LIMIT:
        return text + "the strip theory does not apply in transonic or supersonic flow"
    return text + (
        f"use the Prandtl-Glauert correction (compressibility), valid to Mach {MACH_LIMIT:g}"
    )


def check_mach(mach: object, field: str = "mach") -> float:
    """Validate the Mach number of the compressibility correction, ``0 <= M < 0.9``."""
    m = check_number(field, mach, lo=0.0)
    if m >= MACH_LIMIT:
        raise InputError(
            f"{field} = {m:g}: the Prandtl-Glauert correction is refused at Mach >= "
            f"{MACH_LIMIT:g} (transonic flow: shocks, not a linear correction)"
        )
    return m


def compressibility_factors(mach: float) -> tuple[float, float]:
    """``(1 / beta, beta^2)`` of the Prandtl-Glauert correction at a Mach number < 1 (a complex
    Mach number, a complex step, gives complex factors)."""
    m = mach if isinstance(mach, complex) else float(mach)
    beta2 = 1.0 - m**2
    return 1.0 / np.sqrt(beta2), beta2


def lag_factors(wagner: IndicialSet, mach: float) -> tuple[float, np.ndarray, np.ndarray]:
    """Scalars of the circulatory terms at a Mach number: ``c (1 - sum A)`` (the factor of
    ``Pq``, ``Pd`` in ``Ka``, ``Ca``), the lag rates ``b_i beta^2`` and the row
    ``c A_i b_i beta^2`` of ``Dz``."""
    A = np.asarray(wagner.A)
    c, beta2 = compressibility_factors(mach)
    bt = np.asarray(wagner.b) * beta2
    return c * (1.0 - A.sum()), bt, c * A * bt


def pencil_blocks(
    am: AeroMatrices,
    wagner: IndicialSet,
    density: float,
    mach: float = 0.0,
    *,
    constant: bool = True,
) -> dict[str, sp.csr_matrix]:
    """The pencil ``E, A0, A1, A2`` of the module notes and its lag blocks.

    Every block is linear in the matrices of ``am``, so the same function gives the pencil's
    derivative from the matrices' derivatives, with ``constant=False`` (the identity blocks of
    ``qdot = v`` left out).

    Returns
    -------
    dict
        ``E, A0, A1, A2`` (sparse, n x n) and ``M, Ka, Dz, Lam, Ez, Fz, Mz`` of the notes.
    """
    rho = density
    n_q, n_n = am.n_q, am.n_nodes
    scale, bt, dz_row = lag_factors(wagner, mach)
    T = bt.size
    one_col = sp.csr_matrix(np.ones((T, 1)))

    M = (am.Ms + rho * am.Mnc).tocsr()
    Ca = am.Cnc - scale * am.Pd
    Ka = am.Knc - scale * am.Pq
    Mz = sp.kron(am.Mz1, sp.eye(T)).tocsr()
    Lam = sp.kron(am.Lz1, sp.diags(bt)).tocsr()
    Ez = sp.kron(am.E1, one_col).tocsr()
    Fz = sp.kron(am.F1, one_col).tocsr()
    Dz = sp.kron(am.W1, sp.csr_matrix(dz_row[None, :])).tocsr()
    n_z = n_n * T

    I = sp.eye(n_q) if constant else sp.csr_matrix((n_q, n_q))
    Zqq = None
    Cs = -am.Cs if am.Cs is not None else None
    A0 = sp.bmat([[Zqq, I, None], [-am.Ks, Cs, None], [None, Fz, sp.csr_matrix((n_z, n_z))]])
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
    return {
        "E": E,
        "A0": A0.tocsr(),
        "A1": A1.tocsr(),
        "A2": A2.tocsr(),
        "M": M,
        "Ka": Ka,
        "Dz": Dz,
        "Lam": Lam,
        "Ez": Ez,
        "Fz": Fz,
        "Mz": Mz,
    }


def first_order(
    am: AeroMatrices,
    wagner: IndicialSet,
    density: float,
    semichord: float = 1.0,
    *,
    mach: float = 0.0,
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
    mach : float
        Mach number of the Prandtl-Glauert correction (0: incompressible), ``0 <= M < 1``.

    Returns
    -------
    FirstOrderSystem
    """
    rho = float(density)
    blocks = pencil_blocks(am, wagner, rho, mach)
    Ka, Dz, Lam, Ez = (blocks[k] for k in ("Ka", "Dz", "Lam", "Ez"))
    T = np.asarray(wagner.A).size

    lam_dense = Lam.toarray()
    K_static = Ka.toarray() - Dz.toarray() @ np.linalg.solve(lam_dense, Ez.toarray())
    mz_dense = blocks["Mz"].toarray()
    lag_at_rest = sp.csr_matrix(np.linalg.solve(mz_dense, blocks["Fz"].toarray()))

    labels = (
        tuple(am.dof_labels)
        + tuple(f"{lab}_dot" for lab in am.dof_labels)
        + tuple(f"z{t + 1}_{node}" for node in am.lag_labels for t in range(T))
    )
    return FirstOrderSystem(
        E=blocks["E"],
        A0=blocks["A0"],
        A1=blocks["A1"],
        A2=blocks["A2"],
        n_q=am.n_q,
        state_labels=labels,
        density=rho,
        Ks=am.Ks.tocsr(),
        M=blocks["M"],
        K_static=K_static,
        lag_at_rest=lag_at_rest,
        semichord=float(semichord),
        mach=float(mach),
        Cs=am.Cs,
    )
