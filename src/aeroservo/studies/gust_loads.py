"""Gust loads of CS-25.341 over flight points and mass cases, with and without the loop.

A :class:`GustLoadsStudy` names the wing of each mass case, the flight points (pressure altitude,
equivalent airspeed, V_C or V_D), the loads (outputs of the model), the flight profile
alleviation factor and, optionally, a controller (a :class:`~aeroservo.design.ControllerSpec`
designed once at the design point, or any controller object). Each flight point of each mass
case is one task (:func:`evaluate_point`): the model at the ISA density of the altitude and the
true airspeed of the EAS, the tuned discrete gusts of CS-25.341(a)
(:func:`~aeroservo.studies.tuned_gusts.tuned_gust_loads`) and the continuous turbulence of
CS-25.341(b) (:func:`~aeroservo.studies.turbulence.turbulence_response`), open loop and with the
controller. :func:`run_gust_loads` runs the tasks in this process or on Dask.

The strip model is a cantilever wing clamped at the root: no rigid-body modes, no 1 g load;
every load is the increment of the clamped wing (``docs/gust-loads.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..aero.atmosphere import isa, tas_from_eas
from ..aero.gust_rules import GRADIENT_RANGE, flight_profile_alleviation
from ..errors import InputError, check_int, check_number
from ..system.damping import NO_DAMPING, StructuralDamping

__all__ = ["FlightPoint", "GustLoadsStudy", "PointLoads", "evaluate_point", "design_point"]

SPEED_NAMES = ("V_C", "V_D", "")


@dataclass(frozen=True)
class FlightPoint:
    """One flight point of a gust-loads study.

    Parameters
    ----------
    altitude : float
        Pressure altitude [m] (ISA density, U_ref, U_sigma, F_g).
    speed : float
        Equivalent airspeed [m/s].
    speed_name : str
        ``"V_C"``, ``"V_D"`` (the rule's gust velocities halved) or ``""``.
    mass_case : str
        Name of the mass case (a key of :attr:`GustLoadsStudy.mass_cases`).
    """

    altitude: float
    speed: float
    speed_name: str = "V_C"
    mass_case: str = ""

    def __post_init__(self) -> None:
        check_number("flight point altitude", self.altitude, unit="m", lo=0.0, hi=18288.0)
        check_number("flight point speed (EAS)", self.speed, unit="m/s", lo=0.0, lo_open=True)
        if self.speed_name not in SPEED_NAMES:
            raise InputError(
                f"flight point speed_name = {self.speed_name!r}: expected one of {SPEED_NAMES}"
            )

    @property
    def at_vd(self) -> bool:
        """True at the design dive speed (half the rule's gust velocities)."""
        return self.speed_name == "V_D"

    @property
    def density(self) -> float:
        """ISA density [kg/m^3]."""
        return isa(self.altitude).density

    @property
    def tas(self) -> float:
        """True airspeed [m/s]."""
        return tas_from_eas(self.speed, self.density)

    @property
    def label(self) -> str:
        """E.g. ``"MTOW 3000 m V_C 120 m/s EAS"``."""
        name = f" {self.speed_name}" if self.speed_name else ""
        case = f"{self.mass_case} " if self.mass_case else ""
        return f"{case}{self.altitude:g} m{name} {self.speed:g} m/s EAS"


@dataclass(frozen=True)
class GustLoadsStudy:
    """What a gust-loads study computes (SI units). See the module docstring.

    Attributes
    ----------
    mass_cases : dict
        Mass case name -> :class:`~aeroservo.structure.Wing`.
    points : tuple of FlightPoint
    loads : tuple of str
        Outputs of the model that are loads (and any user output).
    controls, sensors : tuple of str
        The controller's controls and sensors (empty: open loop only).
    outputs : tuple of str
        Further outputs of the model the controller needs (those its weights name); they are
        in the time histories, not in the load tables.
    controller : object
        None (open loop only), a :class:`~aeroservo.design.ControllerSpec` designed at the
        design point, or any controller :func:`aeroservo.design.as_controller` accepts.
    design_mass_case, design_density, design_speed : str, float, float
        Where a spec is designed: mass case, density [kg/m^3] and true airspeed [m/s] (or
        ``design_speed_factor`` x the open-loop flutter speed there).
    limits : aeroservo.design.Limits or None
        Actuator limits of the closed loop (default: those of a spec; none for an object).
    f_g : float or None
        Flight profile alleviation factor; None: from ``weights`` at each altitude.
    weights : dict
        ``mlw, mzfw, mtow`` [kg] and ``z_mo`` [m] of CS-25.341(a)(6).
    aero : {"strip", "dlm"}, DoubletLattice or None
        Aerodynamic model of every mass case (None: strip theory; the doublet lattice at
        Mach 0, as the control loop is built).
    """

    mass_cases: dict
    points: tuple
    loads: tuple
    controls: tuple = ()
    sensors: tuple = ()
    outputs: tuple = ()
    controller: object = None
    design_mass_case: str = ""
    design_density: float = 1.225
    design_speed: float | None = None
    design_speed_factor: float | None = None
    limits: object = None
    f_g: float | None = 1.0
    weights: dict = field(default_factory=dict)
    elements: int = 10
    wagner: object = "rt_jones"
    damping: StructuralDamping = NO_DAMPING
    gust_model: str = "kussner"
    design_modes: int | None = 8
    sensor_filter: float | None = 30.0
    filter_order: int = 2
    sample_rate: float = 1000.0
    delay: bool = False
    n_gradients: int = 20
    turbulence: bool = True
    name: str = "gust_loads"
    aero: object = None

    def __post_init__(self) -> None:
        from ..aero.dlm_settings import as_aero

        object.__setattr__(self, "aero", as_aero(self.aero))
        if not self.mass_cases:
            raise InputError("gust loads: give at least one mass case (a wing)")
        if not self.points:
            raise InputError("gust loads: give at least one flight point")
        for p in self.points:
            if p.mass_case not in self.mass_cases:
                raise InputError(
                    f"flight point {p.label}: mass_case = {p.mass_case!r} is not one of "
                    f"{list(self.mass_cases)}"
                )
        if not self.loads:
            raise InputError("gust loads: name at least one load (an output of the model)")
        if self.controller is not None and not self.controls:
            raise InputError("gust loads: a controller needs its controls (signals.controls)")
        check_int("n_gradients", self.n_gradients, lo=3)
        if self.f_g is None:
            w = self.weights
            for k in ("mlw", "mzfw", "mtow", "z_mo"):
                if k not in w:
                    raise InputError(f"gust loads: F_g from the weights needs {k!r}")
        else:
            check_number("f_g", self.f_g, lo=0.0, lo_open=True, hi=1.0)

    def alleviation_factor(self, altitude: float) -> float:
        """F_g at ``altitude`` [m] (CS-25.341(a)(6))."""
        if self.f_g is not None:
            return float(self.f_g)
        w = self.weights
        return flight_profile_alleviation(w["mlw"], w["mzfw"], w["mtow"], w["z_mo"], altitude)

    def model(self, mass_case: str):
        """The aeroelastic model of a mass case."""
        from ..system.aeroelastic import AeroelasticModel

        wing = self.mass_cases[mass_case]
        aero = "strip" if self.aero is None else self.aero
        return AeroelasticModel(wing, self.elements, self.wagner, damping=self.damping, aero=aero)

    def loop(self, mass_case: str, density: float):
        """The :class:`~aeroservo.design.loop.ControlLoop` (or, open loop only, a plain builder
        with the gust input) of a mass case at ``density``."""
        from ..design.loop import ControlLoop

        return ControlLoop(
            self.model(mass_case),
            density,
            self.controls or ("gust",),
            self.sensors,
            tuple(dict.fromkeys(self.loads + tuple(self.outputs))),
            design_modes=self.design_modes if self.controller is not None else None,
            sensor_filter=self.sensor_filter,
            filter_order=self.filter_order,
            gust=self.gust_model,
        )


@dataclass
class PointLoads:
    """The loads at one flight point of one mass case.

    Attributes
    ----------
    point : FlightPoint
    f_g : float
    u_sigma : float
        Design turbulence intensity [m/s TAS] (times F_g; half at V_D).
    open_loop_stable : bool
    discrete, turbulence : dict
        ``"open"`` / ``"closed"`` -> :class:`~aeroservo.studies.tuned_gusts.TunedGustResult` /
        :class:`~aeroservo.studies.turbulence.TurbulenceResult` (a loop is missing when it is
        unstable or absent).
    notes : list of str
        What could not be computed and why.
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


_DESIGNED: dict = {}
"""Controllers designed in this process, by study (a Dask worker designs once per study)."""


def design_point(study: GustLoadsStudy):
    """``(controller, state_scaling)``: the study's controller (a spec designed at the design
    point) and the plant state scaling a state feedback acts in: that of the design point's
    plant (for a state-feedback object too, which must have been designed on the balanced
    states of ``study.loop(design_mass_case, design_density)``); None for output feedback."""
    from ..design.spec import ControllerSpec

    key = id(study)
    if key in _DESIGNED and _DESIGNED[key][0] is study:
        return _DESIGNED[key][1]
    ctrl, scaling = study.controller, None
    if isinstance(ctrl, ControllerSpec):
        from ..stability.boundary import flutter_boundary

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
            speed = study.design_speed_factor * vf
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
    for k in ("speed", "density", "signal_units"):
        if hasattr(plant, k):
            setattr(sys, k, getattr(plant, k))
    return sys


def evaluate_point(study: GustLoadsStudy, point: FlightPoint) -> PointLoads:
    """The open- and closed-loop discrete-gust and turbulence loads at one flight point."""
    import time

    from .tuned_gusts import tuned_gust_loads
    from .turbulence import turbulence_response, u_sigma

    t0 = time.perf_counter()
    rho, v = point.density, point.tas
    f_g = study.alleviation_factor(point.altitude)
    loop = study.loop(point.mass_case, rho)
    plant = loop.plant(v)
    plant.density = rho
    lam = np.linalg.eigvals(np.asarray(plant.A))
    res = PointLoads(
        point, f_g, u_sigma(point.altitude, f_g, at_vd=point.at_vd), bool(lam.real.max() < 0)
    )
    common = dict(at_vd=point.at_vd, n_gradients=study.n_gradients)
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
            except InputError as exc:
                res.notes.append(f"closed loop: {exc}")
                continue
        else:
            res.discrete[name] = tuned_gust_loads(sys, point.altitude, f_g, **common)
        if study.turbulence:
            try:
                res.turbulence[name] = turbulence_response(sys, list(study.loads), **kw)
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
