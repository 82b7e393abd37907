"""Optimization files (TOML): a wing, design variables with bounds, an objective and speed
constraints for :func:`aeroservo.studies.optimize.optimize_wing` (``aeroservo optimize``).

```toml
[optimize]
name = "..."
density = 1.225          # kg/m^3
elements = 10
v_max = 300.0            # m/s, optional top of each speed search

[wing]                   # the keys of a wing file's [wing] table (docs/wing-file.md)
...

[variables]              # wing-file names -> [lower, upper]
"segments[0].GJ" = [3.0e5, 3.0e6]

[objective]              # minimize = {variable = weight}  or  maximize = "flutter_speed"
minimize = { "segments[0].GJ" = 3.048 }   # a negative weight maximizes the variable

[constraints]            # m/s
flutter_speed_min = 150.0

[damping]                # optional: structural damping, as in a wing file (g, ratio, alpha/beta)
g = 0.02

[dlm]                    # optional, with [optimize] aero = "dlm" (and mach = 0.3, a fixed Mach
chordwise = 6            # number): the doublet lattice's settings, as in a wing file
```

``aeroservo optimize FILE --out DIR`` writes the optimum as a set (:func:`optimum_writers`):
``<stem>_wing.toml`` (a wing file with the file's density, elements, ``v_max``, ``aero``,
``mach`` and damping in ``[analysis]``, ``[dlm]`` and ``[damping]``: ``aeroservo flutter`` on it
repeats the optimum's fresh analysis), ``<stem>_history.csv`` (one row per SLSQP iterate) and
``<stem>_convergence.png``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import MAX_ELEMENTS, InputError
from .aero_tables import aero_options, dlm_toml
from .toml_tables import Table, check_integers, one_line_errors, read_toml
from .wing_file import damping_from_dict, wing_from_dict

__all__ = [
    "OptimizationFile",
    "CoDesignFile",
    "load_optimization",
    "load_codesign",
    "optimum_writers",
]

UNITS = {
    "segment": {
        "mass": "kg/m",
        "x_alpha": "-",
        "inertia": "kg m",
        "EI": "N m^2",
        "GJ": "N m^2",
        "a": "-",
        "semichord": "m",
    },
    "surface": {
        "hinge": "-",
        "static_moment": "kg m/m",
        "inertia": "kg m",
        "GJ": "N m^2",
        "hinge_stiffness": "N m/rad/m",
    },
    "actuator": {"stiffness": "N m/rad", "station": "m"},
    "mass": {
        "mass": "kg",
        "station": "m",
        "offset": "m",
        "inertia": "kg m^2",
        "vertical_offset": "m",
    },
}
"""Units of the design variables (wing-file keys by owner, ``docs/wing-file.md``)."""


@dataclass(frozen=True)
class OptimizationFile:
    """A validated optimization file."""

    name: str
    wing: object
    density: float
    elements: int
    v_max: float | None
    variables: dict
    objective: object
    constraints: dict
    damping: object = None
    aero: object = None  # DoubletLattice or None (strip theory)
    mach: float | None = None


def _bounds(top: Table) -> dict:
    """The ``[variables]`` table: ``name = [lower, upper]``, at least one."""
    vt = top.table("variables")
    variables = {}
    for key in vt.data:
        bounds = vt.numbers(key)
        if len(bounds) != 2 or not bounds[0] < bounds[1]:
            vt.fail(key, bounds, "expected [lower, upper], lower < upper")
        variables[key] = tuple(bounds)
    if not variables:
        top.fail("variables", {}, "give at least one design variable")
    return variables


def load_optimization(path: str | Path) -> OptimizationFile:
    """Read and validate an optimization file (every error names the file and the key)."""
    data = read_toml(path, "optimization file (TOML)")
    file = str(path)
    with one_line_errors():
        check_integers(data, file)
        top = Table(data, "", file).check_keys(
            ("optimize", "wing", "variables", "objective", "constraints"), ("damping", "dlm")
        )
        op = top.table("optimize").check_keys(
            ("density",), ("name", "elements", "v_max", "aero", "mach")
        )
        try:
            aero, mach = aero_options(op.data, "optimize", data.get("dlm"), "dlm")
        except InputError as exc:
            raise InputError(f"{file}: {exc}") from None
        try:
            wing = wing_from_dict(data["wing"])
        except InputError as exc:
            raise InputError(f"{file}: {exc}") from None
        variables = _bounds(top)
        ob = top.table("objective")
        if set(ob.data) == {"maximize"} and ob.data["maximize"] == "flutter_speed":
            objective = "flutter_speed"
        else:
            mn = ob.check_keys(("minimize",)).table("minimize")
            objective = {k: mn.check_value(k, v) for k, v in mn.data.items()}
            if not objective:
                mn.fail(None, {}, "give at least one variable and its weight")
        cons = top.table("constraints").check_keys(
            (), ("flutter_speed_min", "divergence_speed_min")
        )
        constraints = {k: cons.number(k, quantity="flight_speed") for k in cons.data}
        damping = None
        if "damping" in data:
            try:
                damping = damping_from_dict(top.table("damping").data, "damping")
            except InputError as exc:
                raise InputError(f"{file}: {exc}") from None
        return OptimizationFile(
            name=op.string("name", Path(file).stem),
            wing=wing,
            density=op.number("density", quantity="density", required=True),
            elements=op.integer("elements", 10, lo=1, hi=MAX_ELEMENTS),
            v_max=op.number("v_max", quantity="flight_speed"),
            variables=variables,
            objective=objective,
            constraints=constraints,
            damping=damping,
            aero=aero,
            mach=mach,
        )


@dataclass(frozen=True)
class CoDesignFile:
    """A validated co-design file: a trade scenario, a starting case, variables, a limit."""

    name: str
    scenario: object
    start: dict
    variables: dict
    hinge_moment_peak_max: float | None


def load_codesign(path: str | Path) -> CoDesignFile:
    """Read a co-design file: ``[codesign]`` (``name``, ``scenario`` = a trade scenario),
    ``[start]`` (the case, trade-parameter names), ``[variables]`` (``name = [lower, upper]``)
    and ``[constraints]`` (``hinge_moment_peak_max`` [N m]); the objective is the closed-loop
    flutter speed, maximized."""
    from .scenario_file import load_scenario

    data = read_toml(path, "co-design file (TOML)")
    file = str(path)
    with one_line_errors():
        check_integers(data, file)
        top = Table(data, "", file).check_keys(("codesign", "start", "variables"), ("constraints",))
        cd = top.table("codesign").check_keys(("scenario",), ("name",))
        sc_path = cd.path("scenario", Path(file).parent, required=True)
        scenario = load_scenario(sc_path)
        if scenario.trade is None:
            cd.fail("scenario", cd.data["scenario"], f"a trade scenario, not {scenario.kind!r}")
        start = {k: top.table("start").number(k) for k in top.table("start").data}
        variables = _bounds(top)
        for key, bounds in variables.items():
            if key not in start:
                top.table("variables").fail(key, list(bounds), f"not in [start] {sorted(start)}")
        cons = top.table("constraints").check_keys((), ("hinge_moment_peak_max",))
        return CoDesignFile(
            name=cd.string("name", Path(file).stem),
            scenario=scenario,
            start=start,
            variables=variables,
            hinge_moment_peak_max=cons.number("hinge_moment_peak_max", quantity="limit"),
        )


def _num(x: float | None) -> str:
    return "" if x is None else repr(float(x))


def _wing_text(op: OptimizationFile, result, source: str) -> str:
    """The optimum as a wing file that ``aeroservo flutter`` reads with the same model."""
    from dataclasses import replace

    from .._version import __version__
    from ..studies.optimize import with_parameters
    from .wing_file import wing_toml

    wing = with_parameters(op.wing, result.variables)
    wing = replace(wing, name=f"{op.wing.name} (optimum of {Path(source).name})")
    state = "converged" if result.success else "NOT converged"
    lines = [
        f"# Optimum of {source} ({op.name}), aeroservo {__version__} 'optimize --out'.",
        f"# SLSQP {state}: {result.message}",
        f"# Fresh analysis of this wing: flutter speed {_num(result.flutter_speed) or 'none'} m/s, "
        f"divergence speed {_num(result.divergence_speed) or 'none'} m/s; active: "
        f"{', '.join(result.active) or 'none'}.",
        *(f"#   {n} = {v!r} (start {result.start[n]!r})" for n, v in result.variables.items()),
        "# Run again: aeroservo flutter <this file>",
        "",
        wing_toml(wing).rstrip("\n"),
        "",
        "[analysis]",
        f"density = {_num(op.density)}",
        f"elements = {op.elements}",
    ]
    if op.v_max is not None:
        lines.append(f"v_max = {_num(op.v_max)}")
    if op.aero is not None:
        lines.append('aero = "dlm"')
    if op.mach is not None:
        lines.append(f"mach = {_num(op.mach)}")
    lines += dlm_toml(op.aero)
    d = op.damping.to_dict() if op.damping is not None and op.damping.active else {}
    if d:
        lines += ["", "[damping]"]
        for k, v in d.items():
            if k != "kind":
                lines.append(
                    f"{k} = " + (f"[{', '.join(map(_num, v))}]" if k == "ratio" else _num(v))
                )
    return "\n".join(lines) + "\n"


def _history_csv(op: OptimizationFile, result) -> str:
    """One row per SLSQP iterate: variables (units in the header), objective, speeds,
    constraint margins ``speed / bound - 1`` (>= 0: met), designs and boundaries so far."""
    import csv
    import io

    from ..stability.sensitivity import parameter_values

    table = parameter_values(op.wing)
    names = list(result.variables)
    units = {n: UNITS[table[n][0]][table[n][2]] for n in names}
    objective = "objective [m/s]" if op.objective == "flutter_speed" else "objective"
    cons = list(result.constraints)
    header = [
        "iteration",
        *(f"{n} [{units[n]}]" for n in names),
        objective,
        "flutter_speed [m/s]",
        "divergence_speed [m/s]",
        *(f"{c} margin [-]" for c in cons),
        "designs_analysed",
        "flutter_boundaries",
    ]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for h in result.history:
        w.writerow(
            [
                h["iteration"],
                *(_num(h["variables"][n]) for n in names),
                _num(h["objective"]),
                _num(h["flutter_speed"]),
                _num(h["divergence_speed"]),
                *(_num(h["constraints"][c]) for c in cons),
                h["designs_analysed"],
                h["n_boundaries"],
            ]
        )
    return buf.getvalue()


def optimum_writers(op: OptimizationFile, result, out_dir: str | Path, source: str) -> dict:
    """The files of ``optimize --out``: ``{kind: (path, writer)}`` for
    :func:`aeroservo.atomic.atomic_write_set` (kinds ``wing``, ``history``, ``convergence``).

    Parameters
    ----------
    op : OptimizationFile
    result : Optimization
        From :func:`aeroservo.studies.optimize.optimize_wing` on ``op``.
    out_dir : str or Path
        Output folder (must exist when written).
    source : str
        The optimization file's path: its stem names the files.
    """
    from .._figures import detached
    from ..atomic import figure_writer
    from ..studies.optimize_plot import plot_convergence

    out, stem = Path(out_dir), Path(source).stem
    wing = _wing_text(op, result, source)
    csv_text = _history_csv(op, result)
    with detached():  # written to a file, not left in pyplot
        fig = plot_convergence(result, op.variables, op.objective, title=op.name)
    png = out / f"{stem}_convergence.png"

    def text(t: str):
        return lambda p: p.write_text(t, encoding="utf-8")

    return {
        "wing": (out / f"{stem}_wing.toml", text(wing)),
        "history": (out / f"{stem}_history.csv", text(csv_text)),
        "convergence": (png, figure_writer(fig, png, dpi=120)),
    }
