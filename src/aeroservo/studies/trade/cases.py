"""One case of a trade study: the variant wing, its open-loop boundary, the controller, the
closed-loop boundary and the gust response (:func:`evaluate_case` never raises)."""

from __future__ import annotations

import dataclasses
import math
import time
import traceback
from collections import OrderedDict
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ...errors import InputError, check_number
from ...structure.wing import Actuator, Wing
from .grid import case_id
from .mass_parameters import with_masses
from .study import _DOMAINS, METRICS, PARAMETERS, TradeStudy

__all__ = ["variant_wing", "evaluate_case"]


def variant_wing(study: TradeStudy, params: Mapping) -> Wing:
    """The base wing with the design parameters of ``params`` applied.

    Controller parameters (``bryson_hinge_moment``, ``speed_factor``) are ignored here; the
    concentrated masses' (``masses[i].mass`` ...) set the base wing's masses.

    Raises
    ------
    InputError
        If a parameter is unknown or the variant is invalid (e.g. an actuator outside the
        aileron, a hinge ahead of the elastic axis); the message names the field and value.
    """
    for k in params:
        if k != "case_id" and k not in PARAMETERS:
            raise InputError(f"parameters.{k}: unknown parameter; known are {sorted(PARAMETERS)}")
    wing = with_masses(study.base_wing, params)
    cs = wing.control_surfaces[0] if wing.control_surfaces else None
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
    from ...stability.boundary import flutter_boundary
    from ...system.aeroelastic import AeroelasticModel

    key = (repr(wing), study.density, study.elements, study.wagner, study.damping, study.aero)
    hit = _CACHE.get(key)
    if hit is not None:
        _CACHE.move_to_end(key)
        return hit
    aero = "strip" if study.aero is None else study.aero
    model = AeroelasticModel(wing, study.elements, study.wagner, damping=study.damping, aero=aero)
    entry = {"model": model, "flutter": flutter_boundary(model, study.density), "loops": {}}
    _CACHE[key] = entry
    while len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return entry


def _loop(study: TradeStudy, entry: dict):
    from ...design.loop import ControlLoop

    key = (
        study.controls,
        study.sensors,
        study.outputs,
        study.design_modes,
        study.sensor_filter,
        study.filter_order,
        study.gust_model,
        tuple(sorted((study.actuator or {}).items())),
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
            actuator=study.actuator,
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
    from ...aero.gusts import OneMinusCosine
    from ...design.closed_loop import closed_loop_boundary
    from ...simulate.march import simulate

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
    b = closed_loop_boundary(
        loop, ctrl, v_max, n_grid=study.n_grid, reference_speed=speed, delay=study.delay
    )
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
    if stable:
        from ...design.margins import loop_margins

        rec["closed_loop_lower_speed"] = _num(b.lower_speed)
        ch = loop_margins(loop.plant(speed), ctrl, sensors=False, delay=study.delay)
        ch = ch.channels[study.controls[0]]
        for key in ("gain_margin_db", "gain_reduction_margin_db", "phase_margin_deg"):
            rec[key] = _num(getattr(ch, key))
        rec["disk_margin"] = _num(ch.disk_margin)

    stage[0] = "gust"
    gust = OneMinusCosine(study.gust_length, study.gust_amplitude, 0.0)
    control = study.controls[0]
    plant = loop.plant(speed)
    applied = [n for n in (control + "_actuator",) if n in plant.output_labels]
    sim = simulate(
        plant,
        ctrl,
        duration=study.gust_duration,
        disturbance=gust,
        limits=spec.limits,
        delay=study.delay,
        outputs=["tip_accel"] + applied,
    )
    u = sim.outputs.get(control + "_actuator", sim.applied[control])  # what the surface gets
    u = np.asarray(u, dtype=float)
    a = np.asarray(sim.outputs["tip_accel"], dtype=float)
    rec["hinge_moment_peak"] = _num(np.max(np.abs(u)))
    rec["hinge_moment_rms"] = _num(np.sqrt(np.mean(u**2)))
    rec["hinge_moment_saturation"] = _num(sim.saturated_fraction[control])
    rec["tip_accel_peak"] = _num(np.max(np.abs(a)))
    rec["tip_accel_rms"] = _num(np.sqrt(np.mean(a**2)))
