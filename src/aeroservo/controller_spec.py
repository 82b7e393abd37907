"""Controller specification files (``controllers/*.toml``, schema in ``docs/scenarios.md``).

A controller file describes *how* to design a flutter-suppression controller, independently of
the wing: the type (``lqr``, ``lqg``, ``mpc`` or ``none`` for the open loop), Bryson weights,
actuator limits, estimator noise levels, MPC settings and an optional gain schedule. Scenarios
refer to it by path, so one wing can be tried with many controllers. Signal names are checked
against the wing's model when a scenario is resolved.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from .design.mpc import SOLVERS
from .design.plant import Limits
from .tomlspec import Table, check_integers, one_line_errors, read_toml

__all__ = ["ControllerSpec", "load_controller", "controller_from_dict", "CONTROLLER_TYPES"]

CONTROLLER_TYPES = ("none", "lqr", "lqg", "mpc")


@dataclass(frozen=True)
class ControllerSpec:
    """How to design a controller.

    Attributes
    ----------
    type : str
        ``"none"`` (open loop), ``"lqr"`` (full-state feedback), ``"lqg"`` (Kalman filter on
        the sensors + LQR) or ``"mpc"`` (constrained MPC, casadi, Kalman filter).
    name : str
    bryson_outputs, bryson_inputs : dict
        Allowed output and control values (Bryson's rule), in the signals' units.
    state_weight : float
        Small regularizing weight on all states (relative).
    limits : Limits
        Actuator magnitude [signal unit] and rate [signal unit / s] limits, applied in every
        simulation and used by MPC.
    process_noise : dict
        Variance of each disturbance input, e.g. ``{"gust": 1.0}`` [(m/s)^2] (LQG, MPC).
    sensor_noise : dict
        Variance of each sensor [unit^2] (LQG, MPC).
    horizon : int
        MPC horizon [samples].
    solver : str
        casadi conic solver of the MPC QP.
    soft_outputs : dict
        MPC soft output limits (slack variables; never infeasible).
    slack_weight : float
        Relative weight of the squared slacks.
    schedule : tuple of float or None
        Gain-schedule design speeds as multiples of the open-loop flutter speed (LQR, LQG).
    source : str
        File the spec was read from.
    """

    type: str
    name: str = ""
    bryson_outputs: dict = field(default_factory=dict)
    bryson_inputs: dict = field(default_factory=dict)
    state_weight: float = 1e-8
    limits: Limits = field(default_factory=Limits)
    process_noise: dict = field(default_factory=dict)
    sensor_noise: dict = field(default_factory=dict)
    horizon: int = 20
    solver: str = "daqp"
    soft_outputs: dict = field(default_factory=dict)
    slack_weight: float = 1e4
    schedule: tuple | None = None
    source: str = "<dict>"

    @property
    def signals(self) -> dict:
        """Every signal name the spec refers to, by the key that names it."""
        return {
            "weights.outputs": list(self.bryson_outputs),
            "weights.inputs": list(self.bryson_inputs),
            "limits.magnitude": list(self.limits.magnitude),
            "limits.rate": list(self.limits.rate),
            "estimator.process_noise": list(self.process_noise),
            "estimator.sensor_noise": list(self.sensor_noise),
            "mpc.soft_outputs": list(self.soft_outputs),
        }


TOP_KEYS = ("type", "name", "description", "weights", "limits", "estimator", "mpc", "schedule")


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
    }[kind]
    allowed = {
        "none": ("limits",),
        "lqr": ("weights", "limits", "schedule"),
        "lqg": ("weights", "estimator", "limits", "schedule"),
        "mpc": ("weights", "estimator", "limits", "mpc"),
    }[kind]
    for key in TOP_KEYS[3:]:
        if top.has(key) and key not in allowed:
            top.fail(key, top.data[key], f"not used by a controller of type {kind!r}")
        if key in needs and not top.has(key):
            raise_missing(top, key, kind)

    w = top.table("weights").check_keys(
        ("outputs", "inputs") if top.has("weights") else (), ("state_weight",)
    )
    kw["bryson_outputs"] = w.number_map("outputs")
    kw["bryson_inputs"] = w.number_map("inputs")
    if top.has("weights") and (not kw["bryson_outputs"] or not kw["bryson_inputs"]):
        key = "outputs" if not kw["bryson_outputs"] else "inputs"
        w.fail(key, w.data[key], "give at least one allowed value")
    kw["state_weight"] = w.number("state_weight", 1e-8, lo=0.0)

    lim = top.table("limits").check_keys((), ("magnitude", "rate"))
    kw["limits"] = Limits(magnitude=lim.number_map("magnitude"), rate=lim.number_map("rate"))
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
    kw["process_noise"] = est.number_map("process_noise")
    kw["sensor_noise"] = est.number_map("sensor_noise")
    for k in ("process_noise", "sensor_noise"):
        if top.has("estimator") and not kw[k]:
            est.fail(k, est.data[k], "give at least one variance")

    m = top.table("mpc").check_keys((), ("horizon", "solver", "soft_outputs", "slack_weight"))
    kw["horizon"] = m.integer("horizon", 20, lo=1, hi=500)
    kw["solver"] = m.string("solver", "daqp", choices=sorted(SOLVERS))
    kw["soft_outputs"] = m.number_map("soft_outputs")
    kw["slack_weight"] = m.number("slack_weight", 1e4, lo=0.0, lo_open=True)

    if top.has("schedule"):
        s = top.table("schedule").check_keys(("speed_factors",))
        kw["schedule"] = tuple(s.numbers("speed_factors", lo=0.0, lo_open=True, increasing=True))
        if len(kw["schedule"]) < 2:
            s.fail("speed_factors", s.data["speed_factors"], "give at least two speeds")
    return ControllerSpec(**kw)


def raise_missing(table: Table, key: str, kind: str):
    from .errors import InputError

    raise InputError(
        f"{table.file}: {table.key_name(key)}: missing; a controller of type {kind!r} needs it"
    )


def load_controller(path: str | Path) -> ControllerSpec:
    """Read a controller file (``controllers/*.toml``)."""
    with one_line_errors():
        return controller_from_dict(read_toml(path), str(path))
