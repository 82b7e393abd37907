"""The eigenvalue and null-vector derivatives behind :mod:`aeroservo.stability.sensitivity`.

One :class:`Terms` holds, for one analysis, the derivative of the matrices in every parameter
(:mod:`aeroservo.system.derivatives`), and turns them into flutter and divergence speed
derivatives with the eigenvectors at the crossing (formulas in the module notes of
:mod:`aeroservo.stability.sensitivity`). The partial derivatives in the Mach number (the
Prandtl-Glauert factors of the pencil) are taken by a complex step of the pencil's scalar
factors, exact to rounding.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..aero.atmosphere import isa, isa_slopes, on_layer_boundary
from ..system.damping import damping_derivatives
from ..system.derivatives import matrix_derivative, station_kink, zero_derivative
from ..system.first_order import pencil_blocks
from ..system.pencil_forms import pencil_form, static_form

__all__ = ["Terms"]

MACH_STEP = 1e-20
"""Complex step in the Mach number (exact to rounding for any small value)."""


class Terms:
    """Matrix derivatives of the parameters of one analysis, and the speed derivatives."""

    def __init__(self, model, result, matched: bool):
        self.model, self.r, self.matched = model, result, matched
        self.rho, self.mach = result.density, result.mach
        self.am = model.matrices
        self.items: dict[str, list] = {}  # name -> matrix derivatives (two for a kink)
        self.kinks: dict[str, tuple[str, tuple[str, ...]]] = {}  # name -> (why, sides)
        self.damping = (
            damping_derivatives(model.damping, self.am.Ms, self.am.Ks, self.am.dof_labels)
            if model.damping.active
            else None
        )
        self.a = result.speed_of_sound
        self.slopes = []  # (drho/dH, da/dH) of the layer, or below and above a layer's top
        if result.altitude is not None:
            atm = isa(result.altitude)
            self.slopes = [isa_slopes(atm, -1)]
            if on_layer_boundary(result.altitude):
                self.slopes.append(isa_slopes(atm, 1))
                self.kinks["altitude"] = (
                    "at the top of an atmosphere layer (the lapse rate changes): density and "
                    "speed of sound have kinks",
                    ("below", "above"),
                )

    # ---- parameters -------------------------------------------------------------------------
    def add(self, name: str, entry) -> str | None:
        """Register a parameter (``entry``: its row of the wing table, None for the others);
        returns why it has no derivative, if so."""
        if name in ("density", "altitude", "mach"):
            self.items[name] = [name]
            return None
        m = self.model
        if entry is None:  # a damping parameter
            self.items[name] = [replace(zero_derivative(m.mesh), Cs=self.damping[1](name))]
            return None
        owner, index, key, _ = entry
        sides = [1]
        where, inward, why = (
            station_kink(m.wing, m.mesh, owner, index) if key == "station" else (None, 1, "")
        )
        if where == "node":
            sides = [-1, 1]
            self.kinks[name] = (why, ("inboard", "outboard"))
        elif where == "edge":  # the station may only move inwards (into its surface, the span)
            sides = [inward]
            self.kinks[name] = (why, ("inward",))
        elif where == "jump":
            return why
        mats = []
        for side in sides:
            dam = matrix_derivative(
                m.wing, m.mesh, owner, index, key, side=side, sweep_terms=m.sweep_terms
            )
            if self.damping is not None:
                try:
                    dam = replace(dam, Cs=self.damping[0](dam.Ms, dam.Ks))
                except ValueError as exc:
                    return str(exc)
            mats.append(dam)
        self.items[name] = mats
        return None

    def _aero_only(self):
        """The matrices that the density multiplies (``d/drho`` of the pencil at rho = 1)."""
        am, z = self.am, zero_derivative(self.model.mesh)
        return replace(am, Ms=z.Ms, Ks=z.Ks, Cs=None, Mz1=z.Mz1, Lz1=z.Lz1, E1=z.E1, F1=z.F1)

    # ---- flutter ------------------------------------------------------------------------------
    def flutter(self, out, touch: float) -> str | None:
        """Fill the flutter derivatives of ``out``; return why there are none, if so."""
        r, system = self.r, self.model.system(self.rho, self.mach)
        vf = r.flutter_speed
        lam, x, y = _eigenpair(system, vf, 2j * np.pi * r.flutter_frequency)
        den = y.conj() @ (system.E @ x)

        wagner = self.model.wagner

        def of(blocks):
            e, a0, a1, a2 = (blocks[k] for k in ("E", "A0", "A1", "A2"))
            yh = y.conj()
            return (yh @ ((a0 + vf * a1 + vf * vf * a2) @ x) - lam * (yh @ (e @ x))) / den

        def form(dam, rho=self.rho):
            return pencil_form(dam, wagner, rho, self.mach, y, x, vf, lam) / den

        dl_dv = (y.conj() @ (system.d_pencil(vf) @ x)) / den
        dl_dm = None
        if self.matched or "mach" in self.items:
            dl_dm = of(self._mach_blocks(self.mach))
        if self.matched:
            dl_dv = dl_dv + dl_dm / self.a
        if dl_dv.real * vf / abs(lam) < touch:
            return (
                f"the branch only touches the axis at {vf:.6g} m/s (dRe(lambda)/dV = "
                f"{dl_dv.real:.3g} 1/m): a hump, the flutter speed jumps"
            )
        dl_drho = None
        for name, mats in self.items.items():
            if name in ("density", "altitude"):
                if dl_drho is None:
                    dl_drho = form(self._aero_only(), 1.0)
                d = [dl_drho]
                if name == "altitude":
                    d = [
                        dl_drho * drho + (dl_dm * (-vf * da / self.a**2) if self.matched else 0)
                        for drho, da in self.slopes
                    ]
            elif name == "mach":
                d = [dl_dm]
            else:
                d = [form(dam) for dam in mats]
            dv = [-v.real / dl_dv.real for v in d]
            if name in self.kinks:
                self._one_sided(out, name, "dV_f", dv)
                continue
            out.d_flutter_speed[name] = float(dv[0])
            out.d_flutter_frequency[name] = float((d[0].imag + dl_dv.imag * dv[0]) / (2 * np.pi))
        return None

    def _mach_blocks(self, mach: float) -> dict:
        """``d/dM`` of the pencil at fixed speed and density (complex step)."""
        b = pencil_blocks(self.am, self.model.wagner, self.rho, mach + 1j * MACH_STEP)
        return {k: b[k].imag / MACH_STEP for k in ("E", "A0", "A1", "A2")}

    # ---- divergence ---------------------------------------------------------------------------
    def divergence(self, out) -> None:
        """Fill the divergence derivatives of ``out``."""
        vd, rho = self.r.divergence_speed, self.rho
        mach = vd / self.a if self.matched else self.mach
        base = pencil_blocks(self.am, self.model.wagner, rho, mach)
        k_st = _static_of(base)
        F = self.am.Ks.toarray() + rho * vd * vd * k_st
        U, _, Vh = np.linalg.svd(F)
        u, q = U[:, -1], Vh[-1]
        lam = base["Lam"].toarray()
        av = np.linalg.solve(lam, base["Ez"] @ q)
        bv = np.linalg.solve(lam.T, base["Dz"].T @ u)
        static = u @ k_st @ q
        dk_dm = None
        if self.matched or "mach" in self.items:
            c = _static(self.am, self.model.wagner, rho, mach + 1j * MACH_STEP)
            dk_dm = u @ (c.imag / MACH_STEP) @ q
        df_dv = 2 * rho * vd * static + (rho * vd * vd * dk_dm / self.a if self.matched else 0.0)
        for name, mats in self.items.items():
            if name == "density":
                g = [vd * vd * static]
            elif name == "altitude":
                g = [
                    drho * vd * vd * static
                    + (rho * vd * vd * dk_dm * (-vd * da / self.a**2) if self.matched else 0.0)
                    for drho, da in self.slopes
                ]
            elif name == "mach":
                g = [rho * vd * vd * dk_dm]
            else:
                g = [
                    u @ (dam.Ks @ q)
                    + rho * vd * vd * static_form(dam, self.model.wagner, mach, u, q, av, bv)
                    for dam in mats
                ]
            dv = [-float(v) / df_dv for v in g]
            if name in self.kinks:
                self._one_sided(out, name, "dV_d", dv)
            else:
                out.d_divergence_speed[name] = float(dv[0])

    def _one_sided(self, out, name: str, what: str, dv: list) -> None:
        why, sides = self.kinks[name]
        text = f"{what}/dp = " + ", ".join(f"{v:.6g} {s}" for v, s in zip(dv, sides, strict=True))
        out.undefined[name] = f"{out.undefined.get(name, why)}; {text}"


def _static(am, wagner, rho: float, mach) -> np.ndarray:
    """``K_static = Ka - Dz Lam^-1 Ez`` (dense) at a Mach number (complex: a complex step)."""
    return _static_of(pencil_blocks(am, wagner, rho, mach))


def _static_of(b: dict) -> np.ndarray:
    """``K_static`` of the pencil blocks ``b``."""
    lam = b["Lam"].toarray()
    return b["Ka"].toarray() - b["Dz"].toarray() @ np.linalg.solve(lam, b["Ez"].toarray())


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
        lu = spla.splu(sp.csc_matrix(P - lam * E))
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
