"""Sensitivities of a closed-loop trade case to its parameters, by central differences.

The closed-loop flutter speed of a case passes through the controller design (an LQR or LQG
Riccati solution at the design speed, on a modal design model) and a closed-loop boundary of
the sampled loop. No analytic derivative is implemented for that chain (the Riccati
derivative would be the next step): these are **central finite differences** of
:func:`aeroservo.studies.trade.cases.evaluate_case`, documented as such, with a relative step
(default 1e-3) large against the boundary's tolerance (1e-7 relative) and small against the
curvature of the design space. A derivative is reported as unavailable when a perturbed case
fails, loses its closed-loop flutter point (stable to the end of the search) or lands on a
different stable interval (the closed-loop flutter speed is not continuous there).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from ...errors import InputError, check_number
from .cases import evaluate_case
from .study import PARAMETERS, TradeStudy

__all__ = ["CaseSensitivities", "case_sensitivities"]

METRICS = ("closed_loop_flutter_speed", "suppression_margin", "hinge_moment_peak")
"""The metrics differentiated."""


@dataclass
class CaseSensitivities:
    """Central-difference derivatives of one trade case's metrics.

    Attributes
    ----------
    case : dict
        The evaluated base case (every metric of the trade study).
    derivatives : dict
        Metric -> {parameter: derivative [metric unit per parameter unit]}.
    unavailable : dict
        Parameter -> why no derivative is given.
    steps : dict
        Parameter -> the absolute step used.
    """

    case: dict
    derivatives: dict = field(default_factory=dict)
    unavailable: dict = field(default_factory=dict)
    steps: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {
            "method": "central finite differences of the trade case (no analytic form)",
            "case": dict(self.case),
            "derivatives": {m: dict(d) for m, d in self.derivatives.items()},
            "unavailable": dict(self.unavailable),
            "steps": dict(self.steps),
        }


def case_sensitivities(
    study: TradeStudy,
    params: Mapping,
    parameters: Sequence[str] | None = None,
    *,
    rel_step: float = 1e-3,
) -> CaseSensitivities:
    """Derivatives of the closed-loop flutter speed, the suppression margin and the gust peak
    hinge moment of one case, by central differences (two case evaluations per parameter).

    Parameters
    ----------
    study : TradeStudy
    params : mapping
        The case ``{parameter: value}`` (the trade study's parameter names, e.g.
        ``bryson_hinge_moment`` [N m], ``aileron_chord``, ``hinge_stiffness``).
    parameters : sequence of str, optional
        Which parameters (default: those of ``params``).
    rel_step : float
        Relative step (default 1e-3; absolute 1e-3 for a zero value).

    Returns
    -------
    CaseSensitivities
    """
    if not isinstance(params, Mapping):
        raise InputError(f"params = {params!r}: expected a mapping {{parameter: value}}")
    names = list(params) if parameters is None else list(parameters)
    for n in names:
        if n not in PARAMETERS or n not in params:
            raise InputError(f"parameters: {n!r} is not a parameter of this case {list(params)}")
    h_rel = check_number("rel_step", rel_step, lo=1e-6, hi=0.1)
    base = evaluate_case(study, params)
    if base["status"] != "ok":
        raise InputError(f"the base case failed at {base['failed_stage']}: {base['error']}")
    out = CaseSensitivities(case=base, derivatives={m: {} for m in METRICS})
    for n in names:
        x = float(params[n])
        h = h_rel * (abs(x) or 1.0)
        out.steps[n] = h
        up = evaluate_case(study, {**params, n: x + h})
        dn = evaluate_case(study, {**params, n: x - h})
        why = _why_not(base, up, dn)
        if why:
            out.unavailable[n] = why
            continue
        for m in METRICS:
            if up[m] is not None and dn[m] is not None:
                out.derivatives[m][n] = (up[m] - dn[m]) / (2 * h)
    return out


def _why_not(base: dict, up: dict, dn: dict) -> str | None:
    for side, rec in (("+", up), ("-", dn)):
        if rec["status"] != "ok":
            return f"the {side} step fails at {rec['failed_stage']}: {rec['error']}"
        if (rec["closed_loop_flutter_speed"] is None) != (
            base["closed_loop_flutter_speed"] is None
        ):
            return f"the {side} step changes whether the closed loop flutters below v_max"
        if rec["stable_at_design"] != base["stable_at_design"]:
            return f"the {side} step changes the stable interval (not continuous there)"
    return None
