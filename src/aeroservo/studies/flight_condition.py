"""Flutter at a flight condition as files and the command line give it (a density or an
altitude; a fixed Mach number, a Mach number matched to the speed, or Mach 0), and the record of
a model's aerodynamics (strip theory or the doublet lattice at its Mach number) for summaries."""

from __future__ import annotations

from collections.abc import Callable

from ..errors import InputError

__all__ = ["flutter_at_condition", "aero_record", "aero_text", "mach_source"]


def flutter_at_condition(
    model,
    density: float,
    atmosphere=None,
    compressibility: str | None = None,
    mach: float | None = None,
    *,
    solver: Callable | None = None,
    **kw,
):
    """Flutter and divergence of ``model`` at a flight condition.

    Parameters
    ----------
    model : AeroelasticModel
    density : float
        Air density [kg/m^3] (the atmosphere's, when one is given).
    atmosphere : Atmosphere, optional
        The standard atmosphere of an altitude.
    compressibility : {None, "none", "prandtl-glauert", "matched"}
        With an atmosphere: the Mach number matched to the speed
        (:func:`aeroservo.stability.matched.flutter_at`).
    mach : float, optional
        A fixed Mach number (not with ``compressibility``); None: 0 (strip theory:
        incompressible; the doublet lattice at Mach 0).
    solver : callable, optional
        :func:`aeroservo.flutter_boundary` (default) or :func:`aeroservo.stability.pk_flutter`.
    **kw
        Passed to the solver (``v_max``, ``n_modes``, ``progress``, ...).

    Returns
    -------
    FlutterResult
        With the altitude and the speed of sound of an atmosphere.
    """
    comp = None if compressibility in (None, "none") else compressibility
    if comp is not None and mach is not None:
        raise InputError(
            f"mach = {mach!r} and compressibility = {comp!r}: give a fixed Mach number or a "
            "Mach number matched to the speed, not both"
        )
    if solver is None:
        from ..stability.boundary import flutter_boundary as solver
    if atmosphere is not None and mach is None:
        from ..stability.matched import flutter_at

        return flutter_at(model, atmosphere, compressibility=comp, solver=solver, **kw)
    if comp is not None:
        raise InputError(
            f"compressibility = {comp!r}: needs the speed of sound, give an altitude instead of "
            "a density"
        )
    rho = density if atmosphere is None else atmosphere.density
    r = solver(model, rho, **({"mach": mach} if mach is not None else {}), **kw)
    if atmosphere is not None:
        r.altitude, r.speed_of_sound = atmosphere.altitude, atmosphere.speed_of_sound
    return r


def mach_source(compressibility: str | None, mach: float | None, atmosphere=None) -> str:
    """How the Mach number of an analysis was chosen: ``"fixed"``, ``"matched"`` or
    ``"default"`` (0: neither a fixed Mach number nor a matched compressibility)."""
    if mach is not None:
        return "fixed"
    if compressibility not in (None, "none") and atmosphere is not None:
        return "matched"
    return "default"


def aero_record(model, mach: float, source: str = "default") -> dict:
    """The aerodynamics of a result for its summary: ``aero`` (``"strip"``, ``"dlm"``),
    ``mach`` (of the aerodynamics), ``mach_source`` and, for the doublet lattice, ``dlm``: its
    ``settings``, ``n_boxes``, the rational-function ``fit`` at that Mach number
    (:meth:`~aeroservo.system.dlm_forces.DLMFit.summary`) and the fit's ``warnings``."""
    out = {"aero": model.aero_model, "mach": float(mach), "mach_source": source}
    if model.dlm is not None:
        fit = model.dlm_fit(mach)
        out["dlm"] = {
            "settings": model.aero.to_dict(),
            "n_boxes": int(model.dlm.grid.n_boxes),
            "fit": fit.summary(),
            "warnings": list(fit.warnings),
        }
    return out


def aero_text(model, mach: float, source: str = "default") -> str:
    """One line: the aerodynamic model and its Mach number (and how it was chosen)."""
    how = {
        "fixed": "fixed",
        "matched": "matched to the flutter speed",
        "default": "default: no fixed Mach number nor matched compressibility",
    }[source]
    if model.dlm is None:
        comp = "incompressible" if not mach else f"Prandtl-Glauert at Mach {mach:.4g}"
        return f"aerodynamics: strip theory, Wagner '{model.wagner.name}', {comp} ({how})"
    boxes = model.dlm.grid.n_boxes
    return f"aerodynamics: {model.aero.describe()}; {boxes} boxes; Mach {mach:.4g} ({how})"


def sol145_at_condition(cond: tuple, boundary, sol145: dict):
    """The p-k at a Nastran flutter case's velocities (a scenario's ``[sol145]`` table) and its
    flutter summary (:class:`aeroservo.stability.sol145.Sol145Summary`).

    ``cond`` is ``(model, density, atmosphere, compressibility, mach)`` as for
    :func:`flutter_at_condition`; ``boundary`` the time-domain result there (its speed range
    and modal model). Returns ``(pk, summary)``.
    """
    from ..stability.pk import pk_flutter
    from ..stability.sol145 import sol145_summary

    velocities = sol145["velocities"]
    v_max = max(boundary.v_max, max(velocities))
    kw = {"boundary": boundary} if cond[2] is None else {}
    pk = flutter_at_condition(*cond, solver=pk_flutter, v_max=v_max, speeds=velocities, **kw)
    summary = sol145_summary(
        pk,
        velocities,
        sol145["reference_chord"],
        method=sol145["method"],
        density_ratio=sol145["density_ratio"],
        velocity_unit=sol145["velocity_unit"],
        velocity_factor=sol145["velocity_factor"],
    )
    return pk, summary
