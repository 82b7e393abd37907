"""Running a gust-loads study: every flight point of every mass case is one task, run in this
process or on Dask (a local cluster of worker processes, or an existing scheduler) with a
progress bar, like a trade study (:mod:`aeroservo.studies.dask_runner`)."""

from __future__ import annotations

import time

from ...errors import InputError, check_int
from .point import PointLoads, design_point, evaluate_point
from .records import point_records
from .results import GustLoadsResult
from .study import GustLoadsStudy

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
        **({} if study.aero is None else {"aero": "dlm", "dlm": study.aero.to_dict()}),
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


def _spanwise_delay(study: GustLoadsStudy) -> list[str]:
    """A swept wing under the strip model: the gust reaches every strip at once (issue 38)."""
    swept = sorted(
        name
        for name, wing in study.mass_cases.items()
        if any(getattr(seg, "sweep", 0.0) for seg in getattr(wing, "segments", ()))
    )
    if study.aero is not None or not swept:
        return []
    return [
        f"mass case{'s' * (len(swept) > 1)} {', '.join(swept)}: a swept wing, but the strip "
        "model's gust reaches every strip at once (the spanwise delay, station x sin(sweep) / "
        'V, is left out); the doublet lattice (aero = "dlm") delays it box by box'
    ]


def _measures(study: GustLoadsStudy) -> str | None:
    """What the closed loop feeds back (issue 38: a state feedback is not realisable and
    sees the gust states, a perfect gust measurement)."""
    if study.controller is None:
        return None
    ctrl = design_point(study)[0]
    if getattr(ctrl, "needs_state", False):
        return (
            "the plant state (state feedback): not realisable as built; it feeds back the gust "
            "and aerodynamic lag states no sensor measures (a perfect gust measurement)"
        )
    return f"its sensors: {', '.join(study.sensors)}"


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
    settings["loop_measures"] = _measures(study)
    settings["warnings"] = _spanwise_delay(study)
    settings["elapsed"] = time.perf_counter() - t0
    settings["skipped_points"] = skipped
    return GustLoadsResult(study.name, records, arrays, units, settings)


def _on_dask(study, points, workers, scheduler, timeout, bar) -> list[PointLoads]:
    from ..dask_runner import map_tasks

    try:
        return map_tasks(
            evaluate_point, study, points, workers=workers, scheduler=scheduler,
            timeout=timeout, bar=bar, what=f"gust-loads-{study.name}",
        )  # fmt: skip
    except RuntimeError as exc:  # name the flight point
        head, _, rest = str(exc).partition(": ")
        i = int(head.rsplit(" ", 1)[-1])
        raise RuntimeError(f"flight point {points[i].label}: {rest}") from None
