"""The ``aeroservo`` command.

Exit codes: 0 success, 2 usage or input error (one-line message), 1 numerical failure.
Heavy packages (matplotlib, python-control, casadi) are imported only by the commands that
need them.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence

from ._threads import blas_limited
from .errors import InputError

__all__ = ["main"]


def _positive_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not v > 0 or v != v or v == float("inf"):
        raise argparse.ArgumentTypeError(f"{text!r}: must be a finite number > 0")
    return v


def _positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: must be >= 1")
    return v


def _parser() -> argparse.ArgumentParser:
    from ._version import __version__

    p = argparse.ArgumentParser(
        prog="aeroservo",
        description="Aero-servo-elastic analysis of wings with control surfaces (SI units).",
    )
    p.add_argument("--version", action="version", version=f"aeroservo {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    f = sub.add_parser(
        "flutter",
        help="flutter and divergence boundaries of a wing",
        description="Flutter and divergence boundaries of a built-in wing or a wing file.",
    )
    f.add_argument(
        "wing",
        help="built-in wing (goland, goland_aileron), a wing .toml or a scenario .toml",
    )
    f.add_argument("--json", action="store_true", help="print one JSON object")
    f.add_argument(
        "--density", type=_positive_float, help="air density [kg/m^3] (default: file, else 1.225)"
    )
    f.add_argument(
        "--elements", type=_positive_int, help="number of beam elements (default: file, else 10)"
    )
    f.add_argument("--wagner", help="Wagner set: rt_jones, wp_jones, one_term, fit2, fit3, fit4")
    f.add_argument("--v-max", type=_positive_float, help="upper end of the speed search [m/s]")
    f.add_argument(
        "--modes",
        type=_positive_int,
        help="fewest modes in the modal model (default 6; the mode rule and the certificate "
        "add what the wing needs, docs/stability.md)",
    )

    f.add_argument(
        "--pk", action="store_true", help="also solve by p-k with the exact Theodorsen function"
    )
    f.add_argument("--plot", metavar="FILE", help="write V-g and V-f diagrams (png, pdf, svg)")

    m = sub.add_parser("modes", help="natural frequencies of a wing (in vacuo)")
    m.add_argument("wing")
    m.add_argument("--elements", type=_positive_int)
    m.add_argument("-n", type=_positive_int, default=6, help="number of modes (default 6)")
    m.add_argument("--json", action="store_true")

    for name, helptext in (
        ("run", "run a scenario of any kind (flutter, simulate, trade)"),
        ("simulate", "run a closed-loop time simulation scenario"),
        ("trade", "run a trade-study scenario on Dask"),
    ):
        r = sub.add_parser(name, help=helptext, description=helptext.capitalize() + ".")
        r.add_argument("scenario", help="scenario file (.toml), see docs/scenarios.md")
        r.add_argument("--out", metavar="DIR", default="out", help="output folder (default out)")
        r.add_argument("--json", action="store_true", help="print the summary as JSON")
        r.add_argument(
            "--quick",
            action="store_true",
            help="fast settings for smoke tests (short simulation, coarse grids, 2 values per "
            "trade parameter)",
        )
        r.add_argument(
            "--progress",
            action=argparse.BooleanOptionalAction,
            default=None,
            help="progress bars on stderr (default: when stderr is a terminal)",
        )
        if name in ("run", "trade"):
            r.add_argument(
                "--scheduler", metavar="ADDRESS", help="existing Dask scheduler, tcp://host:port"
            )
            r.add_argument(
                "--workers", type=_positive_int, help="LocalCluster workers (default: scenario)"
            )

    pl = sub.add_parser("plot", help="re-plot a saved simulation result (.npz)")
    pl.add_argument("result", help="result file written by 'aeroservo simulate'")
    pl.add_argument("--out", metavar="FILE", help="figure file (default: RESULT with .png)")

    sub.add_parser("examples", help="list the built-in wings and the shipped scenarios")
    return p


def _cmd_flutter(args: argparse.Namespace) -> int:
    from .files.scenario_file import is_scenario_file
    from .files.wing_file import resolve_wing
    from .stability.boundary import flutter_boundary
    from .system.aeroelastic import AeroelasticModel

    if args.wing.endswith(".toml") and is_scenario_file(args.wing):
        from .files.scenario_file import load_scenario
        from .files.wing_file import AnalysisOptions

        sc = load_scenario(args.wing)  # a scenario: its wing, density and model options
        wing = sc.wing
        opts = AnalysisOptions(sc.density, sc.elements, sc.wagner, sc.v_max)
    else:
        wing, opts = resolve_wing(args.wing)
    density = args.density if args.density is not None else opts.density
    elements = args.elements if args.elements is not None else opts.elements
    wagner = args.wagner if args.wagner is not None else opts.wagner
    v_max = args.v_max if args.v_max is not None else opts.v_max
    n_modes = args.modes if args.modes is not None else opts.n_modes
    model = AeroelasticModel(wing, n_elements=elements, wagner=wagner)
    result = flutter_boundary(model, density, v_max=v_max, n_modes=n_modes)
    out = {
        "wing": wing.name,
        "flutter_speed": result.flutter_speed,
        "flutter_frequency": result.flutter_frequency,
        "divergence_speed": result.divergence_speed,
        "n_states": result.n_states,
        "density": density,
        "n_elements": model.n_elements,
        "wagner": model.wagner.name,
        "units": {"speed": "m/s", "frequency": "Hz", "density": "kg/m^3"},
    }
    out.update({k: v for k, v in result.to_dict().items() if k not in out})
    if args.pk:
        from .stability.pk import pk_flutter

        pk = pk_flutter(model, density, v_max=result.v_max, n_modes=n_modes)
        out["pk_exact_theodorsen"] = {
            "flutter_speed": pk.flutter_speed,
            "flutter_frequency": pk.flutter_frequency,
            "divergence_speed": pk.divergence_speed,
        }
    if args.plot:
        from .atomic import save_figure
        from .plots import plot_vg

        fig = plot_vg(
            result, title=f"{wing.name}: {model.n_elements} elements, {model.wagner.name}"
        )
        save_figure(fig, args.plot, dpi=150)
        out["plot"] = args.plot
    for w in result.warnings:
        print(f"aeroservo: warning: {w}", file=sys.stderr)
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        print(f"{wing.name}: {model.n_elements} elements, Wagner '{model.wagner.name}'")
        print(result.summary(warnings=False))
        if args.pk:
            pkr = out["pk_exact_theodorsen"]
            if pkr["flutter_speed"] is None:
                print(f"p-k (exact Theodorsen): no flutter below {result.v_max:.4g} m/s")
            else:
                print(
                    f"p-k (exact Theodorsen): flutter {pkr['flutter_speed']:.6g} m/s at "
                    f"{pkr['flutter_frequency']:.5g} Hz"
                )
        if args.plot:
            print(f"plot written to {args.plot}")
    return 0


def _cmd_modes(args: argparse.Namespace) -> int:
    from .files.wing_file import resolve_wing
    from .system.aeroelastic import AeroelasticModel

    wing, opts = resolve_wing(args.wing)
    model = AeroelasticModel(wing, n_elements=args.elements or opts.elements)
    modes = model.natural_modes(min(args.n, model.n_dofs))
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
        for f, lab in zip(modes.frequencies, modes.labels, strict=True):
            print(f"  {f:10.4f} Hz  {lab}")
    return 0


def _cmd_examples(args: argparse.Namespace) -> int:
    from .files.scenario_file import shipped_scenarios
    from .structure.examples import BUILTIN_WINGS

    print("built-in wings:")
    for name, fn in BUILTIN_WINGS.items():
        doc = (fn.__doc__ or "").strip().splitlines()[0]
        print(f"  {name:16s} {doc}")
    found = shipped_scenarios()
    if found:
        print(f"scenarios ({found[0][0].parent}):")
        for path, kind, title in found:
            print(f"  {path.name:32s} {kind:9s} {title}")
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .files.outputs import write_run
    from .files.results import json_text
    from .files.scenario_file import load_scenario
    from .studies.runs import run_scenario
    from .studies.scenario import quick

    scenario = load_scenario(args.scenario)
    if args.command != "run" and scenario.kind != args.command:
        raise InputError(
            f"{args.scenario}: scenario.kind = {scenario.kind!r}: use 'aeroservo "
            f"{'run' if scenario.kind == 'flutter' else scenario.kind}' for it"
        )
    if args.quick:
        scenario = quick(scenario)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    progress = sys.stderr.isatty() if args.progress is None else args.progress
    run = run_scenario(
        scenario,
        out,
        progress=progress,
        scheduler=getattr(args, "scheduler", None),
        workers=getattr(args, "workers", None),
    )
    write_run(run, out)
    summary = run.summary
    if args.json:
        print(json_text(summary))
    else:
        print(_readable(summary))
    return 0


def _readable(s: dict) -> str:
    """Short human-readable summary of a run."""

    def f(v, unit="", fmt=".5g"):
        return "none" if v is None else f"{v:{fmt}}{unit}"

    lines = [f"{s.get('scenario', '')} [{s.get('kind')}]"]
    if s["kind"] == "flutter":
        top = s.get("searched_range", [0.0, s.get("v_max")])[1]
        if s["flutter_speed"] is None:
            lines.append(f"  no flutter below {top:.5g} m/s")
        else:
            lines.append(
                f"  flutter {f(s['flutter_speed'], ' m/s')} at {f(s['flutter_frequency'], ' Hz')}"
                f" ({s.get('flutter_mode')})"
            )
        lines.append(f"  divergence {f(s['divergence_speed'], ' m/s')}")
        lines += [f"  warning: {w}" for w in s.get("warnings", [])]
        if "pk_exact_theodorsen" in s:
            pk = s["pk_exact_theodorsen"]
            lines.append(f"  p-k, exact C(k): flutter {f(pk['flutter_speed'], ' m/s')}")
    elif s["kind"] == "simulate":
        lines.append(
            f"  {s['controller']} at {s['speed']:.5g} m/s "
            f"(open-loop flutter {f(s['open_loop_flutter_speed'], ' m/s')})"
        )
        for name, v in s["signals"].items():
            unit = s["units"].get(name, "")
            lines.append(
                f"  {name:24s} peak {v['peak']:10.4g} {unit:6s} rms {v['rms']:10.4g}  "
                f"last/first {v['growth']:.3g}"
            )
        if "response" in s:
            lines.append(f"  response {s['response']}")
        if "mpc" in s:
            m = s["mpc"]
            lines.append(
                f"  MPC solve time median {m['solve_time_median'] * 1e3:.3f} ms, "
                f"p99 {m['solve_time_p99'] * 1e3:.3f} ms, fallbacks {m['fallbacks']}"
            )
        if "closed_loop" in s:
            c = s["closed_loop"]
            lines.append(
                f"  closed loop loses stability at {f(c['closed_loop_flutter_speed'], ' m/s')}"
                f" ({c['closed_loop_instability'] or 'not in range'}); "
                f"stable intervals {[(round(a, 2), round(b, 2)) for a, b in c['stable_intervals']]}"
            )
    else:
        lines.append(
            f"  {s['n_cases']} cases ({s['n_skipped']} already done, {s['n_failed']} failed) in "
            f"{s['elapsed']:.1f} s, {s['cases_per_second']:.2f} cases/s"
        )
        b = s.get("best_case")
        if b:
            from .studies.trade.study import PARAMETERS

            params = ", ".join(f"{k} = {b[k]:g}" for k in PARAMETERS if k in b)
            lines.append(
                f"  best suppression margin {b['suppression_margin']:+.1%} ({params}): "
                f"open loop {f(b['open_loop_flutter_speed'], ' m/s')}, closed loop "
                f"{f(b.get('closed_loop_flutter_speed'), ' m/s')}, peak hinge moment "
                f"{f(b.get('hinge_moment_peak'), ' N m')} in the gust"
            )
    for k, v in s.get("files", {}).items():
        lines.append(f"  wrote {k}: {v}")
    return "\n".join(lines)


def _cmd_plot(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .atomic import save_figure
    from .files.results import load_result

    res = load_result(args.result)
    out = Path(args.out) if args.out else Path(args.result).with_suffix(".png")
    save_figure(res.plot(), out, dpi=120)
    print(f"plot written to {out}")
    return 0


@blas_limited
def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    parser = _parser()
    args = parser.parse_args(argv)
    handlers = {
        "flutter": _cmd_flutter,
        "modes": _cmd_modes,
        "examples": _cmd_examples,
        "run": _cmd_run,
        "simulate": _cmd_run,
        "trade": _cmd_run,
        "plot": _cmd_plot,
    }
    try:
        return handlers[args.command](args)
    except InputError as exc:
        print(f"aeroservo: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # unwritable output folder, unreadable file
        print(f"aeroservo: error: {exc}", file=sys.stderr)
        return 2
    except (RuntimeError, ArithmeticError, __import__("numpy").linalg.LinAlgError) as exc:
        print(f"aeroservo: numerical failure: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
