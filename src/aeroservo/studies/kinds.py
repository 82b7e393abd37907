"""The registry of scenario kinds: for each kind, what it computes, the tables of its scenario
file, its typed options, the function that runs it, the result it gives and the command that
offers it. Every dispatch on a scenario's kind goes through :data:`KINDS` (the file reader, the
writer of a run's files and the command line take their per-kind parts from here), so a new
kind is one entry here plus its runner, its options and its file tables.

A run of any kind is one call, :func:`run_scenario` (``workers``, ``scheduler`` and
``progress`` mean the same for every study on Dask), and gives a :class:`Run`.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from .._threads import blas_limited
from ..errors import InputError
from .study_options import GustLoadsOptions, LCOOptions, TradeOptions

if TYPE_CHECKING:  # the registry stays light: the command line reads it to build its parser
    from .scenario import Scenario

__all__ = ["Run", "ScenarioKind", "KINDS", "scenario_kind", "check_kind", "run_scenario"]


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

    @property
    def result(self) -> object:
        """The run's main result: its kind's (:attr:`ScenarioKind.result`)."""
        return getattr(self, scenario_kind(self.scenario.kind).result)


_COMMON = ("scenario", "wing", "flight", "model", "output", "damping")
_LOOP = ("signals", "actuator", "simulation")


@dataclass(frozen=True)
class ScenarioKind:
    """One kind of scenario.

    Attributes
    ----------
    name : str
        ``scenario.kind`` in a scenario file.
    description : str
        What a run computes (one line; the help of its command).
    command : str
        The command that runs it (``aeroservo run`` runs every kind).
    tables : tuple of str
        The top-level tables its scenario file may have (any other is an error).
    runner : str
        ``"module:function"`` under :mod:`aeroservo.studies` of the function that runs it:
        ``f(scenario, *, progress, [out_dir,] [workers, scheduler]) -> Run``.
    result : str
        The attribute of :class:`Run` that holds its main result.
    options : type or None
        Its typed options (:mod:`~aeroservo.studies.study_options`), None: none.
    on_dask : bool
        A study on Dask: takes ``workers`` (local workers, 0 in this process) and
        ``scheduler`` (a running Dask scheduler's address).
    folder : bool
        Keeps a store of its own in the output folder (a trade study's cases: resumable).
    quick : str
        What ``--quick`` does to it.
    section : bool
        May describe a typical section (``[section]``) instead of a wing.
    flight_is_design_point : bool
        ``[flight]`` is only the controller's design point (may be left out without one).
    needs_speed : bool
        ``flight.speed`` or ``flight.speed_factor`` is required.
    flight_condition : bool
        Takes a fixed Mach number and the matched compressibility (flutter at a flight
        condition); the other kinds are built at Mach 0.
    """

    name: str
    description: str
    command: str
    tables: tuple
    runner: str
    result: str
    options: type | None = None
    on_dask: bool = False
    folder: bool = False
    quick: str = ""
    section: bool = False
    flight_is_design_point: bool = False
    needs_speed: bool = False
    flight_condition: bool = False

    def runner_function(self) -> Callable[..., Run]:
        """The function that runs this kind (imported on first use)."""
        module, name = self.runner.split(":")
        return getattr(importlib.import_module(f"{__package__}.{module}"), name)

    def run(
        self,
        scenario: Scenario,
        *,
        out_dir: Path | None = None,
        progress: bool = False,
        scheduler: str | None = None,
        workers: int | None = None,
    ) -> Run:
        """Run a scenario of this kind (see :func:`run_scenario`)."""
        kw: dict = {"progress": progress}
        if self.on_dask:
            kw |= {"scheduler": scheduler, "workers": workers}
        elif scheduler is not None or workers is not None:
            given = "--scheduler" if scheduler is not None else "--workers"
            value = scheduler if scheduler is not None else workers
            on = ", ".join(k.name for k in KINDS.values() if k.on_dask)
            raise InputError(
                f"{given} = {value!r}: only the studies on Dask ({on}) take it; "
                f"{scenario.source} is a {self.name} scenario"
            )
        if self.folder:
            if out_dir is None:
                raise InputError(f"a {self.name} study needs an output folder (--out)")
            kw["out_dir"] = Path(out_dir)
        return self.runner_function()(scenario, **kw)


KINDS: dict[str, ScenarioKind] = {
    k.name: k
    for k in (
        ScenarioKind(
            "flutter",
            "open-loop flutter and divergence of a wing at a flight condition",
            "run",
            (*_COMMON, "analysis", "sol145"),
            "runs:run_flutter",
            "flutter",
            flight_condition=True,
        ),
        ScenarioKind(
            "simulate",
            "a closed-loop time simulation, its loop judged over the engaged speeds",
            "simulate",
            (*_COMMON, *_LOOP, "disturbance", "controller", "analysis"),
            "runs:run_simulation",
            "simulation",
            quick="at most 0.5 s simulated, an 11-point closed-loop grid, 3 margin speeds",
            needs_speed=True,
        ),
        ScenarioKind(
            "trade",
            "a trade study of wing and controller parameters on Dask",
            "trade",
            (*_COMMON, *_LOOP, "trade"),
            "trade.scenario:run_trade_scenario",
            "trade",
            TradeOptions,
            on_dask=True,
            folder=True,
            quick="two values per trade parameter, a 0.3 s gust, an 11-point boundary grid",
        ),
        ScenarioKind(
            "gust_loads",
            "gust and turbulence loads (CS-25.341) over flight points, open and closed loop",
            "loads",
            (*_COMMON, *_LOOP, "controller", "gust_loads"),
            "gust.scenario:run_gust_scenario",
            "loads",
            GustLoadsOptions,
            on_dask=True,
            quick="the first two flight points, at most 5 gust gradients",
            flight_is_design_point=True,
        ),
        ScenarioKind(
            "lco",
            "limit cycles of nonlinear hinges (freeplay, bilinear, cubic)",
            "lco",
            (*_COMMON, "signals", "simulation", "controller", "section", "lco"),
            "lco.scenario:run_lco_scenario",
            "lco",
            LCOOptions,
            on_dask=True,
            quick="3 speeds, 2 initial rotations, 2 s marches, no describing function",
            section=True,
        ),
    )
}
"""The scenario kinds by name."""


def scenario_kind(name: str) -> ScenarioKind:
    """The registered kind ``name`` (an InputError listing the kinds otherwise)."""
    try:
        return KINDS[name]
    except (KeyError, TypeError):
        raise InputError(f"scenario kind {name!r}: expected one of {list(KINDS)}") from None


def check_kind(scenario: Scenario, name: str, source: str | None = None) -> None:
    """An InputError naming the command that runs ``scenario`` unless it is of kind ``name``
    (``source``: the file named in the message, default the scenario's)."""
    if scenario.kind != name:
        use = scenario_kind(scenario.kind).command
        raise InputError(
            f"{source or scenario.source}: scenario.kind = {scenario.kind!r}: use "
            f"'aeroservo {use}' for it"
        )


@blas_limited
def run_scenario(
    scenario: Scenario,
    out_dir: Path | None = None,
    *,
    progress: bool = False,
    scheduler: str | None = None,
    workers: int | None = None,
) -> Run:
    """Run a scenario of any kind.

    Parameters
    ----------
    scenario : Scenario
    out_dir : Path, optional
        Output folder; a trade study keeps its case store in ``out_dir / scenario.result``
        (required for trade studies, unused otherwise).
    progress : bool
        Progress bars on stderr.
    scheduler : str, optional
        Address of a running Dask scheduler (studies on Dask only).
    workers : int, optional
        Local Dask workers, 0 in this process (studies on Dask only; default: the scenario's).

    Returns
    -------
    Run
    """
    return scenario_kind(scenario.kind).run(
        scenario, out_dir=out_dir, progress=progress, scheduler=scheduler, workers=workers
    )
