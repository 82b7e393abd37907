"""The analysis commands: ``flutter`` and ``modes`` (and ``envelope``, :mod:`.envelope`)."""

from __future__ import annotations

import argparse
import json
import sys

from .aero_options import add_aero_options, resolve_aero
from .envelope import add_parser as add_envelope_parser
from .envelope import cmd_envelope
from .options import (
    add_flight_options,
    add_model_options,
    check_figure,
    check_suffix,
    elements,
    named,
    positive_int,
    quantity,
    setup,
)

__all__ = ["add_parsers", "HANDLERS"]


def add_parsers(sub) -> None:
    """The analysis commands' parsers."""
    f = sub.add_parser(
        "flutter",
        help="flutter and divergence boundaries of a wing",
        description="Flutter and divergence boundaries of a built-in wing, a wing file or the "
        "wing of a scenario file, at a density or an altitude (docs/stability.md).",
    )
    f.add_argument(
        "wing",
        help="built-in wing (aeroservo examples lists them), a wing .toml or a scenario .toml",
    )
    f.add_argument("--json", action="store_true", help="print one JSON object")
    add_flight_options(f)
    add_model_options(f)
    f.add_argument(
        "--v-max", type=quantity("flight_speed"), help="upper end of the speed search [m/s]"
    )
    f.add_argument(
        "--modes",
        type=positive_int,
        help="fewest modes in the modal model (default 6; the mode rule and the certificate "
        "add what the wing needs, docs/stability.md)",
    )
    f.add_argument(
        "--pk", action="store_true", help="also solve by p-k with the exact Theodorsen function"
    )
    f.add_argument("--plot", metavar="FILE", help="write V-g and V-f diagrams (png, pdf, svg)")
    f.add_argument(
        "--save",
        metavar="FILE.npz",
        help="save the sweep (eigenvalues, damping, modes, wing, flight condition) for "
        "'aeroservo plot' and Python's aeroservo.load_result",
    )
    f.add_argument(
        "--table",
        metavar="FILE.csv",
        help="write the sweep as an f06-like table: per mode and speed, damping g, frequency, "
        "EAS and knots",
    )
    f.add_argument(
        "--g-required",
        type=quantity("structural_g"),
        metavar="G",
        help="required damping margin drawn on the V-g plot (e.g. 0.03)",
    )

    add_envelope_parser(sub)

    m = sub.add_parser(
        "modes",
        help="natural frequencies and mode shapes of a wing (in vacuo)",
        description="In-vacuo natural frequencies [Hz] and mode shapes of a built-in wing or a "
        "wing file, each mode named by its dominant motion (bending, torsion, control-surface "
        "rotation).",
    )
    m.add_argument("wing", help="built-in wing (aeroservo examples lists them) or a wing .toml")
    m.add_argument(
        "--elements", type=elements, help="beam elements (default: the wing file's, else 10)"
    )
    m.add_argument("-n", type=positive_int, default=6, help="number of modes (default 6)")
    m.add_argument("--json", action="store_true", help="print one JSON object")
    m.add_argument("--plot", metavar="FILE", help="mode shapes figure (png, pdf, svg)")
    m.add_argument("--mode", type=positive_int, metavar="N", help="only mode N (1-based)")
    m.add_argument(
        "--animate", metavar="FILE.gif", help="animation of mode N (default 1) at the tip"
    )
    m.add_argument(
        "--planform",
        metavar="FILE",
        help="top view of the wing: sweep, control surfaces, actuators, masses, and the "
        "doublet-lattice boxes with --aero dlm or a file's aero = 'dlm' (png, pdf, svg)",
    )
    add_aero_options(m)


def _wing_text(spec: str, wing) -> str:
    """The wing file text of a result: the file itself, or the wing written as one."""
    from pathlib import Path

    from ..files.toml_tables import is_scenario_file
    from ..files.user_files import read_text
    from ..files.wing_file import wing_toml

    p = Path(spec)
    if p.suffix == ".toml" and p.is_file() and not is_scenario_file(p):
        return read_text(p, what="wing file (TOML)")
    return wing_toml(wing)


def _cmd_flutter(args: argparse.Namespace) -> int:
    check_figure(args.plot)
    check_suffix("--save", args.save, ".npz")
    check_suffix("--table", args.table, ".csv")
    s = setup(args)
    from ..studies.flight_condition import flutter_analysis

    model, wing = s.model, s.wing
    v_max = args.v_max if args.v_max is not None else s.opts.v_max
    n_modes = args.modes if args.modes is not None else s.opts.n_modes
    cond = (model, s.density, s.atmosphere, s.compressibility, s.mach)
    with named("n_modes", "--modes" if args.modes is not None else None, args, "n_modes"):
        fa = flutter_analysis(
            model, wing.name, cond, v_max=v_max, n_modes=n_modes, pk=args.pk, sol145=s.sol145
        )
    result, pk, sol, out, source, title = (
        fa.boundary,
        fa.pk,
        fa.sol145,
        fa.record,
        fa.mach_source,
        fa.title,
    )
    writers = []
    if args.plot:
        from ..atomic import figure_writer
        from ..plots import plot_vg

        fig = plot_vg(result, title=title, g_required=args.g_required, units=args.units, pk=pk)
        writers.append((args.plot, figure_writer(fig, args.plot, dpi=150)))
        out["plot"] = args.plot
    if args.save:
        from ..files.flutter_file import flutter_writer

        text = _wing_text(args.wing, wing)
        writers.append(
            (args.save, flutter_writer(result, wing_text=text, model=model, pk=pk, title=title))
        )
        out["saved"] = args.save
    if args.table:
        from ..files.flutter_table import flutter_table

        table = flutter_table(result, pk)
        writers.append((args.table, lambda p: p.write_text(table, encoding="utf-8")))
        out["table"] = args.table
    if writers:
        from ..atomic import atomic_write_set

        atomic_write_set(writers)  # all the files, or none
    for w in dict.fromkeys(result.warnings + (pk.warnings if pk is not None else [])):
        print(f"aeroservo: warning: {w}", file=sys.stderr)
    if args.json:
        from ..result_shape import json_text

        print(json_text(out))
        return 0
    if model.dlm is None:
        print(f"{wing.name}: {model.n_elements} elements, Wagner '{model.wagner.name}'")
    else:
        from ..studies.flight_condition import aero_text

        print(f"{wing.name}: {model.n_elements} elements")
        print(aero_text(model, result.mach, source))
    print(result.summary(warnings=False, units=args.units))
    if pk is not None:
        how = "exact Theodorsen" if model.dlm is None else "doublet lattice"
        if pk.flutter_speed is None:
            print(f"p-k ({how}): no flutter below {pk.searched_up_to:.4g} m/s")
        else:
            text = pk.speed_text(pk.flutter_speed, args.units)
            print(f"p-k ({how}): flutter {text} at {pk.flutter_frequency:.5g} Hz")
    if sol is not None:
        print(f"\nNastran flutter summary ({sol.method} velocities of the deck, aeroservo's p-k):")
        print(sol.text())
    elif s.sol145 is not None:
        print(
            f"the deck's {s.sol145['method']} case lists reduced frequencies, not velocities: "
            "p-k over the speed range above (give sol145.velocities [m/s] for a flutter summary)"
        )
    for key, what in (("plot", "plot"), ("saved", "sweep"), ("table", "table")):
        if key in out:
            print(f"{what} written to {out[key]}")
    return 0


def _cmd_modes(args: argparse.Namespace) -> int:
    from ..errors import InputError, check_int
    from ..files.wing_file import resolve_wing
    from ..system.aeroelastic import AeroelasticModel

    check_figure(args.plot)
    check_suffix("--animate", args.animate, ".gif")
    check_figure(args.planform, "--planform")
    wing, opts = resolve_wing(args.wing)
    aero, _mach, _comp = resolve_aero(args, opts)
    with named("n_elements", "--elements" if args.elements else None, args, "elements"):
        model = AeroelasticModel(
            wing, n_elements=args.elements or opts.elements, aero=aero or "strip"
        )
    check_int("-n", args.n, lo=1, hi=model.n_dofs)
    modes = model.natural_modes(min(max(args.n, args.mode or 1), model.n_dofs))
    if args.mode is not None and args.mode > modes.frequencies.size:
        raise InputError(f"--mode = {args.mode}: the model has {modes.frequencies.size} modes")
    if args.plot or args.animate or args.planform:
        _mode_figures(args, model, modes)
    if args.json:
        print(
            json.dumps(
                {
                    "wing": wing.name,
                    "frequencies": modes.frequencies.tolist(),
                    "labels": modes.labels,
                    "units": {"frequency": "Hz"},
                },
                indent=2,
            )
        )
    else:
        print(f"{wing.name}: {model.n_elements} elements, in-vacuo natural modes")
        for fr, lab in zip(modes.frequencies, modes.labels, strict=True):
            print(f"  {fr:10.4f} Hz  {lab}")
    return 0


def _mode_figures(args: argparse.Namespace, model, modes) -> None:
    """The ``--plot``, ``--animate`` and ``--planform`` files of ``aeroservo modes`` (written
    as a set)."""
    from ..atomic import atomic_write_set, figure_writer
    from ..plots.modes import gif_writer, plot_modes, strain_energy_shares

    fields = model.mode_fields(modes.shapes)
    cols = [args.mode - 1] if args.mode else list(range(modes.frequencies.size))
    surfaces = {cs.name: (cs.start, cs.end) for cs in model.wing.control_surfaces}
    writers = []
    title = f"{model.wing.name}: {model.n_elements} elements, in-vacuo natural modes"
    if args.plot:
        shares = strain_energy_shares(model, modes.shapes)
        fig = plot_modes(
            fields,
            modes.labels,
            modes.frequencies,
            surfaces=surfaces,
            modes=cols,
            title=title,
            shares=shares,
            masses={pm.name: pm.station for pm in model.wing.masses},
        )
        writers.append((args.plot, figure_writer(fig, args.plot, dpi=130)))
    if args.planform:
        from ..plots.planform import plot_planform

        lattice = None if model.dlm is None else model.dlm.grid.lattice
        fig = plot_planform(model.wing, lattice=lattice)
        writers.append((args.planform, figure_writer(fig, args.planform, dpi=130)))
    if args.animate:
        j = (args.mode or 1) - 1
        kw = {"label": modes.labels[j], "frequency": float(modes.frequencies[j])}
        writers.append((args.animate, gif_writer(fields, j, model.wing, **kw)))
    atomic_write_set(writers)
    for path, _ in writers:
        print(f"written {path}", file=sys.stderr)


HANDLERS = {"flutter": _cmd_flutter, "envelope": cmd_envelope, "modes": _cmd_modes}
