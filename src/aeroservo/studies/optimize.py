"""Gradient-based aeroelastic tailoring: wing parameters chosen by SLSQP with the analytic
flutter-speed sensitivities (:mod:`aeroservo.stability.sensitivity`).

The design variables are wing parameters named as in the wing file, each within bounds; the
objective is a weighted sum of them (e.g. stiffness times length, a material proxy) to
minimize, or the flutter speed to maximize; the constraints are lower bounds on the flutter
and divergence speeds. Variables are scaled by their starting values. Every iterate is logged;
the optimum is verified by a fresh analysis of a newly built model, and the active constraints
are reported. ``gradients="central"`` solves the same problem with central differences of
the flutter speed (two boundaries per variable and iterate) for comparison.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, check_int, check_number
from ..stability.boundary import flutter_boundary
from ..stability.sensitivity import flutter_sensitivities, parameter_values, with_parameters
from ..system.aeroelastic import AeroelasticModel

__all__ = ["Optimization", "optimize_wing", "with_parameters", "design_variables"]

ACTIVE = 1e-4
"""A constraint within this relative margin of its bound is reported active."""


@dataclass
class Optimization:
    """Result of :func:`optimize_wing` (SI units)."""

    variables: dict
    objective: float
    flutter_speed: float | None
    divergence_speed: float | None
    constraints: dict
    active: list
    success: bool
    message: str
    iterations: list = field(default_factory=list)
    n_boundaries: int = 0
    start: dict = field(default_factory=dict)
    history: list = field(default_factory=list)
    """One record per SLSQP iterate, the start first (:func:`optimize_wing`)."""

    def to_dict(self) -> dict:
        return {
            "success": self.success,
            "message": self.message,
            "variables": dict(self.variables),
            "start": dict(self.start),
            "objective": self.objective,
            "flutter_speed": self.flutter_speed,
            "divergence_speed": self.divergence_speed,
            "constraints": dict(self.constraints),
            "active_constraints": list(self.active),
            "n_boundaries": self.n_boundaries,
            "iterations": list(self.iterations),
        }


def optimize_wing(
    wing,
    density: float,
    variables: dict,
    objective: dict | str,
    constraints: dict,
    *,
    n_elements: int = 10,
    wagner: object = "rt_jones",
    damping=None,
    v_max: float | None = None,
    gradients: str = "analytic",
    max_iterations: int = 60,
    aero: object = "strip",
    mach: float | None = None,
) -> Optimization:
    """Choose wing parameters by SLSQP.

    Parameters
    ----------
    wing : Wing
        The starting design.
    density : float
        Air density [kg/m^3].
    variables : dict
        Parameter name -> (lower, upper) bound, in the parameter's unit.
    objective : dict or str
        ``{name: weight}``: minimize ``sum weight * value``; ``"flutter_speed"``: maximize it.
    constraints : dict
        ``flutter_speed_min`` and/or ``divergence_speed_min`` [m/s].
    n_elements, wagner, damping, v_max
        The model (structural damping: a StructuralDamping or None) and the top of each speed
        search.
    gradients : {"analytic", "central"}
        Analytic sensitivities, or central differences (relative step 1e-5) for comparison.
        Where an analytic derivative does not exist at an iterate (a mode switch, an actuator
        on a mesh node) that iterate's gradient is a central difference, and its log says why.
    max_iterations : int
    aero : {"strip", "dlm"}, dict or DoubletLattice
        Aerodynamic model (:class:`aeroservo.AeroelasticModel`); the doublet lattice's
        "analytic" gradients are central finite differences of its boundaries
        (:func:`aeroservo.stability.sensitivity.flutter_sensitivities`).
    mach : float, optional
        Fixed Mach number of the aerodynamics (default 0).

    Returns
    -------
    Optimization
        ``iterations`` logs every design analysed (line searches included); ``history`` has
        one record per SLSQP iterate, the start first: ``iteration``, ``variables``,
        ``objective`` (the weighted sum, or the flutter speed [m/s]), ``flutter_speed`` and
        ``divergence_speed`` [m/s] (None: none up to ``v_max``), ``constraints`` (each
        constraint's ``speed / bound - 1``, >= 0 where it holds), ``designs_analysed`` and
        ``n_boundaries`` (cumulative).
    """
    from scipy.optimize import minimize

    table = parameter_values(wing)
    start = {n: v[3] for n, v in table.items()}
    names, lo, hi, p0, scale = design_variables(variables, start, "of this wing")
    weights = _objective(objective, names)
    limits = _constraints(constraints)
    if gradients not in ("analytic", "central"):
        raise InputError(f"gradients = {gradients!r}: allowed values are 'analytic', 'central'")
    check_int("max_iterations", max_iterations, lo=1, hi=1000)
    cache: dict = {}
    log: list = []
    count = [0]
    logged: dict = {}  # cache key -> (its entry of log, designs and boundaries so far)
    iterates: list = []  # (x, designs analysed, boundaries) after each iteration

    fb = {"v_max": v_max, **({"mach": mach} if mach else {})}  # each boundary's options

    def make(w):
        return AeroelasticModel(w, n_elements, wagner, damping=damping, aero=aero)

    def key_of(x: np.ndarray) -> tuple:
        return tuple(np.round(x, 14))

    def analyse(x: np.ndarray):
        key = key_of(x)
        if key not in cache:
            p = x * scale
            how = gradients
            if gradients == "analytic":
                count[0] += 1
                moved = with_parameters(wing, dict(zip(names, p, strict=True)))
                s = flutter_sensitivities(make(moved), density, [*names], **fb)
                vf, vd = s.flutter_speed, s.divergence_speed
                why = s.non_differentiable or next(
                    (f"{n}: {s.undefined[n]}" for n in names if n in s.undefined), None
                )
                dvf = np.array([s.d_flutter_speed.get(n, 0.0) for n in names]) * scale
                dvd = np.array([s.d_divergence_speed.get(n, 0.0) for n in names]) * scale
                if why is not None and vf is not None:
                    how = f"central ({why})"
            if how != "analytic":
                vf, vd, dvf, dvd = _central(make, wing, names, p, scale, density, fb, count)
            top = v_max if v_max is not None else np.inf
            cache[key] = (vf if vf is not None else top, vd if vd is not None else top, dvf, dvd)
            log.append(
                {
                    "variables": dict(zip(names, map(float, p), strict=True)),
                    "flutter_speed": vf,
                    "divergence_speed": vd,
                    "gradients": how,
                }
            )
            logged[key] = (log[-1], len(log), count[0])
        return cache[key]

    # the objective's scale: its magnitude at the start (never its sign: a negative weight or
    # value must not turn the minimization into a maximization)
    norm = 1.0 if weights is None else float(abs(weights @ p0)) or float(abs(weights) @ abs(p0))

    def f(x):
        if weights is None:
            return -analyse(x)[0] / analyse(np.ones_like(x))[0]
        return float(weights @ (x * scale)) / (norm or 1.0)

    def df(x):
        if weights is None:
            return -analyse(x)[2] / analyse(np.ones_like(x))[0]
        return weights * scale / (norm or 1.0)

    cons = []
    for idx, bound in limits.values():
        cons.append(
            {
                "type": "ineq",
                "fun": lambda x, i=idx, b=bound: analyse(x)[i] / b - 1.0,
                "jac": lambda x, i=idx, b=bound: analyse(x)[i + 2] / b,
            }
        )

    def iterate(x: np.ndarray) -> None:
        if not iterates or key_of(iterates[-1][0]) != key_of(x):
            iterates.append((np.array(x, dtype=float), len(log), count[0]))

    iterate(p0 / scale)
    sol = minimize(
        f,
        p0 / scale,
        jac=df,
        bounds=list(zip(lo / scale, hi / scale, strict=True)),
        constraints=cons,
        method="SLSQP",
        options={"maxiter": max_iterations, "ftol": 1e-9},
        callback=iterate,
    )
    iterate(sol.x)
    best = dict(zip(names, map(float, sol.x * scale), strict=True))
    check = flutter_boundary(
        make(with_parameters(wing, best)), density, **fb
    )  # a fresh model and analysis
    values = {"flutter_speed": check.flutter_speed, "divergence_speed": check.divergence_speed}
    active, margins = [], {}
    for k, (_idx, bound) in limits.items():
        v = values[k.replace("_min", "")]
        margins[k] = {"bound": bound, "value": v}
        if v is not None and abs(v / bound - 1.0) < ACTIVE:
            active.append(k)
    for i, n in enumerate(names):
        if np.isclose(sol.x[i] * scale[i], lo[i], rtol=ACTIVE) or np.isclose(
            sol.x[i] * scale[i], hi[i], rtol=ACTIVE
        ):
            active.append(f"bound {n}")
    feasible = all(
        m["value"] is None or m["value"] >= m["bound"] * (1 - ACTIVE) for m in margins.values()
    )
    objective_value = (
        check.flutter_speed if weights is None else float(weights @ np.array(list(best.values())))
    )

    def speeds_at(x: np.ndarray) -> tuple:
        """Flutter and divergence speed of an iterate, designs and boundaries analysed then."""
        if key_of(x) not in logged:  # never analysed by SLSQP (no speed in the problem)
            moved = with_parameters(wing, dict(zip(names, x * scale, strict=True)))
            r = flutter_boundary(make(moved), density, **fb)  # a fresh look
            return r.flutter_speed, r.divergence_speed, 0, 0
        entry, n_designs, n_boundaries = logged[key_of(x)]
        return entry["flutter_speed"], entry["divergence_speed"], n_designs, n_boundaries

    top = v_max if v_max is not None else np.inf
    history = _history(iterates, speeds_at, names, scale, weights, limits, top)
    return Optimization(
        variables=best,
        objective=objective_value,
        flutter_speed=check.flutter_speed,
        divergence_speed=check.divergence_speed,
        constraints=margins,
        active=active,
        success=bool(sol.success) and feasible,
        message=str(sol.message) + ("" if feasible else "; constraints violated on re-analysis"),
        iterations=log,
        n_boundaries=count[0] + 1,
        start=dict(zip(names, map(float, p0), strict=True)),
        history=history,
    )


def _history(iterates, speeds_at, names, scale, weights, limits, top) -> list:
    """The records of :attr:`Optimization.history`, one per iterate ``(x, designs, boundaries)``
    (``speeds_at(x)``: flutter and divergence speed [m/s] or None and the designs and
    boundaries analysed by then; ``top``: a missing speed's value in the constraints, as the
    optimizer saw it)."""
    out = []
    for k, (x, designs, boundaries) in enumerate(iterates):
        p = x * scale
        vf, vd, n_designs, n_boundaries = speeds_at(x)
        speeds = {"flutter_speed": vf, "divergence_speed": vd}
        out.append(
            {
                "iteration": k,
                "variables": dict(zip(names, map(float, p), strict=True)),
                "objective": vf if weights is None else float(weights @ p),
                **speeds,
                "constraints": {
                    c: (speeds[c.replace("_min", "")] or top) / bound - 1.0
                    for c, (_i, bound) in limits.items()
                },
                "designs_analysed": max(designs, n_designs),
                "n_boundaries": max(boundaries, n_boundaries),
            }
        )
    return out


def design_variables(variables: object, start: dict, owner: str) -> tuple:
    """Checked design variables ``{name: (lower, upper)}`` with their starting values.

    Returns ``(names, lower, upper, x0, scale)``: the start clipped into the bounds, and the
    scale of each variable (its start, or ``max(|upper|, 1)`` for a zero start) that SLSQP
    works in. ``owner`` names what ``start`` describes, for messages.
    """
    if not isinstance(variables, dict) or not variables:
        raise InputError(f"variables = {variables!r}: expected {{name: (lower, upper)}}")
    for n, b in variables.items():
        if n not in start:
            raise InputError(f"variables: {n!r} is not a parameter {owner} {list(start)[:8]}")
        if not isinstance(b, (list, tuple)) or len(b) != 2:
            raise InputError(f"variables[{n!r}] = {b!r}: expected [lower, upper]")
        a = check_number(f"variables[{n!r}][0]", b[0])
        check_number(f"variables[{n!r}][1]", b[1], lo=a, lo_open=True)
    names = list(variables)
    lo = np.array([variables[n][0] for n in names], float)
    hi = np.array([variables[n][1] for n in names], float)
    x0 = np.clip([float(start[n]) for n in names], lo, hi)
    scale = np.where(x0 != 0, np.abs(x0), np.maximum(np.abs(hi), 1.0))
    return names, lo, hi, x0, scale


def _objective(objective: object, names: list[str]) -> np.ndarray | None:
    if objective == "flutter_speed":
        return None
    if not isinstance(objective, dict) or not objective:
        raise InputError(
            f"objective = {objective!r}: expected 'flutter_speed' or {{variable: weight}}"
        )
    for n, w in objective.items():
        if n not in names:
            raise InputError(f"objective: {n!r} is not a design variable {names}")
        check_number(f"objective[{n!r}]", w)
    return np.array([float(objective.get(n, 0.0)) for n in names])


def _constraints(constraints: object) -> dict:
    known = {"flutter_speed_min": 0, "divergence_speed_min": 1}
    if not isinstance(constraints, dict):
        raise InputError(f"constraints = {constraints!r}: expected a mapping")
    out = {}
    for k, v in constraints.items():
        if k not in known:
            raise InputError(f"constraints.{k}: unknown; allowed are {sorted(known)}")
        out[k] = (known[k], check_number(f"constraints.{k}", v, unit="m/s", lo=0.1, hi=1000.0))
    return out


def _central(make, wing, names, p, scale, density, fb, count):
    """Speeds and their gradients by central differences (relative step 1e-5); ``make``
    builds the model of a wing, ``fb`` the options of its boundaries."""

    def speeds(q):
        count[0] += 1
        m = make(with_parameters(wing, dict(zip(names, q, strict=True))))
        r = flutter_boundary(m, density, rtol=1e-12, **fb)
        return r.flutter_speed, r.divergence_speed

    vf, vd = speeds(p)
    dvf, dvd = np.zeros(len(p)), np.zeros(len(p))
    for i in range(len(p)):
        h = 1e-5 * scale[i]
        up, dn = p.copy(), p.copy()
        up[i] += h
        dn[i] -= h
        (fu, du), (fd, dd) = speeds(up), speeds(dn)
        if fu is not None and fd is not None:
            dvf[i] = (fu - fd) / (2 * h) * scale[i]
        if du is not None and dd is not None:
            dvd[i] = (du - dd) / (2 * h) * scale[i]
    return vf, vd, dvf, dvd
