"""Checks of a scenario that need its wing: signal names, sensor stations, the controller
file's signals, the trade study against the wing, limits against the initial state.

Every error names the scenario file, the key and the value (the checks of each kind are
called by :func:`aeroservo.files.scenario_file.scenario_from_dict`).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..studies.scenario import Scenario
from .toml_tables import Table

__all__ = ["simulate_check", "trade_check", "check_loop_signals"]


def _check_study(s: Scenario) -> None:
    """Validate a trade scenario's study (parameters against the wing, ...)."""
    from ..studies.trade.scenario import study_from_scenario

    try:
        study_from_scenario(s)
    except InputError as exc:
        raise InputError(f"{s.source}: trade: {exc}") from None


def check_loop_signals(s: Scenario, wing, model, top: Table, where: str = "") -> None:
    """A loop's controls, sensors and outputs on ``wing`` (its ``model``), and the design
    modes; ``where`` ends each message (e.g. the mass case)."""
    from ..linear.signals import input_names, resolve_outputs

    sg = top.table("signals")
    if not wing.control_surfaces:
        sg.fail("controls", list(s.controls), f"the wing has no control surface to drive{where}")
    inputs = input_names(wing)
    for c in s.controls:
        if c not in inputs or c == "gust":
            allowed = sorted(k for k in inputs if k != "gust")
            sg.fail(
                "controls", list(s.controls), f"{c!r} is not a control{where}; allowed {allowed}"
            )
    if s.design_modes is not None and s.design_modes > model.n_dofs:
        top.table("model").fail(
            "design_modes",
            s.design_modes,
            f"more than the {model.n_dofs} degrees of freedom of {s.elements} elements",
        )
    for key in ("sensors", "outputs"):
        names = list(getattr(s, key))
        for name in names:
            try:
                resolve_outputs(model, [name], model.n_dofs)
            except InputError as exc:
                sg.fail(key, names, f"{exc}{where}")


def _loop_check(s: Scenario, top: Table, spec, key: str) -> object:
    """The loop's signals on the wing, the sensor filter against the sample rate and the
    controller's signal names against the loop's (``key`` names the controller in errors);
    returns the wing's model."""
    from ..design.loop import check_spec_signals

    sg = top.table("signals")
    model = s.model()
    check_loop_signals(s, s.wing, model, top)
    if s.sensor_filter is not None and s.sensor_filter >= 0.5 * s.sample_rate:
        sg.fail(
            "sensor_filter",
            s.sensor_filter,
            f"must be below the Nyquist frequency {0.5 * s.sample_rate:g} Hz of "
            "simulation.sample_rate",
        )
    # the controller's signal names against the loop's, without building the loop's
    # state-space models (that takes minutes for a fine mesh)
    try:
        check_spec_signals(spec, s.controls, s.sensors, s.outputs)
    except InputError as exc:
        raise InputError(f"{s.source}: {key} -> {exc}") from None
    return model


def trade_check(s: Scenario, top: Table) -> None:
    """Checks of a trade scenario that need the wing: the loop's signals (closed loop) and the
    study against the wing (its parameters, ...)."""
    if s.trade.closed_loop:
        _loop_check(s, top, s.trade.controller, "trade.controller")
    _check_study(s)


def simulate_check(s: Scenario, top: Table) -> None:
    """Checks of a simulation scenario that need the wing: signal names, sensor noise, limits
    against the initial state."""
    spec = s.controller
    model = _loop_check(s, top, spec, "controller.spec")
    for name in s.sensor_noise:
        if name not in s.sensors:
            top.table("simulation").table("sensor_noise").fail(
                name, s.sensor_noise[name], f"not a sensor; sensors are {list(s.sensors)}"
            )
    # soft output limits the initial state already violates
    if spec.type == "mpc" and spec.soft_outputs and s.disturbance.initial_tip:
        try:
            loop = s.loop(model)
        except InputError as exc:
            raise InputError(f"{s.source}: signals: {exc}") from None
        x0 = loop.initial_state(s.disturbance.initial_tip)
        y0 = np.asarray(loop.plant_builder.at(0.0).C) @ x0[: loop.plant_builder.n_states]
        for name, lim in spec.soft_outputs.items():
            v = float(y0[loop.outputs.index(name)])
            if abs(v) > lim:
                dt = top.table("disturbance")
                dt.fail(
                    "initial_tip",
                    s.disturbance.initial_tip,
                    f"the initial {name} = {v:.4g} exceeds the MPC limit {lim:g} of "
                    f"{spec.source} (mpc.soft_outputs.{name}): the initial state is infeasible",
                )
