"""The ``lco`` command: limit-cycle oscillations of an ``lco`` scenario (a wing or a typical
section with nonlinear hinges, open or closed loop) over its speeds and initial rotations (in
this process or on Dask), written as one set of files (``aeroservo plot RESULT.json`` redraws
its figures: ``LCOResult.plot``)."""

from __future__ import annotations

import argparse

from ..errors import InputError
from .aero_options import add_aero_options, load_scenario_with
from .loads import _workers

__all__ = ["add_parsers", "HANDLERS", "run_lco_loaded", "LCO_KINDS"]

LCO_KINDS = ("bifurcation", "histories")
"""The figures of a saved limit-cycle result (``aeroservo plot --kind``)."""


def add_parsers(sub) -> None:
    """The parser of ``lco``."""
    helptext = "limit cycles of nonlinear hinges (freeplay, bilinear, cubic): an lco scenario"
    r = sub.add_parser(
        "lco",
        help=helptext,
        description="March a wing or a typical section with nonlinear hinges from rest with each "
        "initial rotation at each speed of an lco scenario, and along the speeds up and down "
        "(continuation), open loop or with its controller held fixed; judge each march (limit "
        "cycle, decay, divergence) and compare with the describing function. Writes "
        "RESULT.json, .csv, _branches.csv, _histories.npz, _summary.txt and the figures "
        "_bifurcation.png and _histories.png into --out (all or none); 'aeroservo plot "
        "DIR/RESULT.json' redraws them.",
    )
    r.add_argument("scenario", help="scenario file (.toml, kind = 'lco'), docs/scenarios.md")
    r.add_argument("--out", metavar="DIR", default="out", help="output folder (default out)")
    r.add_argument("--json", action="store_true", help="print the summary as JSON")
    r.add_argument(
        "--quick",
        action="store_true",
        help="fast settings for smoke tests (3 speeds, 2 initial rotations, 2 s marches, no "
        "describing function)",
    )
    r.add_argument("--no-plots", action="store_true", help="write the data files only")
    add_aero_options(r, mach=True)
    r.add_argument(
        "--quiet",
        dest="progress",
        action="store_false",
        default=None,
        help="no progress bar (default: a progress bar on stderr when it is a terminal)",
    )
    where = r.add_mutually_exclusive_group()
    where.add_argument(
        "--scheduler", metavar="ADDRESS", help="existing Dask scheduler, tcp://host:port"
    )
    where.add_argument(
        "--workers",
        type=_workers,
        metavar="N",
        help="local Dask workers, 0 in this process (default: lco.workers)",
    )


def _cmd_lco(args: argparse.Namespace) -> int:
    from .options import require_kind

    scenario = load_scenario_with(args.scenario, args)
    require_kind(scenario, args.scenario, "lco")
    return run_lco_loaded(scenario, args)


def run_lco_loaded(scenario, args: argparse.Namespace) -> int:
    """Run a loaded ``lco`` scenario with the options of ``lco`` (or of ``run``), write its
    files and print its summary."""
    from .options import run_study

    workers, scheduler = getattr(args, "workers", None), getattr(args, "scheduler", None)
    if workers is not None and scheduler is not None:  # 'aeroservo run' takes both
        raise InputError(
            f"--workers = {workers} and --scheduler = {scheduler!r}: give one (local workers "
            "or a running Dask scheduler)"
        )
    if workers is not None and not 0 <= workers <= 256:
        raise InputError(f"--workers = {workers}: allowed range is [0, 256]")
    return run_study(scenario, args, lambda run: run.lco.summary())


HANDLERS = {"lco": _cmd_lco}
