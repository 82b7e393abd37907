"""Command line: ``sensitivity`` (analytic derivatives of the flutter and divergence speeds)."""

from __future__ import annotations

import argparse
import sys

from .options import add_flight_options, add_model_options, named, quantity, setup

__all__ = ["add_parsers", "HANDLERS"]


def add_parsers(sub) -> None:
    """The parser of ``sensitivity``."""
    p = sub.add_parser(
        "sensitivity",
        help="derivatives of the flutter and divergence speeds to every wing parameter",
        description="Analytic sensitivities (left and right eigenvectors at the crossing, matrix "
        "derivatives from the element integrals): dV_f/dp, df_f/dp and dV_d/dp for every "
        "segment, control-surface, actuator and concentrated-mass parameter named as in the "
        "wing file (masses[i].mass, station, offset, inertia, vertical_offset), the "
        "structural damping's own parameters, the density, and the altitude (with --altitude; "
        "at the matched Mach number with --compressibility), in SI units per unit of the "
        "parameter.",
    )
    p.add_argument("wing", help="built-in wing, a wing .toml or a scenario .toml")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", metavar="FILE", help="bar chart of (p/V) dV/dp (png, pdf, svg)")
    p.add_argument("--v-max", type=quantity("flight_speed"), help="top of the speed search [m/s]")
    p.add_argument("--top", type=int, default=20, help="parameters drawn (default 20)")
    add_flight_options(p)
    add_model_options(p)


def _cmd_sensitivity(args: argparse.Namespace) -> int:
    from ..errors import check_int
    from .options import check_figure

    check_figure(args.plot)
    check_int("--top", args.top, lo=1, hi=1000)
    s = setup(args)
    from ..stability.sensitivity import flutter_sensitivities

    v_max = args.v_max if args.v_max is not None else s.opts.v_max
    kw = {"v_max": v_max, "n_modes": s.opts.n_modes}
    if s.mach is not None:  # a fixed Mach number: at the density (of the altitude)
        kw.update(density=s.density, mach=s.mach)
    elif s.atmosphere is not None:
        kw.update(atmosphere=s.atmosphere, compressibility=s.compressibility)
    else:
        kw["density"] = s.density
    with named("n_modes", None, args, "n_modes"):
        sens = flutter_sensitivities(s.model, **kw)
    if args.plot:
        from ..atomic import save_figure
        from ..plots.sensitivity import plot_sensitivities

        save_figure(plot_sensitivities(sens, top=args.top, title=s.wing.name), args.plot, dpi=130)
    if args.json:
        from ..files.summaries import json_text

        print(json_text({"wing": s.wing.name, "aero": s.model.aero_model, **sens.to_dict()}))
        return 0
    print(_text(s.wing.name, sens, s.model))
    if sens.non_differentiable:
        print(f"aeroservo: warning: {sens.non_differentiable}", file=sys.stderr)
    return 0


def _text(name: str, sens, model=None) -> str:
    def f(v):
        return "-" if v is None else f"{v:.6g}"

    where = f"{sens.density:.5g} kg/m^3"
    if sens.altitude is not None:
        where = f"{sens.altitude:.6g} m ({where})"
    if sens.mach:
        where += f", Mach {sens.mach:.4g}" + (" (matched)" if sens.matched else "")
    if model is not None and model.dlm is not None:
        where += f", doublet lattice; derivatives by {sens.method}"
    lines = [
        f"{name} at {where}: flutter {f(sens.flutter_speed)} m/s, "
        f"{f(sens.flutter_frequency)} Hz; divergence {f(sens.divergence_speed)} m/s",
        f"{'parameter':44s} {'value':>11s} {'dV_f/dp':>12s} {'(p/V)dV_f/dp':>13s} "
        f"{'df_f/dp':>12s} {'dV_d/dp':>12s}",
    ]
    norm = sens.normalized() if sens.d_flutter_speed else {}
    for k, v in sens.values.items():
        lines.append(
            f"{k:44s} {v:11.5g} {f(sens.d_flutter_speed.get(k)):>12s} {f(norm.get(k)):>13s} "
            f"{f(sens.d_flutter_frequency.get(k)):>12s} {f(sens.d_divergence_speed.get(k)):>12s}"
        )
    lines += [f"no derivative for {k}: {why}" for k, why in sens.undefined.items()]
    return "\n".join(lines)


HANDLERS = {"sensitivity": _cmd_sensitivity}
