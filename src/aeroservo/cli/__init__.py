"""The ``aeroservo`` command.

Exit codes (:mod:`aeroservo.errors`): 0 success, 2 usage or input error (``InputError``, one
line), 1 numerical failure (``NumericalError``, any ``ArithmeticError``), 3 a failed verdict
(``VerdictFailure``: a closed loop that is unstable or misses its margins, unless the scenario
expects it).
Heavy packages (matplotlib, python-control, casadi) are imported only by the commands that
need them. Commands: :mod:`.analysis` (``flutter``, ``envelope``, ``modes``),
:mod:`.scenarios` (``run`` and each scenario kind's command, made from the registry of kinds:
``simulate``, ``trade``, ``loads``, ``lco``; ``examples``) and :mod:`.results` (``plot``,
``export``), :mod:`.importing` (``import nastran``).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from collections.abc import Sequence

from .._threads import blas_limited, blas_threads
from ..errors import InputError, NumericalError, VerdictFailure
from . import analysis, importing, optimize, results, scenarios, sensitivity

__all__ = ["main"]


class _UsageError(InputError):
    """A command-line usage error (one line, exit 2)."""


class _OneLineParser(argparse.ArgumentParser):
    """argparse that reports a usage error in one line (with where to find help)."""

    def error(self, message: str):
        raise _UsageError(f"{message} (see '{self.prog} --help')")


def _parser() -> argparse.ArgumentParser:
    from .._version import __version__

    p = _OneLineParser(
        prog="aeroservo",
        description="Aero-servo-elastic analysis of wings with control surfaces (SI units).",
    )
    p.add_argument("--version", action="version", version=f"aeroservo {__version__}")
    p.add_argument("--debug", action="store_true", help="show the traceback of an unexpected error")
    sub = p.add_subparsers(
        dest="command", required=True, metavar="COMMAND", parser_class=_OneLineParser
    )
    analysis.add_parsers(sub)
    scenarios.add_parsers(sub)
    results.add_parsers(sub)
    sensitivity.add_parsers(sub)
    optimize.add_parsers(sub)
    importing.add_parsers(sub)
    return p


@contextlib.contextmanager
def _json_stdout():
    """While a ``--json`` command runs, what C libraries write to file descriptor 1 goes to
    stderr; Python's ``print`` still reaches the real stdout, so the JSON stays parseable."""
    sys.stdout.flush()
    try:
        saved = os.dup(1)
    except OSError:  # no stdout at all
        yield
        return
    original = sys.stdout
    try:
        on_fd1 = original.fileno() == 1
    except (AttributeError, OSError, ValueError):  # e.g. captured by a test harness
        on_fd1 = False
    os.dup2(2, 1)
    if on_fd1:
        sys.stdout = os.fdopen(os.dup(saved), "w", encoding="utf-8")
    try:
        yield
    finally:
        sys.stdout.flush()
        if on_fd1:
            sys.stdout.close()
            sys.stdout = original
        os.dup2(saved, 1)
        os.close(saved)


@contextlib.contextmanager
def _warnings_in_one_line():
    """Python warnings raised while a command runs (numpy's floating-point warnings, a
    library's notices) are printed once each, one line per kind, at the end."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            yield
        finally:
            counts: dict[tuple[str, str], int] = {}
            for w in caught:
                text = str(w.message).strip().splitlines()
                key = (w.category.__name__, text[0] if text else "")
                counts[key] = counts.get(key, 0) + 1
            for (category, text), n in counts.items():
                times = f" ({n} times)" if n > 1 else ""
                hint = (
                    "; results may be inaccurate: check the magnitudes of the inputs"
                    if category == "RuntimeWarning"
                    else ""
                )
                print(f"aeroservo: warning: {category}: {text}{times}{hint}", file=sys.stderr)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    parser = _parser()
    try:
        args = parser.parse_args(argv)
        blas_threads()  # the environment, checked where its error is one line
    except _UsageError as exc:
        print(f"aeroservo: error: {exc}", file=sys.stderr)
        return 2
    except InputError as exc:
        print(f"aeroservo: error: {exc}", file=sys.stderr)
        return 2
    try:
        with _warnings_in_one_line():
            return blas_limited(_run)(args)
    except BrokenPipeError:  # e.g. 'aeroservo modes goland | head -1': not an error
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except KeyboardInterrupt as exc:
        if args.debug:
            raise
        detail = " ".join(str(exc).split())  # e.g. a trade study's cases written so far
        print(
            f"aeroservo: interrupted: {detail}"
            if detail
            else "aeroservo: interrupted (a run writes its files only once complete; a trade "
            "study resumes where it stopped)",
            file=sys.stderr,
        )
        return 130


def _run(args: argparse.Namespace) -> int:
    handlers = {
        **analysis.HANDLERS,
        **scenarios.HANDLERS,
        **results.HANDLERS,
        **sensitivity.HANDLERS,
        **optimize.HANDLERS,
        **importing.HANDLERS,
    }
    try:
        if getattr(args, "json", False):
            with _json_stdout():
                return handlers[args.command](args)
        return handlers[args.command](args)

    except InputError as exc:
        print(f"aeroservo: error: {exc}", file=sys.stderr)
        return InputError.exit_code
    except VerdictFailure as exc:  # the verdict's one line; the report is already printed
        print(f"aeroservo: {' '.join(str(exc).split())}", file=sys.stderr)
        return VerdictFailure.exit_code
    except BrokenPipeError:
        raise
    except OSError as exc:  # unwritable output folder, unreadable file
        print(f"aeroservo: error: {exc}", file=sys.stderr)
        return InputError.exit_code
    except (RuntimeError, ArithmeticError, __import__("numpy").linalg.LinAlgError) as exc:
        if args.debug:
            raise
        print(f"aeroservo: numerical failure: {' '.join(str(exc).split())}", file=sys.stderr)
        return NumericalError.exit_code
    except Exception as exc:  # a bug: one line, an invitation to report it
        if args.debug:
            raise
        text = " ".join(str(exc).split())
        text = text if len(text) <= 200 else text[:197] + "..."
        print(
            f"aeroservo: internal error: {type(exc).__name__}: {text} (please report it; "
            "'aeroservo --debug ...' shows the traceback)",
            file=sys.stderr,
        )
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
