"""Co-design: aileron and controller parameters of a closed-loop trade case chosen together.

The design variables are trade-study parameters (``aileron_start``, ``aileron_chord``,
``hinge_stiffness``, ``actuator_station``, ``bryson_hinge_moment``, ``speed_factor``) within
bounds; the objective is to maximize the closed-loop flutter speed; the constraint is an upper
limit on the peak hinge moment in the study's 1-cos gust. The gradients are central finite
differences of the case (:func:`aeroservo.studies.trade.sensitivity.case_sensitivities`: the
chain runs through a Riccati design, with no analytic derivative here). SLSQP, variables
scaled by their starting values; the optimum is re-evaluated as a fresh case.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, check_number
from ..optimize import design_variables
from .cases import evaluate_case
from .sensitivity import case_sensitivities
from .study import PARAMETERS, TradeStudy

__all__ = ["CoDesign", "codesign"]


@dataclass
class CoDesign:
    """Result of :func:`codesign`."""

    variables: dict
    start: dict
    case: dict
    active: list
    success: bool
    message: str
    iterations: list = field(default_factory=list)
    n_cases: int = 0

    def to_dict(self) -> dict:
        return {
            "success": self.success,
            "message": self.message,
            "variables": dict(self.variables),
            "start": dict(self.start),
            "closed_loop_flutter_speed": self.case.get("closed_loop_flutter_speed"),
            "hinge_moment_peak": self.case.get("hinge_moment_peak"),
            "active_constraints": list(self.active),
            "n_cases": self.n_cases,
            "iterations": list(self.iterations),
            "gradients": "central finite differences of the trade case",
        }


def codesign(
    study: TradeStudy,
    start: dict,
    bounds: dict,
    *,
    hinge_moment_peak_max: float | None = None,
    rel_step: float = 1e-3,
    max_iterations: int = 30,
) -> CoDesign:
    """Maximize the closed-loop flutter speed over trade parameters, subject to a peak hinge
    moment limit [N m] in the study's gust.

    Parameters
    ----------
    study : TradeStudy
    start : dict
        The starting case ``{parameter: value}`` (every parameter of the study's grid).
    bounds : dict
        Design variables: parameter -> (lower, upper); the others stay at ``start``.
    hinge_moment_peak_max : float, optional
        Upper limit on ``hinge_moment_peak`` [N m].
    rel_step, max_iterations
        Central-difference step (relative) and SLSQP iteration limit.

    Returns
    -------
    CoDesign
    """
    from scipy.optimize import minimize

    case_parameters = {k: v for k, v in start.items() if k in PARAMETERS}
    names, lo, hi, x0, scale = design_variables(bounds, case_parameters, "of the case")
    limit = None
    if hinge_moment_peak_max is not None:
        limit = check_number(
            "hinge_moment_peak_max", hinge_moment_peak_max, unit="N m", lo=0.0, lo_open=True
        )
    cache: dict = {}
    log: list = []
    count = [0]

    def analyse(z: np.ndarray):
        key = tuple(np.round(z, 12))
        if key not in cache:
            case = {**start, **dict(zip(names, map(float, z * scale), strict=True))}
            s = case_sensitivities(study, case, names, rel_step=rel_step)
            count[0] += 1 + 2 * len(names)
            if s.unavailable:
                raise InputError(f"co-design stopped at {case}: {s.unavailable}")
            c = s.case
            if c["closed_loop_flutter_speed"] is None:
                raise InputError(
                    f"co-design: the closed loop is stable up to the search limit at {case}; "
                    "raise trade.v_max_factor"
                )
            d = s.derivatives
            cache[key] = (
                c,
                np.array([d["closed_loop_flutter_speed"][n] for n in names]) * scale,
                np.array([d["hinge_moment_peak"].get(n, 0.0) for n in names]) * scale,
            )
            log.append(
                {
                    **case,
                    "closed_loop_flutter_speed": c["closed_loop_flutter_speed"],
                    "hinge_moment_peak": c["hinge_moment_peak"],
                }
            )
        return cache[key]

    v0 = analyse(x0 / scale)[0]["closed_loop_flutter_speed"]
    cons = []
    if limit is not None:
        cons.append(
            {
                "type": "ineq",
                "fun": lambda z: 1.0 - analyse(z)[0]["hinge_moment_peak"] / limit,
                "jac": lambda z: -analyse(z)[2] / limit,
            }
        )
    sol = minimize(
        lambda z: -analyse(z)[0]["closed_loop_flutter_speed"] / v0,
        x0 / scale,
        jac=lambda z: -analyse(z)[1] / v0,
        bounds=list(zip(lo / scale, hi / scale, strict=True)),
        constraints=cons,
        method="SLSQP",
        options={"maxiter": max_iterations, "ftol": 1e-8},
    )
    best = dict(zip(names, map(float, sol.x * scale), strict=True))
    case = evaluate_case(study, {**start, **best})  # a fresh evaluation
    count[0] += 1
    active = [
        f"bound {n}"
        for i, n in enumerate(names)
        if np.isclose(best[n], lo[i], rtol=1e-4) or np.isclose(best[n], hi[i], rtol=1e-4)
    ]
    ok = case["status"] == "ok"
    if ok and limit is not None:
        peak = case["hinge_moment_peak"]
        if abs(peak / limit - 1.0) < 1e-3:
            active.append("hinge_moment_peak_max")
        ok = peak <= limit * (1 + 1e-3)
    return CoDesign(
        best,
        dict(zip(names, map(float, x0), strict=True)),
        case,
        active,
        bool(sol.success) and ok,
        str(sol.message),
        log,
        count[0],
    )
