"""One flight point of a gust-loads study: the controller designed once per process
(:func:`design_point`), the model at the point and its tuned discrete gusts and continuous
turbulence, open loop and with the controller (:func:`evaluate_point`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...aero.gust_rules import GRADIENT_RANGE, design_gust_velocity, gust_tas
from ...design.user_code import LawError
from ...errors import InputError, check_derived_speed
from ...linear.tags import carry_tags
from .one_g import one_g_loads
from .rigid_wing import rigid_gust_loads
from .study import FlightPoint, GustLoadsStudy

__all__ = ["PointLoads", "design_point", "evaluate_point", "in_state_basis"]


@dataclass
class PointLoads:
    """The loads at one flight point of one mass case.

    Attributes
    ----------
    point : FlightPoint
    f_g : float
    u_sigma : float
        Design turbulence intensity [m/s TAS] (times F_g; half at V_D, linear between V_C
        and V_D).
    open_loop_stable : bool
    discrete, turbulence : dict
        ``"open"`` / ``"closed"`` -> :class:`~aeroservo.studies.gust.tuned.TunedGustResult` /
        :class:`~aeroservo.studies.gust.turbulence.TurbulenceResult` (a loop is missing when it is
        unstable or absent).
    notes : list of str
        What could not be computed and why.
    one_g : dict
        1 g loads per load (the static aeroelastic trim, :mod:`~aeroservo.studies.gust.one_g`;
        empty without the mass case's airplane mass), and ``trim`` its angle of attack, lift
        and weight.
    rigid : dict
        The rigid clamped wing's quasi-static load in the largest design gust, per root and
        station load (:func:`~aeroservo.studies.gust.rigid_wing.rigid_gust_loads`).
    elapsed : float
        Wall time [s].
    """

    point: FlightPoint
    f_g: float
    u_sigma: float
    open_loop_stable: bool
    discrete: dict = field(default_factory=dict)
    turbulence: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    elapsed: float = 0.0
    rigid: dict = field(default_factory=dict)
    one_g: dict = field(default_factory=dict)
    trim: dict = field(default_factory=dict)


_DESIGNED: dict = {}
"""Controllers designed in this process, by study (a Dask worker designs once per study)."""


def design_point(study: GustLoadsStudy):
    """``(controller, state_scaling)``: the study's controller (a spec designed at the design
    point) and the plant state scaling a state feedback acts in: that of the design point's
    plant (for a state-feedback object too, which must have been designed on the balanced
    states of ``study.loop(design_mass_case, design_density)``); None for output feedback."""
    from ...design.spec import ControllerSpec

    key = id(study)
    if key in _DESIGNED and _DESIGNED[key][0] is study:
        return _DESIGNED[key][1]
    ctrl, scaling = study.controller, None
    if isinstance(ctrl, ControllerSpec):
        from ...stability.boundary import flutter_boundary

        case = study.design_mass_case or next(iter(study.mass_cases))
        loop = study.loop(case, study.design_density)
        vf = flutter_boundary(loop.model, study.design_density).flutter_speed
        speed = study.design_speed
        if speed is None:
            if vf is None or study.design_speed_factor is None:
                raise InputError(
                    "gust loads: the controller's design speed is a multiple of the open-loop "
                    "flutter speed, but the design mass case has no flutter in the searched range"
                )
            f = study.design_speed_factor
            speed = check_derived_speed(
                f"{study.source or 'gust loads'}: flight.speed_factor", f, f * vf,
                f"{f:g} x the open-loop flutter speed {vf:.6g} m/s of the design mass case",
            )  # fmt: skip
        ctrl = loop.design_controller(ctrl, speed, study.sample_rate, vf)
        needs = getattr(ctrl, "needs_state", False) or hasattr(ctrl, "state_map")
        scaling = loop.plant_builder.state_scaling if needs else None
    elif ctrl is not None and getattr(ctrl, "needs_state", False):
        # a state-feedback object acts on the balanced states of the design point's plant
        case = study.design_mass_case or next(iter(study.mass_cases))
        scaling = study.loop(case, study.design_density).plant_builder.state_scaling
    _DESIGNED.clear()
    _DESIGNED[key] = (study, (ctrl, scaling))
    return ctrl, scaling


def in_state_basis(plant, scaling: np.ndarray, reference: np.ndarray | None):
    """``plant`` with its model states rescaled from ``scaling`` to ``reference`` (the basis a
    state-feedback gain was designed in; filter states, appended last, are unscaled)."""
    if reference is None or np.array_equal(scaling, reference):
        return plant
    import control

    n = plant.nstates
    t = np.ones(n)
    t[: scaling.size] = scaling / reference  # x_ref = t x (x_physical = s x)
    sys = control.ss(
        t[:, None] * np.asarray(plant.A) / t[None, :],
        t[:, None] * np.asarray(plant.B),
        np.asarray(plant.C) / t[None, :],
        np.asarray(plant.D),
        inputs=list(plant.input_labels),
        outputs=list(plant.output_labels),
        states=list(plant.state_labels),
    )
    return carry_tags(plant, sys)


def with_control_outputs(sys, controls: list):
    """``sys`` with each control input also an output of the same name (``y = u``): sampled in
    a loop, it is the command applied, whose turbulence RMS is then computed like a load's."""
    if not controls:
        return sys
    import control

    inputs = list(sys.input_labels)
    d_extra = np.zeros((len(controls), len(inputs)))
    for i, c in enumerate(controls):
        d_extra[i, inputs.index(c)] = 1.0
    a, b = np.asarray(sys.A), np.asarray(sys.B)
    c_all = np.vstack([np.asarray(sys.C), np.zeros((len(controls), a.shape[0]))])
    d_all = np.vstack([np.asarray(sys.D), d_extra])
    out = control.ss(
        a,
        b,
        c_all,
        d_all,
        inputs=inputs,
        outputs=list(sys.output_labels) + list(controls),
        states=list(sys.state_labels),
    )
    return carry_tags(sys, out)  # the controls' units are the model's input units


def evaluate_point(study: GustLoadsStudy, point: FlightPoint) -> PointLoads:
    """The open- and closed-loop discrete-gust and turbulence loads at one flight point."""
    import time

    from .tuned import tuned_gust_loads
    from .turbulence import turbulence_response, u_sigma

    t0 = time.perf_counter()
    rho, v = point.density, point.tas
    f_g = study.alleviation_factor(point.altitude)
    loop = study.loop(point.mass_case, rho)
    plant = loop.plant(v)
    plant.density = rho
    lam = np.linalg.eigvals(np.asarray(plant.A))
    factor = study.turbulence_factor(point)
    res = PointLoads(point, f_g, u_sigma(point.altitude, f_g) * factor, bool(lam.real.max() < 0))
    if 0.5 < factor < 1.0:
        res.notes.append(
            f"between V_C and V_D: U_sigma x {factor:.4g} (interpolated, CS-25.341(b)(3)(iii)); "
            "the discrete gusts are those of V_C (25.341(a)(5) gives V_C and V_D only)"
        )
    common = dict(at_vd=point.at_vd, n_gradients=study.n_gradients)
    u_max = gust_tas(
        design_gust_velocity(GRADIENT_RANGE[1], point.altitude, f_g, at_vd=point.at_vd),
        point.altitude,
    )
    res.rigid = rigid_gust_loads(study.mass_cases[point.mass_case], study.loads, rho, v, u_max)
    lift = study.one_g_lift(point.mass_case)
    if lift is not None:
        try:
            res.one_g, res.trim = one_g_loads(loop.model, rho, v, study.loads, lift)
        except InputError as exc:
            res.notes.append(str(exc))
    loops: dict = {"open": None}
    if study.controller is not None:
        ctrl, reference = design_point(study)
        loops["closed"] = (ctrl, reference)
        w_dt = np.pi * v / GRADIENT_RANGE[0] * float(ctrl.dt)  # shortest gust x sample period
        if w_dt > 0.1:
            res.notes.append(
                f"the controller samples at {1 / float(ctrl.dt):.4g} Hz, coarse against the "
                f"shortest gust ({2 * GRADIENT_RANGE[0] / v:.3g} s): the closed loop is marched "
                "and its loads read at that rate, so closed-vs-open differences of a few % are "
                "within its error"
            )
    for name, spec in loops.items():
        if spec is None and not res.open_loop_stable:
            res.notes.append(
                f"open loop unstable at {v:.4g} m/s TAS (max Re(eig) = {lam.real.max():.3g} "
                "1/s): no open-loop loads"
            )
            continue
        sys, kw = plant, {}
        if spec is not None:
            ctrl, reference = spec
            if reference is not None and reference.size != loop.plant_builder.n_states:
                raise InputError(
                    f"mass case {point.mass_case!r}: its model has {loop.plant_builder.n_states}"
                    f" states, the state-feedback controller was designed on {reference.size}"
                    " (another control-surface layout or mesh): a state feedback cannot be "
                    "carried to it; give that mass case the design case's surfaces"
                )
            sys = in_state_basis(plant, loop.plant_builder.state_scaling, reference)
            limits = study.limits or getattr(study.controller, "limits", None)
            kw = dict(controller=ctrl, delay=study.delay)
            try:
                res.discrete[name] = tuned_gust_loads(
                    sys, point.altitude, f_g, limits=limits, **kw, **common
                )
            except LawError:  # a Python law that fails: the study stops
                raise
            except InputError as exc:
                res.notes.append(f"closed loop: {exc}")
                continue
        else:
            res.discrete[name] = tuned_gust_loads(sys, point.altitude, f_g, **common)
        if study.turbulence:
            try:
                tsys, outs = sys, list(study.loads)
                if spec is not None:  # the commands applied are loads too (A-bar of each)
                    extra = [c for c in ctrl.controls if c not in sys.output_labels]
                    tsys = with_control_outputs(sys, extra)
                    outs = list(dict.fromkeys(outs + list(ctrl.controls)))
                res.turbulence[name] = turbulence_response(tsys, outs, **kw)
            except InputError as exc:
                res.notes.append(f"{name} loop turbulence: {exc}")
                continue
            if res.discrete[name].saturated:
                res.notes.append(
                    "closed loop: the tuned gusts drive the actuator to its limits here, but the "
                    "turbulence loads are those of the linear loop (limits not applied): they are "
                    "not valid where the actuator saturates"
                )
    res.elapsed = time.perf_counter() - t0
    return res
