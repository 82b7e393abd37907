"""Bilinear forms of the first-order pencil, from the matrices without assembling the pencil.

For eigenvalue derivatives only ``y^H (dP(V) - lambda dE) x`` is needed, with ``dP`` and ``dE``
the pencil (:func:`aeroservo.system.first_order.pencil_blocks`, ``constant=False``) of a set of
matrix derivatives. The pencil is linear in those matrices, so the form is a sum of small
products over its blocks (the lag blocks are Kronecker products: ``Ez = E1 (x) 1``,
``Lam = Lz1 (x) diag(b_i beta^2)``, ``Dz = W1 (x) (c A_i b_i beta^2)``, ``Mz = Mz1 (x) I``).
Each parameter then costs a few sparse products instead of a pencil assembly;
``tests/test_sensitivity.py`` checks the forms against the assembled pencil.
"""

from __future__ import annotations

import numpy as np

from ..aero.indicial import IndicialSet
from .first_order import lag_factors
from .matrices import AeroMatrices

__all__ = ["pencil_form", "static_form"]


def _split(v: np.ndarray, n_q: int, n_n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return v[:n_q], v[n_q : 2 * n_q], v[2 * n_q :].reshape(n_n, -1)


def pencil_form(
    dam: AeroMatrices,
    wagner: IndicialSet,
    density: float,
    mach: float,
    y: np.ndarray,
    x: np.ndarray,
    speed: float,
    lam: complex,
) -> complex:
    """``y^H (dP(V) - lam dE) x`` for the pencil of ``dam`` without its constant blocks.

    Parameters
    ----------
    dam : AeroMatrices
        Matrices (typically derivatives of a model's matrices in one parameter).
    wagner : IndicialSet
    density : float
        Air density [kg/m^3].
    mach : float
        Mach number of the Prandtl-Glauert factors.
    y, x : ndarray (n_states,)
        Left and right vectors ``[q, v, z]`` (lag states node-major).
    speed : float
        V [m/s].
    lam : complex
        The eigenvalue [1/s].
    """
    rho, V = density, speed
    scale, bt, dz_row = lag_factors(wagner, mach)
    n_q, n_n = dam.n_q, dam.n_nodes
    xq, xv, xz = _split(x, n_q, n_n)
    yq, yv, yz = _split(y.conj(), n_q, n_n)
    ysum = yz.sum(axis=1)
    f = -(dam.Ks @ xq) - rho * V * V * (dam.Knc @ xq - scale * (dam.Pq @ xq))
    f = f - rho * V * (dam.Cnc @ xv - scale * (dam.Pd @ xv)) - lam * (dam.Ms @ xv)
    f = f - lam * rho * (dam.Mnc @ xv) + rho * V * V * (dam.W1 @ (xz @ dz_row))
    if dam.Cs is not None:
        f = f - dam.Cs @ xv
    out = yv @ f + ysum @ (dam.F1 @ xv) + V * (ysum @ (dam.E1 @ xq))
    out -= V * np.sum(yz * (dam.Lz1 @ xz) * bt[None, :]) + lam * np.sum(yz * (dam.Mz1 @ xz))
    return complex(out)


def static_form(
    dam: AeroMatrices,
    wagner: IndicialSet,
    mach: float,
    u: np.ndarray,
    q: np.ndarray,
    av: np.ndarray,
    bv: np.ndarray,
) -> float:
    """``u^T dK_static q`` of ``K_static = Ka - Dz Lam^-1 Ez`` for matrix derivatives ``dam``.

    ``av = Lam^-1 Ez q`` and ``bv = Lam^-T Dz^T u`` are of the model's own matrices, so
    ``d(Dz Lam^-1 Ez) = dDz av - bv dLam av + bv dEz q`` in the form.
    """
    scale, bt, dz_row = lag_factors(wagner, mach)
    n_n = dam.n_nodes
    a, b = av.reshape(n_n, -1), bv.reshape(n_n, -1)
    ka = u @ (dam.Knc @ q) - scale * (u @ (dam.Pq @ q))
    dz = u @ (dam.W1 @ (a @ dz_row))
    lam = np.sum(b * (dam.Lz1 @ a) * bt[None, :])
    ez = b.sum(axis=1) @ (dam.E1 @ q)
    return float(np.real(ka - dz + lam - ez))
