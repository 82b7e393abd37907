"""Modified strip theory of a swept wing: Theodorsen's section coefficients turned into those of a
strip normal to a swept elastic axis (``docs/sweep.md``).

Barmby, Cunningham and Garrick (1951), NACA Report 1014; Yates (1958), NACA RM L57L10;
Bisplinghoff, Ashley and Halfman (1955), sec. 5-6 and 8-4. The strip and its section
properties are normal to the elastic axis; the span coordinate ``s`` runs along the axis and
the sweep angle ``Lambda`` is positive backward. The free stream V has the component
``V cos Lambda`` normal to the axis (the section's flow) and ``V sin Lambda`` along it, which
convects the surface's slopes: every rate of the downwash becomes a substantial derivative
``d/dt + V sin Lambda d/ds``. With ``U = V cos Lambda``, Theodorsen's 3/4-chord downwash is

``Q = U r_q.q + r_d.(qdot + V sin Lambda q')``

whose bending term ``-V sin Lambda w'`` is the classical effective incidence
``phi - tan Lambda w'`` (times U) and whose twist and flap terms
``V sin Lambda [b (1/2 - a) phi' + b T11 / (2 pi) delta']`` are the streamwise gradient terms.
The circulatory load is ``rho U b w (C(k_n) Q)`` with ``k_n = omega b / U``; the apparent-mass
loads are Theodorsen's at U (their spanwise-convection terms are left out, see the docs).

Everything here is linear in the section coefficients and builds the per-element coefficients
of the speed-independent matrices once (:mod:`aeroservo.system.swept_assembly`).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["SWEEP_TERMS", "check_sweep_terms", "swept_coefficients"]

SWEEP_TERMS = {
    "full": (1.0, 1.0, 1.0),
    "classical": (1.0, 0.0, 0.0),
}
"""Which spanwise-convection terms of the downwash are kept, as a mask on ``r_d.q'`` of
``[w', phi', delta']``: ``"full"`` (bending slope, twist and flap gradients; the default) or
``"classical"`` (the bending slope alone: ``alpha = phi - tan Lambda w'``, the textbook
divergence closed form's assumption)."""


def check_sweep_terms(terms: object) -> str:
    """Validate the name of a set of sweep terms (:data:`SWEEP_TERMS`)."""
    if terms not in SWEEP_TERMS:
        raise InputError(f"sweep_terms = {terms!r}: allowed values are {list(SWEEP_TERMS)}")
    return str(terms)


def swept_coefficients(coef: dict, sweep: np.ndarray, terms: str = "full") -> dict:
    """Section coefficients of strips normal to a swept elastic axis.

    Parameters
    ----------
    coef : dict
        Per-element coefficients of the unswept section (leading dimension n_el): ``Mnc, Cnc,
        Knc, Pq, Pd`` (n_el, 3, 3), ``w, r_q, r_d`` (n_el, 3), ``b`` and ``inv_b`` (n_el,) [m,
        1/m] (real, or complex for a complex step).
    sweep : ndarray (n_el,)
        Sweep angle of each element's elastic axis [rad], + backward.
    terms : {"full", "classical"}
        Spanwise-convection terms kept (:data:`SWEEP_TERMS`).

    Returns
    -------
    dict
        The same keys scaled to the normal flow ``V cos Lambda`` (``Cnc, Pd, r_q`` by cos,
        ``Knc, Pq, w`` by cos^2, ``inv_b`` by cos: the lag rate; ``b`` divided by cos: the
        semichord of the reduced frequency ``omega b / (V cos Lambda)``), plus ``Pg`` (n_el, 3,
        3): circulatory load per unit ``rho V^2 C`` on the gradients ``[w', phi', delta']``, and
        ``r_g`` (n_el, 3): their downwash per unit V (lag fields).
    """
    terms = check_sweep_terms(terms)
    cos, sin = np.cos(sweep), np.sin(sweep)
    c1, c2 = cos[:, None, None], (cos * cos)[:, None, None]
    mask = np.asarray(SWEEP_TERMS[terms])
    r_grad = coef["r_d"] * mask  # r_d . q' (the substantial derivative's spanwise part)
    b = coef["b"]
    out = dict(coef)
    out.update(
        Mnc=coef["Mnc"],
        Cnc=coef["Cnc"] * c1,
        Knc=coef["Knc"] * c2,
        Pq=coef["Pq"] * c2,
        Pd=coef["Pd"] * c1,
        w=coef["w"] * (cos * cos)[:, None],
        r_q=coef["r_q"] * cos[:, None],
        r_d=coef["r_d"],
        inv_b=coef["inv_b"] * cos,
        b=b / cos,
        Pg=(cos * sin * b)[:, None, None] * coef["w"][:, :, None] * r_grad[:, None, :],
        r_g=r_grad * sin[:, None],
    )
    return out
