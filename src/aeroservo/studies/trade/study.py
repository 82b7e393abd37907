"""Trade studies: flutter suppression over a grid of design and controller parameters, on Dask.

A :class:`TradeStudy` sweeps a full grid (the Cartesian product) of parameters of a wing with
one aileron and of its flutter-suppression controller (:data:`PARAMETERS`). Each case records

* the open-loop flutter speed [m/s] and frequency [Hz] of the variant wing;
* the closed-loop flutter speed and frequency with the controller designed at
  ``speed_factor`` x the open-loop flutter speed, and the suppression margin
  ``V_cl / V_ol - 1`` [-];
* peak and RMS hinge moment [N m] and tip acceleration [m/s^2] in a 1-cos gust, closed loop,
  at the design speed, with the actuator and its limits; the wall time [s] and, for a failed
  case, the stage and the message (a failed case is recorded, never lost).

:func:`run_trade` evaluates the cases on a Dask cluster: a ``distributed.LocalCluster`` on this
machine by default (worker processes, one thread each, BLAS/OpenMP pools limited to one thread
so that N workers use N cores), or an existing cluster given by its scheduler address
``tcp://host:port``. Each finished case is written at once, atomically, to
``out_dir/cases/<case_id>.json``; ``case_id`` is a short hash of the case parameters and of the
study's fixed settings, so a re-run skips the finished cases, an interrupted run loses only the
cases in flight, and a changed study never reuses stale cases.

Result format
-------------
The grid of cases is a regular N-dimensional array with one axis per swept parameter, which is
exactly what a labelled array is: the results are written as an ``xarray.Dataset`` (one
dimension per parameter, its values as coordinates, one variable per metric, units in the
attributes) to NetCDF through xarray's ``"scipy"`` engine (``NETCDF3_64BIT``), which needs no
compiled NetCDF/HDF5 library, only SciPy, already a dependency. The same cases are also
written as a flat CSV table (one row per case) for spreadsheets. ``out_dir/study.json``
describes the study so that :func:`load_trade` can re-read it for re-plotting.

Dask, xarray and pandas are imported only when needed; Dask and xarray: the ``trade`` extra.
"""

from __future__ import annotations

import dataclasses
import math
import re
import types
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ...design.actuator import actuators_of
from ...design.spec import ControllerSpec
from ...errors import MAX_ELEMENTS, InputError, check_int, check_number
from ...linear.signals import check_names
from ...structure.wing import Wing
from ...system.damping import NO_DAMPING, StructuralDamping
from .mass_parameters import TradeParameters, check_mass_values, mass_parameter

__all__ = ["PARAMETERS", "METRICS", "FORMAT", "TradeStudy"]

FORMAT = "aeroservo-trade/2"
"""Version of the case and study files; part of every case id."""

PARAMETERS: dict[str, tuple[str, str]] = TradeParameters(
    {
        "aileron_start": (
            "-",
            "fraction of the span where the aileron starts (it always ends at the tip)",
        ),
        "aileron_chord": (
            "-",
            "aileron chord as a fraction of the wing chord (hinge c = 1 - 2 f semichords aft of "
            "mid-chord; aileron mass per unit area kept, so S_beta ~ f^2 and I_beta ~ f^3)",
        ),
        "hinge_stiffness": ("N m/rad/m", "distributed hinge stiffness per unit span"),
        "actuator_station": (
            "-",
            "station of a single actuator as a fraction of the span (replaces the base actuators "
            "by one of their total stiffness)",
        ),
        "bryson_hinge_moment": (
            "N m",
            "allowed hinge moment of Bryson's rule (replaces the controller's weights.inputs value "
            "for every control)",
        ),
        "speed_factor": (
            "-",
            "design (and gust) speed as a multiple of the variant's open-loop flutter speed",
        ),
    }
)
"""Parameters a study can sweep: name -> (unit, description); also ``masses[i].<key>`` of the
base wing's concentrated masses, in wing-file units (:mod:`.mass_parameters`)."""

_SURFACE = ("aileron_start", "aileron_chord", "hinge_stiffness", "actuator_station")  # aileron

_DOMAINS: dict[str, dict] = {
    "aileron_start": {"lo": 0.0, "hi": 1.0, "hi_open": True},
    "aileron_chord": {"lo": 0.0, "hi": 1.0, "lo_open": True, "hi_open": True},
    "hinge_stiffness": {"lo": 0.0},
    "actuator_station": {"lo": 0.0, "hi": 1.0},
    "bryson_hinge_moment": {"lo": 0.0, "lo_open": True},
    "speed_factor": {"lo": 0.0, "lo_open": True},
}

METRICS: dict[str, tuple[str, str]] = {
    "open_loop_flutter_speed": ("m/s", "open-loop flutter speed V_ol"),
    "open_loop_flutter_frequency": ("Hz", "open-loop flutter frequency"),
    "design_speed": ("m/s", "controller design and gust speed (speed_factor x V_ol)"),
    "closed_loop_flutter_speed": (
        "m/s",
        "closed-loop flutter speed V_cl (missing: stable up to closed_loop_v_max)",
    ),
    "closed_loop_flutter_frequency": ("Hz", "closed-loop flutter frequency (0: static)"),
    "closed_loop_v_max": ("m/s", "upper end of the closed-loop search (v_max_factor x V_ol)"),
    "stable_at_design": ("-", "closed loop stable at the design speed (1 yes, 0 no)"),
    "suppression_margin": ("-", "V_cl / V_ol - 1"),
    "hinge_moment_peak": ("N m", "peak |hinge moment| applied in the 1-cos gust"),
    "hinge_moment_rms": ("N m", "RMS hinge moment applied in the 1-cos gust"),
    "hinge_moment_saturation": ("-", "share of samples at the hinge-moment magnitude limit"),
    "tip_accel_peak": ("m/s^2", "peak |tip acceleration| in the 1-cos gust"),
    "tip_accel_rms": ("m/s^2", "RMS tip acceleration in the 1-cos gust"),
    "closed_loop_lower_speed": (
        "m/s",
        "lower end of the closed loop's stable interval that holds the design speed",
    ),
    "gain_margin_db": (
        "dB",
        "gain margin at the first control at the design speed (loop broken at the actuator, "
        "controller a black box)",
    ),
    "gain_reduction_margin_db": ("dB", "gain-reduction margin there (negative)"),
    "phase_margin_deg": ("deg", "phase margin there"),
    "disk_margin": ("-", "balanced disk margin alpha there"),
    "wall_time": ("s", "wall time of the case evaluation"),
}
"""Numeric results of a case: name -> (unit, description)."""

LINEAR_TYPES = ("lqr", "lqg", "mpc", "hinf", "linear", "gain")
_BRYSON_TYPES = ("lqr", "lqg", "mpc", "hinf")
_NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")


@dataclass(frozen=True, kw_only=True)
class TradeStudy:
    """A grid of flutter-suppression cases (all fields keyword-only, validated).

    Parameters
    ----------
    base_wing : Wing
        Wing with exactly one control surface (the aileron) that the parameters vary.
    density : float
        Air density [kg/m^3].
    damping : StructuralDamping
        Structural damping of every variant (default none).
    elements : int
        Beam elements along the span.
    wagner : str
        Wagner approximation (see :class:`aeroservo.AeroelasticModel`).
    aero : {"strip", "dlm"}, DoubletLattice or None
        Aerodynamic model of every variant (None: strip theory; the doublet lattice at Mach 0).
    controls, sensors, outputs : tuple of str
        Control inputs, measured outputs and further recorded outputs of the loop
        (see :class:`aeroservo.design.loop.ControlLoop`); ``"tip_accel"`` must be among the
        sensors or outputs (the gust metric). The first control is the hinge moment of the metrics.
    design_modes : int or None
        In-vacuo modes of the design model (None: full model).
    sensor_filter : float or None
        Cutoff of the accelerometer filters [Hz] (None: none).
    filter_order : int
        Butterworth order of those filters (1 to 4).
    gust_model : str
        Gust model of the plant: ``"kussner"`` or ``"upwash"``.
    controller : ControllerSpec or None
        A controller with a linear law (type ``"lqr"``, ``"lqg"``, ``"mpc"`` (its law without
        active constraints; the gust is flown with the MPC itself), ``"hinf"``, ``"linear"`` or
        ``"gain"``; the closed-loop boundary needs a linear loop, so a Python law is refused).
        Needed unless ``closed_loop`` is False.
    sample_rate : float
        Controller sample rate [Hz].
    delay, actuator : bool, ActuatorDynamics (or a dict of them by control) or None
        One-sample computational delay (default on) and actuator dynamics (default ideal) of
        every loop (:mod:`aeroservo.design.actuator`: the limits bound its output).
    parameters : dict
        ``{name: values}`` of the swept parameters (names from :data:`PARAMETERS`); the grid is
        their full product, in this order, the last varying fastest.
    speed_factor : float
        Design speed / open-loop flutter speed [-] when ``"speed_factor"`` is not swept.
    gust_length : float
        1-cos gust length [m].
    gust_amplitude : float
        1-cos gust peak velocity [m/s].
    gust_duration : float
        Simulated time [s] (the gust starts at t = 0).
    v_max_factor : float
        The closed-loop boundary is searched up to ``v_max_factor`` x the open-loop flutter
        speed [-].
    n_grid : int
        Speeds of the closed-loop search grid.
    name : str
        Study name, used for the output file names (letters, digits, ``_ . -``).
    closed_loop : bool
        False: only the open-loop flutter boundary of each case (no controller needed).
    """

    base_wing: Wing
    density: float = 1.225
    damping: StructuralDamping = NO_DAMPING
    elements: int = 10
    wagner: str = "rt_jones"
    aero: object = None
    controls: tuple = ("aileron_hinge_moment",)
    sensors: tuple = ("tip_le_accel", "tip_te_accel", "tip_twist")
    outputs: tuple = ("tip_disp", "tip_accel")
    design_modes: int | None = 8
    sensor_filter: float | None = 30.0
    filter_order: int = 2
    gust_model: str = "kussner"
    controller: ControllerSpec | None = None
    sample_rate: float = 1000.0
    delay: bool = True
    actuator: object = None
    parameters: dict = field(default_factory=dict)
    speed_factor: float = 1.1
    gust_length: float = 25.0
    gust_amplitude: float = 5.0
    gust_duration: float = 1.0
    v_max_factor: float = 2.0
    n_grid: int = 21
    name: str = "trade"
    closed_loop: bool = True

    def __post_init__(self) -> None:
        from ...aero.dlm_settings import as_aero
        from ...aero.indicial import wagner_set

        put = object.__setattr__
        put(self, "actuator", actuators_of(self.actuator, self.controls) or None)  # by control
        if not isinstance(self.delay, bool):
            raise InputError(f"delay = {self.delay!r}: expected True or False")
        w = self.base_wing
        if not isinstance(w, Wing):
            raise InputError(f"base_wing = {w!r}: expected an aeroservo.Wing")
        swept = self.parameters if isinstance(self.parameters, Mapping) else {}
        aileron = self.closed_loop is not False or any(k in _SURFACE for k in swept)
        if aileron and len(w.control_surfaces) != 1:
            raise InputError(
                f"base_wing.control_surfaces: {len(w.control_surfaces)} surfaces; a trade study "
                "needs a wing with exactly one control surface (the aileron), unless it is "
                "open loop (closed_loop = false) and sweeps no aileron parameter"
            )
        if not isinstance(self.wagner, str):
            raise InputError(f"wagner = {self.wagner!r}: expected the name of a Wagner set")
        wagner_set(self.wagner)
        put(self, "aero", as_aero(self.aero))
        for key in ("controls", "sensors", "outputs"):
            put(self, key, _names(key, getattr(self, key)))
        if not self.controls and self.closed_loop is not False:
            raise InputError("controls = (): give at least one control input")
        put(self, "elements", check_int("elements", self.elements, lo=1, hi=MAX_ELEMENTS))
        put(self, "n_grid", check_int("n_grid", self.n_grid, lo=3, hi=10_000))
        if self.design_modes is not None:
            put(self, "design_modes", check_int("design_modes", self.design_modes, lo=1))
        put(self, "filter_order", check_int("filter_order", self.filter_order, lo=1, hi=4))
        if self.gust_model not in ("kussner", "upwash"):
            raise InputError(
                f"gust_model = {self.gust_model!r}: allowed values are 'kussner', 'upwash'"
            )
        numbers = {
            "density": {"unit": "kg/m^3", "lo": 0.0, "lo_open": True},
            "sensor_filter": {"unit": "Hz", "lo": 0.0, "lo_open": True},
            "sample_rate": {"unit": "Hz", "lo": 0.0, "hi": 1e6, "lo_open": True},
            "v_max_factor": {"lo": 1.0, "hi": 100.0, "lo_open": True},
            "speed_factor": {"lo": 0.0, "lo_open": True, "hi_open": True},  # hi: v_max_factor
            "gust_length": {"unit": "m", "lo": 0.0, "lo_open": True},
            "gust_amplitude": {"unit": "m/s"},
            "gust_duration": {"unit": "s", "lo": 0.0, "hi": 600.0, "lo_open": True},
        }
        for key, kw in numbers.items():
            value = getattr(self, key)
            if key == "sensor_filter" and value is None:
                continue
            if key == "speed_factor":
                kw["hi"] = self.v_max_factor
            put(self, key, check_number(key, value, **kw))
        if not isinstance(self.name, str) or not _NAME_RE.fullmatch(self.name):
            raise InputError(
                f"name = {self.name!r}: expected letters, digits, '_', '.' or '-' (starting "
                "with a letter or digit); it names the output files"
            )
        if not isinstance(self.closed_loop, bool):
            raise InputError(f"closed_loop = {self.closed_loop!r}: expected true or false")
        if not isinstance(self.damping, StructuralDamping):
            raise InputError(f"damping = {self.damping!r}: expected a StructuralDamping")
        put(self, "parameters", self._check_parameters())
        if self.closed_loop:
            self._check_controller()

    def _check_parameters(self) -> dict:
        p = self.parameters
        if not isinstance(p, Mapping) or not p:
            raise InputError(
                f"parameters = {p!r}: give at least one swept parameter, "
                f"{{name: [values]}} with names from {sorted(PARAMETERS)}"
            )
        out: dict[str, tuple[float, ...]] = {}
        for name, values in p.items():
            if name not in PARAMETERS:
                raise InputError(
                    f"parameters.{name}: unknown parameter; known are {sorted(PARAMETERS)}"
                )
            if isinstance(values, np.ndarray):
                values = values.tolist()
            if isinstance(values, (str, bytes)) or not isinstance(values, (Sequence, range)):
                raise InputError(f"parameters.{name} = {values!r}: expected a list of numbers")
            if len(values) == 0:
                raise InputError(f"parameters.{name} = []: give at least one value")
            unit = PARAMETERS[name][0]
            dom = dict(_DOMAINS.get(name, {}))
            if name == "speed_factor":
                dom.update(hi=self.v_max_factor, hi_open=True)
            vals = (
                check_mass_values(self.base_wing, name, values)
                if mass_parameter(name) is not None
                else tuple(
                    check_number(
                        f"parameters.{name}[{i}]", v, unit="" if unit == "-" else unit, **dom
                    )
                    for i, v in enumerate(values)
                )
            )
            if len(set(vals)) != len(vals):
                dup = sorted({v for v in vals if vals.count(v) > 1})
                raise InputError(
                    f"parameters.{name} = {list(vals)}: repeated values {dup}; each value once"
                )
            out[name] = vals
        n = math.prod(len(v) for v in out.values())
        if n > 1_000_000:
            raise InputError(f"parameters: {n} cases; allowed range is [1, 1000000] cases")
        if "actuator_station" in out and not self.surface.actuators:
            raise InputError(
                "parameters.actuator_station: the base wing's control surface has no actuators "
                "whose total stiffness the single actuator would take"
            )
        return out

    def _check_controller(self) -> None:
        from ...design.loop import ControlLoop

        spec = self.controller
        if not isinstance(spec, ControllerSpec):
            raise InputError(
                f"controller = {spec!r}: expected a ControllerSpec (load_controller(path)); "
                "only closed_loop = false studies run without one"
            )
        if spec.type not in LINEAR_TYPES:
            raise InputError(
                f"controller.type = {spec.type!r}: a trade study needs a controller with a "
                f"linear law, one of {list(LINEAR_TYPES)} (the closed-loop flutter boundary is "
                "an eigenvalue analysis of the linear loop)"
            )
        if "bryson_hinge_moment" in self.parameters and spec.type not in _BRYSON_TYPES:
            raise InputError(
                f"parameters.bryson_hinge_moment: the controller (type {spec.type!r}) is not "
                "designed by Bryson's rule; it is the same in every case"
            )
        if "tip_accel" not in self.sensors + self.outputs:
            raise InputError(
                f"outputs = {list(self.outputs)}: must include 'tip_accel' (gust metric)"
            )
        # the spec's signal names against this loop, without building a model
        loop = types.SimpleNamespace(
            controls=list(self.controls),
            sensors=list(self.sensors),
            outputs=list(dict.fromkeys(self.sensors + self.outputs)),
        )
        ControlLoop.check_spec(loop, self.spec_for(None))

    @property
    def surface(self):
        """The base wing's control surface."""
        return self.base_wing.control_surfaces[0]

    @property
    def n_cases(self) -> int:
        """Number of cases of the grid."""
        return math.prod(len(v) for v in self.parameters.values())

    def spec_for(self, bryson_hinge_moment: float | None) -> ControllerSpec:
        """The controller spec with Bryson's allowed hinge moment replaced [N m]."""
        spec = self.controller
        if bryson_hinge_moment is None:
            return spec
        inputs = dict(spec.bryson_inputs)
        inputs.update({c: float(bryson_hinge_moment) for c in self.controls})
        return dataclasses.replace(spec, bryson_inputs=inputs)


def _names(key: str, value: object) -> tuple[str, ...]:
    value = tuple(check_names(key, list(value) if isinstance(value, (set, frozenset)) else value,
                              empty=True))  # fmt: skip
    if len(set(value)) != len(value):
        raise InputError(f"{key} = {list(value)}: repeated names")
    return value
