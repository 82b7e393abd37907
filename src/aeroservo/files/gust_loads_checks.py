"""The checks of a gust-loads result read back (:mod:`.gust_loads_file`): every value its
summary, table and figures read, of the type and shape aeroservo writes, so that a damaged or
edited file is one :class:`~aeroservo.errors.InputError` naming the file, the key and the
value, never an error inside a figure. A number written as ``null`` (the JSON of a number that
was not finite) reads back as NaN where the result may hold one.
"""

from __future__ import annotations

import math
from pathlib import Path

from ..errors import InputError, show_value

__all__ = ["checked_records", "check_arrays", "check_settings"]

NUM, FINITE, POSITIVE, INDEX, TEXT, SIGN, BOOL = (
    "a number or null",
    "a finite number",
    "a positive number",
    "an index >= 0",
    "a text",
    "1 or -1",
    "true or false",
)
_SIDES = ("max", "min")
_LOAD = {
    "unit": TEXT,
    "discrete": FINITE,
    **{f"{s}{k}": kind for s in _SIDES for k, kind in
       (("", FINITE), ("_gradient", POSITIVE), ("_time", FINITE), ("_sign", SIGN))},
}  # fmt: skip
_LOAD_OPTIONAL = {k: NUM for k in ("rigid", "one_g", "a_bar", "n0", "turbulence")}
_RECORD = {
    "point": INDEX,
    "loop": ("open", "closed"),
    "mass_case": TEXT,
    "speed_name": TEXT,
    **dict.fromkeys(("altitude", "eas", "tas", "f_g", "u_sigma"), FINITE),
}
_TRIM = ("alpha_rad", "lift_N", "weight_N")
_TUNING = ("up_max", "up_min", "down_max", "down_min")


class _Checker:
    """Checks values of the file ``path``, each named by its place (``records[0].loads``)."""

    def __init__(self, path: Path):
        self.path = path

    def fail(self, where: str, value: object, want: str):
        raise InputError(
            f"{self.path}: {where} = {show_value(value)}: expected {want} (not a valid "
            "aeroservo gust-loads result)"
        )

    def value(self, where: str, v: object, kind):
        """``v`` checked as ``kind`` (a NUM read as float, null as NaN)."""
        if isinstance(kind, tuple):
            if v not in kind:
                self.fail(where, v, " or ".join(map(repr, kind)))
            return v
        if kind == TEXT:
            ok = isinstance(v, str)
        elif kind == BOOL:
            ok = isinstance(v, bool)
        elif isinstance(v, bool) or not isinstance(v, int | float | type(None)):
            ok = False
        elif kind == NUM:
            return math.nan if v is None else float(v)
        elif kind == INDEX:
            ok = isinstance(v, int) and v >= 0
        elif kind == SIGN:
            ok = v in (1, -1)
        else:
            ok = v is not None and math.isfinite(v) and (kind == FINITE or v > 0)
        if not ok:
            self.fail(where, v, kind)
        return v

    def table(self, where: str, v: object, keys: dict, optional: dict | None = None) -> dict:
        """A table with ``keys`` (and ``optional`` keys), each value checked."""
        if not isinstance(v, dict):
            self.fail(where, v, "a table")
        out = dict(v)
        for k, kind in keys.items():
            if k not in v:
                self.fail(f"{where}.{k}", "<missing>", kind if isinstance(kind, str) else "it")
            out[k] = self.value(f"{where}.{k}", v[k], kind)
        for k, kind in (optional or {}).items():
            if k in v:
                out[k] = self.value(f"{where}.{k}", v[k], kind)
        return out

    def mapping(self, where: str, v: object, kind) -> dict:
        """A table of any names, each value checked as ``kind``."""
        if not isinstance(v, dict):
            self.fail(where, v, f"a table whose values are each {kind}")
        return {k: self.value(f"{where}.{k}", x, kind) for k, x in v.items()}

    def items(self, where: str, v: object, kind, n: int | None = None) -> list:
        """A list (of ``n`` items when given), each checked as ``kind``."""
        if not isinstance(v, list) or (n is not None and len(v) != n):
            self.fail(where, v, f"a list of {'' if n is None else f'{n} '}values, each {kind}")
        return [self.value(f"{where}[{i}]", x, kind) for i, x in enumerate(v)]


def _record(c: _Checker, i: int, r: object) -> dict:
    where = f"records[{i}]"
    r = c.table(where, r, _RECORD)
    loads = r.get("loads")
    if not isinstance(loads, dict) or not loads:
        c.fail(f"{where}.loads", loads, "a table of loads")
    names = list(loads)
    hist = c.items(f"{where}.history_loads", r.get("history_loads"), TEXT)
    for name in names:
        w = f"{where}.loads.{name}"
        v = c.table(w, loads[name], _LOAD, _LOAD_OPTIONAL)
        for s in _SIDES:
            corr = c.mapping(f"{w}.{s}_correlated", v.get(f"{s}_correlated"), NUM)
            if not set(names) <= set(corr):
                c.fail(f"{w}.{s}_correlated", list(corr), f"every load of the record {names}")
            v[f"{s}_correlated"] = corr
        if name not in hist:
            c.fail(f"{where}.history_loads", hist, f"a list with {name!r}")
        loads[name] = v
    r["time_at_limit"] = c.mapping(f"{where}.time_at_limit", r.get("time_at_limit"), FINITE)
    r["notes"] = c.items(f"{where}.notes", r.get("notes"), TEXT)
    h = c.items(f"{where}.gradients", r.get("gradients"), POSITIVE)
    if not h:
        c.fail(f"{where}.gradients", h, "the scanned gust gradients [m]")
    r["amplitudes"] = c.items(f"{where}.amplitudes", r.get("amplitudes"), FINITE, len(h))
    tuning = r.get("tuning")
    if not isinstance(tuning, dict) or set(tuning) != set(names):
        c.fail(f"{where}.tuning", tuning, f"a table of the loads {names}")
    for name, t in tuning.items():
        t = c.table(f"{where}.tuning.{name}", t, {})
        for k in _TUNING:
            t[k] = c.items(f"{where}.tuning.{name}.{k}", t.get(k), NUM, len(h))
        tuning[name] = t
    sides = {s: TEXT for s in _SIDES}
    histories = r.get("histories")
    if not isinstance(histories, dict) or set(histories) != set(names):
        c.fail(f"{where}.histories", histories, f"a table of the loads {names}")
    for name, keys in histories.items():
        c.table(f"{where}.histories.{name}", keys, sides)
    trim = r.get("trim") or {}
    r["trim"] = c.table(f"{where}.trim", trim, dict.fromkeys(_TRIM, FINITE)) if trim else {}
    cov = r.get("covariance")
    if cov is not None:
        cov = c.table(f"{where}.covariance", cov, {})
        outs = c.items(f"{where}.covariance.outputs", cov.get("outputs"), TEXT)
        rows = cov.get("matrix")
        if not isinstance(rows, list) or len(rows) != len(outs):
            c.fail(f"{where}.covariance.matrix", rows, f"{len(outs)} rows, one per output")
        m = [c.items(f"{where}.covariance.matrix[{j}]", row, NUM, len(outs))
             for j, row in enumerate(rows)]  # fmt: skip
        r["covariance"] = {**cov, "outputs": outs, "matrix": m}
    return r


def checked_records(path: Path, records: object) -> list[dict]:
    """The records of a gust-loads result's JSON, checked (one per flight point and loop)."""
    c = _Checker(path)
    if not isinstance(records, list):
        c.fail("records", records, "a list of records (one per flight point and loop)")
    out = [_record(c, i, r) for i, r in enumerate(records)]
    seen: set = set()
    for i, r in enumerate(out):
        if (r["point"], r["loop"]) in seen:
            c.fail(f"records[{i}]", f"point {r['point']}, {r['loop']} loop", "each once")
        seen.add((r["point"], r["loop"]))
    return out


def check_arrays(path: Path, npz: Path, records: list[dict], arrays: dict) -> None:
    """The histories each record names: ``<key>_t`` [s] and ``<key>_gust`` [m/s] of one length,
    ``<key>_y`` with a column per history load, all real."""
    for i, r in enumerate(records):
        n_loads = len(r["history_loads"])
        for sides in r["histories"].values():
            for key in sides.values():
                got = {}
                for end, ndim in (("_t", 1), ("_gust", 1), ("_y", 2)):
                    a = arrays.get(key + end)
                    if a is None:
                        raise InputError(
                            f"{npz}: missing array {key + end!r} (named by records[{i}] of {path})"
                        )
                    if a.dtype.kind not in "fiu" or a.ndim != ndim or a.size == 0:
                        raise InputError(
                            f"{npz}: array {key + end!r} of {a.dtype} and shape {a.shape}: "
                            f"expected {ndim}-D real numbers (a history of {path.name})"
                        )
                    got[end] = a
                n = got["_t"].shape[0]
                if got["_gust"].shape != (n,) or got["_y"].shape != (n, n_loads):
                    raise InputError(
                        f"{npz}: arrays {key}_gust {got['_gust'].shape} and {key}_y "
                        f"{got['_y'].shape}: expected ({n},) and ({n}, {n_loads}) for its "
                        f"{n} times and records[{i}].history_loads"
                    )


def check_settings(path: Path, units: object, settings: object) -> tuple[dict, dict]:
    """The load units and the settings the summary and the figures read."""
    c = _Checker(path)
    units = c.mapping("units", units if units is not None else {}, TEXT)
    s = c.table("settings", settings if settings is not None else {}, {})
    lim = s.get("limits")
    if lim is not None:
        lim = c.table("settings.limits", lim, {})
        for k in ("magnitude", "rate"):
            if lim.get(k) is not None:
                c.mapping(f"settings.limits.{k}", lim[k], NUM)
    if s.get("loop_measures") is not None:
        c.value("settings.loop_measures", s["loop_measures"], TEXT)
    c.items("settings.warnings", s.get("warnings", []), TEXT)
    skipped = s.get("skipped_points", [])
    if not isinstance(skipped, list):
        c.fail("settings.skipped_points", skipped, "a list of flight points")
    for j, sk in enumerate(skipped):
        w = f"settings.skipped_points[{j}]"
        sk = c.table(w, sk, {"point": INDEX, "flight_point": TEXT})
        c.items(f"{w}.notes", sk.get("notes"), TEXT)
    return units, s
