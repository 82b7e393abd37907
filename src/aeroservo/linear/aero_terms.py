"""The aerodynamic part of a state-space model: the first-order system, the gust states and the
aerodynamic forces on the structure and on the clamped root, for either aerodynamic model.

:class:`AeroTerms` holds, as matrix polynomials in the airspeed V before ``E^-1`` is applied:
the state coefficients of the aeroelastic states (structure, lag states) and the gust states,
the gust input's column, and the aerodynamic generalized forces on the structural unknowns and
on the root (their outputs: aerodynamic hinge moments, root loads). The state-space builder
(:mod:`aeroservo.linear.state_space`) adds inputs, servos and outputs to it.

Strip theory (this module): Wagner lag states, Kussner gust states per semichord (or the gust
as an upwash through the lag states). The doublet-lattice model:
:mod:`aeroservo.linear.dlm_terms`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..aero.indicial import IndicialSet
from ..system.first_order import FirstOrderSystem, compressibility_factors, first_order
from .polynomial import _dense

__all__ = ["AeroTerms", "strip_terms"]


@dataclass
class AeroTerms:
    """Aerodynamic part of a state-space model (module notes).

    Attributes
    ----------
    system : FirstOrderSystem
        The aeroelastic states ``[q, qdot, lag states]`` (``n0`` of them).
    basis : ndarray (n_fe, n_q) or None
        Structural basis: the unknowns are ``q_fe = basis @ q`` (None: the FE unknowns).
    A : ndarray (3, n_a, n_a)
        Coefficients of V^0..V^2 of the state equations before ``E^-1`` (aeroelastic states,
        then the gust states); the rate rows hold ``forces - Ks q - Cs qdot``.
    B_gust : ndarray (2, n_a)
        The gust input's column (V^0, V^1).
    Fa : ndarray (3, n_q, n_a)
        Aerodynamic generalized forces on the unknowns (apparent mass apart).
    Fu : ndarray (2, n_q)
        Their direct gust term.
    Fr, Fru : ndarray (3, n_r, n_a), (2, n_r)
        The same on the clamped root's ``w, theta, phi``, then on those of each cut node asked
        for (``cut_nodes``; ``n_r = 3 (1 + len(cut_nodes))``).
    mnc, root_mnc : ndarray (n_q, n_q), (n_r, n_q)
        Apparent mass per unit density: the aerodynamic force holds ``-rho mnc qddot``.
    Ks, Cs : ndarray (n_q, n_q), ndarray or None
        Structural stiffness and damping in the unknowns.
    root_Ks, root_Ms : ndarray (n_r, n_q)
        Root (and cut) rows of the structural stiffness and mass.
    weight, root_weight : ndarray (n_q,), (n_r,) or None
        Loads of a unit upward acceleration of every mass (``M r``) on the unknowns and on
        the root (and cut) rows (None: the doublet lattice).
    gust_labels : tuple of str
    """

    system: FirstOrderSystem
    basis: np.ndarray | None
    A: np.ndarray
    B_gust: np.ndarray
    Fa: np.ndarray
    Fu: np.ndarray
    Fr: np.ndarray
    Fru: np.ndarray
    mnc: np.ndarray
    root_mnc: np.ndarray
    Ks: np.ndarray
    Cs: np.ndarray | None
    root_Ks: np.ndarray
    root_Ms: np.ndarray
    gust_labels: tuple
    weight: np.ndarray | None = None
    root_weight: np.ndarray | None = None

    @property
    def n_q(self) -> int:
        return self.system.n_q


def strip_terms(
    model,
    rho: float,
    mach: float,
    modes,
    n_modes: int | None,
    has_gust: bool,
    gust: str,
    kussner: IndicialSet,
    cut_nodes: tuple[int, ...] = (),
) -> AeroTerms:
    """Strip theory's terms: Wagner lag states per node, Kussner gust states per distinct
    semichord (or the upwash gust through the lag states).

    Parameters
    ----------
    model : AeroelasticModel
    rho, mach : float
        Density [kg/m^3]; Mach number (Prandtl-Glauert).
    modes : NaturalModes or None
        In-vacuo modes (their shapes give the modal truncation).
    n_modes : int or None
        Modal truncation (None: every unknown of the model).
    has_gust : bool
        Whether the gust is an input.
    gust : {"kussner", "upwash"}
    kussner : IndicialSet
    cut_nodes : tuple of int
        Nodes whose internal loads are wanted, after the root's (rows of ``Fr``).
    """
    am = model.matrices
    basis = None
    if n_modes is not None:
        am = am.project(modes.shapes[:, :n_modes])
        basis = modes.shapes[:, :n_modes]
    cf, beta2 = compressibility_factors(mach)
    system = first_order(am, model.wagner, rho, model.semichord, mach=mach)
    n_q = am.n_q
    wag = model.wagner
    T = wag.n_terms
    n_z = T * am.n_nodes
    groups = am.circ_groups
    kus = kussner
    n_g = len(groups) * kus.n_terms if (gust == "kussner" and has_gust) else 0
    n0 = 2 * n_q + n_z
    n = n0 + n_g
    iq, iv = slice(0, n_q), slice(n_q, 2 * n_q)
    iz = slice(2 * n_q, n0)
    A = np.zeros((3, n, n))
    for k, a in enumerate((system.A0, system.A1, system.A2)):
        A[k, :n0, :n0] = _dense(a)

    # aerodynamic generalized forces (without apparent mass) on the free and root unknowns
    scale = cf * (1.0 - sum(wag.A))
    ab = cf * beta2 * np.asarray(wag.A) * np.asarray(wag.b)
    rt = am.reaction_rows(tuple(cut_nodes))
    n_r = rt.Ks.shape[0]
    Ks = _dense(am.Ks)
    Cs = None if am.Cs is None else _dense(am.Cs)
    Fa = np.zeros((3, n_q, n))
    Fa[:, :, :n0] = A[:, iv, :n0]
    Fa[0, :, iq] += Ks
    if Cs is not None:  # structural damping is not an aerodynamic force
        Fa[0, :, iv] += Cs
    Fr = np.zeros((3, n_r, n))
    Fr[2, :, iq] = -rho * _dense(rt.Knc - scale * rt.Pq)
    Fr[1, :, iv] = -rho * _dense(rt.Cnc - scale * rt.Pd)
    Fr[2, :, iz] = rho * np.kron(_dense(rt.W1), ab[None, :])
    Fu = np.zeros((2, n_q))
    Fru = np.zeros((2, n_r))
    Bg = np.zeros((2, n))

    g_states = []
    if has_gust:
        if gust == "kussner":
            ka, kb = np.asarray(kus.A), np.asarray(kus.b)
            for gi, g in enumerate(groups):
                for t in range(kus.n_terms):
                    s = n0 + gi * kus.n_terms + t
                    A[1, s, s] = -kb[t] * beta2 / g.b
                    Bg[0, s] = 1.0
                    Fa[2, :, s] = rho * cf * beta2 * ka[t] * kb[t] * g.Gw
                    Fr[2, :, s] = rho * cf * beta2 * ka[t] * kb[t] * rt.circ_groups[gi].Gw
                    g_states.append(f"g{t + 1}_b{gi}")
            direct = cf * (1.0 - ka.sum())
        else:
            Bg[0, iz] = np.kron(np.asarray(am.Mz1.sum(axis=1)).ravel(), np.ones(T))
            direct = scale
        Fu[1] = rho * direct * sum(g.b * g.Gw for g in groups)
        Fru[1] = rho * direct * sum(g.b * g.Gw for g in rt.circ_groups)

    A[:, iv, :] = Fa
    A[0, iv, iq] -= Ks
    if Cs is not None:
        A[0, iv, iv] -= Cs
    Bg[:, iv] = Fu
    return AeroTerms(
        system=system,
        basis=basis,
        A=A,
        B_gust=Bg,
        Fa=Fa,
        Fu=Fu,
        Fr=Fr,
        Fru=Fru,
        mnc=_dense(am.Mnc),
        root_mnc=_dense(rt.Mnc),
        Ks=Ks,
        Cs=Cs,
        root_Ks=_dense(rt.Ks),
        root_Ms=_dense(rt.Ms),
        gust_labels=tuple(g_states),
        weight=am.weight,
        root_weight=rt.weight,
    )
