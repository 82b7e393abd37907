"""Gust-loads result files: a :class:`~aeroservo.studies.gust.results.GustLoadsResult` as
``<stem>.json`` (the run's summary, the study's settings, the load units and every record) and
``<stem>.npz`` (the time histories of the critical gusts), with the limit-load table
``<stem>.csv`` and, when both loops were run, the gust-load-alleviation table
``<stem>_alleviation.csv``. :func:`load_gust_loads` reads the JSON and NPZ back into an equal
result (the figures redraw from it). No pickled objects: a damaged or foreign file is one
:class:`~aeroservo.errors.InputError`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InputError
from ..studies.gust.results import GustLoadsResult
from .summaries import json_text
from .user_files import (
    json_of_format,
    json_output,
    read_npz,
    read_result_json,
    write_result_items,
)

__all__ = [
    "FORMAT",
    "gust_loads_items",
    "write_gust_loads",
    "load_gust_loads",
    "is_gust_loads_file",
]

FORMAT = "aeroservo-gust-loads-2"
"""Format 2 (issue 38): ``time_at_limit`` [s] per control replaces format 1's ``limited``
(a share of the samples, which depended on the length of the march)."""


def _json_writer(result: GustLoadsResult, summary: dict, npz: Path):
    """The JSON's writer; the text is made when it writes (``summary`` may still grow)."""

    def write(p: Path) -> None:
        doc = {
            "format": FORMAT,
            **summary,
            "name": result.name,
            "units": dict(result.units),
            "settings": dict(result.settings),
            "arrays": npz.name,
            "records": result.records,
        }
        p.write_text(json_text(doc), encoding="utf-8")

    return write


def _npz_writer(arrays: dict):
    def write(p: Path) -> None:
        with open(p, "wb") as fh:
            np.savez_compressed(fh, **arrays)

    return write


def _csv_writer(frame, float_format: str | None = None):
    """A writer of the CSV of ``frame()`` (a DataFrame made when it writes)."""
    return lambda p: p.write_text(
        frame().to_csv(index=False, float_format=float_format), encoding="utf-8"
    )


def history_frame(result: GustLoadsResult):
    """The time histories of the critical gusts as one long table (pandas DataFrame): a row per
    sample of each critical gust (``point``, ``loop``, ``gradient_m``, ``gust_sign``: those of
    the limit-load table's ``max_gradient_m`` / ``max_sign`` and ``min_...``), with the time
    [s], the gust [m/s TAS] and every load (and control applied) in SI units."""
    import pandas as pd

    frames = []
    for r in result.records:
        seen = set()
        names = [n for n in r["history_loads"] if n in r["loads"]]
        cols = [r["history_loads"].index(n) for n in names]
        for load, sides in r["histories"].items():
            for side, key in sides.items():
                if key in seen:
                    continue
                seen.add(key)
                v = r["loads"][load]
                t = np.asarray(result.arrays[key + "_t"])
                y = np.asarray(result.arrays[key + "_y"])[:, cols]
                head = {
                    "point": r["point"],
                    "loop": r["loop"],
                    "gradient_m": v[f"{side}_gradient"],
                    "gust_sign": v[f"{side}_sign"],
                    "t_s": t,
                    "gust_m_s": np.asarray(result.arrays[key + "_gust"]),
                }
                frames.append(pd.DataFrame(head | {n: y[:, i] for i, n in enumerate(names)}))
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


def gust_loads_items(result: GustLoadsResult, json_path: str | Path, summary: dict) -> dict:
    """The files of a result, ``{kind: (path, writer)}`` for
    :func:`aeroservo.atomic.atomic_write_set`: ``summary`` (the JSON: ``summary`` and every
    record), ``arrays`` (the NPZ next to it), ``table`` (the CSV of limit loads),
    ``histories`` (the CSV of the critical gusts' time histories, :func:`history_frame`) and
    ``alleviation`` (its CSV, when the result has both loops). The texts are made when the
    writers run, so ``summary`` may still be completed (e.g. with the files written)."""
    json_path = Path(json_path)
    stem = json_path.with_suffix("")
    npz = stem.with_suffix(".npz")
    items = {
        "summary": (json_path, _json_writer(result, summary, npz)),
        "arrays": (npz, _npz_writer(result.arrays)),
        "table": (stem.with_suffix(".csv"), _csv_writer(lambda: result.table)),
        "histories": (
            stem.parent / f"{stem.name}_histories.csv",
            _csv_writer(lambda: history_frame(result), "%.7g"),  # the march is good to 1e-5
        ),
    }
    if result.loops == ["open", "closed"]:
        path = stem.parent / f"{stem.name}_alleviation.csv"
        items["alleviation"] = (path, _csv_writer(lambda: result.alleviation))
    return items


def write_gust_loads(
    result: GustLoadsResult, path: str | Path, summary: dict | None = None
) -> dict[str, str]:
    """Write a gust-loads result (atomically, all files or none).

    Parameters
    ----------
    result : GustLoadsResult
    path : str or Path
        The ``.json`` file; the ``.npz``, ``.csv``, ``_histories.csv`` and
        ``_alleviation.csv`` go next to it.
    summary : dict, optional
        The run's summary (default :func:`aeroservo.studies.gust.scenario.gust_summary`).

    Returns
    -------
    dict
        ``{kind: path}`` of the files written.
    """
    from ..studies.gust.scenario import gust_summary

    path = json_output(path, "gust-loads result (.json)")
    return write_result_items(gust_loads_items(result, path, summary or gust_summary(result)))


def is_gust_loads_file(path: str | Path) -> bool:
    """Whether ``path`` is a ``.json`` file written by :func:`write_gust_loads` (its first
    kilobytes name the format)."""
    return json_of_format(path, FORMAT)


def _fail(path: Path, what: str):
    raise InputError(f"{path}: not a valid aeroservo gust-loads result ({what})")


def load_gust_loads(path: str | Path) -> GustLoadsResult:
    """Read a result written by :func:`write_gust_loads` (or ``aeroservo loads``): the JSON and
    the NPZ it names, next to it.

    Raises
    ------
    InputError
        The file is missing, not a gust-loads result, or its NPZ is missing or incomplete.
    """
    from .gust_loads_checks import check_arrays, check_settings, checked_records

    path, doc = read_result_json(path, "gust-loads result", FORMAT, ("aeroservo-gust-loads-1",))
    records = checked_records(path, doc.get("records"))
    name = doc.get("arrays")
    if not isinstance(name, str) or Path(name).name != name or not name.endswith(".npz"):
        _fail(path, f"'arrays' = {name!r}: expected the name of a .npz file next to it")
    npz = path.parent / name
    arrays = read_npz(npz, what="gust-loads histories (.npz)")
    check_arrays(path, npz, records, arrays)
    units, settings = check_settings(path, doc.get("units"), doc.get("settings"))
    name = doc.get("name") or path.stem
    if not isinstance(name, str):
        _fail(path, f"'name' = {name!r}: expected a text")
    return GustLoadsResult(name, records, arrays, units, settings)
