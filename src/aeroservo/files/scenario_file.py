"""Scenario files (``scenarios/*.toml``, schema in ``docs/scenarios.md``).

A scenario says what to run on which wing: an open-loop flutter analysis (``kind =
"flutter"``), a closed-loop time simulation (``"simulate"``), a trade study (``"trade"``),
gust loads (``"gust_loads"``, its tables in :mod:`aeroservo.files.gust_loads_tables`) or limit
cycles of nonlinear hinges (``"lco"``, on a wing or a typical section, its tables in
:mod:`aeroservo.files.lco_tables`),
with the flight condition, model options, signals, disturbance, a reference to a controller
file, simulation settings and what to write. :func:`load_scenario` validates everything,
including the cross-checks that need the wing (signals, sensor stations, controller signals,
limits against the initial state); every error names the file, the key and the value.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import MAX_ELEMENTS, InputError
from ..simulate.march import MAX_SAMPLES
from ..stability.matched import COMPRESSIBILITY
from ..studies.kinds import KINDS
from ..studies.scenario import Scenario
from .aero_tables import model_aero
from .gust_loads_tables import gust_cross_check, gust_loads_tables
from .lco_tables import lco_cross_check, lco_tables, section_table
from .scenario_checks import simulate_check, trade_check
from .scenario_tables import (
    actuator_table,
    controller,
    disturbance,
    engaged_speeds,
    flight,
    is_file,
    sol145_table,
    trade_table,
)
from .toml_tables import Table, check_integers, is_scenario_file, one_line_errors, read_toml
from .wing_file import damping_from_dict

__all__ = ["load_scenario", "scenario_from_dict", "is_scenario_file", "shipped_scenarios"]

TOP = (
    "scenario",
    "wing",
    "flight",
    "model",
    "signals",
    "actuator",
    "disturbance",
    "controller",
    "simulation",
    "analysis",
    "output",
    "damping",
    "trade",
    "gust_loads",
    "lco",
    "section",
    "sol145",
)


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
            return BUILTIN_WINGS[name](), f"builtin {name}", None
        path = tbl.path("file", base)
        if not is_file(path):
            tbl.fail("file", tbl.data["file"], f"no such wing file ({path})")
        data = None
        try:
            data = read_toml(path).get("wing")
            wing, opts = load_wing(path)
            return wing, str(path), (opts.damping if opts.damping.active else None)
        except InputError as exc:
            msg = _surface_keys(str(exc), data, "wing")
            raise InputError(f"{tbl.file}: {tbl.key_name('file')} -> {msg}") from None
    try:
        return wing_from_dict(tbl.data, tbl.where), "inline", None
    except InputError as exc:
        msg = _surface_keys(str(exc), tbl.data, tbl.where)
        raise InputError(f"{tbl.file}: {msg}") from None


MIN_FILTER = 0.01
"""Lowest sensor-filter cut-off [Hz] (a slower filter is a constant: give 0 for none)."""

MAX_RESULT_NAME = 200
"""Longest result stem [bytes]: its longest file, ``<result>_margin_sweep.png``, and the
temporary name it is written under stay within the usual 255-byte file-name limit."""


def scenario_from_dict(data: object, file: str = "<dict>", base: Path | None = None) -> Scenario:
    """Validate a parsed scenario file. ``base`` is the folder relative paths start from."""
    with one_line_errors():
        return _scenario_from_dict(data, file, base)


def _scenario_from_dict(data: object, file: str, base: Path | None) -> Scenario:
    from ..aero.indicial import wagner_set
    from ..structure.mesh import build_mesh

    base = Path(file).parent if base is None else base
    check_integers(data, file)
    top = Table(data, "", file).check_keys(("scenario",), TOP[1:])
    sc = top.table("scenario").check_keys(("name", "kind"), ("description",))
    kind = sc.string("kind", choices=tuple(KINDS), required=True)
    this = KINDS[kind]
    for key in TOP:
        if top.has(key) and key not in this.tables:
            top.fail(key, top.data[key], f"not used by a scenario of kind {kind!r}")
    section = this.section and top.has("section")  # a typical section instead of a wing
    if not section and not top.has("wing"):
        also = " (or [section], a typical section)" if this.section else ""
        raise InputError(f"{file}: wing: missing required key{also}")
    kw: dict = {
        "name": sc.string("name", required=True),
        "kind": kind,
        "source": file,
        "description": sc.string("description", ""),
    }
    if section:
        kw["wing"], kw["wing_source"], wing_damping = None, "section", None
    else:
        kw["wing"], kw["wing_source"], wing_damping = _wing(top.table("wing"), base)
    wing = kw["wing"]

    fl = top.table("flight").check_keys(
        (), ("density", "altitude", "altitude_ft", "speed", "speed_factor")
    )
    if fl.data or not this.flight_is_design_point:  # else: the controller's design point
        flight(fl, kw)
    if fl.has("speed") and fl.has("speed_factor"):
        fl.fail("speed_factor", fl.data["speed_factor"], "give speed or speed_factor, not both")
    kw["speed"] = fl.number("speed", quantity="flight_speed")
    kw["speed_factor"] = fl.number("speed_factor", quantity="speed_factor")
    if this.needs_speed and kw["speed"] is None and kw["speed_factor"] is None:
        raise InputError(f"{file}: flight.speed: missing; give speed [m/s] or speed_factor")

    md = top.table("model").check_keys(
        (),
        ("elements", "wagner", "design_modes", "gust", "v_max", "pk", "compressibility")
        + ("aero", "mach", "dlm"),
    )
    comp = md.string("compressibility", "none", choices=COMPRESSIBILITY)
    if comp != "none":
        if not this.flight_condition:
            md.fail(
                "compressibility",
                comp,
                "only flutter scenarios take it (use 'aeroservo envelope' or a flutter scenario)",
            )
        if kw["altitude"] is None:
            md.fail("compressibility", comp, "needs flight.altitude or flight.altitude_ft")
        kw["compressibility"] = comp
    model_aero(md, kw, this.flight_condition, section)
    if top.has("damping"):
        try:
            kw["damping"] = damping_from_dict(top.data["damping"], "damping")
        except InputError as exc:
            raise InputError(f"{file}: {exc}") from None
    elif wing_damping is not None:
        kw["damping"] = wing_damping
    kw["elements"] = md.integer("elements", 10, lo=1, hi=MAX_ELEMENTS)
    try:
        if wing is not None:
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
    kw["v_max"] = md.number("v_max", quantity="flight_speed")
    kw["pk"] = md.boolean("pk", False)
    kw["sol145"] = sol145_table(top.table("sol145"), kw["v_max"])

    sg = top.table("signals").check_keys(
        (), ("controls", "sensors", "outputs", "sensor_filter", "filter_order")
    )
    surfaces = [cs.name for cs in wing.control_surfaces] if wing is not None else []
    default_controls = [f"{surfaces[0]}_hinge_moment"] if surfaces else []
    kw["controls"] = tuple(sg.strings("controls", default_controls))
    kw["sensors"] = tuple(sg.strings("sensors", ["tip_le_accel", "tip_te_accel", "tip_twist"]))
    kw["outputs"] = tuple(sg.strings("outputs", ["tip_disp"], nonempty=False))
    cutoff = sg.number("sensor_filter", 30.0, quantity="frequency")
    if 0 < cutoff < MIN_FILTER:
        sg.fail("sensor_filter", cutoff, f"0 (no filter) or at least {MIN_FILTER:g} Hz")
    kw["sensor_filter"] = None if cutoff == 0 else cutoff
    kw["filter_order"] = sg.integer("filter_order", 2, lo=1, hi=4)
    kw["actuator"] = actuator_table(top.table("actuator"), kw["controls"])

    sim = top.table("simulation").check_keys(
        (),
        (
            "duration",
            "sample_rate",
            "delay",
            "seed",
            "sensor_noise",
            "expect_failure",
            "expect_unstable",
        ),
    )
    if sim.has("expect_failure") and sim.has("expect_unstable"):
        sim.fail("expect_unstable", sim.data["expect_unstable"], "give expect_failure only")
    kw["expect_failure"] = sim.boolean("expect_failure", sim.boolean("expect_unstable", False))
    kw["duration"] = sim.number("duration", 2.0, quantity="duration")
    kw["sample_rate"] = sim.number("sample_rate", 1000.0, quantity="sample_rate")
    n_samples = round(kw["duration"] * kw["sample_rate"]) + 1
    if n_samples > MAX_SAMPLES:
        sim.fail(
            "duration",
            kw["duration"],
            f"{n_samples} samples at simulation.sample_rate = {kw['sample_rate']:g} Hz, above "
            f"the limit of {MAX_SAMPLES} samples; shorten the run or lower the sample rate",
        )
    kw["delay"] = sim.boolean("delay", True)
    kw["seed"] = sim.integer("seed", 0, lo=0, hi=2**32 - 1)
    kw["sensor_noise"] = sim.number_map("sensor_noise", quantity="variance")

    an = top.table("analysis").check_keys(
        (), ("closed_loop_boundary", "v_max_factor", "n_grid", "margin_speeds")
    )
    kw["closed_loop_boundary"] = an.boolean("closed_loop_boundary", False)
    kw["v_max_factor"] = an.number("v_max_factor", 2.0, lo=1.0, hi=10.0, lo_open=True)
    kw["n_grid"] = an.integer("n_grid", 41, lo=3, hi=2000)
    kw["margin_speeds"] = an.integer("margin_speeds", 9, lo=0, hi=200)

    out = top.table("output").check_keys((), ("result", "plots"))
    stem = Path(file).stem if file != "<dict>" else "scenario"
    kw["result"] = out.string("result", stem)
    result = kw["result"]
    if result in ("", ".", "..") or Path(result).name != result or not result.isprintable():
        out.fail("result", kw["result"], "expected a plain file name stem (no folders)")
    if len(result.encode()) > MAX_RESULT_NAME:
        out.fail(
            "result",
            result[:40] + "...",
            f"{len(result.encode())} bytes; at most {MAX_RESULT_NAME} (file-name limit)",
        )
    kw["plots"] = out.boolean("plots", True)

    tables, check = KIND_TABLES[kind]
    tables(top, base, kw)
    scenario = Scenario(**kw)
    check(scenario, top)
    return scenario


def _simulate_tables(top: Table, base: Path, kw: dict) -> None:
    """``[disturbance]`` and ``[controller]`` of a simulation scenario into ``kw``."""
    kw["disturbance"] = disturbance(top.table("disturbance"), base, kw["wing"].span)
    ct = top.table("controller", required=True).check_keys(
        ("spec",),
        ("engaged_speeds", "engaged_speed_factors", "flutter_margin", "realisable"),
    )
    kw["realisable"] = ct.boolean("realisable", False)
    spec_path = ct.path("spec", base, required=True)
    kw["controller"] = controller(ct, spec_path)
    engaged_speeds(ct, kw)
    kw["flutter_margin"] = ct.number("flutter_margin", 1.15, lo=1.0, hi=3.0)


def _trade_tables(top: Table, base: Path, kw: dict) -> None:
    """``[trade]`` of a trade scenario into ``kw``."""
    kw["options"] = trade_table(top.table("trade", required=True), base)


def _lco_tables(top: Table, base: Path, kw: dict) -> None:
    """``[section]`` (a typical section instead of a wing) and ``[lco]`` into ``kw``."""
    if kw["wing"] is None:
        section_table(top, kw)
    lco_tables(top, base, kw)


def _none(*_args) -> None:
    """No tables of its own, no checks that need the wing."""


KIND_TABLES: dict = {
    "flutter": (_none, _none),
    "simulate": (_simulate_tables, simulate_check),
    "trade": (_trade_tables, trade_check),
    "gust_loads": (gust_loads_tables, gust_cross_check),
    "lco": (_lco_tables, lco_cross_check),
}
"""Per scenario kind (:data:`aeroservo.studies.kinds.KINDS`): the reader of its own tables
into the :class:`~aeroservo.studies.scenario.Scenario` keywords, and its checks that need the
wing."""


def load_scenario(path: str | Path, model: dict | None = None) -> Scenario:
    """Read and validate a scenario file; ``model``: keys that replace the file's ``[model]``
    keys (``aero``, ``mach``, ``dlm`` (merged into ``[model.dlm]``), ...: the command line's
    options; ``aero = "strip"`` drops ``[model.dlm]``, a ``mach`` the matched compressibility).

    Raises
    ------
    InputError
        With the file, the key and the value of the first problem found.
    """
    path = Path(path)
    data = read_toml(path)
    if model:
        md = data.get("model", {})
        md = dict(md) if isinstance(md, dict) else md
        if isinstance(md, dict):
            if model.get("aero") == "strip":
                md.pop("dlm", None)
            if "mach" in model:
                md.pop("compressibility", None)
            dlm = md.get("dlm", {})
            md.update(model)
            if "dlm" in model and isinstance(dlm, dict):
                md["dlm"] = {**dlm, **model["dlm"]}
            data["model"] = md
    with one_line_errors():
        return scenario_from_dict(data, str(path), path.parent)


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
