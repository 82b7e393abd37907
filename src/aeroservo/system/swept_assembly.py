"""The per-element aerodynamic coefficients the assembly integrates, swept or not.

An unswept wing gets Theodorsen's section coefficients unchanged (the same arrays, so its
matrices are bit for bit those of a wing without the sweep feature); a wing with a swept segment
gets those of the modified strip theory (:mod:`aeroservo.aero.swept_strip`), built once: the
speeds only scale the matrices, as for every other term (``docs/sweep.md``).
"""

from __future__ import annotations

import numpy as np

from ..aero.swept_strip import check_sweep_terms, swept_coefficients
from ..aero.theodorsen import SectionAero
from ..structure.mesh import Mesh
from ..structure.wing import Wing

__all__ = [
    "element_sweep",
    "gradient_shapes",
    "kink_transforms",
    "strip_coefficients",
    "to_nodal",
]


def element_sweep(wing: Wing, mesh: Mesh) -> np.ndarray:
    """Sweep angle of the elastic axis on each element [rad] (+ backward)."""
    return np.array([float(wing.segments[i].sweep) for i in mesh.segment])


def kink_transforms(wing: Wing, mesh: Mesh) -> np.ndarray | None:
    """Maps from the nodal unknowns to each element's own (n_el, 8, 8), or None on a wing
    whose elastic axis has no kink (every element's unknowns are then the nodal ones).

    The bending slope ``theta`` and the twist ``phi`` are rotations about the in-plane normal
    to the elastic axis and about the axis itself; a node takes the axes of the element inboard
    of it. Where the sweep changes by ``D`` (a crank), the same rotation vector has, in the
    outboard element's axes, ``theta' = cos D theta - sin D phi`` and
    ``phi' = sin D theta + cos D phi``: the crank couples bending and torsion.
    """
    sweep = element_sweep(wing, mesh)
    turn = np.zeros_like(sweep)
    turn[1:] = sweep[1:] - sweep[:-1]  # change of sweep at each element's inboard node
    if not np.any(turn):
        return None
    t = np.tile(np.eye(8), (sweep.size, 1, 1))
    c, s = np.cos(turn), np.sin(turn)
    t[:, 1, 1], t[:, 1, 4], t[:, 4, 1], t[:, 4, 4] = c, -s, s, c  # local theta_i, phi_i
    return t


def to_nodal(blocks: np.ndarray, t: np.ndarray | None, rows: bool, cols: bool) -> np.ndarray:
    """Element blocks (n_el, p, q) in element unknowns turned to nodal ones (``t`` from
    :func:`kink_transforms`; rows and/or columns that are structural unknowns)."""
    if t is None:
        return blocks
    if rows:
        blocks = np.einsum("eji,ejk->eik", t, blocks)
    if cols:
        blocks = blocks @ t
    return blocks


def gradient_shapes(N: np.ndarray, D: np.ndarray, S: np.ndarray) -> np.ndarray:
    """Shape matrices of the spanwise gradients ``[w', phi', delta']`` (n_el, n_g, 3, 8) from
    those of :func:`aeroservo.structure.beam_element.field_shapes`."""
    out = np.zeros_like(N)
    out[..., 0, :] = S
    out[..., 1:, :] = D[..., 1:, :]
    return out


def strip_coefficients(
    wing: Wing,
    mesh: Mesh,
    aero: SectionAero | dict,
    b: np.ndarray,
    sweep_terms: str = "full",
) -> dict:
    """Coefficients of the aerodynamic element integrals.

    Parameters
    ----------
    wing, mesh : Wing, Mesh
    aero : SectionAero or dict
        Theodorsen's section coefficients per element (a dict with the keys below: complex-step
        derivatives).
    b : ndarray (n_el,)
        Semichord per element [m].
    sweep_terms : {"full", "classical"}
        Spanwise-convection terms of a swept wing (:data:`aeroservo.aero.swept_strip.SWEEP_TERMS`).

    Returns
    -------
    dict
        ``Mnc, Cnc, Knc, Pq, Pd, w, r_q, r_d, b, inv_b`` (the semichord ``b`` is that of the
        reduced frequency, ``inv_b`` the lag rate per unit speed), and ``Pg``, ``r_g``: the load
        and lag downwash of the spanwise gradients ``[w', phi', delta']`` (None on an unswept
        wing).
    """
    check_sweep_terms(sweep_terms)
    keys = ("Mnc", "Cnc", "Knc", "Pq", "Pd", "w", "r_q", "r_d")
    get = aero.get if isinstance(aero, dict) else lambda k: getattr(aero, k)
    coef = {k: get(k) for k in keys}
    coef.update(b=b, inv_b=1.0 / b, Pg=None, r_g=None)
    sweep = element_sweep(wing, mesh)
    if not _is_swept(sweep):  # Theodorsen's arrays themselves: bit for bit the unswept model
        return coef
    return swept_coefficients(coef, sweep, sweep_terms)


def _is_swept(sweep: np.ndarray) -> bool:
    """Whether any element is swept (the tests force the swept path at zero sweep here)."""
    return bool(np.any(sweep))
