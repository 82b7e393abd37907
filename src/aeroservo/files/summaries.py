"""JSON text of run summaries and result headers (numpy scalars and arrays as plain numbers and
lists), the one encoder every result file and ``--json`` output uses; it lives with the shape
of results (:mod:`aeroservo.result_shape`), whose ``to_json`` uses it too."""

from __future__ import annotations

from ..result_shape import finite, json_text

__all__ = ["json_text", "finite"]
