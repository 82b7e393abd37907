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
```
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import MAX_ELEMENTS, InputError
from .toml_tables import Table, check_integers, one_line_errors, read_toml
from .wing_file import damping_from_dict, wing_from_dict

__all__ = ["OptimizationFile", "CoDesignFile", "load_optimization", "load_codesign"]


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
            ("optimize", "wing", "variables", "objective", "constraints"), ("damping",)
        )
        op = top.table("optimize").check_keys(("density",), ("name", "elements", "v_max"))
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
        if scenario.kind != "trade":
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
