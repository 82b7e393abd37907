"""Result files: a simulation as one ``.npz`` (time histories and a JSON ``meta`` record with
units, limits and the summary) or a flutter sweep (:mod:`.flutter_file`), read back for
re-plotting. No pickled objects.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..atomic import atomic_write
from ..errors import InputError
from .summaries import json_text

__all__ = ["save_result", "load_result", "result_writer"]


def result_writer(result, summary: dict | None = None):
    """A writer of a simulation result's ``.npz`` for :func:`aeroservo.atomic.atomic_write_set`."""
    arrays = {"t": result.t}
    for group in ("outputs", "commands", "applied", "disturbance"):
        for name, y in getattr(result, group).items():
            arrays[f"{group}.{name}"] = np.asarray(y)
    meta = {
        "units": result.units,
        "speed": result.speed,
        "density": result.density,
        "limits": {"magnitude": result.limits.magnitude, "rate": result.limits.rate},
        "summary": summary or {},
        "format": "aeroservo-simulation-1",
    }
    arrays["meta"] = np.array(json_text(meta))

    def write(p: Path) -> None:
        with open(p, "wb") as fh:
            np.savez_compressed(fh, **arrays)

    return write


def save_result(result, path: str | Path, summary: dict | None = None, **kw) -> Path:
    """Write a result to ``.npz`` (atomically): a simulation, or a flutter sweep.

    Parameters
    ----------
    result : SimulationResult or FlutterResult
    path : str or Path
    summary : dict, optional
        Summary stored with a simulation.
    **kw
        For a flutter sweep, :func:`aeroservo.files.flutter_file.flutter_writer`'s
        ``wing_text``, ``model``, ``pk`` and ``title`` (``wing_text`` defaults to the model's
        wing written as a wing file).
    """
    from ..stability.result import FlutterResult

    if isinstance(result, FlutterResult):
        from .flutter_file import flutter_writer
        from .wing_file import wing_toml

        model = kw.get("model")
        if "wing_text" not in kw:
            if model is None or not hasattr(model, "wing"):
                raise InputError("save_result: give wing_text= or model= for a flutter result")
            kw["wing_text"] = wing_toml(model.wing)
        return atomic_write(path, flutter_writer(result, **kw))
    if not hasattr(result, "outputs"):
        raise InputError(
            f"save_result: result = {type(result).__name__}: expected a SimulationResult or a "
            "FlutterResult"
        )
    return atomic_write(path, result_writer(result, summary))


def _load_envelope(path: Path):
    """A flutter envelope saved by ``aeroservo envelope --save FILE.json``."""
    from ..studies.envelope import Envelope
    from .user_files import read_text

    text = read_text(path, what="saved envelope (JSON)")
    try:
        data = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        raise InputError(f"{path}: not an aeroservo envelope (not valid JSON: {exc})") from None
    if not isinstance(data, dict) or data.get("format") != "aeroservo-envelope-1":
        raise InputError(
            f"{path}: not a saved aeroservo result (a JSON summary? save a sweep with "
            "'aeroservo flutter ... --save FILE.npz', an envelope with 'aeroservo envelope ... "
            "--save FILE.json')"
        )
    try:
        return Envelope.from_dict(data)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None


def load_result(path: str | Path):
    """Read a result written by :func:`save_result`: a ``SimulationResult``, a
    :class:`~aeroservo.files.flutter_file.SavedFlutter` for a flutter sweep, a trade study's
    folder (``TradeResult``), a flutter envelope saved as JSON (``Envelope``), a gust-loads
    result's JSON (``GustLoadsResult``) or a limit-cycle result's JSON (``LCOResult``, with its
    time histories when its NPZ is next to it)."""
    from .flutter_file import FORMAT, open_npz, read_flutter
    from .user_files import user_path

    path = user_path(path, "result file")
    if path.is_dir():
        from ..studies.trade.results import load_trade

        return load_trade(path)
    if path.suffix.lower() == ".json":
        from .gust_loads_file import is_gust_loads_file, load_gust_loads
        from .lco_file import is_lco_file, load_lco

        if is_gust_loads_file(path):
            return load_gust_loads(path)
        if is_lco_file(path):
            return load_lco(path)
        return _load_envelope(path)
    data, meta = open_npz(path)
    fmt = meta.get("format")
    if fmt == FORMAT:
        return read_flutter(path, data, meta)
    if fmt != "aeroservo-simulation-1":
        raise InputError(f"{path}: not an aeroservo result (format {fmt!r})")
    from ..design.plant import Limits
    from ..simulate.result import SimulationResult

    groups: dict = {"outputs": {}, "commands": {}, "applied": {}, "disturbance": {}}
    for key, value in data.items():
        if "." in key:
            g, name = key.split(".", 1)
            if g in groups:
                groups[g][name] = value
    t = data.get("t")
    if t is None or t.ndim != 1 or t.dtype.kind != "f":
        raise InputError(f"{path}: simulation result without a 1-D time array 't'")
    for g, sig in groups.items():
        for name, y in sig.items():
            if y.dtype.kind not in "fiub" or y.shape[:1] != t.shape:
                raise InputError(f"{path}: signal {g}.{name} does not match the {t.size} times")
    if set(groups["commands"]) != set(groups["applied"]) or not groups["outputs"]:
        raise InputError(
            f"{path}: simulation result without matching commands and applied controls "
            f"({sorted(groups['commands'])} vs {sorted(groups['applied'])}) or without outputs"
        )
    try:
        return SimulationResult(
            t=t,
            status=[],
            limits=Limits(**meta["limits"]),
            units=dict(meta["units"]),
            speed=float(meta["speed"]),
            density=float(meta["density"]),
            summary=dict(meta.get("summary", {})),
            **groups,
        )
    except (KeyError, TypeError, ValueError, InputError) as exc:
        raise InputError(f"{path}: header of the simulation result is not valid ({exc})") from None
