"""The wing stick model: a wing, its mesh, and the speed-independent matrices built once."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import scipy.linalg as sla

from ..aero.dlm_settings import DoubletLattice, as_aero
from ..aero.indicial import IndicialSet, wagner_set
from ..aero.swept_strip import check_sweep_terms
from ..errors import MAX_ELEMENTS, InputError, check_int, check_number
from ..structure.mesh import Mesh, build_mesh
from ..structure.wing import Wing
from .assembly import assemble, element_properties
from .damping import NO_DAMPING, StructuralDamping, damping_matrix
from .first_order import FirstOrderSystem, check_mach, first_order
from .matrices import AeroMatrices, without_strip_aero

__all__ = ["AeroelasticModel", "NaturalModes"]


@dataclass(frozen=True)
class NaturalModes:
    """Natural modes of the structure.

    Attributes
    ----------
    frequencies : ndarray (n_modes,)
        Natural frequencies [Hz].
    shapes : ndarray (n_q, n_modes)
        Mass-normalized mode shapes (structural unknowns, see ``dof_labels``).
    labels : list of str
        E.g. ``"1st bending"``, ``"1st torsion"``, ``"1st flap (aileron)"``.
    """

    frequencies: np.ndarray
    shapes: np.ndarray
    labels: list[str]


class AeroelasticModel:
    """Aeroelastic beam finite-element model of a cantilever wing.

    Parameters
    ----------
    wing : Wing
        Geometry, structure and control surfaces (SI units).
    n_elements : int
        Number of beam elements along the span (default 10).
    wagner : str, mapping or IndicialSet
        Wagner approximation: ``"rt_jones"`` (default), ``"wp_jones"``, ``"one_term"``,
        ``"fit2"``, ``"fit3"``, ``"fit4"``, or ``{"A": [...], "b": [...]}``.
    damping : StructuralDamping, optional
        Structural damping (:mod:`aeroservo.system.damping`); default none.
    sweep_terms : {"full", "classical"}
        Spanwise-convection terms of swept segments: all of them (default), or the bending
        slope's alone, as the classical divergence closed form (``docs/sweep.md``).
    aero : {"strip", "dlm"} or DoubletLattice
        Aerodynamic model: 2-D strip theory with Wagner lag states (default), or the
        doublet-lattice method with a rational-function approximation (``"dlm"`` with default
        settings, or :class:`aeroservo.aero.dlm_settings.DoubletLattice`; ``docs/dlm.md``).
    load_stations : sequence of float
        Spanwise stations [m] where loads are wanted: the mesh gets a node at each (with
        ``n_elements`` kept), so that ``shear_at_<x>``, ``bending_moment_at_<x>`` and
        ``torque_at_<x>`` are outputs (any node's loads are).

    Notes
    -----
    The structural and aerodynamic matrices do not depend on speed or density; they are
    assembled here once. :meth:`system` scales them for a density (cached) and the state matrix
    at speed V is ``A(V) = A0 + V A1 + V^2 A2``. With the doublet-lattice model the Mach number
    of :meth:`system` is the doublet lattice's (its AICs and fit are made once per Mach number).
    """

    def __init__(
        self,
        wing: Wing,
        n_elements: int = 10,
        wagner: object = "rt_jones",
        damping: StructuralDamping | None = None,
        *,
        sweep_terms: str = "full",
        aero: object = "strip",
        load_stations: Sequence[float] = (),
    ):
        if not isinstance(wing, Wing):
            raise InputError(f"wing = {wing!r}: expected an aeroservo.Wing")
        self.wing = wing
        self.n_elements = check_int("n_elements", n_elements, lo=1, hi=MAX_ELEMENTS)
        self.wagner: IndicialSet = wagner_set(wagner)
        self.damping = NO_DAMPING if damping is None else damping
        if isinstance(load_stations, (str, bytes)) or not hasattr(load_stations, "__iter__"):
            raise InputError(
                f"load_stations = {load_stations!r}: expected a list of spanwise stations [m]"
            )
        self.load_stations = tuple(
            sorted(
                {
                    check_number("load_stations", x, unit="m", lo=0.0, hi=wing.span)
                    for x in load_stations
                }
            )
        )
        self.mesh: Mesh = build_mesh(wing, self.n_elements, self.load_stations)
        self.sweep_terms = check_sweep_terms(sweep_terms)
        am = assemble(wing, self.mesh, sweep_terms=self.sweep_terms)
        self.matrices: AeroMatrices = replace(
            am, Cs=damping_matrix(self.damping, am.Ms, am.Ks, am.dof_labels)
        )
        self.properties = element_properties(wing, self.mesh)
        self._systems: dict[tuple[float, float], FirstOrderSystem] = {}
        self._parts: dict | None = None  # stiffness parts for label_modes
        self.aero: DoubletLattice | None = as_aero(aero)
        self.dlm = None
        if self.aero is not None:
            from .dlm_forces import DLMAerodynamics

            self.dlm = DLMAerodynamics(
                wing,
                self.mesh,
                self.aero,
                self.semichord,
                self.vacuum_modes(),
                self.rigid_motions(),
            )
            self.matrices = without_strip_aero(self.matrices)

    @property
    def aero_model(self) -> str:
        """``"strip"`` or ``"dlm"``."""
        return "strip" if self.aero is None else "dlm"

    def __repr__(self) -> str:
        damping = "" if not self.damping.active else f", damping={self.damping.describe()!r}"
        aero = f"wagner={self.wagner.name!r}" if self.aero is None else "aero='dlm'"
        return (
            f"AeroelasticModel({self.wing.name!r}, n_elements={self.n_elements}, "
            f"{aero}{damping}, n_states={self.n_states})"
        )

    @property
    def n_dofs(self) -> int:
        """Structural unknowns after the root clamp."""
        return self.matrices.n_q

    @property
    def n_states(self) -> int:
        """States of the first-order system: 2 x structural + aerodynamic lag states (Wagner
        terms x nodes; with the doublet lattice, Roger's lags x unknowns or the minimum-state
        roots)."""
        if self.dlm is not None:
            n = self.dlm.n_a
            return 2 * n + self.aero.lags * (n if self.aero.rfa == "roger" else 1)
        return 2 * self.n_dofs + self.wagner.n_terms * self.mesh.n_nodes

    @property
    def semichord(self) -> float:
        """Span-averaged semichord [m]."""
        return float(np.sum(self.properties["b"] * self.mesh.lengths) / self.wing.span)

    def system(self, density: float, mach: float = 0.0) -> FirstOrderSystem:
        """First-order system at air density ``density`` [kg/m^3] and the Mach number ``mach``
        of the compressibility correction (0: incompressible), cached."""
        rho = check_number("density", density, unit="kg/m^3", lo=0.0, lo_open=True)
        if self.aero is not None:
            return self._dlm_system(rho, mach)
        mach = check_mach(mach)
        key = (rho, mach)
        if key not in self._systems:
            self._systems[key] = first_order(
                self.matrices, self.wagner, rho, self.semichord, mach=mach
            )
        return self._systems[key]

    def dlm_fit(self, mach: float = 0.0):
        """The doublet-lattice forces' rational approximation at a Mach number
        (:class:`aeroservo.system.dlm_forces.DLMFit`; its AICs computed once and cached)."""
        if self.dlm is None:
            raise InputError("dlm_fit: this model's aerodynamics is strip theory (aero='strip')")
        return self.dlm.fit(mach)

    def rigid_motions(self) -> np.ndarray:
        """The wing's rigid-body motions that move the clamped root by a unit ``w``, ``theta``
        and ``phi`` (heave, pitch and roll about the root), on the free unknowns then the root's
        three, (n_q + 3, 3): the free part ``-Ks^-1 Ks_fr`` (static condensation; the wing moves
        rigidly because nothing else holds it). Projected on them, the loads on the wing give the
        root loads by force summation (``docs/dlm.md``)."""
        am = self.matrices
        free = -np.linalg.solve(am.Ks.toarray(), am.root.Ks.toarray().T)
        return np.vstack([free, np.eye(3)])

    def vacuum_modes(self) -> np.ndarray:
        """Every in-vacuo mode shape, mass-normalized, by increasing frequency (cached)."""
        if getattr(self, "_vacuum", None) is None:
            am = self.matrices
            self._vacuum = sla.eigh(am.Ks.toarray(), am.Ms.toarray())[1]
        return self._vacuum

    def _dlm_system(self, rho: float, mach: float) -> FirstOrderSystem:
        """The doublet-lattice model: modal, on the aerodynamic basis (its first unknowns are
        the modal coordinates ``eta_j`` of the lowest in-vacuo modes)."""
        from .rfa_system import rfa_first_order

        fit = self.dlm_fit(mach)
        key = (rho, fit.mach)
        if key not in self._systems:
            am = self.matrices
            phi = self.dlm.basis
            n = phi.shape[1]

            def both(a):
                return phi.T @ (a.toarray() @ phi)

            self._systems[key] = rfa_first_order(
                both(am.Ms),
                both(am.Ks),
                None if am.Cs is None else both(am.Cs),
                self.dlm.modal_fit(fit.mach, np.eye(n)),
                rho,
                self.dlm.b_ref,
                tuple(f"eta_{j + 1}" for j in range(n)),
                semichord=self.semichord,
                mach=fit.mach,
            )
        return self._systems[key]

    def state_matrix(self, speed: float, density: float, mach: float = 0.0) -> np.ndarray:
        """Dense state matrix A(V) [1/s] at ``speed`` [m/s] and ``density`` [kg/m^3]."""
        v = check_number("speed", speed, unit="m/s", lo=0.0)
        return self.system(density, mach).state_matrix(v)

    def natural_modes(self, n_modes: int = 6) -> NaturalModes:
        """In-vacuo natural modes (structural mass and stiffness only).

        Parameters
        ----------
        n_modes : int
            Number of lowest modes.
        """
        n = check_int("n_modes", n_modes, lo=1, hi=self.n_dofs)
        # every mode by the divide-and-conquer driver, then the lowest n: LAPACK's subset
        # driver (gvx) lost 5e-5 of the lowest frequency of a 200-element shaft with a tip disk
        # (tests/test_masses.py) where the full solve keeps 1e-8
        w2, phi = sla.eigh(self.matrices.Ks.toarray(), self.matrices.Ms.toarray(), driver="gvd")
        w2, phi = w2[:n], phi[:, :n]
        freqs = np.sqrt(np.clip(w2, 0.0, None)) / (2 * np.pi)
        return NaturalModes(freqs, phi, self.label_modes(phi))

    def label_modes(self, shapes: np.ndarray) -> list[str]:
        """Name mode shapes by the dominant share of their strain energy.

        Bending (EI w''^2), torsion (GJ phi'^2) or a flap (hinge springs, actuators, G_f J_f);
        numbered in order of appearance, e.g. ``"2nd bending"``.

        Parameters
        ----------
        shapes : ndarray (n_q, n_modes)
        """
        if getattr(self, "_parts", None) is None:  # dense copies of small ones: cheaper products
            small = self.n_dofs <= 200
            self._parts = {
                k: v.toarray() if small else v for k, v in self.matrices.stiffness_parts.items()
            }
        shapes = np.asarray(shapes)
        energies = {
            name: np.real(np.einsum("ij,ij->j", shapes.conj(), np.asarray(k @ shapes)))
            for name, k in self._parts.items()
        }
        counts: dict[str, int] = {}
        labels = []
        for j in range(shapes.shape[1]):
            energy = {name: float(e[j]) for name, e in energies.items()}
            kind = max(energy, key=energy.get)
            counts[kind] = counts.get(kind, 0) + 1
            labels.append(f"{_ordinal(counts[kind])} {kind}")
        return labels

    def nodal_fields(self, q: np.ndarray) -> dict[str, np.ndarray]:
        """Split a structural vector into nodal fields (zeros where an unknown is absent).

        Returns a dict with ``"x"`` (stations [m]), ``"w"`` [m], ``"theta"`` [rad], ``"phi"``
        [rad] and ``"delta_<surface>"`` [rad] arrays over the nodes.
        """
        q = np.asarray(q)
        m = self.mesh

        def take(idx: np.ndarray) -> np.ndarray:
            out = np.zeros(idx.shape, dtype=q.dtype)
            out[idx >= 0] = q[idx[idx >= 0]]
            return out

        fields = {
            "x": m.nodes.copy(),
            "w": take(m.dof_w),
            "theta": take(m.dof_theta),
            "phi": take(m.dof_phi),
        }
        for k, cs in enumerate(self.wing.control_surfaces):
            fields[f"delta_{cs.name}"] = take(m.dof_delta[k])
        return fields

    def mode_fields(self, shapes: np.ndarray) -> dict[str, np.ndarray]:
        """Nodal fields of mode shapes (columns of ``shapes``, real or complex), each scaled so
        that its largest deflection or rotation (``w`` in m, ``phi`` and the flap rotations in
        rad; the slope is left out) is real and equal to 1.

        Returns a dict with ``"x"`` (n_nodes,) [m] and ``"w"``, ``"phi"``, ``"delta_<surface>"``
        (n_nodes, n_modes).
        """
        shapes = np.asarray(shapes)
        cols = []
        for j in range(shapes.shape[1]):
            fld = {
                k: v for k, v in self.nodal_fields(shapes[:, j]).items() if k not in ("x", "theta")
            }
            values = np.concatenate(list(fld.values()))
            top = values[int(np.argmax(np.abs(values)))]
            cols.append({k: v / top for k, v in fld.items()})
        out = {"x": self.mesh.nodes.copy()}
        out.update({k: np.stack([c[k] for c in cols], axis=1) for k in cols[0]})
        return out


def _ordinal(n: int) -> str:
    suffix = "th" if 10 <= n % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"
