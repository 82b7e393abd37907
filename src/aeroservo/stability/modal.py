"""The modal model the stability sweep runs on, and the rule that says which modes it keeps.

**Which modes.** :func:`mode_rule` sets a band ``f < f_cut = max(3 f_T1, 2 f_F)``: three
times the first torsion frequency ``f_T1`` (flutter of a wing couples bending and torsion modes
up to about twice the torsion frequency) and twice the highest first mode ``f_F`` of a control
surface below ``10 f_T1`` (a flap mode couples with the bending and torsion modes around it, and
the aerodynamic hinge stiffness raises its frequency with speed). Every in-vacuo mode up to
:data:`BUFFER` x ``f_cut`` is kept, never fewer than :data:`MIN_MODES`: the highest modes of a
truncation are its least accurate, so they stay above the band the certificate checks. The
time-domain search and the p-k use the same rule. The stability certificate
(:mod:`aeroservo.stability.certificate`) checks the choice against the full model and enlarges
the band when a mode was missed.

**The modal model.** The structure is projected on those modes (Galerkin; exact at V = 0 for
the kept modes). The lag fields are projected on the smallest subspace that contains the
downwash of the kept modes and is invariant under the lag dynamics (a Krylov space): for a wing
of one semichord that subspace has two dimensions per mode and the projection is exact for the
kept modes (only unobservable lag states, eigenvalues ``-b_i V / b``, are dropped); when it is
not small the lag fields are kept complete. Speeds and densities scale the projected matrices
as they scale the full ones.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..aero.indicial import wagner_set
from ..system.first_order import FirstOrderSystem, first_order
from ..system.matrices import AeroMatrices

__all__ = [
    "MIN_MODES",
    "ModalBasis",
    "ModalSystem",
    "mode_rule",
    "modal_basis",
    "modal_info",
    "modal_system",
]

MIN_MODES = 6
"""The modal model never has fewer modes than this (or all of them, if the model has fewer)."""

BUFFER = 1.3
"""Modes are kept up to this multiple of the band: the highest modes of a Galerkin truncation
are its least accurate, so the band the certificate checks stays below them."""

TORSION_FACTOR = 3.0

FLAP_FACTOR = 2.0
FLAP_RANGE = 10.0


@dataclass(frozen=True)
class ModalBasis:
    """In-vacuo modes kept in the modal model.

    Attributes
    ----------
    shapes : ndarray (n_q, m)
        Mass-normalized mode shapes.
    frequencies : ndarray (m,)
        In-vacuo frequencies [Hz].
    labels : list of str
        Mode names (``"1st torsion"``, ``"1st flap (aileron)"``, ...).
    cutoff : float
        Top of the band [Hz] the modal model must represent (the certificate checks it); modes
        are kept up to :data:`BUFFER` x this.
    rule : str
        How the cut-off was chosen (for reports).
    """

    shapes: np.ndarray
    frequencies: np.ndarray
    labels: list
    cutoff: float
    rule: str

    @property
    def n_modes(self) -> int:
        return self.shapes.shape[1]


def mode_rule(frequencies: np.ndarray, labels: list[str], n_min: int = MIN_MODES) -> tuple:
    """Number of modes the rule keeps, its cut-off [Hz] and a one-line description.

    Parameters
    ----------
    frequencies : ndarray
        In-vacuo frequencies [Hz], increasing.
    labels : list of str
        Their names (a torsion mode's contains ``"torsion"`` or ``"pitch"``, a control
        surface's first mode starts with ``"1st flap"``).
    n_min : int
        Fewest modes kept.
    """
    f = np.asarray(frequencies, dtype=float)
    torsion = [fi for fi, lab in zip(f, labels, strict=True) if "torsion" in lab or "pitch" in lab]
    f_t1 = torsion[0] if torsion else float(f[min(1, f.size - 1)])
    flaps = [
        fi
        for fi, lab in zip(f, labels, strict=True)
        if lab.startswith("1st flap") and fi <= FLAP_RANGE * f_t1
    ]
    cut = max(TORSION_FACTOR * f_t1, FLAP_FACTOR * max(flaps, default=0.0))
    n_band = int(np.sum(f <= BUFFER * cut * (1 + 1e-9)))
    n = max(n_band, min(n_min, f.size))
    why = f"band up to {cut:.4g} Hz = max({TORSION_FACTOR:g} x 1st torsion {f_t1:.4g} Hz"
    why += f", {FLAP_FACTOR:g} x highest 1st flap mode {max(flaps):.4g} Hz)" if flaps else ")"
    why += f"; modes up to {BUFFER:g} x that" + (f", at least {n}" if n > n_band else "")
    return n, cut, why


def model_cache(model) -> dict:
    """The results kept on a model between analyses (they do not depend on the density, or
    carry it in their key)."""
    return model.__dict__.setdefault("_modal_cache", {})


def _all_modes(model) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """All in-vacuo modes of a model (cached on it: they do not depend on density)."""
    cache = model_cache(model)
    if "all" not in cache:
        am: AeroMatrices = model.matrices
        w2, phi = sla.eigh(am.Ks.toarray(), am.Ms.toarray())
        dlm = getattr(model, "dlm", None)
        if dlm is not None:  # a doublet-lattice model has the modes of its aerodynamic basis
            w2, phi = w2[: dlm.n_a], dlm.basis
        freqs = np.sqrt(np.clip(w2, 0.0, None)) / (2 * np.pi)
        labeller = getattr(model, "label_modes", None)
        labels = labeller(phi) if labeller else [f"mode {j + 1}" for j in range(phi.shape[1])]
        cache["all"] = (freqs, phi, list(labels))
    return cache["all"]


def modal_basis(model, n_min: int = MIN_MODES, cutoff: float | None = None) -> ModalBasis:
    """The in-vacuo modes the rule keeps (or every mode up to ``cutoff`` [Hz], if given).

    Parameters
    ----------
    model : AeroelasticModel or TypicalSection
    n_min : int
        Fewest modes kept.
    cutoff : float, optional
        Band top [Hz] to use instead of the rule's, if higher.

    """
    freqs, phi, labels = _all_modes(model)
    n, cut, why = mode_rule(freqs, labels, n_min)
    if cutoff is not None and cutoff > cut:
        n = max(n, int(np.sum(freqs <= BUFFER * cutoff * (1 + 1e-9))))
        cut = cutoff
        why = f"band up to {cutoff:.4g} Hz (enlarged)"
        why += f"; modes up to {BUFFER:g} x that"
    n = min(n, freqs.size)
    return ModalBasis(phi[:, :n], freqs[:n], labels[:n], cut, why)


@dataclass
class ModalSystem:
    """A modal model and the map from its states to the full model's.

    Attributes
    ----------
    system : FirstOrderSystem
        States ``[eta, eta_dot, zeta]``: modal coordinates, their rates and the projected lag
        states (``T`` per lag basis vector).
    basis : ModalBasis or None
        None when the "modal" model is the full one.
    lag_basis : ndarray (n_nodes, r) or None
        Orthonormal lag-field basis (None: lag fields complete).
    n_terms : int
        Wagner terms ``T``.
    lag_map : ndarray or None
        Doublet-lattice models: the full model's lag states of the modal ones (``z = lag_map
        @ zeta``: the kept modes for each of Roger's lag vectors, the identity for
        minimum-state).
    coords : ndarray or None
        Doublet-lattice models: the kept modes' coordinates in the full (modal) model's basis.
    """

    system: FirstOrderSystem
    basis: ModalBasis | None
    lag_basis: np.ndarray | None
    n_terms: int
    lag_map: np.ndarray | None = None
    coords: np.ndarray | None = None

    def lift(self, x: np.ndarray) -> np.ndarray:
        """Full-model state vectors (columns) of modal-model state vectors."""
        if self.basis is None:
            return x
        phi = self.basis.shapes if self.coords is None else self.coords
        m = phi.shape[1]
        x = np.asarray(x)
        one = x.ndim == 1
        X = x[:, None] if one else x
        q = phi @ X[:m]
        v = phi @ X[m : 2 * m]
        z = X[2 * m :]
        if self.lag_map is not None:
            z = self.lag_map @ z
        elif self.lag_basis is not None:
            T = self.n_terms
            r = self.lag_basis.shape[1]
            z = np.einsum("nr,rtk->ntk", self.lag_basis, z.reshape(r, T, -1)).reshape(
                -1, X.shape[1]
            )
        out = np.vstack([q, v, z])
        return out[:, 0] if one else out


def _lag_subspace(am: AeroMatrices, max_fraction: float = 0.6) -> np.ndarray | None:
    """Orthonormal basis of the smallest lag-dynamics-invariant subspace containing the
    downwash of the kept modes, or None if it is not much smaller than the lag space."""
    n = am.n_nodes
    Mz = am.Mz1.toarray()
    G = np.linalg.solve(Mz, am.Lz1.toarray())
    S = np.linalg.solve(Mz, np.hstack([np.asarray(am.E1.todense()), np.asarray(am.F1.todense())]))
    scale = max(np.linalg.norm(S), 1e-300)
    Q = np.zeros((n, 0))
    new = S
    for _ in range(n):
        new = new - Q @ (Q.T @ new)
        new = new - Q @ (Q.T @ new)
        u, s, _vt = np.linalg.svd(new, full_matrices=False)
        keep = s > 1e-11 * scale
        if not keep.any():
            return Q
        Q = np.hstack([Q, u[:, keep]])
        if Q.shape[1] > max_fraction * n:
            return None
        new = G @ u[:, keep]
        scale = max(scale, float(np.linalg.norm(new)))
    return Q


def _project_lags(am: AeroMatrices, Q: np.ndarray) -> AeroMatrices:
    """Lag fields ``z = Q zeta``: the lag equations premultiplied by ``Q^T Mz^-1``."""
    Mz = am.Mz1.toarray()
    r = Q.shape[1]

    def csr(a):
        return sp.csr_matrix(a)

    return replace(
        am,
        Mz1=csr(np.eye(r)),
        Lz1=csr(Q.T @ np.linalg.solve(Mz, am.Lz1.toarray() @ Q)),
        E1=csr(Q.T @ np.linalg.solve(Mz, np.asarray(am.E1.todense()))),
        F1=csr(Q.T @ np.linalg.solve(Mz, np.asarray(am.F1.todense()))),
        W1=csr(np.asarray(am.W1 @ Q)),
        lag_labels=tuple(f"psi{k + 1}" for k in range(r)),
        root=None,
    )


def modal_system(model, density: float, basis: ModalBasis | None, mach: float = 0.0) -> ModalSystem:
    """The modal model of ``model`` at ``density`` [kg/m^3] and compressibility Mach number
    ``mach`` on ``basis`` (None: the full model).

    The projected matrices are cached on the model per basis, so other densities only rescale.
    """
    wagner = wagner_set(model.wagner)
    dlm = getattr(model, "dlm", None)
    n_full = model.matrices.n_q if dlm is None else dlm.n_a
    if basis is None or basis.n_modes >= n_full:
        return ModalSystem(model.system(density, mach), None, None, wagner.n_terms)
    if dlm is not None:
        return _modal_dlm(model, density, basis, mach)
    cache = model_cache(model)
    key = ("matrices", basis.n_modes)
    if key not in cache:
        am = model.matrices.project(basis.shapes)
        Q = _lag_subspace(am)
        if Q is not None:
            am = _project_lags(am, Q)
        cache[key] = (am, Q)
    am, Q = cache[key]
    skey = ("system", basis.n_modes, float(density), float(mach))
    if skey not in cache:
        cache[skey] = first_order(am, wagner, density, model.semichord, mach=mach)
    return ModalSystem(cache[skey], basis, Q, wagner.n_terms)


def _modal_dlm(model, density: float, basis: ModalBasis, mach: float) -> ModalSystem:
    """The modal model of a doublet-lattice model: its lowest modes (exact for the kept modes:
    Roger's lag vectors stay in their span)."""
    from ..system.rfa_system import rfa_first_order

    fit = model.dlm_fit(mach)
    cache = model_cache(model)
    key = ("dlm-system", basis.n_modes, float(density), float(fit.mach))
    if key not in cache:
        dlm = model.dlm
        am = model.matrices
        C = dlm.basis.T @ (am.Ms @ basis.shapes)  # the kept modes in the aerodynamic basis
        phi = basis.shapes
        m = phi.shape[1]

        def both(a):
            return phi.T @ (a.toarray() @ phi)

        system = rfa_first_order(
            both(am.Ms),
            both(am.Ks),
            None if am.Cs is None else both(am.Cs),
            dlm.modal_fit(fit.mach, C),
            density,
            dlm.b_ref,
            tuple(f"eta_{j + 1}" for j in range(m)),
            semichord=model.semichord,
            mach=fit.mach,
        )
        kron = np.eye(fit.forces.roots.size)
        lag_map = kron if fit.forces.kind == "minimum-state" else np.kron(kron, C)
        cache[key] = (system, C, lag_map)
    system, C, lag_map = cache[key]
    return ModalSystem(system, basis, None, 0, lag_map, C)


def modal_info(modal: ModalSystem) -> dict:
    b = modal.basis
    if b is None:
        return {
            "n_modes": modal.system.n_q,
            "rule": "full model",
            "n_states": modal.system.n_states,
        }
    return {
        "n_modes": b.n_modes,
        "cutoff_hz": b.cutoff,
        "rule": b.rule,
        "n_states": modal.system.n_states,
        "lag_states": "projected" if modal.lag_basis is not None else "complete",
    }
