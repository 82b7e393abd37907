"""Sensitivities of a doublet-lattice model by central finite differences.

The analytic derivatives of :mod:`aeroservo.stability.sensitivity` differentiate the strip
model's matrices; a doublet-lattice model's aerodynamic forces come from a lattice, a spline and
a rational fit that move with the planform, so its derivatives are taken as central differences
of whole analyses: for each parameter ``p`` the model is built again at ``p +- h`` (same
aerodynamic settings; the AICs are computed again only when the planform moves) and its flutter
and divergence speeds are found to ``rtol``:

``dV/dp ~ (V(p + h) - V(p - h)) / (2 h)``,   ``h = STEP max(|p|, scale)``

with ``scale`` the parameter's natural size (a semichord, the span, ...) for parameters whose
value may be zero. The error is ``O(h^2)`` plus ``rtol V / h``. A derivative whose two sides
find different crossings (another mode goes unstable first, or the speed vanishes) is listed as
undefined with its one-sided values, as the analytic derivatives are. A parameter at a bound of
its allowed range (a mass at the tip, a rotary inertia's zero mass) is differenced on the side
that stays inside, to first order, and listed in ``one_sided``.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..system.damping import StructuralDamping, damping_parameters

__all__ = ["finite_differences", "STEP"]

STEP = 1e-4
"""Relative step of the central differences."""


def _scale(model, name: str) -> float:
    """The natural size of a parameter whose value may be zero."""
    wing = model.wing
    if name.endswith((".a", ".x_alpha", ".hinge")):
        return 1.0  # semichords
    if name.endswith(("offset", "station", "vertical_offset")):
        return wing.span
    return 0.0


def _damped(damping: StructuralDamping, name: str, value: float) -> StructuralDamping:
    """The damping with one of its own parameters set to ``value``."""
    if name == "damping.g":
        return StructuralDamping.structural(value)
    if name in ("damping.alpha", "damping.beta"):
        alpha = value if name == "damping.alpha" else damping.alpha
        beta = value if name == "damping.beta" else damping.beta
        return StructuralDamping.rayleigh(alpha, beta)
    ratios = list(damping.ratios)
    i = int(name[name.index("[") + 1 : name.index("]")]) if "[" in name else 0
    ratios[i] = value
    if damping.kind == "per_dof":
        return StructuralDamping.per_dof(ratios, damping.plunge_mass)
    return StructuralDamping.modal(ratios if len(ratios) > 1 else ratios[0])


def finite_differences(model, result, out, table: dict, atmosphere, compressibility, kw) -> None:
    """Fill ``out`` (a :class:`FlutterSensitivities`) with central differences (module notes).

    Parameters
    ----------
    model : AeroelasticModel
        A doublet-lattice model.
    result : FlutterResult
        Its boundary at the flight condition.
    out : FlutterSensitivities
        Its ``values`` name the parameters; derivatives and undefined ones are added.
    table : dict
        :func:`aeroservo.stability.sensitivity.parameter_values` of the wing.
    atmosphere, compressibility, kw
        The flight condition and boundary options of the analysis.
    """
    from ..aero.atmosphere import isa
    from ..system.aeroelastic import AeroelasticModel
    from .boundary import flutter_boundary
    from .matched import flutter_at
    from .parameters import TIE, _tie, with_parameters

    out.method = "finite differences"
    base = {k: v for k, v in kw.items() if k != "mach"}
    base["rtol"] = 1e-10
    base.setdefault("v_max", result.v_max)
    own = damping_parameters(model.damping)

    def analysis(name: str, value: float):
        wing, damping = model.wing, model.damping
        rho, mach, atm = result.density, kw.get("mach", 0.0), atmosphere
        if name in table:
            wing = with_parameters(wing, {name: value})
        elif name in own:
            damping = _damped(damping, name, value)
        elif name == "density":
            rho = value
        elif name == "mach":
            mach = value
        elif name == "altitude":
            atm = isa(value)
        m = AeroelasticModel(wing, model.n_elements, model.wagner, damping, aero=model.aero)
        if atm is not None:
            return flutter_at(m, atm, compressibility=compressibility, **base)
        return flutter_boundary(m, rho, mach=mach, **base)

    out.non_differentiable = _tie(result) if result.flutter_speed is not None else None
    for name, p in out.values.items():
        h = STEP * max(abs(p), _scale(model, name))
        if h == 0.0:
            out.undefined[name] = "zero value without a natural scale: no step to take"
            continue
        sides = []
        for sign in (1.0, -1.0):
            try:
                sides.append(analysis(name, p + sign * h))
            except InputError:  # a bound of the parameter: a mass at the tip, a zero mass
                sides.append(None)
        if sides[0] is None and sides[1] is None:
            out.undefined[name] = "both sides of the step leave the parameter's allowed range"
            continue
        if None in sides:
            side = "upper" if sides[1] is None else "lower"
            out.one_sided[name] = f"the {side} side only (the other leaves the allowed range)"
        for what, target, get in (
            ("flutter speed", out.d_flutter_speed, lambda r: r.flutter_speed),
            ("flutter frequency", out.d_flutter_frequency, lambda r: r.flutter_frequency),
            ("divergence speed", out.d_divergence_speed, lambda r: r.divergence_speed),
        ):
            v0 = get(result)
            if v0 is None or (what != "divergence speed" and out.non_differentiable):
                continue
            if None in sides:  # one-sided, first order
                r = sides[0] if sides[1] is None else sides[1]
                v = get(r)
                if v is not None:
                    target[name] = (v - v0) / h if sides[1] is None else (v0 - v) / h
                continue
            hi, lo = (get(r) for r in sides)
            same = what == "divergence speed" or all(
                r.flutter is not None and r.flutter.mode == result.flutter.mode for r in sides
            )
            if hi is None or lo is None or not same or _jump(hi, lo, v0, TIE):
                right = None if hi is None else (hi - v0) / h
                left = None if lo is None else (v0 - lo) / h
                out.undefined.setdefault(
                    name,
                    f"{what}: the two sides find different crossings (one-sided derivatives "
                    f"{_show(right)} and {_show(left)})",
                )
                continue
            target[name] = (hi - lo) / (2.0 * h)


def _jump(hi: float, lo: float, v0: float, tie: float) -> bool:
    """The two sides lie on different branches: their difference is out of proportion."""
    return bool(abs(hi - lo) > 10 * tie * abs(v0) and np.sign(hi - v0) == np.sign(lo - v0))


def _show(v: float | None) -> str:
    return "none" if v is None else f"{v:.6g}"
