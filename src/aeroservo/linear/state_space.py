"""Linear state-space export for control design (python-control ``StateSpace``, named signals).

The model ``x' = A(V) x + B(V) u``, ``y = C(V) x + D(V) u`` is polynomial in the airspeed V:
every coefficient matrix is computed once per (model, density, inputs, outputs) by
:class:`StateSpaceBuilder`; a model at a speed, or a family over a speed grid, is then a few
matrix additions.

State vector (names in ``sys.state_labels``): structural unknowns q, their rates, the Wagner lag
states ``z<i>_<node>``, the Kussner gust states ``g<i>_b<group>`` (gust model ``"kussner"``)
and the servo states ``<surface>_servo[_rate]`` (commanded-deflection inputs with servo
dynamics). Signals, units and sign conventions: :mod:`aeroservo.linear.signals` and
``docs/statespace.md``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.linalg as sla

from .._threads import blas_limited
from ..aero.indicial import IndicialSet, kussner_set
from ..errors import RANGES, InputError, check_int, check_number
from ..system.first_order import check_mach
from .aero_terms import strip_terms
from .dlm_terms import dlm_terms
from .output_rows import (
    actuator_rows,
    hinge_moment_vector,
    sensor_row,
    surface_mean_row,
    surface_unit,
)
from .polynomial import _dense, _Poly
from .servo import Servo, servos_of
from .signals import Sensor, describe, output_units, resolve_inputs, resolve_outputs
from .tags import system_name, tag

__all__ = ["Servo", "StateSpaceBuilder", "MAX_SPEED", "DENSITIES", "STANDARD_GRAVITY"]

STANDARD_GRAVITY = 9.80665
"""g [m/s^2] of the ``load_factor`` input (ISO 80000-3)."""

MAX_SPEED = RANGES["airspeed"].hi
"""Largest airspeed [m/s] of a state-space model."""
DENSITIES = (RANGES["density"].lo, RANGES["density"].hi)
"""Allowed air densities [kg/m^3] of a state-space model."""
MAX_FAMILY_BYTES = 1 << 30  # largest memory [bytes] of the matrices of a family of models


class StateSpaceBuilder:
    """Speed-independent state-space coefficients of a wing model; models at any speed are cheap.

    Parameters
    ----------
    model : AeroelasticModel
    density : float
        Air density [kg/m^3].
    inputs : sequence of str, optional
        Input names (default: every surface's ``<s>_hinge_moment`` and ``gust``).
    outputs : sequence of str or Sensor, optional
        Output names or sensors (default ``tip_le_accel``, ``tip_te_accel``, ``tip_twist``).
    servo : Servo or dict of Servo, optional
        Servo dynamics of commanded-deflection inputs (per surface name, or one for all);
        default ideal (order 0).
    gust : {"kussner", "upwash"}
        ``"kussner"``: the gust penetrates the chord; Kussner lag states (one set per distinct
        semichord; uniform spanwise gust). ``"upwash"``: the chordwise travel time is neglected
        and the gust acts as a uniform upwash through the Wagner lag states (no extra states).
    kussner : str, mapping or IndicialSet
        Kussner approximation (default Sears & Sparks).
    n_modes : int, optional
        Modal truncation of the structure: keep this many in-vacuo modes (the lag states stay
        complete and consistent with the projected downwash). Default: no truncation.
    mach : float
        Mach number of the Prandtl-Glauert correction (0: incompressible): circulatory and gust
        loads x 1/beta, lag and Kussner rates x beta^2 (:mod:`aeroservo.system.first_order`);
        with the doublet-lattice model, its Mach number.

    Notes
    -----
    The model's structural damping (``model.damping``) is part of the plant; it is not counted
    in the aerodynamic outputs (``<surface>_aero_hinge_moment``).
    """

    @blas_limited
    def __init__(
        self,
        model,
        density: float,
        inputs: Sequence[str] | None = None,
        outputs: Sequence[str | Sensor] | None = None,
        *,
        servo: Servo | dict | None = None,
        gust: str = "kussner",
        kussner: object = "sears_sparks",
        n_modes: int | None = None,
        mach: float = 0.0,
    ):
        from ..system.aeroelastic import AeroelasticModel

        if not isinstance(model, AeroelasticModel):
            raise InputError(f"model = {describe(model)}: expected an aeroservo.AeroelasticModel")
        self.model = model
        self.density = rho = check_number(
            "density", density, unit="kg/m^3", lo=DENSITIES[0], hi=DENSITIES[1]
        )
        if not isinstance(gust, str) or gust not in ("kussner", "upwash"):
            raise InputError(f"gust = {describe(gust)}: allowed values are 'kussner' and 'upwash'")
        self.gust = gust
        self.kussner: IndicialSet = kussner_set(kussner)
        wing = model.wing
        self.inputs = resolve_inputs(wing, inputs)
        n_avail = model.n_dofs if model.dlm is None else model.dlm.n_a  # DLM: its modal basis
        if n_modes is not None:
            n_modes = check_int("n_modes", n_modes, lo=1, hi=n_avail)
        self.outputs = resolve_outputs(model, outputs, n_avail)
        self.servos = servos_of(wing, servo, self.inputs)

        # structural basis: full FE unknowns, a modal truncation, or a doublet-lattice model's
        # modes; the aerodynamic states and forces of either aerodynamic model
        n_need = max([n_modes or 0] + [o.index + 1 for o in self.outputs if o.kind == "modal"])
        modes = model.natural_modes(n_need) if n_need else None
        self.mach = mach = _check_mach(model, mach)
        has_gust = any(d.kind == "gust" for d in self.inputs)
        cuts = tuple(dict.fromkeys(o.node for o in self.outputs if o.kind == "cut"))
        if model.dlm is not None:
            if any(d.kind == "load_factor" for d in self.inputs):
                raise InputError(
                    "input 'load_factor': the wing's weight is modelled with the strip model "
                    "only (aero = 'strip')"
                )
            if cuts:
                raise InputError(
                    "outputs <quantity>_at_<x>: loads along the span need the strip model; "
                    "the doublet-lattice model gives the root loads only"
                )
            terms = dlm_terms(model, rho, mach, n_modes, has_gust, gust)
        else:
            terms = strip_terms(
                model, rho, mach, modes, n_modes, has_gust, gust, self.kussner, cut_nodes=cuts
            )
        self.n_modes = n_modes
        self.basis = basis = terms.basis

        def vec(v: np.ndarray) -> np.ndarray:  # generalized force / row in the used unknowns
            return v if basis is None else basis.T @ v

        system = terms.system
        self.system = system
        self.aero_terms = terms
        n_q = system.n_q
        n_a = terms.A.shape[1]
        n_s = sum(sv.n_states for sv in self.servos.values())
        n = n_a + n_s
        m = len(self.inputs)
        iq, iv = slice(0, n_q), slice(n_q, 2 * n_q)
        self.n_states = n
        n0 = system.n_states

        A = np.zeros((3, n, n))
        B = np.zeros((2, n, m))
        A[:, :n_a, :n_a] = terms.A
        Fa = np.zeros((3, n_q, n))
        Fa[:, :, :n_a] = terms.Fa
        n_r = terms.Fr.shape[1]  # root rows, then those of each cut node
        Fr = np.zeros((3, n_r, n))
        Fr[:, :, :n_a] = terms.Fr
        Fu = np.zeros((2, n_q, m))
        Fru = np.zeros((2, n_r, m))
        col = {d.name: j for j, d in enumerate(self.inputs)}
        if "gust" in col:
            j = col["gust"]
            B[:, :n_a, j] = terms.B_gust
            Fu[:, :, j] = terms.Fu
            Fru[:, :, j] = terms.Fru
        g_states = list(terms.gust_labels)
        if "load_factor" in col:  # n g downward on every mass: -g n (M r) on every row
            j = col["load_factor"]
            B[0, iv, j] = -STANDARD_GRAVITY * terms.weight
            Fru[0, :, j] = -STANDARD_GRAVITY * terms.root_weight

        # control inputs and servo states
        s_next = n_a
        servo_states: list[str] = []
        self._servo_index: dict[int, int] = {}
        for d in self.inputs:
            j = col[d.name]
            k = d.surface
            if d.kind == "hinge_moment":
                B[0, iv, j] += vec(hinge_moment_vector(model, k))
            elif d.kind == "element":  # a moment at one actuator (a nonlinear hinge's)
                B[0, iv, j] += vec(actuator_rows(model, k)[d.actuator][1])
            elif d.kind == "command":
                force = vec(sum(ka * r for ka, r in actuator_rows(model, k)))
                sv = self.servos[k]
                name = model.wing.control_surfaces[k].name
                if sv.order == 0:
                    B[0, iv, j] += force
                else:
                    y = s_next
                    self._servo_index[k] = y
                    A[0, iv, y] += force
                    w = sv.bandwidth
                    if sv.order == 1:
                        A[0, y, y] = -w
                        B[0, y, j] = w
                        servo_states.append(f"{name}_servo")
                    else:
                        A[0, y, y + 1] = 1.0
                        A[0, y + 1, y] = -w * w
                        A[0, y + 1, y + 1] = -2 * sv.damping * w
                        B[0, y + 1, j] = w * w
                        servo_states += [f"{name}_servo", f"{name}_servo_rate"]
                    s_next += sv.order

        # E^-1 applied once: A(V) = sum V^k Abar_k
        einv = np.eye(n)
        einv[:n0, :n0] = _block_inverse_dense(system, n0)
        self._A = _Poly(A).left(einv)
        self._B = _Poly(B).left(einv)
        acc_x = _Poly(self._A.c[:, iv, :])  # qdd = acc_x x + acc_u u
        acc_u = _Poly(self._B.c[:, iv, :])

        # outputs: y = Cx x + Du u + Cacc qdd
        p = len(self.outputs)
        Cx = np.zeros((3, p, n))
        Du = np.zeros((2, p, m))
        Cacc = np.zeros((p, n_q))
        mnc = terms.mnc
        for i, o in enumerate(self.outputs):
            if o.kind == "sensor":
                row = vec(sensor_row(model, o.sensor))
                q = o.sensor.quantity
                if q in ("displacement", "twist"):
                    Cx[0, i, iq] = row
                elif q in ("velocity", "twist_rate"):
                    Cx[0, i, iv] = row
                else:
                    Cacc[i] = row
            elif o.kind == "deflection":
                Cx[0, i, iq] = vec(surface_mean_row(model, o.surface))
            elif o.kind in ("actuator_rotation", "actuator_rotation_rate"):
                rows = iq if o.kind == "actuator_rotation" else iv
                Cx[0, i, rows] = vec(actuator_rows(model, o.surface)[o.index][1])
            elif o.kind == "rate":
                Cx[0, i, iv] = vec(surface_mean_row(model, o.surface))
            elif o.kind == "modal":
                Cx[0, i, iq] = vec(_dense(model.matrices.Ms) @ modes.shapes[:, o.index])
            elif o.kind == "aero_hinge_moment":
                e = vec(surface_unit(model, o.surface))
                Cx[:, i, :] = np.einsum("j,kjl->kl", e, Fa)
                Du[:, i, :] = np.einsum("j,kjl->kl", e, Fu)
                Cacc[i] = -rho * (e @ mnc)
            elif o.kind == "actuator_moment":
                k = o.surface
                for ka, r in actuator_rows(model, k):
                    Cx[0, i, iq] -= ka * vec(r)
                k_tot = sum(ka for ka, _ in actuator_rows(model, k))
                for d in self.inputs:
                    if d.surface != k:
                        continue
                    if d.kind in ("hinge_moment", "element"):
                        Du[0, i, col[d.name]] = 1.0
                    elif d.kind == "command" and self.servos[k].order == 0:
                        Du[0, i, col[d.name]] = k_tot
                    elif d.kind == "command":
                        Cx[0, i, self._servo_index[k]] = k_tot
            elif o.kind in ("root", "cut"):
                r = o.index if o.kind == "root" else 3 + 3 * cuts.index(o.node) + o.index
                Cx[:, i, :] = Fr[:, r, :]
                Cx[0, i, iq] -= terms.root_Ks[r]
                Du[:, i, :] = Fru[:, r, :]
                Cacc[i] = -terms.root_Ms[r] - rho * terms.root_mnc[r]
        self._C = _Poly(Cx) + acc_x.left(Cacc)
        self._D = _Poly(Du) + acc_u.left(Cacc)

        self.state_labels = tuple(system.state_labels) + tuple(g_states) + tuple(servo_states)
        self.input_labels = tuple(d.name for d in self.inputs)
        self.output_labels = tuple(d.name for d in self.outputs)
        self.units = {d.name: d.unit for d in self.inputs} | output_units(self.outputs)
        self._scaling: np.ndarray | None = None

    def matrices(self, speed: float, *, balanced: bool = False) -> tuple[np.ndarray, ...]:
        """``(A, B, C, D)`` at ``speed`` [m/s] (``balanced``: the states of :meth:`at`)."""
        v = check_number("speed", speed, unit="m/s", lo=0.0, hi=MAX_SPEED)
        A, B, C, D = self._A(v), self._B(v), self._C(v), self._D(v)
        if balanced:
            s = self.state_scaling
            A, B, C = A * (1.0 / s)[:, None] * s[None, :], B / s[:, None], C * s[None, :]
        return A, B, C, D

    @property
    def state_scaling(self) -> np.ndarray:
        """Diagonal state scaling ``s`` of the balanced models: ``x_physical = s * x``.

        Powers of two (exact), from :func:`scipy.linalg.matrix_balance` of the state matrix at
        a reference speed (twice the semichord times the second frequency at rest), the same
        at every speed, so that a family of models shares one state basis.
        """
        if self._scaling is None:
            lam, _ = self.system.modes_at_rest(min(2, self.system.n_q))
            v_ref = 2.0 * self.model.semichord * float(np.abs(lam[-1]))
            A = self._A(v_ref)
            _, (scale, _perm) = sla.matrix_balance(A, permute=False, separate=True)
            self._scaling = np.asarray(scale, dtype=float)
        return self._scaling

    def at(self, speed: float, *, balanced: bool = True):
        """``control.StateSpace`` at ``speed`` [m/s], with named signals.

        Parameters
        ----------
        speed : float
            [m/s]
        balanced : bool
            True (default): the states scaled by :attr:`state_scaling` (the same transfer
            function, state names kept, entries of A within a few decades instead of 1e10:
            frequency responses and controller syntheses on it are accurate); False: the
            physical states (metres, radians, their rates, the lag states), as needed to set
            initial states such as :func:`aeroservo.linear.models.tip_deflection_state`.

        Returns
        -------
        control.StateSpace
            With attributes ``speed`` [m/s], ``density`` [kg/m^3], ``signal_units`` (dict) and
            ``state_scaling`` (``x_physical = state_scaling * x``; ones when not balanced).
        """
        import control

        if not isinstance(balanced, (bool, np.bool_)):
            raise InputError(f"balanced = {describe(balanced)}: expected True or False")
        A, B, C, D = self.matrices(speed, balanced=balanced)
        s = self.state_scaling if balanced else np.ones(A.shape[0])
        sys = control.StateSpace(
            A,
            B,
            C,
            D,
            states=list(self.state_labels),
            inputs=list(self.input_labels),
            outputs=list(self.output_labels),
            name=system_name(self.model.wing.name, float(speed)),
        )
        tag(sys, float(speed), self.density, self.units)
        sys.state_scaling = s
        return sys

    def family(self, speeds: Sequence[float], *, balanced: bool = True) -> list:
        """Models at every speed of a grid [m/s] (no re-assembly; one state scaling)."""
        if not (isinstance(speeds, (list, tuple, range)) or getattr(speeds, "ndim", 0) == 1):
            raise InputError(f"speeds = {describe(speeds)}: expected a sequence of speeds [m/s]")
        if len(speeds) == 0:
            raise InputError("speeds = []: give at least one speed [m/s]")
        n, k = self.n_states, len(speeds)
        gib = 8 * k * (n + len(self.outputs)) * (n + len(self.inputs)) / 2**30
        if gib > MAX_FAMILY_BYTES / 2**30:
            raise InputError(
                f"speeds: {k} models of {n} states need {gib:.3g} GiB, above the limit of "
                f"{MAX_FAMILY_BYTES / 2**30:g} GiB; use fewer speeds"
            )
        vs = [
            check_number(f"speeds[{i}]", v, unit="m/s", lo=0.0, hi=MAX_SPEED)
            for i, v in enumerate(speeds)
        ]
        return [self.at(v, balanced=balanced) for v in vs]


def _check_mach(model, mach: object) -> float:
    """The Mach number of a model: Prandtl-Glauert's for strip theory, the doublet lattice's."""
    if getattr(model, "dlm", None) is not None:
        from ..aero.dlm import check_dlm_mach

        return check_dlm_mach(mach)
    return check_mach(mach)


def _block_inverse_dense(system, n0: int) -> np.ndarray:
    from ..system.first_order import _block_inverse

    return _block_inverse(system.E, system.n_q)[:n0, :n0]
