"""Result files: :func:`save_result` writes any result as the command line does (every result
has ``save()``, :mod:`aeroservo.result_shape`) and :func:`load_result` reads it back.

A simulation is one ``.npz`` (time histories and a JSON ``meta`` record with units, limits and
the summary); a flutter sweep one ``.npz`` too (:mod:`.flutter_file`); gust loads
(:mod:`.gust_loads_file`) and limit cycles (:mod:`.lco_file`) a ``.json`` with files next to
it; a trade study a folder (``study.json``, its CSV and NetCDF files); a flutter envelope a
``.json``; a closed-loop boundary, loop margins, a margin sweep and a recoverable set a
``.npz`` (:mod:`.result_state`). No pickled objects.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..atomic import atomic_write, atomic_write_set, atomic_write_text
from ..errors import InputError
from .summaries import json_text

__all__ = ["save_result", "load_result", "result_writer"]


def result_writer(result, summary: dict | None = None):
    """A writer of a simulation result's ``.npz`` for :func:`aeroservo.atomic.atomic_write_set`
    (``summary``: the run's summary; default the result's ``run_summary``)."""
    arrays = {"t": result.t}
    for group in ("outputs", "commands", "applied", "disturbance"):
        for name, y in getattr(result, group).items():
            arrays[f"{group}.{name}"] = np.asarray(y)
    meta = {
        "units": result.units,
        "speed": result.speed,
        "density": result.density,
        "limits": {"magnitude": result.limits.magnitude, "rate": result.limits.rate},
        "summary": dict(result.run_summary) if summary is None else summary,
        "format": "aeroservo-simulation-1",
    }
    arrays["meta"] = np.array(json_text(meta))

    def write(p: Path) -> None:
        with open(p, "wb") as fh:
            np.savez_compressed(fh, **arrays)

    return write


def save_result(result, path: str | Path, summary: dict | None = None, **kw) -> Path:
    """Write a result as the command line does, atomically (all its files or none).

    ============================  ==========================================================
    result                        file(s)
    ============================  ==========================================================
    FlutterResult                 ``.npz`` (needs the wing: ``model=`` or ``wing_text=``)
    SavedFlutter                  the same ``.npz`` again
    SimulationResult              ``.npz``
    GustLoadsResult               ``.json`` with ``.npz``, ``.csv`` next to it
    LCOResult                     ``.json`` with ``.csv``, ``_histories.npz``, ... next to it
    TradeResult                   a folder: ``study.json``, ``<name>.csv``, ``<name>.nc``
    Envelope                      ``.json``
    ClosedLoopBoundary,           ``.npz`` (:mod:`aeroservo.files.result_state`)
    LoopMargins, MarginSweep,
    RecoverableSet
    ============================  ==========================================================

    Parameters
    ----------
    result
        Any aeroservo result.
    path : str or Path
        The file (or a trade study's folder) :func:`load_result` reads back.
    summary : dict, optional
        The run summary stored with a simulation, gust loads or limit cycles.
    **kw
        For a flutter sweep, :func:`aeroservo.files.flutter_file.flutter_writer`'s
        ``wing_text``, ``model``, ``pk`` and ``title`` (``wing_text`` defaults to the model's
        wing written as a wing file).

    Returns
    -------
    Path
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
    if kw:
        raise InputError(
            f"save_result: {', '.join(kw)} = ...: options of a FlutterResult, not of a "
            f"{type(result).__name__}"
        )
    write = _writer(result, path, summary)
    if write is None:
        raise InputError(
            f"save_result: result = {type(result).__name__}: not an aeroservo result with a file"
        )
    return write()


_WITH_SUMMARY = ("SimulationResult", "GustLoadsResult", "LCOResult")
_KINDS = (*_WITH_SUMMARY, "SavedFlutter", "Envelope", "TradeResult")


def _writer(result, path, summary: dict | None):
    """A function that writes ``result`` to ``path`` and returns the path, or None (the
    result's class, or the aeroservo class it derives from, names its file; only that file's
    module is imported)."""
    from .result_state import format_of, state_writer

    mro = [c.__name__ for c in type(result).__mro__ if c.__module__.startswith("aeroservo.")]
    kind = next((n for n in mro if n in _KINDS), None)
    if summary is not None and kind not in _WITH_SUMMARY:
        raise InputError(f"save_result: summary = ...: not stored with a {type(result).__name__}")
    if kind == "SimulationResult":
        return lambda: atomic_write(path, result_writer(result, summary))
    if kind == "SavedFlutter":
        from .flutter_file import saved_writer

        return lambda: atomic_write(path, saved_writer(result))
    if kind == "GustLoadsResult":
        from .gust_loads_file import write_gust_loads

        return lambda: Path(write_gust_loads(result, path, summary)["summary"])
    if kind == "LCOResult":
        from .lco_file import write_lco

        return lambda: Path(write_lco(result, path, summary)["summary"])
    if kind == "Envelope":
        from .user_files import json_output

        text = json_text({"format": "aeroservo-envelope-1", **result.to_dict()})
        return lambda: atomic_write_text(json_output(path, "flutter envelope (.json)"), text)
    if kind == "TradeResult":
        return lambda: _save_trade(result, Path(path))
    if format_of(result) is not None:
        return lambda: atomic_write(path, state_writer(result))
    return None


def _save_trade(result, folder: Path) -> Path:
    """A trade study's folder as a run leaves it (without the case store ``cases/``)."""
    from ..studies.trade.grid import _digest
    from ..studies.trade.study import FORMAT

    if folder.suffix:
        raise InputError(f"path = {str(folder)!r}: a trade study is saved as a folder (no suffix)")
    if not folder.parent.is_dir():
        raise InputError(f"path = {str(folder)!r}: folder {str(folder.parent)!r} does not exist")
    folder.mkdir(exist_ok=True)
    manifest = {
        "format": FORMAT,
        "name": result.name,
        "parameters": {k: list(v) for k, v in result.parameters.items()},
        "fingerprint": _digest(result.settings),
        "settings": result.settings,
        "case_ids": list(result.table["case_id"]),
        "csv": f"{result.name}.csv",
        "netcdf": f"{result.name}.nc",
    }
    text = json.dumps(manifest, indent=1) + "\n"
    nc = result.dataset
    atomic_write_set(
        [
            (folder / "study.json", lambda p: p.write_text(text, encoding="utf-8")),
            (folder / manifest["csv"], lambda p: result.table.to_csv(p, index=False)),
            (folder / manifest["netcdf"],
             lambda p: nc.to_netcdf(p, engine="scipy", format="NETCDF3_64BIT")),
        ]
    )  # fmt: skip
    return folder


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
    """Read a result written by :func:`save_result` (or by the command line): a
    ``SimulationResult``, a :class:`~aeroservo.files.flutter_file.SavedFlutter` for a flutter
    sweep, a trade study's folder (``TradeResult``), a flutter envelope saved as JSON
    (``Envelope``), a gust-loads result's JSON (``GustLoadsResult``), a limit-cycle result's
    JSON (``LCOResult``, with its time histories when its NPZ is next to it), or a
    ``ClosedLoopBoundary``, ``LoopMargins``, ``MarginSweep`` or ``RecoverableSet``
    (:mod:`.result_state`); a nonlinear-hinge march (``HingeSimulation``) reads back as a
    ``SimulationResult``."""
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
    from .result_state import FORMATS, read_state

    if fmt in FORMATS:
        return read_state(path, data, meta)
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
            run_summary=dict(meta.get("summary", {})),
            **groups,
        )
    except (KeyError, TypeError, ValueError, InputError) as exc:
        raise InputError(f"{path}: header of the simulation result is not valid ({exc})") from None
