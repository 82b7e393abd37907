"""Running a trade study on Dask: a local cluster or an existing one, finished cases skipped,
each case written atomically as it arrives (see :mod:`aeroservo.studies.trade`)."""

from __future__ import annotations

import contextlib
import json
import os
import re
import time
from collections.abc import Iterator
from pathlib import Path

from ...atomic import atomic_write, atomic_write_text
from ...errors import InputError, check_int, check_number
from .cases import _blank, evaluate_case
from .grid import _digest, study_settings, trade_cases
from .results import TradeResult, _assemble
from .study import FORMAT, TradeStudy

__all__ = ["local_cluster", "run_trade"]

_ADDRESS_RE = re.compile(r"(tcp|tls)://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):(\d{1,5})")
_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def _case_task(study: TradeStudy, params: dict) -> dict:
    """The work function shipped to the workers (module level: picklable by reference)."""
    return evaluate_case(study, params)


def _worker_probe() -> dict:
    """What a worker runs before the study: its aeroservo version and thread settings."""
    from ..._version import __version__

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
    N cores instead of fighting over them.

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


def _check_address(scheduler: str) -> str:
    if not isinstance(scheduler, str) or not _ADDRESS_RE.fullmatch(scheduler.strip()):
        raise InputError(
            f"scheduler = {scheduler!r}: expected a Dask scheduler address 'tcp://host:port'"
        )
    return scheduler.strip()


def _read_case(path: Path, cid: str) -> dict | None:
    """A finished case file, or None if it is missing or not a finished case of this id."""
    try:
        rec = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(rec, dict) or rec.get("case_id") != cid:
        return None
    if rec.get("status") not in ("ok", "failed"):
        return None
    return rec


def _write_case(cases_dir: Path, rec: dict) -> None:
    atomic_write_text(
        cases_dir / f"{rec['case_id']}.json", json.dumps(rec, indent=1, allow_nan=False) + "\n"
    )


def _manifest(study: TradeStudy, cases: list[dict]) -> dict:
    return {
        "format": FORMAT,
        "name": study.name,
        "parameters": {k: list(v) for k, v in study.parameters.items()},
        "fingerprint": _digest(study_settings(study)),
        "settings": study_settings(study),
        "case_ids": [c["case_id"] for c in cases],
        "csv": f"{study.name}.csv",
        "netcdf": f"{study.name}.nc",
    }


def run_trade(
    study: TradeStudy,
    out_dir: str | Path,
    *,
    scheduler: str | None = None,
    n_workers: int = 2,
    progress: bool = True,
    timeout: float = 60.0,
) -> TradeResult:
    """Run a trade study on Dask, skipping the cases already finished in ``out_dir``.

    Parameters
    ----------
    study : TradeStudy
    out_dir : str or Path
        Output folder (created): ``cases/<case_id>.json`` per case, ``<name>.csv``,
        ``<name>.nc`` and ``study.json``.
    scheduler : str, optional
        Address ``tcp://host:port`` of a running Dask scheduler whose workers can import this
        version of aeroservo. Default: a local cluster of ``n_workers`` processes.
    n_workers : int
        Worker processes of the local cluster.
    progress : bool
        Show a tqdm progress bar over the cases as they finish.
    timeout : float
        Time allowed to start or reach the cluster [s].

    Returns
    -------
    TradeResult

    Notes
    -----
    Each case's file is written as soon as its result arrives, so an interrupted run loses only
    the cases in flight. A case whose evaluation failed is a finished case (recorded with its
    message); a case lost to the cluster itself (e.g. a worker killed) is reported in the
    table but not written, so that the next run tries it again.
    """
    t_start = time.perf_counter()
    if not isinstance(study, TradeStudy):
        raise InputError(f"study = {study!r}: expected a TradeStudy")
    if scheduler is not None:
        scheduler = _check_address(scheduler)
    n_workers = check_int("n_workers", n_workers, lo=1, hi=256)
    timeout = check_number("timeout", timeout, unit="s", lo=0.0, lo_open=True)
    out = Path(out_dir)
    cases_dir = out / "cases"
    fresh = not cases_dir.exists()  # a new study: on a failure before any case, leave nothing
    cases_dir.mkdir(parents=True, exist_ok=True)

    cases = trade_cases(study)
    records: dict[str, dict] = {}
    for c in cases:
        rec = _read_case(cases_dir / f"{c['case_id']}.json", c["case_id"])
        if rec is not None:
            records[c["case_id"]] = rec
    n_skipped = len(records)
    manifest = _manifest(study, cases)
    atomic_write_text(out / "study.json", json.dumps(manifest, indent=1) + "\n")

    pending = [c for c in cases if c["case_id"] not in records]
    if pending:
        try:
            done = _run_pending(
                study, pending, cases_dir, scheduler, n_workers, progress, timeout, n_skipped
            )
        except BaseException:
            if fresh and not any(cases_dir.iterdir()):  # e.g. no scheduler at that address
                (out / "study.json").unlink(missing_ok=True)
                cases_dir.rmdir()
            raise
        records.update(done)

    rows = [records[c["case_id"]] for c in cases]
    result = _assemble(study.name, study.parameters, rows, manifest["settings"])
    result.n_skipped = n_skipped
    result.csv_path = atomic_write(
        out / manifest["csv"], lambda p: result.table.to_csv(p, index=False)
    )
    result.netcdf_path = atomic_write(
        out / manifest["netcdf"],
        lambda p: result.dataset.to_netcdf(p, engine="scipy", format="NETCDF3_64BIT"),
    )
    result.elapsed = time.perf_counter() - t_start
    return result


def _run_pending(
    study: TradeStudy,
    pending: list[dict],
    cases_dir: Path,
    scheduler: str | None,
    n_workers: int,
    progress: bool,
    timeout: float,
    n_skipped: int,
) -> dict[str, dict]:
    from distributed import Client, as_completed
    from tqdm import tqdm

    done: dict[str, dict] = {}
    with contextlib.ExitStack() as stack:
        if scheduler is None:
            cluster = stack.enter_context(local_cluster(n_workers, timeout=timeout))
            address = cluster.scheduler_address
        else:
            address = scheduler
        try:
            client = stack.enter_context(Client(address, timeout=f"{timeout}s"))
        except (OSError, TimeoutError) as exc:
            raise InputError(
                f"scheduler = {address!r}: cannot connect within {timeout:g} s ({exc})"
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
        [study_f] = client.scatter([study], broadcast=True)
        futures = client.map(
            _case_task,
            [study_f] * len(pending),
            [{k: v for k, v in c.items() if k != "case_id"} for c in pending],
            key=[f"trade-{study.name}-{c['case_id']}" for c in pending],
            pure=False,
        )
        ids = {f.key: c["case_id"] for f, c in zip(futures, pending, strict=True)}
        params = {c["case_id"]: c for c in pending}
        bar = stack.enter_context(
            tqdm(total=len(pending), desc=study.name, unit="case", disable=not progress)
        )
        if n_skipped:
            bar.set_postfix(skipped=n_skipped)
        try:
            for fut, res in as_completed(futures, with_results=True, raise_errors=False):
                cid = ids[fut.key]
                if fut.status == "finished" and isinstance(res, dict):
                    _write_case(cases_dir, res)
                else:  # lost to the cluster: reported, not written (retried next run)
                    lost = _blank(params[cid])
                    lost.update(
                        case_id=cid, failed_stage="cluster", error=f"not evaluated: {res!r}"
                    )
                    res = lost
                done[cid] = res
                fut.release()
                bar.update(1)
        finally:
            client.cancel([f for f in futures if not f.done()])
    return done
