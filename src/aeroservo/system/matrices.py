"""Speed- and density-independent matrices of a linear aeroelastic model (structure, apparent
mass, circulatory strips, lag fields) and their Galerkin projection onto a modal basis.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp

__all__ = ["AeroMatrices", "StripGroup", "StripOnly", "without_strip_aero"]


@dataclass(frozen=True)
class StripGroup:
    """Circulatory matrices of the strips that share one semichord.

    Attributes
    ----------
    b : float
        Semichord [m].
    Pq, Pd : sparse (n, n_q)
        Circulatory stiffness and damping per unit C(k): the harmonic load on the right-hand side
        is ``rho C(omega b / V) (V^2 Pq + i omega V Pd) q``.
    Gw : ndarray (n,)
        Circulatory load distribution ``int N^T w dx`` (the load of a unit circulatory downwash,
        per unit ``rho V b``); it carries gust loads.
    """

    b: float
    Pq: sp.csr_matrix
    Pd: sp.csr_matrix
    Gw: np.ndarray


@dataclass(frozen=True)
class AeroMatrices:
    """Speed- and density-independent matrices of a linear aeroelastic model.

    Structural unknowns q (``n_q``) and lag nodes (``n_nodes``). Aerodynamic matrices are per
    unit density; the factor of speed each multiplies is given below.

    Attributes
    ----------
    Ms, Ks : sparse (n_q, n_q)
        Structural mass and stiffness (hinge springs and actuators included).
    Mnc, Cnc, Knc : sparse (n_q, n_q)
        Non-circulatory apparent mass (x rho), damping (x rho V), stiffness (x rho V^2).
    circ_groups : tuple of StripGroup
        Circulatory matrices grouped by semichord.
    Mz1, Lz1 : sparse (n_nodes, n_nodes)
        Lag-field Gram matrix and Gram matrix weighted by 1/b [1/m].
    E1, F1 : sparse (n_nodes, n_q)
        Downwash projections: ``int Nz^T r_q N`` and ``int Nz^T r_d N``.
    W1 : sparse (n_q, n_nodes)
        Circulatory load distribution ``int N^T w Nz``.
    stiffness_parts : dict of sparse
        ``Ks`` split by origin (e.g. ``"bending"``, ``"torsion"``, ``"flap (aileron)"``), used to
        name modes by their strain energy.
    Cs : sparse (n_q, n_q) or None
        Structural damping (:mod:`aeroservo.system.damping`); None: undamped.
    root : AeroMatrices or None
        The same matrices restricted to the rows of the clamped root unknowns ``(w, theta,
        phi)`` (3 rows each): the root reactions are ``Ks q + Ms qdd - f_aero`` on those rows.
    weight : ndarray (n_q,) or None
        The loads of a unit vertical acceleration of every point of the wing, per unit
        acceleration [kg] (upward; ``-g weight`` is the wing's weight), ``M r`` with ``r`` the
        rigid vertical translation; on the reaction rows of ``root`` and ``cuts`` too.
    cuts : AeroMatrices or None
        The same for a cut at every node j (rows ``3j .. 3j + 2``, from the elements outboard
        of it): the shear, bending moment and torque the wing carries there (zero at the tip).
    basis : ndarray (n_full, n_q) or None
        Set when the structural unknowns are modal coordinates ``q_full = basis @ q``.
    """

    Ms: sp.csr_matrix
    Ks: sp.csr_matrix
    Mnc: sp.csr_matrix
    Cnc: sp.csr_matrix
    Knc: sp.csr_matrix
    circ_groups: tuple
    Mz1: sp.csr_matrix
    Lz1: sp.csr_matrix
    E1: sp.csr_matrix
    F1: sp.csr_matrix
    W1: sp.csr_matrix
    dof_labels: tuple[str, ...]
    lag_labels: tuple[str, ...]
    stiffness_parts: dict = field(default_factory=dict)
    Cs: sp.csr_matrix | None = None
    root: AeroMatrices | None = None
    cuts: AeroMatrices | None = None
    basis: np.ndarray | None = None
    weight: np.ndarray | None = None

    @property
    def n_q(self) -> int:
        return self.Ms.shape[1]

    @property
    def n_nodes(self) -> int:
        return self.Mz1.shape[0]

    @property
    def Pq(self) -> sp.csr_matrix:
        return sum((g.Pq for g in self.circ_groups), sp.csr_matrix(self.Ms.shape))

    @property
    def Pd(self) -> sp.csr_matrix:
        return sum((g.Pd for g in self.circ_groups), sp.csr_matrix(self.Ms.shape))

    @property
    def Gw(self) -> np.ndarray:
        """Total circulatory load distribution (all strips)."""
        return sum(g.Gw for g in self.circ_groups)

    def reaction_rows(self, nodes: tuple[int, ...] = ()) -> AeroMatrices:
        """The root rows, then the cut rows of each node in ``nodes`` (3 per node): the
        matrices of the internal loads at the root and at those nodes."""
        if not nodes:
            return self.root
        idx = np.concatenate([[3 * j, 3 * j + 1, 3 * j + 2] for j in nodes])
        rt, cut = self.root, self.cuts

        def stack(a, b):
            return sp.vstack([a, sp.csr_matrix(b)[idx]]).tocsr()

        groups = tuple(
            StripGroup(g.b, stack(g.Pq, h.Pq), stack(g.Pd, h.Pd), np.r_[g.Gw, h.Gw[idx]])
            for g, h in zip(rt.circ_groups, cut.circ_groups, strict=True)
        )
        return replace(
            rt,
            Ms=stack(rt.Ms, cut.Ms),
            Ks=stack(rt.Ks, cut.Ks),
            Mnc=stack(rt.Mnc, cut.Mnc),
            Cnc=stack(rt.Cnc, cut.Cnc),
            Knc=stack(rt.Knc, cut.Knc),
            W1=stack(rt.W1, cut.W1),
            circ_groups=groups,
            weight=None if rt.weight is None else np.r_[rt.weight, cut.weight[idx]],
        )

    def project(self, basis: np.ndarray, labels: tuple[str, ...] | None = None) -> AeroMatrices:
        """Galerkin projection of the structural unknowns onto ``q = basis @ eta``.

        The lag fields are kept complete (consistent with the projected downwash).

        Parameters
        ----------
        basis : ndarray (n_q, r)
            E.g. in-vacuo mode shapes.
        labels : tuple of str, optional
            Names of the new unknowns (default ``eta_1 .. eta_r``).
        """
        phi = np.asarray(basis, dtype=float)
        r = phi.shape[1]

        def both(m):
            return sp.csr_matrix(phi.T @ (m @ phi))

        def cols(m):
            return sp.csr_matrix(np.asarray(m @ phi))

        groups = tuple(
            StripGroup(g.b, both(g.Pq), both(g.Pd), phi.T @ g.Gw) for g in self.circ_groups
        )

        def rows(rt):
            if rt is None:
                return None
            return replace(
                rt,
                Ms=cols(rt.Ms),
                Ks=cols(rt.Ks),
                Mnc=cols(rt.Mnc),
                Cnc=cols(rt.Cnc),
                Knc=cols(rt.Knc),
                circ_groups=tuple(
                    StripGroup(g.b, cols(g.Pq), cols(g.Pd), g.Gw) for g in rt.circ_groups
                ),
                stiffness_parts={},
                Cs=None,
            )

        full = phi if self.basis is None else self.basis @ phi
        return replace(
            self,
            Ms=both(self.Ms),
            Ks=both(self.Ks),
            Mnc=both(self.Mnc),
            Cnc=both(self.Cnc),
            Knc=both(self.Knc),
            circ_groups=groups,
            E1=cols(self.E1),
            F1=cols(self.F1),
            W1=sp.csr_matrix(phi.T @ self.W1),
            dof_labels=labels or tuple(f"eta_{j + 1}" for j in range(r)),
            stiffness_parts={k: both(v) for k, v in self.stiffness_parts.items()},
            Cs=None if self.Cs is None else both(self.Cs),
            root=rows(self.root),
            cuts=rows(self.cuts),
            basis=full,
            weight=None if self.weight is None else phi.T @ self.weight,
        )


class StripOnly:
    """Stands in for a strip-theory matrix in a model whose aerodynamics is another theory
    (the doublet-lattice method): any use raises one clear line instead of computing with
    strip aerodynamics the model does not have."""

    def __init__(self, name: str):
        self._name = name

    def _fail(self, *args, **kwargs):
        from ..errors import InputError

        raise InputError(
            f"strip-theory matrix {self._name!r} used on a model with aero = 'dlm': this "
            "analysis does not support the doublet-lattice model (use aero = 'strip')"
        )

    def __getattr__(self, name: str):
        if name.startswith("__"):
            raise AttributeError(name)
        self._fail()

    __add__ = __radd__ = __sub__ = __rsub__ = __mul__ = __rmul__ = _fail
    __matmul__ = __rmatmul__ = __neg__ = __iter__ = __len__ = __getitem__ = __array__ = _fail

    def __repr__(self) -> str:
        return f"StripOnly({self._name!r})"


def without_strip_aero(am: AeroMatrices) -> AeroMatrices:
    """``am`` with its strip aerodynamic matrices replaced by :class:`StripOnly` (structure
    kept): the matrices of a model whose aerodynamics is not strip theory."""
    names = ("Mnc", "Cnc", "Knc", "circ_groups", "Mz1", "Lz1", "E1", "F1", "W1")
    root, cuts = (
        None if rt is None else replace(rt, **{k: StripOnly(k) for k in names})
        for rt in (am.root, am.cuts)
    )
    return replace(am, root=root, cuts=cuts, **{k: StripOnly(k) for k in names})
