"""A gust-loads scenario (``kind = "gust_loads"``): the
:class:`~aeroservo.studies.gust.study.GustLoadsStudy` it describes, its run and the figures a
run writes.

The scenario's ``[flight]`` table is the controller's design point (density, and the speed or
a multiple of the open-loop flutter speed); each flight point of ``[[gust_loads.points]]`` has
its own altitude (ISA density) and equivalent airspeed. Loads are increments of the wing clamped
at its root (no rigid-body modes, no 1 g load).
"""

from __future__ import annotations

from ...errors import InputError
from ...result_shape import finite
from ..kinds import Run, check_kind
from ..scenario import Scenario
from .plots import CORRELATED, FIGURES, gust_figures
from .results import _point_label as _label

__all__ = [
    "gust_study",
    "run_gust_scenario",
    "gust_summary",
    "gust_figures",
    "FIGURES",
    "CORRELATED",
]


def gust_study(scenario: Scenario):
    """The :class:`~aeroservo.studies.gust.study.GustLoadsStudy` of a ``gust_loads`` scenario
    (a controller file of type ``none`` is no controller: open loop only)."""
    from .study import GustLoadsStudy

    check_kind(scenario, "gust_loads")
    g = scenario.gust_loads
    ctrl = scenario.controller
    if ctrl is not None and getattr(ctrl, "type", "") == "none":
        ctrl = None
    loop = ctrl is not None
    return GustLoadsStudy(
        mass_cases=dict(g.mass_cases),
        points=tuple(g.points),
        loads=tuple(g.loads),
        load_stations=tuple(g.stations),
        v_c=g.v_c,
        v_d=g.v_d,
        aircraft_mass=dict(g.aircraft_mass),
        lift_share=g.lift_share,
        controls=tuple(scenario.controls) if loop else (),
        sensors=tuple(scenario.sensors) if loop else (),
        outputs=tuple(scenario.outputs) if loop else (),
        controller=ctrl,
        design_mass_case=g.design_mass_case,
        design_density=scenario.density,
        design_speed=scenario.speed,
        design_speed_factor=scenario.speed_factor,
        source=scenario.source,
        f_g=g.f_g,
        weights=dict(g.weights),
        elements=scenario.elements,
        wagner=scenario.wagner,
        damping=scenario.damping,
        gust_model=scenario.gust_model,
        design_modes=scenario.design_modes,
        sensor_filter=scenario.sensor_filter,
        filter_order=scenario.filter_order,
        sample_rate=scenario.sample_rate,
        delay=scenario.delay,
        actuator=scenario.actuator if loop else None,
        n_gradients=g.n_gradients,
        turbulence=g.turbulence,
        name=scenario.result,
        aero=scenario.aero,
    )


def run_gust_scenario(
    scenario: Scenario,
    *,
    progress: bool = False,
    scheduler: str | None = None,
    workers: int | None = None,
) -> Run:
    """Run a ``gust_loads`` scenario.

    Parameters
    ----------
    scenario : Scenario
    progress : bool
        A progress bar over the flight points on stderr.
    scheduler : str, optional
        Address of a running Dask scheduler (overrides ``workers``).
    workers : int, optional
        Local Dask workers (0: this process); None: ``gust_loads.workers`` of the scenario.

    Returns
    -------
    Run
        Its JSON-ready summary (:func:`gust_summary`) and ``loads``, the
        :class:`~aeroservo.studies.gust.results.GustLoadsResult`: records and histories of every
        flight point and loop.
    """
    from .run import run_gust_loads

    study = gust_study(scenario)
    n = scenario.gust_loads.workers if workers is None else workers
    result = run_gust_loads(study, workers=n, scheduler=scheduler, progress=progress)
    if not result.records:
        raise InputError(
            f"{scenario.source}: gust_loads.points: no flight point has loads: the open loop is "
            "unstable (above its flutter speed) at every point"
            + (" and the closed loop nowhere stable" if study.controller is not None else "")
        )
    return Run(scenario, gust_summary(result, scenario), loads=result, title=scenario.name)


def gust_summary(result, scenario: Scenario | None = None) -> dict:
    """The JSON-ready summary of a gust-loads result: the worst limit load of each load per
    loop (incremental, clamped wing), the loads the loop raises, the notes, the actuator
    saturation and the study's settings (SI units, radians)."""
    worst: dict = {}
    for loop in result.loops:
        rows = result.worst(loop)
        worst[loop] = {
            load: {
                "limit": finite(row["limit"]),
                "unit": row["unit"],
                "source": row["source"],
                "point": int(row["point"]),
                "flight_point": _label(result.record(int(row["point"]), loop)),
                "discrete_max": finite(row["discrete_max"]),
                "discrete_min": finite(row["discrete_min"]),
                "turbulence": finite(row["turbulence"]),
            }
            for load, row in rows.iterrows()
        }
    summary: dict = {
        "scenario": scenario.name if scenario is not None else result.name,
        "kind": "gust_loads",
        "result": result.name,
        "mass_cases": dict(result.settings.get("mass_cases", {})),
        "n_points": len(result.settings.get("points", []))
        or len({r["point"] for r in result.records}),
        "loops": result.loops,
        "worst": worst,
        "raised_loads": result.raised_loads(),
        "notes": list(
            {
                (r["point"], note): {"point": r["point"], "flight_point": _label(r), "note": note}
                for r in result.records
                for note in r["notes"]
            }.values()
        )
        + [
            {"point": k["point"], "flight_point": k["flight_point"], "note": f"no loads: {n}"}
            for k in result.settings.get("skipped_points", [])
            for n in k["notes"]
        ],
        "saturation": [
            {
                "point": r["point"],
                "flight_point": _label(r),
                "loop": r["loop"],
                "time_at_limit_s": r["time_at_limit"],
            }
            for r in result.records
            if any(s > 0 for s in r["time_at_limit"].values())
        ],
        "settings": dict(result.settings),
        "units": dict(result.units),
        "loads_are": "increments of the wing clamped at its root (no rigid-body modes); the 1 g "
        "loads and the totals in the table when the airplane's mass is given",
    }
    if result.loops == ["open", "closed"]:
        a = result.alleviation
        summary["alleviation_pct"] = [
            {k: finite(v) for k, v in row.items()} for row in a.to_dict(orient="records")
        ]
    return summary
