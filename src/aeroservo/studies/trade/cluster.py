"""Running a trade study on Dask: a local cluster or an existing one, finished cases skipped,
each case written atomically as it arrives (see :mod:`aeroservo.studies.trade`); the cluster
itself, and its failures, in :mod:`.workers`."""

from __future__ import annotations

import contextlib
import json
import time
import warnings
from pathlib import Path

from ...atomic import atomic_write, atomic_write_text
from ...errors import InputError, check_int, check_number
from ..dask_runner import (
    LostWorkers,
    _worker_probe,  # noqa: F401 (tests import it from here)
    check_address,
    connect,
    local_cluster,
    quiet_distributed,
)
from .cases import _blank, evaluate_case
from .grid import _digest, study_settings, trade_cases
from .results import TradeResult, _assemble
from .study import FORMAT, TradeStudy

__all__ = ["local_cluster", "run_trade"]


def _case_task(study: TradeStudy, params: dict) -> dict:
    """The work function shipped to the workers (module level: picklable by reference)."""
    return evaluate_case(study, params)


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
    workers: int = 2,
    progress: bool = True,
    timeout: float = 60.0,
    connect_timeout: float = 5.0,
    worker_timeout: float = 10.0,
    n_workers: int | None = None,
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
        version of aeroservo. Default: a local cluster of ``workers`` processes.
    workers : int
        Worker processes of the local cluster (as ``workers`` of
        :func:`~aeroservo.studies.gust.run.run_gust_loads` and
        :func:`~aeroservo.studies.lco.run.run_lco`; a trade study runs on at least one).
    progress : bool
        Show a tqdm progress bar over the cases as they finish.
    timeout : float
        Time allowed for the local cluster's workers to start [s].
    connect_timeout : float
        Time allowed to reach the scheduler [s].
    worker_timeout : float
        Time allowed for the scheduler to have a worker [s].
    n_workers : int, optional
        Deprecated name of ``workers``.

    Returns
    -------
    TradeResult

    Raises
    ------
    InputError
        No scheduler answers at ``scheduler`` within ``connect_timeout``, or it has no worker
        within ``worker_timeout`` (nothing is left in a new ``out_dir``).
    KeyboardInterrupt
        On an interrupt, with a message saying how many cases are written.

    Warns
    -----
    UserWarning
        A worker was lost while the study ran; Dask resubmits its cases to the other workers,
        and the warning says how many.

    Notes
    -----
    Each case's file is written as soon as its result arrives, so an interrupted run loses only
    the cases in flight. A case whose evaluation failed is a finished case (recorded with its
    message); a case lost to the cluster itself (e.g. killing a worker each time it runs it)
    is reported in the table but not written, so that the next run tries it again.
    """
    t_start = time.perf_counter()
    if not isinstance(study, TradeStudy):
        raise InputError(f"study = {study!r}: expected a TradeStudy")
    if scheduler is not None:
        scheduler = check_address(scheduler)
    if n_workers is not None:
        import warnings

        warnings.warn(
            "run_trade(n_workers=...) is deprecated: use workers=", DeprecationWarning, stacklevel=2
        )
        workers = n_workers
    n_workers = check_int("workers", workers, lo=1, hi=256)
    timeout = check_number("timeout", timeout, unit="s", lo=0.0, lo_open=True)
    connect_timeout = check_number(
        "connect_timeout", connect_timeout, unit="s", lo=0.0, lo_open=True
    )
    worker_timeout = check_number("worker_timeout", worker_timeout, unit="s", lo=0.0, lo_open=True)
    out = Path(out_dir)
    cases_dir = out / "cases"
    made_out = not out.exists()
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
                study,
                pending,
                cases_dir,
                scheduler,
                n_workers,
                progress,
                (timeout, connect_timeout, worker_timeout),
                n_skipped,
            )
        except BaseException:
            if fresh and not any(cases_dir.iterdir()):  # e.g. no scheduler at that address
                (out / "study.json").unlink(missing_ok=True)
                cases_dir.rmdir()
                if made_out and not any(out.iterdir()):
                    out.rmdir()
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
    timeouts: tuple[float, float, float],
    n_skipped: int,
) -> dict[str, dict]:
    from tqdm import tqdm

    timeout, connect_timeout, worker_timeout = timeouts
    done: dict[str, dict] = {}
    with contextlib.ExitStack() as quiet, contextlib.ExitStack() as stack:
        if scheduler is None:
            cluster = stack.enter_context(local_cluster(n_workers, timeout=timeout))
            address = cluster.scheduler_address
        else:
            address = scheduler
        client = connect(stack, address, connect_timeout, worker_timeout)
        keys = [f"trade-{study.name}-{c['case_id']}" for c in pending]
        lost = LostWorkers(client, keys)
        bar = stack.enter_context(
            tqdm(total=len(pending), desc=study.name, unit="case", disable=not progress)
        )
        try:
            _gather(client, study, pending, keys, cases_dir, done, lost, bar, n_skipped)
        except KeyboardInterrupt:
            quiet_distributed(quiet)
            files = (cases_dir / f"{c['case_id']}.json" for c in pending)
            n_written = n_skipped + sum(f.exists() for f in files)
            raise KeyboardInterrupt(
                f"{n_written} of {n_skipped + len(pending)} cases written to {cases_dir}; "
                "run the study again to resume"
            ) from None
    return done


def _gather(
    client,
    study: TradeStudy,
    pending: list[dict],
    keys: list[str],
    cases_dir: Path,
    done: dict[str, dict],
    lost: LostWorkers,
    bar,
    n_skipped: int,
) -> None:
    """Submit the pending cases (task keys ``keys``) to ``client`` and write each as it
    arrives, into ``done`` too; report the workers lost meanwhile."""
    from distributed import as_completed

    [study_f] = client.scatter([study], broadcast=True)
    futures = client.map(
        _case_task,
        [study_f] * len(pending),
        [{k: v for k, v in c.items() if k != "case_id"} for c in pending],
        key=keys,
        pure=False,
    )
    ids = {f.key: c["case_id"] for f, c in zip(futures, pending, strict=True)}
    params = {c["case_id"]: c for c in pending}
    if n_skipped:
        bar.set_postfix(skipped=n_skipped)
    try:
        for fut, res in as_completed(futures, with_results=True, raise_errors=False):
            cid = ids[fut.key]
            if fut.status == "finished" and isinstance(res, dict):
                _write_case(cases_dir, res)
            else:  # lost to the cluster: reported, not written (retried next run)
                failed = _blank(params[cid])
                failed.update(case_id=cid, failed_stage="cluster", error=f"not evaluated: {res!r}")
                res = failed
            done[cid] = res
            fut.release()
            _report_lost(lost, bar, n_skipped)
            bar.update(1)
        _report_lost(lost, bar, n_skipped)
    finally:
        client.cancel([f for f in futures if not f.done()])


def _report_lost(lost: LostWorkers, bar, n_skipped: int) -> None:
    """A warning per worker lost since the last call, and their count on the progress bar."""
    notes = lost.notes()
    for note in notes:
        warnings.warn(note, UserWarning, stacklevel=5)
    if notes:
        post = {"skipped": n_skipped} if n_skipped else {}
        bar.set_postfix(**post, lost_workers=lost.n_workers, resubmitted=lost.n_cases)
