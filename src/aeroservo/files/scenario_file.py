"""Scenario files (``scenarios/*.toml``, schema in ``docs/scenarios.md``).

A scenario says what to run on which wing: an open-loop flutter analysis (``kind =
"flutter"``), a closed-loop time simulation (``"simulate"``) or a trade study (``"trade"``),
with the flight condition, model options, signals, disturbance, a reference to a controller
file, simulation settings and what to write. :func:`load_scenario` validates everything,
including the cross-checks that need the wing (signals, sensor stations, controller signals,
limits against the initial state); every error names the file, the key and the value.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from ..design.spec import ControllerSpec
from ..errors import InputError
from ..studies.scenario import GUST_KEYS, GUST_TYPES, SCENARIO_KINDS, Disturbance, Scenario
from .controller_file import load_controller
from .scenario_checks import cross_check
from .toml_tables import Table, check_integers, one_line_errors, read_toml

__all__ = ["load_scenario", "scenario_from_dict", "is_scenario_file", "shipped_scenarios"]

TOP = (
    "scenario",
    "wing",
    "flight",
    "model",
    "signals",
    "disturbance",
    "controller",
    "simulation",
    "analysis",
    "output",
    "trade",
)
USED = {
    "flutter": ("scenario", "wing", "flight", "model", "analysis", "output"),
    "simulate": TOP[:-1],
    "trade": ("scenario", "wing", "flight", "model", "signals", "simulation", "output", "trade"),
}


def _is_file(path: Path) -> bool:
    """``path.is_file()``, False for names the OS rejects (e.g. too long)."""
    try:
        return path.is_file()
    except (OSError, ValueError):
        return False


def _surface_keys(message: str, data: object, where: str) -> str:
    """Name control surfaces by their key path: ``control_surface 'aileron'`` (as the wing
    model says) becomes ``wing.control_surfaces[0]``."""
    surfaces = data.get("control_surfaces") if isinstance(data, dict) else None
    if not isinstance(surfaces, list):
        return message
    for i, cs in enumerate(surfaces):
        if isinstance(cs, dict) and isinstance(cs.get("name"), str):
            message = message.replace(
                f"control_surface '{cs['name']}'", f"{where}.control_surfaces[{i}]"
            )
    return message


def _wing(tbl: Table, base: Path):
    from ..structure.examples import BUILTIN_WINGS
    from .wing_file import load_wing, wing_from_dict

    if tbl.has("builtin") or tbl.has("file"):
        tbl.check_keys((), ("builtin", "file"))
        if tbl.has("builtin") and tbl.has("file"):
            tbl.fail("file", tbl.data["file"], "give either builtin or file, not both")
        if tbl.has("builtin"):
            name = tbl.string("builtin", choices=sorted(BUILTIN_WINGS))
            return BUILTIN_WINGS[name](), f"builtin {name}"
        path = tbl.path("file", base)
        if not _is_file(path):
            tbl.fail("file", tbl.data["file"], f"no such wing file ({path})")
        data = None
        try:
            data = read_toml(path).get("wing")
            return load_wing(path)[0], str(path)
        except InputError as exc:
            msg = _surface_keys(str(exc), data, "wing")
            raise InputError(f"{tbl.file}: {tbl.key_name('file')} -> {msg}") from None
    try:
        return wing_from_dict(tbl.data, tbl.where), "inline"
    except InputError as exc:
        msg = _surface_keys(str(exc), tbl.data, tbl.where)
        raise InputError(f"{tbl.file}: {msg}") from None


def _disturbance(tbl: Table, base: Path, span: float) -> Disturbance:
    from ..aero.gusts import GustSeries, OneMinusCosine, Turbulence

    kind = tbl.string("gust", "none", choices=GUST_TYPES)
    tbl.check_keys((), ("initial_tip", "gust") + GUST_KEYS[kind])
    tip = tbl.number("initial_tip", 0.0, unit="m", lo=-0.25 * span, hi=0.25 * span)
    gust = None
    if kind == "one_minus_cosine":
        gust = OneMinusCosine(
            length=tbl.number("length", unit="m", lo=0.0, lo_open=True, required=True),
            amplitude=tbl.number("amplitude", unit="m/s", lo=-50.0, hi=50.0, required=True),
            start=tbl.number("start", 0.0, unit="s", lo=0.0),
        )
    elif kind == "turbulence":
        gust = Turbulence(
            sigma=tbl.number("sigma", unit="m/s", lo=0.0, hi=30.0, required=True),
            scale=tbl.number("scale", 533.0, unit="m", lo=0.0, lo_open=True),
            model=tbl.string("model", "von_karman", choices=("von_karman", "dryden")),
            seed=tbl.integer("seed", 0, lo=0, hi=2**32 - 1),
        )
    elif kind == "series":
        path = tbl.path("file", base, required=True)
        gust = _gust_series(tbl, path, GustSeries)
    return Disturbance(initial_tip=tip, gust=gust)


def _gust_series(tbl: Table, path: Path, cls):
    """CSV with columns time [s], velocity [m/s] (a header line is allowed)."""
    if not _is_file(path):
        tbl.fail("file", tbl.data["file"], f"no such gust file ({path})")
    rows = []
    try:
        with path.open(newline="", encoding="utf-8") as fh:
            for i, row in enumerate(csv.reader(fh)):
                if not row or row[0].strip().startswith("#"):
                    continue
                try:
                    rows.append((float(row[0]), float(row[1])))
                except (ValueError, IndexError):
                    if i == 0:
                        continue  # header
                    tbl.fail("file", tbl.data["file"], f"line {i + 1}: expected time, velocity")
    except UnicodeDecodeError:
        tbl.fail("file", tbl.data["file"], "not a UTF-8 text file")
    except csv.Error as exc:
        tbl.fail("file", tbl.data["file"], f"not a CSV file: {exc}")
    except OSError as exc:
        tbl.fail("file", tbl.data["file"], f"cannot read the gust file: {exc.strerror}")
    t = np.array([r[0] for r in rows])
    w = np.array([r[1] for r in rows])
    try:
        return cls(tuple(t), tuple(w))
    except InputError as exc:
        tbl.fail("file", tbl.data["file"], str(exc))


def scenario_from_dict(data: object, file: str = "<dict>", base: Path | None = None) -> Scenario:
    """Validate a parsed scenario file. ``base`` is the folder relative paths start from."""
    with one_line_errors():
        return _scenario_from_dict(data, file, base)


def _scenario_from_dict(data: object, file: str, base: Path | None) -> Scenario:
    from ..aero.indicial import wagner_set
    from ..structure.mesh import build_mesh

    base = Path(file).parent if base is None else base
    check_integers(data, file)
    top = Table(data, "", file).check_keys(("scenario", "wing"), TOP[2:])
    sc = top.table("scenario").check_keys(("name", "kind"), ("description",))
    kind = sc.string("kind", choices=SCENARIO_KINDS, required=True)
    for key in TOP:
        if top.has(key) and key not in USED[kind]:
            top.fail(key, top.data[key], f"not used by a scenario of kind {kind!r}")
    kw: dict = {
        "name": sc.string("name", required=True),
        "kind": kind,
        "source": file,
        "description": sc.string("description", ""),
    }
    kw["wing"], kw["wing_source"] = _wing(top.table("wing"), base)
    wing = kw["wing"]

    fl = top.table("flight").check_keys(("density",), ("speed", "speed_factor"))
    kw["density"] = fl.number("density", unit="kg/m^3", lo=0.0, hi=2.0, lo_open=True, required=True)
    if fl.has("speed") and fl.has("speed_factor"):
        fl.fail("speed_factor", fl.data["speed_factor"], "give speed or speed_factor, not both")
    kw["speed"] = fl.number("speed", unit="m/s", lo=0.0, hi=1000.0, lo_open=True)
    kw["speed_factor"] = fl.number("speed_factor", lo=0.0, hi=10.0, lo_open=True)
    if kind == "simulate" and kw["speed"] is None and kw["speed_factor"] is None:
        raise InputError(f"{file}: flight.speed: missing; give speed [m/s] or speed_factor")

    md = top.table("model").check_keys(
        (), ("elements", "wagner", "design_modes", "gust", "v_max", "pk")
    )
    kw["elements"] = md.integer("elements", 10, lo=1, hi=400)
    try:
        build_mesh(wing, kw["elements"])
    except InputError as exc:  # too few elements for the wing's breakpoints
        md.fail("elements", kw["elements"], str(exc).split(": ", 1)[-1])
    if md.has("wagner"):
        try:
            wagner_set(md.data["wagner"])
        except InputError as exc:
            md.fail("wagner", md.data["wagner"], str(exc))
        kw["wagner"] = md.data["wagner"]
    modes = md.integer("design_modes", 8, lo=0, hi=10_000)
    kw["design_modes"] = None if modes == 0 else modes
    kw["gust_model"] = md.string("gust", "kussner", choices=("kussner", "upwash"))
    kw["v_max"] = md.number("v_max", unit="m/s", lo=0.0, lo_open=True)
    kw["pk"] = md.boolean("pk", False)

    sg = top.table("signals").check_keys(
        (), ("controls", "sensors", "outputs", "sensor_filter", "filter_order")
    )
    surfaces = [cs.name for cs in wing.control_surfaces]
    default_controls = [f"{surfaces[0]}_hinge_moment"] if surfaces else []
    kw["controls"] = tuple(sg.strings("controls", default_controls))
    kw["sensors"] = tuple(sg.strings("sensors", ["tip_le_accel", "tip_te_accel", "tip_twist"]))
    kw["outputs"] = tuple(sg.strings("outputs", ["tip_disp"], nonempty=False))
    cutoff = sg.number("sensor_filter", 30.0, unit="Hz", lo=0.0)
    kw["sensor_filter"] = None if cutoff == 0 else cutoff
    kw["filter_order"] = sg.integer("filter_order", 2, lo=1, hi=4)

    sim = top.table("simulation").check_keys(
        (), ("duration", "sample_rate", "delay", "seed", "sensor_noise")
    )
    kw["duration"] = sim.number("duration", 2.0, unit="s", lo=0.0, hi=600.0, lo_open=True)
    kw["sample_rate"] = sim.number("sample_rate", 1000.0, unit="Hz", lo=1.0, hi=1.0e5)
    kw["delay"] = sim.boolean("delay", False)
    kw["seed"] = sim.integer("seed", 0, lo=0, hi=2**32 - 1)
    kw["sensor_noise"] = sim.number_map("sensor_noise", lo=0.0, lo_open=False)

    an = top.table("analysis").check_keys((), ("closed_loop_boundary", "v_max_factor", "n_grid"))
    kw["closed_loop_boundary"] = an.boolean("closed_loop_boundary", False)
    kw["v_max_factor"] = an.number("v_max_factor", 2.0, lo=1.0, hi=10.0, lo_open=True)
    kw["n_grid"] = an.integer("n_grid", 41, lo=3, hi=2000)

    out = top.table("output").check_keys((), ("result", "plots"))
    stem = Path(file).stem if file != "<dict>" else "scenario"
    kw["result"] = out.string("result", stem)
    result = kw["result"]
    if result in ("", ".", "..") or Path(result).name != result or not result.isprintable():
        out.fail("result", kw["result"], "expected a plain file name stem (no folders)")
    kw["plots"] = out.boolean("plots", True)

    if kind == "simulate":
        kw["disturbance"] = _disturbance(top.table("disturbance"), base, wing.span)
        ct = top.table("controller", required=True).check_keys(("spec",))
        spec_path = ct.path("spec", base, required=True)
        kw["controller"] = _controller(ct, spec_path)
    if kind == "trade":
        kw["trade"] = _trade_table(top.table("trade", required=True), base)

    scenario = Scenario(**kw)
    cross_check(scenario, top)
    return scenario


def _controller(ct: Table, path: Path, key: str = "spec") -> ControllerSpec:
    """The controller file ``path`` named by ``key``; its errors also name this file."""
    if not _is_file(path):
        ct.fail(key, ct.data[key], f"no such controller file ({path})")
    try:
        return load_controller(path)
    except InputError as exc:
        raise InputError(f"{ct.file}: {ct.key_name(key)} -> {exc}") from None


def _trade_table(tbl: Table, base: Path) -> dict:
    """Raw trade settings; validated against the wing by :mod:`aeroservo.studies.trade`."""
    from ..studies.trade.study import PARAMETERS

    tbl.check_keys(
        ("controller", "parameters"),
        (
            "speed_factor",
            "gust_length",
            "gust_amplitude",
            "gust_duration",
            "v_max_factor",
            "n_grid",
            "workers",
        ),
    )
    spec = _controller(tbl, tbl.path("controller", base, required=True), "controller")
    if spec.type not in ("lqr", "lqg"):
        tbl.fail(
            "controller",
            tbl.data["controller"],
            f"a trade study needs a linear controller (lqr or lqg), this one is {spec.type!r}",
        )
    pt = tbl.table("parameters").check_keys((), tuple(PARAMETERS))
    params = {}
    for name in pt.data:
        params[name] = tuple(pt.numbers(name, lo=0.0, lo_open=name != "hinge_stiffness"))
        if len(set(params[name])) != len(params[name]):
            pt.fail(name, pt.data[name], "values must not repeat")
    if not params:
        tbl.fail("parameters", tbl.data["parameters"], f"give at least one of {list(PARAMETERS)}")
    n_cases = int(np.prod([len(v) for v in params.values()]))
    if n_cases > 1_000_000:
        tbl.fail("parameters", tbl.data["parameters"], f"{n_cases} cases: the limit is 1 000 000")
    return {
        "controller": spec,
        "parameters": params,
        "speed_factor": tbl.number("speed_factor", 1.1, lo=0.0, hi=10.0, lo_open=True),
        "gust_length": tbl.number("gust_length", 25.0, unit="m", lo=0.0, lo_open=True),
        "gust_amplitude": tbl.number("gust_amplitude", 5.0, unit="m/s", lo=-50.0, hi=50.0),
        "gust_duration": tbl.number("gust_duration", 1.0, unit="s", lo=0.0, hi=60.0, lo_open=True),
        "v_max_factor": tbl.number("v_max_factor", 2.0, lo=1.0, hi=10.0, lo_open=True),
        "n_grid": tbl.integer("n_grid", 21, lo=3, hi=2000),
        "workers": tbl.integer("workers", 2, lo=1, hi=256),
    }


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario file.

    Raises
    ------
    InputError
        With the file, the key and the value of the first problem found.
    """
    path = Path(path)
    with one_line_errors():
        return scenario_from_dict(read_toml(path), str(path), path.parent)


def is_scenario_file(path: str | Path) -> bool:
    """Whether a TOML file is a scenario (it has a ``[scenario]`` table)."""
    try:
        return "scenario" in read_toml(path)
    except InputError:
        return False


def scenario_folder():
    """The ``scenarios/`` folder shipped with the source tree (or ``./scenarios``), or None."""
    for folder in (Path(__file__).resolve().parents[3] / "scenarios", Path.cwd() / "scenarios"):
        if folder.is_dir():
            return folder
    return None


def shipped_scenarios() -> list:
    """``(path, kind, name)`` of every scenario file in :func:`scenario_folder`."""
    folder = scenario_folder()
    out = []
    for path in sorted(folder.glob("*.toml")) if folder else []:
        try:
            sc = read_toml(path).get("scenario")
        except InputError:
            continue
        if isinstance(sc, dict):
            out.append((path, str(sc.get("kind", "?")), str(sc.get("name", ""))))
    return out
