"""Result files: a simulation as one ``.npz`` (time histories and a JSON ``meta`` record with
units, limits and the summary), read back for re-plotting. No pickled objects.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..atomic import atomic_write
from ..errors import InputError

__all__ = ["save_result", "load_result", "result_writer", "json_text"]


def json_text(obj: object) -> str:
    """JSON text of a summary (numpy scalars and arrays as plain numbers and lists)."""

    def default(o):
        if isinstance(o, np.generic):
            return o.item()
        if isinstance(o, np.ndarray):
            return o.tolist()
        return str(o)

    return json.dumps(obj, indent=2, default=default)


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


def save_result(result, path: str | Path, summary: dict | None = None) -> Path:
    """Write a simulation result to ``.npz`` (atomically)."""
    return atomic_write(path, result_writer(result, summary))


def load_result(path: str | Path):
    """Read a result written by :func:`save_result` back into a ``SimulationResult``."""
    from ..design.plant import Limits
    from ..simulate.result import SimulationResult

    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
            groups: dict = {"outputs": {}, "commands": {}, "applied": {}, "disturbance": {}}
            for key in data.files:
                if "." in key:
                    g, name = key.split(".", 1)
                    if g in groups:
                        groups[g][name] = data[key]
            t = data["t"]
    except FileNotFoundError:
        raise InputError(f"{path}: no such result file") from None
    except (OSError, ValueError, KeyError) as exc:
        raise InputError(f"{path}: not an aeroservo simulation result ({exc})") from None
    if meta.get("format") != "aeroservo-simulation-1":
        raise InputError(
            f"{path}: not an aeroservo simulation result (format {meta.get('format')})"
        )
    return SimulationResult(
        t=t,
        status=[],
        limits=Limits(**meta["limits"]),
        units=meta["units"],
        speed=meta["speed"],
        density=meta["density"],
        summary=meta.get("summary", {}),
        **groups,
    )
