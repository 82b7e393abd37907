"""JSON text of run summaries and result headers (numpy scalars and arrays as plain numbers and
lists), the one encoder every result file and ``--json`` output uses."""

from __future__ import annotations

import json

import numpy as np

__all__ = ["json_text", "finite"]


def _plain(o: object) -> object:
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)


def finite(obj: object) -> object:
    """``obj`` with every non-finite float (NaN, inf, also in numpy arrays and scalars) as
    None, so that its JSON is standard (``null``, not ``NaN``)."""
    if isinstance(obj, dict):
        return {k: finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite(v) for v in obj]
    if isinstance(obj, (np.ndarray, np.generic)):
        return finite(obj.tolist())
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    return obj


def json_text(obj: object, indent: int | None = 2) -> str:
    """JSON text of ``obj``: numpy scalars and arrays become plain numbers and lists, anything
    else unknown its ``str``."""
    return json.dumps(obj, indent=indent, default=_plain)
