"""How to design a flutter-suppression controller (read from a controller file by
:mod:`aeroservo.files.controller_file`): type, Bryson weights, limits, estimator noise, MPC
settings and an optional gain schedule.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from ..errors import InputError
from .hinf import HinfWeights
from .margins import MarginRequirement
from .plant import Limits

__all__ = ["ControllerSpec", "CONTROLLER_TYPES", "check_spec_signals"]


CONTROLLER_TYPES = ("none", "lqr", "lqg", "mpc", "hinf", "linear", "gain", "python")
"""Controller file types: designed here (lqr ... hinf) or brought (linear, gain, python)."""


ANTI_WINDUP_DEFAULTS = {"lqg": True, "hinf": False, "linear": False}
"""Default use of the applied input per type, from the recoverable sets of the shipped loops
(:func:`aeroservo.studies.recovery.recoverable_set`, 9 x 9 grids of tip deflection 1-30 cm x
hinge-moment limit 200-4000 N m at 1.05 and 1.1 V_f, issue 38): the H-infinity compensator's
observer-form anti-windup lost 2-3 of 81 cells and never gained one, so a compensator (built-in
or brought) has it off; the LQG's estimator predicting with the applied input differed by one
cell of 81 either way, so it keeps the consistent model (on). Measured again with the aileron
servo and the one-sample delay (the H-infinity weights retuned for them): H-infinity 30/33 and
29/31 cells recovered on/off, LQG 35/34 and 35/35; the defaults stand. ``anti_windup``
switches it."""


@dataclass(frozen=True)
class ControllerSpec:
    """How to design a controller.

    Attributes
    ----------
    type : str
        ``"none"`` (open loop), ``"lqr"`` (full-state feedback), ``"lqg"`` (Kalman filter on
        the sensors + LQR), ``"mpc"`` (constrained MPC, casadi, Kalman filter) or ``"hinf"``
        (H-infinity mixed sensitivity at the actuator); brought from elsewhere: ``"linear"`` (a
        saved compensator, :attr:`linear`), ``"gain"`` (a static gain, :attr:`gain`) or
        ``"python"`` (a Python law, :attr:`python`).
    name : str
    bryson_outputs, bryson_inputs : dict
        Allowed output and control values (Bryson's rule), in the signals' units; for
        ``"hinf"`` the inputs are the controls' nominal magnitudes.
    sensor_scales : dict
        Nominal sensor magnitudes (``"hinf"``), in the sensors' units.
    hinf : HinfWeights or None
        Mixed-sensitivity weights (``"hinf"``).
    margins : MarginRequirement
        Loop-margin requirement at the actuator the runs check (default MIL-F-9490D).
    state_weight : float
        Small regularizing weight on all states (relative).
    limits : Limits
        Actuator magnitude [signal unit] and rate [signal unit / s] limits, applied in every
        simulation and used by MPC.
    process_noise : dict
        Variance of each disturbance input, e.g. ``{"gust": 1.0}`` [(m/s)^2] (LQG, MPC).
    sensor_noise : dict
        Variance of each sensor [unit^2] (LQG, MPC).
    input_noise : dict
        Loop transfer recovery: fictitious noise variance entering with each control
        [unit^2] (LQG, MPC; :func:`aeroservo.design.output_feedback.kalman_filter`).
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
    linear : dict or None
        A saved compensator (``"linear"``): ``A, B, C, D``, ``dt`` [s] (0 continuous, None
        the loop's), ``inputs`` (sensors), ``outputs`` (commands), ``source``, and how to
        bring it: ``method``, ``prewarp`` [Hz], ``sign``, ``anti_windup`` (bool).
    gain : dict or None
        A static gain ``u = sign K y`` (``"gain"``): ``K``, ``sign``, ``controls`` and
        ``sensors`` or ``states``.
    python : dict or None
        A Python law (``"python"``): ``function`` (the callable ``fn(t, y)``), ``sensors``,
        ``needs_state``, ``source``.
    anti_windup : bool or None
        Whether an LQG, an H-infinity or a brought compensator uses the applied input when
        the limits cut its command (:mod:`aeroservo.design.anti_windup`); None: the measured
        default of its type (:data:`ANTI_WINDUP_DEFAULTS`).
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
    input_noise: dict = field(default_factory=dict)
    horizon: int = 20
    solver: str = "daqp"
    soft_outputs: dict = field(default_factory=dict)
    slack_weight: float = 1e4
    schedule: tuple | None = None
    sensor_scales: dict = field(default_factory=dict)
    hinf: HinfWeights | None = None
    margins: MarginRequirement = field(default_factory=MarginRequirement)
    linear: dict | None = None
    gain: dict | None = None
    python: dict | None = None
    source: str = "<dict>"
    anti_windup: bool | None = None

    @property
    def uses_applied_input(self) -> bool | None:
        """Whether the designed controller uses the applied input (its anti-windup): the
        spec's ``anti_windup``, else the measured default of its type
        (:data:`ANTI_WINDUP_DEFAULTS`); None for a type without the switch."""
        if self.type not in ANTI_WINDUP_DEFAULTS:
            return None
        return ANTI_WINDUP_DEFAULTS[self.type] if self.anti_windup is None else self.anti_windup

    @property
    def signals(self) -> dict:
        """Every signal name the spec refers to, by the key that names it."""
        return {
            "weights.outputs": list(self.bryson_outputs),
            "weights.inputs": list(self.bryson_inputs),
            "weights.sensors": list(self.sensor_scales),
            "limits.magnitude": list(self.limits.magnitude),
            "limits.rate": list(self.limits.rate),
            "estimator.process_noise": list(self.process_noise),
            "estimator.sensor_noise": list(self.sensor_noise),
            "estimator.input_noise": list(self.input_noise),
            "mpc.soft_outputs": list(self.soft_outputs),
            "linear inputs": list((self.linear or {}).get("inputs", [])),
            "linear outputs": list((self.linear or {}).get("outputs", [])),
            "gain.controls": list((self.gain or {}).get("controls", [])),
            "gain.sensors": list((self.gain or {}).get("sensors") or []),
            "python.sensors": list((self.python or {}).get("sensors") or []),
        }


def check_spec_signals(
    spec: ControllerSpec, controls: Sequence[str], sensors: Sequence[str], outputs: Sequence[str]
) -> None:
    """Check a controller spec's signal names against a loop's controls, sensors and outputs.

    Raises
    ------
    InputError
        Naming the spec's file, the key and the signal.
    """
    outputs = list(dict.fromkeys(list(sensors) + list(outputs)))
    allowed = {
        "weights.outputs": outputs,
        "weights.inputs": list(controls),
        "weights.sensors": list(sensors),
        "limits.magnitude": list(controls),
        "limits.rate": list(controls),
        "estimator.process_noise": ["gust"],
        "estimator.sensor_noise": list(sensors),
        "estimator.input_noise": list(controls),
        "mpc.soft_outputs": outputs,
        "linear inputs": outputs,
        "linear outputs": list(controls),
        "gain.controls": list(controls),
        "gain.sensors": outputs,
        "python.sensors": outputs,
    }
    for key, names in spec.signals.items():
        for n in names:
            if n not in allowed[key]:
                raise InputError(
                    f"{spec.source}: {key}.{n}: not a signal of this loop; allowed {allowed[key]}"
                )
    if spec.type in ("lqr", "lqg", "mpc", "hinf"):
        missing = [c for c in controls if c not in spec.bryson_inputs]
        if missing:
            raise InputError(f"{spec.source}: weights.inputs: give an allowed value for {missing}")
    if spec.type == "hinf":
        missing = [s for s in sensors if s not in spec.sensor_scales]
        if missing:
            raise InputError(
                f"{spec.source}: weights.sensors: give a nominal magnitude for {missing}"
            )

    if spec.type in ("lqg", "mpc"):
        missing = [s for s in sensors if s not in spec.sensor_noise]
        if missing:
            raise InputError(
                f"{spec.source}: estimator.sensor_noise: give a variance for {missing}"
            )
