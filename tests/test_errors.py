"""One exception module (issue 39 item 3): ``InputError``, ``NumericalError`` and
``VerdictFailure`` under ``AeroservoError``, each mapped to its exit code (2, 1, 3) with one
line on stderr; the built-in bases keep ``except ValueError`` / ``except ArithmeticError``."""

from __future__ import annotations

import contextlib
import io

import numpy as np
import pytest

import aeroservo as aes
from aeroservo import cli
from aeroservo.errors import AeroservoError, InputError, NumericalError, VerdictFailure


@pytest.mark.parametrize(
    "cls, base, code",
    [(InputError, ValueError, 2), (NumericalError, ArithmeticError, 1), (VerdictFailure, None, 3)],
)
def test_the_hierarchy_and_exit_codes(cls, base, code):
    assert issubclass(cls, AeroservoError) and cls.exit_code == code
    if base is not None:
        assert issubclass(cls, base)
    assert getattr(aes, cls.__name__) is cls


@pytest.mark.parametrize(
    "exc, code, line",
    [
        (InputError("f.toml: a.b = 3: must be below 2"), 2, "aeroservo: error: f.toml: a.b = 3"),
        (NumericalError("solver did not\nconverge"), 1, "aeroservo: numerical failure: solver"),
        (VerdictFailure("loop unstable\nat 150 m/s"), 3, "aeroservo: loop unstable at 150 m/s"),
        (ArithmeticError("plain"), 1, "aeroservo: numerical failure: plain"),
        (np.linalg.LinAlgError("singular"), 1, "aeroservo: numerical failure: singular"),
    ],
)
def test_the_command_line_maps_each_error_to_its_code(exc, code, line, monkeypatch):
    def fail(args):
        raise exc

    monkeypatch.setitem(cli.scenarios.HANDLERS, "examples", fail)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        got = cli.main(["examples"])
    assert got == code
    text = err.getvalue()
    assert text.count("\n") == 1 and text.startswith(line), text


def test_numerical_failures_of_the_engines_are_numerical_errors():
    """A solver that cannot complete raises NumericalError (exit 1), not an input error."""
    from aeroservo.design.riccati import solve_dare

    A = np.array([[2.0, 0.0], [0.0, 3.0]])  # unstable and uncontrollable: no stabilising X
    B = np.array([[0.0], [1.0]])
    with pytest.raises(NumericalError, match="no stabilising solution"), np.errstate(all="ignore"):
        solve_dare(A, B, np.eye(2), np.eye(1))
