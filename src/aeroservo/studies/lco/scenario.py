"""A limit-cycle scenario (``kind = "lco"``): the :class:`~aeroservo.studies.lco.study.LCOSetup` and
:class:`~aeroservo.studies.lco.study.LCOSweep` it describes, its run, its summary and the figures a
run writes.

The model is the scenario's wing (or typical section) with its nonlinear hinges at the
``[flight]`` density. With a controller the loop is the scenario's ``[signals]`` loop; the
controller is designed once, at the ``[flight]`` speed (or ``speed_factor`` x the open-loop
flutter speed, springs closed) with ``simulation.sample_rate``, and held fixed at every speed
of the study (a gain schedule at its design speed), with the actuator limits of its file.
"""

from __future__ import annotations

import math

from ...result_shape import finite
from ..kinds import Run, check_kind
from ..scenario import Scenario

__all__ = ["lco_setup", "run_lco_scenario", "lco_summary", "lco_figures", "FIGURES"]

FIGURES = ("bifurcation", "histories")
"""The figures of a limit-cycle run, by file suffix (:func:`lco_figures`)."""


def lco_setup(scenario: Scenario):
    """The ``(LCOSetup, LCOSweep)`` of an ``lco`` scenario (the controller designed here).

    Returns
    -------
    setup : LCOSetup
    sweep : LCOSweep
    """
    from ...stability.boundary import flutter_boundary
    from .study import LCOSetup, LCOSweep

    check_kind(scenario, "lco")
    c = scenario.lco
    model = scenario.model()
    vf = flutter_boundary(model, scenario.density).flutter_speed
    spec = scenario.controller
    spec = None if spec is None or getattr(spec, "type", "") == "none" else spec
    extra: dict = {
        "scenario": scenario.name,
        "model": scenario.wing_source,
        "hinges_source": c.hinges_source,
        "open_loop_flutter_speed": vf,
        "describing_function": c.describing,
    }
    loop = ctrl = limits = None
    if spec is not None:
        from ...design.interface import controller_at

        speed = scenario.design_speed(vf)
        loop = scenario.loop(model)
        ctrl = controller_at(loop.design_controller(spec, speed, scenario.sample_rate, vf), speed)
        limits = spec.limits
        extra |= {"design_speed": speed, "sample_rate": scenario.sample_rate}
        extra["controller"] = spec.name or spec.type  # the file's name, not the class's
        extra["controller_file"] = str(getattr(spec, "source", "") or "")
    setup = LCOSetup(
        model,
        c.hinges,
        scenario.density,
        loop=loop,
        controller=ctrl,
        limits=limits,
        name=scenario.result,
    )
    sweep = LCOSweep(
        speeds=tuple(c.speeds),
        amplitudes=tuple(c.amplitudes),
        duration=c.duration,
        dt=c.dt,
        settle=c.settle,
        continuation=c.continuation,
        history=c.history,
        extra=extra,
    )
    return setup, sweep


def run_lco_scenario(
    scenario: Scenario,
    *,
    progress: bool = False,
    scheduler: str | None = None,
    workers: int | None = None,
) -> Run:
    """Run an ``lco`` scenario.

    Parameters
    ----------
    scenario : Scenario
    progress : bool
        A progress bar over the marches on stderr.
    scheduler : str, optional
        Address of a running Dask scheduler (overrides ``workers``).
    workers : int, optional
        Local Dask workers (0: this process); None: ``lco.workers`` of the scenario.

    Returns
    -------
    Run
        Its JSON-ready summary (:func:`lco_summary`) and ``lco``, the
        :class:`~aeroservo.studies.lco.result.LCOResult`: every march's verdict and history,
        and the describing-function branches.
    """
    from .run import run_lco

    setup, sweep = lco_setup(scenario)
    c = scenario.lco
    n = c.workers if workers is None else workers
    result = run_lco(
        setup,
        sweep,
        workers=n,
        scheduler=scheduler,
        progress=progress,
        describing=c.describing,
    )
    notes = result.settings.setdefault("notes", [])
    vf = result.settings.get("open_loop_flutter_speed")
    notes.append(
        "linear flutter speed, open loop with every spring closed: "
        + ("none in the searched range" if vf is None else f"{vf:.4g} m/s")
    )
    coarse = _coarse_step(result)
    if coarse:
        notes.append(coarse)
    if not c.describing:
        notes.append("describing function: not computed (lco.describing = false)")
    if c.wing_hinges_replaced:
        notes.append("hinges: the scenario's [[lco.hinges]] replace the wing file's [[hinges]]")
    if "design_speed" in result.settings:
        notes.append(
            f"controller {result.settings['controller']} designed at "
            f"{result.settings['design_speed']:.4g} m/s, held fixed at every speed"
        )
    return Run(scenario, lco_summary(result, scenario), lco=result, title=scenario.name)


MIN_SAMPLES_PER_CYCLE = 20
"""Fewest steps per cycle of a march's motion before the run warns that its step is coarse
(the march misses a rotation that crosses a gap edge and back within one step; at 10 per
cycle the Conner section's verdicts lose confidence, at 4 they change)."""


def _coarse_step(result) -> str:
    """A note when the step of the marches resolves the motion they found with fewer than
    :data:`MIN_SAMPLES_PER_CYCLE` steps per cycle ("" otherwise); motions below 1 % of the
    gap (or of the smallest initial rotation) are left out (the noise of a march at rest)."""
    s = result.settings
    dt = s.get("dt")
    scale = s.get("gap") or min(s.get("amplitudes") or [0.0])
    found = [
        (r["frequency"], r["speed"])
        for r in result.rows
        if math.isfinite(r["frequency"])
        and r["frequency"] > 0
        and math.isfinite(r["amplitude"])
        and r["amplitude"] >= 0.01 * scale
    ]
    if not dt or not found:
        return ""
    f, v = max(found)
    per_cycle = 1.0 / (f * dt)
    if per_cycle >= MIN_SAMPLES_PER_CYCLE:
        return ""
    fix = "raise simulation.sample_rate" if s.get("closed_loop") else "lower lco.dt"
    return (
        f"step {dt:g} s coarse: {per_cycle:.3g} steps per cycle at {f:.3g} Hz ({v:.4g} m/s), "
        f"below {MIN_SAMPLES_PER_CYCLE}; a rotation across a gap edge and back within one "
        f"step is missed and a faster motion shows at an alias frequency: {fix} and run again"
    )


def lco_summary(result, scenario: Scenario | None = None) -> dict:
    """The JSON-ready summary of a limit-cycle result: where sustained oscillations settle
    (``lco_onset``, ``lco_speeds`` and the ranges of the amplitudes and frequencies of the
    reference rotation, over every class; ``lco_classes``: the same per class, periodic,
    quasi-periodic and chaotic; SI units and radians), where the motion diverges, the hysteresis
    of the sweeps, the notes and the study's settings."""
    from .result import class_ranges

    s = result.settings
    lcos = result.sustained_rows()
    counts: dict = {}
    for r in result.rows:
        counts[r["kind"]] = counts.get(r["kind"], 0) + 1
    summary: dict = {
        "scenario": scenario.name if scenario is not None else s.get("scenario", ""),
        "kind": "lco",
        "result": s.get("name", ""),
        "reference": s.get("reference"),
        "gap": s.get("gap"),
        "closed_loop": s.get("closed_loop", False),
        "controller": s.get("controller", ""),
        "open_loop_flutter_speed": finite(s.get("open_loop_flutter_speed")),
        "lco_onset": finite(result.onset()),
        "lco_speeds": sorted({r["speed"] for r in lcos}),
        "lco_amplitude_range": [
            min(r["amplitude"] for r in lcos),
            max(r["amplitude"] for r in lcos),
        ]
        if lcos
        else None,
        "lco_frequency_range": [
            min(r["frequency"] for r in lcos),
            max(r["frequency"] for r in lcos),
        ]
        if lcos
        else None,
        "lco_classes": class_ranges(result),
        "diverged_from": finite(result.diverged_from()),
        "hysteresis_speeds": result.hysteresis(),
        "marches": len(result.rows),
        "verdicts": counts,
        "notes": list(s.get("notes", [])),
        "settings": dict(s),
        "units": {
            "speed": "m/s",
            "amplitude": "rad (half peak-to-peak of the reference rotation)",
            "frequency": "Hz (of a limit cycle its fundamental; of a quasi-periodic or chaotic "
            "oscillation the strongest line of its spectrum)",
            "gap": "rad (total)",
            "density": "kg/m^3",
        },
    }
    if result.branches is not None:
        summary["describing_onset"] = finite(result.branches.onset())
    return summary


def lco_figures(result, which=FIGURES) -> dict:
    """The figures a limit-cycle run writes, by file suffix: ``bifurcation`` (amplitude
    against speed, with the describing-function branches) and ``histories`` (the end of a
    few marches; drawn only when the result has time histories); ``which``: those to draw.
    See :mod:`aeroservo.studies.lco.plots`."""
    out = {}
    if "bifurcation" in which:
        out["bifurcation"] = result.plot_bifurcation().figure
    if "histories" in which and any(r.get("history") for r in result.rows):
        out["histories"] = result.plot_histories()
    return out
