"""Structural damping ``C_s`` (the seed's equation 1): modal ratios, Rayleigh, structural g,
per-DOF viscous ratios.

Four forms, all giving a symmetric damping matrix on the structural unknowns that multiplies
the rates in ``Ms qdd + C_s qd + Ks q = f_aero``:

* **modal**: a viscous damping ratio ``zeta_j`` per in-vacuo mode (one value for all, or a list
  for the lowest modes, the last value repeated for the higher ones):
  ``C_s = Ms Phi diag(2 zeta_j omega_j) Phi^T Ms`` with mass-normalized shapes ``Phi`` of every
  mode, so that each in-vacuo mode decays at ``zeta_j omega_j``;
* **Rayleigh**: ``C_s = alpha Ms + beta Ks`` (``zeta_j = alpha / (2 omega_j) + beta omega_j / 2``);
* **structural g** (Nastran's ``g``): the equivalent viscous ratio ``zeta_j = g / 2`` at every
  in-vacuo mode (the damping of ``(1 + i g) K`` at resonance);
* **per DOF**: a viscous ratio per kind of unknown (plunge/bending, pitch/torsion, flap/control
  rotation), on the modes of the uncoupled structure (:mod:`.dof_damping`); on a typical section
  the damper ``c_i = 2 zeta_i sqrt(k_i m_ii)`` of each degree of freedom, as Conner et al.
  (1997) define it (with ``plunge_mass``, their wing mass in the plunge damper).

The matrix does not depend on speed or density: it is built once per model.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..errors import InputError, check_number, check_quantity
from .dof_damping import GAP, dense, dof_blocks, modal_terms, per_dof_derivatives

__all__ = [
    "StructuralDamping",
    "damping_matrix",
    "damping_derivatives",
    "damping_parameters",
    "NO_DAMPING",
    "GAP",
]

KINDS = ("none", "modal", "rayleigh", "structural_g", "per_dof")

PLAUSIBLE_G = 0.2
"""Largest structural damping g [-] taken without a warning (g = 0.2 is zeta = 0.1; built
wings have g of 0.01 to 0.06): a larger value is most likely a percentage."""

PLAUSIBLE_RATIO = 0.1
"""Largest modal damping ratio zeta [-] taken without a warning (see :data:`PLAUSIBLE_G`)."""


@dataclass(frozen=True)
class StructuralDamping:
    """Structural damping of a model (validated on construction).

    Parameters
    ----------
    kind : str
        ``"none"``, ``"modal"``, ``"rayleigh"``, ``"structural_g"`` or ``"per_dof"``.
    ratios : tuple of float
        Modal viscous damping ratios [-], lowest mode first (``"modal"``); per-DOF ratios
        [-], one for every kind of unknown or one per kind: plunge/bending, pitch/torsion,
        flap/control rotation (``"per_dof"``).
    alpha : float
        Mass-proportional coefficient [1/s] (``"rayleigh"``).
    beta : float
        Stiffness-proportional coefficient [s] (``"rayleigh"``).
    g : float
        Structural damping coefficient [-] (``"structural_g"``).
    plunge_mass : float or None
        Mass [kg/m] in a typical section's plunge damper ``2 zeta_h sqrt(k_h m)``
        (``"per_dof"``; default the section's plunge inertia). Conner et al. (1997) use the
        wing-and-flap mass ``m``, not the plunge inertia ``m_t`` with the supports.
    """

    kind: str = "none"
    ratios: tuple = ()
    alpha: float = 0.0
    beta: float = 0.0
    g: float = 0.0
    plunge_mass: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise InputError(f"damping.kind = {self.kind!r}: allowed values are {list(KINDS)}")
        if self.kind in ("modal", "per_dof"):
            key = "damping.ratio" if self.kind == "modal" else "damping.dof_ratio"
            r = self.ratios
            if isinstance(r, (int, float)) and not isinstance(r, bool):
                r = (r,)
            if isinstance(r, (str, bytes)) or not isinstance(r, Sequence) or len(r) == 0:
                raise InputError(
                    f"{key} = {self.ratios!r}: expected a damping ratio or a list of them"
                )
            if self.kind == "per_dof" and len(r) > 3:
                raise InputError(
                    f"{key} = {list(r)!r}: one ratio, or one per kind of unknown "
                    "(plunge/bending, pitch/torsion, flap/control rotation): at most 3"
                )
            vals = tuple(
                check_number(f"{key}[{i}]", v, lo=0.0, hi=1.0, hi_open=True)
                for i, v in enumerate(r)
            )
            object.__setattr__(self, "ratios", vals)
        if self.plunge_mass is not None:
            if self.kind != "per_dof":
                raise InputError(
                    f"damping.plunge_mass = {self.plunge_mass!r}: only with per-DOF ratios "
                    "(dof_ratio)"
                )
            m = check_number("damping.plunge_mass", self.plunge_mass, unit="kg/m", lo=0.0)
            if m <= 0.0:
                raise InputError(f"damping.plunge_mass = {m!r}: must be > 0 kg/m")
            object.__setattr__(self, "plunge_mass", m)
        if self.kind == "rayleigh":
            check_quantity("damping.alpha", self.alpha, "rayleigh_alpha")
            check_quantity("damping.beta", self.beta, "rayleigh_beta")
        if self.kind == "structural_g":
            check_quantity("damping.g", self.g, "structural_g")
        self._warn_if_percentage()

    def _warn_if_percentage(self) -> None:
        """Warn about a damping that reads like a percentage typed as a fraction."""
        import warnings

        if self.kind == "structural_g" and self.g > PLAUSIBLE_G:
            warnings.warn(
                f"damping.g = {self.g:g} means zeta = {self.g / 2:g} ({50 * self.g:g} % of "
                f"critical) in every mode, far above the 0.01 to 0.06 of built wings; g is a "
                f"fraction, not a percentage: for {self.g:g} % write g = {self.g / 100:g}",
                UserWarning,
                stacklevel=4,
            )
        viscous = self.kind in ("modal", "per_dof")
        big = [z for z in self.ratios if z > PLAUSIBLE_RATIO] if viscous else []
        if big:
            key = "damping.ratio" if self.kind == "modal" else "damping.dof_ratio"
            warnings.warn(
                f"{key} = {big[0]:g} is {100 * big[0]:g} % of critical damping, far "
                "above the 0.005 to 0.03 of built wings; the ratio is a fraction, not a "
                f"percentage: for {big[0]:g} % write ratio = {big[0] / 100:g}",
                UserWarning,
                stacklevel=4,
            )

    @classmethod
    def modal(cls, ratios: float | Sequence[float]) -> StructuralDamping:
        """Modal viscous damping ratio(s) [-]."""
        return cls("modal", ratios=ratios)

    @classmethod
    def rayleigh(cls, alpha: float, beta: float) -> StructuralDamping:
        """Rayleigh damping ``alpha Ms + beta Ks``."""
        return cls("rayleigh", alpha=alpha, beta=beta)

    @classmethod
    def structural(cls, g: float) -> StructuralDamping:
        """Structural damping g (``zeta = g / 2`` at every in-vacuo mode)."""
        return cls("structural_g", g=g)

    @classmethod
    def per_dof(
        cls, ratios: float | Sequence[float], plunge_mass: float | None = None
    ) -> StructuralDamping:
        """Per-DOF viscous damping ratio(s) [-]: one for every kind of unknown, or one each for
        plunge/bending, pitch/torsion and flap/control rotation (:mod:`.dof_damping`); on a
        typical section the dampers ``2 zeta_i sqrt(k_i m_ii)``, with ``plunge_mass`` [kg/m]
        in the plunge's if given."""
        return cls("per_dof", ratios=ratios, plunge_mass=plunge_mass)

    @property
    def active(self) -> bool:
        return self.kind != "none" and (
            any(self.ratios) or self.alpha or self.beta or self.g or False
        )

    def describe(self) -> str:
        """E.g. ``"g = 0.03"``, ``"zeta = 0.02"``, ``"Rayleigh 0.1 M + 1e-4 K"``, ``"none"``."""
        if self.kind == "modal":
            r = self.ratios
            return f"zeta = {r[0]:g}" if len(r) == 1 else "zeta = " + ", ".join(f"{z:g}" for z in r)
        if self.kind == "per_dof":
            mass = "" if self.plunge_mass is None else f", plunge mass {self.plunge_mass:g} kg/m"
            return "zeta per DOF = " + ", ".join(f"{z:g}" for z in self.ratios) + mass
        if self.kind == "rayleigh":
            return f"Rayleigh {self.alpha:g} M + {self.beta:g} K"
        if self.kind == "structural_g":
            return f"g = {self.g:g}"
        return "none"

    def to_dict(self) -> dict:
        out: dict = {"kind": self.kind}
        if self.kind == "modal":
            out["ratio"] = list(self.ratios)
        elif self.kind == "per_dof":
            out["dof_ratio"] = list(self.ratios)
            if self.plunge_mass is not None:
                out["plunge_mass"] = self.plunge_mass
        elif self.kind == "rayleigh":
            out.update(alpha=self.alpha, beta=self.beta)
        elif self.kind == "structural_g":
            out["g"] = self.g
        return out

    def mode_ratios(self, omega: np.ndarray) -> np.ndarray:
        """Damping ratio of each in-vacuo mode of circular frequencies ``omega`` [rad/s] (not
        for per-DOF damping, whose ratios belong to the modes of the uncoupled structure)."""
        if self.kind == "per_dof":
            raise ValueError("per-DOF damping has no ratio per coupled in-vacuo mode")
        omega = np.asarray(omega, dtype=float)
        if self.kind == "modal":
            r = np.asarray(self.ratios)
            return np.concatenate([r, np.full(max(omega.size - r.size, 0), r[-1])])[: omega.size]
        if self.kind == "structural_g":
            return np.full(omega.size, 0.5 * self.g)
        if self.kind == "rayleigh":
            w = np.maximum(omega, 1e-300)
            return self.alpha / (2 * w) + self.beta * w / 2
        return np.zeros(omega.size)


NO_DAMPING = StructuralDamping()


def damping_matrix(damping: StructuralDamping, Ms, Ks, labels=None) -> sp.csr_matrix | None:
    """The structural damping matrix on the structural unknowns, or None without damping.

    Parameters
    ----------
    damping : StructuralDamping
    Ms, Ks : sparse or ndarray (n, n)
        Structural mass and stiffness.
    labels : sequence of str, optional
        The unknowns' labels (``AeroMatrices.dof_labels``); per-DOF damping needs them.
    """
    if not isinstance(damping, StructuralDamping):
        raise InputError(f"damping = {damping!r}: expected an aeroservo StructuralDamping")
    if not damping.active:
        return None
    if damping.kind == "rayleigh":
        return sp.csr_matrix(damping.alpha * Ms + damping.beta * Ks)
    M = Ms.toarray() if sp.issparse(Ms) else np.asarray(Ms, dtype=float)
    K = Ks.toarray() if sp.issparse(Ks) else np.asarray(Ks, dtype=float)
    if damping.kind == "per_dof":
        out = np.zeros_like(M)
        for idx, m_b, k_b, zeta, _, _ in dof_blocks(
            damping.ratios, damping.plunge_mass, M, K, _labels(labels, M)
        ):
            w2, phi = sla.eigh(k_b, m_b)
            mp = m_b @ phi
            out[np.ix_(idx, idx)] = (mp * (2.0 * zeta * np.sqrt(np.clip(w2, 0.0, None)))) @ mp.T
        return sp.csr_matrix(out)
    w2, phi = sla.eigh(K, M)
    omega = np.sqrt(np.clip(w2, 0.0, None))
    c = 2.0 * damping.mode_ratios(omega) * omega
    mp = M @ phi
    return sp.csr_matrix((mp * c) @ mp.T)


def _labels(labels, M: np.ndarray):
    if labels is None or len(labels) != M.shape[0]:
        raise InputError(
            "damping.dof_ratio: per-DOF damping needs the labels of the structural unknowns "
            "(w, theta, phi, delta)"
        )
    return labels


def damping_parameters(damping: StructuralDamping) -> dict[str, float]:
    """The damping's own parameters by their file names (``damping.g``, ``damping.ratio`` or
    ``damping.ratio[i]``, ``damping.alpha``, ``damping.beta``) and values; empty if undamped."""
    if not damping.active:
        return {}
    if damping.kind in ("modal", "per_dof"):
        key = "damping.ratio" if damping.kind == "modal" else "damping.dof_ratio"
        r = damping.ratios
        if len(r) == 1:
            return {key: r[0]}
        return {f"{key}[{i}]": v for i, v in enumerate(r)}
    if damping.kind == "rayleigh":
        return {"damping.alpha": damping.alpha, "damping.beta": damping.beta}
    return {"damping.g": damping.g}


def damping_derivatives(damping: StructuralDamping, Ms, Ks, labels=None):
    """Derivatives of the damping matrix, as two functions of one eigen-decomposition.

    Returns
    -------
    (d_structure, d_own)
        ``d_structure(dMs, dKs)`` gives ``dCs/dp`` for a parameter moving the structural matrices
        by ``dMs, dKs`` (Rayleigh: ``alpha dMs + beta dKs``; modal and structural g: the
        eigenvector derivatives of ``Cs = Ms Phi diag(2 zeta_j omega_j) Phi^T Ms``, Nelson's
        closed form through the divided differences of ``f(lambda) = 2 zeta sqrt(lambda)``;
        raises ValueError when two modes of different ratios coincide, see :data:`GAP`; per
        DOF: the same on each uncoupled block, ``labels`` the unknowns' labels).
        ``d_own(name)`` gives ``dCs/dp`` for a name of :func:`damping_parameters`.
    """
    M = Ms.toarray() if sp.issparse(Ms) else np.asarray(Ms, dtype=float)
    K = Ks.toarray() if sp.issparse(Ks) else np.asarray(Ks, dtype=float)
    if damping.kind == "rayleigh":

        def d_structure(dMs, dKs):
            return sp.csr_matrix(damping.alpha * dMs + damping.beta * dKs)

        def d_own(name):
            return sp.csr_matrix(M if name == "damping.alpha" else K)

        return d_structure, d_own
    if damping.kind == "per_dof":
        return per_dof_derivatives(damping.ratios, damping.plunge_mass, M, K, _labels(labels, M))
    core, mp, s = modal_terms(M, K, damping.mode_ratios)

    def d_structure(dMs, dKs):
        return sp.csr_matrix(core(dense(dMs), dense(dKs)))

    def d_own(name):
        if name == "damping.g":
            weight = s  # C = g Ms Phi diag(omega) Phi^T Ms
        else:
            ratios = np.asarray(damping.ratios)
            i = 0 if name == "damping.ratio" else int(name[len("damping.ratio[") : -1])
            idx = np.arange(s.size)
            last = ratios.size - 1
            on = (idx == i) | ((i == last) & (idx > last)) if ratios.size > 1 else idx >= 0
            weight = 2.0 * s * on
        return sp.csr_matrix((mp * weight) @ mp.T)

    return d_structure, d_own
