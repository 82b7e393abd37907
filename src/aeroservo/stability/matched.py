"""Flutter and divergence at a flight condition: an altitude of the standard atmosphere, with the
compressibility correction matched to the speed it is evaluated at.

Without compressibility the aerodynamics do not depend on the speed of sound: the boundary at
the altitude's density is the answer, and Mach numbers follow as ``V / a``. With the
Prandtl-Glauert correction the Mach number of the aerodynamics is a parameter of the model, and
a *matched point* is one where it equals ``V / a`` at the speed reported: the flutter speed is
found by iterating on the Mach number (secant method on ``V_f(M) / a - M``, started from the
incompressible answer) to ``|M - V_f / a| <`` :data:`MACH_TOL`, and the divergence speed by
root finding on the static problem at each Mach number. Each speed is matched at its own Mach
number; the branches reported are those of the flutter match. The correction is refused at
Mach 0.9 and above, and flagged as approximate above 0.7.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..aero.atmosphere import Atmosphere
from ..aero.dlm import DLM_MACH_WARN
from ..errors import InputError
from ..system.first_order import (
    MACH_APPROXIMATE,
    MACH_LIMIT,
    compressibility_factors,
    mach_note,
)
from .brent import brentq
from .divergence import divergence_speeds, static_speeds
from .result import Crossing, FlutterResult

__all__ = ["flutter_at", "COMPRESSIBILITY", "MACH_TOL"]

COMPRESSIBILITY = ("none", "prandtl-glauert", "matched")
MACH_TOL = 1e-6
"""Matched-point tolerance on ``|M - V / a|``."""

_TOP = MACH_LIMIT * (1 - 1e-9)
DLM_TOP = 0.99
"""Highest Mach number of a doublet-lattice matched point."""


def _check(compressibility: str | None, model=None) -> str | None:
    """The compressibility of a model: None, ``"prandtl-glauert"`` (strip theory, also given as
    ``"matched"``) or ``"dlm"`` (a doublet-lattice model matched to its Mach number)."""
    if compressibility in (None, "none"):
        return None
    if compressibility not in COMPRESSIBILITY:
        raise InputError(
            f"compressibility = {compressibility!r}: allowed values are {list(COMPRESSIBILITY)}"
        )
    return "dlm" if getattr(model, "dlm", None) is not None else "prandtl-glauert"


def flutter_at(
    model,
    atmosphere: Atmosphere,
    *,
    compressibility: str | None = None,
    solver: Callable[..., FlutterResult] | None = None,
    max_iterations: int = 20,
    mach_start: float = 0.0,
    **kw,
) -> FlutterResult:
    """Flutter and divergence of a model at a standard-atmosphere flight condition.

    Parameters
    ----------
    model : AeroelasticModel or TypicalSection
    atmosphere : Atmosphere
        From :func:`aeroservo.aero.atmosphere.isa`.
    compressibility : {None, "none", "prandtl-glauert"}
        Compressibility correction; with it the Mach number is matched.
    solver : callable, optional
        ``solver(model, density, mach=..., **kw)``: :func:`flutter_boundary` (default) or
        :func:`aeroservo.stability.pk_flutter`.
    max_iterations : int
        Largest number of boundary evaluations of the Mach iteration.
    mach_start : float
        First Mach number tried (e.g. the matched Mach of a neighbouring altitude).
    **kw
        Passed to the solver (``v_max``, ``n_modes``, ``rtol``, ...).

    Returns
    -------
    FlutterResult
        With ``altitude`` and ``speed_of_sound`` set; ``info["mach_iterations"]`` lists the
        Mach numbers tried and the flutter speeds found.
    """
    if solver is None:
        from .boundary import flutter_boundary as solver
    if not isinstance(atmosphere, Atmosphere):
        raise InputError(
            f"atmosphere = {atmosphere!r}: expected aeroservo.aero.atmosphere.isa(...)"
        )
    comp = _check(compressibility, model)
    rho, a = atmosphere.density, atmosphere.speed_of_sound
    top_mach = _TOP if comp != "dlm" else DLM_TOP
    if comp is None:
        r = _flight(solver(model, rho, **kw), atmosphere, None, [])
        for what, v in (("flutter", r.flutter_speed), ("divergence", r.divergence_speed)):
            if getattr(model, "dlm", None) is not None:
                note = _dlm_mach_note(what, v, a, float(kw.get("mach", 0.0) or 0.0))
            else:
                note = None if v is None else mach_note(what, v, a)
            if note:
                r.warnings.append(note)
        return r

    history: list[dict] = []
    warnings: list[str] = []

    def run(mach: float) -> FlutterResult:
        res = solver(model, rho, mach=mach, **kw)
        history.append({"mach": mach, "flutter_speed": res.flutter_speed})
        return res

    m = float(np.clip(mach_start, 0.0, top_mach))
    r = run(m)
    ms, fs = [m], [_residual(r, a, m)]

    for _ in range(max_iterations - 1):
        f = fs[-1]
        if abs(f) < MACH_TOL:
            break
        if len(ms) == 1 or fs[-1] == fs[-2]:
            m_new = m + f  # fixed point: M <- V_f / a
        else:
            m_new = m - f * (ms[-1] - ms[-2]) / (fs[-1] - fs[-2])
        m_new = float(np.clip(m_new, 0.0, top_mach))
        if m_new == m:
            break
        m = m_new
        r = run(m)
        ms.append(m)
        fs.append(_residual(r, a, m))
    matched = abs(fs[-1]) < MACH_TOL
    limit = MACH_LIMIT if comp != "dlm" else 1.0
    theory = "Prandtl-Glauert correction" if comp != "dlm" else "subsonic doublet lattice"
    if not matched:
        top = min(r.searched_up_to, limit * a)
        if r.flutter_speed is None or r.flutter_speed / a >= top_mach * (1 - 1e-6):
            warnings.append(
                f"no matched flutter point below Mach {limit:g} (the limit of the {theory}): "
                f"no flutter below {top:.5g} m/s TAS"
            )
            r = _without_flutter(r, top)
        else:
            warnings.append(
                f"the Mach iteration did not converge in {len(ms)} boundaries "
                f"(|M - V/a| = {abs(fs[-1]):.2g})"
            )
    if comp == "dlm":
        v_div, diverges = _matched_dlm_divergence(model, rho, a)
    else:
        v_div = _matched_divergence(model, rho, a)
        diverges = divergence_speeds(model.system(rho)).size > 0
    r = _with_divergence(r, v_div)
    if v_div is None and diverges:
        warnings.append(
            f"no matched divergence below Mach {limit:g} (the limit of the {theory}, "
            f"{limit * a:.5g} m/s TAS)"
        )
    approximate = MACH_APPROXIMATE if comp != "dlm" else DLM_MACH_WARN
    for what, v in (("flutter", r.flutter_speed), ("divergence", v_div)):
        if v is not None and v / a > approximate:
            warnings.append(
                f"{what} at Mach {v / a:.3f}: the {theory} is approximate above "
                f"Mach {approximate:g}"
            )

    out = _flight(r, atmosphere, comp, history)
    out.warnings.extend(warnings)
    out.info["matched"] = {"flutter_mach_residual": abs(fs[-1]), "converged": matched}
    return out


def _residual(r: FlutterResult, a: float, mach: float) -> float:
    """``V_f / a - M``; without flutter below the range, from its top (a lower bound)."""
    v = r.flutter_speed if r.flutter_speed is not None else r.searched_up_to
    return v / a - mach


def _flight(r, atm: Atmosphere, comp, history) -> FlutterResult:
    r.altitude = atm.altitude
    r.speed_of_sound = atm.speed_of_sound
    if r.compressibility != "dlm":  # a doublet-lattice result keeps its aerodynamics' name
        r.compressibility = comp
    if history:
        r.info["mach_iterations"] = history
    return r


def _without_flutter(r: FlutterResult, top: float) -> FlutterResult:
    """The result with its search ending at ``top`` (no crossing above it is valid)."""
    r.crossings = [c for c in r.crossings if c.speed < top]
    r.searched_up_to = min(r.searched_up_to, top)
    return r


def _matched_divergence(model, rho: float, a: float) -> float | None:
    """Divergence speed whose Mach number V / a is the one of the static aerodynamics.

    The steady aerodynamic stiffness is ``Knc - K_circ / beta`` (only its circulatory part is
    corrected), so one incompressible system gives it at every Mach number.
    """
    am = model.matrices
    ks, knc = am.Ks.toarray(), am.Knc.toarray()
    k_circ = knc - model.system(rho).K_static

    def v_d(m: float) -> float:
        cf, _ = compressibility_factors(m)
        v = static_speeds(ks, knc - cf * k_circ, rho)
        return float(v[0]) if v.size else np.inf

    def g(m: float) -> float:
        return min(v_d(m) / a, 10.0) - m

    if g(0.0) <= 0:
        return v_d(0.0)
    if g(_TOP) > 0:
        return None  # no divergence below Mach 0.9
    m = brentq(g, 0.0, _TOP, xtol=1e-12, rtol=1e-12)
    return v_d(m)


def _matched_dlm_divergence(model, rho: float, a: float) -> tuple[float | None, bool]:
    """The divergence speed of a doublet-lattice model whose Mach number V / a is the one of its
    steady vortex-lattice forces (root finding on the Mach number), and whether it diverges at
    Mach 0."""
    dlm = model.dlm
    ks = dlm.basis.T @ (model.matrices.Ks.toarray() @ dlm.basis)

    def v_d(m: float) -> float:
        v = static_speeds(ks, -0.5 * dlm.steady(m), rho)
        return float(v[0]) if v.size else np.inf

    def g(m: float) -> float:
        return min(v_d(m) / a, 10.0) - m

    v0 = v_d(0.0)
    if g(0.0) <= 0:
        return v0, True
    if g(DLM_TOP) > 0:
        return None, np.isfinite(v0)
    m = brentq(g, 0.0, DLM_TOP, xtol=1e-10, rtol=1e-12)
    return v_d(m), True


def _dlm_mach_note(what: str, v: float | None, a: float, mach: float) -> str | None:
    """A doublet-lattice result at a fixed Mach number far from its own ``V / a``."""
    if v is None or abs(v / a - mach) <= 0.05 or max(v / a, mach) <= 0.3:
        return None
    return (
        f"{what} at Mach {v / a:.3f} with the doublet lattice at Mach {mach:g}: match the Mach "
        "number (compressibility = 'matched')"
    )


def _with_divergence(r: FlutterResult, v_div: float | None) -> FlutterResult:
    """Replace the divergence of a flutter match by the divergence's own match."""
    others = [c for c in r.crossings if c.kind != "divergence"]
    if v_div is not None and v_div <= r.searched_up_to:
        k = int(np.argmin(np.abs(r.speeds - v_div)))
        j = int(np.argmin(np.abs(r.eigenvalues[k])))
        others.append(Crossing(float(v_div), 0.0, j, "divergence"))
    r.crossings = sorted(others, key=lambda c: c.speed)
    r.divergence_speed = v_div
    return r
