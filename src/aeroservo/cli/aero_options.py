"""The aerodynamic model on the command line: ``--aero strip|dlm``, ``--boxes NC[,NS]`` and a
fixed ``--mach M``, over what a wing file or a scenario file says (``docs/dlm.md``)."""

from __future__ import annotations

import argparse

from ..errors import InputError, parse_number

__all__ = [
    "COMPRESSIBILITY_CHOICES",
    "boxes",
    "add_aero_options",
    "add_mach_option",
    "resolve_aero",
    "load_scenario_with",
]

COMPRESSIBILITY_CHOICES = ("none", "prandtl-glauert", "matched")
"""``--compressibility``: ``matched`` and ``prandtl-glauert`` both match the Mach number to the
speed (strip theory's Prandtl-Glauert correction, the doublet lattice's Mach number)."""


def boxes(text: str) -> tuple[int, ...]:
    """An argparse type: ``NC[,NS]`` doublet-lattice box counts (chordwise[, spanwise])."""
    parts = text.split(",")
    try:
        if not 1 <= len(parts) <= 2:
            raise ValueError
        out = tuple(int(t) for t in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected NC or NC,NS (chordwise and spanwise box counts, integers)"
        ) from None
    if min(out) < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: box counts must be >= 1")
    return out


def finite_number(text: str) -> float:
    """An argparse type: a finite number (a Mach number, an altitude, ...)."""
    try:
        v = parse_number(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if v != v or abs(v) == float("inf"):
        raise argparse.ArgumentTypeError(f"{text!r}: must be a finite number")
    return v


def add_mach_option(p: argparse.ArgumentParser) -> None:
    """``--mach M``: a fixed Mach number."""
    p.add_argument(
        "--mach",
        type=finite_number,
        metavar="M",
        help="fixed Mach number of the aerodynamics (doublet lattice: 0 <= M < 1; strip theory: "
        "Prandtl-Glauert, M < 0.9); default: the file's, else 0 (or matched with "
        "--compressibility matched)",
    )


def add_aero_options(p: argparse.ArgumentParser, mach: bool = False) -> None:
    """``--aero`` and ``--boxes`` (and ``--mach`` if ``mach``)."""
    p.add_argument(
        "--aero",
        choices=("strip", "dlm"),
        help="aerodynamic model: strip theory or the doublet lattice (docs/dlm.md); default: "
        "the file's, else strip",
    )
    p.add_argument(
        "--boxes",
        type=boxes,
        metavar="NC[,NS]",
        help="doublet-lattice boxes chordwise[,spanwise] (with --aero dlm or a file's "
        "aero = 'dlm'; default: the file's, else 6 chordwise and square boxes)",
    )
    if mach:
        add_mach_option(p)


def _boxes_text(nb) -> str:
    return ",".join(map(str, nb))


def resolve_aero(args: argparse.Namespace, opts, where: str = "analysis") -> tuple:
    """``(settings, mach, compressibility)`` of a command: ``--aero``, ``--boxes``, ``--mach``
    and ``--compressibility`` over the file's options ``opts``
    (:class:`~aeroservo.files.wing_file.AnalysisOptions`; ``where`` names its table). A fixed
    Mach number and a matched compressibility are refused together on the command line; one
    given there replaces the other from the file."""
    from dataclasses import replace

    name = getattr(args, "aero", None)
    aero = opts.aero if name is None or name == "dlm" else None
    if name == "dlm" and aero is None:
        from ..aero.dlm_settings import DoubletLattice

        aero = DoubletLattice()
    nb = getattr(args, "boxes", None)
    if nb is not None:
        if aero is None:
            raise InputError(
                f"--boxes = {_boxes_text(nb)}: box counts of the doublet lattice; the model is "
                "strip theory (give --aero dlm)"
            )
        try:
            aero = replace(aero, chordwise=nb[0], **({"spanwise": nb[1]} if len(nb) > 1 else {}))
        except InputError as exc:
            msg = (
                str(exc)
                .replace("dlm.chordwise", "--boxes NC")
                .replace("dlm.spanwise", "--boxes NS")
            )
            raise InputError(msg) from None
    comp_arg, mach_arg = getattr(args, "compressibility", None), getattr(args, "mach", None)
    if mach_arg is not None and comp_arg not in (None, "none"):
        raise InputError(
            f"--mach = {mach_arg:g} and --compressibility = {comp_arg!r}: give a fixed Mach "
            "number or a Mach number matched to the speed, not both"
        )
    if mach_arg is not None:
        from ..files.aero_tables import check_model_mach

        return aero, check_model_mach(aero, mach_arg, "--mach"), None
    comp = comp_arg or opts.compressibility
    comp = None if comp == "none" else comp
    mach = opts.mach if comp_arg in (None, "none") else None  # the file's, unless matched
    if mach is not None:  # checked again: --aero may have changed the model
        from ..files.aero_tables import check_model_mach

        mach = check_model_mach(aero, mach, f"{args.wing}: {where}.mach")
    return aero, mach, comp


_SCENARIO_KEYS = {
    "model.dlm.chordwise": "--boxes NC",
    "model.dlm.spanwise": "--boxes NS",
    "model.dlm": "--boxes",
    "model.aero": "--aero",
    "model.mach": "--mach",
}


def load_scenario_with(path: str, args: argparse.Namespace):
    """A scenario file read with the command's ``--aero``, ``--boxes`` and ``--mach`` in its
    ``[model]`` table (a fixed ``--mach`` replaces a matched ``model.compressibility``); an
    error about a value given on the command line names the option."""
    from ..files.scenario_file import load_scenario

    over: dict = {}
    if getattr(args, "aero", None) is not None:
        over["aero"] = args.aero
    if getattr(args, "mach", None) is not None:
        over["mach"] = args.mach
    nb = getattr(args, "boxes", None)
    if nb is not None:
        over["dlm"] = {"chordwise": nb[0], **({"spanwise": nb[1]} if len(nb) > 1 else {})}
    if not over:
        return load_scenario(path)
    try:
        return load_scenario(path, model=over)
    except InputError as exc:
        msg = str(exc)
        given = {
            "model.dlm.chordwise": nb is not None,
            "model.dlm.spanwise": nb is not None and len(nb) > 1,
            "model.dlm": nb is not None,
            "model.aero": "aero" in over,
            "model.mach": "mach" in over,
        }
        for key, option in _SCENARIO_KEYS.items():
            head = f"{path}: {key}"
            rest = msg[len(head) :]
            if given[key] and msg.startswith(head) and rest[:2] in (" =", ": "):
                if key == "model.dlm":
                    if not rest.startswith(": "):
                        continue
                    rest = f" = {_boxes_text(nb)}{rest}"
                raise InputError(option + rest) from None
        raise
