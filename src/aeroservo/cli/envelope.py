"""The ``envelope`` command: flutter clearance over altitude (:mod:`aeroservo.studies.envelope`).

V_D is the design dive speed (``--vd``) and M_D the dive Mach number; the divergence speed is
written V_div (``Vdiv EAS`` in the table) so the two are never confused.
"""

from __future__ import annotations

import argparse
import sys

from .aero_options import COMPRESSIBILITY_CHOICES, add_mach_option
from .options import add_model_options, check_figure, check_suffix, positive_float, setup

__all__ = ["add_parser", "cmd_envelope"]


def add_parser(sub) -> None:
    """The ``envelope`` command's parser."""
    e = sub.add_parser(
        "envelope",
        help="flutter clearance over altitude against a V_D / M_D envelope",
        description="Matched flutter and divergence speeds (TAS, EAS, Mach) at each altitude of "
        "the standard atmosphere, checked against the design envelope with the margin.",
    )
    e.add_argument("wing", help="built-in wing, a wing .toml or a scenario .toml")
    alt = e.add_mutually_exclusive_group(required=True)
    alt.add_argument("--altitudes", metavar="START:STOP:STEP", help="altitudes [m], or a,b,c")
    alt.add_argument("--altitudes-ft", metavar="START:STOP:STEP", help="altitudes [ft]")
    e.add_argument("--vd", type=positive_float, help="design dive speed V_D, EAS (in --units)")
    e.add_argument("--md", type=positive_float, help="design dive Mach number M_D")
    e.add_argument(
        "--margin", type=positive_float, default=1.15, help="margin on V_D/M_D (default 1.15)"
    )
    e.add_argument(
        "--compressibility",
        choices=COMPRESSIBILITY_CHOICES,
        help="Mach number matched to the speed at each altitude (strip theory's Prandtl-Glauert "
        "correction, the doublet lattice's Mach number)",
    )
    add_mach_option(e)
    e.add_argument("--units", choices=("si", "knots"), default="si")
    add_model_options(e)
    e.add_argument("--json", action="store_true", help="print one JSON object")
    e.add_argument("--csv", metavar="FILE", help="write the table (one row per altitude)")
    e.add_argument("--plot", metavar="FILE", help="write the envelope plot (png, pdf, svg)")
    e.add_argument("--save", metavar="FILE.json", help="save the envelope for 'aeroservo plot'")
    e.add_argument("--x", choices=("eas", "mach"), default="eas", help="plot axis")
    e.add_argument(
        "--progress",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="progress bar on stderr (default: when stderr is a terminal)",
    )


def cmd_envelope(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..aero.atmosphere import KNOT
    from ..atomic import atomic_write_set, figure_writer
    from ..files.summaries import json_text
    from ..studies.envelope import flutter_envelope, parse_altitudes

    check_figure(args.plot)
    check_suffix("--save", args.save, ".json")
    check_suffix("--csv", args.csv, ".csv")
    alts = parse_altitudes(args.altitudes_ft, "ft") if args.altitudes_ft else None
    alts = alts or parse_altitudes(args.altitudes)
    s = setup(args, altitudes=True)
    vd = None if args.vd is None else args.vd * (KNOT if args.units == "knots" else 1.0)
    progress = sys.stderr.isatty() if args.progress is None else args.progress
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(alts), desc="envelope", unit="altitude", leave=False)
    try:
        env = flutter_envelope(
            s.model,
            alts,
            compressibility=s.compressibility,
            vd=vd,
            md=args.md,
            margin=args.margin,
            progress=(lambda i: bar.update(1)) if bar is not None else None,
            **({} if s.mach is None else {"mach": s.mach}),
        )
    finally:
        if bar is not None:
            bar.close()
    items = []
    if args.csv:
        items.append((Path(args.csv), lambda p: p.write_text(env.csv_text(args.units))))
    if args.plot:
        fig = env.plot(units=args.units, x=args.x)
        items.append((Path(args.plot), figure_writer(fig, args.plot, dpi=150)))
    if args.save:
        text = json_text({"format": "aeroservo-envelope-1", **env.to_dict()})
        items.append((Path(args.save), lambda p: p.write_text(text, encoding="utf-8")))
    atomic_write_set(items)
    for p in env.points:
        for w in p.warnings:
            print(f"aeroservo: warning: {p.altitude:g} m: {w}", file=sys.stderr)
    if args.json:
        print(json_text(env.to_dict()))
        return 0
    print(_envelope_text(env, args.units, _aero_label(s)))
    for kind, path in (("table", args.csv), ("plot", args.plot), ("envelope", args.save)):
        if path:
            print(f"{kind} written to {path}")
    return 0


def _aero_label(s) -> str | None:
    """The aerodynamics of the envelope when it is not strip theory's default (None)."""
    if s.model.dlm is not None:
        mach = "Mach matched" if s.compressibility else f"Mach {s.mach or 0.0:g}"
        return f"doublet lattice, {mach}"
    return None if s.mach is None else f"Prandtl-Glauert at Mach {s.mach:g}"


def _envelope_text(env, units: str, aero: str | None = None) -> str:
    from ..aero.atmosphere import KNOT

    k = 1 / KNOT if units == "knots" else 1.0
    u = "kt" if units == "knots" else "m/s"

    def f(v, fmt="8.4g"):
        return f"{'-':>8s}" if v is None else f"{v:{fmt}}"

    comp = aero or env.compressibility or "incompressible"
    lines = [f"{env.wing}: flutter envelope ({comp}; structural damping {env.damping})"]
    head = f"  {'alt [m]':>8s} {'VF TAS':>8s} {'VF EAS':>8s} {'MF':>8s} {'Vdiv EAS':>8s}"
    if env.envelope:
        head += f" {'req EAS':>8s}  margin"
    lines += [head + f"   (speeds in {u})"]
    for p in env.points:
        row = f"  {p.altitude:8.0f} {f(p.flutter_speed and p.flutter_speed * k)}"
        row += f" {f(p.flutter_eas and p.flutter_eas * k)} {f(p.flutter_mach, '8.3f')}"
        row += f" {f(p.divergence_eas and p.divergence_eas * k)}"
        if env.envelope:
            row += f" {f(p.required_eas * k)}  {'ok' if p.margin_ok else 'FAIL'}"
        lines.append(row)
    if env.envelope:
        lines.append(f"  clearance with margin {env.margin:g}: {'ok' if env.margin_ok else 'FAIL'}")
    return "\n".join(lines)
