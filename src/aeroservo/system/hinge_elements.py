"""Nonlinear hinge elements of a model: where each law acts and on which rotation.

Each element is a spring of linear stiffness ``k`` acting on one rotation ``s = r @ q`` of a
control surface (an actuator's station on a wing, the flap of a typical section). The linear
model keeps every spring closed; the element adds the moment ``phi(s) = k s - M(s)`` on that
rotation (``docs/freeplay.md``), so the first-order system reads (Lur'e form)

    x' = A(V) x + B_n phi(C_n x),      B_n = E^-1 [0; r^T; 0],   C_n = [r, 0, 0].

Everything here is independent of speed; :meth:`HingeElements.lure` gives ``B_n`` and ``C_n``
for a first-order system once.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from ..errors import InputError
from ..structure.hinge_laws import HingeLaw, check_law
from .assembly import actuator_row

__all__ = ["NonlinearHinge", "HingeElements", "hinge_elements"]


@dataclass(frozen=True)
class NonlinearHinge:
    """A nonlinear law on a hinge or actuator.

    Parameters
    ----------
    target : str
        An actuator's name, a control surface's name (the law on each of its actuators) or,
        for a typical section, ``"flap"``.
    law : Freeplay, Bilinear or Cubic
        The restoring moment (:mod:`aeroservo.structure.hinge_laws`).
    """

    target: str
    law: HingeLaw

    def __post_init__(self) -> None:
        if not isinstance(self.target, str) or not self.target:
            raise InputError(f"hinge target = {self.target!r}: expected a surface or actuator name")
        check_law(f"hinge '{self.target}'.law", self.law)


@dataclass(frozen=True)
class HingeElements:
    """The nonlinear elements of one model (speed independent).

    Attributes
    ----------
    names : tuple of str
        One per element (the actuator's name, or ``"flap"``).
    rows : ndarray (n_e, n_q)
        ``s = rows @ q``: the rotation [rad] each element acts on.
    stiffness : ndarray (n_e,)
        Linear stiffness k [N m/rad] the law replaces (kept in the linear model).
    laws : tuple
    """

    names: tuple[str, ...]
    rows: np.ndarray
    stiffness: np.ndarray
    laws: tuple

    @property
    def n(self) -> int:
        return len(self.names)

    @property
    def piecewise_linear(self) -> bool:
        return all(law.piecewise_linear for law in self.laws)

    def correction(self, s: np.ndarray) -> np.ndarray:
        """``phi(s) = k s - M(s)`` [N m] per element at the rotations ``s`` [rad]."""
        s = np.asarray(s, dtype=float)
        return np.array(
            [
                k * v - law.moment(v, k)
                for k, v, law in zip(self.stiffness, s, self.laws, strict=True)
            ]
        )

    def moment(self, s: np.ndarray) -> np.ndarray:
        """Hinge moments ``M(s)`` [N m] per element (rows of ``s``: elements)."""
        s = np.asarray(s, dtype=float)
        return np.array(
            [law.moment(v, k) for k, v, law in zip(self.stiffness, s, self.laws, strict=True)]
        )

    def lure(self, system) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(B_n, C_n, C_rate)`` on the states of a first-order system: the moment input,
        the rotations and their rates (dense, ``(n, n_e)``, ``(n_e, n)``, ``(n_e, n)``)."""
        n, n_q = system.n_states, system.n_q
        if self.rows.shape[1] != n_q:
            raise InputError(
                f"hinge elements: {self.rows.shape[1]} structural unknowns, the system has {n_q}"
            )
        f = np.zeros((n, self.n))
        f[n_q : 2 * n_q] = self.rows.T
        lu = spla.splu(system.E.tocsc())
        b_n = lu.solve(f)
        c_n = np.zeros((self.n, n))
        c_rate = np.zeros((self.n, n))
        c_n[:, :n_q] = self.rows
        c_rate[:, n_q : 2 * n_q] = self.rows
        return b_n, c_n, c_rate

    def project(self, basis: np.ndarray) -> HingeElements:
        """The elements on modal coordinates ``q = basis @ eta``."""
        return HingeElements(self.names, self.rows @ basis, self.stiffness, self.laws)


def hinge_elements(model, hinges: Sequence[NonlinearHinge]) -> HingeElements:
    """The elements of ``hinges`` on ``model`` (an AeroelasticModel or a TypicalSection).

    A surface's name puts the law on each of its actuators; an actuator named twice, an
    unknown name, a surface without actuators or a section without a flap is refused.
    """
    if isinstance(hinges, NonlinearHinge):
        hinges = [hinges]
    hinges = list(hinges)
    if not hinges:
        raise InputError("hinges: give at least one NonlinearHinge")
    for i, h in enumerate(hinges):
        if not isinstance(h, NonlinearHinge):
            raise InputError(f"hinges[{i}] = {h!r}: expected an aeroservo NonlinearHinge")
    if hasattr(model, "wing"):
        names, rows, ks, laws = _wing_elements(model, hinges)
    else:
        names, rows, ks, laws = _section_elements(model, hinges)
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise InputError(f"hinges: actuator {sorted(dup)[0]!r} is given more than one law")
    return HingeElements(tuple(names), np.array(rows), np.array(ks, dtype=float), tuple(laws))


def _wing_elements(model, hinges):
    wing, mesh, n_q = model.wing, model.mesh, model.n_dofs
    surfaces = {cs.name: i for i, cs in enumerate(wing.control_surfaces)}
    actuators = {a.name: (i, a) for i, cs in enumerate(wing.control_surfaces) for a in cs.actuators}
    names, rows, ks, laws = [], [], [], []
    for h in hinges:
        if h.target in actuators:
            chosen = [actuators[h.target]]
        elif h.target in surfaces:
            i = surfaces[h.target]
            chosen = [(i, a) for a in wing.control_surfaces[i].actuators]
            if not chosen:
                raise InputError(
                    f"hinge '{h.target}': the surface has no actuators; a nonlinear law acts on "
                    "an actuator (the distributed hinge stiffness stays linear)"
                )
        else:
            known = sorted(actuators) + sorted(surfaces)
            raise InputError(
                f"hinge target = {h.target!r}: not an actuator or surface of wing "
                f"'{wing.name}' (known: {', '.join(known) or 'none'})"
            )
        for i, a in chosen:
            names.append(a.name)
            rows.append(actuator_row(wing, mesh, n_q, i, a))
            ks.append(a.stiffness)
            laws.append(h.law)
    return names, rows, ks, laws


def _section_elements(model, hinges):
    if getattr(model, "hinge", None) is None:
        raise InputError("hinges: the section has no flap (give TypicalSection(hinge=...))")
    if len(hinges) != 1 or hinges[0].target != "flap":
        raise InputError(
            f"hinges: a typical section has one nonlinear hinge, target 'flap'; got "
            f"{[h.target for h in hinges]}"
        )
    row = np.zeros(model.n_dofs)
    row[2] = 1.0
    return ["flap"], [row], [model.k_flap], [hinges[0].law]
