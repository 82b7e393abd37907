"""Running scenarios: open-loop flutter, closed-loop simulation, trade study.

Each ``run_*`` function computes and returns a :class:`Run`: the JSON-ready summary and the
result objects behind it. Nothing is written here except a trade study's own case store (its
folder, so that an interrupted study resumes); :func:`aeroservo.files.outputs.write_run` writes
a run's summary, result file and figures as one set.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._threads import blas_limited
from ..errors import InputError
from .loop_analysis import analyse_loop
from .scenario import Scenario
from .verdict import loop_verdict, signal_growth

__all__ = ["Run", "run_scenario", "run_flutter", "run_simulation", "study_from_scenario"]


@dataclass
class Run:
    """What one scenario run produced.

    Attributes
    ----------
    scenario : Scenario
    summary : dict
        JSON-ready summary (SI units; the ``units`` entry names them).
    flutter : FlutterResult or None
        Open-loop boundary (flutter scenarios; the plant's, for simulations).
    simulation : SimulationResult or None
        Time histories (simulate scenarios).
    open_loop : SimulationResult or None
        The same run with the controller off (same speed, initial state and gust), for the
        time-history figure's overlay (controlled simulations with plots).
    boundary : ClosedLoopBoundary or None
        Closed-loop boundary, when the scenario asks for it.
    margins : LoopMargins or None
        Loop margins at the actuator at the scenario's speed (controlled loops).
    margin_sweep : MarginSweep or None
        The margins across the engaged speed range (linear controllers).
    judgement : LoopJudgement or SimulatedJudgement or None
        The loop judged over its engaged speed range (controlled loops).
    trade : TradeResult or None
        Trade-study results (its case store, CSV and NetCDF are already in ``folder``).
    loads, lco : GustLoadsResult, LCOResult or None
        Gust loads (gust_loads scenarios), limit cycles (lco scenarios).
    folder : Path or None
        Folder of a trade study's outputs.
    title : str
        Title of the figures.
    """

    scenario: Scenario
    summary: dict
    flutter: object = None
    simulation: object = None
    open_loop: object = None
    boundary: object = None
    margins: object = None
    margin_sweep: object = None
    judgement: object = None
    trade: object = None
    loads: object = None
    lco: object = None
    folder: Path | None = None
    title: str = ""


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
    from .flight_condition import aero_record, flutter_at_condition, mach_source

    model = scenario.model()
    atm = scenario.atmosphere
    cond = (model, scenario.density, atm, scenario.compressibility, scenario.mach)
    update, close = _progress_bar(scenario.v_max or 300.0, "flutter sweep", progress)
    try:
        kw = {} if atm is not None else {"progress": update}
        fr = flutter_at_condition(*cond, v_max=scenario.v_max, **kw)
    finally:
        close()
    summary = {
        "scenario": scenario.name,
        "kind": "flutter",
        "wing": scenario.wing.name,
        "flutter_speed": fr.flutter_speed,
        "flutter_frequency": fr.flutter_frequency,
        "divergence_speed": fr.divergence_speed,
        "n_states": fr.n_states,
        "density": scenario.density,
        "n_elements": model.n_elements,
        "wagner": model.wagner.name,
        "units": {"speed": "m/s", "frequency": "Hz", "density": "kg/m^3"},
        **aero_record(model, fr.mach, mach_source(scenario.compressibility, scenario.mach, atm)),
    }
    summary.update({k: v for k, v in fr.to_dict().items() if k not in summary})
    sol145 = scenario.sol145
    if sol145 is not None and sol145["velocities"]:
        from .flight_condition import sol145_at_condition

        pk, table = sol145_at_condition(cond, fr, sol145)
        summary["sol145"] = table.to_dict()
    elif scenario.pk:
        from ..stability.pk import pk_flutter

        kw = {"boundary": fr} if atm is None else {}
        pk = flutter_at_condition(*cond, solver=pk_flutter, v_max=fr.v_max, **kw)
    if scenario.pk or "sol145" in summary:
        summary["pk_exact_theodorsen" if model.dlm is None else "pk_doublet_lattice"] = {
            "flutter_speed": pk.flutter_speed,
            "flutter_frequency": pk.flutter_frequency,
        }

    aero = model.wagner.name if model.dlm is None else f"doublet lattice, Mach {fr.mach:.3g}"
    title = f"{scenario.wing.name}: {model.n_elements} elements, {aero}"
    return Run(scenario, summary, flutter=fr, title=title)


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

    if scenario.kind != "simulate":
        raise InputError(f"{scenario.source}: scenario.kind = {scenario.kind!r}: not 'simulate'")
    t0 = time.perf_counter()
    model = scenario.model()
    fr = flutter_boundary(model, scenario.density)
    vf = fr.flutter_speed
    if scenario.speed is not None:
        speed = scenario.speed
    elif vf is None:
        raise ArithmeticError(
            f"{scenario.source}: flight.speed_factor needs the open-loop flutter speed, but the "
            f"wing has no flutter below {fr.v_max:.4g} m/s"
        )
    else:
        speed = scenario.speed_factor * vf
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


@blas_limited
def run_scenario(
    scenario: Scenario,
    out_dir: Path | None = None,
    *,
    progress: bool = False,
    scheduler: str | None = None,
    workers: int | None = None,
    log: Callable[[str], None] | None = None,
) -> dict:
    """Run any scenario.

    Parameters
    ----------
    scenario : Scenario
    out_dir : Path, optional
        Output folder; a trade study keeps its case store in ``out_dir / scenario.result``
        (required for trade studies, unused otherwise).
    progress : bool
        Progress bars on stderr.
    scheduler, workers :
        Dask scheduler address and local workers of a trade, gust-loads or limit-cycle study.

    Returns
    -------
    Run
    """
    if scenario.kind == "flutter":
        return run_flutter(scenario, progress)
    if scenario.kind == "simulate":
        return run_simulation(scenario, progress)
    if scenario.kind in ("gust_loads", "lco"):
        from .gust_scenario import run_gust_scenario
        from .lco_scenario import run_lco_scenario

        study = {"gust_loads": ("loads", run_gust_scenario), "lco": ("lco", run_lco_scenario)}
        field, run = study[scenario.kind]
        summary, res = run(scenario, progress, scheduler, workers)
        return Run(scenario, summary, **{field: res}, title=scenario.name)
    from .trade.cluster import run_trade

    if out_dir is None:
        raise InputError("a trade study needs an output folder (--out)")
    folder = out_dir / scenario.result
    res = run_trade(
        study_from_scenario(scenario),
        folder,
        scheduler=scheduler,
        n_workers=workers or scenario.trade["workers"],
        progress=progress,
    )
    summary = {
        "scenario": scenario.name,
        "kind": "trade",
        "n_cases": res.n_cases,
        "n_failed": res.n_failed,
        "n_skipped": res.n_skipped,
        "elapsed": res.elapsed,
        "cases_per_second": (res.n_cases - res.n_skipped) / max(res.elapsed, 1e-9),
    }
    best = res.best_case()  # the case the figures outline (trade.ranking)
    if best is not None:
        summary["best_case"] = {
            k: (v.item() if hasattr(v, "item") else v) for k, v in best.items() if v == v
        }
        summary["best_case_criterion"] = res.best_criterion
    return Run(scenario, summary, trade=res, folder=folder)


def study_from_scenario(scenario: Scenario):
    """The :class:`~aeroservo.studies.trade.TradeStudy` of a ``trade`` scenario."""
    from .trade.study import TradeStudy

    t = scenario.trade
    return TradeStudy(
        base_wing=scenario.wing,
        density=scenario.density,
        damping=scenario.damping,
        elements=scenario.elements,
        wagner=scenario.wagner,
        aero=scenario.aero,
        controls=tuple(scenario.controls),
        sensors=tuple(scenario.sensors),
        outputs=tuple(scenario.outputs),
        design_modes=scenario.design_modes,
        sensor_filter=scenario.sensor_filter,
        filter_order=scenario.filter_order,
        gust_model=scenario.gust_model,
        controller=t["controller"],
        sample_rate=scenario.sample_rate,
        delay=scenario.delay,
        actuator=scenario.actuator,
        parameters=dict(t["parameters"]),
        speed_factor=t["speed_factor"],
        gust_length=t["gust_length"],
        gust_amplitude=t["gust_amplitude"],
        gust_duration=t["gust_duration"],
        v_max_factor=t["v_max_factor"],
        n_grid=t["n_grid"],
        name=scenario.result,
        closed_loop=t.get("closed_loop", True),
    )
