"""Options shared by the analysis commands: numbers, the model, the flight condition, damping."""

from __future__ import annotations

import argparse
import contextlib
from dataclasses import dataclass

from ..errors import InputError, parse_number
from .aero_options import (
    COMPRESSIBILITY_CHOICES,
    add_aero_options,
    add_mach_option,
    finite_number,
    resolve_aero,
)

__all__ = [
    "quantity",
    "elements",
    "positive_float",
    "positive_int",
    "add_model_options",
    "add_flight_options",
    "Setup",
    "setup",
]


def positive_float(text: str) -> float:
    try:
        v = parse_number(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not v > 0 or v != v or v == float("inf"):
        raise argparse.ArgumentTypeError(f"{text!r}: must be a finite number > 0")
    return v


def positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: must be >= 1")
    return v


def quantity(name: str):
    """An argparse type: a number within the range of ``name`` in
    :data:`aeroservo.errors.RANGES`, the rule files and the API use too."""
    from ..errors import check_quantity

    def parse(text: str) -> float:
        try:
            v = parse_number(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
        try:
            return check_quantity(repr(text), v, name)
        except InputError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = name  # argparse names the type in some messages
    return parse


def elements(text: str) -> int:
    """An argparse type: a number of beam elements in [1, MAX_ELEMENTS]."""
    from ..errors import MAX_ELEMENTS

    v = positive_int(text)
    if v > MAX_ELEMENTS:
        raise argparse.ArgumentTypeError(f"{text!r}: allowed range is [1, {MAX_ELEMENTS}]")
    return v


def _numbers(text: str) -> list[float]:
    try:
        return [parse_number(t) for t in text.split(",")]  # a blank item is a ValueError
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected numbers separated by commas"
        ) from None


def add_model_options(p: argparse.ArgumentParser) -> None:
    """``--elements``, ``--wagner``, ``--aero``, ``--boxes`` and the structural damping
    options."""
    p.add_argument(
        "--elements", type=elements, help="number of beam elements (default: file, else 10)"
    )
    p.add_argument("--wagner", help="Wagner set: rt_jones, wp_jones, one_term, fit2, fit3, fit4")
    add_aero_options(p)
    d = p.add_mutually_exclusive_group()
    d.add_argument(
        "--damping-ratio",
        type=_numbers,
        metavar="Z[,Z...]",
        help="modal viscous damping ratio (one for all in-vacuo modes, or one per mode, the "
        "last repeated)",
    )
    d.add_argument(
        "--structural-g",
        type=finite_number,
        metavar="G",
        help="structural damping g (equivalent viscous zeta = g/2 at every in-vacuo mode)",
    )
    d.add_argument(
        "--rayleigh",
        type=_numbers,
        metavar="ALPHA,BETA",
        help="Rayleigh damping alpha M + beta K (alpha [1/s], beta [s])",
    )


def add_flight_options(p: argparse.ArgumentParser) -> None:
    """The flight condition: density or altitude, compressibility, units."""
    f = p.add_mutually_exclusive_group()
    f.add_argument(
        "--density",
        type=quantity("density"),
        help="air density [kg/m^3] (default: file, else 1.225)",
    )
    f.add_argument(
        "--altitude", type=finite_number, metavar="M", help="geopotential altitude [m] (ISA 1976)"
    )
    f.add_argument(
        "--altitude-ft", type=finite_number, metavar="FT", help="altitude [ft] (ISA 1976)"
    )
    p.add_argument(
        "--compressibility",
        choices=COMPRESSIBILITY_CHOICES,
        help="Mach number matched to the speed at the altitude (needs an altitude): strip "
        "theory's Prandtl-Glauert correction, the doublet lattice's Mach number ('matched' and "
        "'prandtl-glauert' say the same)",
    )
    add_mach_option(p)
    p.add_argument(
        "--units", choices=("si", "knots"), default="si", help="speeds in the text and plots"
    )


@dataclass
class Setup:
    """What the options resolve to."""

    wing: object
    model: object
    atmosphere: object  # Atmosphere or None
    density: float
    compressibility: str | None
    opts: object
    mach: float | None = None  # a fixed Mach number (None: 0, or matched with compressibility)
    sol145: dict | None = None  # a scenario's Nastran flutter case (``[sol145]``)


def _damping(args, default):
    from ..system.damping import StructuralDamping

    try:
        if getattr(args, "damping_ratio", None) is not None:
            return StructuralDamping.modal(args.damping_ratio)
        if getattr(args, "structural_g", None) is not None:
            return StructuralDamping.structural(args.structural_g)
        if getattr(args, "rayleigh", None) is not None:
            if len(args.rayleigh) != 2:
                raise InputError(f"--rayleigh = {args.rayleigh}: give ALPHA,BETA")
            return StructuralDamping.rayleigh(*args.rayleigh)
    except InputError as exc:  # named by the option the user typed
        msg = str(exc)
        for key, option in DAMPING_OPTIONS.items():
            if msg.startswith(key):
                raise InputError(option + msg[len(key) :]) from None
        raise
    return default


DAMPING_OPTIONS = {
    "damping.ratio": "--damping-ratio",
    "damping.g": "--structural-g",
    "damping.alpha": "--rayleigh ALPHA",
    "damping.beta": "--rayleigh BETA",
}


@contextlib.contextmanager
def named(argument: str, option: str | None, args: argparse.Namespace, key: str):
    """Re-raise an InputError about the API argument ``argument`` (``"n_elements = 1: ..."``)
    naming where the value came from: the option if it was given, else the file's key."""
    try:
        yield
    except InputError as exc:
        msg = str(exc)
        if not msg.startswith(f"{argument} = "):
            raise
        rest = msg[len(argument) :]
        if option is not None:
            raise InputError(f"{option}{rest}") from None
        where = "model" if _is_scenario(args.wing) else "analysis"
        raise InputError(f"{args.wing}: {where}.{key}{rest}") from None


def _is_scenario(spec: str) -> bool:
    from ..files.toml_tables import is_scenario_file

    return spec.endswith(".toml") and is_scenario_file(spec)


def setup(args: argparse.Namespace, altitudes: bool = False) -> Setup:
    """The wing, model and flight condition of an analysis command (file defaults, then the
    command-line options); ``altitudes``: the command sweeps altitudes itself."""
    from ..files.toml_tables import read_toml

    # a missing or malformed file is reported before numpy and scipy are imported
    scenario = args.wing.endswith(".toml") and "scenario" in read_toml(args.wing)

    from ..aero.atmosphere import isa, isa_ft
    from ..files.wing_file import AnalysisOptions, resolve_wing
    from ..system.aeroelastic import AeroelasticModel

    if scenario:
        from ..files.scenario_file import load_scenario

        sc = load_scenario(args.wing)  # a scenario: its wing, flight condition and options
        if sc.wing is None:
            raise InputError(
                f"{args.wing}: section: a typical section, not a wing; run the scenario with "
                "'aeroservo lco'"
            )
        wing = sc.wing
        opts = AnalysisOptions(
            sc.density,
            sc.elements,
            sc.wagner,
            sc.v_max,
            altitude=sc.altitude,
            compressibility=sc.compressibility,
            damping=sc.damping,
            aero=sc.aero,
            mach=sc.mach,
        )
    else:
        wing, opts = resolve_wing(args.wing)
    atm = None
    if getattr(args, "altitude", None) is not None:
        atm = isa(args.altitude)
    elif getattr(args, "altitude_ft", None) is not None:
        atm = isa_ft(args.altitude_ft)
    elif getattr(args, "density", None) is None and opts.altitude is not None:
        atm = isa(opts.altitude)
    density = atm.density if atm is not None else (getattr(args, "density", None) or opts.density)

    aero, mach, comp = resolve_aero(args, opts, "model" if scenario else "analysis")
    if comp is not None and atm is None and not altitudes:
        raise InputError(
            f"--compressibility = {comp!r}: needs the speed of sound, give --altitude M or "
            "--altitude-ft FT instead of a density"
        )
    elements = args.elements if args.elements is not None else opts.elements
    wagner = args.wagner if args.wagner is not None else opts.wagner
    option = "--elements" if args.elements is not None else None
    with named("n_elements", option, args, "elements"):
        model = AeroelasticModel(
            wing, elements, wagner, damping=_damping(args, opts.damping), aero=aero or "strip"
        )
    sol145 = sc.sol145 if scenario else None
    return Setup(wing, model, atm, density, comp, opts, mach, sol145)


def check_figure(path: str | None, option: str = "--plot") -> None:
    """Refuse an unknown figure format before computing anything."""
    if path is None:
        return
    from pathlib import Path

    from ..atomic import check_output_path
    from ..errors import InputError

    fmt = Path(path).suffix.lstrip(".").lower()
    if fmt not in ("png", "pdf", "svg", "jpg", "jpeg", "eps", "ps", "tif", "tiff", "webp"):
        raise InputError(f"{option} = {path!r}: unknown figure format {fmt!r}; use png, pdf or svg")
    check_output_path(path, option)


def check_suffix(option: str, path: str | None, suffix: str) -> None:
    if path is None:
        return
    from pathlib import Path

    from ..atomic import check_output_path
    from ..errors import InputError

    if Path(path).suffix.lower() != suffix:
        raise InputError(f"{option} = {path!r}: expected a {suffix} file name")
    check_output_path(path, option)


def run_into_folder(scenario, args: argparse.Namespace):
    """Run a loaded scenario into the folder ``args.out`` (created; refused if it is a file)
    with the progress, scheduler and worker options of ``args``, and write its files as one
    set; returns ``(run, {kind: path})``."""
    import sys
    from pathlib import Path

    from ..files.outputs import write_run
    from ..studies.runs import run_scenario

    if not args.out.strip():
        raise InputError("--out = '': give an output folder")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out = {args.out!r}: is a file, expected a folder")
    made = not out.exists()
    out.mkdir(parents=True, exist_ok=True)
    progress = sys.stderr.isatty() if args.progress is None else args.progress
    try:
        run = run_scenario(
            scenario,
            out,
            progress=progress,
            scheduler=getattr(args, "scheduler", None),
            workers=getattr(args, "workers", None),
        )
        return run, write_run(run, out)
    except BaseException:
        if made and out.is_dir() and not any(out.iterdir()):  # a failed run leaves nothing
            out.rmdir()
        raise
