"""The Dask cluster of a trade study: a local cluster, or a scheduler reached and checked,
with its failures reported in one line.

No scheduler at the address fails after ``connect_timeout`` and a scheduler without workers
after ``worker_timeout`` (an :class:`~aeroservo.errors.InputError` naming the address); a
worker lost while the study runs is a warning naming it and the number of cases Dask
resubmitted to the other workers (:class:`LostWorkers`); an interrupted run shuts the cluster
down without distributed's warnings about the tasks cancelled in flight
(:func:`quiet_distributed`, :func:`dask_setup`).
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import signal
import threading
from collections.abc import Iterator

from ..errors import InputError, check_int, check_number

__all__ = [
    "LostWorkers",
    "check_address",
    "connect",
    "dask_setup",
    "dask_teardown",
    "local_cluster",
    "quiet_distributed",
]

_ADDRESS_RE = re.compile(r"(tcp|tls)://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):(\d{1,5})")
_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def dask_setup(worker: object) -> None:
    """Preload of :func:`local_cluster`'s worker processes, called as each starts.

    They share the terminal's process group, so Ctrl-C reaches them too: they ignore it (the
    main process shuts them down), and they do not warn about the case cancelled in flight
    when they are closed.
    """
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    logging.getLogger("distributed.worker.state_machine").setLevel(logging.ERROR)


def dask_teardown(worker: object) -> None:
    """Preload teardown, called as a worker of :func:`local_cluster` closes: its shutdown,
    perhaps with the scheduler closing too after an interrupt, logs nothing."""
    _silence(logging.CRITICAL + 1)


def _worker_probe() -> dict:
    """What a worker runs before the study: its aeroservo version and thread settings."""
    from .._version import __version__

    return {
        "aeroservo": __version__,
        "pid": os.getpid(),
        **{k: os.environ.get(k) for k in _THREAD_VARS},
    }


@contextlib.contextmanager
def local_cluster(n_workers: int = 2, *, timeout: float = 60.0) -> Iterator[object]:
    """A ``distributed.LocalCluster`` for trade studies (context manager).

    Worker processes on the loopback interface, one thread each, no dashboard, with
    ``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS`` and ``MKL_NUM_THREADS`` = 1 set *before*
    the worker processes start (BLAS reads them when NumPy is imported), so that N workers use
    N cores instead of fighting over them. The workers ignore SIGINT (see :func:`dask_setup`).

    Parameters
    ----------
    n_workers : int
        Worker processes.
    timeout : float
        Time allowed for a worker to reach the scheduler [s].
    """
    import dask
    from distributed import LocalCluster

    n_workers = check_int("n_workers", n_workers, lo=1, hi=256)
    timeout = check_number("timeout", timeout, unit="s", lo=0.0, lo_open=True)
    one = {k: "1" for k in _THREAD_VARS}
    saved = {k: os.environ.get(k) for k in _THREAD_VARS}
    # Nanny reads "pre-spawn-environ" (overridden by os.environ) when it is created and sets
    # it in the worker's environment before spawning; restore ours once the workers run.
    os.environ.update(one)
    try:
        with dask.config.set(
            {
                "distributed.nanny.pre-spawn-environ": one,
                "distributed.comm.timeouts.connect": f"{timeout}s",
            }
        ):
            cluster = LocalCluster(
                n_workers=n_workers,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address=None,
                # no dashboard; its HTTP server (health checks) on a free loopback port
                scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
                env=one,
                death_timeout=timeout,
                preload=[__name__],
            )
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    try:
        yield cluster
    finally:
        cluster.close()


def check_address(scheduler: str) -> str:
    """The scheduler address, checked (``tcp://host:port``)."""
    if not isinstance(scheduler, str) or not _ADDRESS_RE.fullmatch(scheduler.strip()):
        raise InputError(
            f"scheduler = {scheduler!r}: expected a Dask scheduler address 'tcp://host:port'"
        )
    return scheduler.strip()


def connect(
    stack: contextlib.ExitStack, address: str, connect_timeout: float, worker_timeout: float
):
    """A ``distributed.Client`` of the scheduler at ``address`` (closed with ``stack``) that
    has a worker, its workers running this version of aeroservo.

    Parameters
    ----------
    stack : contextlib.ExitStack
    address : str
        Scheduler address.
    connect_timeout : float
        Time allowed to reach the scheduler [s].
    worker_timeout : float
        Time allowed for the scheduler to have a worker [s].

    Returns
    -------
    distributed.Client
    """
    from distributed import Client

    try:
        client = stack.enter_context(Client(address, timeout=f"{connect_timeout}s"))
    except (OSError, TimeoutError):
        raise InputError(
            f"scheduler = {address!r}: no Dask scheduler answered within {connect_timeout:g} s "
            "(is 'dask scheduler' running there?)"
        ) from None
    try:
        client.wait_for_workers(1, timeout=worker_timeout)
    except TimeoutError:
        raise InputError(
            f"scheduler = {address!r} has no workers (waited {worker_timeout:g} s); start one with "
            f"'dask worker {address}' where this aeroservo is installed"
        ) from None
    try:
        probes = client.run(_worker_probe)
    except Exception as exc:
        raise RuntimeError(
            f"the workers of {address} cannot run aeroservo.studies.trade "
            f"({type(exc).__name__}: {exc}); install aeroservo on them"
        ) from exc
    here = _worker_probe()["aeroservo"]
    other = {w: p["aeroservo"] for w, p in probes.items() if p["aeroservo"] != here}
    if other:
        raise RuntimeError(
            f"the workers of {address} run other aeroservo versions {other} than this "
            f"process ({here}); the case ids and results would not match"
        )
    return client


@contextlib.contextmanager
def _sigint_deferred() -> Iterator[None]:
    """Hold Ctrl-C back during a short call to the scheduler and deliver it after: a
    ``KeyboardInterrupt`` inside a blocking call of distributed's client makes its event loop
    log a traceback (``distributed.utils.sync``)."""
    caught: list[int] = []
    main = threading.current_thread() is threading.main_thread()
    previous = signal.getsignal(signal.SIGINT) if main else None
    if previous is None:  # not the main thread, or a handler not set from Python
        yield
        return
    signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        if caught:
            signal.raise_signal(signal.SIGINT)


class LostWorkers:
    """The workers that left the cluster while the study ran, and how many of its cases each
    held (those Dask resubmits to the other workers).

    :meth:`notes` compares the scheduler's workers with those of its last call and reads the
    ``remove-worker`` event the scheduler logged under each departed worker's address (it
    names the tasks the worker was processing or held the only result of).

    Parameters
    ----------
    client : distributed.Client
    keys : list of str
        Task keys of the study's cases.
    """

    def __init__(self, client, keys: list[str]) -> None:
        self.client = client
        self.keys = set(keys)
        self.known = set(client.nthreads())
        self.n_workers = 0
        self.n_cases = 0

    def _held(self, worker: str) -> tuple[int | None, bool]:
        """Cases ``worker`` held when it was removed (None: unknown), and whether the removal
        was expected (a worker retired, not lost)."""
        try:
            events = self.client.get_events(worker)
        except Exception:  # an old or unusual scheduler: say it without the count
            return None, False
        held, expected = None, False
        for _, msg in events:
            if isinstance(msg, dict) and msg.get("action") == "remove-worker":
                tasks = set(msg.get("processing-tasks") or ())
                tasks |= set(msg.get("lost-computed-tasks") or ())
                held, expected = len(self.keys & tasks), bool(msg.get("expected"))
        return held, expected

    def notes(self) -> list[str]:
        """One line per worker lost since the last call (or retired with cases of ours)."""
        with _sigint_deferred():
            now = set(self.client.nthreads())
            gone, self.known = sorted(self.known - now), now
            removals = {worker: self._held(worker) for worker in gone}
        out = []
        for worker in gone:
            held, expected = removals[worker]
            if expected and not held:
                continue  # retired without our cases: nothing to say
            self.n_workers += 1
            self.n_cases += held or 0
            cases = (
                "its cases in flight were"
                if held is None
                else f"{held} of its cases {'was' if held == 1 else 'were'}"
            )
            out.append(
                f"Dask worker {worker} was {'retired' if expected else 'lost'} during the "
                f"study; {cases} resubmitted to the other workers"
            )
        return out


def _silence(level: int) -> list[tuple[logging.Logger, int]]:
    """Set distributed's and tornado's loggers to ``level``; returns their previous levels."""
    names = ["distributed", "tornado"] + [
        n
        for n, lg in logging.root.manager.loggerDict.items()
        if isinstance(lg, logging.Logger) and n.split(".")[0] in ("distributed", "tornado")
    ]
    saved = [(lg, lg.level) for lg in map(logging.getLogger, names)]
    for lg, _ in saved:
        lg.setLevel(level)
    return saved


def quiet_distributed(stack: contextlib.ExitStack) -> None:
    """Silence distributed's and tornado's loggers until ``stack`` closes: an interrupted
    run's shutdown logs a warning for every task cancelled in flight."""
    saved = _silence(logging.CRITICAL + 1)
    stack.callback(lambda: [lg.setLevel(level) for lg, level in saved])


def map_tasks(fn, shared, items: list, *, workers: int, scheduler, timeout: float, bar, what: str):
    """``[fn(shared, item) for item in items]`` on Dask (a local cluster of ``workers``
    processes, or the running scheduler at ``scheduler``), in order, ``bar`` updated as each
    finishes; a failed task raises a RuntimeError naming ``what`` and the item's index."""
    import contextlib
    import time
    import warnings

    from distributed import as_completed

    results: dict = {}
    with contextlib.ExitStack() as stack:
        if scheduler is None:
            address = stack.enter_context(local_cluster(workers, timeout=timeout)).scheduler_address
        else:
            address = check_address(scheduler)
        client = connect(stack, address, 5.0, 10.0)
        keys = [f"{what}-{i}-{time.time_ns()}" for i in range(len(items))]
        lost = LostWorkers(client, keys)
        [shared_f] = client.scatter([shared], broadcast=True)
        futures = client.map(fn, [shared_f] * len(items), items, key=keys, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for fut, res in as_completed(futures, with_results=True, raise_errors=False):
                if fut.status != "finished":
                    raise RuntimeError(f"{what} {index[fut.key]}: {res!r}")
                results[index[fut.key]] = res
                for note in lost.notes():
                    warnings.warn(note, UserWarning, stacklevel=3)
                bar.update(1)
        finally:
            client.cancel([f for f in futures if not f.done()])
    return [results[i] for i in range(len(items))]
