"""Closed-loop trade-study throughput on Dask (issue 17); every figure is measured in the same
run.

The shipped trade study (``scenarios/trade_aileron.toml``: Goland with aileron; per case the
open-loop boundary, an LQR design at 1.1 V_f, the closed-loop boundary and a 1-cos gust) on a
finer grid of the same ranges, ``aileron_start`` x ``aileron_chord`` x
``bryson_hinge_moment`` = 10 x 10 x 10 = 1 000 cases, run through
:func:`aeroservo.studies.trade.run_trade` (case files, CSV and NetCDF included) on a warmed-up
``LocalCluster`` with 1 worker and then with 2 workers. Reported: cases per second, the
speed-up, the projected time of 10 000 cases on 2 workers (target: <= 15 min), the median
compute time of one case, and whether the two runs' CSV tables agree.

Run: ``make bench`` (or ``python bench/bench_trade.py``); ``--quick`` runs 4 x 4 x 3 = 48
cases on 2 workers only (a smoke test); ``--two-workers`` skips the 1-worker run; ``--csv FILE``
keeps the 2-worker table. Other load on the machine lowers the rates: the load averages and the
share of a core each worker got are printed.
"""

from __future__ import annotations

import dataclasses
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from aeroservo.files import load_scenario
from aeroservo.studies.runs import study_from_scenario
from aeroservo.studies.trade import TradeStudy, local_cluster, run_trade

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "trade_aileron.toml"


def grid_study(quick: bool) -> TradeStudy:
    study = study_from_scenario(load_scenario(SCENARIO))
    n = (4, 4, 3) if quick else (10, 10, 10)
    grid = {
        "aileron_start": np.linspace(0.5, 0.7, n[0]),
        "aileron_chord": np.linspace(0.15, 0.25, n[1]),
        "bryson_hinge_moment": np.geomspace(250.0, 1000.0, n[2]),
    }
    params = {k: tuple(np.round(v, 6).tolist()) for k, v in grid.items()}
    return dataclasses.replace(study, name="bench", parameters=params)


def warm_up() -> float:
    """Imports and first-call costs of a worker, paid before the timing starts."""
    from aeroservo.studies.trade.cases import evaluate_case

    study = grid_study(True)
    return evaluate_case(study, {k: v[0] for k, v in study.parameters.items()})["wall_time"]


def measure(study: TradeStudy, n_workers: int, out: str) -> dict:
    from distributed import Client

    with local_cluster(n_workers) as cluster:
        with Client(cluster.scheduler_address) as client:
            client.run(warm_up)
            cpu0 = client.run(time.process_time)
            r = run_trade(study, out, scheduler=cluster.scheduler_address, progress=False)
            cpu1 = client.run(time.process_time)
    assert r.n_failed == 0, r.table.loc[r.table["status"] != "ok", "error"].tolist()
    return {
        "workers": n_workers,
        "elapsed_s": r.elapsed,
        "rate": r.n_cases / r.elapsed,
        "case_s": statistics.median(r.table["wall_time"]),
        "cpu_share": sum(cpu1[w] - cpu0[w] for w in cpu0) / (r.elapsed * n_workers),
        "table": r.table.drop(columns=["wall_time"]).sort_values("case_id").reset_index(drop=True),
    }


def main() -> None:
    quick = "--quick" in sys.argv
    study = grid_study(quick)
    n = study.n_cases
    print(
        f"aeroservo closed-loop trade benchmark: {n} cases of scenarios/trade_aileron.toml's grid"
    )
    print(f"  load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    res = {}
    with tempfile.TemporaryDirectory() as tmp:
        for w in (2,) if quick or "--two-workers" in sys.argv else (1, 2):
            r = measure(study, w, os.path.join(tmp, f"w{w}"))
            res[w] = r
            print(
                f"  {w} worker{'s' if w > 1 else ' '}: {r['rate']:6.2f} cases/s "
                f"({n} cases in {r['elapsed_s']:6.1f} s; median case {r['case_s'] * 1e3:.0f} ms; "
                f"workers got {r['cpu_share']:.0%} of a core each)"
            )
    if 1 in res:
        print(f"  speed-up 2 workers / 1 worker: {res[2]['rate'] / res[1]['rate']:.2f} x")
        same = res[1]["table"].equals(res[2]["table"])
        print(f"  1-worker and 2-worker tables identical: {same}")
    if "--csv" in sys.argv:  # keep the 2-worker table (e.g. to compare two versions' results)
        res[2]["table"].to_csv(sys.argv[sys.argv.index("--csv") + 1], index=False)
    t10k = 10_000 / res[2]["rate"]
    print(
        f"  projected 10 000 cases on 2 workers: {t10k:.0f} s ({t10k / 60:.1f} min) "
        f"[target <= 15 min: {'PASS' if t10k <= 900 else 'FAIL'}]"
    )
    print(f"  load average after:  {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
