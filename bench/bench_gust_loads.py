"""Gust-loads benchmarks (targets from issue 29), with a same-run baseline.

Goland wing with aileron, 10 elements, sea level, 0.9 V_f, the LQR loop of
``scenarios/goland_aileron_lqr.toml`` (1 kHz, actuator limits), six loads:

* a 10-gradient x 2-sign tuned-gust search (no refinement), open and closed loop: < 2 s;
* the turbulence A-bar and N0 of every load at one flight point, open and closed loop: < 0.5 s;
* the same search refined (the default), for information;
* a gust-loads study at one flight point (open and closed loop, tuned gusts and turbulence;
  ``--quick``: open loop) with 5 load stations against the same study with the root loads
  only: < 1.5 x (issue 38);
* baseline: one open-loop flutter boundary of the same model (``flutter_boundary``), reported
  as the ratio of each figure to it.
"""

from __future__ import annotations

import inspect
import sys
from pathlib import Path

from _timing import median

from aeroservo.files.scenario_file import load_scenario
from aeroservo.stability.boundary import flutter_boundary
from aeroservo.studies.gust.tuned import tuned_gust_loads
from aeroservo.studies.gust.turbulence import turbulence_response

LOADS = [
    "root_shear",
    "root_bending_moment",
    "root_torque",
    "tip_le_accel",
    "tip_te_accel",
    "aileron_aero_hinge_moment",
]


def main() -> None:
    quick = "--quick" in sys.argv[1:]
    root = Path(__file__).resolve().parents[1]
    sc = load_scenario(root / "scenarios" / "goland_aileron_lqr.toml")
    model = sc.model()
    vf = flutter_boundary(model, sc.density).flutter_speed
    from dataclasses import replace

    sc = replace(sc, outputs=tuple(dict.fromkeys(sc.outputs + tuple(LOADS))))
    loop = sc.loop(model)
    ctrl = loop.design_controller(sc.controller, 1.1 * vf, sc.sample_rate, vf)
    plant = loop.plant(0.9 * vf)
    plant.density = sc.density
    lim = sc.controller.limits
    base = median(lambda: flutter_boundary(model, sc.density), 5)

    def search(**kw):
        return tuned_gust_loads(plant, 0.0, n_gradients=10, **kw)

    t_ol = median(lambda: search(refine=False), 3)
    t_cl = median(lambda: search(refine=False, controller=ctrl, limits=lim), 3)
    t_ol_r = None if quick else median(lambda: search(), 1)
    t_cl_r = None if quick else median(lambda: search(controller=ctrl, limits=lim), 1)
    turb_ol = median(lambda: turbulence_response(plant, LOADS), 5)
    closed_ok = "controller" in inspect.signature(turbulence_response).parameters
    turb_cl = (
        median(lambda: turbulence_response(plant, LOADS, controller=ctrl), 5) if closed_ok else None
    )

    t_root, t_span = _stations(sc, quick)

    print("aeroservo gust loads (10-element Goland with aileron, 0.9 V_f, LQR at 1 kHz, medians)")
    print(f"  baseline: one flutter boundary:              {base * 1e3:8.1f} ms")
    for label, t, target in (
        ("tuned gusts, 10 H, open loop (down = -up)", t_ol, 2.0),
        ("tuned gusts, 10 H, closed loop (down = -up)", t_cl, 2.0),
        ("tuned gusts refined, open loop", t_ol_r, None),
        ("tuned gusts refined, closed loop", t_cl_r, None),
        ("turbulence A-bar, 6 loads, open loop", turb_ol, 0.5),
        ("turbulence A-bar, 6 loads, closed loop", turb_cl, 0.5),
    ):
        if t is None:
            print(f"  {label:44s} not run")
            continue
        goal = f"  target < {target:g} s: {'PASS' if t < target else 'FAIL'}" if target else ""
        print(f"  {label:44s} {t:7.3f} s = {t / base:6.1f} x boundary{goal}")
    ratio = t_span / t_root
    print(
        f"  {'study, 5 load stations vs the root only':44s} {ratio:7.2f} x"
        f"  ({t_root:.2f} s, {t_span:.2f} s)  target < 1.5 x: {'PASS' if ratio < 1.5 else 'FAIL'}"
    )


def _stations(sc, quick: bool) -> tuple[float, float]:
    """Wall time of one flight point of a study with the root loads, then with 5 stations."""
    from aeroservo.studies.gust.point import evaluate_point
    from aeroservo.studies.gust.study import FlightPoint, GustLoadsStudy

    def study(stations):
        return GustLoadsStudy(
            mass_cases={"nominal": sc.wing},
            points=(FlightPoint(0.0, 100.0, "V_C", "nominal"),),
            loads=("root_shear", "root_bending_moment", "root_torque"),
            load_stations=stations,
            controls=() if quick else sc.controls,
            sensors=() if quick else sc.sensors,
            outputs=() if quick else sc.outputs,
            controller=None if quick else sc.controller,  # quick: the open loop alone
            design_speed_factor=1.1,
            n_gradients=5 if quick else 10,
        )

    plain, span = study(()), study((1.2192, 2.4384, 3.048, 3.6576, 4.8768))
    if not quick:  # the controller designed once per study: not timed (quick: open loop)
        evaluate_point(plain, plain.points[0])
        evaluate_point(span, span.points[0])
    n = 1 if quick else 3
    return (
        median(lambda: evaluate_point(plain, plain.points[0]), n),
        median(lambda: evaluate_point(span, span.points[0]), n),
    )


if __name__ == "__main__":
    main()
