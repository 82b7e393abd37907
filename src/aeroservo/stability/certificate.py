"""The certificate of a stability sweep: the modal model misses no mode that matters.

Two checks, independent of the modal model's own eigenvalues:

* **In the band of the modal model** (frequencies up to 1.1 x its highest mode at rest): at
  checkpoints along the sweep an independent spectrum is computed: the full model's, by dense
  ``eig``, for models up to :data:`DENSE_LIMIT` states; for larger ones that of a modal model
  with twice the modes (a modal convergence check), while every branch eigenvalue in the band
  is recomputed on the full model by inverse iteration. Every eigenvalue of that spectrum that
  is oscillatory and lightly damped (damping ratio below :data:`CERT_ZETA`), and every
  unstable one at any frequency, must be an eigenvalue of the modal model to :data:`MATCH` of
  its modulus. (Shift-invert Arnoldi on the full sparse pencil was tried and rejected: the
  hundreds of nearly equal lag eigenvalues ``-b_i V / b`` of a fine mesh stall ARPACK.)
* **Above the band** (:func:`truncated_modes`): every in-vacuo mode left out must have positive
  aerodynamic damping and keep at least :data:`KEEP_FREQUENCY` of its frequency at every speed
  up to ``v_max`` on its own (single-mode p-k estimate with the exact Theodorsen function). A
  mode left out couples with the kept ones only if its frequency comes down towards theirs,
  and flutters alone only with negative aerodynamic damping.

A mode that fails either check joins the modal model and the sweep is redone
(:func:`aeroservo.stability.boundary.flutter_boundary`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ..system.first_order import compressibility_factors
from .assignment import min_cost_assignment
from .branches import Branches, is_complex
from .modal import ModalBasis, modal_basis

__all__ = [
    "Certificate",
    "certify",
    "checked_basis",
    "truncated_modes",
    "DENSE_LIMIT",
    "CERT_ZETA",
    "MATCH",
]

DENSE_LIMIT = 250
"""Full models up to this many states are certified with dense ``eig``."""

CERT_ZETA = 0.1
"""Full-model eigenvalues with a damping ratio below this must be in the modal model."""

MATCH = 5e-3
"""Largest distance between a full-model eigenvalue and its modal one, relative to modulus."""

KEEP_FREQUENCY = 0.8
"""A mode left out of the modal model must keep this fraction of its in-vacuo frequency."""


@dataclass
class Certificate:
    """Outcome of the checks.

    Attributes
    ----------
    ok : bool
    speeds : list of float
        Checkpoints [m/s].
    method : str
        What the modal model was compared with.
    max_mismatch : float
        Largest relative distance between a checked full-model eigenvalue and its modal one.
    missing : list of (speed, eigenvalue)
        Full-model eigenvalues the modal model lacks.
    n_checked : int
        Full-model eigenvalues checked.
    branch_error : ndarray (m,) or None
        Largest relative distance between each branch's modal eigenvalue and the nearest
        independent one at the checkpoints (NaN where never checked).
    """

    ok: bool = True
    speeds: list = field(default_factory=list)
    method: str = ""
    max_mismatch: float = 0.0
    missing: list = field(default_factory=list)
    n_checked: int = 0
    branch_error: np.ndarray | None = None

    def to_dict(self) -> dict:
        return {
            "ok": self.ok,
            "checkpoints": [float(v) for v in self.speeds],
            "method": self.method,
            "max_mismatch": self.max_mismatch,
            "n_checked": self.n_checked,
            "missing": [
                {"speed": float(v), "frequency": abs(lam.imag) / (2 * np.pi), "real": lam.real}
                for v, lam in self.missing
            ],
        }


def _relevant(lam: np.ndarray, band_top: float) -> np.ndarray:
    """Oscillatory eigenvalues (Im > 0) in the band with a damping ratio below CERT_ZETA, and
    unstable ones at any frequency."""
    low = (-lam.real < CERT_ZETA * np.abs(lam)) & (lam.imag <= band_top)
    return is_complex(lam) & (low | (lam.real >= 0))


def certify(
    reference: Callable[[float], np.ndarray],
    br: Branches,
    exact: np.ndarray,
    values: np.ndarray,
    checkpoints: list[int],
    band_top: float,
    method: str,
) -> Certificate:
    """Check the modal model against an independent spectrum at grid points ``checkpoints``.

    Parameters
    ----------
    reference : callable
        ``reference(v)``: eigenvalues at speed v [m/s] of the full model (dense eig) or, for
        large models, of a modal model with twice the modes.
    br : Branches
        The modal sweep (its ``spectra`` are the modal eigenvalues at each grid point).
    exact, values : ndarray (n_speeds, m)
        Full-model values of the branches where computed (they replace the modal ones).
    checkpoints : list of int
        Grid indices to check.
    band_top : float
        Top of the modal model's band [rad/s].
    method : str
        Description of ``reference`` for the report.
    """
    cert = Certificate(method=method)
    err = np.full(br.eigenvalues.shape[1], np.nan)
    for k in checkpoints:
        v = float(br.speeds[k])
        cert.speeds.append(v)
        modal = np.asarray(br.spectra[k])
        modal = modal[modal.imag >= 0]
        known = np.concatenate([values[k][exact[k]], modal])
        lam_all = reference(v)
        lam_b = br.eigenvalues[k]
        mod = np.abs(lam_b)
        with np.errstate(divide="ignore", invalid="ignore"):  # lam_b = 0 only where skipped
            nearest = np.min(np.abs(lam_all[:, None] - lam_b[None, :]), axis=0) / mod
            d = np.where(
                exact[k],
                np.abs(values[k] - lam_b) / mod,
                np.where(is_complex(lam_b) & (mod <= band_top), nearest, np.nan),
            )
        err = np.fmax(err, d)  # NaN (not checked) keeps the previous value
        lam_f = lam_all[_relevant(lam_all, band_top)]
        cert.n_checked += lam_f.size
        if lam_f.size == 0:
            continue
        cost = np.abs(lam_f[:, None] - known[None, :]) / np.abs(lam_f)[:, None]
        rows, cols = min_cost_assignment(cost)
        dist = np.full(lam_f.size, np.inf)
        dist[rows] = cost[rows, cols]
        for lam, d in zip(lam_f, dist, strict=True):
            if d > MATCH:
                cert.ok = False
                cert.missing.append((v, complex(lam)))
            else:
                cert.max_mismatch = max(cert.max_mismatch, float(d))
    cert.branch_error = err
    return cert


def truncated_modes(model, n_kept: int, density: float, v_max: float, mach: float = 0.0) -> list:
    """In-vacuo modes left out of the modal model that are not safe to leave out.

    For each mode j above the modal model (mass-normalized shape phi), the single-mode p-k
    estimate ``m p^2 + c(V, w) p + k(V, w) = 0`` with the exact Theodorsen function at
    ``k = w b / V`` is evaluated on a speed grid up to ``v_max``; the mode is safe if its
    aerodynamic damping c stays positive and its frequency sqrt(k/m) above
    :data:`KEEP_FREQUENCY` of its in-vacuo one. With compressibility, ``C(k / beta^2) / beta``
    (:mod:`aeroservo.system.first_order`).

    Returns
    -------
    list of (frequency [Hz], reason)
    """
    from .modal import _all_modes

    freqs, phi, _labels = _all_modes(model)
    if phi.shape[1] <= n_kept:
        return []
    w0 = 2 * np.pi * freqs[n_kept:]
    V = np.linspace(v_max / 16, v_max, 16)[:, None]  # speeds down, modes across
    if getattr(model, "dlm", None) is not None:
        w, c = _single_mode_dlm(model, np.arange(n_kept, phi.shape[1]), w0, V, density, mach)
    else:
        w, c = _single_mode_strip(model, n_kept, w0, V, density, mach)
    damped_out = c <= 0
    failed = damped_out | (w <= KEEP_FREQUENCY * w0)
    out = []
    for j in np.flatnonzero(failed.any(axis=0)):  # at the first speed at which it fails
        i = int(np.argmax(failed[:, j]))
        v = V[i, 0]
        why = (
            f"negative aerodynamic damping at {v:.4g} m/s"
            if damped_out[i, j]
            else f"frequency down to {w[i, j] / (2 * np.pi):.4g} Hz at {v:.4g} m/s"
        )
        out.append((float(freqs[n_kept + j]), why))
    return out


def _single_mode_strip(model, n_kept: int, w0, V, rho: float, mach: float) -> tuple:
    """Frequencies [rad/s] and aerodynamic damping of each left-out mode alone, strip theory
    with the exact Theodorsen function (the frequency of the aerodynamics once re-evaluated)."""
    from ..aero.theodorsen import theodorsen_function

    mnc, knc, cnc, groups = _modal_aero(model, n_kept)
    cf, beta2 = compressibility_factors(mach)
    m = 1.0 + rho * mnc
    w = np.broadcast_to(w0, (V.size, w0.size))
    for _ in range(2):  # frequency of the aerodynamic terms: once re-evaluated
        k = w0**2 + rho * V * V * knc
        c = rho * V * cnc
        for b, pq, pd in groups:
            C = theodorsen_function(np.maximum(w * b / (V * beta2), 1e-9)) * cf
            F, G = C.real, C.imag
            k = k + rho * (-V * V * F * pq + w * V * G * pd)
            # a frequency driven to zero (flagged below) gives an infinite, harmless term
            with np.errstate(divide="ignore", invalid="ignore"):
                c = c + rho * (-V * F * pd - (V * V * G / w) * pq)
        w = np.sqrt(np.clip(k / m, 0.0, None))
    return w, c


def _single_mode_dlm(model, cols, w0, V, rho: float, mach: float) -> tuple:
    """As :func:`_single_mode_strip` with the doublet-lattice forces: ``p^2 + c p + k = 0`` with
    ``k = w0^2 - q Re Q_jj``, ``c = -q Im Q_jj / w`` at ``k = w b / V``."""
    q = 0.5 * rho * V * V
    b = model.dlm.b_ref
    w = np.broadcast_to(w0, (V.size, w0.size))
    for _ in range(2):
        Q = model.dlm.diagonal(mach, np.maximum(w * b / V, 1e-9), cols)
        k = w0**2 - q * Q.real
        with np.errstate(divide="ignore", invalid="ignore"):
            c = -q * Q.imag / w
        w = np.sqrt(np.clip(k, 0.0, None))
    return w, c


def _modal_aero(model, n_kept: int) -> tuple:
    """Modal (diagonal) aerodynamic terms of the in-vacuo modes above the first ``n_kept``:
    apparent mass, non-circulatory stiffness and damping, and per circulatory group its
    semichord with the downwash terms (cached on the model: they do not depend on density)."""
    from .modal import _all_modes, model_cache

    cache = model_cache(model)
    key = ("truncated", n_kept)
    if key not in cache:
        rest = _all_modes(model)[1][:, n_kept:]
        am = model.matrices

        def diag(a):
            return np.einsum("ij,ij->j", rest, np.asarray(a @ rest))

        groups = [(g.b, diag(g.Pq), diag(g.Pd)) for g in am.circ_groups]
        cache[key] = (diag(am.Mnc), diag(am.Knc), diag(am.Cnc), groups)
    return cache[key]


def checked_basis(
    src, n_min: int, rho: float, v_max: float, mach: float, enlarged: list, cutoff=None
) -> ModalBasis:
    """The rule's modes, plus every mode the truncation check cannot leave out (an enlargement
    is appended to ``enlarged``)."""
    basis = modal_basis(src, n_min, cutoff)
    n_before = basis.n_modes
    notes = []
    for _ in range(8):
        n_band = int(np.sum(basis.frequencies <= basis.cutoff * (1 + 1e-9)))
        bad = truncated_modes(src, n_band, rho, v_max, mach)
        if not bad:
            break
        f_bad, why = max(bad)
        notes.append(f"{f_bad:.4g} Hz ({why})")
        basis = modal_basis(src, n_min, max(basis.cutoff, 1.01 * f_bad))
    if notes:
        basis = replace(basis, rule=basis.rule + "; kept as well: " + ", ".join(notes))
        enlarged.append(
            {
                "by": "truncation check",
                "modes": [n_before, basis.n_modes],
                "reason": "modes left out must keep their frequency and aerodynamic damping: "
                + ", ".join(notes),
            }
        )
    return basis
