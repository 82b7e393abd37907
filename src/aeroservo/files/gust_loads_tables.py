"""The tables of a gust-loads scenario (``kind = "gust_loads"``): ``[gust_loads]`` with its flight
points and mass cases, the optional ``[controller]``, and the checks that need the wings (loads
and signals against every mass case's model). Called by
:func:`aeroservo.files.scenario_file.scenario_from_dict`; every error names the file, the key and
the value.
"""

from __future__ import annotations

from pathlib import Path

from ..aero.gust_rules import U_REF_TABLE, Z_REF
from ..errors import InputError
from ..studies.gust.study import SPEED_NAMES, FlightPoint, speed_order
from ..studies.scenario import Scenario
from ..studies.study_options import GustLoadsOptions
from .scenario_tables import controller, is_file
from .toml_tables import Table

__all__ = ["gust_loads_tables", "gust_cross_check", "NOMINAL", "DEFAULT_LOADS"]

NOMINAL = "nominal"
"""Name of the mass case of the scenario's ``[wing]`` (always the first)."""

DEFAULT_LOADS = ("root_shear", "root_bending_moment", "root_torque")
"""Loads of a ``[gust_loads]`` table without ``loads``."""

MAX_POINTS = 1000
"""Most flight points of one scenario."""

UNUSED = {
    "model": ("v_max", "pk"),
    "simulation": ("duration", "seed", "sensor_noise", "expect_failure", "expect_unstable"),
}
"""Keys of the shared tables a gust-loads scenario has no use for (an error, not ignored)."""


def gust_loads_tables(top: Table, base: Path, kw: dict) -> None:
    """Read ``[controller]`` and ``[gust_loads]`` of a gust-loads scenario into ``kw`` (the
    :class:`~aeroservo.studies.scenario.Scenario` keywords read so far). Without
    ``controller.spec`` the study is open loop only, and ``[flight]`` (the controller's design
    point) may be left out."""
    for name, keys in UNUSED.items():
        tbl = top.table(name)
        for key in keys:
            if tbl.has(key):
                tbl.fail(key, tbl.data[key], "not used by a scenario of kind 'gust_loads'")
    ct = top.table("controller").check_keys((), ("spec", "design_mass_case"))
    design_case = ct.string("design_mass_case", NOMINAL)
    if ct.has("design_mass_case") and not ct.has("spec"):
        ct.fail("design_mass_case", design_case, "needs controller.spec (open loop only without)")
    if ct.has("spec"):
        kw["controller"] = controller(ct, ct.path("spec", base, required=True))
        if not top.table("flight").data:
            raise InputError(
                f"{top.file}: flight: missing required table (the controller's design point: "
                "density or altitude, and speed or speed_factor)"
            )
        if kw.get("speed") is None and kw.get("speed_factor") is None:
            raise InputError(
                f"{top.file}: flight.speed: missing; give speed [m/s] or speed_factor (x the "
                "open-loop flutter speed): the controller's design point"
            )
    gl = top.table("gust_loads", required=True)
    g = gust_loads_table(gl, base, kw["wing"])
    if design_case not in g["mass_cases"]:
        top.table("controller").fail(
            "design_mass_case", design_case, f"not a mass case; they are {list(g['mass_cases'])}"
        )
    kw["options"] = GustLoadsOptions(**g, design_mass_case=design_case)


def gust_loads_table(gl: Table, base: Path, wing) -> dict:
    """The ``[gust_loads]`` table: loads, gust search, turbulence, F_g, mass cases and points."""
    gl.check_keys(
        ("points",),
        (
            "loads",
            "stations",
            "n_gradients",
            "turbulence",
            "workers",
            "f_g",
            "weights",
            "mass_cases",
            "v_c",
            "v_d",
            "aircraft_mass",
            "lift_share",
        ),
    )
    stations = gl.numbers("stations", [], unit="m", lo=0.0, hi=wing.span, increasing=True)
    if any(b - a < 2e-3 for a, b in zip(stations[:-1], stations[1:], strict=True)):
        gl.fail("stations", stations, "closer than 2 mm (loads are named to the millimetre)")
    out: dict = {
        "loads": tuple(gl.strings("loads", DEFAULT_LOADS)),
        "stations": tuple(stations),
        "n_gradients": gl.integer("n_gradients", 20, lo=3, hi=500),
        "turbulence": gl.boolean("turbulence", True),
        "workers": gl.integer("workers", 0, lo=0, hi=256),
    }
    if gl.has("f_g") and gl.has("weights"):
        gl.fail("weights", gl.data["weights"], "give f_g or weights, not both")
    out["weights"] = _weights(gl.table("weights")) if gl.has("weights") else {}
    out["f_g"] = None if out["weights"] else gl.number("f_g", 1.0, lo=0.0, lo_open=True, hi=1.0)
    for key in ("v_c", "v_d"):  # design cruising and dive speeds [m/s EAS]
        out[key] = gl.number(key, None, unit="m/s EAS", lo=0.0, lo_open=True, hi=1000.0)
    if out["v_c"] is not None and out["v_d"] is not None and out["v_d"] <= out["v_c"]:
        gl.fail("v_d", out["v_d"], f"must exceed v_c = {out['v_c']:g} m/s EAS")
    masses: dict = {}
    out["mass_cases"] = _mass_cases(gl, base, wing, masses)
    if gl.has("aircraft_mass"):  # the airplane in the nominal case: 1 g loads (trim)
        masses[NOMINAL] = gl.number("aircraft_mass", unit="kg", lo=0.0, lo_open=True, hi=1e7)
    out["aircraft_mass"] = masses
    out["lift_share"] = gl.number("lift_share", 0.5, lo=0.0, lo_open=True, hi=1.0)
    out["points"] = _points(gl, out["mass_cases"], out["v_c"], out["v_d"])
    return out


def _weights(wt: Table) -> dict:
    """``[gust_loads.weights]``: MLW, MZFW, MTOW [kg] and Z_mo [m] of CS-25.341(a)(6)."""
    wt.check_keys(("mlw", "mzfw", "mtow", "z_mo"))
    mtow = wt.number("mtow", unit="kg", lo=0.0, lo_open=True, hi=1e9)
    w = {"mtow": mtow}
    for key in ("mlw", "mzfw"):
        w[key] = wt.number(key, unit="kg", lo=0.0, lo_open=True, hi=1e9)
        if w[key] > mtow:
            wt.fail(key, w[key], f"must not exceed mtow = {mtow:g} kg")
    w["z_mo"] = wt.number("z_mo", unit="m", lo=0.0, lo_open=True, hi=Z_REF, hi_open=True)
    return w


def _mass_cases(gl: Table, base: Path, wing, masses: dict) -> dict:
    """``nominal`` (the ``[wing]``) and each ``[[gust_loads.mass_cases]]`` (``name``, ``wing``
    a wing file relative to the scenario, ``aircraft_mass`` [kg] into ``masses``)."""
    from .wing_file import load_wing

    cases = {NOMINAL: wing}
    if not gl.has("mass_cases"):
        return cases
    items = gl.data["mass_cases"]
    if not isinstance(items, list) or not items:
        gl.fail("mass_cases", items, "expected [[gust_loads.mass_cases]] tables (name, wing)")
    for i, item in enumerate(items):
        mc = Table(item, f"{gl.key_name('mass_cases')}[{i}]", gl.file)
        mc.check_keys(("name", "wing"), ("aircraft_mass",))
        name = mc.string("name", required=True)
        if not name.strip() or not name.isprintable():
            mc.fail("name", name, "expected a printable, non-blank name")
        if name in cases:
            what = "the [wing] of the scenario" if name == NOMINAL else "another mass case"
            mc.fail("name", name, f"already the name of {what}")
        path = mc.path("wing", base, required=True)
        if not is_file(path):
            mc.fail("wing", mc.data["wing"], f"no such wing file ({path})")
        if mc.has("aircraft_mass"):
            masses[name] = mc.number("aircraft_mass", unit="kg", lo=0.0, lo_open=True, hi=1e7)
        try:
            cases[name] = load_wing(path)[0]
        except InputError as exc:
            raise InputError(f"{mc.file}: {mc.key_name('wing')} -> {exc}") from None
    return cases


def _points(gl: Table, cases: dict, v_c=None, v_d=None) -> tuple:
    """``[[gust_loads.points]]``: altitude [m], speed [m/s EAS], speed_name, mass_case (a
    point named V_C or V_D flies at ``v_c`` or ``v_d`` when given; none beyond ``v_d``)."""
    items = gl.data["points"]
    if not isinstance(items, list) or not items:
        gl.fail("points", items, "expected [[gust_loads.points]] tables (altitude, speed)")
    if len(items) > MAX_POINTS:
        gl.fail("points", f"{len(items)} tables", f"at most {MAX_POINTS} flight points")
    top = U_REF_TABLE[-1][0]
    points = []
    for i, item in enumerate(items):
        pt = Table(item, f"{gl.key_name('points')}[{i}]", gl.file)
        pt.check_keys(("altitude", "speed"), ("speed_name", "mass_case"))
        altitude = pt.number("altitude", unit="m (the rule's table)", lo=0.0, hi=top, required=True)
        speed = pt.number("speed", quantity="flight_speed", required=True)
        speed_name = pt.string("speed_name", "V_C", choices=SPEED_NAMES)
        at = {"V_C": v_c, "V_D": v_d}.get(speed_name)
        if at is not None and abs(speed - at) > 1e-9 * at:
            pt.fail(
                "speed",
                speed,
                f"the point is named {speed_name} = {at:g} m/s EAS "
                '(speed_name = "" for a speed in between)',
            )
        if speed_name == "" and v_d is not None and speed > v_d * (1 + 1e-9):
            pt.fail("speed", speed, f"beyond v_d = {v_d:g} m/s EAS (the envelope ends at V_D)")
        case = pt.string("mass_case", NOMINAL)
        if case not in cases:
            pt.fail("mass_case", case, f"not a mass case; they are {list(cases)}")
        points.append(FlightPoint(altitude, speed, speed_name, case))
    bad = speed_order(points, v_c, v_d)
    if bad is not None:
        i, why = bad
        pt = Table(items[i], f"{gl.key_name('points')}[{i}]", gl.file)
        pt.fail("speed", points[i].speed, why)
    return tuple(points)


def gust_cross_check(s: Scenario, top: Table) -> None:
    """Checks that need the wings: each load an output of every mass case's model; with a
    controller, its controls, sensors and outputs on every mass case and its file's signals."""
    from ..design.loop import check_spec_signals
    from ..linear.signals import resolve_outputs
    from ..system.aeroelastic import AeroelasticModel
    from .scenario_checks import check_loop_signals

    g = s.gust_loads
    gl, sg = top.table("gust_loads"), top.table("signals")
    spec = s.controller if s.controller is not None and s.controller.type != "none" else None
    if s.aero is not None and s.aero != "strip":
        for key in ("stations", "aircraft_mass"):
            if getattr(g, key):
                gl.fail(
                    key,
                    gl.data.get(key, "(a mass case's)"),
                    "needs the strip model "
                    "(loads along the span and the wing's weight); the doublet lattice "
                    "gives root loads only",
                )
    for case, wing in g.mass_cases.items():
        where = "" if case == NOMINAL else f" (mass case {case!r})"
        aero = "strip" if s.aero is None else s.aero
        for x in g.stations:
            if x > wing.span:
                gl.fail(
                    "stations",
                    list(g.stations),
                    f"{x:g} m is beyond the span {wing.span:g} m of mass case {case!r}",
                )
        model = AeroelasticModel(
            wing, s.elements, s.wagner, damping=s.damping, aero=aero, load_stations=g.stations
        )
        for i, name in enumerate(g.loads):
            try:
                resolve_outputs(model, [name], model.n_dofs)
            except InputError as exc:
                known = str(exc).split("unknown sensor; ", 1)[-1]
                gl.fail(f"loads[{i}]", name, f"not an output of the model{where}; {known}")
        if spec is None:
            continue
        check_loop_signals(s, wing, model, top, where)
    if spec is None:
        return
    if s.sensor_filter is not None and s.sensor_filter >= 0.5 * s.sample_rate:
        sg.fail(
            "sensor_filter",
            s.sensor_filter,
            f"must be below the Nyquist frequency {0.5 * s.sample_rate:g} Hz of "
            "simulation.sample_rate",
        )
    try:
        check_spec_signals(spec, s.controls, s.sensors, tuple(g.loads) + tuple(s.outputs))
    except InputError as exc:
        raise InputError(f"{s.source}: controller.spec -> {exc}") from None
