"""The degrees of freedom that per-DOF viscous damping acts on, by kind of unknown.

Per-DOF damping (:meth:`aeroservo.system.damping.StructuralDamping.per_dof`) gives one viscous
ratio to each kind of structural unknown: plunge or bending (``w``, ``theta``), pitch or
torsion (``phi``), flap or control rotation (``delta``). Its matrix is that of the **uncoupled**
structure: the inertial and elastic coupling between the kinds is removed, and each uncoupled
block ``(M_b, K_b)`` is given the modal damping of its own modes,

    C_b = M_b Phi_b diag(2 zeta_b omega_j) Phi_b^T M_b,

zero between blocks. On a typical section each block is one unknown and this is the damper of
its spring-mass oscillator, ``c_i = 2 zeta_i sqrt(k_i m_ii)``: the structural damping matrix of
the typical section with a flap of Conner, Tang, Dowell & Virgin (1997), J. Fluids Struct. 11,
89-109, as coded in the public ``samayala22/tinyvlm`` (``scripts/dof3.py``: ``D_s = 2 mu
diag(sigma zeta_h, r_alpha^2 zeta_alpha, (omega_beta / omega_alpha) r_beta^2 zeta_beta)``, with
``omega_h = sqrt(k_h / m)`` of the wing mass ``m``, not of the plunge inertia ``m_t``: hence
``plunge_mass``). On a beam the blocks are the uncoupled bending, torsion and control-rotation
motions of the whole wing, which converge with the mesh; a damper on each nodal unknown
(``2 zeta sqrt(k_ii m_ii)``) would not: its modal damping grows with the number of elements
(``k_ii m_ii`` of a Hermite element scales as ``1 / L^2``), and a slope unknown is not a motion
that is damped by itself.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..errors import InputError

__all__ = [
    "DOF_KINDS",
    "dof_kinds",
    "dof_blocks",
    "is_section",
    "modal_terms",
    "per_dof_derivatives",
    "GAP",
]

DOF_KINDS = ("plunge/bending", "pitch/torsion", "flap/control rotation")
"""The kinds of unknown a per-DOF ratio belongs to, in the order of ``dof_ratio``."""

_KIND = {"w": 0, "theta": 0, "phi": 1, "delta": 2}
"""The kind of a structural unknown from its label's prefix (``docs/conventions.md``)."""


def dof_kinds(labels) -> np.ndarray:
    """The kind (0 plunge/bending, 1 pitch/torsion, 2 flap/control) of each unknown, from its
    label (``"w"``, ``"w_3"``, ``"theta_3"``, ``"phi_3"``, ``"delta_aileron_7"``)."""
    out = []
    for lab in labels:
        head = str(lab).split("_", 1)[0]
        if head not in _KIND:
            raise InputError(
                f"damping.dof_ratio: the unknown {lab!r} is not a plunge/bending, pitch/torsion "
                "or flap/control unknown (per-DOF damping needs the full structural model)"
            )
        out.append(_KIND[head])
    return np.asarray(out, dtype=int)


def is_section(labels) -> bool:
    """True for a typical section's unknowns (``w``, ``phi``[, ``delta``])."""
    return tuple(labels) in (("w", "phi"), ("w", "phi", "delta"))


def dof_blocks(ratios, plunge_mass, M: np.ndarray, K: np.ndarray, labels):
    """The uncoupled blocks: ``[(index, M_b, K_b, zeta_b, kind, own)]``, one per kind present.

    ``ratios`` has one value (every kind) or one per kind; ``plunge_mass`` [kg/m] (a typical
    section only) replaces the plunge's own mass in its block, where ``own`` is False (that
    mass is a constant: it has no derivative in the structural parameters).
    """
    kinds = dof_kinds(labels)
    section = is_section(labels)
    if plunge_mass is not None and not section:
        raise InputError(
            f"damping.plunge_mass = {plunge_mass!r}: only for a typical section (the mass its "
            "plunge damper refers to); a wing's bending is damped on its own mass"
        )
    blocks = []
    for kind in np.unique(kinds):
        if kind >= len(ratios) and len(ratios) > 1:
            raise InputError(
                f"damping.dof_ratio = {list(ratios)}: the model has {DOF_KINDS[kind]} unknowns; "
                f"give {kind + 1} ratios (plunge/bending, pitch/torsion, flap/control)"
            )
        idx = np.flatnonzero(kinds == kind)
        zeta = ratios[0] if len(ratios) == 1 else ratios[kind]
        m_b = M[np.ix_(idx, idx)]
        own = True
        if kind == 0 and plunge_mass is not None:
            m_b, own = np.array([[float(plunge_mass)]]), False
        blocks.append((idx, m_b, K[np.ix_(idx, idx)], float(zeta), int(kind), own))
    return blocks


GAP = 1e-6
"""In-vacuo eigenvalues closer than this (relative) with different damping ratios: the modal
damping matrix has no derivative (which mode gets which ratio is undecided)."""


def dense(a) -> np.ndarray:
    """A sparse or dense matrix as an ndarray."""
    return a.toarray() if sp.issparse(a) else np.asarray(a)


def modal_terms(M: np.ndarray, K: np.ndarray, ratios_of):
    """``(core, M Phi, omega)`` of the modal damping ``M Phi diag(2 zeta_j omega_j) Phi^T M``
    with the ratios ``ratios_of(omega)``; ``core(dm, dk)`` is its derivative (dense)."""
    lam, phi = sla.eigh(K, M)
    lam = np.clip(lam, 0.0, None)
    s = np.sqrt(lam)
    zeta = ratios_of(s)
    f = 2.0 * zeta * s
    mp = M @ phi
    li, lj = lam[:, None], lam[None, :]
    si, sj = s[:, None], s[None, :]
    zi, zj = zeta[:, None], zeta[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        gap = lj - li
        d1 = (zj * sj - zi * si) * 2.0 / gap
        d2 = (zj * sj * lj - zi * si * li) * 2.0 / gap
        same = zi == zj  # the closed forms of the divided differences of 2 zeta sqrt(lambda)
        d1 = np.where(same, 2.0 * zi / (si + sj), d1)
        d2 = np.where(same, 2.0 * zi * (li + si * sj + lj) / (si + sj), d2)
    clash = ~same & (np.abs(gap) <= GAP * np.maximum(li, lj))
    np.fill_diagonal(d1, zeta / s)
    np.fill_diagonal(d2, 3.0 * zeta * s)

    def core(dm: np.ndarray, dk: np.ndarray) -> np.ndarray:
        if clash.any():
            i, j = np.argwhere(clash)[0]
            raise ValueError(
                f"in-vacuo modes {i + 1} and {j + 1} have the same frequency and different "
                "damping ratios: the modal damping matrix has no derivative"
            )
        g = (phi.T @ dk @ phi) * d1 - (phi.T @ dm @ phi) * d2
        outer = (dm @ phi * f) @ mp.T
        return outer + outer.T + mp @ g @ mp.T

    return core, mp, s


def per_dof_derivatives(ratios, plunge_mass, M: np.ndarray, K: np.ndarray, labels):
    """``(d_structure, d_own)`` of per-DOF damping (as
    :func:`aeroservo.system.damping.damping_derivatives`): the modal closed forms on each
    uncoupled block."""
    blocks = []
    for idx, m_b, k_b, zeta, kind, own in dof_blocks(ratios, plunge_mass, M, K, labels):
        core, mp, s = modal_terms(m_b, k_b, lambda w, z=zeta: np.full(w.size, z))
        blocks.append((np.ix_(idx, idx), kind, own, core, mp, s))

    def d_structure(dMs, dKs):
        dm, dk = dense(dMs), dense(dKs)
        out = np.zeros(M.shape)
        for ii, _, own, core, _, _ in blocks:
            out[ii] = core(dm[ii] if own else np.zeros_like(dk[ii]), dk[ii])
        return sp.csr_matrix(out)

    def d_own(name):
        i = 0 if name == "damping.dof_ratio" else int(name[len("damping.dof_ratio[") : -1])
        out = np.zeros(M.shape)
        for ii, kind, _, _, mp, s in blocks:
            if name == "damping.dof_ratio" or kind == i:
                out[ii] = (mp * (2.0 * s)) @ mp.T
        return sp.csr_matrix(out)

    return d_structure, d_own
