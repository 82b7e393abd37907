"""Package attributes imported on first use (PEP 562).

A package lists its public names and the module each lives in; importing the package then
costs nothing, and ``from aeroservo.files import load_wing`` imports only ``wing_file``. This
keeps the command line's start-up to what a command needs (issue 17).

A public name must not be the name of one of the package's modules (``design.lqr`` was both a
module and a function until issue 39): importing the module binds the package attribute to it,
and the function would never be looked up. ``aeroservo.design`` still imports its modules
eagerly.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable


def lazy_attributes(
    package: str, names: dict[str, str], modules: dict[str, str] | None = None
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """``__getattr__`` and ``__dir__`` of a package whose attributes load on first use.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    names : dict
        Public name -> module (relative to the package) that defines it.
    modules : dict, optional
        Attribute -> module (relative) bound as a whole.
    """
    modules = modules or {}

    def __getattr__(name: str) -> object:
        if name in names:
            value = getattr(importlib.import_module(f".{names[name]}", package), name)
        elif name in modules:
            value = importlib.import_module(f".{modules[name]}", package)
        else:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        vars(importlib.import_module(package))[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(importlib.import_module(package))) | set(names) | set(modules))

    return __getattr__, __dir__
