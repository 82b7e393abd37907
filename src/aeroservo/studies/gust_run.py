"""Running a gust-loads study: every flight point of every mass case is one task, run in this
process or on Dask (a local cluster of worker processes, or an existing scheduler) with a
progress bar, like a trade study (:mod:`aeroservo.studies.trade.workers`)."""

from __future__ import annotations

import contextlib
import time
import warnings

from ..errors import InputError, check_int
from .gust_loads import GustLoadsStudy, PointLoads, design_point, evaluate_point
from .gust_results import GustLoadsResult, point_records

__all__ = ["run_gust_loads"]


def _settings(study: GustLoadsStudy) -> dict:
    ctrl = study.controller
    limits = study.limits or getattr(ctrl, "limits", None)
    return {
        "limits": {
            "magnitude": dict(getattr(limits, "magnitude", {}) or {}),
            "rate": dict(getattr(limits, "rate", {}) or {}),
        },
        "mass_cases": {k: getattr(w, "name", "") for k, w in study.mass_cases.items()},
        "loads": list(study.loads),
        "controls": list(study.controls),
        "sensors": list(study.sensors),
        "controller": None if ctrl is None else (getattr(ctrl, "name", "") or type(ctrl).__name__),
        "f_g": study.f_g,
        "weights": dict(study.weights),
        "elements": study.elements,
        "gust_model": study.gust_model,
        "sample_rate": study.sample_rate,
        "delay": study.delay,
        "n_gradients": study.n_gradients,
        "turbulence": study.turbulence,
        "points": [
            {
                "altitude": p.altitude,
                "speed": p.speed,
                "speed_name": p.speed_name,
                "mass_case": p.mass_case,
            }
            for p in study.points
        ],
    }


def run_gust_loads(
    study: GustLoadsStudy,
    *,
    workers: int = 0,
    scheduler: str | None = None,
    progress: bool = False,
    timeout: float = 60.0,
) -> GustLoadsResult:
    """Run a gust-loads study.

    Parameters
    ----------
    study : GustLoadsStudy
    workers : int
        0: every point in this process; N > 0: a local Dask cluster of N worker processes.
    scheduler : str, optional
        Address ``tcp://host:port`` of a running Dask scheduler (its workers run this version
        of aeroservo); overrides ``workers``.
    progress : bool
        A progress bar over the flight points on stderr.
    timeout : float
        Time allowed for local workers to start [s].

    Returns
    -------
    GustLoadsResult
    """
    from tqdm import tqdm

    if not isinstance(study, GustLoadsStudy):
        raise InputError(f"study = {study!r}: expected a GustLoadsStudy")
    workers = check_int("workers", workers, lo=0, hi=256)
    t0 = time.perf_counter()
    if study.controller is not None:
        design_point(study)  # errors of the design surface here, once
    points = list(study.points)
    bar = tqdm(total=len(points), desc=study.name, unit="point", disable=not progress)
    with bar:
        if scheduler is None and workers == 0:
            done = []
            for p in points:
                done.append(evaluate_point(study, p))
                bar.update(1)
        else:
            done = _on_dask(study, points, workers, scheduler, timeout, bar)
    records, arrays, skipped = [], {}, []
    for i, pl in enumerate(done):
        r, a = point_records(i, pl, study.loads)
        records += r
        arrays.update(a)
        if not r:  # no loop could be computed there: the point is kept with its reasons
            skipped.append({"point": i, "flight_point": pl.point.label, "notes": list(pl.notes)})
    units: dict = {}
    for pl in done:
        for d in pl.discrete.values():
            units.update(d.units)
    settings = _settings(study)
    settings["elapsed"] = time.perf_counter() - t0
    settings["skipped_points"] = skipped
    return GustLoadsResult(study.name, records, arrays, units, settings)


def _on_dask(study, points, workers, scheduler, timeout, bar) -> list[PointLoads]:
    from distributed import as_completed

    from .trade.workers import LostWorkers, check_address, connect, local_cluster

    results: dict[int, PointLoads] = {}
    with contextlib.ExitStack() as stack:
        if scheduler is None:
            address = stack.enter_context(local_cluster(workers, timeout=timeout)).scheduler_address
        else:
            address = check_address(scheduler)
        client = connect(stack, address, 5.0, 10.0)
        keys = [f"gust-loads-{study.name}-{i}-{time.time_ns()}" for i in range(len(points))]
        lost = LostWorkers(client, keys)
        [study_f] = client.scatter([study], broadcast=True)
        futures = client.map(evaluate_point, [study_f] * len(points), points, key=keys, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for fut, res in as_completed(futures, with_results=True, raise_errors=False):
                if fut.status != "finished":
                    raise RuntimeError(f"flight point {points[index[fut.key]].label}: {res!r}")
                results[index[fut.key]] = res
                for note in lost.notes():
                    warnings.warn(note, UserWarning, stacklevel=3)
                bar.update(1)
        finally:
            client.cancel([f for f in futures if not f.done()])
    return [results[i] for i in range(len(points))]
