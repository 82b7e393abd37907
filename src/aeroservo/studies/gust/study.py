"""Gust loads of CS-25.341 over flight points and mass cases, with and without the loop.

A :class:`GustLoadsStudy` names the wing of each mass case, the flight points (pressure altitude,
equivalent airspeed, V_C, V_D or a speed between them), the loads (outputs of the model, and
the shear, bending moment and torque at each load station), the flight profile alleviation
factor and, optionally, a controller (a :class:`~aeroservo.design.ControllerSpec` designed once
at the design point, or any controller object). Each flight point of each mass case is one task
(:func:`~aeroservo.studies.gust.point.evaluate_point`): the model at the ISA density of the
altitude and the true airspeed of the EAS, the tuned discrete gusts of CS-25.341(a)
(:func:`~aeroservo.studies.gust.tuned.tuned_gust_loads`) and the continuous turbulence of
CS-25.341(b) (:func:`~aeroservo.studies.gust.turbulence.turbulence_response`), open loop and
with the controller. :func:`~aeroservo.studies.gust.run.run_gust_loads` runs the tasks in this
process or on Dask.

The strip model is a cantilever wing clamped at the root: no rigid-body modes; every gust load
is the increment of the clamped wing, and the 1 g loads are added when ``aircraft_mass`` is
given (``docs/gust-loads.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ...aero.atmosphere import isa, tas_from_eas
from ...aero.gust_rules import flight_profile_alleviation
from ...errors import InputError, check_int, check_number
from ...system.damping import NO_DAMPING, StructuralDamping

__all__ = ["FlightPoint", "GustLoadsStudy", "SPEED_NAMES"]

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


def speed_order(points, v_c: float | None, v_d: float | None) -> tuple[int, str] | None:
    """The first flight point whose named speed is out of order, as ``(index, why)``: V_D is
    not below V_C, so a point named ``V_D`` must not fly slower than ``v_c`` nor than a point
    named ``V_C`` at its altitude (V_C and V_D may change with altitude, e.g. above a Mach
    limit; the same speed is allowed, to compare the rule's gusts there), and a point named
    ``V_C`` not faster than ``v_d``. None when all are in order."""
    vc_at: dict = {}
    for p in points:
        if p.speed_name == "V_C":
            vc_at[p.altitude] = max(vc_at.get(p.altitude, 0.0), p.speed)
    for i, p in enumerate(points):
        if p.speed_name == "V_D" and v_c is not None and p.speed < v_c:
            return i, f"the point is named V_D, but v_c = {v_c:g} m/s EAS (V_D is not below V_C)"
        if p.speed_name == "V_D" and p.speed < vc_at.get(p.altitude, 0.0):
            return i, (
                f"the point is named V_D, but a point named V_C at the same altitude "
                f"({p.altitude:g} m) flies at {vc_at[p.altitude]:g} m/s EAS (V_D is not below V_C)"
            )
        if p.speed_name == "V_C" and v_d is not None and p.speed > v_d:
            return i, f"the point is named V_C, but v_d = {v_d:g} m/s EAS (V_C is not above V_D)"
    return None


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
    load_stations : tuple of float
        Spanwise stations [m] with loads: every mass case's mesh gets a node there and its
        shear, bending moment and torque (``shear_at_<x>mm``, ...) join ``loads``.
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
        Actuator limits of the closed loop (default: those of a spec; none for an object): on the
        actuator output where ``actuator`` gives one.
    delay : bool
        One-sample computational delay of the closed loop (default on).
    actuator : ActuatorDynamics, dict of ActuatorDynamics or None
        Actuator dynamics in series with the controls (:mod:`aeroservo.design.actuator`).
    f_g : float or None
        Flight profile alleviation factor; None: from ``weights`` at each altitude.
    weights : dict
        ``mlw, mzfw, mtow`` [kg] and ``z_mo`` [m] of CS-25.341(a)(6).
    aero : {"strip", "dlm"}, DoubletLattice or None
        Aerodynamic model of every mass case (None: strip theory; the doublet lattice at
        Mach 0, as the control loop is built).
    aircraft_mass : dict
        Mass case name -> the airplane's mass [kg] in it: that case gets its 1 g loads from
        the wing's static aeroelastic trim to carry ``lift_share`` of the weight
        (:mod:`~aeroservo.studies.gust.one_g`), and total limit loads 1 g +- increment.
    lift_share : float
        Share of the airplane's weight the wing carries in 1 g flight (0.5: one of two wings).
    source : str
        The scenario file it comes from, named in messages (empty: none).
    v_c, v_d : float or None
        Design cruising and dive speeds [m/s EAS]. With both, a flight point named ``""``
        between them gets U_sigma interpolated linearly between its V_C and V_D values
        (CS-25.341(b)(3)(iii)) and the discrete gust of V_C (25.341(a)(5) gives V_C and V_D
        only; the V_C gust is the larger); a point named ``V_C`` or ``V_D`` must fly at it.
    """

    mass_cases: dict
    points: tuple
    loads: tuple
    load_stations: tuple = ()
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
    delay: bool = True
    actuator: object = None
    n_gradients: int = 20
    turbulence: bool = True
    name: str = "gust_loads"
    aero: object = None
    v_c: float | None = None
    v_d: float | None = None
    aircraft_mass: dict = field(default_factory=dict)
    lift_share: float = 0.5
    source: str = ""

    def __post_init__(self) -> None:
        from ...aero.dlm_settings import as_aero

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
        from ...linear.signals import STATION_QUANTITIES, station_output

        stations = tuple(sorted({float(x) for x in self.load_stations}))
        close = [(a, b) for a, b in zip(stations[:-1], stations[1:], strict=True) if b - a < 2e-3]
        if close:
            a, b = close[0]
            raise InputError(
                f"load_stations: {a:g} m and {b:g} m are closer than 2 mm (their loads are named "
                "to the millimetre); keep one"
            )
        object.__setattr__(self, "load_stations", stations)
        extra = [station_output(q, x) for x in stations for q in STATION_QUANTITIES]
        object.__setattr__(self, "loads", tuple(dict.fromkeys(tuple(self.loads) + tuple(extra))))
        if not self.loads:
            raise InputError("gust loads: name at least one load (an output of the model)")
        if self.controller is not None and not self.controls:
            raise InputError("gust loads: a controller needs its controls (signals.controls)")
        check_int("n_gradients", self.n_gradients, lo=3)
        self._check_design_speeds()
        for case, mass in self.aircraft_mass.items():
            if case not in self.mass_cases:
                raise InputError(
                    f"aircraft_mass: {case!r} is not a mass case; they are {list(self.mass_cases)}"
                )
            check_number(f"aircraft_mass[{case!r}]", mass, unit="kg", lo=0.0, lo_open=True)
        check_number("lift_share", self.lift_share, lo=0.0, lo_open=True, hi=1.0)
        if self.f_g is None:
            w = self.weights
            for k in ("mlw", "mzfw", "mtow", "z_mo"):
                if k not in w:
                    raise InputError(f"gust loads: F_g from the weights needs {k!r}")
        else:
            check_number("f_g", self.f_g, lo=0.0, lo_open=True, hi=1.0)

    def _check_design_speeds(self) -> None:
        vc, vd = self.v_c, self.v_d
        if vc is not None:
            check_number("v_c", vc, unit="m/s EAS", lo=0.0, lo_open=True)
        if vd is not None:
            check_number("v_d", vd, unit="m/s EAS", lo=0.0, lo_open=True)
        if vc is not None and vd is not None and not vd > vc:
            raise InputError(f"v_d = {vd:g} m/s EAS: must exceed v_c = {vc:g} m/s EAS")
        for p in self.points:
            at = {"V_C": vc, "V_D": vd}.get(p.speed_name)
            if at is not None and abs(p.speed - at) > 1e-9 * at:
                raise InputError(
                    f"flight point {p.label}: speed = {p.speed:g} m/s EAS, but "
                    f"{p.speed_name} = {at:g} m/s EAS (name it '' for a speed in between)"
                )
            if p.speed_name == "" and vd is not None and p.speed > vd * (1 + 1e-9):
                raise InputError(
                    f"flight point {p.label}: speed = {p.speed:g} m/s EAS is beyond v_d = "
                    f"{vd:g} m/s EAS (the design envelope ends at V_D)"
                )
        bad = speed_order(self.points, vc, vd)
        if bad is not None:
            p = self.points[bad[0]]
            raise InputError(f"flight point {p.label}: speed = {p.speed:g} m/s EAS: {bad[1]}")

    def one_g_lift(self, mass_case: str) -> float | None:
        """The lift [N] the wing carries in 1 g flight in a mass case (None: not given)."""
        from ...linear.state_space import STANDARD_GRAVITY

        mass = self.aircraft_mass.get(mass_case)
        return None if mass is None else self.lift_share * mass * STANDARD_GRAVITY

    def turbulence_factor(self, point: FlightPoint) -> float:
        """Factor on the V_C value of U_sigma at ``point``: 1 up to V_C, 1/2 at V_D, linear
        between (CS-25.341(b)(3)(ii)-(iii)); without ``v_c`` and ``v_d``, 1 unless at V_D."""
        if point.at_vd:
            return 0.5
        vc, vd = self.v_c, self.v_d
        if point.speed_name or vc is None or vd is None or point.speed <= vc:
            return 1.0
        return 1.0 - 0.5 * (point.speed - vc) / (vd - vc)

    def alleviation_factor(self, altitude: float) -> float:
        """F_g at ``altitude`` [m] (CS-25.341(a)(6))."""
        if self.f_g is not None:
            return float(self.f_g)
        w = self.weights
        return flight_profile_alleviation(w["mlw"], w["mzfw"], w["mtow"], w["z_mo"], altitude)

    def model(self, mass_case: str):
        """The aeroelastic model of a mass case."""
        from ...system.aeroelastic import AeroelasticModel

        wing = self.mass_cases[mass_case]
        aero = "strip" if self.aero is None else self.aero
        return AeroelasticModel(
            wing,
            self.elements,
            self.wagner,
            damping=self.damping,
            aero=aero,
            load_stations=self.load_stations,
        )

    def loop(self, mass_case: str, density: float):
        """The :class:`~aeroservo.design.loop.ControlLoop` (or, open loop only, a plain builder
        with the gust input) of a mass case at ``density``."""
        from ...design.loop import ControlLoop

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
            actuator=self.actuator if self.controls else None,
        )
