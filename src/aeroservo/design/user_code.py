"""The user's own Python code in a loop: laws written as Python functions (:class:`PythonLaw`,
built by :func:`python_law`) and the files they come from (:func:`run_law_file`), each run
within a wall-clock budget, with what it may do to aeroservo contained.

The rules (``docs/controllers.md``, "Python laws: what they may do"):

* Each call of a law has a **budget** of wall-clock time (:data:`DEFAULT_BUDGET`, 1 s, a
  controller file's ``budget_s``); loading its file has :data:`IMPORT_BUDGET` (60 s,
  ``import_budget_s``). On the main thread of a platform with ``signal.setitimer`` (Linux,
  macOS) a ``SIGALRM`` timer interrupts the code when the budget runs out (and again at every
  further budget, should the code swallow the first); elsewhere (Windows, a Dask worker's
  thread) the time of each call is measured and a call over the budget fails once it returns.
  Either way it is a :class:`LawError` (exit code 2): the law, not the computation, is at
  fault, and the fix is in the input (the law, or its budget).
* A command must be finite and at most :data:`MAX_COMMAND` (1e12, the bound of a gain file's
  entries and of every limit) in magnitude: beyond it no actuator is meant.
* ``sys.exit`` in the law or in its file, and any exception, become one line naming the law,
  the exception's type and the first line of its message, and the time of the sample.
* What the file writes to ``sys.stdout`` and ``sys.stderr`` while loaded is captured (a script's
  ``argparse`` cannot print a usage line that reads as aeroservo's): quoted in the error if
  loading fails, reported as one warning if it succeeds.
"""

from __future__ import annotations

import contextlib
import io
import signal
import threading
import time
import types
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, check_number, show_value
from ..linear.signals import check_names, describe
from .compensator import sample_period

__all__ = [
    "PythonLaw",
    "python_law",
    "LawError",
    "run_law_file",
    "call_within",
    "law_session",
    "first_line",
    "check_budget",
    "DEFAULT_BUDGET",
    "IMPORT_BUDGET",
    "MAX_BUDGET",
    "MAX_COMMAND",
]

DEFAULT_BUDGET = 1.0
"""Wall-clock budget of one call of a law [s] (a controller file's ``budget_s``)."""

IMPORT_BUDGET = 60.0
"""Wall-clock budget of loading a law's file [s] (a controller file's ``import_budget_s``)."""

MAX_BUDGET = 3600.0
"""Largest budget [s] either may be given."""

MAX_LAW_BYTES = 10 * 2**20
"""Largest Python file of a law [bytes] (read whole)."""

MAX_COMMAND = 1e12
"""Largest magnitude of a law's command [the control's unit]: a gain file's bound on its
entries and the bound of every limit (``aeroservo.errors.RANGES["limit"]``)."""


class LawError(InputError):
    """A user's law failed: raised, exited, ran over its budget or returned bad commands
    (exit code 2). Studies that record a failed march re-raise it: the law is wrong everywhere."""


class OverBudget(Exception):
    """User code ran over its wall-clock budget; ``elapsed`` [s] when it was stopped or
    returned."""

    def __init__(self, elapsed: float):
        super().__init__(f"{elapsed:.3g} s")
        self.elapsed = elapsed


class _Alarm(BaseException):
    """Raised inside the user's code by the timer (not an ``Exception``: a law's ``except
    Exception`` does not swallow it)."""


def _alarm(signum, frame):
    raise _Alarm


_SESSION: dict = {"thread": None}
"""The thread of the :func:`law_session` under way (its SIGALRM handler installed), or None."""


def check_budget(field_name: str, value: object) -> float:
    """A budget [s] in ``(0, MAX_BUDGET]``."""
    return check_number(field_name, value, unit="s", lo=0.0, lo_open=True, hi=MAX_BUDGET)


def _timer_usable() -> bool:
    """Whether a SIGALRM timer can stop code here: POSIX, the main thread, no timer running."""
    return (
        hasattr(signal, "setitimer")
        and threading.current_thread() is threading.main_thread()
        and signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    )


def call_within(budget: float | None, fn: Callable, *args):
    """``fn(*args)`` within ``budget`` seconds of wall-clock time (None: unbounded).

    Raises
    ------
    OverBudget
        When the call ran over: stopped by a SIGALRM timer where one can be used
        (:func:`_timer_usable`), or measured once it returned elsewhere. The timer is disarmed
        and the previous handler of SIGALRM restored in every case (inside :func:`law_session`
        the handler stays for the session: a call then costs two ``setitimer``).
    """
    if budget is None:
        return fn(*args)
    t0 = time.perf_counter()
    ours = _SESSION["thread"] == threading.get_ident()  # a session's handler is in place
    timed = signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0) if ours else _timer_usable()
    if not timed:  # measured: stopped only once it returns
        out = fn(*args)
        elapsed = time.perf_counter() - t0
        if elapsed > budget:
            raise OverBudget(elapsed)
        return out
    previous = None if ours else signal.signal(signal.SIGALRM, _alarm)
    try:
        signal.setitimer(signal.ITIMER_REAL, budget, budget)  # again if the first is swallowed
        return fn(*args)
    except _Alarm:
        pass
    finally:
        _disarm()
        if not ours:
            signal.signal(signal.SIGALRM, signal.SIG_DFL if previous is None else previous)
    raise OverBudget(time.perf_counter() - t0)


def _disarm() -> None:
    """Stop the timer; an alarm due meanwhile is taken here, never left to another handler."""
    while True:
        try:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
            return
        except _Alarm:
            pass


@contextlib.contextmanager
def law_session(controller: object) -> Iterator[None]:
    """While a march steps ``controller``: for a :class:`PythonLaw` with a budget, on the main
    thread, the SIGALRM handler of its budget is installed once for the march rather than at
    every call (the previous handler is restored at the end); anything else runs as it is."""
    if getattr(controller, "budget", None) is None or not isinstance(controller, PythonLaw):
        yield
        return
    if not _timer_usable() or _SESSION["thread"] is not None:
        yield
        return
    previous = signal.signal(signal.SIGALRM, _alarm)
    _SESSION["thread"] = threading.get_ident()
    try:
        yield
    finally:
        _SESSION["thread"] = None
        _disarm()
        signal.signal(signal.SIGALRM, signal.SIG_DFL if previous is None else previous)


def first_line(exc: BaseException) -> str:
    """``"Type: first line of the message"`` (at most 200 characters) of an exception."""
    try:
        lines = str(exc).strip().splitlines()
    except Exception:  # an exception whose message cannot be made
        lines = []
    text = f"{type(exc).__name__}: {lines[0].strip()}" if lines else type(exc).__name__
    return text if len(text) <= 200 else text[:197] + "..."


def _exit_text(exc: SystemExit) -> str:
    return f"called sys.exit({show_value(exc.code) if exc.code is not None else ''})"


class _Captured(io.StringIO):
    """A text sink keeping the first :attr:`KEEP` characters of what is written (bounded
    memory) and counting the lines."""

    KEEP = 2000

    def __init__(self):
        super().__init__()
        self.kept, self.lines, self.chars = "", 0, 0

    def write(self, s: str) -> int:
        s = str(s)
        if len(self.kept) < self.KEEP:
            self.kept += s[: self.KEEP - len(self.kept)]
        self.lines += s.count("\n")
        self.chars += len(s)
        return len(s)

    def summary(self) -> str:
        """``""`` or ``"it wrote N lines, the first 'text'"``."""
        shown = [ln.strip() for ln in self.kept.splitlines() if ln.strip()]
        if not self.chars or not shown:
            return ""
        n = max(self.lines, 1)
        return f"it wrote {n} line{'s' if n > 1 else ''}, the first {show_value(shown[0])}"


def run_law_file(path: Path, budget: float = IMPORT_BUDGET) -> tuple[types.ModuleType, str]:
    """Run the Python file ``path`` as a module (the user's own code) within ``budget`` [s];
    returns ``(module, output)``, ``output`` the summary of what it wrote (``""``: nothing).
    No bytecode is cached next to it (no ``__pycache__`` is left behind).

    Raises
    ------
    InputError
        Its message (to follow ``file = ...: ``) says why: not a ``.py`` file, not readable,
        ``sys.exit`` or an exception while it ran (first line, and the first line it wrote),
        over budget.
    """
    import importlib.util

    if path.suffix != ".py":
        raise InputError(f"expected a Python file ending in .py ({path.name})")
    try:
        if path.stat().st_size > MAX_LAW_BYTES:
            raise InputError(f"larger than {MAX_LAW_BYTES // 2**20} MiB: not a law's source")
        source = importlib.util.decode_source(path.read_bytes())
    except (OSError, UnicodeDecodeError, SyntaxError) as exc:
        raise InputError(f"cannot be read: {first_line(exc)}") from None
    module = types.ModuleType(f"aeroservo_law_{path.stem}")
    module.__file__ = str(path)
    out = _Captured()

    def run() -> None:
        exec(compile(source, str(path), "exec"), module.__dict__)

    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
            call_within(budget, run)
    except OverBudget as exc:
        raise InputError(
            f"loading it took over its budget of {budget:g} s (stopped after {exc}): an endless "
            "loop at import? (the controller file's import_budget_s)"
        ) from None
    except SystemExit as exc:
        note = out.summary()
        raise InputError(
            f"running it {_exit_text(exc)} at import"
            + (f"; {note}" if note else "")
            + " (a script's code belongs under if __name__ == '__main__':)"
        ) from None
    except Exception as exc:  # the user's code (a SyntaxError too): an input error here
        note = out.summary()
        raise InputError(
            f"running it failed: {first_line(exc)}" + (f"; {note}" if note else "")
        ) from None
    return module, out.summary()


@dataclass
class PythonLaw:
    """A nonlinear or adaptive law written in Python (simulated; no linear analyses).

    ``fn(t, y)`` (or ``fn(t, y, x)`` with ``needs_state``) returns the commands at time ``t``
    [s] from the sensor values ``y`` (and the plant state ``x``); ``reset()`` (optional) is
    called before each run. Each call has ``budget`` seconds of wall-clock time (None:
    unbounded) and must return finite commands of magnitude at most :data:`MAX_COMMAND`;
    a failure is a :class:`LawError` naming the law and the time. Built, it is at ``t = 0``:
    ``command`` works before ``reset``. Use :func:`python_law` to build one.
    """

    fn: Callable
    controls: tuple
    sensors: tuple
    dt: float
    needs_state: bool = False
    on_reset: Callable | None = None
    name: str = "Python law"
    budget: float | None = DEFAULT_BUDGET
    is_linear: bool = False
    _k: int = field(default=0, init=False, repr=False, compare=False)

    def reset(self) -> None:
        self._k = 0
        if self.on_reset is not None:
            self._run(self.on_reset, (), "in its reset()")

    def _run(self, fn: Callable, args: tuple, when: str):
        """``fn(*args)`` within the budget; every failure a :class:`LawError` saying ``when``."""
        try:
            return call_within(self.budget, fn, *args)
        except OverBudget as exc:
            raise LawError(
                f"{self.name}: {when}: ran over its budget of {self.budget:g} s per call (stopped "
                f"after {exc}): an endless loop? (the controller file's budget_s, "
                "python_law(budget=...))"
            ) from None
        except SystemExit as exc:
            raise LawError(
                f"{self.name}: {when}: {_exit_text(exc)} (a law returns its commands)"
            ) from None
        except Exception as exc:  # the user's code: reported as an input error, with its place
            raise LawError(f"{self.name}: {when}: raised {first_line(exc)}") from exc

    def command(self, y: np.ndarray, x: np.ndarray | None = None) -> np.ndarray:
        t = self._k * self.dt
        args = (t, y, x) if self.needs_state else (t, y)
        out = self._run(self.fn, args, f"at t = {t:g} s")
        try:
            c = np.asarray(out, dtype=float).reshape(-1)
        except (TypeError, ValueError, OverflowError):
            c = np.array([np.nan])
        if c.size != len(self.controls) or not np.all(np.abs(c) <= MAX_COMMAND):
            raise LawError(
                f"{self.name}: at t = {t:g} s: returned {describe(out)}; expected "
                f"{len(self.controls)} finite commands {list(self.controls)} of magnitude at "
                f"most {MAX_COMMAND:g}"
            )
        return c

    def update(self, y: np.ndarray, u: np.ndarray) -> None:
        self._k += 1


def python_law(
    fn: Callable,
    controls: Sequence[str],
    sensors: Sequence[str] = (),
    *,
    sample_rate: float,
    needs_state: bool = False,
    reset: Callable | None = None,
    name: str | None = None,
    budget: float | None = DEFAULT_BUDGET,
) -> PythonLaw:
    """A controller from a Python function ``fn(t, y) -> commands`` (see :class:`PythonLaw`).

    Parameters
    ----------
    fn : callable
        ``fn(t [s], y)`` or, with ``needs_state``, ``fn(t, y, x)``; returns one command per
        control, in the controls' units, each at most :data:`MAX_COMMAND` in magnitude.
    controls, sensors : sequence of str
    sample_rate : float
        [Hz]
    needs_state : bool
        Pass the plant state too.
    reset : callable, optional
        Called before each simulation (to clear the law's own memory).
    name : str, optional
        The law's name in messages (default: the function's name).
    budget : float or None
        Wall-clock time one call may take [s] (default 1 s; None: unbounded); see the module
        docstring for how it is enforced.
    """
    if not callable(fn):
        raise InputError(f"fn = {describe(fn)}: expected a function fn(t, y)")
    if reset is not None and not callable(reset):
        raise InputError(f"reset = {describe(reset)}: expected a function of no argument")
    return PythonLaw(
        fn,
        tuple(check_names("controls", controls)),
        tuple(check_names("sensors", sensors, empty=True)),
        sample_period(sample_rate),
        bool(needs_state),
        reset,
        name or getattr(fn, "__name__", "Python law"),
        None if budget is None else check_budget("budget", budget),
    )
