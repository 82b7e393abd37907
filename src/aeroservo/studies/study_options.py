"""The typed options of the study scenarios: a trade study's ``[trade]``, a gust-loads study's
``[gust_loads]`` and a limit-cycle study's ``[lco]``, each read and validated once by
:mod:`aeroservo.files.scenario_file` and held by the :class:`~aeroservo.studies.scenario.Scenario`
(``scenario.options``). SI units; the keys and their ranges are in ``docs/scenarios.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

__all__ = ["TradeOptions", "GustLoadsOptions", "LCOOptions"]


@dataclass(frozen=True)
class TradeOptions:
    """``[trade]``: the parameters swept and what each case evaluates.

    Attributes
    ----------
    parameters : dict
        Parameter name -> its values (the grid is their product).
    controller : ControllerSpec or None
        The controller designed at every case (None: open loop only).
    closed_loop : bool
        Whether the cases close a loop (``controller`` given and not ``none``).
    speed_factor : float
        The gust speed as a multiple of each case's open-loop flutter speed.
    gust_length, gust_amplitude, gust_duration : float
        The 1-cos gust [m, m/s] and the simulated time [s].
    v_max_factor : float
        The closed-loop boundary searched to this multiple of the open-loop flutter speed.
    n_grid : int
        Speeds of the closed-loop boundary's grid.
    workers : int
        Local Dask workers (at least 1).
    """

    parameters: dict
    controller: object = None
    closed_loop: bool = True
    speed_factor: float = 1.1
    gust_length: float = 25.0
    gust_amplitude: float = 5.0
    gust_duration: float = 1.0
    v_max_factor: float = 2.0
    n_grid: int = 21
    workers: int = 2

    def quick(self) -> TradeOptions:
        """Two values per parameter, a 0.3 s gust, at most 11 speeds in the boundary grid."""
        return replace(
            self,
            parameters={k: v[:2] for k, v in self.parameters.items()},
            gust_duration=min(self.gust_duration, 0.3),
            n_grid=min(self.n_grid, 11),
        )


@dataclass(frozen=True)
class GustLoadsOptions:
    """``[gust_loads]``: the flight points, mass cases, loads and gust settings.

    Attributes
    ----------
    points : tuple of FlightPoint
    mass_cases : dict
        Mass-case name -> wing (the first the scenario's ``[wing]``, ``"nominal"``).
    design_mass_case : str
        The mass case the controller is designed on.
    loads : tuple of str
        The loads recorded (root loads and loads at ``stations``).
    stations : tuple of float
        Load stations along the span [m].
    n_gradients : int
        Gust gradients of the tuned-gust search.
    turbulence : bool
        Continuous turbulence (CS-25.341(b)) as well as tuned gusts.
    workers : int
        Local Dask workers (0: in this process).
    f_g : float or None
        The flight profile alleviation factor given (None: computed from ``weights``).
    weights : dict
        The airplane's weights [kg] that give F_g (empty: ``f_g`` given).
    v_c, v_d : float or None
        Design cruise and dive speeds [m/s EAS].
    aircraft_mass : dict
        The airplane's mass by mass case [kg] (the 1 g loads; empty: increments only).
    lift_share : float
        The share of the airplane's weight this wing lifts.
    """

    points: tuple
    mass_cases: dict
    design_mass_case: str = "nominal"
    loads: tuple = ()
    stations: tuple = ()
    n_gradients: int = 20
    turbulence: bool = True
    workers: int = 0
    f_g: float | None = 1.0
    weights: dict = field(default_factory=dict)
    v_c: float | None = None
    v_d: float | None = None
    aircraft_mass: dict = field(default_factory=dict)
    lift_share: float = 0.5

    def quick(self) -> GustLoadsOptions:
        """The first two flight points, at most 5 gust gradients."""
        return replace(self, points=tuple(self.points[:2]), n_gradients=min(self.n_gradients, 5))


@dataclass(frozen=True)
class LCOOptions:
    """``[lco]``: the speeds, initial rotations, marches and nonlinear hinges.

    Attributes
    ----------
    speeds : tuple of float
        Increasing speeds [m/s].
    amplitudes : tuple of float
        Initial rotations of the reference hinge [rad].
    hinges : tuple of NonlinearHinge
    hinges_source : str
        Where the hinges come from (``"lco.hinges"`` or the wing file).
    wing_hinges_replaced : bool
        The scenario's hinges replace the wing file's.
    duration, dt, history : float
        Length of a march, its step (open loop) and the time history kept [s].
    settle : float
        Share of a march left out before it is judged.
    continuation : bool
        March along the speeds up and down, each from the last state.
    workers : int
        Local Dask workers (0: in this process).
    describing : bool
        Compare with the describing function.
    """

    speeds: tuple
    amplitudes: tuple
    hinges: tuple = ()
    hinges_source: str = "lco.hinges"
    wing_hinges_replaced: bool = False
    duration: float = 30.0
    dt: float = 1e-3
    settle: float = 0.5
    continuation: bool = True
    history: float = 2.0
    workers: int = 0
    describing: bool = True

    def quick(self) -> LCOOptions:
        """The first, middle and last speeds from the smallest and largest initial rotations,
        at most 2 s each and no describing function."""
        v, a = self.speeds, sorted(self.amplitudes)
        duration = min(self.duration, 2.0)
        return replace(
            self,
            speeds=tuple(sorted({v[0], v[len(v) // 2], v[-1]})),
            amplitudes=tuple(sorted({a[0], a[-1]})),
            duration=duration,
            history=min(self.history, duration),
            describing=False,
        )
