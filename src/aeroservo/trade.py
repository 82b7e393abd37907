"""Trade studies: flutter suppression over a grid of design and controller parameters, on Dask.

A :class:`TradeStudy` sweeps a full grid (the Cartesian product) of parameters of a wing with
one aileron and of its flutter-suppression controller (:data:`PARAMETERS`). Each case records

* the open-loop flutter speed [m/s] and frequency [Hz] of the variant wing;
* the closed-loop flutter speed and frequency with the controller designed at
  ``speed_factor`` x the open-loop flutter speed, and the suppression margin
  ``V_cl / V_ol - 1`` [-];
* peak and RMS hinge moment [N m] and tip acceleration [m/s^2] in a 1-cos gust, closed loop,
  at the design speed, with the controller's actuator limits applied;
* the wall time [s] and, for a failed case, the stage and the message (a failed case is
  recorded, never lost).

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

Dask, xarray and pandas are imported only when needed (``import aeroservo`` stays fast); they
come with the ``trade`` extra.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import itertools
import json
import math
import os
import re
import time
import traceback
import types
from collections import OrderedDict
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .controller_spec import ControllerSpec
from .errors import InputError, check_int, check_number
from .fileio import atomic_write, atomic_write_text
from .model import Actuator, Wing

__all__ = [
    "PARAMETERS",
    "METRICS",
    "TradeStudy",
    "TradeResult",
    "trade_cases",
    "case_id",
    "study_settings",
    "variant_wing",
    "evaluate_case",
    "run_trade",
    "load_trade",
    "local_cluster",
    "pareto_front",
]

FORMAT = "aeroservo-trade/1"
"""Version of the case and study files; part of every case id."""

PARAMETERS: dict[str, tuple[str, str]] = {
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
"""Parameters a study can sweep: name -> (unit, description)."""

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
    "wall_time": ("s", "wall time of the case evaluation"),
}
"""Numeric results of a case: name -> (unit, description)."""

_TEXT = ("status", "failed_stage", "error")
_LINEAR_TYPES = ("lqr", "lqg")
_NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")
_ADDRESS_RE = re.compile(r"(tcp|tls)://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):(\d{1,5})")
_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


# --------------------------------------------------------------------------------------------
# The study
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, kw_only=True)
class TradeStudy:
    """A grid of flutter-suppression cases (all fields keyword-only, validated).

    Parameters
    ----------
    base_wing : Wing
        Wing with exactly one control surface (the aileron) that the parameters vary.
    density : float
        Air density [kg/m^3].
    elements : int
        Beam elements along the span.
    wagner : str
        Wagner approximation (see :class:`aeroservo.AeroelasticModel`).
    controls, sensors, outputs : tuple of str
        Control inputs, measured outputs and further recorded outputs of the loop
        (see :class:`aeroservo.loop.ControlLoop`); ``"tip_accel"`` must be among the sensors or
        outputs (the gust metric). The first control is the hinge moment of the metrics.
    design_modes : int or None
        In-vacuo modes of the design model (None: full model).
    sensor_filter : float or None
        Cutoff of the accelerometer filters [Hz] (None: none).
    filter_order : int
        Butterworth order of those filters (1 to 4).
    gust_model : str
        Gust model of the plant: ``"kussner"`` or ``"upwash"``.
    controller : ControllerSpec or None
        Linear controller (type ``"lqr"`` or ``"lqg"``; the closed-loop boundary needs a linear
        loop). Needed unless ``closed_loop`` is False.
    sample_rate : float
        Controller sample rate [Hz].
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
    elements: int = 10
    wagner: str = "rt_jones"
    controls: tuple = ("aileron_hinge_moment",)
    sensors: tuple = ("tip_le_accel", "tip_te_accel", "tip_twist")
    outputs: tuple = ("tip_disp", "tip_accel")
    design_modes: int | None = 8
    sensor_filter: float | None = 30.0
    filter_order: int = 2
    gust_model: str = "kussner"
    controller: ControllerSpec | None = None
    sample_rate: float = 1000.0
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
        from .wagner import wagner_set

        put = object.__setattr__
        w = self.base_wing
        if not isinstance(w, Wing):
            raise InputError(f"base_wing = {w!r}: expected an aeroservo.Wing")
        if len(w.control_surfaces) != 1:
            raise InputError(
                f"base_wing.control_surfaces: {len(w.control_surfaces)} surfaces; a trade study "
                "needs a wing with exactly one control surface (the aileron)"
            )
        if not isinstance(self.wagner, str):
            raise InputError(f"wagner = {self.wagner!r}: expected the name of a Wagner set")
        wagner_set(self.wagner)
        for key in ("controls", "sensors", "outputs"):
            put(self, key, _names(key, getattr(self, key)))
        if not self.controls:
            raise InputError("controls = (): give at least one control input")
        put(self, "elements", check_int("elements", self.elements, lo=1, hi=1000))
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
            dom = dict(_DOMAINS[name])
            if name == "speed_factor":
                dom.update(hi=self.v_max_factor, hi_open=True)
            vals = tuple(
                check_number(f"parameters.{name}[{i}]", v, unit="" if unit == "-" else unit, **dom)
                for i, v in enumerate(values)
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
        from .loop import ControlLoop

        spec = self.controller
        if not isinstance(spec, ControllerSpec):
            raise InputError(
                f"controller = {spec!r}: expected a ControllerSpec (load_controller(path)); "
                "only closed_loop = false studies run without one"
            )
        if spec.type not in _LINEAR_TYPES:
            raise InputError(
                f"controller.type = {spec.type!r}: a trade study needs a linear controller, "
                f"one of {list(_LINEAR_TYPES)} (the closed-loop flutter boundary is an "
                "eigenvalue analysis of the linear loop)"
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
    if isinstance(value, str) or not isinstance(value, (Sequence, set, frozenset)):
        raise InputError(f"{key} = {value!r}: expected a list of signal names")
    value = tuple(value)
    for i, n in enumerate(value):
        if not isinstance(n, str) or not n:
            raise InputError(f"{key}[{i}] = {n!r}: expected a signal name")
    if len(set(value)) != len(value):
        raise InputError(f"{key} = {list(value)}: repeated names")
    return value


def _jsonable(obj: object) -> object:
    """Plain JSON data of settings (dataclasses, tuples, numpy scalars)."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: _jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, Mapping):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def study_settings(study: TradeStudy) -> dict:
    """The fixed settings of a study (everything but the swept values and the name).

    These, with the format version and the aeroservo version, enter every case id: a study
    whose settings change gets new case ids and never reuses stale case files.
    """
    from . import __version__

    s: dict = {
        "format": FORMAT,
        "aeroservo": __version__,
        "base_wing": _jsonable(study.base_wing),
        "density": study.density,
        "elements": study.elements,
        "wagner": study.wagner,
        "closed_loop": study.closed_loop,
    }
    if study.closed_loop:
        spec = _jsonable(study.controller)
        for k in ("name", "source"):  # labels only: they do not change the results
            spec.pop(k, None)
        s.update(
            controls=list(study.controls),
            sensors=list(study.sensors),
            outputs=list(study.outputs),
            design_modes=study.design_modes,
            sensor_filter=study.sensor_filter,
            filter_order=study.filter_order,
            gust_model=study.gust_model,
            controller=spec,
            sample_rate=study.sample_rate,
            gust_length=study.gust_length,
            gust_amplitude=study.gust_amplitude,
            gust_duration=study.gust_duration,
            v_max_factor=study.v_max_factor,
            n_grid=study.n_grid,
        )
        if "speed_factor" not in study.parameters:
            s["speed_factor"] = study.speed_factor
    return s


def _digest(obj: object) -> str:
    text = json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()


def case_id(study: TradeStudy, params: Mapping, _fingerprint: str | None = None) -> str:
    """Short stable hash (12 hex digits) of a case's parameters and the study's settings."""
    fp = _fingerprint or _digest(study_settings(study))
    p = {k: float(v) for k, v in params.items() if k != "case_id"}
    return _digest({"study": fp, "case": p})[:12]


def trade_cases(study: TradeStudy) -> list[dict]:
    """The grid of a study: ``[{"case_id": ..., parameter: value, ...}, ...]``.

    The full product of the parameter values, in the order of ``study.parameters`` (the last
    parameter varies fastest, as in a C-ordered array).
    """
    if not isinstance(study, TradeStudy):
        raise InputError(f"study = {study!r}: expected a TradeStudy")
    fp = _digest(study_settings(study))
    names = list(study.parameters)
    out = []
    for values in itertools.product(*study.parameters.values()):
        params = dict(zip(names, values, strict=True))
        out.append({"case_id": case_id(study, params, fp), **params})
    return out


# --------------------------------------------------------------------------------------------
# One case
# --------------------------------------------------------------------------------------------


def variant_wing(study: TradeStudy, params: Mapping) -> Wing:
    """The base wing with the design parameters of ``params`` applied.

    Controller parameters (``bryson_hinge_moment``, ``speed_factor``) are ignored here.

    Raises
    ------
    InputError
        If a parameter is unknown or the variant is invalid (e.g. an actuator outside the
        aileron, a hinge ahead of the elastic axis); the message names the field and value.
    """
    for k in params:
        if k != "case_id" and k not in PARAMETERS:
            raise InputError(f"parameters.{k}: unknown parameter; known are {sorted(PARAMETERS)}")
    wing = study.base_wing
    cs = study.surface
    span = wing.span
    kw: dict = {}
    if "aileron_start" in params:
        f = check_number("aileron_start", params["aileron_start"], **_DOMAINS["aileron_start"])
        kw["start"] = f * span
        kw["end"] = span
    if "aileron_chord" in params:
        f = check_number("aileron_chord", params["aileron_chord"], **_DOMAINS["aileron_chord"])
        f0 = 0.5 * (1.0 - cs.hinge)  # base chord fraction
        kw["hinge"] = 1.0 - 2.0 * f
        kw["static_moment"] = cs.static_moment * (f / f0) ** 2
        kw["inertia"] = cs.inertia * (f / f0) ** 3
    if "hinge_stiffness" in params:
        kw["hinge_stiffness"] = check_number(
            "hinge_stiffness", params["hinge_stiffness"], unit="N m/rad/m", lo=0.0
        )
    if "actuator_station" in params:
        f = check_number(
            "actuator_station", params["actuator_station"], **_DOMAINS["actuator_station"]
        )
        total = float(sum(a.stiffness for a in cs.actuators))
        kw["actuators"] = (Actuator(station=f * span, stiffness=total, name="actuator"),)
    if not kw:
        return wing
    surface = dataclasses.replace(cs, **kw)
    return dataclasses.replace(wing, control_surfaces=(surface,))


_CACHE: OrderedDict = OrderedDict()
_CACHE_SIZE = 4


def _stage_model(study: TradeStudy, wing: Wing) -> dict:
    """Model and open-loop boundary of a variant wing; cached per process (a few variants),
    so that cases differing only in controller parameters share them."""
    from .aeroelastic import AeroelasticModel
    from .stability import flutter_boundary

    key = (repr(wing), study.density, study.elements, study.wagner)
    hit = _CACHE.get(key)
    if hit is not None:
        _CACHE.move_to_end(key)
        return hit
    model = AeroelasticModel(wing, study.elements, study.wagner)
    entry = {"model": model, "flutter": flutter_boundary(model, study.density), "loops": {}}
    _CACHE[key] = entry
    while len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return entry


def _loop(study: TradeStudy, entry: dict):
    from .loop import ControlLoop

    key = (
        study.controls,
        study.sensors,
        study.outputs,
        study.design_modes,
        study.sensor_filter,
        study.filter_order,
        study.gust_model,
    )
    if key not in entry["loops"]:
        entry["loops"][key] = ControlLoop(
            entry["model"],
            study.density,
            list(study.controls),
            list(study.sensors),
            list(study.outputs),
            design_modes=study.design_modes,
            sensor_filter=study.sensor_filter,
            filter_order=study.filter_order,
            gust=study.gust_model,
        )
    return entry["loops"][key]


def _num(x: object) -> float | None:
    """A finite float, or None."""
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def _blank(params: Mapping) -> dict:
    rec: dict = {"case_id": None}
    rec.update({k: v for k, v in params.items() if k != "case_id"})
    rec.update(status="failed", failed_stage=None, error=None)
    rec.update({m: None for m in METRICS})
    return rec


def evaluate_case(study: TradeStudy, params: Mapping) -> dict:
    """Evaluate one case; never raises.

    Parameters
    ----------
    study : TradeStudy
    params : dict
        ``{parameter: value}`` (a row of :func:`trade_cases`; its ``case_id`` is recomputed).

    Returns
    -------
    dict
        ``case_id``, the parameters, ``status`` (``"ok"`` or ``"failed"``), ``failed_stage``
        (``"input"``, ``"wing"``, ``"open_loop"``, ``"design"``, ``"closed_loop"`` or
        ``"gust"``; None when ok), ``error`` (the message; None when ok) and every metric of
        :data:`METRICS` (None when unavailable; ``wall_time`` [s] always set). A failed case
        keeps the metrics of the stages before the failure.

    Notes
    -----
    The controller is designed at ``V_d = speed_factor x V_ol`` and the closed loop searched on
    ``[v_max / 20, v_max]`` with ``v_max = v_max_factor x V_ol``. If the loop is stable at
    ``V_d``, the closed-loop flutter speed is the first loss of stability above ``V_d`` (None:
    stable up to ``v_max``, the margin is then at least ``v_max / V_ol - 1``); if it is not,
    it is the last loss of stability below ``V_d`` and ``stable_at_design`` is False. The gust
    is flown at ``V_d``. A variant without open-loop flutter fails at the ``"open_loop"``
    stage (no design speed).
    """
    t0 = time.perf_counter()
    rec = _blank(params if isinstance(params, Mapping) else {})
    stage = ["input"]
    try:
        if not isinstance(study, TradeStudy):
            raise InputError(f"study = {study!r}: expected a TradeStudy")
        if not isinstance(params, Mapping):
            raise InputError(f"params = {params!r}: expected a mapping {{parameter: value}}")
        p = {k: v for k, v in params.items() if k != "case_id"}
        for k, v in p.items():
            if k not in PARAMETERS:
                raise InputError(f"parameters.{k}: unknown; known are {sorted(PARAMETERS)}")
            p[k] = check_number(f"parameters.{k}", v)
        rec.update(p)
        rec["case_id"] = case_id(study, p)
        stage[0] = "wing"
        wing = variant_wing(study, p)
        stage[0] = "open_loop"
        entry = _stage_model(study, wing)
        ol = entry["flutter"]
        v_ol = _num(ol.flutter_speed)
        rec["open_loop_flutter_speed"] = v_ol
        rec["open_loop_flutter_frequency"] = _num(ol.flutter_frequency)
        if study.closed_loop:
            if v_ol is None:
                raise InputError(
                    f"open-loop flutter: none up to {ol.v_max:.4g} m/s, so the design speed "
                    "(speed_factor x V_ol) is undefined"
                )
            _closed_loop(study, p, entry, v_ol, rec, stage)
        rec["status"] = "ok"
    except Exception as exc:  # a failed case is recorded, never raised
        rec["failed_stage"] = stage[0]
        if isinstance(exc, InputError):
            rec["error"] = str(exc)
        else:
            tb = traceback.extract_tb(exc.__traceback__)
            where = f" ({Path(tb[-1].filename).name}:{tb[-1].lineno})" if tb else ""
            rec["error"] = f"{type(exc).__name__}: {exc}{where}"
    rec["wall_time"] = time.perf_counter() - t0
    return rec


def _closed_loop(
    study: TradeStudy, p: dict, entry: dict, v_ol: float, rec: dict, stage: list
) -> None:
    """Design, closed-loop boundary and gust response of one case (fills ``rec``)."""
    from .design import closed_loop_boundary
    from .gusts import OneMinusCosine
    from .simulate import simulate

    stage[0] = "design"
    sf = p.get("speed_factor", study.speed_factor)
    speed = sf * v_ol
    v_max = study.v_max_factor * v_ol
    rec["design_speed"] = speed
    rec["closed_loop_v_max"] = v_max
    spec = study.spec_for(p.get("bryson_hinge_moment"))
    loop = _loop(study, entry)
    ctrl = loop.design_controller(spec, speed, study.sample_rate, v_ol)

    stage[0] = "closed_loop"
    b = closed_loop_boundary(loop.plant, ctrl, v_max, n_grid=study.n_grid, reference_speed=speed)
    stable = b.stable_at_reference
    if stable:
        onset = b.flutter
    else:  # where the loop lost the stability it lacks at the design speed
        below = [c for c in b.crossings if c["kind"] == "onset" and c["speed"] <= speed]
        onset = below[-1] if below else None
    rec["stable_at_design"] = bool(stable)
    if onset is not None:
        v_cl = float(onset["speed"])
        rec["closed_loop_flutter_speed"] = v_cl
        rec["closed_loop_flutter_frequency"] = _num(onset["frequency"])
        rec["suppression_margin"] = v_cl / v_ol - 1.0

    stage[0] = "gust"
    gust = OneMinusCosine(study.gust_length, study.gust_amplitude, 0.0)
    control = study.controls[0]
    sim = simulate(
        loop.plant(speed),
        ctrl,
        duration=study.gust_duration,
        disturbance=gust,
        limits=spec.limits,
        outputs=["tip_accel"],
    )
    u = np.asarray(sim.applied[control], dtype=float)
    a = np.asarray(sim.outputs["tip_accel"], dtype=float)
    rec["hinge_moment_peak"] = _num(np.max(np.abs(u)))
    rec["hinge_moment_rms"] = _num(np.sqrt(np.mean(u**2)))
    rec["hinge_moment_saturation"] = _num(sim.saturated_fraction()[control])
    rec["tip_accel_peak"] = _num(np.max(np.abs(a)))
    rec["tip_accel_rms"] = _num(np.sqrt(np.mean(a**2)))


# --------------------------------------------------------------------------------------------
# Running on Dask
# --------------------------------------------------------------------------------------------


def _case_task(study: TradeStudy, params: dict) -> dict:
    """The work function shipped to the workers (module level: picklable by reference)."""
    return evaluate_case(study, params)


def _worker_probe() -> dict:
    """What a worker runs before the study: its aeroservo version and thread settings."""
    from . import __version__

    return {
        "aeroservo": __version__,
        "pid": os.getpid(),
        **{k: os.environ.get(k) for k in _THREAD_VARS},
    }


@contextlib.contextmanager
def local_cluster(n_workers: int = 2, *, timeout: float = 60.0) -> Iterator[object]:
    """A ``distributed.LocalCluster`` for trade studies (context manager).

    Worker processes on the loopback interface, one thread each, no dashboard, with
    ``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS`` and ``MKL_NUM_THREADS`` = 1 set *before*
    the worker processes start (BLAS reads them when NumPy is imported), so that N workers use
    N cores instead of fighting over them.

    Parameters
    ----------
    n_workers : int
        Worker processes.
    timeout : float
        Time allowed for a worker to reach the scheduler [s].
    """
    import dask
    from distributed import LocalCluster

    n_workers = check_int("n_workers", n_workers, lo=1, hi=256)
    timeout = check_number("timeout", timeout, unit="s", lo=0.0, lo_open=True)
    one = {k: "1" for k in _THREAD_VARS}
    saved = {k: os.environ.get(k) for k in _THREAD_VARS}
    # Nanny reads "pre-spawn-environ" (overridden by os.environ) when it is created and sets
    # it in the worker's environment before spawning; restore ours once the workers run.
    os.environ.update(one)
    try:
        with dask.config.set(
            {
                "distributed.nanny.pre-spawn-environ": one,
                "distributed.comm.timeouts.connect": f"{timeout}s",
            }
        ):
            cluster = LocalCluster(
                n_workers=n_workers,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address=None,
                # no dashboard; its HTTP server (health checks) on a free loopback port
                scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
                env=one,
                death_timeout=timeout,
            )
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    try:
        yield cluster
    finally:
        cluster.close()


def _check_address(scheduler: str) -> str:
    if not isinstance(scheduler, str) or not _ADDRESS_RE.fullmatch(scheduler.strip()):
        raise InputError(
            f"scheduler = {scheduler!r}: expected a Dask scheduler address 'tcp://host:port'"
        )
    return scheduler.strip()


def _read_case(path: Path, cid: str) -> dict | None:
    """A finished case file, or None if it is missing or not a finished case of this id."""
    try:
        rec = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(rec, dict) or rec.get("case_id") != cid:
        return None
    if rec.get("status") not in ("ok", "failed"):
        return None
    return rec


def _write_case(cases_dir: Path, rec: dict) -> None:
    atomic_write_text(
        cases_dir / f"{rec['case_id']}.json", json.dumps(rec, indent=1, allow_nan=False) + "\n"
    )


def _manifest(study: TradeStudy, cases: list[dict]) -> dict:
    return {
        "format": FORMAT,
        "name": study.name,
        "parameters": {k: list(v) for k, v in study.parameters.items()},
        "fingerprint": _digest(study_settings(study)),
        "settings": study_settings(study),
        "case_ids": [c["case_id"] for c in cases],
        "csv": f"{study.name}.csv",
        "netcdf": f"{study.name}.nc",
    }


def run_trade(
    study: TradeStudy,
    out_dir: str | Path,
    *,
    scheduler: str | None = None,
    n_workers: int = 2,
    progress: bool = True,
    timeout: float = 60.0,
) -> TradeResult:
    """Run a trade study on Dask, skipping the cases already finished in ``out_dir``.

    Parameters
    ----------
    study : TradeStudy
    out_dir : str or Path
        Output folder (created): ``cases/<case_id>.json`` per case, ``<name>.csv``,
        ``<name>.nc`` and ``study.json``.
    scheduler : str, optional
        Address ``tcp://host:port`` of a running Dask scheduler whose workers can import this
        version of aeroservo. Default: a local cluster of ``n_workers`` processes.
    n_workers : int
        Worker processes of the local cluster.
    progress : bool
        Show a tqdm progress bar over the cases as they finish.
    timeout : float
        Time allowed to start or reach the cluster [s].

    Returns
    -------
    TradeResult

    Notes
    -----
    Each case's file is written as soon as its result arrives, so an interrupted run loses only
    the cases in flight. A case whose evaluation failed is a finished case (recorded with its
    message); a case lost to the cluster itself (e.g. a worker killed) is reported in the
    table but not written, so that the next run tries it again.
    """
    t_start = time.perf_counter()
    if not isinstance(study, TradeStudy):
        raise InputError(f"study = {study!r}: expected a TradeStudy")
    if scheduler is not None:
        scheduler = _check_address(scheduler)
    n_workers = check_int("n_workers", n_workers, lo=1, hi=256)
    timeout = check_number("timeout", timeout, unit="s", lo=0.0, lo_open=True)
    out = Path(out_dir)
    cases_dir = out / "cases"
    cases_dir.mkdir(parents=True, exist_ok=True)

    cases = trade_cases(study)
    records: dict[str, dict] = {}
    for c in cases:
        rec = _read_case(cases_dir / f"{c['case_id']}.json", c["case_id"])
        if rec is not None:
            records[c["case_id"]] = rec
    n_skipped = len(records)
    manifest = _manifest(study, cases)
    atomic_write_text(out / "study.json", json.dumps(manifest, indent=1) + "\n")

    pending = [c for c in cases if c["case_id"] not in records]
    if pending:
        records.update(
            _run_pending(
                study, pending, cases_dir, scheduler, n_workers, progress, timeout, n_skipped
            )
        )

    rows = [records[c["case_id"]] for c in cases]
    result = _assemble(study.name, study.parameters, rows, manifest["settings"])
    result.n_skipped = n_skipped
    result.csv_path = atomic_write(
        out / manifest["csv"], lambda p: result.table.to_csv(p, index=False)
    )
    result.netcdf_path = atomic_write(
        out / manifest["netcdf"],
        lambda p: result.dataset.to_netcdf(p, engine="scipy", format="NETCDF3_64BIT"),
    )
    result.elapsed = time.perf_counter() - t_start
    return result


def _run_pending(
    study: TradeStudy,
    pending: list[dict],
    cases_dir: Path,
    scheduler: str | None,
    n_workers: int,
    progress: bool,
    timeout: float,
    n_skipped: int,
) -> dict[str, dict]:
    from distributed import Client, as_completed
    from tqdm import tqdm

    done: dict[str, dict] = {}
    with contextlib.ExitStack() as stack:
        if scheduler is None:
            cluster = stack.enter_context(local_cluster(n_workers, timeout=timeout))
            address = cluster.scheduler_address
        else:
            address = scheduler
        try:
            client = stack.enter_context(Client(address, timeout=f"{timeout}s"))
        except (OSError, TimeoutError) as exc:
            raise InputError(
                f"scheduler = {address!r}: cannot connect within {timeout:g} s ({exc})"
            ) from None
        try:
            probes = client.run(_worker_probe)
        except Exception as exc:
            raise RuntimeError(
                f"the workers of {address} cannot run aeroservo.trade "
                f"({type(exc).__name__}: {exc}); install aeroservo on them"
            ) from exc
        here = _worker_probe()["aeroservo"]
        other = {w: p["aeroservo"] for w, p in probes.items() if p["aeroservo"] != here}
        if other:
            raise RuntimeError(
                f"the workers of {address} run other aeroservo versions {other} than this "
                f"process ({here}); the case ids and results would not match"
            )
        [study_f] = client.scatter([study], broadcast=True)
        futures = client.map(
            _case_task,
            [study_f] * len(pending),
            [{k: v for k, v in c.items() if k != "case_id"} for c in pending],
            key=[f"trade-{study.name}-{c['case_id']}" for c in pending],
            pure=False,
        )
        ids = {f.key: c["case_id"] for f, c in zip(futures, pending, strict=True)}
        params = {c["case_id"]: c for c in pending}
        bar = stack.enter_context(
            tqdm(total=len(pending), desc=study.name, unit="case", disable=not progress)
        )
        if n_skipped:
            bar.set_postfix(skipped=n_skipped)
        try:
            for fut, res in as_completed(futures, with_results=True, raise_errors=False):
                cid = ids[fut.key]
                if fut.status == "finished" and isinstance(res, dict):
                    _write_case(cases_dir, res)
                else:  # lost to the cluster: reported, not written (retried next run)
                    lost = _blank(params[cid])
                    lost.update(
                        case_id=cid, failed_stage="cluster", error=f"not evaluated: {res!r}"
                    )
                    res = lost
                done[cid] = res
                fut.release()
                bar.update(1)
        finally:
            client.cancel([f for f in futures if not f.done()])
    return done


# --------------------------------------------------------------------------------------------
# Results
# --------------------------------------------------------------------------------------------


@dataclass
class TradeResult:
    """Results of a trade study.

    Attributes
    ----------
    name : str
    parameters : dict
        ``{name: values}`` of the swept parameters (the dataset's dimensions).
    table : pandas.DataFrame
        One row per case, in grid order: ``case_id``, the parameters, ``status``,
        ``failed_stage``, ``error`` and the metrics (NaN when unavailable).
    dataset : xarray.Dataset
        One dimension per parameter, one variable per metric (units in ``attrs``), plus
        ``case_id``, ``status`` and ``error``.
    csv_path, netcdf_path : Path or None
    n_skipped : int
        Cases already finished before this run.
    n_failed : int
        Cases that failed.
    elapsed : float
        Wall time of the run [s].
    settings : dict
        The study's fixed settings (:func:`study_settings`).
    """

    name: str
    parameters: dict
    table: object
    dataset: object
    settings: dict = field(default_factory=dict)
    csv_path: Path | None = None
    netcdf_path: Path | None = None
    n_skipped: int = 0
    elapsed: float = 0.0

    @property
    def n_cases(self) -> int:
        return len(self.table)

    @property
    def n_failed(self) -> int:
        return int((self.table["status"] != "ok").sum())

    def __repr__(self) -> str:
        dims = " x ".join(f"{k}[{len(v)}]" for k, v in self.parameters.items())
        return (
            f"TradeResult({self.name!r}: {dims} = {self.n_cases} cases, {self.n_failed} failed, "
            f"{self.n_skipped} skipped, {self.elapsed:.1f} s)"
        )

    def heatmap(
        self,
        metric: str = "closed_loop_flutter_speed",
        x: str | None = None,
        y: str | None = None,
        **fixed: float,
    ):
        """Heat map of a metric over two parameters.

        Parameters
        ----------
        metric : str
            A name of :data:`METRICS`.
        x, y : str, optional
            Swept parameters on the axes (default: the first two).
        **fixed
            The other parameters' positions: an ``int`` is an index into the parameter's
            values, a ``float`` a value (the nearest one); default: the first value.

        Returns
        -------
        matplotlib.figure.Figure
        """
        return _heatmap(self.dataset, self.parameters, metric, x, y, fixed)

    def pareto(self):
        """Suppression margin versus peak hinge moment, the Pareto front highlighted.

        Returns
        -------
        matplotlib.figure.Figure
        """
        return _pareto(self.table, self.name)


def _assemble(name: str, parameters: dict, rows: list[dict], settings: dict):
    import pandas as pd
    import xarray as xr

    names = list(parameters)
    cols = ["case_id", *names, *_TEXT, *METRICS]
    table = pd.DataFrame([{c: r.get(c) for c in cols} for r in rows], columns=cols)
    for m in METRICS:
        table[m] = pd.to_numeric(table[m].astype(object).where(table[m].notna(), np.nan))
        table[m] = table[m].astype(float)
    for c in ("case_id", *_TEXT):
        table[c] = table[c].where(table[c].notna(), "").astype(str)
    shape = tuple(len(v) for v in parameters.values())
    data_vars = {}
    for m, (unit, desc) in METRICS.items():
        data_vars[m] = (
            names,
            table[m].to_numpy().reshape(shape),
            {"units": unit, "long_name": desc},
        )
    for c in ("case_id", *_TEXT):
        arr = np.array(table[c].tolist(), dtype=object).reshape(shape)
        data_vars[c] = (names, arr)
    coords = {
        k: (
            k,
            np.asarray(v, dtype=float),
            {"units": PARAMETERS[k][0], "long_name": PARAMETERS[k][1]},
        )
        for k, v in parameters.items()
    }
    ds = xr.Dataset(
        data_vars,
        coords=coords,
        attrs={
            "title": f"aeroservo trade study {name!r}",
            "study": name,
            "format": FORMAT,
            "settings": json.dumps(settings, sort_keys=True),
        },
    )
    return TradeResult(
        name=name, parameters=dict(parameters), table=table, dataset=ds, settings=settings
    )


def load_trade(out_dir: str | Path) -> TradeResult:
    """Re-read a finished study from its folder (for re-plotting).

    Parameters
    ----------
    out_dir : str or Path
        The ``out_dir`` of :func:`run_trade`.

    Returns
    -------
    TradeResult
        Table from the CSV, dataset from the NetCDF file (``n_skipped`` = number of cases).
    """
    import pandas as pd
    import xarray as xr

    out = Path(out_dir)
    try:
        manifest = json.loads((out / "study.json").read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError(f"out_dir = {str(out)!r}: no readable study.json ({exc})") from None
    if manifest.get("format") != FORMAT:
        raise InputError(
            f"{out / 'study.json'}: format = {manifest.get('format')!r}; expected {FORMAT!r}"
        )
    csv, nc = out / manifest["csv"], out / manifest["netcdf"]
    for p in (csv, nc):
        if not p.is_file():
            raise InputError(f"{p}: missing; the study has not finished (run it again)")
    table = pd.read_csv(csv, keep_default_na=False, na_values={m: ["", "NaN"] for m in METRICS})
    for c in ("case_id", *_TEXT):
        table[c] = table[c].astype(str)
    with xr.open_dataset(nc, engine="scipy") as ds:
        dataset = ds.load()
    params = {k: tuple(float(x) for x in v) for k, v in manifest["parameters"].items()}
    result = TradeResult(
        name=manifest["name"],
        parameters=params,
        table=table,
        dataset=dataset,
        settings=manifest.get("settings", {}),
        csv_path=csv,
        netcdf_path=nc,
        n_skipped=len(table),
    )
    return result


# --------------------------------------------------------------------------------------------
# Plots
# --------------------------------------------------------------------------------------------


def _label(name: str) -> str:
    unit = (PARAMETERS.get(name) or METRICS.get(name) or ("-",))[0]
    return f"{name} [{unit}]"


def _heatmap(ds, parameters: dict, metric: str, x, y, fixed: dict):
    from matplotlib.figure import Figure

    names = list(parameters)
    if metric not in METRICS:
        raise InputError(f"metric = {metric!r}: unknown; known are {list(METRICS)}")
    if len(names) < 2:
        raise InputError(f"heatmap: needs two swept parameters; this study sweeps {names}")
    x = names[0] if x is None else x
    y = (names[1] if names[1] != x else names[0]) if y is None else y
    for key, v in (("x", x), ("y", y)):
        if v not in names:
            raise InputError(f"{key} = {v!r}: not a swept parameter; swept are {names}")
    if x == y:
        raise InputError(f"x = y = {x!r}: give two different parameters")
    sel: dict = {}
    for k, v in fixed.items():
        if k not in names or k in (x, y):
            others = [n for n in names if n not in (x, y)]
            raise InputError(f"{k} = {v!r}: not a parameter to fix; the others are {others}")
        vals = parameters[k]
        if isinstance(v, (int, np.integer)) and not isinstance(v, bool):
            sel[k] = check_int(f"{k} (index)", v, lo=0, hi=len(vals) - 1)
        else:
            v = check_number(k, v)
            sel[k] = int(np.argmin(np.abs(np.asarray(vals) - v)))
    for k in names:
        if k not in (x, y):
            sel.setdefault(k, 0)
    da = ds[metric].isel(sel).transpose(y, x)
    z = np.ma.masked_invalid(np.asarray(da.values, dtype=float))
    failed = np.asarray(ds["status"].isel(sel).transpose(y, x).values).astype(str) != "ok"
    xs, ys = parameters[x], parameters[y]

    fig = Figure(
        layout="constrained", figsize=(1.2 + 0.9 * max(len(xs), 4), 1.0 + 0.6 * max(len(ys), 4))
    )
    ax = fig.subplots()
    import matplotlib

    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="0.85")
    im = ax.imshow(z, origin="lower", aspect="auto", cmap=cmap, interpolation="nearest")
    ax.set_xticks(range(len(xs)), [f"{v:.4g}" for v in xs])
    ax.set_yticks(range(len(ys)), [f"{v:.4g}" for v in ys])
    ax.set_xlabel(_label(x))
    ax.set_ylabel(_label(y))
    fig.colorbar(im, ax=ax, label=_label(metric))
    if z.size <= 400:
        lo, hi = (float(z.min()), float(z.max())) if z.count() else (0.0, 1.0)
        for (i, j), v in np.ndenumerate(z.filled(np.nan)):
            if np.isfinite(v):
                dark = (v - lo) < 0.5 * (hi - lo) if hi > lo else True
                ax.text(
                    j,
                    i,
                    f"{v:.4g}",
                    ha="center",
                    va="center",
                    fontsize=7,
                    color="w" if dark else "k",
                )
            else:
                text = "failed" if failed[i, j] else "n/a"
                ax.text(j, i, text, ha="center", va="center", fontsize=7, color="0.4")
    rest = [f"{k} = {parameters[k][i]:.4g}" for k, i in sel.items()]
    ax.set_title(f"{metric}" + (f" ({', '.join(rest)})" if rest else ""), fontsize=9)
    return fig


def pareto_front(margin: Sequence[float], peak: Sequence[float]) -> np.ndarray:
    """Mask of the Pareto-optimal points: no other point has a margin at least as high and a
    peak hinge moment at least as low, one of them strictly (NaN points are never optimal)."""
    m = np.asarray(margin, dtype=float)
    h = np.asarray(peak, dtype=float)
    ok = np.isfinite(m) & np.isfinite(h)
    front = np.zeros(m.shape, dtype=bool)
    for i in np.flatnonzero(ok):
        better = ok & (m >= m[i]) & (h <= h[i]) & ((m > m[i]) | (h < h[i]))
        front[i] = not better.any()
    return front


def _pareto(table, name: str):
    from matplotlib.figure import Figure

    t = table
    ok = (t["status"] == "ok").to_numpy()
    margin = t["suppression_margin"].to_numpy(dtype=float).copy()
    # stable up to the end of the search: the margin is at least v_max / V_ol - 1
    bound = (
        ok
        & ~np.isfinite(margin)
        & (t["stable_at_design"].to_numpy(dtype=float) == 1.0)
        & np.isfinite(t["closed_loop_v_max"].to_numpy(dtype=float))
    )
    v_ol = t["open_loop_flutter_speed"].to_numpy(dtype=float)
    margin[bound] = t["closed_loop_v_max"].to_numpy(dtype=float)[bound] / v_ol[bound] - 1.0
    peak = t["hinge_moment_peak"].to_numpy(dtype=float)
    usable = ok & np.isfinite(margin) & np.isfinite(peak)
    unstable = usable & (t["stable_at_design"].to_numpy(dtype=float) != 1.0)
    front = pareto_front(np.where(usable & ~unstable, margin, np.nan), peak)

    fig = Figure(layout="constrained", figsize=(6.5, 4.5))
    ax = fig.subplots()
    plain = usable & ~front & ~bound & ~unstable
    ax.scatter(peak[plain], margin[plain], s=18, color="C0", alpha=0.6, label="case")
    if bound.any():
        ax.scatter(
            peak[bound & usable],
            margin[bound & usable],
            marker="^",
            s=30,
            color="C2",
            label="stable to search limit (margin >=)",
        )
    if unstable.any():
        ax.scatter(
            peak[unstable],
            margin[unstable],
            marker="x",
            s=30,
            color="C3",
            label="unstable at design speed",
        )
    if front.any():
        order = np.argsort(peak[front])
        ax.plot(
            peak[front][order], margin[front][order], "o-", color="C1", ms=6, label="Pareto front"
        )
    n_bad = int((~usable).sum())
    ax.set_xlabel(_label("hinge_moment_peak"))
    ax.set_ylabel(_label("suppression_margin"))
    ax.axhline(0.0, color="k", lw=0.8)
    ax.grid(True, alpha=0.3)
    ax.set_title(
        f"{name}: {int(usable.sum())} cases" + (f", {n_bad} without result" if n_bad else ""),
        fontsize=9,
    )
    if usable.any():
        ax.legend(fontsize=8)
    return fig
