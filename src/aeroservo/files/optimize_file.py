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
minimize = { "segments[0].GJ" = 3.048 }

[constraints]            # m/s
flutter_speed_min = 150.0
```
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import MAX_ELEMENTS, InputError
from .toml_tables import Table, check_integers, one_line_errors, read_toml
from .wing_file import wing_from_dict

__all__ = ["OptimizationFile", "load_optimization"]


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


def load_optimization(path: str | Path) -> OptimizationFile:
    """Read and validate an optimization file (every error names the file and the key)."""
    data = read_toml(path, "optimization file (TOML)")
    file = str(path)
    with one_line_errors():
        check_integers(data, file)
        top = Table(data, "", file).check_keys(
            ("optimize", "wing", "variables", "objective", "constraints")
        )
        op = top.table("optimize").check_keys(("density",), ("name", "elements", "v_max"))
        try:
            wing = wing_from_dict(data["wing"])
        except InputError as exc:
            raise InputError(f"{file}: {exc}") from None
        variables = {}
        for key in top.table("variables").data:
            bounds = top.table("variables").numbers(key)
            if len(bounds) != 2 or not bounds[0] < bounds[1]:
                top.table("variables").fail(key, bounds, "expected [lower, upper], lower < upper")
            variables[key] = tuple(bounds)
        if not variables:
            top.fail("variables", {}, "give at least one design variable")
        ob = top.table("objective")
        if set(ob.data) == {"maximize"} and ob.data["maximize"] == "flutter_speed":
            objective = "flutter_speed"
        else:
            mn = ob.check_keys(("minimize",)).table("minimize")
            objective = {k: mn.check_value(k, v, lo=0.0) for k, v in mn.data.items()}
            if not objective:
                mn.fail(None, {}, "give at least one variable and its weight")
        cons = top.table("constraints").check_keys(
            (), ("flutter_speed_min", "divergence_speed_min")
        )
        constraints = {k: cons.number(k, quantity="flight_speed") for k in cons.data}
        return OptimizationFile(
            name=op.string("name", Path(file).stem),
            wing=wing,
            density=op.number("density", quantity="density", required=True),
            elements=op.integer("elements", 10, lo=1, hi=MAX_ELEMENTS),
            v_max=op.number("v_max", quantity="flight_speed"),
            variables=variables,
            objective=objective,
            constraints=constraints,
        )
