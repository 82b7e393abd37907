"""The grid of a trade study: its fixed settings, stable case ids and the list of cases."""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
from collections.abc import Mapping

import numpy as np

from ...errors import InputError
from .study import FORMAT, TradeStudy

__all__ = ["study_settings", "case_id", "trade_cases"]


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
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if callable(obj):  # a Python law: named, not hashed (trade studies refuse it anyway)
        return getattr(obj, "__qualname__", repr(obj))
    return obj


def study_settings(study: TradeStudy) -> dict:
    """The fixed settings of a study (everything but the swept values and the name).

    These, with the format version and the aeroservo version, enter every case id: a study
    whose settings change gets new case ids and never reuses stale case files.
    """
    from ..._version import __version__

    s: dict = {
        "format": FORMAT,
        "aeroservo": __version__,
        "base_wing": _jsonable(study.base_wing),
        "density": study.density,
        "elements": study.elements,
        "wagner": study.wagner,
        "closed_loop": study.closed_loop,
    }
    if study.damping.active:  # only then: undamped studies keep their case ids
        s["damping"] = study.damping.to_dict()
    if study.aero is not None:  # the doublet lattice (strip studies keep their case ids)
        s["aero"] = study.aero.to_dict()
    if study.closed_loop:
        spec = _jsonable(study.controller)
        for k in ("name", "source"):  # labels only: they do not change the results
            spec.pop(k, None)
        for k in ("linear", "gain", "python", "input_noise"):  # unset: ids as before them
            if not spec.get(k):
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
        s["delay"] = study.delay
        if study.actuator:  # by control (TradeStudy makes it a dict)
            s["actuator"] = {c: _jsonable(a) for c, a in sorted(study.actuator.items())}
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
