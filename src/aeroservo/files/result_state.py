"""Result files of the results the command line does not write itself (issue 39): a
closed-loop boundary, loop margins, a margin sweep and a recoverable set, each as one ``.npz``
of plain arrays with a JSON header ``meta``: ``format`` (:data:`FORMATS`), the aeroservo
version and ``state``, the result's fields (``to_state()``) with every array replaced by
``{"__array__": name}`` (the array of that name in the file) and every number that is not
finite by ``{"__float__": "nan" | "inf" | "-inf"}``, so that the header is standard JSON and
the result reads back exactly (:func:`read_state`). No pickled objects.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .._version import __version__
from ..errors import InputError
from .summaries import json_text

__all__ = ["FORMATS", "format_of", "state_writer", "read_state"]

FORMATS = {
    "aeroservo-closed-loop-boundary-1": "ClosedLoopBoundary",
    "aeroservo-loop-margins-1": "LoopMargins",
    "aeroservo-margin-sweep-1": "MarginSweep",
    "aeroservo-recoverable-set-1": "RecoverableSet",
}
"""Format name -> the result class it holds."""


def _class(name: str):
    """The result class of :data:`FORMATS` named ``name`` (its module imported)."""
    if name == "ClosedLoopBoundary":
        from ..design.boundary_result import ClosedLoopBoundary as cls
    elif name == "LoopMargins":
        from ..design.margins import LoopMargins as cls
    elif name == "MarginSweep":
        from ..design.margin_sweep import MarginSweep as cls
    else:
        from ..studies.recovery import RecoverableSet as cls
    return cls


def format_of(result) -> str | None:
    """The format of ``result``'s file, or None if it has none here."""
    for c in type(result).__mro__:
        for fmt, name in FORMATS.items():
            if c.__name__ == name and c is _class(name):
                return fmt
    return None


def _pack(obj, arrays: dict):
    """``obj`` as JSON values, its arrays moved into ``arrays``."""
    if isinstance(obj, dict):
        if not all(isinstance(k, str) for k in obj):
            raise TypeError(f"keys {list(obj)} are not all text")
        return {k: _pack(v, arrays) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_pack(v, arrays) for v in obj]
    if isinstance(obj, np.ndarray):
        key = f"a{len(arrays)}"
        arrays[key] = obj
        return {"__array__": key}
    if isinstance(obj, np.generic):
        return _pack(obj.item(), arrays)
    if isinstance(obj, float) and not math.isfinite(obj):
        return {"__float__": str(obj)}
    if obj is None or isinstance(obj, (bool, int, float, str)):
        return obj
    raise TypeError(f"{type(obj).__name__} is not plain data")


def _unpack(obj, arrays: dict):
    if isinstance(obj, dict):
        if set(obj) == {"__array__"}:
            return arrays[obj["__array__"]]
        if set(obj) == {"__float__"}:
            return float(obj["__float__"])
        return {k: _unpack(v, arrays) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_unpack(v, arrays) for v in obj]
    return obj


def state_writer(result):
    """A writer of ``result``'s ``.npz`` for :func:`aeroservo.atomic.atomic_write_set`."""
    fmt = format_of(result)
    if fmt is None:
        raise InputError(f"result = {type(result).__name__}: no file format for it")
    arrays: dict = {}
    meta = {
        "format": fmt,
        "aeroservo_version": __version__,
        "state": _pack(result.to_state(), arrays),
    }
    arrays["meta"] = np.array(json_text(meta))

    def write(p: Path) -> None:
        with open(p, "wb") as fh:
            np.savez_compressed(fh, **arrays)

    return write


def read_state(path: Path, data: dict, meta: dict):
    """The result of a file of :data:`FORMATS` (its arrays and header, from
    :func:`~aeroservo.files.flutter_file.open_npz`)."""
    cls = _class(FORMATS[meta["format"]])
    try:
        return cls.from_state(_unpack(meta["state"], data))
    except (KeyError, TypeError, ValueError, AttributeError, IndexError) as exc:
        why = " ".join(str(exc).split())[:120]
        raise InputError(
            f"{path}: the {cls.__name__} in the file is not valid ({type(exc).__name__}: {why})"
        ) from None
