"""Structural damping ``C_s`` (the seed's equation 1): modal ratios, Rayleigh, structural g.

Three forms, all giving a symmetric damping matrix on the structural unknowns that multiplies
the rates in ``Ms qdd + C_s qd + Ks q = f_aero``:

* **modal**: a viscous damping ratio ``zeta_j`` per in-vacuo mode (one value for all, or a list
  for the lowest modes, the last value repeated for the higher ones):
  ``C_s = Ms Phi diag(2 zeta_j omega_j) Phi^T Ms`` with mass-normalized shapes ``Phi`` of every
  mode, so that each in-vacuo mode decays at ``zeta_j omega_j``;
* **Rayleigh**: ``C_s = alpha Ms + beta Ks`` (``zeta_j = alpha / (2 omega_j) + beta omega_j / 2``);
* **structural g** (Nastran's ``g``): the equivalent viscous ratio ``zeta_j = g / 2`` at every
  in-vacuo mode (the damping of ``(1 + i g) K`` at resonance).

The matrix does not depend on speed or density: it is built once per model.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..errors import InputError, check_number, check_quantity

__all__ = [
    "StructuralDamping",
    "damping_matrix",
    "damping_derivatives",
    "damping_parameters",
    "NO_DAMPING",
]

KINDS = ("none", "modal", "rayleigh", "structural_g")

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
        ``"none"``, ``"modal"``, ``"rayleigh"`` or ``"structural_g"``.
    ratios : tuple of float
        Modal viscous damping ratios [-], lowest mode first (``"modal"``).
    alpha : float
        Mass-proportional coefficient [1/s] (``"rayleigh"``).
    beta : float
        Stiffness-proportional coefficient [s] (``"rayleigh"``).
    g : float
        Structural damping coefficient [-] (``"structural_g"``).
    """

    kind: str = "none"
    ratios: tuple = ()
    alpha: float = 0.0
    beta: float = 0.0
    g: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise InputError(f"damping.kind = {self.kind!r}: allowed values are {list(KINDS)}")
        if self.kind == "modal":
            r = self.ratios
            if isinstance(r, (int, float)) and not isinstance(r, bool):
                r = (r,)
            if isinstance(r, (str, bytes)) or not isinstance(r, Sequence) or len(r) == 0:
                raise InputError(
                    f"damping.ratio = {self.ratios!r}: expected a damping ratio or a list of them"
                )
            vals = tuple(
                check_number(f"damping.ratio[{i}]", v, lo=0.0, hi=1.0, hi_open=True)
                for i, v in enumerate(r)
            )
            object.__setattr__(self, "ratios", vals)
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
        big = [z for z in self.ratios if z > PLAUSIBLE_RATIO] if self.kind == "modal" else []
        if big:
            warnings.warn(
                f"damping.ratio = {big[0]:g} is {100 * big[0]:g} % of critical damping, far "
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
        if self.kind == "rayleigh":
            return f"Rayleigh {self.alpha:g} M + {self.beta:g} K"
        if self.kind == "structural_g":
            return f"g = {self.g:g}"
        return "none"

    def to_dict(self) -> dict:
        out: dict = {"kind": self.kind}
        if self.kind == "modal":
            out["ratio"] = list(self.ratios)
        elif self.kind == "rayleigh":
            out.update(alpha=self.alpha, beta=self.beta)
        elif self.kind == "structural_g":
            out["g"] = self.g
        return out

    def mode_ratios(self, omega: np.ndarray) -> np.ndarray:
        """Damping ratio of each in-vacuo mode of circular frequencies ``omega`` [rad/s]."""
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


def damping_matrix(damping: StructuralDamping, Ms, Ks) -> sp.csr_matrix | None:
    """The structural damping matrix on the structural unknowns, or None without damping.

    Parameters
    ----------
    damping : StructuralDamping
    Ms, Ks : sparse or ndarray (n, n)
        Structural mass and stiffness.
    """
    if not isinstance(damping, StructuralDamping):
        raise InputError(f"damping = {damping!r}: expected an aeroservo StructuralDamping")
    if not damping.active:
        return None
    if damping.kind == "rayleigh":
        return sp.csr_matrix(damping.alpha * Ms + damping.beta * Ks)
    M = Ms.toarray() if sp.issparse(Ms) else np.asarray(Ms, dtype=float)
    K = Ks.toarray() if sp.issparse(Ks) else np.asarray(Ks, dtype=float)
    w2, phi = sla.eigh(K, M)
    omega = np.sqrt(np.clip(w2, 0.0, None))
    c = 2.0 * damping.mode_ratios(omega) * omega
    mp = M @ phi
    return sp.csr_matrix((mp * c) @ mp.T)


GAP = 1e-6
"""In-vacuo eigenvalues closer than this (relative) with different damping ratios: the modal
damping matrix has no derivative (which mode gets which ratio is undecided)."""


def damping_parameters(damping: StructuralDamping) -> dict[str, float]:
    """The damping's own parameters by their file names (``damping.g``, ``damping.ratio`` or
    ``damping.ratio[i]``, ``damping.alpha``, ``damping.beta``) and values; empty if undamped."""
    if not damping.active:
        return {}
    if damping.kind == "modal":
        r = damping.ratios
        if len(r) == 1:
            return {"damping.ratio": r[0]}
        return {f"damping.ratio[{i}]": v for i, v in enumerate(r)}
    if damping.kind == "rayleigh":
        return {"damping.alpha": damping.alpha, "damping.beta": damping.beta}
    return {"damping.g": damping.g}


def damping_derivatives(damping: StructuralDamping, Ms, Ks):
    """Derivatives of the damping matrix, as two functions of one eigen-decomposition.

    Returns
    -------
    (d_structure, d_own)
        ``d_structure(dMs, dKs)`` gives ``dCs/dp`` for a parameter moving the structural matrices
        by ``dMs, dKs`` (Rayleigh: ``alpha dMs + beta dKs``; modal and structural g: the
        eigenvector derivatives of ``Cs = Ms Phi diag(2 zeta_j omega_j) Phi^T Ms``, Nelson's
        closed form through the divided differences of ``f(lambda) = 2 zeta sqrt(lambda)``;
        raises ValueError when two modes of different ratios coincide, see :data:`GAP`).
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
    lam, phi = sla.eigh(K, M)
    lam = np.clip(lam, 0.0, None)
    s = np.sqrt(lam)
    zeta = damping.mode_ratios(s)
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

    def d_structure(dMs, dKs):
        if clash.any():
            i, j = np.argwhere(clash)[0]
            raise ValueError(
                f"in-vacuo modes {i + 1} and {j + 1} have the same frequency and different "
                "damping ratios: the modal damping matrix has no derivative"
            )
        dm = dMs.toarray() if sp.issparse(dMs) else np.asarray(dMs)
        dk = dKs.toarray() if sp.issparse(dKs) else np.asarray(dKs)
        g = (phi.T @ dk @ phi) * d1 - (phi.T @ dm @ phi) * d2
        outer = (dm @ phi * f) @ mp.T
        return sp.csr_matrix(outer + outer.T + mp @ g @ mp.T)

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
