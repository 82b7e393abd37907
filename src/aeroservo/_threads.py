"""BLAS thread pools limited while aeroservo computes.

The matrices of a stick model are small (tens to a few thousand rows) and used in long
sequences of small operations (inverse iterations, eigenvalue sweeps, time steps). A
multi-threaded BLAS only adds synchronization there, and OpenBLAS's busy-waiting threads make
it many times slower on a loaded machine: the 20-element Goland flutter boundary took 0.52 s
with one thread and 3.6 s with two on this 2-core machine under load. aeroservo's compute
entry points therefore run with the BLAS/OpenMP pools limited to ``AEROSERVO_BLAS_THREADS``
threads (default 1) through threadpoolctl; the caller's settings are restored on return, so
code outside aeroservo is not affected.
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Callable
from typing import TypeVar

__all__ = ["blas_limited", "blas_threads"]

F = TypeVar("F", bound=Callable)
_controller = None
_n_modules = 0


def blas_threads() -> int:
    """Thread count used inside aeroservo (environment ``AEROSERVO_BLAS_THREADS``, default 1)."""
    text = os.environ.get("AEROSERVO_BLAS_THREADS", "1")
    try:
        n = int(text) if text.strip().isascii() and text.strip().isdigit() else 0
    except ValueError:  # more digits than Python converts
        n = 0
    if not 1 <= n <= 1024:
        from .errors import InputError

        raise InputError(
            f"AEROSERVO_BLAS_THREADS = {text[:40]!r}: expected an integer from 1 to 1024"
        )
    return n


def blas_limited(fn: F) -> F:
    """Decorator: run ``fn`` with the BLAS pools limited to :func:`blas_threads` threads."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        global _controller, _n_modules
        if _controller is None or len(sys.modules) != _n_modules:
            # the pools are found once; again after an import, which may have loaded a BLAS
            from threadpoolctl import ThreadpoolController

            _controller = ThreadpoolController()
            _n_modules = len(sys.modules)
        with _controller.limit(limits=blas_threads()):
            return fn(*args, **kwargs)

    return wrapper
