"""The one shape of every aeroservo result (issue 39), and the JSON text of results.

Every result a user gets back and saves (a flutter sweep, a simulation, gust loads, limit
cycles, a trade study, a flight envelope, a closed-loop boundary, loop margins, a margin
sweep, a recoverable set) derives from :class:`Result` and has

* ``summary()``: readable text, a few lines;
* ``table``: a :class:`pandas.DataFrame` of its numbers (SI units, named in the columns);
* ``plot(kind=None, **kw)``: a :class:`matplotlib.figure.Figure`; ``kind`` names the figure
  (:attr:`Result.FIGURES`; ``None``: the main one, the first), ``**kw`` go to the method that
  draws it; an unknown kind is one :class:`~aeroservo.errors.InputError` that lists the kinds;
* ``to_json()``: standard JSON text (a number that is not finite is ``null``, never a bare
  ``NaN``);
* ``save(path)``: the file(s) the command line writes for that result, atomically; and
  :func:`aeroservo.files.results.load_result` reads them back.

Writing files is the shell's (``files/``) and some figures are drawn above a result's stage
(``plots/``): a result reaches them through :func:`shell`, which the package
(``aeroservo/__init__``, the command-line stage that may import every stage) fills in once
with :func:`use_shell`, so that imports still only go down the stages
(``docs/architecture.md``).
"""

from __future__ import annotations

import json
import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from pathlib import Path
from typing import ClassVar

from .errors import InputError

__all__ = ["Result", "json_text", "finite", "shell", "use_shell"]

_SHELL: list[Callable[[str], Callable]] = []


def use_shell(resolve: Callable[[str], Callable]) -> None:
    """Set the function that returns a function of the upper stages by name
    (``"save_result"``, ``"plot_vg"``, ...); called once by ``aeroservo/__init__``."""
    _SHELL[:] = [resolve]


def shell(name: str) -> Callable:
    """The function ``name`` of the upper stages (see the module docstring)."""
    if not _SHELL:  # pragma: no cover - aeroservo/__init__ always runs first
        raise RuntimeError("aeroservo.result_shape: the package did not set its shell")
    return _SHELL[0](name)


def _plain(o: object) -> object:
    import numpy as np

    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)


def finite(obj: object) -> object:
    """``obj`` with every non-finite float (NaN, inf, also in numpy arrays and scalars) as
    None, so that its JSON is standard (``null``, not ``NaN``)."""
    import numpy as np

    if isinstance(obj, dict):
        return {k: finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite(v) for v in obj]
    if isinstance(obj, (np.ndarray, np.generic)):
        return finite(obj.tolist())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def json_text(obj: object, indent: int | None = 2) -> str:
    """Standard JSON text of ``obj``: numpy scalars and arrays become plain numbers and lists,
    non-finite numbers ``null`` (not the bare ``NaN`` / ``Infinity`` that JSON does not have),
    anything else unknown its ``str``."""
    return json.dumps(finite(obj), indent=indent, default=_plain, allow_nan=False)


class Result(ABC):
    """The shape every result shares (see the module docstring).

    A subclass defines ``summary()``, ``table``, ``to_dict()`` (its JSON-ready record) and
    :attr:`FIGURES`; :meth:`plot`, :meth:`to_json` and :meth:`save` are the same for all.
    """

    FIGURES: ClassVar[dict[str, str]] = {}
    """Figure kind -> the name of the method that draws it; the first is the main figure."""

    @abstractmethod
    def summary(self) -> str:
        """A readable summary, a few lines of text."""

    @abstractmethod
    def to_dict(self) -> dict:
        """The result as JSON-ready data (SI units)."""

    @property
    def figure_kinds(self) -> tuple[str, ...]:
        """The kinds of figure this result can draw (of :attr:`FIGURES`: some need data a
        result may not have, e.g. time histories)."""
        return tuple(self.FIGURES)

    def plot(self, kind: str | None = None, **kw):
        """A figure of the result.

        Parameters
        ----------
        kind : str, optional
            One of :attr:`FIGURES` (default: the main figure, the first).
        **kw
            Options of the method that draws it (``FIGURES[kind]``).

        Returns
        -------
        matplotlib.figure.Figure
        """
        kinds = tuple(self.FIGURES)
        kind = kinds[0] if kind is None else kind
        if kind not in self.FIGURES:
            raise InputError(f"kind = {kind!r}: a {type(self).__name__} draws {', '.join(kinds)}")
        return getattr(self, self.FIGURES[kind])(**kw)

    def to_json(self, indent: int | None = 2) -> str:
        """:meth:`to_dict` as standard JSON text (non-finite numbers as ``null``)."""
        return json_text(finite(self.to_dict()), indent)

    def save(self, path: str | Path, **kw) -> Path:
        """Write the result as the command line does (atomically: all its files or none).

        ``aeroservo.load_result(path)`` reads it back. See
        :func:`aeroservo.files.results.save_result` for the file of each result and ``**kw``.

        Returns
        -------
        Path
            The file (or a trade study's folder) to give ``load_result``.
        """
        return shell("save_result")(self, path, **kw)
