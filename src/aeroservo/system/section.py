"""Typical section: plunge, pitch and (optionally) trailing-edge flap on springs.

The "simplest model" of the seed (Theodorsen's 3-DOF section), built on exactly the same
aerodynamic coefficients (:func:`aeroservo.aero.theodorsen.section_aero`) and the same
first-order assembly (:func:`aeroservo.system.first_order.first_order`) as the wing stick model,
with one strip of unit span. Unknowns ``[w, phi]`` or ``[w, phi, delta]`` (plunge up, pitch
nose-up, flap TE down).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..aero.indicial import wagner_set
from ..aero.theodorsen import section_aero
from ..errors import InputError, check_number
from .damping import NO_DAMPING, StructuralDamping, damping_matrix
from .first_order import FirstOrderSystem, check_mach, first_order
from .matrices import AeroMatrices, StripGroup

__all__ = ["TypicalSection", "conner_section", "CONNER"]


@dataclass(frozen=True)
class TypicalSection:
    """A 2-D typical section per unit span (SI units).

    Parameters
    ----------
    semichord : float
        b [m].
    a : float
        Elastic axis, semichords aft of mid-chord [-].
    mass : float
        Mass per unit span m [kg/m] (flap included).
    x_alpha : float
        (CG - EA)/b [-].
    inertia : float
        Pitch inertia about the elastic axis I_alpha [kg m] (flap included).
    k_plunge, k_pitch : float
        Plunge spring [N/m per m] and pitch spring [N m/rad per m].
    hinge : float or None
        Flap hinge c, semichords aft of mid-chord [-]; None for a 2-DOF section.
    flap_static_moment, flap_inertia, k_flap : float
        S_beta [kg m/m], I_beta about the hinge [kg m], hinge spring [N m/rad per m].
    wagner : str or mapping
        Wagner approximation for the time-domain model (default ``"rt_jones"``).
    damping : StructuralDamping, optional
        Structural damping (:mod:`aeroservo.system.damping`); default none.
    """

    semichord: float
    a: float
    mass: float
    x_alpha: float
    inertia: float
    k_plunge: float
    k_pitch: float
    hinge: float | None = None
    flap_static_moment: float = 0.0
    flap_inertia: float = 0.0
    k_flap: float = 0.0
    wagner: object = "rt_jones"
    damping: StructuralDamping | None = None

    def __post_init__(self) -> None:
        check_number("section.semichord", self.semichord, unit="m", lo=0.0, lo_open=True)
        check_number("section.a", self.a, lo=-1.0, hi=1.0)
        check_number("section.mass", self.mass, unit="kg/m", lo=0.0, lo_open=True)
        check_number("section.x_alpha", self.x_alpha, lo=-1.0 - self.a, hi=1.0 - self.a)
        check_number("section.inertia", self.inertia, unit="kg m", lo=0.0, lo_open=True)
        check_number("section.k_plunge", self.k_plunge, unit="N/m/m", lo=0.0, lo_open=True)
        check_number("section.k_pitch", self.k_pitch, unit="N m/rad/m", lo=0.0, lo_open=True)
        if self.hinge is not None:
            check_number("section.hinge", self.hinge, lo=self.a, hi=1.0, hi_open=True)
            check_number(
                "section.flap_inertia", self.flap_inertia, unit="kg m", lo=0.0, lo_open=True
            )
            check_number("section.k_flap", self.k_flap, unit="N m/rad/m", lo=0.0)
        if np.linalg.eigvalsh(self.mass_matrix()).min() <= 0:
            raise InputError("section: the mass matrix is not positive definite")
        wagner_set(self.wagner)
        if self.damping is not None and not isinstance(self.damping, StructuralDamping):
            raise InputError(f"section.damping = {self.damping!r}: expected a StructuralDamping")

    @classmethod
    def from_nondimensional(
        cls,
        *,
        semichord: float,
        a: float,
        mu: float,
        x_alpha: float,
        r_alpha2: float,
        omega_h: float,
        omega_alpha: float,
        density: float,
        hinge: float | None = None,
        x_beta: float = 0.0,
        r_beta2: float = 0.0,
        omega_beta: float = 0.0,
        wagner: object = "rt_jones",
        damping: StructuralDamping | None = None,
    ) -> TypicalSection:
        """Section from the classical parameters (Theodorsen, Bisplinghoff, Hodges & Pierce).

        ``m = mu pi rho b^2``, ``I_alpha = m b^2 r_alpha2``, ``S_beta = m b x_beta``,
        ``I_beta = m b^2 r_beta2``, springs ``m omega_h^2``, ``I_alpha omega_alpha^2`` and
        ``I_beta omega_beta^2`` (uncoupled frequencies in rad/s).
        """
        m = mu * np.pi * density * semichord**2
        i_a = m * semichord**2 * r_alpha2
        i_b = m * semichord**2 * r_beta2
        return cls(
            semichord=semichord,
            a=a,
            mass=m,
            x_alpha=x_alpha,
            inertia=i_a,
            k_plunge=m * omega_h**2,
            k_pitch=i_a * omega_alpha**2,
            hinge=hinge,
            flap_static_moment=m * semichord * x_beta,
            flap_inertia=i_b,
            k_flap=i_b * omega_beta**2,
            wagner=wagner,
            damping=damping,
        )

    @property
    def n_dofs(self) -> int:
        return 2 if self.hinge is None else 3

    def mass_matrix(self) -> np.ndarray:
        """Structural mass matrix on ``[w, phi(, delta)]``."""
        b = self.semichord
        s_a = self.mass * self.x_alpha * b
        m = np.array([[self.mass, -s_a, 0.0], [-s_a, self.inertia, 0.0], [0.0, 0.0, 0.0]])
        if self.hinge is not None:
            s_b, i_b = self.flap_static_moment, self.flap_inertia
            c = i_b + b * (self.hinge - self.a) * s_b
            m[0, 2] = m[2, 0] = -s_b
            m[1, 2] = m[2, 1] = c
            m[2, 2] = i_b
        n = self.n_dofs
        return m[:n, :n]

    @property
    def matrices(self) -> AeroMatrices:
        """Speed-independent matrices (one strip of unit span, one lag node)."""
        n = self.n_dofs
        c = 1.0 if self.hinge is None else self.hinge
        aero = section_aero(self.semichord, self.a, c)
        ks = np.diag([self.k_plunge, self.k_pitch, self.k_flap])[:n, :n]
        labels = ("w", "phi", "delta")[:n]
        cs = damping_matrix(self.damping or NO_DAMPING, self.mass_matrix(), ks, labels)

        def csr(x):
            return sp.csr_matrix(np.atleast_2d(x))

        return AeroMatrices(
            Ms=csr(self.mass_matrix()),
            Ks=csr(ks),
            Mnc=csr(aero.Mnc[:n, :n]),
            Cnc=csr(aero.Cnc[:n, :n]),
            Knc=csr(aero.Knc[:n, :n]),
            circ_groups=(
                StripGroup(
                    self.semichord, csr(aero.Pq[:n, :n]), csr(aero.Pd[:n, :n]), aero.w[:n].copy()
                ),
            ),
            Mz1=csr(1.0),
            Lz1=csr(1.0 / self.semichord),
            E1=csr(aero.r_q[None, :n]),
            F1=csr(aero.r_d[None, :n]),
            W1=csr(aero.w[:n, None]),
            dof_labels=labels,
            lag_labels=("0",),
            Cs=cs,
        )

    def system(self, density: float, mach: float = 0.0) -> FirstOrderSystem:
        """First-order system at air density ``density`` [kg/m^3] and compressibility Mach
        number ``mach``."""
        rho = check_number("density", density, unit="kg/m^3", lo=0.0, lo_open=True)
        return first_order(
            self.matrices, wagner_set(self.wagner), rho, self.semichord, mach=check_mach(mach)
        )

    def label_modes(self, shapes: np.ndarray) -> list[str]:
        """Name modes by their dominant unknown (plunge, pitch, flap)."""
        names = ("plunge", "pitch", "flap")
        k = np.diag(self.matrices.Ks.toarray())
        return [
            names[int(np.argmax(k * np.abs(shapes[:, j]) ** 2))] for j in range(shapes.shape[1])
        ]


CONNER = {
    "semichord": 0.127,  # m
    "a": -0.5,
    "hinge": 0.5,
    "m_plunge": 3.3843,  # kg/m, plunge inertia with the supports (m_t)
    "m_wing": 1.558,  # kg/m, wing and flap without the supports (m): the plunge damper's mass
    "S_alpha": 0.08587,  # kg m/m
    "I_alpha": 0.01347,  # kg m
    "S_beta": 0.00395,  # kg m/m
    "I_beta": 0.0003264,  # kg m
    "k_h": 2818.8,  # N/m per m
    "k_alpha": 37.34,  # N m/rad per m
    "k_beta": 3.9,  # N m/rad per m
    "zeta": (0.0113, 0.01626, 0.0115),  # viscous ratios, plunge, pitch, flap
    "gap": 0.0740,  # rad: total freeplay 4.24 deg (+-2.12 deg)
}
"""The freeplay section of Conner, Tang, Dowell & Virgin (1997), J. Fluids Struct. 11, 89-109,
per unit span (SI; values as in ``shared/reference`` "Freeplay section")."""


def conner_section(
    k_flap: float = CONNER["k_beta"], *, damped: bool | str = False, wagner: object = "rt_jones"
) -> TypicalSection:
    """The 3-DOF section with flap of Conner et al. (1997), gap closed (hinge spring
    ``k_flap`` [N m/rad per m]).

    The plunge inertia is ``m_t`` (wing, flap and supports) and the pitch coupling the measured
    static moment ``S_alpha`` (``x_alpha = S_alpha / (m_t b)``). Linear flutter with the gap
    closed: 23.91 m/s with exact C(k), 23.73 m/s undamped with R. T. Jones's lag states (this
    model: 23.74); flap free (``k_flap = 0``) about 6.5 m/s (6.49).

    ``damped``: False (default) undamped; ``"per_dof"`` the paper's damping, a viscous damper
    ``2 zeta_i sqrt(k_i m_i)`` on each degree of freedom with the ratios ``CONNER["zeta"]``
    and, in the plunge's, the wing mass ``m`` (``CONNER["m_wing"]``), not ``m_t``
    (:meth:`~aeroservo.system.damping.StructuralDamping.per_dof`): 23.84 m/s, as the reference;
    True or ``"modal"`` the same ratios as modal damping of the in-vacuo modes (23.97 m/s, not
    the paper's). Flap free the reference's 6.65 m/s keeps the flap damper of the hinge spring
    3.9 N m/rad; ``conner_section(0.0, damped="per_dof")`` damps the flap on its own spring,
    zero (6.90 m/s). The freeplay section keeps the spring and its damper (the law removes the
    spring inside the gap), as the paper does.
    """
    from .damping import StructuralDamping

    c, b = CONNER, CONNER["semichord"]
    if damped not in (False, True, "modal", "per_dof"):
        raise InputError(f"damped = {damped!r}: allowed values are False, True, 'modal', 'per_dof'")
    damping = None
    if damped == "per_dof":
        damping = StructuralDamping.per_dof(list(c["zeta"]), plunge_mass=c["m_wing"])
    elif damped:
        damping = StructuralDamping.modal(list(c["zeta"]))
    return TypicalSection(
        semichord=b,
        a=c["a"],
        mass=c["m_plunge"],
        x_alpha=c["S_alpha"] / (c["m_plunge"] * b),
        inertia=c["I_alpha"],
        k_plunge=c["k_h"],
        k_pitch=c["k_alpha"],
        hinge=c["hinge"],
        flap_static_moment=c["S_beta"],
        flap_inertia=c["I_beta"],
        k_flap=k_flap,
        wagner=wagner,
        damping=damping,
    )
