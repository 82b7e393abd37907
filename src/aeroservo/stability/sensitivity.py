"""Analytic sensitivities of the flutter and divergence speeds to the wing's parameters.

At the flutter point (speed ``V_f``) a pair ``lambda = i omega`` of the pencil
``(lambda E - P(V)) x = 0``, ``P(V) = A0 + V A1 + V^2 A2``, crosses the imaginary axis. With the
right and left eigenvectors ``x``, ``y`` of that eigenvalue,

    dlambda/dp = y^H (dP/dp - lambda dE/dp) x / (y^H E x),
    dlambda/dV = y^H (A1 + 2 V A2) x / (y^H E x),

and, since ``Re lambda(V_f(p), p) = 0`` along the boundary,

    dV_f/dp = -Re(dlambda/dp) / Re(dlambda/dV),
    d omega_f/dp = Im(dlambda/dp) + Im(dlambda/dV) dV_f/dp.

``dE/dp`` and ``dP/dp`` are the pencil (:func:`aeroservo.system.first_order.pencil_blocks`, linear
in the matrices) of the matrix derivatives (:mod:`aeroservo.system.derivatives`: element
integrals of the derivatives of the section coefficients), structural damping's derivative
included (:func:`aeroservo.system.damping.damping_derivatives`). With the Prandtl-Glauert
correction at a matched Mach number ``M = V / a`` the speed derivative is the total one,
``dlambda/dV + (dlambda/dM) / a``; the altitude moves the density and the speed of sound
(:func:`aeroservo.aero.atmosphere.isa_slopes`).

The divergence speed ``V_d`` solves ``(Ks + rho V_d^2 K_static) q = 0``,
``K_static = Ka - Dz Lam^-1 Ez``; with left and right null vectors ``u``, ``q`` of that matrix
``F``: ``dV_d/dp = -(u^T dF/dp q) / (u^T dF/dV q)``.

All sensitivities together cost one flutter boundary plus two sparse factorizations and one
sparse pencil per parameter. Where the flutter speed is not differentiable (two branches cross
within ``TIE`` of each other: a mode switch; or a branch that only touches the axis, a hump
whose crossing speed has an infinite slope) the result says so instead of giving a number; a
parameter without a derivative of its own (an actuator on a mesh node, a kink of the discretized
model) is listed in ``undefined`` with its one-sided derivatives.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import InputError
from ..system.aeroelastic import AeroelasticModel
from ..system.damping import damping_parameters
from .eigen_derivatives import Terms
from .parameters import TIE, TOUCH, _tie, parameter_values, with_parameters
from .result import FlutterResult

__all__ = [
    "FlutterSensitivities",
    "flutter_sensitivities",
    "parameter_values",
    "with_parameters",
    "TIE",
    "TOUCH",
]


@dataclass
class FlutterSensitivities:
    """Derivatives of the flutter speed and frequency and of the divergence speed.

    Attributes
    ----------
    flutter_speed, flutter_frequency, divergence_speed : float or None
        [m/s], [Hz], [m/s] of the analysis the derivatives belong to.
    values : dict
        Parameter name -> its value (wing-file units; ``density`` in kg/m^3, ``altitude`` in m,
        ``mach``, ``damping.*`` as in the damping table).
    d_flutter_speed, d_flutter_frequency, d_divergence_speed : dict
        Parameter name -> derivative [m/s or Hz per unit of the parameter]; empty when the
        speed does not exist or is not differentiable.
    non_differentiable : str or None
        Why the flutter speed has no derivative here (None: it has one).
    undefined : dict
        Parameter name -> why it has no derivative (with its one-sided derivatives).
    density : float
        Air density [kg/m^3].
    altitude, mach : float or None
        Geopotential altitude [m] of an atmosphere-based analysis, Mach number of the
        aerodynamics (0: incompressible); ``matched``: the Mach number follows the speed.
    method : str
        ``"analytic"`` (eigenvalue derivatives) or ``"finite differences"`` (a
        doublet-lattice model: central differences of whole boundaries).
    """

    flutter_speed: float | None
    flutter_frequency: float | None
    divergence_speed: float | None
    values: dict
    d_flutter_speed: dict = field(default_factory=dict)
    d_flutter_frequency: dict = field(default_factory=dict)
    d_divergence_speed: dict = field(default_factory=dict)
    non_differentiable: str | None = None
    undefined: dict = field(default_factory=dict)
    one_sided: dict = field(default_factory=dict)
    density: float = 1.225
    altitude: float | None = None
    mach: float = 0.0
    matched: bool = False
    method: str = "analytic"

    def normalized(self) -> dict[str, float]:
        """``p / V_f dV_f/dp`` per parameter [-]: the % change of V_f per % of p."""
        vf = self.flutter_speed
        return {k: self.values[k] * d / vf for k, d in self.d_flutter_speed.items()}

    def to_dict(self) -> dict:
        """JSON-ready dict (SI units)."""
        return {
            "flutter_speed": self.flutter_speed,
            "flutter_frequency": self.flutter_frequency,
            "divergence_speed": self.divergence_speed,
            "density": self.density,
            "altitude": self.altitude,
            "mach": self.mach,
            "matched_mach": self.matched,
            "method": self.method,
            "non_differentiable": self.non_differentiable,
            "undefined": dict(self.undefined),
            "one_sided": dict(self.one_sided),
            "values": dict(self.values),
            "d_flutter_speed": dict(self.d_flutter_speed),
            "d_flutter_frequency": dict(self.d_flutter_frequency),
            "d_divergence_speed": dict(self.d_divergence_speed),
            "normalized_flutter_speed": self.normalized() if self.d_flutter_speed else {},
            "units": {
                "d_flutter_speed": "m/s per unit of the parameter",
                "d_flutter_frequency": "Hz per unit of the parameter",
            },
        }


def flutter_sensitivities(
    model: AeroelasticModel,
    density: float | None = None,
    parameters: list[str] | None = None,
    *,
    atmosphere=None,
    compressibility: str | None = None,
    result: FlutterResult | None = None,
    rtol: float = 1e-10,
    **kw,
) -> FlutterSensitivities:
    """Analytic sensitivities of the flutter and divergence speeds (see the module notes); of a
    doublet-lattice model, central finite differences (:mod:`.sensitivity_fd`).

    Parameters
    ----------
    model : AeroelasticModel
        The wing's model (structural damping of any kind included).
    density : float
        Air density [kg/m^3]; or give ``atmosphere``.
    parameters : list of str, optional
        Names as in the wing file (``"segments[0].GJ"``, ``"segments[0].a"``,
        ``"control_surfaces[0].hinge"``, ``"control_surfaces[0].actuators[1].station"``,
        ``"masses[0].mass"``, ``.station``, ``.offset``, ``.inertia``, ``.vertical_offset``), the
        damping's (``"damping.g"``, ``"damping.ratio"``, ``"damping.alpha"``), and the flight
        condition's (``"density"``; ``"altitude"`` with an atmosphere; ``"mach"`` at a fixed
        Mach number); default all of them.
    atmosphere : Atmosphere, optional
        A standard-atmosphere flight condition (:func:`aeroservo.aero.atmosphere.isa`).
    compressibility : {None, "prandtl-glauert"}
        With ``atmosphere``: the Prandtl-Glauert correction at the matched Mach number.
    result : FlutterResult, optional
        The boundary at this flight condition, if already computed (else computed with
        ``rtol``).
    rtol : float
        Tolerance of the boundary's crossing speeds (tight: the derivative is taken there).
    **kw
        Passed to :func:`aeroservo.flutter_boundary` (``v_max``, ``n_modes``, ``mach``).

    Returns
    -------
    FlutterSensitivities
    """
    if not isinstance(model, AeroelasticModel):
        raise InputError(f"model = {type(model).__name__}: expected an aeroservo.AeroelasticModel")
    if result is None:
        result = _boundary(model, density, atmosphere, compressibility, rtol, kw)
    r = result
    matched = "matched" in r.info
    flight = {"density": r.density}
    if r.altitude is not None:
        flight["altitude"] = r.altitude
    if r.mach and not matched:
        flight["mach"] = r.mach
    table = parameter_values(model.wing)
    own = damping_parameters(model.damping)
    known = {**{n: v[3] for n, v in table.items()}, **own, **flight}
    names = list(known) if parameters is None else _checked(parameters, known)
    out = FlutterSensitivities(
        r.flutter_speed,
        r.flutter_frequency,
        r.divergence_speed,
        {n: known[n] for n in names},
        density=r.density,
        altitude=r.altitude,
        mach=r.mach,
        matched=matched,
    )
    if model.dlm is not None:
        from .sensitivity_fd import finite_differences

        finite_differences(model, r, out, table, atmosphere, compressibility, kw)
        return out
    terms = Terms(model, r, matched)
    for name in names:
        why = terms.add(name, table.get(name))
        if why:
            out.undefined[name] = why
    if "altitude" in terms.kinks and "altitude" in names:
        out.undefined["altitude"] = terms.kinks["altitude"][0]
    if r.flutter_speed is not None:
        out.non_differentiable = _tie(r)
        if out.non_differentiable is None:
            out.non_differentiable = terms.flutter(out, TOUCH)
    if r.divergence_speed is not None:
        terms.divergence(out)
    return out


def _boundary(model, density, atmosphere, compressibility, rtol, kw) -> FlutterResult:
    from .boundary import flutter_boundary

    if atmosphere is None:
        if density is None:
            raise InputError("density = None: give the air density [kg/m^3] or an atmosphere")
        if compressibility not in (None, "none"):
            raise InputError(
                f"compressibility = {compressibility!r}: needs the speed of sound, give an "
                "atmosphere instead of a density"
            )
        return flutter_boundary(model, density, rtol=rtol, **kw)
    if density is not None:
        raise InputError("density and atmosphere: give one of them")
    if "mach" in kw:
        raise InputError(
            "mach with an atmosphere: the Mach number is the flight's (give compressibility="
            "'prandtl-glauert' to match it), or give a density and a fixed mach"
        )
    from .matched import flutter_at

    return flutter_at(model, atmosphere, compressibility=compressibility, rtol=rtol, **kw)


def _checked(parameters: object, known: dict) -> list[str]:
    if isinstance(parameters, str) or not isinstance(parameters, (list, tuple)):
        raise InputError(f"parameters = {parameters!r}: expected a list of parameter names")
    for p in parameters:
        if p not in known:
            raise InputError(
                f"parameters: {p!r} is not a parameter of this analysis; known: "
                f"{[*list(known)[:6], '...', *[k for k in known if '[' not in k]]}"
            )
    return list(parameters)
