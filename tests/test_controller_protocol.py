"""The declared controller protocol (issue 39, item 2).

(a) Every controller type the package builds has the attributes of its protocol
    (:class:`~aeroservo.design.Controller`, a linear one those of
    :class:`~aeroservo.design.LinearController`, a gain schedule those of
    :class:`~aeroservo.design.ScheduledController`), is accepted by ``as_controller`` as it is,
    and is ready to use once built: ``command`` works before ``reset`` (a static gain on states
    before ``law``, a Python law at t = 0).
(b) ``static_gain`` returns one type, whose law is the one it had as two types.
(c) No module of ``aeroservo.design`` is shadowed by a function of the same name, and no public
    function is named like a python-control function unless it returns what that one returns
    (``lqr``, a deprecated alias of ``lqr_controller``, warns).
(d) The top level exports ``as_controller`` and the protocol classes.

A two-state plant designed on at 100 Hz: milliseconds per design.
"""

from __future__ import annotations

import importlib
import pkgutil
import types
import warnings

import control
import numpy as np
import pytest

import aeroservo as aes
from aeroservo import design
from aeroservo.design import (
    Controller,
    GainSchedule,
    Limits,
    LinearController,
    OpenLoop,
    PythonLaw,
    ScheduledController,
    StaticGain,
    as_controller,
    compensator_from_lti,
    lqg,
    lqr_controller,
    mpc,
    python_law,
    schedule,
    static_gain,
)
from aeroservo.design.hinf import HinfWeights, hinf

RATE = 100.0  # [Hz]
SENSORS = ("y1", "y2")
STATES = ("q", "qd")
CONTROLS = ("u",)
NOISE = {"process_noise": {"gust": 1.0}, "sensor_noise": {"y1": 1e-4, "y2": 1e-4}}
WEIGHTS = {"Q": np.eye(2), "R": np.eye(1), "sample_rate": RATE}


def plant(stiffness: float = -4.0):
    """An unstable two-state plant (``q'' = 4 q + ...``) with a control and a gust input."""
    A = np.array([[0.0, 1.0], [-stiffness, -0.2]])
    B = np.array([[0.0, 0.5], [1.0, 0.3]])
    return control.ss(
        A, B, np.eye(2), np.zeros((2, 2)), inputs=["u", "gust"], outputs=list(SENSORS),
        states=list(STATES),
    )  # fmt: skip


def build(kind: str):
    """A controller of each type the package builds."""
    sys = plant()
    if kind == "StateFeedback":
        return lqr_controller(sys, CONTROLS, **WEIGHTS)
    if kind == "OutputFeedback":
        return lqg(sys, CONTROLS, SENSORS, **NOISE, **WEIGHTS)
    if kind == "MPCController":
        limits = Limits({"u": 10.0}, {"u": 1e3})
        return mpc(sys, CONTROLS, SENSORS, limits=limits, horizon=5, **NOISE, **WEIGHTS)
    if kind == "H-infinity":
        weights = HinfWeights(order=3, bandwidth=1.0, roll_off=10.0)
        scales = {"input_scale": {"u": 1.0}, "sensor_scale": {"y1": 1.0, "y2": 1.0}}
        return hinf(sys, CONTROLS, SENSORS, weights=weights, sample_rate=RATE, **scales)
    if kind == "DiscreteCompensator":
        comp = control.ss([[0.5]], [[1.0, 0.0]], [[-2.0]], [[-1.0, 0.0]], 1 / RATE,
                          inputs=list(SENSORS), outputs=list(CONTROLS))  # fmt: skip
        return compensator_from_lti(comp, sample_rate=RATE)
    if kind == "StaticGain-sensors":
        return static_gain([[1.0, 2.0]], CONTROLS, sensors=SENSORS, sample_rate=RATE)
    if kind == "StaticGain-states":
        return static_gain([[1.0, 2.0]], CONTROLS, states=STATES, sample_rate=RATE)
    if kind == "PythonLaw":
        return python_law(lambda t, y: [-3.0 * y[0] - t], CONTROLS, SENSORS, sample_rate=RATE)
    if kind == "OpenLoop":
        return OpenLoop(CONTROLS, 1 / RATE)
    if kind == "GainSchedule":
        return schedule(lambda v: lqr_controller(plant(-v), CONTROLS, **WEIGHTS), [2.0, 4.0])
    raise AssertionError(kind)


LINEAR = ["StateFeedback", "OutputFeedback", "MPCController", "H-infinity",
          "DiscreteCompensator", "StaticGain-sensors", "StaticGain-states", "OpenLoop"]  # fmt: skip
KINDS = [*LINEAR, "PythonLaw", "GainSchedule"]


@pytest.mark.parametrize("kind", KINDS)
def test_every_built_controller_has_its_protocol(kind):
    """Each type is a ``Controller`` (a linear one a ``LinearController``; a schedule a
    ``ScheduledController`` whose controller at a speed is a ``LinearController``), and
    ``as_controller`` returns it as it is."""
    c = build(kind)
    assert as_controller(c, sample_rate=RATE) is c
    if kind == "GainSchedule":
        assert isinstance(c, (GainSchedule, ScheduledController))
        assert isinstance(c, ScheduledController) and not isinstance(c, Controller)
        assert isinstance(c.at(3.0), LinearController)
        return
    assert isinstance(c, Controller) and not isinstance(c, ScheduledController)
    assert isinstance(c, LinearController) == (kind in LINEAR)
    assert c.dt == pytest.approx(1 / RATE) and tuple(c.controls) == CONTROLS
    if kind in LINEAR:
        law = c.law(STATES)
        assert law.controls == CONTROLS and law.dt == c.dt
        assert law.state_feedback == (c.needs_state or kind == "OpenLoop")  # zero on the state


@pytest.mark.parametrize("kind", [k for k in KINDS if k != "GainSchedule"])
def test_built_controllers_are_ready_to_use(kind):
    """``command`` works right after construction (no ``reset``, no ``law``), and gives what
    it gives after ``reset``."""
    c = build(kind)
    y, x = np.array([0.1, -0.2]), np.array([0.1, -0.2])
    first = c.command(y if c.sensors else np.zeros(0), x)
    assert first.shape == (1,) and np.all(np.isfinite(first))
    c.update(y, first)
    c.reset()
    np.testing.assert_array_equal(c.command(y if c.sensors else np.zeros(0), x), first)


def test_a_static_state_gain_commands_before_and_after_its_law():
    """Before ``law``, ``x`` is the named states in order; after ``law(plant.state_labels)``,
    the plant's state (the gain placed on its columns); the commands are the law's."""
    g = static_gain([[1.0, 2.0]], CONTROLS, states=("qd", "q"), sample_rate=RATE, sign=1)
    np.testing.assert_array_equal(g.command(None, np.array([3.0, 5.0])), [13.0])
    law = g.law(("filter", "q", "qd"))
    x = np.array([7.0, 5.0, 3.0])
    np.testing.assert_array_equal(g.command(None, x), [13.0])
    np.testing.assert_array_equal(law.D @ x, [13.0])
    with pytest.raises(aes.InputError, match=r"call law\(plant.state_labels\)"):
        g.command(None, np.ones(5))


def test_a_python_law_commands_before_reset():
    """A Python law built is at t = 0: ``command`` before ``reset`` calls ``fn(0, y)``."""
    seen = []
    law = python_law(lambda t, y: seen.append(t) or [0.0], CONTROLS, SENSORS, sample_rate=RATE)
    law.command(np.zeros(2))
    law.update(np.zeros(2), np.zeros(1))
    law.command(np.zeros(2))
    assert seen == [0.0, pytest.approx(1 / RATE)]
    assert isinstance(law, PythonLaw)


@pytest.mark.parametrize("sign", [-1, 1])
def test_static_gain_is_one_type_with_the_laws_it_had(sign):
    """On sensors: a compensator law without state, ``D = sign K`` (as the
    ``DiscreteCompensator`` it was); on states: a state feedback ``D = sign K`` on the named
    columns (as the ``StateGain`` it was)."""
    K = np.array([[1.5, -2.0]])
    on_y = static_gain(K, CONTROLS, sensors=SENSORS, sample_rate=RATE, sign=sign)
    on_x = static_gain(K, CONTROLS, states=("qd", "q"), sample_rate=RATE, sign=sign)
    assert type(on_y) is StaticGain and type(on_x) is StaticGain
    assert not on_y.needs_state and on_x.needs_state
    a = on_y.law()
    assert (a.kind, a.source, a.sensors, a.applied_input) == (
        "compensator",
        "static output gain",
        SENSORS,
        "anti-windup",
    )
    assert a.A.shape == (0, 0) and a.L.shape == (0, 1)
    np.testing.assert_array_equal(a.D, sign * K)
    b = on_x.law(("q", "z", "qd"))
    assert (b.kind, b.source, b.sensors) == ("state", "static state gain", ())
    np.testing.assert_array_equal(b.D, sign * np.array([[-2.0, 0.0, 1.5]]))
    K[0, 0] = 99.0  # the caller's matrix is copied
    np.testing.assert_array_equal(on_y.law().D, sign * np.array([[1.5, -2.0]]))


def test_design_modules_are_not_shadowed():
    """``import aeroservo.design.<module>`` gives the module for every module of the package:
    no public name of ``aeroservo.design`` is the name of one of its modules."""
    names = [m.name for m in pkgutil.iter_modules(design.__path__)]
    assert {"state_feedback", "output_feedback", "model_predictive", "gain_schedule"} <= set(names)
    assert not set(design.__all__) & set(names)
    for name in names:
        module = importlib.import_module(f"aeroservo.design.{name}")
        assert isinstance(module, types.ModuleType)
        assert getattr(design, name, module) is module


def test_python_control_names_return_what_python_control_returns():
    """The only public name of ``aeroservo.design`` that is also python-control's is ``lqr``,
    the deprecated alias of ``lqr_controller``: it warns, naming the new one, and designs the
    same controller."""
    assert set(design.__all__) & set(dir(control)) == {"lqr"}
    sys = plant()
    with pytest.warns(DeprecationWarning, match="lqr_controller"):
        old = design.lqr(sys, CONTROLS, **WEIGHTS)
    new = lqr_controller(sys, CONTROLS, **WEIGHTS)
    np.testing.assert_array_equal(old.Kd, new.Kd)
    with pytest.warns(DeprecationWarning, match="StaticGain"):
        assert design.StateGain is StaticGain


def test_top_level_exports_the_protocol():
    """``aeroservo.as_controller`` and the protocol classes, imported on first use."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert aes.as_controller is as_controller
        assert aes.Controller is Controller
        assert aes.LinearController is LinearController
        assert aes.ScheduledController is ScheduledController
    assert {"as_controller", "Controller", "LinearController"} <= set(aes.__all__)
