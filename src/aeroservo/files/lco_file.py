"""Limit-cycle result files: an :class:`~aeroservo.studies.lco.result.LCOResult` as
``<stem>.json`` (the run's summary, the study's settings, every march's verdict without its
time history, the describing-function branches and the summary text), ``<stem>_histories.npz``
(the end of each march: ``row<i>/t`` [s] and ``row<i>/<signal>``, rows numbered as in the
JSON), the table ``<stem>.csv`` (units in the header), the branches ``<stem>_branches.csv`` and
the text ``<stem>_summary.txt``. :func:`load_lco` reads the JSON (and the NPZ when it is next to
it) back into an equal result; the figures redraw from it. No pickled objects: a damaged or
foreign file is one :class:`~aeroservo.errors.InputError`.
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..studies.lco.result import TABLE_COLUMNS, LCOResult
from .summaries import finite, json_text
from .user_files import (
    json_of_format,
    json_output,
    read_npz,
    read_result_json,
    write_result_items,
)

__all__ = ["FORMAT", "lco_items", "write_lco", "load_lco", "is_lco_file", "TABLE_UNITS"]

FORMAT = "aeroservo-lco-2"
"""Version 2 (issue 40): rows have ``modulation`` [Hz] and the verdicts name sustained
oscillations of every class ("lco", "quasi-periodic", "chaotic") and "unsettled" motion."""
OLDER = ("aeroservo-lco-1",)
"""Formats of earlier versions (refused with a message that says so: run the study again; their
verdicts called sustained quasi-periodic and chaotic oscillations 'aperiodic')."""

TABLE_UNITS = {
    "speed": "m/s",
    "initial": "rad",
    "frequency": "Hz",
    "modulation": "Hz",
    "amplitude": "rad",
    "rms": "rad",
    "mean": "rad",
    "amplitude_per_gap": "-",
    "rms_per_gap": "-",
    "growth": "1/s",
    "switches_per_second": "1/s",
}
"""Units of the columns of the table (the others are text)."""

_BRANCH_COLUMNS = (
    ("branch", ""),
    ("element", ""),
    ("amplitude_rad", "amplitude [rad]"),
    ("amplitude_per_gap", "amplitude_per_gap [-]"),
    ("speed_m_s", "speed [m/s]"),
    ("frequency_hz", "frequency [Hz]"),
    ("stable", ""),
    ("others_stable", ""),
)


def _header(name: str) -> str:
    return f"{name} [{TABLE_UNITS[name]}]" if name in TABLE_UNITS else name


def _csv_text(header: list, rows: list) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    w.writerows(rows)
    return buf.getvalue()


def table_csv(result: LCOResult) -> str:
    """The CSV of :meth:`LCOResult.table_rows` (one row per march; SI units, radians)."""
    rows = [[r[k] for k in TABLE_COLUMNS] for r in result.table_rows()]
    return _csv_text([_header(k) for k in TABLE_COLUMNS], rows)


def branches_csv(branches) -> str:
    """The CSV of :meth:`DescribingBranches.table` (one row per LCO point)."""
    table = branches.table()
    names = list(branches.names) or list(table[0]["ratios"] if table else [])
    head = [h or k for k, h in _BRANCH_COLUMNS] + [f"ratio_{n} [-]" for n in names]
    rows = [[r[k] for k, _h in _BRANCH_COLUMNS] + [r["ratios"][n] for n in names] for r in table]
    return _csv_text(head, rows)


def _arrays(result: LCOResult) -> dict:
    return {
        f"row{i}/{k}": np.asarray(v)
        for i, r in enumerate(result.rows)
        for k, v in (r.get("history") or {}).items()
    }


def _doc(result: LCOResult, summary: dict, npz: Path | None) -> dict:
    b = result.branches
    return {
        "format": FORMAT,
        **summary,
        "name": result.settings.get("name", ""),
        "settings": dict(result.settings),
        "arrays": None if npz is None else npz.name,
        "rows": [{k: v for k, v in r.items() if k != "history"} for r in result.rows],
        "branches": None
        if b is None
        else {"gap": b.gap, "element": b.element, "names": list(b.names), "table": b.table()},
        "summary_text": result.summary(),
    }


def _text(make):
    """A writer of the text ``make()`` (made when it writes)."""
    return lambda p: p.write_text(make(), encoding="utf-8")


def _npz_writer(arrays: dict):
    def write(p: Path) -> None:
        with open(p, "wb") as fh:
            np.savez_compressed(fh, **arrays)

    return write


def lco_items(result: LCOResult, json_path: str | Path, summary: dict) -> dict:
    """The files of a result, ``{kind: (path, writer)}`` for
    :func:`aeroservo.atomic.atomic_write_set`: ``summary`` (the JSON), ``table`` (the CSV),
    ``branches`` (its CSV, when the result has describing-function branches), ``histories``
    (the NPZ, when the marches kept histories) and ``summary_text``. The texts are made when
    the writers run, so ``summary`` may still be completed (e.g. with the files written)."""
    json_path = Path(json_path)
    stem = json_path.with_suffix("")
    arrays = _arrays(result)
    npz = stem.parent / f"{stem.name}_histories.npz" if arrays else None
    items = {
        # standard JSON: a number that is not finite is null (the reader reads it as NaN)
        "summary": (json_path, _text(lambda: json_text(finite(_doc(result, summary, npz))))),
        "table": (stem.with_suffix(".csv"), _text(lambda: table_csv(result))),
    }
    if result.branches is not None:
        path = stem.parent / f"{stem.name}_branches.csv"
        items["branches"] = (path, _text(lambda: branches_csv(result.branches)))
    if npz is not None:
        items["histories"] = (npz, _npz_writer(arrays))
    items["summary_text"] = (
        stem.parent / f"{stem.name}_summary.txt",
        _text(lambda: result.summary() + "\n"),
    )
    return items


def write_lco(result: LCOResult, path: str | Path, summary: dict | None = None) -> dict[str, str]:
    """Write a limit-cycle result (atomically, all files or none).

    Parameters
    ----------
    result : LCOResult
    path : str or Path
        The ``.json`` file; the other files go next to it.
    summary : dict, optional
        The run's summary (default :func:`aeroservo.studies.lco.scenario.lco_summary`).

    Returns
    -------
    dict
        ``{kind: path}`` of the files written.
    """
    from ..studies.lco.scenario import lco_summary

    if not isinstance(result, LCOResult):
        raise InputError(f"result = {type(result).__name__}: expected an aeroservo LCOResult")
    path = json_output(path, "limit-cycle result (.json)")
    return write_result_items(lco_items(result, path, summary or lco_summary(result)))


def is_lco_file(path: str | Path) -> bool:
    """Whether ``path`` is a ``.json`` file written by :func:`write_lco`, of this version or an
    older one (its first kilobytes name the format)."""
    return any(json_of_format(path, f) for f in (FORMAT, *OLDER))


def _fail(path: Path, what: str):
    raise InputError(f"{path}: not a valid aeroservo limit-cycle result ({what})")


def load_lco(path: str | Path) -> LCOResult:
    """Read a result written by :func:`write_lco` (or ``aeroservo lco``): the JSON, and the
    time histories from the NPZ it names when that file is next to it (without it the rows
    have no history and only the bifurcation diagram redraws).

    Raises
    ------
    InputError
        The file is missing or not a limit-cycle result, of an older format (run the study
        again), or its NPZ is damaged.
    """
    from ..stability.describing_function import DescribingBranches

    path, doc = read_result_json(path, "limit-cycle result", FORMAT, older=OLDER)
    rows, settings = doc.get("rows"), doc.get("settings")
    if not isinstance(rows, list) or not all(
        isinstance(r, dict) and all(k in r for k in TABLE_COLUMNS) for r in rows
    ):
        _fail(path, f"'rows' must be a list of marches with {list(TABLE_COLUMNS)}")
    if not rows:  # a study marches at least one speed: an empty list is not what it writes
        _fail(path, "'rows' is empty: a limit-cycle result has at least one march")
    if not isinstance(settings, dict):
        _fail(path, "'settings' must be a table")
    _check_settings(path, settings)
    rows = [_checked_row(path, i, r) for i, r in enumerate(rows)]
    branches = None
    b = doc.get("branches")
    if b is not None:
        if not isinstance(b, dict) or not isinstance(b.get("table"), list):
            _fail(path, "'branches' must be a table with a 'table' list")
        try:
            branches = DescribingBranches.from_table(
                b["table"], gap=b.get("gap"), element=b.get("element", ""), names=b.get("names")
            )
        except InputError as exc:
            _fail(path, str(exc))
    hist = _histories(path, doc.get("arrays"), len(rows), settings.get("reference"))
    out = [{**r, "history": hist.get(i, {})} for i, r in enumerate(rows)]
    return LCOResult(out, settings, branches)


_ROW_TEXT = ("start", "kind", "confidence", "reason")
_ROW_MAPS = ("peaks", "rmss", "saturated")
_SETTINGS = {  # the settings the summary and the figures read: key -> type
    **dict.fromkeys(("name", "scenario", "reference", "controller", "model"), str),
    **dict.fromkeys(("duration", "dt", "settle", "density"), float),
    **dict.fromkeys(("elements", "laws", "notes"), list),
    "speeds": list,
    "amplitudes": list,
    "closed_loop": bool,
}


def _is_number(v: object) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _checked_row(path: Path, i: int, row: dict) -> dict:
    """A row of the JSON with its types checked; a number written as null reads as NaN."""
    out = dict(row)
    for k in TABLE_COLUMNS + _ROW_MAPS:
        v = row.get(k)
        if k in _ROW_MAPS:
            ok = v is None or (isinstance(v, dict) and all(map(_is_number, v.values())))
        elif k in _ROW_TEXT:
            ok = isinstance(v, str) and (k != "start" or v in ("point", "up", "down"))
        elif v is None:
            out[k], ok = float("nan"), k != "speed"
        else:
            ok = _is_number(v) and (k != "speed" or math.isfinite(v))
        if not ok:
            _fail(path, f"rows[{i}].{k} = {v!r}: not what aeroservo writes")
    return out


def _check_settings(path: Path, settings: dict) -> None:
    """The settings the summary and the figures read, of the types aeroservo writes."""
    for k, kind in _SETTINGS.items():
        v = settings.get(k)
        if v is None:
            continue
        if kind is float:
            ok = _is_number(v)
        elif kind is list:
            item = str if k in ("elements", "laws", "notes") else (int, float)
            ok = isinstance(v, list) and all(
                isinstance(x, item) and not isinstance(x, bool) for x in v
            )
            if ok and item is not str:  # the speeds scale the figure's axis: some, finite
                ok = all(map(math.isfinite, v)) and (k != "speeds" or bool(v))
        else:
            ok = isinstance(v, kind)
        if not ok:
            _fail(path, f"settings.{k} = {v!r}: not what aeroservo writes")
    gap = settings.get("gap")
    if gap is not None and not (_is_number(gap) and 0.0 < gap < math.inf):
        _fail(path, f"settings.gap = {gap!r}: expected a positive gap [rad] or null")


def _histories(path: Path, name: object, n_rows: int, reference: object = None) -> dict:
    """``{row: {signal: array}}`` from the NPZ ``name`` next to ``path`` ({} if absent):
    each row's arrays real, one-dimensional and as long as its ``t``, with the rotation and
    hinge moment of the ``reference`` element."""
    if name is None:
        return {}
    if not isinstance(name, str) or Path(name).name != name or not name.endswith(".npz"):
        _fail(path, f"'arrays' = {name!r}: expected the name of a .npz file next to it")
    npz = path.parent / name
    if not npz.is_file():
        return {}
    arrays = read_npz(npz, what="limit-cycle histories (.npz)")
    out: dict = {}
    for key, v in arrays.items():
        row, sep, signal = key.partition("/")
        i = int(row[3:]) if row.startswith("row") and row[3:].isdigit() else -1
        if not sep or not signal or not 0 <= i < n_rows or v.ndim != 1:
            raise InputError(f"{npz}: array {key!r} is not a history of a row of {path.name}")
        if not (np.issubdtype(v.dtype, np.floating) or np.issubdtype(v.dtype, np.integer)):
            raise InputError(f"{npz}: array {key!r} of {v.dtype} values: expected real numbers")
        out.setdefault(i, {})[signal] = v
    need = ["t"] + ([f"{reference}_rotation", f"{reference}_hinge_moment"] if reference else [])
    for i, h in out.items():
        missing = [k for k in need if k not in h]
        if missing:
            raise InputError(f"{npz}: row{i}/{missing[0]}: missing (the history of row {i})")
        bad = [k for k, v in h.items() if v.shape != h["t"].shape]
        if bad:
            raise InputError(
                f"{npz}: row{i}/{bad[0]}: {h[bad[0]].size} values, its row{i}/t "
                f"{h['t'].size}: not a history of {path.name}"
            )
    return out
