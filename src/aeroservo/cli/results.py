"""Command line: ``plot`` (redraw a saved result) and ``export`` (a state-space model for MATLAB
/ Simulink or NumPy)."""

from __future__ import annotations

import argparse

from .options import add_flight_options, add_model_options, positive_float, quantity

__all__ = ["add_parsers", "HANDLERS"]

FLUTTER_KINDS = ("vg", "vf", "root-locus", "modes", "flutter-mode")
GUST_KINDS = ("envelope", "correlated", "critical-gusts", "spanwise")
LCO_KINDS = ("bifurcation", "histories")
KINDS = (*FLUTTER_KINDS, "time", "pareto", "heatmap", "envelope", *GUST_KINDS[1:], *LCO_KINDS)
KINDS += ("boundary", "margins", "margin-sweep", "recovery")
"""Every result's figures (``result.FIGURES``; ``aeroservo plot --kind``)."""


def _mode_list(text: str) -> list[int]:
    try:
        out = [int(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: give mode numbers such as 1,2,4") from None
    if not out or min(out) < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: mode numbers start at 1")
    return out


def _names(text: str) -> list[str]:
    out = [t.strip() for t in text.split(",") if t.strip()]
    if not out:
        raise argparse.ArgumentTypeError(f"{text!r}: give signal names separated by commas")
    return out


def add_parsers(sub) -> None:
    """The parsers of ``plot`` and ``export``."""
    pl = sub.add_parser(
        "plot",
        help="redraw a saved result: flutter sweep, simulation, trade study, envelope or gust "
        "loads",
        description="Redraw a result: a sweep saved by 'aeroservo flutter --save' (kinds vg, "
        "vf, root-locus, modes, flutter-mode), a simulation written by 'aeroservo simulate' "
        "(time), a trade study's folder (pareto, heatmap: --metric and --slice choose the "
        "metric and the other parameters' values) or an envelope saved by 'aeroservo envelope "
        "--save' (envelope), gust loads written by 'aeroservo loads' (RESULT.json: envelope, "
        "correlated, critical-gusts, spanwise) or limit cycles written by 'aeroservo lco' "
        "(RESULT.json: bifurcation, histories); all of a result's figures without --kind and "
        "--out. Any result saved by its save() method (Python) redraws too: a closed-loop "
        "boundary (boundary), loop margins (margins), a margin sweep (margin-sweep), a "
        "recoverable set (recovery).",
    )
    pl.add_argument(
        "result", help="result file (.npz, envelope, gust-loads or lco .json) or trade folder"
    )
    pl.add_argument("--out", metavar="FILE", help="figure file (default: RESULT with .png)")
    pl.add_argument("--kind", choices=KINDS, help="figure (default: vg, time, pareto, envelope)")
    pl.add_argument(
        "--fmax",
        type=positive_float,
        metavar="HZ",
        help="modes up to HZ only (default: 3 x the highest crossing frequency)",
    )
    pl.add_argument("--modes", type=_mode_list, metavar="LIST", help="modes to draw, e.g. 1,2,4")
    pl.add_argument("--units", choices=("si", "knots"), default="si", help="speed units")
    pl.add_argument("--eas", action="store_true", help="equivalent airspeed on the speed axis")
    pl.add_argument(
        "--g-required", type=quantity("structural_g"), metavar="G", help="required damping g"
    )
    pl.add_argument(
        "--metric",
        metavar="NAME",
        help="trade-study heat map: the metric (default: suppression_margin; implies --kind "
        "heatmap)",
    )
    pl.add_argument(
        "--slice",
        metavar="P=V[,P=V]",
        help="trade-study heat map: hold parameters at values of the grid, e.g. "
        "bryson_hinge_moment=500 (default: one panel per value, or the best case's values)",
    )

    ex = sub.add_parser(
        "export",
        help="write a state-space model for MATLAB/Simulink (.mat) or NumPy (.npz)",
        description="Export A, B, C, D with signal names and units at one flight condition; "
        "MATLAB: matlab/load_aeroservo.m builds a named ss from the .mat file.",
    )
    ex.add_argument("wing", help="built-in wing, a wing .toml or a scenario .toml")
    ex.add_argument("--speed", type=quantity("airspeed"), required=True, help="airspeed [m/s]")
    ex.add_argument("--inputs", type=_names, help="input signals (default: hinge moments, gust)")
    ex.add_argument("--outputs", type=_names, help="output signals (default: tip sensors)")
    ex.add_argument("--design-modes", type=int, help="truncate to this many structural modes")
    ex.add_argument("--physical", action="store_true", help="physical (unbalanced) states")
    ex.add_argument("--out", required=True, metavar="FILE", help="model.mat or model.npz")
    add_flight_options(ex)
    add_model_options(ex)


def _cmd_plot(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..atomic import atomic_write_set, figure_writer
    from ..errors import InputError
    from ..files.results import load_result
    from ..files.user_files import check_readable
    from .options import check_figure

    src = Path(args.result)
    if not src.is_dir():
        check_readable(src, "saved result (.npz, .json) or trade folder")
    out = (
        Path(args.out) if args.out else src.with_suffix(".png") if src.suffix else src / "plot.png"
    )
    gif = out.suffix.lower() == ".gif"
    if gif and args.kind not in ("modes", "flutter-mode"):
        raise InputError(f"--out = {str(out)!r}: a .gif animates --kind modes or flutter-mode")
    if not gif:
        check_figure(str(out), "--out")
    else:
        from ..atomic import check_output_path

        check_output_path(out, "--out")
    res = load_result(src)
    what, kinds = _what(res), tuple(res.FIGURES)
    heat = args.metric is not None or args.slice is not None
    kind = args.kind or ("heatmap" if heat and "heatmap" in kinds else kinds[0])
    if heat and kind != "heatmap":
        raise InputError(
            f"--metric and --slice apply to the heat map of a trade study, not to --kind {kind}"
        )
    if kind not in kinds:
        raise InputError(f"--kind = {kind!r}: {args.result} is {what}; use {', '.join(kinds)}")
    if gif:
        return _animate_saved(res, args, out)
    if what != "a flutter sweep" and (args.fmax or args.modes or args.eas):
        raise InputError(f"--fmax, --modes and --eas apply to flutter sweeps, not to {what}")
    several = what in ("gust loads", "limit cycles")  # named <stem>_<kind>.png
    which = res.figure_kinds if several and args.kind is None and args.out is None else (kind,)
    if kind not in res.figure_kinds:
        raise InputError(_missing(res, src, args, kind))
    items = []  # every figure drawn first, then written as a set: all of them or none
    for k in which:
        fig = res.plot(k, **_options(res, k, args))
        name = k.replace("-", "_")
        path = out if args.out or not several else src.with_name(f"{src.stem}_{name}.png")
        items.append((path, figure_writer(fig, path, dpi=130)))
    for path in atomic_write_set(items):
        print(f"plot written to {path}")
    return 0


def _options(res, kind: str, args: argparse.Namespace) -> dict:
    """The options of ``res.plot(kind, ...)`` the command's arguments give."""
    if kind in ("vg", "vf"):
        fmax = args.fmax or "auto"
        return dict(units=args.units, eas=args.eas, fmax=fmax, modes=args.modes,
                    g_required=args.g_required)  # fmt: skip
    if kind == "root-locus":
        return dict(fmax=args.fmax, modes=args.modes, units=args.units)
    if kind == "modes":
        return dict(fmax=args.fmax, modes=args.modes)
    if kind == "envelope" and _what(res) == "a flutter envelope":
        return dict(units=args.units)
    if kind == "heatmap":
        return _heatmap(res, args)
    return {}


def _missing(res, src, args: argparse.Namespace, kind: str) -> str:
    """Why ``res`` cannot draw ``kind`` (one line)."""
    if kind == "histories":
        return (
            f"--kind = {kind!r}: {args.result} has no time histories (its "
            f"{src.stem}_histories.npz is not next to it)"
        )
    if _what(res) == "gust loads":
        return f"{'--kind = ' + repr(kind) + ': ' if args.kind else ''}{src}: {res.missing(kind)}"
    if not res.modes:
        return f"{args.result}: the file has no mode shapes"
    return f"{args.result}: no flutter in the sweep, so no flutter mode"


def _animate_saved(saved, args: argparse.Namespace, out) -> int:
    """A tip-section animation of a saved sweep's flutter mode or of one natural mode."""
    import tomllib

    from ..atomic import atomic_write
    from ..errors import InputError
    from ..files.wing_file import wing_from_dict
    from ..plots.modes import gif_writer

    r = saved.result
    if not saved.modes:
        raise InputError(f"{args.result}: the file has no mode shapes")
    wing = wing_from_dict(tomllib.loads(saved.wing_text)["wing"], f"{args.result}: wing")
    if args.kind == "flutter-mode":
        if saved.flutter_mode is None or r.flutter is None:
            raise InputError(f"{args.result}: no flutter in the sweep, so no flutter mode")
        fields = {k: (v if k == "x" else v[:, None]) for k, v in saved.flutter_mode.items()}
        j, label, freq = 0, f"flutter mode at {r.flutter.speed:.4g} m/s", r.flutter.frequency
    else:
        fields = saved.modes
        j = (args.modes or [1])[0] - 1
        if j >= fields["frequency"].size:
            raise InputError(f"--modes: the file has {fields['frequency'].size} mode shapes")
        label, freq = fields["label"][j], float(fields["frequency"][j])
    atomic_write(out, gif_writer(fields, j, wing, label=label, frequency=freq))
    print(f"animation written to {out}")
    return 0


def _heatmap(res, args: argparse.Namespace) -> dict:
    """The options of a trade study's heat map of ``--metric`` on ``--slice`` (one-line errors
    that list the valid names and values)."""
    from ..errors import InputError
    from ..studies.trade.study import METRICS

    if args.metric is not None and args.metric not in METRICS:
        raise InputError(
            f"--metric = {args.metric!r}: not a trade-study metric; valid are {', '.join(METRICS)}"
        )
    fixed = _slice(args.slice, res.parameters) if args.slice is not None else {}
    free = [n for n in res.parameters if n not in fixed]
    if len(free) < 2:
        raise InputError(
            f"--slice = {args.slice!r}: a heat map needs two parameters left free; this study "
            f"sweeps {', '.join(res.parameters)}"
        )
    return {"metric": args.metric, **fixed}


def _slice(text: str, parameters: dict) -> dict:
    """``--slice P=V[,P=V]``: each P a swept parameter, each V one of its values."""
    import math

    from ..errors import InputError

    names = ", ".join(parameters)
    out: dict = {}
    for item in text.split(","):
        name, sep, value = (t.strip() for t in item.partition("="))
        if not sep or not name or not value:
            example = next(iter(parameters))
            raise InputError(
                f"--slice = {text!r}: expected PARAM=VALUE[,PARAM=VALUE], e.g. "
                f"{example}={parameters[example][0]:g}; parameters are {names}"
            )
        if name not in parameters:
            raise InputError(f"--slice: {name!r} is not a swept parameter; swept are {names}")
        if name in out:
            raise InputError(f"--slice = {text!r}: {name} given twice")
        grid = parameters[name]
        values = ", ".join(f"{g:g}" for g in grid)
        try:
            v = float(value)
        except ValueError:
            v = math.nan
        match = [g for g in grid if math.isclose(v, g, rel_tol=1e-9, abs_tol=1e-12)]
        if not match:
            raise InputError(
                f"--slice {name} = {value!r}: not a value of the study; its values are {values}"
            )
        out[name] = float(match[0])
    return out


_WHAT = {
    "GustLoadsResult": "gust loads",
    "LCOResult": "limit cycles",
    "SavedFlutter": "a flutter sweep",
    "TradeResult": "a trade study",
    "Envelope": "a flutter envelope",
    "SimulationResult": "a simulation",
    "ClosedLoopBoundary": "a closed-loop boundary",
    "LoopMargins": "loop margins",
    "MarginSweep": "a margin sweep",
    "RecoverableSet": "a recoverable set",
}


def _what(res) -> str:
    """What a loaded result is, for messages."""
    return _WHAT.get(type(res).__name__, f"a {type(res).__name__}")


def _cmd_export(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..atomic import check_output_path
    from ..errors import InputError, check_int
    from ..files.statespace_export import export_mat, export_npz
    from ..linear.models import statespace
    from .options import setup

    suffix = Path(args.out).suffix.lower()
    if suffix not in (".mat", ".npz"):
        raise InputError(f"--out = {args.out!r}: expected a .mat or .npz file name")
    check_output_path(args.out, "--out")
    s = setup(args)
    n_modes = None
    if args.design_modes is not None:
        n_modes = check_int("--design-modes", args.design_modes, lo=1, hi=s.model.n_dofs)
    from ..files.wing_model import correction_mach

    # a fixed Mach number, or (when asked for) the export's own Mach number V / a
    mach = s.mach
    if mach is None:
        field = "--speed / speed of sound"
        mach = correction_mach(args.speed, s.atmosphere, s.compressibility, field, s.model)
    sys = statespace(
        s.model,
        args.speed,
        s.density,
        args.inputs,
        args.outputs,
        n_modes=n_modes,
        balanced=not args.physical,
        mach=mach,
    )
    (export_mat if suffix == ".mat" else export_npz)(sys, args.out)
    print(
        f"{s.wing.name} at {args.speed:g} m/s, {s.density:.5g} kg/m^3: {sys.nstates} states, "
        f"inputs {list(sys.input_labels)}, outputs {list(sys.output_labels)}"
        + (f", Prandtl-Glauert at Mach {mach:.4g}" if mach and s.model.dlm is None else "")
        + (f", doublet lattice at Mach {mach:.4g}" if s.model.dlm is not None else "")
        + f" -> {args.out}"
    )
    return 0


HANDLERS = {"plot": _cmd_plot, "export": _cmd_export}
