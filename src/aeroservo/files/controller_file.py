"""Controller specification files (``controllers/*.toml``, schema in ``docs/scenarios.md``).

A controller file describes *how* to design a flutter-suppression controller, independently of
the wing: the type (``lqr``, ``lqg``, ``mpc``, ``hinf`` or ``none`` for the open loop), Bryson
weights or nominal magnitudes, actuator limits, estimator noise levels, MPC settings,
H-infinity weights, an optional gain schedule and the loop-margin requirement; or it brings a
controller designed elsewhere: a saved compensator (``linear``: ``.npz`` or MATLAB ``.mat``,
:mod:`aeroservo.files.linear_controller`), a static gain (``gain``) or a Python law
(``python``). Scenarios
refer to it by path, so one wing can be tried with many controllers. Signal names are checked
against the wing's model when a scenario is resolved.
"""

from __future__ import annotations

from pathlib import Path

from ..design.hinf import HinfWeights
from ..design.interface import MAX_GAIN
from ..design.margin_requirement import BREAK_POINT_KEYS, MarginRequirement
from ..design.model_predictive import SOLVERS
from ..design.plant import Limits
from ..design.spec import CONTROLLER_TYPES, ControllerSpec
from ..errors import InputError
from .toml_tables import Table, check_integers, one_line_errors, read_toml

__all__ = ["load_controller", "controller_from_dict"]


TOP_KEYS = (
    "type",
    "name",
    "description",
    "file",
    "method",
    "prewarp",
    "sign",
    "anti_windup",
    "function",
    "needs_state",
    "budget_s",
    "import_budget_s",
    "sensors",
    "gain",
    "weights",
    "limits",
    "estimator",
    "mpc",
    "schedule",
    "hinf",
    "margins",
)
HINF_KEYS = tuple(HinfWeights.__dataclass_fields__)


MAX_SCHEDULE = 50
"""Most design speeds of a gain schedule (each is an LQR/LQG design)."""


NO_ANTI_WINDUP = {
    "lqr": " (a state feedback has no state to wind up)",
    "gain": " (a static gain has no state to wind up)",
    "mpc": " (an MPC plans within its limits)",
    "python": " (a Python law handles its limits itself)",
    "none": " (an open loop commands nothing)",
}
"""Why a type has no ``anti_windup`` switch (:mod:`aeroservo.design.anti_windup`)."""


def controller_from_dict(data: object, file: str = "<dict>") -> ControllerSpec:
    """Build a :class:`ControllerSpec` from a parsed controller file."""
    with one_line_errors():
        return _controller_from_dict(data, file)


def _controller_from_dict(data: object, file: str) -> ControllerSpec:
    check_integers(data, file)
    top = Table(data, "", file).check_keys(("type",), TOP_KEYS[1:])
    kind = top.string("type", choices=CONTROLLER_TYPES, required=True)
    top.string("description")
    kw: dict = {"type": kind, "name": top.string("name", "") or kind, "source": file}
    needs = {
        "none": (),
        "lqr": ("weights",),
        "lqg": ("weights", "estimator"),
        "mpc": ("weights", "estimator", "limits"),
        "hinf": ("weights",),
        "linear": ("file",),  # and sign, whose absence gets its own line (_sign)
        "gain": ("gain",),
        "python": ("file", "function"),
    }[kind]
    allowed = {
        "none": ("limits",),
        "lqr": ("weights", "limits", "schedule", "margins"),
        "lqg": ("weights", "estimator", "limits", "schedule", "margins", "anti_windup"),
        "mpc": ("weights", "estimator", "limits", "mpc", "margins"),
        "hinf": ("weights", "limits", "hinf", "margins", "anti_windup"),
        "linear": ("file", "method", "prewarp", "sign", "anti_windup", "limits", "margins"),
        "gain": ("gain", "sign", "limits", "margins"),
        "python": (
            "file",
            "function",
            "sensors",
            "needs_state",
            "budget_s",
            "import_budget_s",
            "limits",
        ),  # fmt: skip
    }[kind]
    for key in TOP_KEYS[3:]:
        if top.has(key) and key not in allowed:
            why = NO_ANTI_WINDUP.get(kind, "") if key == "anti_windup" else ""
            top.fail(key, top.data[key], f"not used by a controller of type {kind!r}{why}")
        if key in needs and not top.has(key):
            raise_missing(top, key, kind)

    if kind in ("linear", "gain", "python"):
        brought(top, kind, kw, Path(file).parent)
    elif kind == "hinf":
        w = top.table("weights").check_keys(("inputs", "sensors"))
        kw["bryson_inputs"] = w.number_map("inputs", quantity="bryson")
        kw["sensor_scales"] = w.number_map("sensors", quantity="bryson")
        for key in ("inputs", "sensors"):
            if not w.number_map(key):
                w.fail(key, w.data[key], "give a nominal magnitude per signal")
        h = top.table("hinf").check_keys((), HINF_KEYS)
        d = HinfWeights()
        kw["hinf"] = HinfWeights(
            order=h.integer("order", d.order, lo=1, hi=1000),
            **{
                k: h.number(
                    k,
                    getattr(d, k),
                    unit="Hz" if k in ("bandwidth", "roll_off") else "",
                    lo=1.0 if k == "gamma_factor" else 0.0,
                    hi=1e6,
                    lo_open=True,
                )
                for k in HINF_KEYS
                if k != "order"
            },
        )
    else:
        w = top.table("weights").check_keys(
            ("outputs", "inputs") if top.has("weights") else (), ("state_weight",)
        )
        kw["bryson_outputs"] = w.number_map("outputs", quantity="bryson")
        kw["bryson_inputs"] = w.number_map("inputs", quantity="bryson")
        if top.has("weights") and (not kw["bryson_outputs"] or not kw["bryson_inputs"]):
            key = "outputs" if not kw["bryson_outputs"] else "inputs"
            w.fail(key, w.data[key], "give at least one allowed value")
        kw["state_weight"] = w.number("state_weight", 1e-8, lo=0.0, hi=1.0)
    mg = top.table("margins").check_keys(
        (), ("gain_db", "phase_deg", "disk_alpha", "delay_ms", "at")
    )
    req = MarginRequirement()
    at = mg.strings("at", list(req.at))
    bad = [a for a in at if a not in BREAK_POINT_KEYS]
    if bad:
        mg.fail("at", at, f"allowed break points are {list(BREAK_POINT_KEYS)}")
    kw["margins"] = MarginRequirement(
        gain_db=mg.number("gain_db", req.gain_db, lo=0.0),
        phase_deg=mg.number("phase_deg", req.phase_deg, lo=0.0, hi=180.0),
        disk_alpha=mg.number("disk_alpha", None, lo=0.0, hi=2.0, lo_open=True),
        delay_ms=mg.number("delay_ms", None, unit="ms", lo=0.0, hi=1e4),
        at=tuple(at),
    )

    if top.has("anti_windup"):  # lqg, hinf, linear (others refused above)
        kw["anti_windup"] = top.boolean("anti_windup")

    lim = top.table("limits").check_keys((), ("magnitude", "rate"))
    kw["limits"] = Limits(
        magnitude=lim.number_map("magnitude", quantity="limit"),
        rate=lim.number_map("rate", quantity="limit"),
    )
    if kind == "mpc":
        for k in ("magnitude", "rate"):
            if not getattr(kw["limits"], k):
                raise_missing(lim, k, kind)
        for c in kw["bryson_inputs"]:
            for k in ("magnitude", "rate"):
                if c not in getattr(kw["limits"], k):
                    lim.fail(k, lim.data[k], f"MPC needs a {k} limit for control {c!r}")

    est = top.table("estimator").check_keys(
        ("process_noise", "sensor_noise") if top.has("estimator") else (), ("input_noise",)
    )
    kw["process_noise"] = est.number_map("process_noise", quantity="estimator_variance")
    kw["sensor_noise"] = est.number_map("sensor_noise", quantity="estimator_variance")
    kw["input_noise"] = est.number_map("input_noise", quantity="input_noise")
    for k in ("process_noise", "sensor_noise"):
        if top.has("estimator") and not kw[k]:
            est.fail(k, est.data[k], "give at least one variance")

    m = top.table("mpc").check_keys((), ("horizon", "solver", "soft_outputs", "slack_weight"))
    kw["horizon"] = m.integer("horizon", 20, lo=1, hi=500)
    kw["solver"] = m.string("solver", "daqp", choices=sorted(SOLVERS))
    kw["soft_outputs"] = m.number_map("soft_outputs", quantity="limit")
    kw["slack_weight"] = m.number("slack_weight", 1e4, lo=0.0, hi=1e12, lo_open=True)

    if top.has("schedule"):
        s = top.table("schedule").check_keys(("speed_factors",))
        kw["schedule"] = tuple(s.numbers("speed_factors", quantity="speed_factor", increasing=True))
        if len(kw["schedule"]) > MAX_SCHEDULE:
            s.fail("speed_factors", f"<{len(kw['schedule'])} speeds>", f"at most {MAX_SCHEDULE}")
        if len(kw["schedule"]) < 2:
            s.fail("speed_factors", s.data["speed_factors"], "give at least two speeds")
    return ControllerSpec(**kw)


def brought(top: Table, kind: str, kw: dict, base: Path) -> None:
    """The ``linear``, ``gain`` and ``python`` types: a controller designed elsewhere."""
    sign = _sign(top) if kind in ("gain", "linear") else None
    if kind == "gain":
        g = top.table("gain").check_keys(("controls", "matrix"), ("sensors", "states"))
        if g.has("sensors") == g.has("states"):
            g.fail("sensors", g.data.get("sensors"), "give sensors or states (one of them)")
        controls = g.strings("controls")
        cols = g.strings("sensors" if g.has("sensors") else "states")
        rows = g.data["matrix"]
        if not isinstance(rows, list) or len(rows) != len(controls):
            g.fail("matrix", rows, f"expected {len(controls)} rows (one per control)")
        K = []
        for i, row in enumerate(rows):
            if not isinstance(row, list) or len(row) != len(cols):
                g.fail("matrix", rows, f"row {i}: expected {len(cols)} numbers")
            K.append(
                [
                    g.check_value(f"matrix[{i}][{j}]", x, lo=-MAX_GAIN, hi=MAX_GAIN)
                    for j, x in enumerate(row)
                ]
            )
        kw["gain"] = {
            "K": K,
            "sign": sign,
            "controls": controls,
            ("sensors" if g.has("sensors") else "states"): cols,
        }
        return
    path = top.path("file", base, required=True)
    if kind == "python":
        from ..design.user_code import DEFAULT_BUDGET, IMPORT_BUDGET, MAX_BUDGET

        seconds = {"unit": "s", "lo": 0.0, "lo_open": True, "hi": MAX_BUDGET}
        budget = top.number("budget_s", DEFAULT_BUDGET, **seconds)
        kw["python"] = {
            "function": python_function(
                top,
                path,
                top.string("function", required=True),
                top.number("import_budget_s", IMPORT_BUDGET, **seconds),
            ),  # fmt: skip
            "sensors": top.strings("sensors") if top.has("sensors") else None,
            "needs_state": top.boolean("needs_state", False),
            "source": f"{path.name}:{top.data['function']}",
        }
        if top.has("budget_s"):  # only then: the ids of trade cases stay as they were
            kw["python"]["budget"] = budget
        return
    from ..design.compensator import DISCRETIZATIONS
    from .linear_controller import read_linear_controller

    try:
        lin = read_linear_controller(path)
    except InputError as exc:
        top.fail("file", top.data["file"], str(exc))
    lin["method"] = top.string("method", "tustin", choices=DISCRETIZATIONS)
    lin["prewarp"] = top.number("prewarp", None, unit="Hz", lo=0.0, lo_open=True, hi=5e4)
    lin["sign"] = sign
    kw["linear"] = lin


def _sign(top: Table) -> int:
    """``sign``, required by a ``gain`` and a ``linear`` file: the command is ``u = sign K y``
    (``+1``: the matrix's or the compensator's output is the command, as MATLAB's hinfsyn and
    lqgreg give it; ``-1``: negative feedback, as python-control's lqr K and feedback())."""
    if not top.has("sign"):
        raise InputError(
            f"{top.file}: {top.key_name('sign')}: missing; give sign = 1 (u = +K y: the matrix "
            "or compensator output is the command) or sign = -1 (u = -K y: negative feedback, "
            "control.lqr's K); older versions read a gain file as -1 and a linear file as +1 "
            "without saying so (docs/conventions.md)"
        )
    sign = top.integer("sign", lo=-1, hi=1)
    if sign == 0:
        top.fail("sign", 0, "expected 1 (u = +K y) or -1 (u = -K y)")
    return sign


def python_function(top: Table, path: Path, name: str, budget: float):
    """The function ``name`` of the Python file ``path`` (run as a module, as the user's own
    code, within ``budget`` [s]: :func:`~aeroservo.design.user_code.run_law_file`); errors
    name the controller file's key, what the file wrote while loaded is one warning."""
    import warnings

    from ..design.user_code import run_law_file

    if path.suffix != ".py":
        top.fail("file", top.data["file"], "expected a Python file ending in .py")
    if not path.is_file():
        top.fail("file", top.data["file"], f"no such Python file ({path})")
    try:
        module, output = run_law_file(path, budget)
    except InputError as exc:
        top.fail("file", top.data["file"], str(exc))
    if output:
        warnings.warn(f"{path.name}: not shown: {output} while loaded", stacklevel=2)
    fn = getattr(module, name, None)
    if not callable(fn):
        top.fail("function", name, f"{path.name} defines no function of that name")
    return fn


def raise_missing(table: Table, key: str, kind: str):
    raise InputError(
        f"{table.file}: {table.key_name(key)}: missing; a controller of type {kind!r} needs it"
    )


def load_controller(path: str | Path) -> ControllerSpec:
    """Read a controller file (``controllers/*.toml``)."""
    with one_line_errors():
        return controller_from_dict(read_toml(path), str(path))
