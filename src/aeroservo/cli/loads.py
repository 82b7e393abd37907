"""The ``loads`` command: the CS-25.341 gust loads of a ``gust_loads`` scenario, open and closed
loop, over its flight points (in this process or on Dask), written as one set of files."""

from __future__ import annotations

import argparse

from .aero_options import add_aero_options, load_scenario_with

__all__ = ["add_parsers", "HANDLERS", "run_loaded"]


def _workers(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if not 0 <= v <= 256:
        raise argparse.ArgumentTypeError(f"{text!r}: allowed range is [0, 256]")
    return v


def add_parsers(sub) -> None:
    """The parser of ``loads``."""
    helptext = "gust and turbulence loads (CS-25.341) of a gust_loads scenario"
    r = sub.add_parser(
        "loads",
        help=helptext,
        description="Discrete tuned gusts and continuous turbulence of CS-25.341 at every flight "
        "point of a gust_loads scenario, with and without its controller. Loads are increments "
        "of the wing clamped at its root (1 g loads added with the airplane's mass). Writes "
        "RESULT.json, .npz, .csv, _histories.csv, _alleviation.csv and the figures into --out "
        "(all or none); 'aeroservo plot DIR/RESULT.json' redraws them.",
    )
    r.add_argument("scenario", help="scenario file (.toml, kind = 'gust_loads'), docs/scenarios.md")
    r.add_argument("--out", metavar="DIR", default="out", help="output folder (default out)")
    r.add_argument("--json", action="store_true", help="print the summary as JSON")
    r.add_argument(
        "--quick",
        action="store_true",
        help="fast settings for smoke tests (the first two flight points, at most 5 gradients)",
    )
    r.add_argument("--no-plots", action="store_true", help="write the data files only")
    add_aero_options(r, mach=True)
    r.add_argument(
        "--progress",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="progress bar on stderr (default: when stderr is a terminal)",
    )
    r.add_argument(
        "--scheduler", metavar="ADDRESS", help="existing Dask scheduler, tcp://host:port"
    )
    r.add_argument(
        "--workers",
        type=_workers,
        metavar="N",
        help="local Dask workers, 0 in this process (default: gust_loads.workers)",
    )


def _cmd_loads(args: argparse.Namespace) -> int:
    from .options import require_kind

    scenario = load_scenario_with(args.scenario, args)
    require_kind(scenario, args.scenario, "gust_loads")
    return run_loaded(scenario, args)


def run_loaded(scenario, args: argparse.Namespace) -> int:
    """Run a loaded ``gust_loads`` scenario with the options of ``loads`` (or of ``run``), write
    its files and print its summary."""
    from .options import run_study

    return run_study(scenario, args, lambda run: run.loads.summary())


HANDLERS = {"loads": _cmd_loads}
