"""The aerodynamic part of a state-space model with the doublet-lattice model (``docs/dlm.md``).

The structural unknowns are the modal coordinates of the model's aerodynamic basis (or its
lowest ``n_modes``); the aeroelastic states and forces come from the rational-function
approximation (:mod:`aeroservo.system.rfa_system`). The gust's GAFs, fitted in the lag-only form
``C0 + sum_j C_j p / (p + g_j)``, become one gust state per gust lag root (twice as many roots as
the modal forces have, :data:`aeroservo.system.dlm_forces.GUST_LAG_FACTOR`),

``y_j' = (g_j V / b) (w_g - y_j)``,  force ``(rho V / 2) [(C0 + sum_j C_j) w_g - sum_j C_j y_j]``,

on the modes and on the root: the gust input is the vertical gust velocity ``w_g`` [m/s] (up)
that reaches the wing's most forward leading-edge point at t = 0; each box sees it when it
arrives there (chordwise and spanwise delays are in the GAFs the fit approximates).
"""

from __future__ import annotations

import numpy as np

from ..aero.dlm import check_dlm_mach
from ..errors import InputError
from ..system.rfa_system import rfa_blocks, rfa_first_order
from .aero_terms import AeroTerms
from .polynomial import _dense

__all__ = ["dlm_terms"]


def dlm_terms(
    model, rho: float, mach: float, n_modes: int | None, has_gust: bool, gust: str
) -> AeroTerms:
    """Doublet-lattice terms (:class:`aeroservo.linear.aero_terms.AeroTerms`; the strip-theory
    ones: :func:`aeroservo.linear.aero_terms.strip_terms`)."""
    dlm = model.dlm
    if gust != "kussner":
        raise InputError(
            f"gust = {gust!r}: not used with aero = 'dlm' (its gust forces have the chordwise "
            "and spanwise travel of the gust; leave gust at 'kussner')"
        )
    mach = check_dlm_mach(mach)
    n_a = dlm.n_a
    if n_modes is not None and n_modes > n_a:
        raise InputError(
            f"n_modes = {n_modes}: the doublet-lattice model has {n_a} modes (dlm.modes)"
        )
    m = n_a if n_modes is None else n_modes
    coords = np.eye(n_a)[:, :m]
    fit = model.dlm_fit(mach)
    b = dlm.b_ref
    basis = dlm.basis[:, :m]
    am = model.matrices

    def both(a):
        return basis.T @ (_dense(a) @ basis)

    rows = np.vstack([coords, np.zeros((3, m))])
    full_rows = np.zeros((n_a + 3, m + 3))
    full_rows[:n_a, :m] = coords
    full_rows[n_a:, m:] = np.eye(3)
    forces = fit.forces.project(full_rows, coords)  # rows: modes, then the root
    Ks, Cs = both(am.Ks), None if am.Cs is None else both(am.Cs)
    system = rfa_first_order(
        both(am.Ms),
        Ks,
        Cs,
        fit.forces.project(rows, coords),
        rho,
        b,
        tuple(f"eta_{j + 1}" for j in range(m)),
        semichord=model.semichord,
        mach=fit.mach,
    )
    n0 = system.n_states
    roots = fit.gust.roots
    n_g = roots.size if has_gust else 0
    n = n0 + n_g
    iq, iv = slice(0, m), slice(m, 2 * m)
    iz = slice(2 * m, n0)
    A = np.zeros((3, n, n))
    for k, a in enumerate((system.A0, system.A1, system.A2)):
        A[k, :n0, :n0] = _dense(a)
    half = 0.5 * rho
    Fa = np.zeros((3, m, n))
    Fa[:, :, :n0] = A[:, iv, :n0]
    Fa[0, :, iq] += Ks
    if Cs is not None:
        Fa[0, :, iv] += Cs
    H_root = rfa_blocks(forces, b)["H"][m:]  # lag loads on the root rows
    Fr = np.zeros((3, 3, n))
    Fr[2, :, iq] = half * forces.A0[m:]
    Fr[1, :, iv] = half * b * forces.A1[m:]
    Fr[2, :, iz] = half * H_root
    Fu = np.zeros((2, m))
    Fru = np.zeros((2, 3))
    Bg = np.zeros((2, n))
    labels = []
    if has_gust:
        g = fit.gust.project(full_rows, np.eye(1))  # rows: modes, root; one column
        C = g.B[:, :, 0]  # (n_r, m + 3)
        direct = g.A0[:, 0] + C.sum(axis=0)
        for j, gam in enumerate(roots):
            s = n0 + j
            A[1, s, s] = -gam / b
            Bg[1, s] = gam / b
            Fa[1, :, s] = -half * C[j, :m]
            Fr[1, :, s] = -half * C[j, m:]
            labels.append(f"gust_lag{j + 1}")
        Fu[1] = half * direct[:m]
        Fru[1] = half * direct[m:]
    A[:, iv, :] = Fa
    A[0, iv, iq] -= Ks
    if Cs is not None:
        A[0, iv, iv] -= Cs
    Bg[:, iv] = Fu
    rt = am.root
    return AeroTerms(
        system=system,
        basis=basis,
        A=A,
        B_gust=Bg,
        Fa=Fa,
        Fu=Fu,
        Fr=Fr,
        Fru=Fru,
        mnc=-0.5 * b * b * forces.A2[:m],
        root_mnc=-0.5 * b * b * forces.A2[m:],
        Ks=Ks,
        Cs=Cs,
        root_Ks=np.zeros((3, m)),  # force summation: the rigid motions do no elastic work
        root_Ms=(dlm.rigid[: am.n_q].T @ _dense(am.Ms) + _dense(rt.Ms)) @ basis,
        gust_labels=tuple(labels),
    )
