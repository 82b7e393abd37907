"""Running the scenarios of kinds ``flutter`` (open-loop flutter) and ``simulate`` (a
closed-loop simulation judged over its engaged speeds); :func:`run_scenario` runs any kind
(:mod:`aeroservo.studies.kinds`).

Each ``run_*`` function computes and returns a :class:`Run`: the JSON-ready summary and the
result objects behind it. Nothing is written here except a trade study's own case store (its
folder, so that an interrupted study resumes); :func:`aeroservo.files.outputs.write_run` writes
a run's summary, result file and figures as one set.
"""

from __future__ import annotations

import time
import warnings

import numpy as np

from .._threads import blas_limited
from .kinds import Run, check_kind, run_scenario
from .loop_analysis import analyse_loop
from .scenario import Scenario
from .verdict import loop_verdict, signal_growth

__all__ = ["Run", "run_scenario", "run_flutter", "run_simulation", "study_from_scenario"]


def study_from_scenario(scenario: Scenario):
    """The :class:`~aeroservo.studies.trade.TradeStudy` of a ``trade`` scenario."""
    from .trade.scenario import study_from_scenario as study

    return study(scenario)


def _progress_bar(total: float, desc: str, enabled: bool, unit: str = "m/s"):
    """A tqdm bar advanced to an absolute position by the returned callback (or no-ops)."""
    if not enabled:
        return (lambda v: None), (lambda: None)
    from tqdm.auto import tqdm

    bar = tqdm(total=round(total, 1), desc=desc, unit=unit, leave=False, dynamic_ncols=True)

    def update(v: float) -> None:
        bar.n = round(min(v, total), 1)
        bar.refresh()

    return update, bar.close


@blas_limited
def run_flutter(scenario: Scenario, progress: bool = False) -> Run:
    """Open-loop flutter and divergence of the scenario's wing (summary and V-g figure)."""
    from .flight_condition import flutter_analysis

    model = scenario.model()
    cond = (model, scenario.density, scenario.atmosphere, scenario.compressibility, scenario.mach)
    update, close = _progress_bar(scenario.v_max or 300.0, "flutter sweep", progress)
    try:
        fa = flutter_analysis(
            model,
            scenario.wing.name,
            cond,
            v_max=scenario.v_max,
            pk=scenario.pk,
            sol145=scenario.sol145,
            progress=update,
        )
    finally:
        close()
    summary = {"scenario": scenario.name, "kind": "flutter", **fa.record}
    return Run(scenario, summary, flutter=fa.boundary, title=fa.title)


@blas_limited
def run_simulation(scenario: Scenario, progress: bool = False) -> Run:
    """Closed-loop time simulation of a ``simulate`` scenario.

    Returns
    -------
    Run
        The time histories (``simulation``), the closed-loop boundary if asked, and a JSON-ready
        summary (speeds [m/s], peaks and RMS in the signals' units, growth ratio of the
        response, closed-loop flutter speed if asked).
    """
    from ..design.plant import OpenLoop
    from ..simulate.march import simulate
    from ..stability.boundary import flutter_boundary

    check_kind(scenario, "simulate")
    t0 = time.perf_counter()
    model = scenario.model()
    fr = flutter_boundary(model, scenario.density)
    vf = fr.flutter_speed
    speed = scenario.design_speed(vf, fr.v_max)
    loop = scenario.loop(model)
    spec = scenario.controller
    from ..design.interface import controller_at
    from ..design.realisability import refuse_unrealisable

    controller = loop.design_controller(spec, speed, scenario.sample_rate, vf)
    at = controller_at(controller, speed)  # a schedule at the scenario's speed
    plant = loop.plant(speed)
    if scenario.realisable:
        refuse_unrealisable(scenario.source, plant, at)
    dist = scenario.disturbance
    x0 = loop.initial_state(dist.initial_tip) if dist.initial_tip else None
    noise = {k: np.sqrt(v) for k, v in scenario.sensor_noise.items()} or None
    kw = {"limits": spec.limits, "delay": scenario.delay, "sensor_noise": noise}
    with warnings.catch_warnings():  # the summary gives the windup warning, once
        warnings.filterwarnings("ignore", message="simulate: the controller's commands run")
        result = simulate(
            plant, at, duration=scenario.duration, x0=x0, disturbance=dist.gust,
            seed=scenario.seed, **kw,
        )  # fmt: skip
    open_loop = None
    if scenario.plots and not isinstance(controller, OpenLoop):  # overlay of the figure
        open_loop = simulate(
            plant,
            OpenLoop(tuple(loop.controls), 1.0 / scenario.sample_rate),
            duration=scenario.duration,
            x0=x0,
            disturbance=dist.gust,
        )
    summary: dict = {
        "scenario": scenario.name,
        "kind": "simulate",
        "wing": scenario.wing.name,
        "controller": spec.name,
        "controller_type": spec.type,
        "speed": speed,
        "density": scenario.density,
        "aero": model.aero_model,
        "open_loop_flutter_speed": vf,
        "open_loop_flutter_frequency": fr.flutter_frequency,
        "speed_over_flutter_speed": None if vf is None else speed / vf,
        "open_loop_unstable": bool(np.max(np.linalg.eigvals(np.asarray(plant.A)).real) > 0),
        "duration": scenario.duration,
        "sample_rate": scenario.sample_rate,
        "n_plant_states": plant.nstates,
        "signals": {},
        "saturated_fraction": result.saturated_fraction,
        "rate_limited_fraction": result.rate_limited_fraction,
        "units": dict(result.units),
    }
    for name, y in {**result.outputs, **result.applied}.items():
        rms, growth = float(np.sqrt(np.mean(y**2))), signal_growth(y)
        summary["signals"][name] = {"peak": float(np.abs(y).max()), "rms": rms, "growth": growth}
    sat, rl = summary["saturated_fraction"], summary["rate_limited_fraction"]
    limited = {c: max(sat[c], rl[c]) for c in sat}
    summary.update(loop_verdict(plant, at, scenario.delay, summary["signals"], limited))

    summary["expect_failure"] = scenario.expect_failure
    summary["response"] = "grows" if summary["growing_signals"] else "decays"
    wound = result.windup()
    if wound:
        from ..simulate.result import windup_text

        summary["windup"] = wound
        if "hint" in summary:  # a lost run: its one line says it
            summary["hint"] += f"; {windup_text(wound)}"
        else:
            summary.setdefault("warnings", []).append(windup_text(wound))
    if result.status:
        times = np.array([s["solve_time"] for s in result.status])
        summary["mpc"] = {
            "solve_time_median": float(np.median(times)),
            "solve_time_p99": float(np.percentile(times, 99)),
            "fallbacks": int(sum(s["fallback"] for s in result.status)),
            "statuses": sorted({s["status"] for s in result.status}),
        }
    analysis = analyse_loop(
        scenario,
        loop,
        plant,
        controller,
        speed,
        vf,
        lambda total, label: _progress_bar(total, label, progress),
        x0=x0,
    )
    summary.update(analysis.summary(vf))
    _final_verdict(summary, analysis)
    summary["wall_time"] = time.perf_counter() - t0
    return Run(
        scenario,
        summary,
        flutter=fr,
        simulation=result,
        open_loop=open_loop,
        boundary=analysis.boundary,
        margins=analysis.margins,
        margin_sweep=analysis.sweep,
        judgement=analysis.judgement,
    )


def _final_verdict(summary: dict, analysis) -> None:
    """The run's verdict over its engaged range: ``verdict`` "unstable" if the loop is unstable
    at the scenario's speed or anywhere in the engaged range; ``passed`` if it is stable and
    meets its margin requirement over the range (and at the speed); ``hint`` the one line that
    says why not."""
    j = analysis.judgement
    lines = [] if j is None else j.lines()
    if j is not None and not j.stable and summary["verdict"] == "stable":
        summary["verdict"] = "unstable"
        summary["hint"] = lines[0]
    margins = summary.get("margins")
    met = (margins is None or margins["meets"]) and (j is None or j.meets_requirement is not False)
    summary["passed"] = summary["verdict"] == "stable" and met
    if margins is not None and not margins["meets"] and not lines:
        lines = [f"loop margins miss the requirement: {'; '.join(margins['violations'])}"]
    if not summary["passed"] and "hint" not in summary:
        summary["hint"] = lines[0] if lines else "the loop fails its verdict"
    summary["verdict_lines"] = lines
