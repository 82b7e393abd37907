"""Command line: ``optimize`` (aeroservo.studies.optimize on an optimization file)."""

from __future__ import annotations

import argparse

__all__ = ["add_parsers", "HANDLERS"]


def add_parsers(sub) -> None:
    """The parser of ``optimize``."""
    p = sub.add_parser(
        "optimize",
        help="tailor wing parameters by SLSQP with analytic flutter-speed gradients",
        description="Design variables, bounds, an objective and speed constraints from an "
        "optimization file (docs/stability.md, scenarios/optimize_*.toml); every iterate is "
        "logged, the optimum is verified by a fresh analysis.",
    )
    p.add_argument("file", help="optimization or co-design .toml")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument(
        "--gradients",
        choices=("analytic", "central"),
        default="analytic",
        help="analytic sensitivities (default) or central differences, for comparison",
    )
    p.add_argument(
        "--out",
        metavar="DIR",
        help="write the optimum into DIR (created): FILE-stem_wing.toml (a wing file for "
        "'aeroservo flutter'), _history.csv (one row per iterate) and _convergence.png",
    )


def _out_dir(text: str | None):
    """The ``--out`` folder, checked before the optimization runs (None: not given)."""
    from pathlib import Path

    from ..errors import InputError

    if text is None:
        return None
    if not text.strip():
        raise InputError("--out = '': give an output folder")
    out = Path(text)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out = {text!r}: is a file, expected a folder")
    return out


def _write(op, r, out, source: str) -> dict:
    """The optimum's files, all or none (the folder created only now)."""
    from ..atomic import atomic_write_set
    from ..files.optimize_file import optimum_writers

    items = optimum_writers(op, r, out, source)
    created = not out.exists()
    out.mkdir(parents=True, exist_ok=True)
    try:
        atomic_write_set(list(items.values()))
    except BaseException:
        if created and not any(out.iterdir()):
            out.rmdir()
        raise
    return {k: str(path) for k, (path, _w) in items.items()}


def _cmd_optimize(args: argparse.Namespace) -> int:
    from ..errors import InputError
    from ..files.optimize_file import load_optimization
    from ..files.toml_tables import read_toml

    out = _out_dir(args.out)
    if "codesign" in read_toml(args.file):
        if out is not None:
            raise InputError(
                f"--out = {args.out!r}: writes the wing of an optimization file; the optimum "
                f"of the co-design file {args.file} is a trade case (printed)"
            )
        return _codesign(args)
    op = load_optimization(args.file)
    from ..studies.optimize import optimize_wing

    r = optimize_wing(
        op.wing,
        op.density,
        op.variables,
        op.objective,
        op.constraints,
        n_elements=op.elements,
        damping=op.damping,
        v_max=op.v_max,
        gradients=args.gradients,
        aero="strip" if op.aero is None else op.aero,
        mach=op.mach,
    )
    # the doublet lattice's sensitivities are finite differences (stability.sensitivity_fd)
    how = args.gradients if op.aero is None else f"{args.gradients} (finite differences, dlm)"
    files = _write(op, r, out, args.file) if out is not None else {}
    if args.json:
        from ..files.summaries import json_text

        extra = {"files": files} if files else {}
        aero = {"aero": "strip" if op.aero is None else "dlm", "mach": op.mach or 0.0}
        print(json_text({"name": op.name, "gradients": how, **aero, **r.to_dict(), **extra}))
        return 0 if r.success else 1
    print(
        f"{op.name}: {r.message} ({len(r.iterations)} designs analysed, "
        f"{r.n_boundaries} flutter boundaries, {how} gradients)"
    )
    for n, v in r.variables.items():
        print(f"  {n:44s} {r.start[n]:12.6g} -> {v:12.6g}")
    print(
        f"  objective {r.objective:.6g}; flutter {r.flutter_speed} m/s, divergence "
        f"{r.divergence_speed} m/s (fresh analysis); active: {', '.join(r.active) or 'none'}"
    )
    for kind, path in files.items():
        print(f"  wrote {kind}: {path}")
    return 0 if r.success else 1


def _codesign(args: argparse.Namespace) -> int:
    from ..files.optimize_file import load_codesign

    cd = load_codesign(args.file)
    from ..studies.runs import study_from_scenario
    from ..studies.trade.codesign import codesign

    r = codesign(
        study_from_scenario(cd.scenario),
        cd.start,
        cd.variables,
        hinge_moment_peak_max=cd.hinge_moment_peak_max,
    )
    if args.json:
        from ..files.summaries import json_text

        print(json_text({"name": cd.name, **r.to_dict()}))
        return 0 if r.success else 1
    c = r.case
    print(
        f"{cd.name}: {r.message} ({len(r.iterations)} designs, {r.n_cases} trade cases, "
        "central-difference gradients)"
    )
    for n, v in r.variables.items():
        print(f"  {n:44s} {r.start[n]:12.6g} -> {v:12.6g}")
    print(
        f"  closed-loop flutter {c['closed_loop_flutter_speed']} m/s, peak hinge moment "
        f"{c['hinge_moment_peak']} N m (fresh case); active: {', '.join(r.active) or 'none'}"
    )
    return 0 if r.success else 1


HANDLERS = {"optimize": _cmd_optimize}
