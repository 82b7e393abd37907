"""A scenario: what to run on which wing (open-loop flutter, closed-loop simulation, trade study,
gust loads, limit cycles of nonlinear hinges), with the flight condition, model options, signals,
disturbance, controller and outputs.
Read from a scenario file by :mod:`aeroservo.files.scenario_file`; run by
:mod:`aeroservo.studies.runs`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..design.spec import ControllerSpec
from ..system.damping import NO_DAMPING, StructuralDamping

__all__ = ["Scenario", "Disturbance", "quick", "SCENARIO_KINDS"]


SCENARIO_KINDS = ("flutter", "simulate", "trade", "gust_loads", "lco")
GUST_TYPES = ("none", "one_minus_cosine", "turbulence", "series")
GUST_KEYS = {
    "none": (),
    "one_minus_cosine": ("length", "amplitude", "start"),
    "turbulence": ("sigma", "scale", "model", "seed"),
    "series": ("file",),
}


@dataclass(frozen=True)
class Disturbance:
    """Initial condition and gust of a simulation.

    Attributes
    ----------
    initial_tip : float
        Initial tip deflection [m] (static tip-load shape), 0 for none.
    gust : object or None
        A callable ``w(t, speed)`` [m/s] from :mod:`aeroservo.aero.gusts`, or None.
    """

    initial_tip: float = 0.0
    gust: object = None


@dataclass(frozen=True)
class Scenario:
    """A validated scenario (SI units). See ``docs/scenarios.md`` for every key.

    ``trade`` holds a trade study's table and ``gust_loads`` a gust-loads study's (a dict:
    ``loads``, ``points`` (:class:`~aeroservo.studies.gust_loads.FlightPoint`), ``mass_cases``
    (name -> wing, the first the default), ``design_mass_case``, ``n_gradients``,
    ``turbulence``, ``workers``, ``f_g`` or ``weights``) and ``lco`` a limit-cycle study's
    (``hinges``, ``speeds``, ``amplitudes``, ``duration``, ``dt``, ``settle``, ``continuation``,
    ``history``, ``workers``, ``describing``, ``hinges_source``); None for the other kinds. A
    limit-cycle study on a typical section has ``section`` (a
    :class:`~aeroservo.system.section.TypicalSection`) and no ``wing``. ``aero`` is the
    doublet-lattice settings (a :class:`~aeroservo.aero.dlm_settings.DoubletLattice`; None:
    strip theory) and ``mach`` a fixed Mach number (None: 0, or matched with
    ``compressibility``).
    """

    name: str
    kind: str
    source: str
    wing: object
    description: str = ""
    wing_source: str = ""
    density: float = 1.225
    altitude: float | None = None
    compressibility: str | None = None
    damping: StructuralDamping = NO_DAMPING
    speed: float | None = None
    speed_factor: float | None = None
    elements: int = 10
    wagner: object = "rt_jones"
    design_modes: int | None = 8
    gust_model: str = "kussner"
    v_max: float | None = None
    pk: bool = False
    sol145: dict | None = None  # a Nastran flutter case's velocities (files/scenario_tables)
    realisable: bool = False  # refuse a law on states no sensor measures ([controller])
    controls: tuple = ()
    sensors: tuple = ()
    outputs: tuple = ()
    sensor_filter: float | None = 30.0
    filter_order: int = 2
    actuator: dict | None = None  # ActuatorDynamics by control ([actuator]); None: ideal
    disturbance: Disturbance = field(default_factory=Disturbance)
    controller: ControllerSpec | None = None
    duration: float = 2.0
    sample_rate: float = 1000.0
    delay: bool = True  # one-sample computational delay ([simulation] delay)
    expect_failure: bool = False
    engaged_speeds: tuple | None = None
    engaged_speed_factors: tuple | None = None
    flutter_margin: float = 1.15
    seed: int = 0
    sensor_noise: dict = field(default_factory=dict)
    closed_loop_boundary: bool = False
    v_max_factor: float = 2.0
    n_grid: int = 41
    margin_speeds: int = 9
    result: str = ""
    plots: bool = True
    trade: object = None
    gust_loads: object = None
    lco: object = None
    section: object = None
    aero: object = None
    mach: float | None = None

    def model(self):
        """The aeroelastic model of the scenario's wing and options (its typical section, if
        it has one)."""
        from ..system.aeroelastic import AeroelasticModel

        if self.section is not None:
            return self.section

        return AeroelasticModel(
            self.wing,
            self.elements,
            self.wagner,
            damping=self.damping,
            aero="strip" if self.aero is None else self.aero,
        )

    def engaged_range(self, flutter_speed: float | None, speed: float):
        """The speeds where the loop is engaged (:class:`~aeroservo.design.EngagedRange`):
        ``controller.engaged_speeds`` [m/s], ``controller.engaged_speed_factors`` (x the
        open-loop flutter speed), or the default (0.5 V_f to ``speed``); stability is judged up
        to ``controller.flutter_margin`` x its top."""
        from dataclasses import replace

        return replace(self._engaged(flutter_speed, speed), flutter_margin=self.flutter_margin)

    def _engaged(self, flutter_speed: float | None, speed: float):
        from ..design.judgement import EngagedRange

        if self.engaged_speeds is not None:
            return EngagedRange(*self.engaged_speeds, "scenario: controller.engaged_speeds")
        if self.engaged_speed_factors is not None:
            if flutter_speed is None:
                raise ArithmeticError(
                    f"{self.source}: controller.engaged_speed_factors needs the open-loop "
                    "flutter speed, but the wing has none in the searched range"
                )
            lo, hi = (f * flutter_speed for f in self.engaged_speed_factors)
            return EngagedRange(
                lo, hi, "scenario: controller.engaged_speed_factors x the open-loop V_f"
            )
        return EngagedRange.default(flutter_speed, speed)

    @property
    def atmosphere(self):
        """The standard atmosphere at the scenario's altitude, or None (density given)."""
        from ..aero.atmosphere import isa

        return None if self.altitude is None else isa(self.altitude)

    def loop(self, model=None):
        """The :class:`~aeroservo.design.loop.ControlLoop` of a simulate scenario."""
        from ..design.loop import ControlLoop

        return ControlLoop(
            model or self.model(),
            self.density,
            self.controls,
            self.sensors,
            self.outputs,
            design_modes=self.design_modes,
            sensor_filter=self.sensor_filter,
            filter_order=self.filter_order,
            gust=self.gust_model,
            actuator=self.actuator,
        )


def quick(s: Scenario) -> Scenario:
    """Fast settings of a scenario for smoke tests: at most 0.5 s simulated, an 11-point
    closed-loop grid, 3 margin speeds, two values per trade parameter and a 0.3 s gust in
    trade studies; gust loads at the first two flight points with at most 5 gust gradients;
    limit cycles at the first, middle and last speeds from the smallest and largest initial
    rotations, at most 2 s each and no describing function."""
    from dataclasses import replace

    kw: dict = {
        "duration": min(s.duration, 0.5),
        "n_grid": min(s.n_grid, 11),
        "margin_speeds": min(s.margin_speeds, 3),
    }

    if s.trade is not None:
        t = dict(s.trade)
        t["parameters"] = {k: v[:2] for k, v in t["parameters"].items()}
        t["gust_duration"] = min(t["gust_duration"], 0.3)
        t["n_grid"] = min(t["n_grid"], 11)
        kw["trade"] = t
    if s.gust_loads is not None:
        g = dict(s.gust_loads)
        g["points"] = tuple(g["points"][:2])
        g["n_gradients"] = min(g["n_gradients"], 5)
        kw["gust_loads"] = g
    if s.lco is not None:
        c = dict(s.lco)
        v, a = c["speeds"], sorted(c["amplitudes"])
        c["speeds"] = tuple(sorted({v[0], v[len(v) // 2], v[-1]}))
        c["amplitudes"] = tuple(sorted({a[0], a[-1]}))
        c["duration"] = min(c["duration"], 2.0)
        c["history"] = min(c["history"], c["duration"])
        c["describing"] = False
        kw["lco"] = c
    return replace(s, **kw)
