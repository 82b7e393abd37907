"""The flutter and divergence boundary of a model at one air density.

:func:`flutter_boundary` runs in four steps:

1. **Divergence**: every static divergence speed, exactly, from the steady equations
   (:mod:`aeroservo.stability.divergence`); it also sets the default speed range.
2. **Sweep**: the eigenvalues of a modal model (:mod:`aeroservo.stability.modal`: every mode up
   to a physical frequency cut-off) are computed with dense ``eig`` at every speed of an
   adaptive grid and followed as branches (:mod:`aeroservo.stability.branches`); nothing has to
   converge, so coalescences on the real axis, overdamped modes and flutter above divergence
   pass without trouble.
3. **Decisions on the full model**: wherever a branch is near the imaginary axis its eigenvalue
   is recomputed on the full model, and every crossing and hump is found by root finding on the
   full model's eigenvalue to a relative tolerance ``rtol`` (:mod:`aeroservo.stability.crossings`).
4. **Certificate**: at checkpoints the full model's lightly damped and unstable eigenvalues are
   computed independently and must all be in the modal model; if one is missing, the sweep is
   redone with more modes (:mod:`aeroservo.stability.certificate`).

If the sweep cannot go on (a non-finite eigenvalue, a branch the full model does not confirm),
everything found below that speed is returned with ``searched_up_to`` and a warning.

Damping convention: ``damping_ratio = -Re(lambda) / |lambda|`` (positive: stable);
V-g plots show ``g = -2 zeta`` (positive: unstable).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._threads import blas_limited
from ..errors import RANGES, InputError, check_int, check_number, check_quantity
from ..system.first_order import FirstOrderSystem
from .branches import Branches, is_complex, sweep_branches
from .certificate import DENSE_LIMIT, Certificate, certify, checked_basis
from .crossings import VerificationError, Verifier, branch_crossings, sign_changes
from .divergence import divergence_speeds
from .modal import MIN_MODES, ModalBasis, ModalSystem, modal_basis, modal_info, modal_system
from .near_critical import near_critical
from .result import Crossing, FlutterResult
from .tracking import EigenTracker

__all__ = ["flutter_boundary", "sign_changes", "default_v_max"]

CHECKPOINTS = (0.25, 0.5, 0.75, 1.0)
"""Fractions of the speed range at which the certificate checks the modal model."""

MAX_ENLARGE = 3
"""Times the certificate may enlarge the modal model before the full model is used."""


def _as_system(
    model: object, density: float | None, mach: float = 0.0
) -> tuple[FirstOrderSystem, object]:
    """The full first-order system, and the model it comes from (None for a bare system)."""
    if isinstance(model, FirstOrderSystem):
        return model, None
    if not hasattr(model, "system") or not hasattr(model, "matrices"):
        raise InputError(
            f"model = {model!r}: expected an AeroelasticModel, a TypicalSection or a "
            "FirstOrderSystem"
        )
    if density is None:
        raise InputError("density = None: give the air density [kg/m^3]")
    rho = check_number("density", density, unit="kg/m^3", lo=0.0, lo_open=True)
    return model.system(rho, mach), model


def default_v_max(semichord: float, omega_2: float, v_div: np.ndarray) -> float:
    """Default upper speed [m/s]: 1.2 x the first divergence speed, at most 8 b omega_2, or
    4 b omega_2 without divergence; never above the documented speed range (1000 m/s).

    Parameters
    ----------
    semichord : float
        Mean semichord b [m].
    omega_2 : float
        Second frequency at rest [rad/s].
    v_div : ndarray
        Static divergence speeds [m/s], increasing.
    """
    ref = semichord * omega_2
    v = min(1.2 * v_div[0], 8.0 * ref) if v_div.size else 4.0 * ref
    return float(min(v, RANGES["flight_speed"].hi))


@blas_limited
def flutter_boundary(
    model: object,
    density: float | None = None,
    *,
    v_max: float | None = None,
    n_modes: int | None = None,
    rtol: float = 1e-7,
    progress: Callable[[float], None] | None = None,
    exact_branches: bool = False,
    mach: float = 0.0,
) -> FlutterResult:
    """Flutter and divergence boundaries of a model at one air density.

    Parameters
    ----------
    model : AeroelasticModel, TypicalSection or FirstOrderSystem
        A model (its modal model is swept) or a first-order system (swept as it is, every
        mode followed).
    density : float
        Air density [kg/m^3] (not needed for a FirstOrderSystem).
    v_max : float, optional
        Upper end of the speed range [m/s]. Default (:func:`default_v_max`): 1.2 x the first
        divergence speed (at most 8 b omega_2), or 4 b omega_2 without divergence, with b the
        mean semichord and omega_2 the second frequency at rest.
    n_modes : int, optional
        Fewest modes in the modal model (default 6). The modes kept follow a physical rule
        (:func:`aeroservo.stability.modal.mode_rule`) and the certificate adds any it finds
        missing, so the answer does not depend on this number.
    rtol : float
        Relative tolerance on crossing speeds (default 1e-7).
    progress : callable, optional
        Called with each accepted speed [m/s].
    exact_branches : bool
        Recompute every branch value on the full model (by default only those near the
        imaginary axis are; the others are the modal model's, to about 1e-3).
    mach : float
        Mach number of the Prandtl-Glauert correction (0: incompressible), fixed over the
        sweep; :func:`aeroservo.stability.matched.flutter_at` finds the matched point.

    Returns
    -------
    FlutterResult
    """
    if progress is not None and not callable(progress):
        raise InputError(f"progress = {progress!r}: expected a callable(speed) or None")
    if not isinstance(exact_branches, (bool, np.bool_)):
        raise InputError(f"exact_branches = {exact_branches!r}: expected True or False")
    system, src = _as_system(model, density, mach)
    n_min = MIN_MODES if n_modes is None else check_int("n_modes", n_modes, lo=1, hi=system.n_q)
    rtol = check_number("rtol", rtol, lo=1e-14, hi=1e-2)
    rho, mach = system.density, system.mach
    warnings = list(getattr(getattr(src, "mesh", None), "warnings", ()))
    v_div = divergence_speeds(system, src)
    if src is None:
        lam_full0, _ = system.modes_at_rest(system.n_q if n_modes is None else n_min)
    else:
        lam_full0, _ = system.modes_at_rest(min(max(n_min, 2), system.n_q))
    omega_2 = float(np.abs(lam_full0[min(1, lam_full0.size - 1)]))
    if v_max is None:
        v_max = default_v_max(system.semichord, omega_2, v_div)
    v_max = check_quantity("v_max", v_max, "flight_speed")
    tracker = EigenTracker(system)
    enlarged: list[dict] = []
    band_hz = modal_basis(src, n_min).cutoff if src is not None else None
    basis = checked_basis(src, n_min, rho, v_max, mach, enlarged) if src is not None else None
    crossings: list[Crossing] | None = None
    for attempt in range(MAX_ENLARGE + 1):
        modal = _modal(src, system, basis, n_modes)
        br, ver, cert = _sweep(tracker, src, modal, v_max, progress)
        top = float(br.speeds[-1])
        errors = _branch_errors(cert, br.eigenvalues.shape[1])
        band_top = 2 * np.pi * 1.1 * basis.cutoff if modal.basis is not None else np.inf
        missing, above = list(cert.missing), None
        if cert.ok:
            try:
                crossings = _crossings(ver, rtol, errors, band_top)
            except VerificationError as exc:
                missing = [(exc.speed, exc.eigenvalue)]
                above = str(exc) if exc.above_band else None
            except (RuntimeError, ValueError):
                break  # not a missing mode: decided as far as possible below
        if crossings is not None or modal.basis is None or attempt == MAX_ENLARGE:
            break
        lost = max(abs(lam.imag) for _v, lam in missing) / (2 * np.pi)
        cutoff = max(1.5 * basis.cutoff, 1.3 * lost)
        why = "certificate" if not cert.ok else "full model" if above is None else "modal model"
        found = (
            f"the {why} found a lightly damped mode near {lost:.4g} Hz that the modal model "
            f"({basis.n_modes} modes, band up to {basis.cutoff:.4g} Hz) lacked or misplaced"
            if above is None
            else f"{above}, coupled with the modes in the band"
        )
        warnings.append(f"{found}; swept again with the band up to {cutoff:.4g} Hz")
        n_before = basis.n_modes
        band_hz = cutoff
        basis = checked_basis(src, n_min, rho, v_max, mach, enlarged, cutoff)
        enlarged.append(
            {
                "by": why,
                "modes": [n_before, basis.n_modes],
                "reason": f"lightly damped mode near {lost:.4g} Hz missing or misplaced"
                if above is None
                else f"mode above the band near {lost:.4g} Hz nears the axis",
            }
        )
    if not cert.ok:
        top = min(top, min(v for v, _lam in cert.missing))
        warnings.append(
            f"search complete only up to {top:.6g} m/s: the certificate still finds full-model "
            "eigenvalues the modal model lacks or misplaces: "
            + ", ".join(
                f"{abs(lam.imag) / (2 * np.pi):.4g} Hz at {v:.4g} m/s"
                for v, lam in cert.missing[:3]
            )
            + "; try more modes (n_modes, --modes) and report the wing if it persists"
        )
    if br.stopped:
        warnings.append(f"search stopped at {top:.6g} m/s: {br.stopped}; results below it stand")
    if crossings is None:
        crossings, top = _crossings_as_far_as_possible(ver, rtol, errors, band_top, top, warnings)
    crossings = [c for c in crossings if c.speed <= top]
    if exact_branches:
        _verify_all(ver)
    near = near_critical(ver, rtol, top, band_top)
    crossings += _divergence(br, v_div, top)
    crossings.sort(key=lambda c: c.speed)
    lam = ver.best()
    exact = ver.exact.copy()
    if modal.basis is None:
        exact[:] = True  # the modal model is the full model
    if modal.basis is not None:  # at rest: the full model's modes (apparent mass included)
        m = lam.shape[1]
        lam[0] = lam_full0 if lam_full0.size == m else system.modes_at_rest(m)[0]
        exact[0] = True
    labels = _labels(src, modal, br)
    info = {
        "method": "modal sweep, decisions and crossings on the full model",
        "n_factorizations": tracker.n_factorizations,
        "n_speeds": int(br.n_speeds),
        "ambiguous_steps": int(br.n_ambiguous),
        "divergence_speeds": [float(v) for v in v_div if v <= top],
        "modal_model": modal_info(modal)
        | ({"band_hz": band_hz} if band_hz is not None else {})
        | ({"enlarged": enlarged} if enlarged else {}),
        "certificate": cert.to_dict(),
    }
    dlm = getattr(src, "dlm", None)
    if dlm is not None:
        warnings += src.dlm_fit(mach).warnings
    result = FlutterResult(
        speeds=br.speeds,
        eigenvalues=lam,
        mode_labels=labels,
        crossings=crossings,
        divergence_speed=float(v_div[0]) if v_div.size else None,
        density=system.density,
        v_max=v_max,
        n_states=system.n_states,
        info=info,
        searched_up_to=top,
        warnings=warnings,
        exact=exact,
        mach=mach,
        compressibility=("prandtl-glauert" if mach > 0 else None) if dlm is None else "dlm",
        damping=_damping_text(src),
        near_critical=near,
    )
    if dlm is not None:  # the RFA's onsets against the tabulated forces
        from .rfa_check import rfa_onset_notes

        notes, info["rfa_check"] = rfa_onset_notes(src, result, mach)
        result.warnings.extend(notes)
    return result


def _modal(src, system: FirstOrderSystem, basis: ModalBasis | None, n_modes) -> ModalSystem:
    if src is None:
        return ModalSystem(system, None, None, 0)
    return modal_system(src, system.density, basis, system.mach)


def _sweep(tracker: EigenTracker, src, modal: ModalSystem, v_max: float, progress):
    """Sweep the modal model, verify it near the axis and certify it at the checkpoints."""
    sys_m = modal.system
    m = modal.basis.n_modes if modal.basis is not None else sys_m.n_q
    lam0, X0 = sys_m.modes_at_rest(m)
    checkpoints = [f * v_max for f in CHECKPOINTS]
    br = sweep_branches(sys_m, lam0, X0, v_max, forced=checkpoints, progress=progress)
    ver = Verifier(tracker, modal, br)
    if modal.basis is None:
        ver.values[:] = br.eigenvalues  # the modal model is the full model
        return br, ver, Certificate(method="modal model is the full model")
    idx = sorted({int(np.argmin(np.abs(br.speeds - v))) for v in checkpoints if v <= br.speeds[-1]})
    band_top = 1.1 * 2 * np.pi * modal.basis.cutoff

    full = tracker.system
    if full.n_states <= DENSE_LIMIT:
        method = "dense eig of the full model"

        def reference(v: float) -> np.ndarray:
            return np.linalg.eigvals(full.state_matrix(v)).astype(complex, copy=False)

    else:
        n_big = min(2 * m, full.n_q)
        big = modal_system(src, full.density, modal_basis(src, n_big), full.mach).system
        method = f"modal model of {n_big} modes; branches in the band verified on the full model"

        def reference(v: float) -> np.ndarray:
            return np.linalg.eigvals(big.state_matrix(v)).astype(complex, copy=False)

        unconfirmed = []
        for k in idx:
            for j in np.flatnonzero(
                is_complex(br.eigenvalues[k]) & (np.abs(br.eigenvalues[k]) <= band_top)
            ):
                try:
                    ver.at(k, int(j))
                except VerificationError as exc:  # a missing mode: enlarge, or stop there
                    unconfirmed.append((exc.speed, exc.eigenvalue))
    cert = certify(reference, br, ver.exact, ver.values, idx, band_top, method)
    if full.n_states > DENSE_LIMIT and unconfirmed:
        cert.ok = False
        cert.missing = sorted(unconfirmed[:1] + cert.missing, key=lambda m: m[0])
    return br, ver, cert


def _branch_errors(cert: Certificate, m: int) -> np.ndarray:
    """Measured modal error per branch; the largest one where a branch was never checked."""
    err = cert.branch_error if cert.branch_error is not None else np.full(m, np.nan)
    worst = float(np.nanmax(err)) if np.isfinite(err).any() else cert.max_mismatch
    return np.where(np.isfinite(err), err, max(worst, cert.max_mismatch))


def _crossings(ver: Verifier, rtol: float, errors: np.ndarray, band_top: float) -> list:
    """Onsets and recoveries of every branch (raises VerificationError if the full model does
    not confirm a branch in the band)."""
    out: list[Crossing] = []
    for j in range(ver.br.eigenvalues.shape[1]):
        out += branch_crossings(ver, j, rtol, float(errors[j]), band_top)
    return _dedupe(out)


def _crossings_as_far_as_possible(
    ver: Verifier, rtol: float, errors: np.ndarray, band_top: float, top: float, warnings: list
) -> tuple[list, float]:
    """As :func:`_crossings`, but a branch the full model cannot confirm ends the complete part
    of the search at the speed where that happened."""
    out: list[Crossing] = []
    for j in range(ver.br.eigenvalues.shape[1]):
        try:
            out += branch_crossings(ver, j, rtol, float(errors[j]), band_top)
        except (VerificationError, RuntimeError, ValueError) as exc:
            bad = getattr(exc, "speed", float(ver.br.speeds[0]))
            top = min(top, bad)
            warnings.append(
                f"search complete only up to {top:.6g} m/s: {exc}; try more modes (n_modes, "
                "--modes) or a finer mesh, and report the wing if it persists"
            )
    return _dedupe([c for c in out if c.speed <= top]), top


def _dedupe(crossings: list[Crossing]) -> list[Crossing]:
    out: list[Crossing] = []
    for c in sorted(crossings, key=lambda c: c.speed):
        if any(
            d.kind == c.kind
            and abs(d.speed - c.speed) <= 1e-6 * c.speed
            and abs(d.frequency - c.frequency) <= 1e-6 * max(c.frequency, 1e-12)
            for d in out
        ):
            continue
        out.append(c)
    return out


def _divergence(br: Branches, v_div: np.ndarray, top: float) -> list[Crossing]:
    """A crossing at each static divergence speed in range, on the branch nearest zero."""
    out = []
    for v in v_div[v_div <= top]:
        k = int(np.argmin(np.abs(br.speeds - v)))
        j = int(np.argmin(np.abs(br.eigenvalues[k])))
        out.append(Crossing(float(v), 0.0, j, "divergence"))
    return out


def _verify_all(ver: Verifier) -> None:
    n, m = ver.br.eigenvalues.shape
    for k in range(1, n):
        for j in range(m):
            try:
                ver.at(k, j)
            except (VerificationError, RuntimeError):
                pass


def _labels(src, modal: ModalSystem, br: Branches) -> list[str]:
    m = br.eigenvalues.shape[1]
    labeller = getattr(src, "label_modes", None)
    if labeller is None:
        return [f"mode {j + 1}" for j in range(m)]
    x = modal.lift(br.vectors[0])
    dlm = getattr(src, "dlm", None)
    if dlm is not None:  # a doublet-lattice model's unknowns are its basis' modal coordinates
        return list(labeller(np.real(dlm.basis @ x[: dlm.n_a])))
    return list(labeller(np.real(x[: src.matrices.n_q])))


def _damping_text(src) -> str:
    damping = getattr(src, "damping", None)
    return damping.describe() if damping is not None else "none"
