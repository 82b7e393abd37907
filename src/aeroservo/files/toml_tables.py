"""Validation of TOML tables: every error names the file, the key and the value.

:class:`Table` wraps one table of a parsed TOML document; its getters check type, range and
unknown keys, and raise :class:`~aeroservo.errors.InputError` with a message of the form
``"<file>: <table>.<key> = <value>: <what is allowed>"``.
"""

from __future__ import annotations

import json
import math
import re
import tomllib
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path

from ..errors import RANGES, InputError, show_value
from .user_files import read_text, user_path

__all__ = ["Table", "read_toml", "check_integers", "one_line", "one_line_errors"]

INT64 = (-(2**63), 2**63 - 1)
"""Range of TOML integers (tomllib reads integers of any size)."""


def one_line(message: str) -> str:
    """Escape line breaks and other unprintable characters (from keys, values or file names
    quoted as they are): an error message is one line."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in message)


@contextmanager
def one_line_errors() -> Iterator[None]:
    """Re-raise an :class:`InputError` whose message spans several lines as a one-line one."""
    try:
        yield
    except InputError as exc:
        message = one_line(str(exc))
        if message == str(exc):
            raise
        raise InputError(message) from None


def read_toml(path: str | Path, what: str = "TOML file") -> dict:
    """Parse a TOML file read by :func:`~aeroservo.files.user_files.read_text`; a missing
    file, a file that is not UTF-8 text or bad syntax is an :class:`InputError`."""
    path = user_path(path, what)
    text = read_text(path, what=what)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML: {exc}") from None
    except ValueError:  # an integer literal of more than 4300 digits
        raise InputError(
            f"{path}: not valid TOML: an integer of more than 4300 digits (TOML integers are "
            "64-bit)"
        ) from None
    except RecursionError:
        raise InputError(f"{path}: not valid TOML: arrays or tables nested too deeply") from None
    check_integers(data, str(path))
    return data


def check_integers(data: object, file: str, where: str = "") -> None:
    """Reject integers outside the 64-bit range of TOML, by key path."""
    if isinstance(data, Mapping):
        for k, v in data.items():
            check_integers(v, file, f"{where}.{_key(k)}" if where else _key(k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            check_integers(v, file, f"{where}[{i}]")
    elif isinstance(data, int) and not isinstance(data, bool):
        if not INT64[0] <= data <= INT64[1]:
            raise InputError(
                f"{file}: {where or '(top level)'} = {show_value(data)}: integer outside the "
                f"64-bit range of TOML [{INT64[0]}, {INT64[1]}]"
            )


_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+(\[\d+\])?")


def _key(key: object) -> str:
    """A key as written in TOML: bare if it can be, else quoted (never a line break)."""
    if isinstance(key, str) and _BARE_KEY.fullmatch(key):
        return key
    return json.dumps(key) if isinstance(key, str) else repr(key)


class Table:
    """One TOML table with checked getters.

    Parameters
    ----------
    data : mapping
        The table.
    where : str
        Its dotted name (``""`` for the top level).
    file : str
        File name used in messages.
    """

    def __init__(self, data: object, where: str, file: str):
        self.file = file
        self.where = where
        if not isinstance(data, Mapping):
            self.fail(None, data, "expected a table")
        self.data = data

    # -- messages -----------------------------------------------------------------------
    def key_name(self, key: str | None) -> str:
        if key is None:
            return self.where or "(top level)"
        return f"{self.where}.{_key(key)}" if self.where else _key(key)

    def fail(self, key: str | None, value: object, what: str):
        """Raise the error for ``key`` (None: the table itself) with value and explanation."""
        raise InputError(f"{self.file}: {self.key_name(key)} = {show_value(value)}: {what}")

    # -- structure ----------------------------------------------------------------------
    def check_keys(self, required: Sequence[str] = (), optional: Sequence[str] = ()) -> Table:
        """Reject unknown keys and require the required ones."""
        allowed = list(required) + list(optional)
        for k in self.data:
            if k not in allowed:
                self.fail(k, self.data[k], f"unknown key; allowed keys are {sorted(allowed)}")
        for k in required:
            if k not in self.data:
                raise InputError(f"{self.file}: {self.key_name(k)}: missing required key")
        return self

    def has(self, key: str) -> bool:
        return key in self.data

    def table(self, key: str, required: bool = False) -> Table:
        """Sub-table ``key`` (an empty one if absent and not required)."""
        if key not in self.data:
            if required:
                raise InputError(f"{self.file}: {self.key_name(key)}: missing required table")
            return Table({}, self.key_name(key), self.file)
        return Table(self.data[key], self.key_name(key), self.file)

    # -- scalars ------------------------------------------------------------------------
    def number(
        self,
        key: str,
        default: float | None = None,
        *,
        unit: str = "",
        lo: float | None = None,
        hi: float | None = None,
        lo_open: bool = False,
        hi_open: bool = False,
        required: bool = False,
        quantity: str | None = None,
    ) -> float | None:
        """A finite real number within bounds (integers accepted); ``quantity``: the bounds
        and unit of that entry of :data:`aeroservo.errors.RANGES`."""
        if key not in self.data:
            if required:
                raise InputError(f"{self.file}: {self.key_name(key)}: missing required key")
            return default
        if quantity is not None:
            unit, lo, hi, lo_open, hi_open = _bounds(quantity)
        return self.check_value(key, self.data[key], unit, lo, hi, lo_open, hi_open)

    def check_value(self, key, v, unit="", lo=None, hi=None, lo_open=False, hi_open=False):
        u = f" [{unit}]" if unit else ""
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            self.fail(key, v, f"expected a number{u}")
        v = float(v)
        if not math.isfinite(v):
            self.fail(key, v, f"must be a finite number{u}")
        if (lo is not None and (v < lo or (lo_open and v == lo))) or (
            hi is not None and (v > hi or (hi_open and v == hi))
        ):
            left = "(-inf" if lo is None else ("(" if lo_open else "[") + f"{lo:g}"
            right = "inf)" if hi is None else f"{hi:g}" + (")" if hi_open else "]")
            self.fail(key, v, f"allowed range is {left}, {right}{u}")
        return v

    def integer(
        self,
        key: str,
        default: int | None = None,
        *,
        lo: int | None = None,
        hi: int | None = None,
        required: bool = False,
    ) -> int | None:
        if key not in self.data:
            if required:
                raise InputError(f"{self.file}: {self.key_name(key)}: missing required key")
            return default
        v = self.data[key]
        if isinstance(v, bool) or not isinstance(v, int):
            self.fail(key, v, "expected an integer")
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            left = "-inf" if lo is None else str(lo)
            right = "inf" if hi is None else str(hi)
            self.fail(key, v, f"allowed range is [{left}, {right}]")
        return int(v)

    def string(
        self,
        key: str,
        default: str | None = None,
        *,
        choices: Sequence[str] | None = None,
        required: bool = False,
    ) -> str | None:
        if key not in self.data:
            if required:
                raise InputError(f"{self.file}: {self.key_name(key)}: missing required key")
            return default
        v = self.data[key]
        if not isinstance(v, str):
            self.fail(key, v, "expected a string")
        if choices is not None and v not in choices:
            self.fail(key, v, f"allowed values are {list(choices)}")
        return v

    def boolean(self, key: str, default: bool = False) -> bool:
        if key not in self.data:
            return default
        v = self.data[key]
        if not isinstance(v, bool):
            self.fail(key, v, "expected true or false")
        return v

    # -- collections --------------------------------------------------------------------
    def strings(self, key: str, default: Sequence[str] | None = None, *, nonempty=True) -> list:
        if key not in self.data:
            return None if default is None else list(default)
        v = self.data[key]
        if not isinstance(v, list) or not all(isinstance(s, str) for s in v):
            self.fail(key, v, "expected a list of strings")
        if nonempty and not v:
            self.fail(key, v, "must not be empty")
        if len(set(v)) != len(v):
            self.fail(key, v, "names must not repeat")
        return list(v)

    def numbers(
        self,
        key: str,
        default=None,
        *,
        unit: str = "",
        lo=None,
        hi=None,
        lo_open=False,
        increasing: bool = False,
        quantity: str | None = None,
    ) -> list | None:
        """A non-empty list of numbers, each within bounds (or ``quantity``'s range)."""
        hi_open = False
        if quantity is not None:
            unit, lo, hi, lo_open, hi_open = _bounds(quantity)
        if key not in self.data:
            return default
        v = self.data[key]
        if not isinstance(v, list) or not v:
            self.fail(key, v, f"expected a non-empty list of numbers{f' [{unit}]' if unit else ''}")
        out = [
            self.check_value(f"{key}[{i}]", x, unit, lo, hi, lo_open, hi_open)
            for i, x in enumerate(v)
        ]
        if increasing and any(b <= a for a, b in zip(out[:-1], out[1:], strict=True)):
            self.fail(key, v, "values must increase")
        return out

    def number_map(
        self, key: str, *, unit: str = "", lo=0.0, lo_open=True, quantity: str | None = None
    ) -> dict:
        """An inline table ``{name = number}`` (e.g. limits or noise levels by signal), each
        value within ``[lo, inf)`` or within ``quantity``'s range."""
        hi, hi_open = None, False
        if quantity is not None:
            unit, lo, hi, lo_open, hi_open = _bounds(quantity)
        if key not in self.data:
            return {}
        sub = self.table(key)
        for name, val in sub.data.items():
            if not isinstance(name, str) or not name.isidentifier():
                sub.fail(name, val, "not a signal name (letters, digits and underscores)")
        return {
            name: sub.check_value(name, val, unit, lo, hi, lo_open, hi_open)
            for name, val in sub.data.items()
        }

    def path(self, key: str, base: Path, *, required: bool = False) -> Path | None:
        """A file path, relative to the folder of the file being read."""
        s = self.string(key, required=required)
        if s is None:
            return None
        if not s:
            self.fail(key, s, "expected a file path")
        p = Path(s)
        return p if p.is_absolute() else base / p


def _bounds(quantity: str) -> tuple:
    r = RANGES[quantity]
    return r.unit, r.lo, r.hi, r.lo_open, r.hi_open


def is_scenario_file(path: str | Path) -> bool:
    """Whether a TOML file is a scenario (it has a ``[scenario]`` table)."""
    try:
        return "scenario" in read_toml(path)
    except InputError:
        return False
