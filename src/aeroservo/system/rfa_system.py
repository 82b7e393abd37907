"""The first-order system of a structure with rationally approximated aerodynamic forces.

With ``Q(p) ~ A0 + A1 p + A2 p^2 + lag terms`` (:mod:`aeroservo.aero.rfa`), ``p = s b / V`` and
``q_dyn = rho V^2 / 2``, the generalized aerodynamic force ``q_dyn Q(p) q`` is, in time,

``(rho/2) (V^2 A0 q + V b A1 qdot + b^2 A2 qddot) + (rho/2) V^2 (lag term)``

* Roger: one lag vector ``z_j`` per root, ``z_j' = qdot - (g_j V / b) z_j``, lag term
  ``sum_j B_j z_j``;
* minimum-state: the lag vector ``x_a`` of all roots, ``x_a' = (V / b) R x_a + E qdot``, lag
  term ``D x_a``.

So the model keeps the form ``E x' = (A0 + V A1 + V^2 A2) x`` of the strip model
(:mod:`aeroservo.system.first_order`) with state ``x = [q, qdot, z]`` and the mass
``M = Ms - (rho/2) b^2 A2``: its symmetric part is positive definite (the fit's apparent mass
is dissipative), but it is not symmetric in general. At rest the lag states follow the
displacements (``z = F q``, ``F`` stacked identities or ``E``), and the steady stiffness is
``Ks - (rho/2) V^2 A0``: ``K_static = -A0 / 2``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..aero.rfa import RationalFit
from ..errors import NumericalError
from .first_order import FirstOrderSystem

__all__ = ["rfa_blocks", "rfa_first_order"]


def rfa_blocks(fit: RationalFit, b: float) -> dict:
    """The lag blocks of a fit on n unknowns (square): ``F`` (lag states driven by ``qdot``),
    ``G`` (their decay rate per unit speed, [1/m]) and ``H`` (their load, per unit ``rho V^2 /
    2``), and the lag state names' stems."""
    n = fit.A0.shape[1]
    g = np.asarray(fit.roots, dtype=float)
    if fit.kind == "minimum-state":
        return {
            "F": np.asarray(fit.E),
            "G": np.diag(-g / b),
            "H": np.asarray(fit.D),
            "names": [f"a{j + 1}" for j in range(g.size)],
        }
    return {
        "F": np.tile(np.eye(n), (g.size, 1)),
        "G": np.kron(np.diag(-g / b), np.eye(n)),
        "H": np.hstack(list(fit.B)),
        "names": [f"r{j + 1}" for j in range(g.size)],
    }


def rfa_first_order(
    Ms: np.ndarray,
    Ks: np.ndarray,
    Cs: np.ndarray | None,
    fit: RationalFit,
    density: float,
    b: float,
    dof_labels: tuple[str, ...],
    *,
    semichord: float,
    mach: float,
) -> FirstOrderSystem:
    """Assemble ``E x' = (A0 + V A1 + V^2 A2) x`` (module notes).

    Parameters
    ----------
    Ms, Ks : ndarray (n, n)
        Structural mass and stiffness.
    Cs : ndarray (n, n) or None
        Structural damping.
    fit : RationalFit
        Of the free unknowns' forces, square (n, n).
    density : float
        [kg/m^3].
    b : float
        Reference semichord of the fit's reduced frequency [m].
    dof_labels : tuple of str
        Names of the unknowns.
    semichord : float
        Reference semichord stored on the system (default speed ranges) [m].
    mach : float
        Mach number of the fit.

    Raises
    ------
    ArithmeticError
        The fitted apparent mass makes the mass matrix indefinite.
    """
    rho = float(density)
    n = Ms.shape[0]
    half = 0.5 * rho
    blocks = rfa_blocks(fit, b)
    F, G, H = blocks["F"], blocks["G"], blocks["H"]
    n_z = F.shape[0]
    M = Ms - half * b * b * fit.A2
    if np.linalg.eigvalsh(0.5 * (M + M.T)).min() <= 0.0:
        raise NumericalError(
            f"the rational approximation's apparent mass makes the mass matrix indefinite at "
            f"{rho:g} kg/m^3: fit fewer lag roots or a narrower k range"
        )
    Z = np.zeros
    I = np.eye(n)
    C = -Cs if Cs is not None else Z((n, n))
    A0 = np.block(
        [[Z((n, n)), I, Z((n, n_z))], [-Ks, C, Z((n, n_z))], [Z((n_z, n)), F, Z((n_z, n_z))]]
    )
    A1 = np.block(
        [
            [Z((n, 2 * n + n_z))],
            [Z((n, n)), half * b * fit.A1, Z((n, n_z))],
            [Z((n_z, 2 * n)), G],
        ]
    )
    A2 = np.block(
        [[Z((n, 2 * n + n_z))], [half * fit.A0, Z((n, n)), half * H], [Z((n_z, 2 * n + n_z))]]
    )
    E = sp.block_diag([sp.eye(n), sp.csr_matrix(M), sp.eye(n_z)]).tocsr()
    stems = blocks["names"]
    if fit.kind == "minimum-state":
        lag_labels = tuple(stems)
    else:
        lag_labels = tuple(f"{st}_{lab}" for st in stems for lab in dof_labels)
    labels = tuple(dof_labels) + tuple(f"{lab}_dot" for lab in dof_labels) + lag_labels
    return FirstOrderSystem(
        E=E,
        A0=sp.csr_matrix(A0),
        A1=sp.csr_matrix(A1),
        A2=sp.csr_matrix(A2),
        n_q=n,
        state_labels=labels,
        density=rho,
        Ks=sp.csr_matrix(Ks),
        M=sp.csr_matrix(M),
        K_static=-0.5 * fit.A0,
        lag_at_rest=sp.csr_matrix(F),
        semichord=float(semichord),
        mach=float(mach),
        Cs=None if Cs is None else sp.csr_matrix(Cs),
    )
