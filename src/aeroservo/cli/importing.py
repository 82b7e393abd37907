"""Command line: ``import nastran`` (a Nastran stick-model deck as a wing file)."""

from __future__ import annotations

import argparse

from .options import quantity

UNIT_NAMES = ("si", "in-lbf-s", "ft-slug-s", "mm-t-s")
"""The unit systems of ``--units`` (``files/nastran/units.UNIT_SYSTEMS``, not imported here to
keep the parser free of numpy)."""

__all__ = ["add_parsers", "HANDLERS"]


def _elastic_axis(text: str) -> float:
    """An argparse type: the elastic-axis position a in [-1, 1]."""
    from ..errors import InputError, check_number, parse_number

    try:
        return check_number(repr(text), parse_number(text), lo=-1.0, hi=1.0)
    except ValueError as exc:  # InputError is a ValueError
        detail = str(exc) if isinstance(exc, InputError) else f"{text!r} is not a number"
        raise argparse.ArgumentTypeError(detail) from None


def add_parsers(sub) -> None:
    """The parser of ``import`` and its formats."""
    p = sub.add_parser(
        "import",
        help="a wing file from another tool's model (a Nastran beam deck)",
        description="Write a wing file from a model made by another tool.",
    )
    formats = p.add_subparsers(dest="format", required=True, metavar="FORMAT")
    nas = formats.add_parser(
        "nastran",
        help="a cantilever stick model (CBAR/CBEAM, masses, SPC) with its aero and flutter "
        "cards (CAERO1, SPLINE, FLUTTER)",
        description="Read a Nastran cantilever stick model (read with pyNastran: pip install "
        "'aeroservo[nastran]') and write a wing file with a comment on each value saying where "
        "it came from, converted to SI from the units given. The chord and elastic axis come "
        "from the deck's CAERO1 panels, or from the options or a companion table; a deck with a "
        "FLUTTER card also gets a flutter scenario <out>_flutter.toml (docs/nastran.md).",
    )
    nas.add_argument("deck", help="Nastran bulk data (.bdf, .dat, .nas)")
    nas.add_argument("--out", required=True, metavar="FILE", help="wing file to write (.toml)")
    nas.add_argument(
        "--units",
        choices=tuple(UNIT_NAMES),
        default="si",
        help="the deck's unit system (default si: N, m, kg, s); converted to SI once",
    )
    chord = nas.add_mutually_exclusive_group()
    chord.add_argument(
        "--chord",
        type=quantity("semichord"),
        metavar="C",
        help="chord [m] normal to the beam (default: from the CAERO1 panels)",
    )
    chord.add_argument(
        "--semichord", type=quantity("semichord"), metavar="B", help="[m], normal to the beam"
    )
    nas.add_argument(
        "--elastic-axis",
        type=_elastic_axis,
        metavar="A",
        help="elastic-axis position a, semichords aft of mid-chord (-1 leading edge)",
    )
    nas.add_argument(
        "--companion",
        metavar="TABLE",
        help="TOML table: chord, elastic axis, x_alpha, inertia, control surfaces, per span",
    )
    nas.add_argument("--name", help="wing name (default: the deck's file name)")


def _cmd_import(args: argparse.Namespace) -> int:
    from ..files.nastran.importer import write_nastran_wing

    result = write_nastran_wing(
        args.deck,
        args.out,
        chord=args.chord,
        semichord=args.semichord,
        elastic_axis=args.elastic_axis,
        companion=args.companion,
        name=args.name,
        units=args.units,
    )
    print(f"wrote {args.out}: {result.summary}")
    if result.scenario is not None:
        from ..files.nastran.importer import scenario_path

        print(
            f"wrote {scenario_path(args.out)}: run it with 'aeroservo flutter "
            f"{scenario_path(args.out)}'"
        )
    return 0


HANDLERS = {"import": _cmd_import}
