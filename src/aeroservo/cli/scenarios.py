"""The scenario commands, made from the registry of scenario kinds
(:data:`aeroservo.studies.kinds.KINDS`): ``run`` (any kind) and each kind's own command
(``simulate``, ``trade``, ``loads``, ``lco``), all with the same options; and ``examples``."""

from __future__ import annotations

import argparse

from ..errors import InputError, VerdictFailure
from .aero_options import add_aero_options, load_scenario_with
from .options import run_into_folder

__all__ = ["add_parsers", "HANDLERS"]


def _workers(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if not 0 <= v <= 256:
        raise argparse.ArgumentTypeError(f"{text!r}: allowed range is [0, 256]")
    return v


DESCRIPTIONS = {
    "loads": "Discrete tuned gusts and continuous turbulence of CS-25.341 at every flight point "
    "of a gust_loads scenario, with and without its controller. Loads are increments of the "
    "wing clamped at its root (1 g loads added with the airplane's mass). Writes RESULT.json, "
    ".npz, .csv, _histories.csv, _alleviation.csv and the figures into --out (all or none); "
    "'aeroservo plot DIR/RESULT.json' redraws them.",
    "lco": "March a wing or a typical section with nonlinear hinges from rest with each initial "
    "rotation at each speed of an lco scenario, and along the speeds up and down "
    "(continuation), open loop or with its controller held fixed; judge each march (limit "
    "cycle, decay, divergence) and compare with the describing function. Writes RESULT.json, "
    ".csv, _branches.csv, _histories.npz, _summary.txt and the figures _bifurcation.png and "
    "_histories.png into --out (all or none); 'aeroservo plot DIR/RESULT.json' redraws them.",
}
"""Longer descriptions of the scenario commands than their kind's one line."""


def _commands() -> dict:
    """``{command: (help, kinds)}``: ``run`` for every kind, and each kind's own command
    (:data:`aeroservo.studies.kinds.KINDS`)."""
    from ..studies.kinds import KINDS

    names = ", ".join(KINDS)
    out = {"run": (f"run a scenario of any kind ({names})", tuple(KINDS.values()))}
    for k in KINDS.values():
        if k.command != "run":
            out[k.command] = (f"{k.description} (a scenario of kind '{k.name}')", (k,))
    return out


def add_parsers(sub) -> None:
    """The scenario commands' parsers, one per command of the registry of kinds, with the same
    options (those of the studies on Dask where one of its kinds is)."""
    for name, (helptext, kinds) in _commands().items():
        r = sub.add_parser(
            name, help=helptext, description=DESCRIPTIONS.get(name, helptext.capitalize() + ".")
        )
        which = "" if len(kinds) > 1 else f", kind = '{kinds[0].name}'"
        r.add_argument("scenario", help=f"scenario file (.toml{which}), see docs/scenarios.md")
        r.add_argument("--out", metavar="DIR", default="out", help="output folder (default out)")
        r.add_argument("--json", action="store_true", help="print the summary as JSON")
        quick = "; ".join(f"{k.name}: {k.quick}" for k in kinds if k.quick)
        r.add_argument(
            "--quick", action="store_true", help=f"fast settings for smoke tests ({quick})"
        )
        r.add_argument("--no-plots", action="store_true", help="write the data files only")
        r.add_argument(
            "--progress",
            action=argparse.BooleanOptionalAction,
            default=None,
            help="progress bars on stderr (default: when stderr is a terminal)",
        )
        r.add_argument("--quiet", dest="progress", action="store_false", help="no progress bars")
        add_aero_options(r, mach=True)
        if any(k.on_dask for k in kinds):
            where = r.add_mutually_exclusive_group()
            where.add_argument(
                "--scheduler", metavar="ADDRESS", help="existing Dask scheduler, tcp://host:port"
            )
            where.add_argument(
                "--workers",
                type=_workers,
                metavar="N",
                help="local Dask workers, 0 in this process (default: the scenario's)",
            )

    sub.add_parser("examples", help="list the built-in wings and the shipped scenarios")


def _cmd_examples(args: argparse.Namespace) -> int:
    from ..files.scenario_file import shipped_scenarios
    from ..files.toml_tables import read_toml
    from ..structure.examples import BUILTIN_WINGS

    print("built-in wings:")
    for name, fn in BUILTIN_WINGS.items():
        doc = (fn.__doc__ or "").strip().splitlines()[0]
        print(f"  {name:16s} {doc}")
    found = shipped_scenarios()
    if found:
        print(f"scenarios ({found[0][0].parent}):")
        for path, kind, title in found:
            print(f"  {path.name:32s} {kind:10s} {title}")
        wings = []
        for path in sorted(found[0][0].parent.glob("*.toml")):
            try:
                data = read_toml(path)
            except InputError:
                continue
            top = {"wing", "analysis", "damping", "hinges", "dlm"}
            if set(data) <= top and isinstance(data.get("wing"), dict):
                wings.append((path.name, str(data["wing"].get("name", ""))))
        if wings:
            print("wing files (aeroservo flutter FILE, aes.load_model(FILE)):")
            for name, title in wings:
                print(f"  {name:32s} {title}")
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    """Run a scenario (of the command's kind, or of any kind for ``run``), write its files as
    one set and print its report (or its summary as JSON)."""
    from dataclasses import replace

    from ..files.summaries import json_text
    from ..studies.kinds import check_kind
    from ..studies.scenario import quick

    scenario = load_scenario_with(args.scenario, args)
    kinds = _commands()[args.command][1]
    if len(kinds) == 1:
        check_kind(scenario, kinds[0].name, args.scenario)
    if args.quick:
        scenario = quick(scenario)
    if args.no_plots:
        scenario = replace(scenario, plots=False)
    run, files = run_into_folder(scenario, args)
    summary = run.summary
    if args.json:
        print(json_text(summary))
    else:
        print(REPORTS[scenario.kind](run, files))
    # a run's warnings are in its report (the text's "warning:" lines, the JSON's "warnings"),
    # once: stderr keeps the one line of a failed verdict
    if summary.get("passed") is False and not scenario.expect_failure:
        raise VerdictFailure(summary["hint"])
    return 0


def _study_report(run, files: dict) -> str:
    """A study's report: its name and kind, its result's summary and the files written."""
    lines = [f"{run.scenario.name} [{run.scenario.kind}]", run.result.summary()]
    lines += [f"  wrote {kind}: {path}" for kind, path in files.items()]
    return "\n".join(lines)


def _summary_report(run, files: dict) -> str:
    return _readable(run.summary)


REPORTS = {
    "flutter": _summary_report,
    "simulate": _summary_report,
    "trade": _summary_report,
    "gust_loads": _study_report,
    "lco": _study_report,
}
"""The printed report of a run of each scenario kind (:data:`aeroservo.studies.kinds.KINDS`)."""


def _channel_text(c: dict) -> str:
    """Gain, phase and disk margins of one break point."""

    def db(x, sign="+"):
        return f"{sign}inf" if x is None else f"{x:+.3g} dB"

    if not c["stable"]:
        return "closed loop unstable"
    pm = "inf" if c["phase_margin_deg"] is None else f"{c['phase_margin_deg']:.3g} deg"
    at = "" if c["phase_frequency"] is None else f" at {c['phase_frequency']:.3g} Hz"
    tau = c.get("delay_margin_s")
    delay = (
        "inf" if tau is None else f"{tau * 1e3:.3g} ms ({c['delay_margin_samples']:.3g} samples)"
    )
    return (
        f"gain {db(c['gain_margin_db'])} / {db(c['gain_reduction_margin_db'], '-')}, "
        f"phase {pm}{at}, delay {delay}, disk {c['disk_margin']:.3g}"
    )


def _margin_lines(m: dict | None) -> list[str]:
    """Margins at each break point, saying where the loop is broken."""
    if not m:
        return []
    r = m["requirement"]
    req = (
        f"disk {r['disk_alpha']:g}"
        if r["disk_alpha"] is not None
        else f"{r['gain_db']:g} dB, {r['phase_deg']:g} deg"
    ) + (f", {r['delay_ms']:g} ms" if r.get("delay_ms") is not None else "")
    at = r.get("at", ["inputs"])
    verdict = f"{'meets' if m['meets'] else 'misses'} {req} at the {', '.join(at)}"
    out = [f"  margins at {m['speed']:.5g} m/s ({verdict}); broken at the {m['break_point']}:"]
    for name, c in m["channels"].items():
        out.append(f"    {name}: {_channel_text(c)}")
    multi = m.get("multiloop") or {}
    if len(m["channels"]) > 1 and multi.get("disk_margin") is not None:
        out.append(f"    all inputs at once: disk {multi['disk_margin']:.3g} ({multi['method']})")
    if m.get("peak_sensitivity") is not None:
        out.append(
            f"    peak |S| {m['peak_sensitivity']:.3g} at {m['peak_sensitivity_frequency']:.3g} "
            f"Hz, peak |T| {m['peak_complementary_sensitivity']:.3g} at "
            f"{m['peak_complementary_sensitivity_frequency']:.3g} Hz (plant input)"
        )
    judged = "judged" if "sensors" in at else "reported"
    for name, c in m.get("sensors", {}).items():
        out.append(f"    at sensor {name} (plant output, {judged}): {_channel_text(c)}")
    outs = m.get("multiloop_outputs") or {}
    if len(m.get("sensors", {})) > 1 and outs.get("disk_margin") is not None:
        judged = "judged" if "multiloop" in at else "reported"
        gm, pm, f = (outs.get(k) for k in ("disk_gain_margin_db", "disk_phase_margin_deg",
                                           "frequency"))  # fmt: skip
        out.append(
            f"    all sensors at once ({judged}): disk {outs['disk_margin']:.3g} "
            f"(+-{_unbounded(gm)} dB, +-{_unbounded(pm)} deg at {_unbounded(f)} Hz; "
            f"{outs['method']})"
        )
    return out


def _unbounded(x) -> str:
    """A margin figure, or "inf" where the JSON holds null for an unbounded one."""
    return "inf" if x is None else f"{x:.3g}"


def _engaged_lines(s: dict) -> list[str]:
    """The engaged range, its stability and its margins."""
    e = s.get("engaged")
    if not e:
        return []
    r = e["engaged_range"]
    head = (
        f"  engaged {r['low']:.5g}-{r['high']:.5g} m/s ({r['source']}), stability required to "
        f"{r['stable_to']:.5g} m/s ({r['flutter_margin']:g} x): "
    )
    if e["stable_over_range"]:
        head += "stable throughout"
    else:
        parts = [
            f"{u['from']:.5g}-{u['to']:.5g} m/s ({u['kind']})"
            for u in e.get("unstable_intervals", [])
        ]
        head += "UNSTABLE at " + (
            "; ".join(parts) or ", ".join(f"{v:.5g}" for v in e.get("unstable_speeds", []))
        )
    mr = e["margins_over_range"]
    if mr["meets"] is None:
        head += f"; margins {mr.get('note', 'not judged')}"
    else:
        n, bad = len(mr["speeds"]), len(mr["failures"])
        head += f"; margins meet the requirement at {n - bad} of {n} speeds" + (
            "" if mr["meets"] else " (FAIL)"
        )
    return [head]


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
        if s.get("aero") == "dlm":
            lines.append(f"  doublet lattice at Mach {s['mach']:.4g} ({s['mach_source']})")
        for key, how in (("pk_exact_theodorsen", "exact C(k)"), ("pk_doublet_lattice", "DLM")):
            if key in s:
                lines.append(f"  p-k, {how}: flutter {f(s[key]['flutter_speed'], ' m/s')}")
    elif s["kind"] == "simulate":
        lines.append(
            f"  {s['controller']} at {s['speed']:.5g} m/s "
            f"(open-loop flutter {f(s['open_loop_flutter_speed'], ' m/s')})"
        )
        width = max([24] + [len(n) for n in s["signals"]])
        for name, v in s["signals"].items():
            unit = s["units"].get(name, "")
            lines.append(
                f"  {name:{width}s} peak {v['peak']:10.4g} {unit:6s} rms {v['rms']:10.4g}  "
                f"growth {v['growth']:.3g}"
            )
        if "verdict" in s:
            expected = " (expected: simulation.expect_failure)" if s.get("expect_failure") else ""
            rho = s["spectral_radius"]
            radius = "" if rho is None else f"spectral radius of the sampled loop {rho:.6g}, "
            lines.append(
                f"  verdict {s['verdict']}, {'passed' if s['passed'] else 'FAILED'}{expected}: "
                f"{radius}response {s['response']}"
                + (f" ({', '.join(s['growing_signals'])} grow)" if s["growing_signals"] else "")
            )
        lines += _margin_lines(s.get("margins"))
        lines += _engaged_lines(s)
        lines += [f"  warning: {w}" for w in s.get("warnings", [])]
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
                f" ({c['closed_loop_instability'] or 'not in range'}), lower end "
                f"{f(c['lower_speed'], ' m/s')}"
                + (f" ({c['lower_speed_kind']})" if c.get("lower_speed_kind") else "")
                + "; stable intervals "
                f"{[(round(a, 2), round(b, 2)) for a, b in c['stable_intervals']]}"
            )
    else:
        lines.append(
            f"  {s['n_cases']} cases ({s['n_skipped']} already done, {s['n_failed']} failed) in "
            f"{s['elapsed']:.1f} s, {s['cases_per_second']:.2f} cases/s"
        )
        b = s.get("best_case")
        if b:
            from ..studies.trade.study import PARAMETERS

            params = ", ".join(f"{k} = {b[k]:g}" for k in b if k in PARAMETERS)
            if b.get("design_speed") is None:  # an open-loop study
                lines.append(
                    f"  highest open-loop flutter speed {f(b['open_loop_flutter_speed'], ' m/s')}"
                    f" ({params})"
                )
                b = None
        if b:
            bound = "suppression_margin" not in b  # stable to the end of the search
            margin = (
                b["closed_loop_v_max"] / b["open_loop_flutter_speed"] - 1.0
                if bound
                else b["suppression_margin"]
            )
            lines.append(
                f"  best suppression margin {'>= ' if bound else ''}{margin:+.1%} ({params}): "
                f"open loop {f(b['open_loop_flutter_speed'], ' m/s')}, closed loop "
                f"{f(b.get('closed_loop_flutter_speed'), ' m/s')}, peak hinge moment "
                f"{f(b.get('hinge_moment_peak'), ' N m')} in the gust"
            )
    for k, v in s.get("files", {}).items():
        lines.append(f"  wrote {k}: {v}")
    return "\n".join(lines)


HANDLERS = {"examples": _cmd_examples, **dict.fromkeys(_commands(), _cmd_run)}
