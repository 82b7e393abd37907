"""A trade-study scenario (``kind = "trade"``): the :class:`~aeroservo.studies.trade.TradeStudy`
it describes and its run, whose case store is kept in the output folder (resumable)."""

from __future__ import annotations

from pathlib import Path

from ..kinds import Run, check_kind
from ..scenario import Scenario

__all__ = ["study_from_scenario", "run_trade_scenario"]


def study_from_scenario(scenario: Scenario):
    """The :class:`~aeroservo.studies.trade.TradeStudy` of a ``trade`` scenario."""
    from .study import TradeStudy

    check_kind(scenario, "trade")
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
        controller=t.controller,
        sample_rate=scenario.sample_rate,
        delay=scenario.delay,
        actuator=scenario.actuator,
        parameters=dict(t.parameters),
        speed_factor=t.speed_factor,
        gust_length=t.gust_length,
        gust_amplitude=t.gust_amplitude,
        gust_duration=t.gust_duration,
        v_max_factor=t.v_max_factor,
        n_grid=t.n_grid,
        name=scenario.result,
        closed_loop=t.closed_loop,
    )


def run_trade_scenario(
    scenario: Scenario,
    *,
    out_dir: Path,
    progress: bool = False,
    scheduler: str | None = None,
    workers: int | None = None,
) -> Run:
    """Run a ``trade`` scenario; its cases, CSV, NetCDF and figures go to
    ``out_dir / scenario.result`` (``workers``: local Dask workers, default the scenario's
    ``trade.workers``; ``scheduler``: a running Dask scheduler's address instead)."""
    from ...errors import InputError
    from .cluster import run_trade

    study = study_from_scenario(scenario)
    if workers is not None and workers < 1 and scheduler is None:
        raise InputError(f"workers = {workers}: a trade study runs on Dask workers (1 to 256)")
    folder = Path(out_dir) / scenario.result
    res = run_trade(
        study,
        folder,
        scheduler=scheduler,
        workers=scenario.trade.workers if workers is None else workers,
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
