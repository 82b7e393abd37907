"""A flutter-suppression loop: plant and design models of one wing, and controller design.

:class:`ControlLoop` holds, for one wing model and air density,

* the **plant**: the full state-space model (every FE unknown), used for simulation and
  closed-loop stability;
* the **design model**: a modal truncation (``design_modes`` in-vacuo modes, lag states kept
  complete) on which LQG and MPC are designed (LQR too, with its gain mapped back onto the
  plant states);

both with the same analogue low-pass filters on the accelerometers (sensors with a direct
feedthrough), so that a design on the truncated model stays consistent with the plant. It
turns a :class:`~aeroservo.design.spec.ControllerSpec` into a controller at a design speed.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Sequence

import numpy as np

from ..errors import InputError, check_derived_speed, check_int, check_number, show_value
from ..linear.models import tip_deflection_state
from ..linear.state_space import StateSpaceBuilder
from ..linear.tags import carry_tags
from .actuator import actuator_arrays, actuator_labels, actuator_outputs, actuators_of
from .compensator import compensator_from_lti
from .gain_schedule import GainSchedule, schedule
from .hinf import hinf
from .interface import python_law, static_gain
from .model_predictive import mpc
from .output_feedback import lqg
from .plant import OpenLoop, SampledPlant, filter_arrays, state_map, with_sensor_filters
from .spec import ControllerSpec, check_spec_signals
from .state_feedback import Bryson, lqr_controller
from .user_code import DEFAULT_BUDGET

SAMPLED_CACHE = 96
"""Sampled plants kept per :class:`ControlLoop` (about 80 kB each for a 10-element wing)."""

__all__ = ["ControlLoop", "check_spec_signals"]


class ControlLoop:
    """Plant and design models of a wing with named controls and sensors.

    Parameters
    ----------
    model : AeroelasticModel
    density : float
        Air density [kg/m^3].
    controls : sequence of str
        Control inputs, e.g. ``["aileron_hinge_moment"]``.
    sensors : sequence of str
        Measured outputs read by output-feedback controllers.
    outputs : sequence of str
        Further outputs (recorded, weighted or limited); the sensors are always included.
    design_modes : int or None
        In-vacuo modes kept in the design model (None: the full model).
    sensor_filter : float or None
        Cutoff [Hz] of the Butterworth filters on the acceleration sensors (None: no filters).
    filter_order : int
        Order of those filters.
    gust : str
        Gust model of the plant (``"kussner"`` or ``"upwash"``).
    actuator : ActuatorDynamics or dict of ActuatorDynamics, optional
        Actuator dynamics in series with the controls (one for all, or by control name; None:
        ideal), in the plant and in the design models of LQG, H-infinity and MPC
        (:mod:`aeroservo.design.actuator`); the loop's limits then bound its output.
    """

    def __init__(
        self,
        model,
        density: float,
        controls: Sequence[str],
        sensors: Sequence[str],
        outputs: Sequence[str] = (),
        *,
        design_modes: int | None = 8,
        sensor_filter: float | None = 30.0,
        filter_order: int = 2,
        gust: str = "kussner",
        actuator=None,
    ):
        self.model = model
        self.density = check_number("density", density, unit="kg/m^3", lo=0.0, lo_open=True)
        self.controls = list(controls)
        self.sensors = list(sensors)
        if not self.controls:
            raise InputError("controls: give at least one control input")
        self.outputs = list(dict.fromkeys(self.sensors + list(outputs)))
        inputs = self.controls + (["gust"] if "gust" not in self.controls else [])
        self.plant_builder = StateSpaceBuilder(model, self.density, inputs, self.outputs, gust=gust)
        if design_modes is not None:
            design_modes = check_int("design_modes", design_modes, lo=1, hi=model.n_dofs)
        self.design_modes = design_modes
        self.design_builder = (
            StateSpaceBuilder(
                model, self.density, inputs, self.outputs, gust=gust, n_modes=design_modes
            )
            if design_modes is not None
            else self.plant_builder
        )
        units = self.plant_builder.units
        self.filtered = [s for s in self.sensors if units[s] == "m/s^2"]
        if sensor_filter is not None:
            check_number("sensor_filter", sensor_filter, unit="Hz", lo=0.0, lo_open=True)
        self.sensor_filter = sensor_filter if self.filtered else None
        self.filter_order = filter_order
        self.T = state_map(self.plant_builder, self.design_builder)
        self.actuators = actuators_of(actuator, self.controls)
        inputs = self.plant_builder.input_labels
        self._act_columns = [inputs.index(c) for c in self.actuators]
        self._sampled: OrderedDict = OrderedDict()

    @property
    def units(self) -> dict:
        """Signal units by name."""
        return {**self.plant_builder.units, **self._actuator_units}

    def _filter(self, sys):
        """``sys`` with the sensor filters, then the actuators."""
        if self.sensor_filter is not None:
            sys = with_sensor_filters(sys, self.filtered, self.sensor_filter, self.filter_order)
        return self._actuate(sys)

    def _actuate(self, sys):
        """``sys`` with the actuators in series with its controls (states last)."""
        if not self.actuators:
            return sys
        import control

        arrays = actuator_arrays(*(np.asarray(x) for x in control.ssdata(sys)),
                                 self._act_columns, list(self.actuators.values()))  # fmt: skip
        out = control.ss(*arrays, inputs=list(sys.input_labels),
                         outputs=list(sys.output_labels) + actuator_outputs(self.actuators),
                         states=list(sys.state_labels) + self._actuator_states)  # fmt: skip
        carry_tags(sys, out)
        out.signal_units = {**getattr(sys, "signal_units", {}), **self._actuator_units}
        return out

    @property
    def _actuator_units(self) -> dict:
        u = self.plant_builder.units
        units = [x for c in self.actuators for x in (u[c], f"{u[c]}/s")]
        return dict(zip(actuator_outputs(self.actuators), units, strict=True))

    @property
    def _actuator_states(self) -> list[str]:
        return [n for c, a in self.actuators.items() for n in actuator_labels(c, a)]

    def plant(self, speed: float):
        """Full plant at ``speed`` [m/s] (``control.StateSpace``, filters included)."""
        return self._filter(self.plant_builder.at(speed))

    def sampled_plant(
        self, speed: float, dt: float, controls: Sequence[str], outputs: Sequence[str]
    ) -> SampledPlant:
        """The full plant at ``speed`` [m/s] discretized with a zero-order hold of ``dt`` [s]
        (:meth:`SampledPlant.from_statespace` of :meth:`plant`), restricted to ``controls``
        and ``outputs``.

        The last :data:`SAMPLED_CACHE` results are kept: a closed-loop boundary evaluates the
        same grid speeds for every controller designed around this loop (the cases of a trade
        study that differ only in controller weights), and the plant at a speed never changes.
        """
        key = (float(speed), float(dt), tuple(controls), tuple(outputs))
        hit = self._sampled.get(key)
        if hit is not None:
            self._sampled.move_to_end(key)
            return hit
        # the matrices of plant(speed) without its python-control models (the same numbers)
        arrays = self.plant_builder.matrices(speed, balanced=True)
        if self.sensor_filter is not None:
            rows = [self.plant_builder.output_labels.index(s) for s in self.filtered]
            arrays = filter_arrays(*arrays, rows, self.sensor_filter, self.filter_order)
        outs = tuple(self.plant_builder.output_labels)
        if self.actuators:
            acts = list(self.actuators.values())
            arrays = actuator_arrays(*arrays, self._act_columns, acts)
            outs += tuple(actuator_outputs(self.actuators))
        labels = (self.plant_builder.input_labels, outs)
        sp = SampledPlant.from_arrays(arrays, labels, dt, controls, (), outputs)
        self._sampled[key] = sp
        while len(self._sampled) > SAMPLED_CACHE:
            self._sampled.popitem(last=False)
        return sp

    def design(self, speed: float, filtered: bool = True):
        """Design model at ``speed`` [m/s] (truncated, with the actuators; the sensor filters
        too if ``filtered``)."""
        d = self.design_builder.at(speed)
        return self._filter(d) if filtered else self._actuate(d)

    @property
    def n_plant_states(self) -> int:
        """States of the full plant, sensor filters and actuators included."""
        return self.plant_builder.n_states + self.n_filter_states + len(self._actuator_states)

    @property
    def state_labels(self) -> tuple[str, ...]:
        """Names of the full plant's states, then filter states (``<sensor>_filter<i>``),
        then actuator states (``<control>_actuator...``)."""
        names = tuple(self.plant_builder.state_labels)
        if self.sensor_filter is not None:
            k = self.filter_order
            names += tuple(f"{s}_filter{i + 1}" for s in self.filtered for i in range(k))
        return names + tuple(self._actuator_states)

    @property
    def n_filter_states(self) -> int:
        return self.filter_order * len(self.filtered) if self.sensor_filter is not None else 0

    def plant_state_map(self) -> np.ndarray:
        """``x_design = T x_plant`` for the design model without sensor filters (filter
        states ignored; actuator states, last in both, shared)."""
        n_a = len(self._actuator_states)
        T = np.zeros((self.T.shape[0] + n_a, self.n_plant_states))
        T[: self.T.shape[0], : self.T.shape[1]] = self.T
        T[self.T.shape[0] :, self.n_plant_states - n_a :] = np.eye(n_a)
        return T

    def initial_state(self, tip: float) -> np.ndarray:
        """Plant state with the static tip-load shape scaled to a tip deflection ``tip`` [m]."""
        x = tip_deflection_state(self.plant_builder, tip)
        return np.r_[x, np.zeros(self.n_plant_states - len(x))]

    def bryson(self, spec: ControllerSpec) -> Bryson:
        return Bryson(spec.bryson_outputs, spec.bryson_inputs, spec.state_weight)

    def check_spec(self, spec: ControllerSpec) -> None:
        """Every signal of a spec must be a control, a sensor or an output of this loop."""
        check_spec_signals(spec, self.controls, self.sensors, self.outputs)

    def design_controller(
        self,
        spec: ControllerSpec,
        speed: float,
        sample_rate: float,
        flutter_speed: float | None = None,
    ):
        """The controller a spec describes, designed at ``speed`` [m/s].

        Parameters
        ----------
        spec : ControllerSpec
        speed : float
            Design speed [m/s].
        sample_rate : float
            Controller sample rate [Hz].
        flutter_speed : float, optional
            Open-loop flutter speed [m/s], needed by a gain schedule (its speeds are multiples
            of it).

        Returns
        -------
        OpenLoop, StateFeedback, OutputFeedback, GainSchedule, MPCController,
        DiscreteCompensator, StaticGain or PythonLaw
        """
        from .anti_windup import with_anti_windup

        ctrl = self._designed(spec, speed, sample_rate, flutter_speed)
        on = spec.uses_applied_input
        return ctrl if on is None else with_anti_windup(ctrl, on)

    def _designed(self, spec: ControllerSpec, speed: float, sample_rate: float, flutter_speed):
        """The controller of :meth:`design_controller` before its anti-windup is set."""
        self.check_spec(spec)
        rate = check_number("sample_rate", sample_rate, unit="Hz", lo=0.0, lo_open=True)
        if spec.type == "none":
            return OpenLoop(tuple(self.controls), 1.0 / rate)
        if spec.type in ("linear", "gain", "python"):
            try:
                ctrl = brought_controller(spec, self.controls, self.sensors, rate)
                if spec.type == "gain" and (spec.gain or {}).get("states"):
                    from .sampled_loop import plant_states

                    states = plant_states(self.plant(speed))  # its states must be the plant's
                    missing = [s for s in spec.gain["states"] if s not in states]
                    if missing:
                        raise InputError(
                            f"gain.states = {show_value(spec.gain['states'])}: "
                            f"{show_value(missing[:5])} are not states of the plant "
                            f"({len(states)} states, e.g. {states[:4]})"
                        )
                    ctrl.law(states)
                return ctrl
            except InputError as exc:
                raise InputError(f"{spec.source}: {exc}") from None
        if spec.type == "hinf":
            try:
                return hinf(
                    self.design(speed),
                    self.controls,
                    self.sensors,
                    input_scale=spec.bryson_inputs,
                    sensor_scale=spec.sensor_scales,
                    weights=spec.hinf,
                    sample_rate=rate,
                )
            except (InputError, ArithmeticError) as exc:
                raise type(exc)(f"{spec.source}: {exc}") from None
        if spec.type == "mpc":
            return mpc(
                self.design(speed),
                self.controls,
                self.sensors,
                limits=spec.limits,
                process_noise=spec.process_noise,
                sensor_noise=spec.sensor_noise,
                input_noise=spec.input_noise,
                horizon=spec.horizon,
                bryson=self.bryson(spec),
                soft_outputs=spec.soft_outputs or None,
                slack_weight=spec.slack_weight,
                sample_rate=rate,
                solver=spec.solver,
            )

        def one(v: float):
            if spec.type == "lqr":
                return lqr_controller(
                    self.design(v, filtered=False),
                    self.controls,
                    bryson=self.bryson(spec),
                    sample_rate=rate,
                    state_map=self.plant_state_map(),
                )
            return lqg(
                self.design(v),
                self.controls,
                self.sensors,
                process_noise=spec.process_noise,
                sensor_noise=spec.sensor_noise,
                input_noise=spec.input_noise,
                bryson=self.bryson(spec),
                sample_rate=rate,
            )

        if spec.schedule is None:
            return one(speed)
        if flutter_speed is None:
            raise InputError(f"{spec.source}: schedule needs the open-loop flutter speed")
        speeds = [
            check_derived_speed(
                f"{spec.source}: schedule.speed_factors",
                list(spec.schedule),
                f * flutter_speed,
                f"{f:g} x the open-loop flutter speed {flutter_speed:.6g} m/s",
            )  # fmt: skip
            for f in spec.schedule
        ]
        ctrl: GainSchedule = schedule(one, speeds)
        ctrl.design_speed = speed
        return ctrl


def brought_controller(spec: ControllerSpec, controls, sensors, rate: float):
    """The controller of a ``linear``, ``gain`` or ``python`` spec at the loop's sample rate
    ``rate`` [Hz] (a continuous compensator discretised by the spec's method)."""
    import control

    if spec.type == "linear":
        c = spec.linear
        dt = True if c["dt"] is None else c["dt"]
        sys = control.ss(
            c["A"], c["B"], c["C"], c["D"], dt, inputs=c["inputs"], outputs=c["outputs"]
        )
        ctrl = compensator_from_lti(
            sys,
            sample_rate=rate,
            method=c.get("method", "tustin"),
            prewarp=c.get("prewarp"),
            sign=c["sign"],
            source=f"compensator from {c['source']}",
        )
        return ctrl
    if spec.type == "gain":
        g = spec.gain
        return static_gain(
            g["K"],
            g["controls"],
            sensors=g.get("sensors"),
            states=g.get("states"),
            sample_rate=rate,
            sign=g["sign"],
        )
    p = spec.python
    return python_law(
        p["function"],
        controls,
        p.get("sensors") or sensors,
        sample_rate=rate,
        needs_state=p.get("needs_state", False),
        name=p.get("source", "Python law"),
        budget=p.get("budget", DEFAULT_BUDGET),
    )
