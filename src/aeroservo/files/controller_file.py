"""Controller specification files (``controllers/*.toml``, schema in ``docs/scenarios.md``).

A controller file describes *how* to design a flutter-suppression controller, independently of
the wing: the type (``lqr``, ``lqg``, ``mpc``, ``hinf`` or ``none`` for the open loop), Bryson
weights or nominal magnitudes, actuator limits, estimator noise levels, MPC settings,
H-infinity weights, an optional gain schedule and the loop-margin requirement. Scenarios
refer to it by path, so one wing can be tried with many controllers. Signal names are checked
against the wing's model when a scenario is resolved.
"""

from __future__ import annotations

from pathlib import Path

from ..design.hinf import HinfWeights
from ..design.margins import MarginRequirement
from ..design.mpc import SOLVERS
from ..design.plant import Limits
from ..design.spec import CONTROLLER_TYPES, ControllerSpec
from .toml_tables import Table, check_integers, one_line_errors, read_toml

__all__ = ["load_controller", "controller_from_dict"]


TOP_KEYS = (
    "type",
    "name",
    "description",
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
    }[kind]
    allowed = {
        "none": ("limits",),
        "lqr": ("weights", "limits", "schedule", "margins"),
        "lqg": ("weights", "estimator", "limits", "schedule", "margins"),
        "mpc": ("weights", "estimator", "limits", "mpc", "margins"),
        "hinf": ("weights", "limits", "hinf", "margins"),
    }[kind]
    for key in TOP_KEYS[3:]:
        if top.has(key) and key not in allowed:
            top.fail(key, top.data[key], f"not used by a controller of type {kind!r}")
        if key in needs and not top.has(key):
            raise_missing(top, key, kind)

    if kind == "hinf":
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
    mg = top.table("margins").check_keys((), ("gain_db", "phase_deg", "disk_alpha"))
    req = MarginRequirement()
    kw["margins"] = MarginRequirement(
        gain_db=mg.number("gain_db", req.gain_db, lo=0.0),
        phase_deg=mg.number("phase_deg", req.phase_deg, lo=0.0, hi=180.0),
        disk_alpha=mg.number("disk_alpha", None, lo=0.0, hi=2.0, lo_open=True),
    )

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
        ("process_noise", "sensor_noise") if top.has("estimator") else ()
    )
    kw["process_noise"] = est.number_map("process_noise", quantity="estimator_variance")
    kw["sensor_noise"] = est.number_map("sensor_noise", quantity="estimator_variance")
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


def raise_missing(table: Table, key: str, kind: str):
    from ..errors import InputError

    raise InputError(
        f"{table.file}: {table.key_name(key)}: missing; a controller of type {kind!r} needs it"
    )


def load_controller(path: str | Path) -> ControllerSpec:
    """Read a controller file (``controllers/*.toml``)."""
    with one_line_errors():
        return controller_from_dict(read_toml(path), str(path))
