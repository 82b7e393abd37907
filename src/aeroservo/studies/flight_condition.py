"""Flutter at a flight condition as files and the command line give it (a density or an
altitude; a fixed Mach number, a Mach number matched to the speed, or Mach 0), and the record of
a model's aerodynamics (strip theory or the doublet lattice at its Mach number) for summaries."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..errors import InputError

__all__ = [
    "flutter_at_condition",
    "flutter_analysis",
    "FlutterAnalysis",
    "aero_record",
    "aero_text",
    "mach_source",
    "sol145_at_condition",
]


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


@dataclass
class FlutterAnalysis:
    """Flutter at a flight condition as a file or the command line gives it: the time-domain
    boundary, the p-k check when asked (or the Nastran case's velocities), and their record.

    Attributes
    ----------
    boundary : FlutterResult
        The time-domain boundary (the eigenvalues of the first-order system).
    pk : FlutterResult or None
        The p-k boundary (exact Theodorsen, or the doublet lattice's tabulated forces).
    sol145 : Sol145Summary or None
        The Nastran flutter summary at the deck's velocities.
    record : dict
        JSON-ready: speeds [m/s], frequencies [Hz], the model and aerodynamics, the boundary's
        own record, ``sol145`` and the p-k's (``pk_exact_theodorsen`` or
        ``pk_doublet_lattice``).
    mach_source : str
        How the Mach number was chosen (:func:`mach_source`).
    title : str
        The figure title: the wing, its elements and aerodynamics.
    """

    boundary: object
    pk: object
    sol145: object
    record: dict
    mach_source: str
    title: str


def flutter_analysis(
    model,
    wing_name: str,
    cond: tuple,
    *,
    v_max: float | None = None,
    n_modes: int | None = None,
    pk: bool = False,
    sol145: dict | None = None,
    progress: Callable[[float], None] | None = None,
) -> FlutterAnalysis:
    """Flutter and divergence of ``model`` at a flight condition, with the p-k check.

    Parameters
    ----------
    model : AeroelasticModel
    wing_name : str
        The wing's name (in the record and the title).
    cond : tuple
        ``(model, density, atmosphere, compressibility, mach)`` as for
        :func:`flutter_at_condition`.
    v_max : float, optional
        Top of the searched speed range [m/s].
    n_modes : int, optional
        Modes of the modal model (None: the mode rule).
    pk : bool
        Also the p-k boundary over the speed range.
    sol145 : dict, optional
        A Nastran flutter case (a scenario's ``[sol145]``): with velocities, the p-k there and
        its flutter summary; without (a K or KE case), the p-k over the speed range.
    progress : callable, optional
        Called with the speed reached [m/s] (the density path only).
    """
    from ..stability.near_critical import method_discrepancy

    _, density, atmosphere, compressibility, mach = cond
    kw: dict = {"v_max": v_max, "n_modes": n_modes}
    extra = {"progress": progress} if progress is not None and atmosphere is None else {}
    result = flutter_at_condition(*cond, **kw, **extra)
    source = mach_source(compressibility, mach, atmosphere)
    record = {
        "wing": wing_name,
        "flutter_speed": result.flutter_speed,
        "flutter_frequency": result.flutter_frequency,
        "divergence_speed": result.divergence_speed,
        "n_states": result.n_states,
        "density": density,
        "n_elements": model.n_elements,
        "wagner": model.wagner.name,
        "units": {"speed": "m/s", "frequency": "Hz", "density": "kg/m^3", "altitude": "m"},
        **aero_record(model, result.mach, source),
    }
    record.update({k: v for k, v in result.to_dict().items() if k not in record})
    pk_result, sol = None, None
    if sol145 is not None and sol145["velocities"]:
        pk_result, sol = sol145_at_condition(cond, result, sol145)
        record["sol145"] = sol.to_dict()
    elif pk or sol145 is not None:  # a deck's K or KE case: p-k over the speed range
        from ..stability.pk import pk_flutter

        kw["v_max"] = result.v_max
        if atmosphere is None:
            kw["boundary"] = result
        pk_result = flutter_at_condition(*cond, solver=pk_flutter, **kw)
    if pk_result is not None:
        note = method_discrepancy(result, pk_result, model.semichord, model.wagner.name)
        if note and note not in pk_result.warnings:  # the matched (altitude) path
            pk_result.warnings.append(note)
        record["pk_exact_theodorsen" if model.dlm is None else "pk_doublet_lattice"] = {
            "flutter_speed": pk_result.flutter_speed,
            "flutter_frequency": pk_result.flutter_frequency,
            "flutter_eas": pk_result.flutter_eas,
            "flutter_mach": pk_result.flutter_mach,
            "divergence_speed": pk_result.divergence_speed,
            "n_modes_followed": pk_result.info.get("n_modes"),
            "restarted_at_onsets": pk_result.info.get("restarted_at_onsets", []),
            "warnings": list(pk_result.warnings),
        }
    aero = model.wagner.name if model.dlm is None else f"doublet lattice, Mach {result.mach:.3g}"
    title = f"{wing_name}: {model.n_elements} elements, {aero}"
    return FlutterAnalysis(result, pk_result, sol, record, source, title)
