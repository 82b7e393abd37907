"""Tables of a scenario file with their own rules: the flight condition, the disturbance (gusts,
a gust series from a CSV file) and the trade study (see :mod:`aeroservo.files.scenario_file`)."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from ..aero.atmosphere import ALTITUDE_RANGE, FT, isa
from ..design.spec import ControllerSpec
from ..errors import NUMBER, InputError
from ..studies.scenario import GUST_KEYS, GUST_TYPES, Disturbance
from ..studies.study_options import TradeOptions
from .controller_file import load_controller
from .toml_tables import Table
from .user_files import read_text

__all__ = ["flight", "disturbance", "trade_table", "controller", "is_file", "actuator_table"]

ACTUATOR_KEYS = ("order", "bandwidth_hz", "damping", "pole_hz", "source")


def actuator_table(tbl: Table, controls) -> dict | None:
    """``[actuator]``: one actuator for every control (keys :data:`ACTUATOR_KEYS`), or one
    sub-table per control name; None when absent (ideal actuators)."""
    from ..design.actuator import ActuatorDynamics

    if not tbl.data:
        return None
    per_control = all(isinstance(v, dict) for v in tbl.data.values())
    tables = {c: tbl.table(c) for c in tbl.data} if per_control else dict.fromkeys(controls, tbl)
    out = {}
    for name, t in tables.items():
        if name not in controls:
            tbl.fail(name, t.data, f"not a control of this scenario; controls {list(controls)}")
        t.check_keys(("order", "bandwidth_hz"), ACTUATOR_KEYS[2:])
        order = t.integer("order", lo=1, hi=3)
        two_pi = 2.0 * np.pi
        pole = t.number("pole_hz", unit="Hz", lo=0.0, hi=1e4, lo_open=True)
        if pole is not None and order != 3:
            t.fail("pole_hz", pole, "only an order-3 actuator has a real pole")
        out[name] = ActuatorDynamics(
            order,
            two_pi * t.number("bandwidth_hz", unit="Hz", lo=0.0, hi=1e4, lo_open=True),
            t.number("damping", 0.7, lo=0.0, hi=10.0, lo_open=True),
            None if pole is None else two_pi * pole,
        )
        t.string("source", "")
    return out


def disturbance(tbl: Table, base: Path, span: float) -> Disturbance:
    from ..aero.gusts import GustSeries, OneMinusCosine, Turbulence

    kind = tbl.string("gust", "none", choices=GUST_TYPES)
    tbl.check_keys((), ("initial_tip", "gust") + GUST_KEYS[kind])
    tip = tbl.number("initial_tip", 0.0, unit="m", lo=-0.25 * span, hi=0.25 * span)
    gust = None
    if kind == "one_minus_cosine":
        gust = OneMinusCosine(
            length=tbl.number("length", quantity="gust_length", required=True),
            amplitude=tbl.number("amplitude", quantity="gust_velocity", required=True),
            start=tbl.number("start", 0.0, quantity="time"),
        )
    elif kind == "turbulence":
        gust = Turbulence(
            sigma=tbl.number("sigma", unit="m/s", lo=0.0, hi=30.0, required=True),
            scale=tbl.number("scale", 533.0, quantity="gust_length"),
            model=tbl.string("model", "von_karman", choices=("von_karman", "dryden")),
            seed=tbl.integer("seed", 0, lo=0, hi=2**32 - 1),
        )
    elif kind == "series":
        path = tbl.path("file", base, required=True)
        gust = gust_series(tbl, path, GustSeries)
    return Disturbance(initial_tip=tip, gust=gust)


PARAMETER_QUANTITIES = {
    "hinge_stiffness": "hinge_stiffness",
    "bryson_hinge_moment": "bryson",
    "speed_factor": "speed_factor",
}
"""Trade parameters that are physical quantities (the others are fractions)."""


def gust_series(tbl: Table, path: Path, cls):
    """CSV with columns time [s], velocity [m/s] (a header line is allowed)."""
    if not is_file(path):
        tbl.fail("file", tbl.data["file"], f"no such gust file ({path})")
    try:
        text = read_text(path, what="gust series (CSV: time, velocity)")
    except InputError as exc:
        tbl.fail("file", tbl.data["file"], str(exc))
    rows = []
    try:
        for i, row in enumerate(csv.reader(io.StringIO(text, newline=""))):
            if not row or row[0].strip().startswith("#"):
                continue
            try:
                if len(row) != 2 or not all(NUMBER.fullmatch(c.strip()) for c in row):
                    raise ValueError
                rows.append((float(row[0]), float(row[1])))
            except ValueError:
                if i == 0:
                    continue  # header
                tbl.fail("file", tbl.data["file"], f"line {i + 1}: expected time, velocity")
    except csv.Error as exc:
        tbl.fail("file", tbl.data["file"], f"not a CSV file: {exc}")
    t = np.array([r[0] for r in rows])
    w = np.array([r[1] for r in rows])
    try:
        return cls(tuple(t), tuple(w))
    except InputError as exc:
        tbl.fail("file", tbl.data["file"], str(exc))


def flight(fl: Table, kw: dict) -> None:
    """Density, or an altitude of the standard atmosphere, and the speed."""
    given = [k for k in ("density", "altitude", "altitude_ft") if fl.has(k)]
    if not given:
        raise InputError(
            f"{fl.file}: flight.density: missing; give density, altitude or altitude_ft"
        )
    if len(given) > 1:
        fl.fail(given[1], fl.data[given[1]], "give one of density, altitude, altitude_ft")
    kw["altitude"] = None
    if given[0] == "density":
        kw["density"] = fl.number("density", quantity="density")
    else:
        ft = given[0] == "altitude_ft"
        lo, hi = ALTITUDE_RANGE
        h = fl.number(
            given[0], unit="ft" if ft else "m", lo=lo / FT if ft else lo, hi=hi / FT if ft else hi
        )
        atm = isa(h * FT if ft else h)
        kw["altitude"], kw["density"] = atm.altitude, atm.density


def trade_table(tbl: Table, base: Path) -> TradeOptions:
    """Raw trade settings; validated against the wing by :mod:`aeroservo.studies.trade`.
    ``closed_loop = false``: the open-loop flutter boundary of each case only (no controller);
    ``masses[i].<key>`` parameters sweep the wing's concentrated masses."""
    from ..studies.trade.mass_parameters import mass_parameter
    from ..studies.trade.study import LINEAR_TYPES, PARAMETERS

    closed_loop = tbl.boolean("closed_loop", True)
    tbl.check_keys(
        ("parameters", *(("controller",) if closed_loop else ())),
        (
            "closed_loop",
            "controller",
            "speed_factor",
            "gust_length",
            "gust_amplitude",
            "gust_duration",
            "v_max_factor",
            "n_grid",
            "workers",
        ),
    )
    spec = None
    if closed_loop or tbl.has("controller"):
        spec = controller(tbl, tbl.path("controller", base, required=True), "controller")
    if spec is not None and spec.type not in LINEAR_TYPES:
        tbl.fail(
            "controller",
            tbl.data["controller"],
            f"a trade study needs a controller with a linear law, one of {list(LINEAR_TYPES)} "
            f"(the closed-loop flutter boundary is an eigenvalue analysis of the linear loop); "
            f"this one is {spec.type!r}",
        )
    masses = tuple(k for k in tbl.table("parameters").data if mass_parameter(k) is not None)
    pt = tbl.table("parameters").check_keys((), (*PARAMETERS, *masses))
    params = {}
    for name in pt.data:
        if name in masses:  # wing-file units; the study checks them against the wing
            values = pt.numbers(name)
        elif name in PARAMETER_QUANTITIES:
            values = pt.numbers(name, quantity=PARAMETER_QUANTITIES[name])
        else:  # fractions of the span or of the chord: the study checks their ranges
            values = pt.numbers(name, lo=0.0, lo_open=True)
        params[name] = tuple(values)
        if len(set(params[name])) != len(params[name]):
            pt.fail(name, pt.data[name], "values must not repeat")
    if not params:
        tbl.fail("parameters", tbl.data["parameters"], f"give at least one of {list(PARAMETERS)}")
    n_cases = int(np.prod([len(v) for v in params.values()]))
    if n_cases > 1_000_000:
        tbl.fail("parameters", tbl.data["parameters"], f"{n_cases} cases: the limit is 1 000 000")
    return TradeOptions(
        closed_loop=closed_loop,
        controller=spec,
        parameters=params,
        speed_factor=tbl.number("speed_factor", 1.1, quantity="speed_factor"),
        gust_length=tbl.number("gust_length", 25.0, quantity="gust_length"),
        gust_amplitude=tbl.number("gust_amplitude", 5.0, quantity="gust_velocity"),
        gust_duration=tbl.number("gust_duration", 1.0, unit="s", lo=0.0, hi=60.0, lo_open=True),
        v_max_factor=tbl.number("v_max_factor", 2.0, lo=1.0, hi=10.0, lo_open=True),
        n_grid=tbl.integer("n_grid", 21, lo=3, hi=2000),
        workers=tbl.integer("workers", 2, lo=1, hi=256),
    )


def is_file(path: Path) -> bool:
    """``path.is_file()``, False for names the OS rejects (e.g. too long)."""
    try:
        return path.is_file()
    except (OSError, ValueError):
        return False


def engaged_speeds(ct: Table, kw: dict) -> None:
    """``engaged_speeds`` [m/s] or ``engaged_speed_factors`` (x V_f) of ``[controller]``: the
    speeds where the loop is engaged, two increasing values (default: 0.5 V_f to 1.15 x the
    scenario speed)."""
    if ct.has("engaged_speeds") and ct.has("engaged_speed_factors"):
        ct.fail(
            "engaged_speed_factors",
            ct.data["engaged_speed_factors"],
            "give engaged_speeds or engaged_speed_factors, not both",
        )
    for key, quantity in (
        ("engaged_speeds", "flight_speed"),
        ("engaged_speed_factors", "speed_factor"),
    ):
        v = ct.numbers(key, quantity=quantity, increasing=True)
        if v is not None:
            if len(v) != 2:
                ct.fail(key, ct.data[key], "expected [low, high]")
            kw[key] = tuple(v)


def controller(ct: Table, path: Path, key: str = "spec") -> ControllerSpec:
    """The controller file ``path`` named by ``key``; its errors also name this file."""
    if not is_file(path):
        ct.fail(key, ct.data[key], f"no such controller file ({path})")
    try:
        return load_controller(path)
    except InputError as exc:
        raise InputError(f"{ct.file}: {ct.key_name(key)} -> {exc}") from None


def sol145_table(tbl: Table, v_max: float | None) -> dict | None:
    """A flutter scenario's ``[sol145]`` table (the flutter case of an imported Nastran deck,
    ``docs/nastran.md``): the p-k at its velocities, printed as Nastran's flutter summary."""
    if not tbl.data:
        return None
    tbl.check_keys(
        (),
        ("method", "velocities", "reference_chord", "density_ratio", "velocity_unit")
        + ("velocity_factor",),
    )
    velocities = tbl.numbers("velocities", None, quantity="flight_speed", increasing=True)
    if velocities is not None and v_max is not None and max(velocities) > v_max:
        tbl.fail("velocities", velocities, f"the highest exceeds model.v_max = {v_max:g} m/s")
    chord = tbl.number("reference_chord", None, unit="m", lo=0.0, hi=2e3, lo_open=True)
    if velocities is not None and chord is None:
        raise InputError(f"{tbl.file}: sol145.reference_chord: missing (KFREQ needs it) [m]")
    return {
        "method": tbl.string("method", "PK"),
        "velocities": velocities,
        "reference_chord": chord,
        "density_ratio": tbl.number("density_ratio", 1.0, lo=0.0, hi=1e3, lo_open=True),
        "velocity_unit": tbl.string("velocity_unit", ""),
        "velocity_factor": tbl.number("velocity_factor", 1.0, lo=0.0, hi=1e3, lo_open=True),
    }
