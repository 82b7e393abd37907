"""Frequency-domain p-k flutter solution with the exact Theodorsen function.

Same structural and aerodynamic matrices as the time-domain model (:class:`AeroMatrices`), but
the circulatory loads use C(k) exactly, evaluated at k = omega b / V for each group of strips of
semichord b. For an eigenvalue p of mode j the aerodynamics is frozen at omega = Im p and split
into a real stiffness and a real damping (Hassig's p-k):

``K(w) = Ks + rho V^2 Knc + rho sum_g (-V^2 F_g Pq_g + w V G_g Pd_g)``
``C(w) = rho V Cnc + rho sum_g (-V F_g Pd_g - (V^2 G_g / w) Pq_g)``

and ``(M p^2 + C(w) p + K(w)) q = 0`` is iterated until Im p = w. At Re p = 0 the frozen
aerodynamics is the exact harmonic one, so the flutter speed is that of exact Theodorsen strip
theory on this structural model; away from it the damping is the usual p-k approximation.
This solver is the yardstick for the error of the Wagner (indicial) approximation.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from .._threads import blas_limited
from ..errors import check_int, check_number, check_quantity
from ..system.first_order import check_mach, compressibility_factors
from ..system.matrices import AeroMatrices
from .boundary import default_v_max
from .brent import brentq
from .divergence import static_speeds
from .modal import modal_basis
from .near_critical import method_discrepancy
from .pk_branches import restart, track
from .pk_frozen import _PK, PKConvergenceError, _reference_semichord, _setup, _setup_dlm
from .result import Crossing, FlutterResult

__all__ = ["pk_flutter", "static_divergence_speed", "PKConvergenceError"]


ONSET_BAND = 1.5
"""The p-k follows every mode up to at least this multiple of the highest onset frequency of
the time-domain search (times the mode rule's buffer)."""


def _followed_modes(model, boundary: FlutterResult) -> int:
    """How many modes the p-k follows: the time-domain search's certified band (the modes
    its truncation check added above the band are in the p-k's matrices anyway), widened to
    :data:`ONSET_BAND` x its highest onset frequency."""
    modal = boundary.info.get("modal_model", {})
    if "band_hz" not in modal:
        return int(modal.get("n_modes", model.matrices.n_q))
    onsets = [c.frequency for c in boundary.crossings if c.kind == "onset"]
    band = max([modal["band_hz"]] + [ONSET_BAND * f for f in onsets])
    return modal_basis(model, cutoff=band).n_modes


def static_divergence_speed(am: AeroMatrices, density: float, mach: float = 0.0) -> float | None:
    """Lowest divergence speed [m/s] with the exact steady strip aerodynamics (C = 1, with the
    Prandtl-Glauert factor at ``mach``), or None (robust to round-off:
    :func:`aeroservo.stability.divergence.static_speeds`)."""
    cf, _ = compressibility_factors(mach)
    v = static_speeds(am.Ks.toarray(), am.Knc.toarray() - cf * am.Pq.toarray(), density)
    return float(v[0]) if v.size else None


@blas_limited
def pk_flutter(
    model: object,
    density: float,
    *,
    v_max: float | None = None,
    n_modes: int | None = None,
    n_speeds: int = 41,
    rtol: float = 1e-7,
    mach: float = 0.0,
    boundary: FlutterResult | None = None,
    speeds: object = None,
) -> FlutterResult:
    """Flutter boundary by the p-k method with the exact Theodorsen function.

    Parameters
    ----------
    model : AeroelasticModel or TypicalSection
        Anything with a ``matrices`` attribute (:class:`AeroMatrices`).
    density : float
        Air density [kg/m^3].
    v_max : float, optional
        Upper speed [m/s]; default as :func:`aeroservo.stability.boundary.default_v_max`
        (1.2 x the exact static divergence speed, at most 8 b omega_2, else 4 b omega_2).
    n_modes : int, optional
        Lowest modes followed (the p-k's matrices always hold every mode). Default: every mode
        of the band the time-domain search certified (its mode rule and every enlargement of
        its certificate), up to 1.5 x its highest onset frequency at least
        (:data:`ONSET_BAND`).
    n_speeds : int
        Uniform grid points from 0 to ``v_max`` (crossings are then found by root finding).
    rtol : float
        Relative tolerance on crossing speeds.
    mach : float
        Mach number of the Prandtl-Glauert correction, ``C(k) -> C(k / beta^2) / beta``
        (0: incompressible).
    boundary : FlutterResult, optional
        The time-domain search of the same model, density and Mach number
        (:func:`aeroservo.flutter_boundary`). Without ``n_modes`` it is computed if not given:
        the p-k follows the modes of its modal model and is restarted at each of its onsets
        (the p-k crossing next to it is added if the branch tracking missed it, with a
        warning), so that no p-k root below the reported flutter speed crosses unseen.
    speeds : sequence of float, optional
        Speeds [m/s] the branches must pass through (added to the uniform grid; at most
        ``v_max``): the velocities of a Nastran flutter case (``stability/sol145.py``).

    Returns
    -------
    FlutterResult
        ``eigenvalues`` holds the converged p [1/s]; ``divergence_speed`` is the exact static one.
    """
    rho = check_number("density", density, unit="kg/m^3", lo=0.0, lo_open=True)
    dlm = getattr(model, "dlm", None)
    if dlm is None:
        mach = check_mach(mach)
        am: AeroMatrices = model.matrices
        pk, basis = _setup(am, rho, mach)
        v_divs = static_speeds(am.Ks.toarray(), am.Knc.toarray() - pk.cf * am.Pq.toarray(), rho)
        n_q = am.n_q
    else:
        pk, basis, v_divs = _setup_dlm(model, rho, mach)
        n_q = dlm.n_a
    if n_modes is None:
        if boundary is None:
            from .boundary import flutter_boundary

            boundary = flutter_boundary(model, rho, v_max=v_max, mach=mach)
        n_modes = _followed_modes(model, boundary)
    n_modes = check_int("n_modes", n_modes, lo=1, hi=n_q)
    n_speeds = check_int("n_speeds", n_speeds, lo=3)
    w2, phi = sla.eigh(pk.Ks, pk.M, subset_by_index=[0, n_modes - 1])
    p0 = 1j * np.sqrt(w2)
    v_div = float(v_divs[0]) if v_divs.size else None
    b_ref = _reference_semichord(model)
    if v_max is None:
        v_max = default_v_max(b_ref, float(abs(p0[min(1, n_modes - 1)])), v_divs)
    v_max = check_quantity("v_max", v_max, "flight_speed")
    grid = np.linspace(0.0, v_max, n_speeds)
    if speeds is not None:
        extra = [check_number("speeds", v, unit="m/s", lo=0.0, hi=v_max) for v in speeds]
        grid = np.unique(np.concatenate([grid, extra]))
    speeds = grid
    n_speeds = speeds.size
    P, Q, ended = track(pk, speeds, p0, phi.astype(complex), PKConvergenceError)

    crossings = []
    skipped: list[float] = []
    for j in range(n_modes):
        g = P[:, j].real
        for k in range(1, n_speeds - 1):
            if np.isfinite(g[k + 1]) and (g[k] < 0) != (g[k + 1] < 0):

                def re_p(v: float, k: int = k, j: int = j) -> float:
                    return pk.converge(v, P[k, j], Q[k, :, j])[0].real

                try:
                    if re_p(speeds[k]) * re_p(speeds[k + 1]) > 0:
                        raise PKConvergenceError("the continuation did not reproduce it")
                    vs = brentq(
                        re_p, speeds[k], speeds[k + 1], xtol=rtol * speeds[k + 1], rtol=1e-15
                    )
                    pc = pk.converge(vs, P[k, j], Q[k, :, j])[0]
                except PKConvergenceError:
                    skipped.append(float(speeds[k]))
                    continue
                kind = "onset" if g[k] < 0 else "recovery"
                crossings.append(Crossing(float(vs), abs(pc.imag) / (2 * np.pi), j, kind))
    warnings, restarted = _restarts(pk, boundary, crossings, P, speeds, rtol)
    crossings.sort(key=lambda c: c.speed)
    labeller = getattr(model, "label_modes", None)
    labels = labeller(basis @ phi) if labeller else [f"mode {j + 1}" for j in range(n_modes)]
    result = FlutterResult(
        speeds=speeds,
        eigenvalues=P,
        mode_labels=list(labels),
        crossings=crossings,
        divergence_speed=v_div,
        density=rho,
        v_max=v_max,
        n_states=2 * n_q,
        info={
            "method": "p-k, exact Theodorsen" if dlm is None else "p-k, doublet lattice",
            "n_modes": n_modes,
            "branches_ended_at": ended,
            "unconfirmed_sign_changes_at": skipped,
            "restarted_at_onsets": restarted,
        },
        warnings=warnings,
        mach=mach,
        compressibility=("prandtl-glauert" if mach > 0 else None) if dlm is None else "dlm",
        damping=getattr(getattr(model, "damping", None), "describe", lambda: "none")(),
    )
    if boundary is not None:
        wagner = getattr(getattr(model, "wagner", None), "name", "") if dlm is None else "RFA"
        note = method_discrepancy(boundary, result, b_ref, wagner)
        if note:
            result.warnings.append(note)
    return result


def _restarts(pk: _PK, boundary, crossings: list, P: np.ndarray, speeds: np.ndarray, rtol: float):
    """Restart the p-k at every onset of the time-domain search; add the p-k crossings the
    branch tracking missed. Returns the warnings and the restart records."""
    warnings: list[str] = []
    records: list[dict] = []
    if boundary is None:
        return warnings, records
    v_max = float(speeds[-1])
    for c in boundary.crossings:
        if c.kind != "onset" or c.speed > v_max:
            continue
        found = restart(pk, c.speed, 2 * np.pi * c.frequency, v_max, rtol, PKConvergenceError)
        rec = {"time_domain_speed": c.speed, "time_domain_frequency": c.frequency}
        if found is None:
            rec["pk_speed"] = None
            records.append(rec)
            continue
        vs, pc, rising = found
        f = abs(pc.imag) / (2 * np.pi)
        rec |= {"pk_speed": vs, "pk_frequency": f}
        records.append(rec)
        if any(
            abs(d.speed - vs) <= 1e-5 * vs and abs(d.frequency - f) <= 1e-4 * max(f, 1e-12)
            for d in crossings
        ):
            continue
        row = np.abs(P[int(np.argmin(np.abs(speeds - vs)))] - pc)
        j = int(np.argmin(np.where(np.isfinite(row), row, np.inf)))
        crossings.append(Crossing(vs, f, j, "onset" if rising else "recovery"))
        if rising:
            warnings.append(
                f"p-k: the branch tracking missed the onset at {vs:.6g} m/s ({f:.4g} Hz), found "
                f"by restarting the p-k at the time-domain onset {c.speed:.6g} m/s"
            )
    return warnings, records
