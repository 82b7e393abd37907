"""Freeplay / limit-cycle benchmarks (targets from issue 28), with a same-run baseline.

Goland wing with aileron, 10 elements, sea level, freeplay of 1 deg total on both actuators,
the LQR loop of ``scenarios/goland_aileron_lqr.toml`` (1 kHz, actuator limits):

* a closed-loop freeplay march at 1 kHz in a limit cycle (120 m/s): at least 100 x faster than
  real time on one core;
* the same wing in open loop at 136.5 m/s (between the flap-free and gap-closed flutter speeds:
  a limit cycle), recorded at 1 kHz: at least 100 x faster than real time;
* a 40-speed x 3-amplitude bifurcation diagram of the open loop (130 to 140 m/s, 20 s marches,
  with the up and down sweeps) on 2 Dask workers: under 2 minutes;
* baseline: the linear march (``simulate``) of the same loop, reported as the ratio of the
  nonlinear march's wall time to it;
* the cost of a switch where the surface knocks (issue 40 item 3): the open wing of
  ``scenarios/goland_aileron_freeplay_lco.toml`` at 137 m/s (both actuators cross an edge some
  90 times a second) and the Conner section at 15 m/s (``scenarios/conner_freeplay_lco.toml``,
  48 a second), each in its limit cycle (the state after 10 s from 3 and 1 gaps), against the
  same plant with a zero gap (no switch: the same sample loop) marched from the same state in
  the same run: the cost per switch is the difference over the number of switches, also in
  samples of that baseline; the real-time factor of the knocking march: at least 100 x.

``--quick``: shorter marches and a 10-speed diagram (the targets are printed for the full size).
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import numpy as np
from _timing import median

from aeroservo.design.hinge_loop import loop_hinge_plant
from aeroservo.files.scenario_file import load_scenario
from aeroservo.linear.hinge_plant import nonlinear_plant, section_plant
from aeroservo.simulate.hinges.march import march_hinges
from aeroservo.simulate.march import simulate
from aeroservo.structure.hinge_laws import Freeplay
from aeroservo.studies.lco.run import run_lco
from aeroservo.studies.lco.study import LCOSetup, LCOSweep
from aeroservo.system.hinge_elements import NonlinearHinge
from aeroservo.system.section import CONNER, conner_section

GAP = float(np.radians(1.0))


def main() -> None:
    quick = "--quick" in sys.argv[1:]
    root = Path(__file__).resolve().parents[1]
    # the march with nonlinear hinges models no actuator dynamics: an ideal actuator here
    sc = dataclasses.replace(load_scenario(root / "scenarios" / "goland_aileron_lqr.toml"),
                             actuator=None)  # fmt: skip
    model = sc.model()
    loop = sc.loop(model)
    vf = 137.4
    ctrl = loop.design_controller(sc.controller, 1.1 * vf, sc.sample_rate, vf)
    lim = sc.controller.limits
    hinges = [NonlinearHinge("aileron", Freeplay(GAP))]
    duration = 2.0 if quick else 10.0

    closed = loop_hinge_plant(loop, hinges, 120.0)
    x0 = closed.initial_state(3 * GAP)
    base = median(lambda: simulate(loop.plant(120.0), ctrl, duration=duration, x0=x0), 3)
    res = {}

    def run_closed():
        res["closed"] = march_hinges(closed, ctrl, duration=duration, x0=x0, limits=lim)

    t_cl = median(run_closed, 3)
    opened = nonlinear_plant(model, hinges, 136.5, sc.density)

    def run_open():
        res["open"] = march_hinges(opened, duration=duration, rotation0=3 * GAP)

    t_ol = median(run_open, 3)

    knocks = []
    wing = load_scenario(root / "scenarios" / "goland_aileron_freeplay_lco.toml").model()
    for label, make, gap, start in (
        ("open wing knocking, 137 m/s", lambda gap: nonlinear_plant(
            wing, [NonlinearHinge("aileron", Freeplay(gap))], 137.0, sc.density), GAP, 3 * GAP),
        ("Conner section knocking, 15 m/s", lambda gap: section_plant(
            conner_section(), [NonlinearHinge("flap", Freeplay(gap))], 15.0, 1.225),
            CONNER["gap"], CONNER["gap"]),
    ):  # fmt: skip
        knocks.append((label, *_knocking(make(gap), make(0.0), start, duration)))

    n_speeds = 10 if quick else 40
    setup = LCOSetup(model, hinges, sc.density, name="goland-freeplay")
    bif_duration = 4.0 if quick else 20.0
    sweep = LCOSweep(
        np.linspace(130.0, 140.0, n_speeds), [0.5 * GAP, GAP, 3 * GAP], duration=bif_duration
    )
    t0 = time.perf_counter()
    diagram = run_lco(setup, sweep, workers=2, describing=False)
    t_bif = time.perf_counter() - t0

    print("aeroservo freeplay / LCO (10-element Goland with aileron, 1 deg freeplay, 1 kHz)")
    print(f"  baseline: linear march of the LQR loop, {duration:g} s:   {base * 1e3:8.1f} ms")
    for label, t, sim, n_sw in (
        (
            "closed loop (LQR) in a limit cycle, 120 m/s",
            t_cl,
            duration,
            res["closed"].switches.size,
        ),
        ("open loop in a limit cycle, 136.5 m/s", t_ol, duration, res["open"].switches.size),
    ):
        rt = sim / t
        print(
            f"  {label:44s} {t:7.3f} s = {t / base:5.1f} x linear, {rt:6.0f} x real time "
            f"({n_sw / sim:.0f} switches/s)  target >= 100 x real time: "
            f"{'PASS' if rt >= 100 else 'FAIL'}"
        )
    for label, t, t0, n_sw in knocks:
        rt = duration / t
        per = (t - t0) / n_sw
        print(
            f"  {label:44s} {t:7.3f} s, {rt:6.0f} x real time ({n_sw / duration:.0f} switches/s; "
            f"zero gap {t0:.3f} s): {per * 1e3:.3f} ms per switch = "
            f"{per / (t0 / (duration * 1e3)):.0f} samples of the zero gap  target >= 100 x real "
            f"time: {'PASS' if rt >= 100 else 'FAIL'}"
        )
    marches = diagram.settings["marches"]
    print(
        f"  bifurcation diagram {n_speeds} speeds x 3 amplitudes + 2 sweeps ({marches} marches "
        f"of {bif_duration:g} s), 2 workers: {t_bif:6.1f} s  target < 120 s: "
        f"{'PASS' if t_bif < 120 else 'FAIL'}"
    )
    lco = diagram.lco_rows()
    print(f"    limit cycles found at {len(lco)} of {len(diagram.rows)} marches")


def _knocking(plant, zero, start: float, duration: float) -> tuple[float, float, int]:
    """Median wall times [s] of a march of ``plant`` in its limit cycle (the state after 10 s
    from ``start`` [rad]) and of ``zero`` (the same plant, zero gap) from the same state, and
    the number of switches."""
    x0 = march_hinges(plant, duration=10.0, rotation0=start).states[-1]
    res = {}

    def run():
        res["sim"] = march_hinges(plant, duration=duration, x0=x0)

    t = median(run, 3)
    t0 = median(lambda: march_hinges(zero, duration=duration, x0=x0), 3)
    return t, t0, int(res["sim"].switches.size)


if __name__ == "__main__":
    main()
