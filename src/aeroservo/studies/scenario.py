"""A scenario: what to run on which wing (open-loop flutter, closed-loop simulation, trade study,
gust loads, limit cycles of nonlinear hinges), with the flight condition, model options, signals,
disturbance, controller and outputs.
Read from a scenario file by :mod:`aeroservo.files.scenario_file`; run by
:mod:`aeroservo.studies.runs`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..design.spec import ControllerSpec
from ..errors import NumericalError
from ..system.damping import NO_DAMPING, StructuralDamping
from .study_options import GustLoadsOptions, LCOOptions, TradeOptions

__all__ = ["Scenario", "Disturbance", "quick"]


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

    ``options`` holds the typed options of a study's table
    (:mod:`~aeroservo.studies.study_options`: a trade study's ``[trade]``, a gust-loads study's
    ``[gust_loads]``, a limit-cycle study's ``[lco]``), also read as ``trade``, ``gust_loads``
    and ``lco`` (None for the other kinds); the kinds are
    :data:`aeroservo.studies.kinds.KINDS`. A
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
    options: object = None  # the kind's typed options (studies/study_options), None: none
    section: object = None
    aero: object = None
    mach: float | None = None

    @property
    def trade(self) -> TradeOptions | None:
        """A trade study's options (``[trade]``), None for the other kinds."""
        return self.options if isinstance(self.options, TradeOptions) else None

    @property
    def gust_loads(self) -> GustLoadsOptions | None:
        """A gust-loads study's options (``[gust_loads]``), None for the other kinds."""
        return self.options if isinstance(self.options, GustLoadsOptions) else None

    @property
    def lco(self) -> LCOOptions | None:
        """A limit-cycle study's options (``[lco]``), None for the other kinds."""
        return self.options if isinstance(self.options, LCOOptions) else None

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

    def design_speed(self, flutter_speed: float | None, searched_to: float | None = None) -> float:
        """The controller's design speed [m/s]: ``flight.speed``, or ``flight.speed_factor`` x
        the open-loop flutter speed (refused beyond the airspeed range with the key); a
        NumericalError when that speed is needed and the wing has no flutter (below
        ``searched_to`` [m/s], or in the searched range)."""
        from ..errors import NumericalError, check_derived_speed

        if self.speed is not None:
            return self.speed
        if flutter_speed is None:
            where = (
                "in the searched range" if searched_to is None else f"below {searched_to:.4g} m/s"
            )
            raise NumericalError(
                f"{self.source}: flight.speed_factor needs the open-loop flutter speed, but the "
                f"wing has no flutter {where}"
            )
        return check_derived_speed(
            f"{self.source}: flight.speed_factor", self.speed_factor,
            self.speed_factor * flutter_speed,
            f"{self.speed_factor:g} x the open-loop flutter speed {flutter_speed:.6g} m/s",
        )  # fmt: skip

    def engaged_range(self, flutter_speed: float | None, speed: float):
        """The speeds where the loop is engaged (:class:`~aeroservo.design.EngagedRange`):
        ``controller.engaged_speeds`` [m/s], ``controller.engaged_speed_factors`` (x the
        open-loop flutter speed), or the default (0.5 V_f to ``speed``); stability is judged up
        to ``controller.flutter_margin`` x its top."""
        from dataclasses import replace

        from ..errors import check_derived_speed

        r = replace(self._engaged(flutter_speed, speed), flutter_margin=self.flutter_margin)
        key, value = "flight.speed", self.speed  # the default range ends at the design speed
        if self.speed is None:
            key, value = "flight.speed_factor", self.speed_factor
        if self.engaged_speeds is not None:
            key, value = "controller.engaged_speeds", list(self.engaged_speeds)
        elif self.engaged_speed_factors is not None:
            key, value = "controller.engaged_speed_factors", list(self.engaged_speed_factors)
        check_derived_speed(
            f"{self.source}: {key}", value, r.stable_to,
            f"up to {r.high:.6g} m/s x controller.flutter_margin = {r.flutter_margin:g}: where "
            "stability is required",
        )  # fmt: skip
        return r

    def _engaged(self, flutter_speed: float | None, speed: float):
        from ..design.judgement import EngagedRange

        if self.engaged_speeds is not None:
            return EngagedRange(*self.engaged_speeds, "scenario: controller.engaged_speeds")
        if self.engaged_speed_factors is not None:
            if flutter_speed is None:
                raise NumericalError(
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
    closed-loop grid, 3 margin speeds, and the study's own quick options (two values per trade
    parameter and a 0.3 s gust in trade studies; gust loads at the first two flight points with
    at most 5 gust gradients; limit cycles at the first, middle and last speeds from the
    smallest and largest initial rotations, at most 2 s each and no describing function)."""
    from dataclasses import replace

    return replace(
        s,
        duration=min(s.duration, 0.5),
        n_grid=min(s.n_grid, 11),
        margin_speeds=min(s.margin_speeds, 3),
        options=None if s.options is None else s.options.quick(),
    )
