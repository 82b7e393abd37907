"""Analytic sensitivities of the flutter and divergence speeds to the wing's parameters.

At the flutter point (speed ``V_f``) a pair ``lambda = i omega`` of the pencil
``(lambda E - P(V)) x = 0``, ``P(V) = A0 + V A1 + V^2 A2``, crosses the imaginary axis. With the
right and left eigenvectors ``x``, ``y`` of that eigenvalue,

    dlambda/dp = y^H (dP/dp - lambda dE/dp) x / (y^H E x),
    dlambda/dV = y^H (A1 + 2 V A2) x / (y^H E x),

and, since ``Re lambda(V_f(p), p) = 0`` along the boundary,

    dV_f/dp = -Re(dlambda/dp) / Re(dlambda/dV),
    d omega_f/dp = Im(dlambda/dp) + Im(dlambda/dV) dV_f/dp.

The matrix derivatives come from the element integrals of the derivatives of the section
matrices (:func:`aeroservo.system.assembly.structural_derivative`; the structural matrices are
linear in every parameter offered here, so the derivatives are exact). The divergence speed
``V_d`` solves ``(Ks + rho V_d^2 K_static) q = 0``; with left and right null vectors ``u``, ``q``:
``d(V_d^2)/dp = -u^T (dKs/dp) q / (rho u^T K_static q)``.

All sensitivities together cost one flutter boundary plus two sparse factorizations, whatever
the number of parameters. Where the flutter speed is not differentiable (two branches cross
within ``TIE`` of each other: a mode switch; or a branch that only touches the axis, a hump
whose crossing speed has an infinite slope) the result says so instead of giving a number.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import InputError
from ..system.aeroelastic import AeroelasticModel
from ..system.assembly import STRUCTURAL_PARAMETERS, structural_derivative
from .boundary import flutter_boundary
from .result import FlutterResult

__all__ = ["FlutterSensitivities", "flutter_sensitivities", "parameter_values", "TIE"]

TIE = 1e-3
"""Two onsets closer than this relative speed: a mode switch, not differentiable."""

TOUCH = 1e-5
"""``Re(dlambda/dV) V / |lambda|`` below this: the branch only touches the axis."""


def parameter_values(wing) -> dict[str, tuple[str, tuple[int, ...], str, float]]:
    """Every parameter offered, by its wing-file name, with ``(owner, index, key, value)``."""
    out: dict = {}
    for i, seg in enumerate(wing.segments):
        for key in STRUCTURAL_PARAMETERS["segment"]:
            out[f"segments[{i}].{key}"] = ("segment", (i,), key, float(getattr(seg, key)))
    for k, cs in enumerate(wing.control_surfaces):
        for key in STRUCTURAL_PARAMETERS["surface"]:
            out[f"control_surfaces[{k}].{key}"] = ("surface", (k,), key, float(getattr(cs, key)))
        for j, act in enumerate(cs.actuators):
            name = f"control_surfaces[{k}].actuators[{j}].stiffness"
            out[name] = ("actuator", (k, j), "stiffness", float(act.stiffness))
    return out


@dataclass
class FlutterSensitivities:
    """Derivatives of the flutter speed and frequency and of the divergence speed.

    Attributes
    ----------
    flutter_speed, flutter_frequency, divergence_speed : float or None
        [m/s], [Hz], [m/s] of the analysis the derivatives belong to.
    values : dict
        Parameter name -> its value (wing-file units; ``density`` in kg/m^3).
    d_flutter_speed, d_flutter_frequency, d_divergence_speed : dict
        Parameter name -> derivative [m/s or Hz per unit of the parameter]; empty when the
        speed does not exist or is not differentiable.
    non_differentiable : str or None
        Why the flutter speed has no derivative here (None: it has one).
    density : float
        Air density [kg/m^3].
    """

    flutter_speed: float | None
    flutter_frequency: float | None
    divergence_speed: float | None
    values: dict
    d_flutter_speed: dict = field(default_factory=dict)
    d_flutter_frequency: dict = field(default_factory=dict)
    d_divergence_speed: dict = field(default_factory=dict)
    non_differentiable: str | None = None
    density: float = 1.225

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
            "non_differentiable": self.non_differentiable,
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
    result: FlutterResult | None = None,
    rtol: float = 1e-10,
    **kw,
) -> FlutterSensitivities:
    """Analytic sensitivities of the flutter and divergence speeds (see the module notes).

    Parameters
    ----------
    model : AeroelasticModel
        The wing's model (incompressible; structural damping not yet supported for the
        structural parameters).
    density : float
        Air density [kg/m^3].
    parameters : list of str, optional
        Names as in the wing file (``"segments[0].GJ"``,
        ``"control_surfaces[0].actuators[1].stiffness"``, ``"density"``); default all of
        :func:`parameter_values` and ``density``.
    result : FlutterResult, optional
        The boundary at this density, if already computed (else computed with ``rtol``).
    rtol : float
        Tolerance of the boundary's crossing speeds (tight: the derivative is taken there).
    **kw
        Passed to :func:`aeroservo.flutter_boundary` (``v_max``, ``n_modes``).

    Returns
    -------
    FlutterSensitivities
    """
    if not isinstance(model, AeroelasticModel):
        raise InputError(f"model = {type(model).__name__}: expected an aeroservo.AeroelasticModel")
    if density is None:
        raise InputError("density = None: give the air density [kg/m^3]")
    table = parameter_values(model.wing)
    names = list(table) + ["density"] if parameters is None else _checked(parameters, table)
    if model.damping.active and any(n != "density" for n in names):
        raise InputError(
            f"damping = {model.damping.describe()!r}: sensitivities to structural parameters "
            "are available for undamped models only (for now); density is available"
        )
    r = result if result is not None else flutter_boundary(model, density, rtol=rtol, **kw)
    if r.mach:
        raise InputError(f"mach = {r.mach:g}: sensitivities are for the incompressible model")
    system = model.system(r.density)
    values = {n: (table[n][3] if n != "density" else r.density) for n in names}
    out = FlutterSensitivities(
        r.flutter_speed, r.flutter_frequency, r.divergence_speed, values, density=r.density
    )
    derivs = {n: _matrices(model, table, n) for n in names if n != "density"}
    if r.flutter_speed is not None:
        out.non_differentiable = _tie(r)
        if out.non_differentiable is None:
            _flutter(out, model, system, r, names, derivs)
    if r.divergence_speed is not None:
        _divergence(out, system, r, names, derivs)
    return out


def _checked(parameters: object, table: dict) -> list[str]:
    if isinstance(parameters, str) or not isinstance(parameters, (list, tuple)):
        raise InputError(f"parameters = {parameters!r}: expected a list of parameter names")
    for p in parameters:
        if p != "density" and p not in table:
            raise InputError(
                f"parameters: {p!r} is not a parameter of this wing; known: "
                f"{[*list(table)[:6], '...', 'density']}"
            )
    return list(parameters)


def _matrices(model, table: dict, name: str) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    owner, index, key, _ = table[name]
    return structural_derivative(model.wing, model.mesh, owner, index, key)


def _tie(r: FlutterResult) -> str | None:
    """A reason the flutter speed is not differentiable, or None."""
    vf = r.flutter_speed
    onsets = [c for c in r.crossings if c.kind == "onset"]
    near = [c for c in onsets if c.mode != r.flutter.mode and abs(c.speed - vf) <= TIE * vf]
    if near:
        c = near[0]
        return (
            f"mode switch: branches {r.flutter.mode} and {c.mode} go unstable at {vf:.6g} and "
            f"{c.speed:.6g} m/s (within {TIE:g}); V_f is the smaller of two smooth functions"
        )
    return None


def _eigenpair(system, speed: float, sigma: complex) -> tuple[complex, np.ndarray, np.ndarray]:
    """Eigenvalue near ``sigma`` of the pencil at ``speed`` with right and left vectors, by
    shift-and-invert iteration on sparse factorizations (two shifts)."""
    E = system.E.astype(complex)
    P = system.pencil(speed).astype(complex)
    n = E.shape[0]
    rng = np.random.default_rng(0)
    x = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    y = x.copy()
    lam = sigma
    for its in (6, 4):
        lu = spla.splu((P - lam * E).tocsc())
        for _ in range(its):
            x = lu.solve(E @ x)
            x /= np.linalg.norm(x)
            y = lu.solve(E.conj().T @ y, trans="H")
            y /= np.linalg.norm(y)
        lam = (y.conj() @ (P @ x)) / (y.conj() @ (E @ x))
    res = np.linalg.norm(P @ x - lam * (E @ x)) / max(spla.norm(P, 1), 1.0)
    if res > 1e-8:
        raise RuntimeError(f"flutter eigenpair not converged (residual {res:.1e})")
    return lam, x, y


def _flutter(out, model, system, r: FlutterResult, names, derivs) -> None:
    vf, n_q = r.flutter_speed, system.n_q
    lam, x, y = _eigenpair(system, vf, 2j * np.pi * r.flutter_frequency)
    den = y.conj() @ (system.E @ x)
    dl_dv = (y.conj() @ (system.d_pencil(vf) @ x)) / den
    if dl_dv.real * vf / abs(lam) < TOUCH:
        out.non_differentiable = (
            f"the branch only touches the axis at {vf:.6g} m/s (dRe(lambda)/dV = "
            f"{dl_dv.real:.3g} 1/m): a hump, the flutter speed jumps"
        )
        return
    xq, xv = x[:n_q], x[n_q : 2 * n_q]
    yv = y[n_q : 2 * n_q].conj()
    for name in names:
        if name == "density":  # M = Ms + rho Mnc; the speed terms of the v-rows are x rho
            rows = sp.diags(np.r_[np.zeros(n_q), np.ones(n_q), np.zeros(system.n_states - 2 * n_q)])
            d_pencil = rows @ (vf * system.A1 + vf * vf * system.A2) / r.density
            d_e = yv @ (model.matrices.Mnc @ xv)
            dl = (y.conj() @ (d_pencil @ x) - lam * d_e) / den
        else:
            dM, dK = derivs[name]
            dl = (-(yv @ (dK @ xq)) - lam * (yv @ (dM @ xv))) / den
        dv = -dl.real / dl_dv.real
        out.d_flutter_speed[name] = float(dv)
        out.d_flutter_frequency[name] = float((dl.imag + dl_dv.imag * dv) / (2.0 * np.pi))


def _divergence(out, system, r: FlutterResult, names, derivs) -> None:
    vd, rho = r.divergence_speed, r.density
    K = system.Ks.toarray() + rho * vd * vd * system.K_static
    U, _, Vh = np.linalg.svd(K)
    u, q = U[:, -1], Vh[-1]
    den = rho * (u @ system.K_static @ q)
    for name in names:
        if name == "density":  # rho V_d^2 is fixed
            out.d_divergence_speed[name] = float(-vd / (2.0 * rho))
        else:
            d_mu = -(u @ (derivs[name][1] @ q)) / den
            out.d_divergence_speed[name] = float(d_mu / (2.0 * vd))
