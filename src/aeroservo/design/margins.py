"""Loop margins of the sampled loop where the field breaks it (MIL-F-9490D, sec. 3.1.3.6).

The loop of :mod:`aeroservo.design.sampled_loop` (plant, filters, controller, delay) is broken

* **at each plant input** (the actuator command), one channel at a time with the others closed,
  the controller a **black box** from sensors to commands: its estimator keeps predicting with
  the command it computed, only the plant sees the perturbation (the default; the requirement
  is judged here). ``measured_input=True`` models hardware that measures the input applied
  (e.g. the hinge moment) and feeds it to the controller's estimator: then the perturbation
  reaches the estimator too, and the margins are those of that hardware only (a controller
  without an estimator, such as H-infinity, gives the black-box figures: its anti-windup
  compares its command with the limited value software knows, not with a measurement);
* **at each sensor** (the plant output), one at a time with the actuators closed (reported);
* **at all plant inputs at once**: the simultaneous (multiloop) disk margin, independent
  gain-phase variations in every channel (Seiler, Packard & Gahinet, "An introduction to disk
  margins", IEEE Control Systems 40(5), 2020): ``alpha = 1 / max_w mu(S - I/2)``, with the
  structured singular value bounded from above by D-scaling (slycot ``ab13md``), so the
  reported ``alpha`` is a guaranteed (conservative) margin; exact with one input.

Each break point's gain, phase and disk margins come from :mod:`aeroservo.design.margin_channel`.
The sensitivity ``S = (I + L)^-1`` and complementary sensitivity ``T = I - S`` at the plant
input are kept over frequency (largest singular values) with their peaks.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.optimize as so

from ..errors import InputError
from ..result_shape import Result, shell
from .interface import controller_at
from .law import delayed
from .margin_channel import (
    ChannelMargins,
    MarginRequirement,
    channel_margins,
    frequency_response,
)
from .margin_tables import margins_from_state, margins_state, margins_summary, margins_table
from .plant import SampledPlant
from .sampled_loop import LoopBlocks, linear_law, plant_states

__all__ = ["MarginRequirement", "ChannelMargins", "LoopMargins", "loop_margins", "BREAK_POINTS"]

BREAK_POINTS = {
    "black_box": "plant input (actuator command), controller a black box from sensors to commands",
    "measured": "plant input (actuator), the applied input measured and fed to the controller's "
    "estimator",
    "sensors": "plant output (each sensor), actuators closed",
    "multiloop": "all plant inputs at once (simultaneous disk margin), controller a black box",
    "multiloop_outputs": "all plant outputs (sensors) at once (simultaneous disk margin), "
    "actuators closed",
}
"""Where each figure of :class:`LoopMargins` breaks the loop (as written in reports)."""


@dataclass
class LoopMargins(Result):
    """Margins of a sampled loop at one speed (frequencies in Hz, gains in dB, phases in deg).

    A result of the common shape (:mod:`aeroservo.result_shape`; one table row per break
    point, figure ``"margins"``, saved as a ``.npz``).

    Attributes
    ----------
    channels : dict
        ``{control: ChannelMargins}`` at each plant input (loop at a time): the requirement is
        judged on these.
    sensors : dict
        ``{sensor: ChannelMargins}`` at each sensor (empty for state feedback).
    multiloop : dict
        Simultaneous disk margin at all inputs: ``disk_margin``, ``disk_gain_margin_db``,
        ``disk_phase_margin_deg``, ``frequency`` [Hz], ``method``.
    multiloop_outputs : dict
        The same at all sensors at once (empty for state feedback or without sensors).
    sensitivity : dict
        ``omega`` [rad/s], ``S`` and ``T`` (largest singular values at the plant input),
        ``peak_S``, ``peak_T`` and their frequencies [Hz].
    speed, dt : float
        [m/s], [s]
    delay : bool
    requirement : MarginRequirement
    measured_input : bool
        Whether the input break point feeds the applied input to the estimator.
    law : str
        What the controller's linear law is (e.g. an MPC's law without active constraints).
    """

    channels: dict
    speed: float
    dt: float
    delay: bool
    requirement: MarginRequirement = field(default_factory=MarginRequirement)
    sensors: dict = field(default_factory=dict)
    multiloop: dict = field(default_factory=dict)
    sensitivity: dict = field(default_factory=dict, repr=False)
    measured_input: bool = False
    law: str = ""
    multiloop_outputs: dict = field(default_factory=dict)

    FIGURES = {"margins": "plot_margins"}

    table = property(margins_table, doc="One row per break point (:func:`.margins_table`).")

    def summary(self) -> str:
        """The requirement met or missed and every break point's margins, a line each."""
        return margins_summary(self)

    def plot_margins(self, control: str | None = None, title: str | None = None):
        """Nyquist, Bode, S and T of one channel (:func:`aeroservo.plots.plot_loop_margins`)."""
        return shell("plot_loop_margins")(self, control, title)

    def to_state(self) -> dict:
        """Every field as plain data and arrays (for a file)."""
        return margins_state(self)

    @classmethod
    def from_state(cls, state: dict) -> LoopMargins:
        """The margins of :meth:`to_state`."""
        return margins_from_state(cls, state)

    @property
    def break_point(self) -> str:
        """Where :attr:`channels` break the loop."""
        return BREAK_POINTS["measured" if self.measured_input else "black_box"]

    def violations(self) -> list[str]:
        """What the loop misses of :attr:`requirement` at the break points it names (empty:
        it meets it); a sensor's figures are prefixed ``sensor``."""
        req = self.requirement
        out = []
        if "inputs" in req.at:
            out += [v for ch in self.channels.values() for v in ch.violations(req)]
        if "sensors" in req.at:  # loop_margins breaks at every sensor when they are judged
            out += [f"sensor {v}" for ch in self.sensors.values() for v in ch.violations(req)]
        disk = self.multiloop.get("disk_margin")
        alpha = req.disk_alpha
        if alpha is not None and not out and disk is not None and disk < alpha:
            out.append(f"simultaneous disk margin {disk:.3g} < {alpha}")
        if "multiloop" in req.at:
            for where, multi in (("inputs", self.multiloop), ("outputs", self.multiloop_outputs)):
                out += _multiloop_violations(where, multi, req)
        return out

    @property
    def meets(self) -> bool:
        """Whether every input channel meets :attr:`requirement`."""
        return not self.violations()

    def to_dict(self) -> dict:
        """JSON-ready: every figure with the break point it belongs to."""
        r = self.requirement

        def fin(x):
            return None if x is None or not np.isfinite(x) else float(x)

        sens = self.sensitivity
        return {
            "speed": self.speed,
            "delay": self.delay,
            "law": self.law,
            "requirement": {
                "gain_db": r.gain_db,
                "phase_deg": r.phase_deg,
                "disk_alpha": r.disk_alpha,
                "delay_ms": r.delay_ms,
                "at": list(r.at),
            },
            "meets": self.meets,
            "violations": self.violations(),
            "break_point": self.break_point,
            "measured_input": self.measured_input,
            "channels": {c: m.to_dict() for c, m in self.channels.items()},
            "sensors_break_point": BREAK_POINTS["sensors"],
            "sensors": {s: m.to_dict() for s, m in self.sensors.items()},
            "multiloop_break_point": BREAK_POINTS["multiloop"],
            "multiloop": {
                k: (fin(v) if not isinstance(v, str) else v) for k, v in self.multiloop.items()
            },
            "multiloop_outputs_break_point": BREAK_POINTS["multiloop_outputs"],
            "multiloop_outputs": {
                k: (fin(v) if not isinstance(v, str) else v)
                for k, v in self.multiloop_outputs.items()
            },
            "peak_sensitivity": fin(sens.get("peak_S")),
            "peak_sensitivity_frequency": fin(sens.get("peak_S_frequency")),
            "peak_complementary_sensitivity": fin(sens.get("peak_T")),
            "peak_complementary_sensitivity_frequency": fin(sens.get("peak_T_frequency")),
        }


def _multiloop_violations(where: str, multi: dict, req: MarginRequirement) -> list[str]:
    """A simultaneous disk margin against the requirement: ``disk_alpha``, or the gain and
    phase it must cover."""
    disk = multi.get("disk_margin")
    if disk is None:
        return []
    if req.disk_alpha is not None:
        if where == "inputs":  # judged above, as before
            return []
        return (
            []
            if disk >= req.disk_alpha
            else [f"all {where} at once: disk {disk:.3g} < {req.disk_alpha}"]
        )
    gm, pm = multi.get("disk_gain_margin_db", 0.0), multi.get("disk_phase_margin_deg", 0.0)
    if gm >= req.gain_db and pm >= req.phase_deg:
        return []
    return [
        f"all {where} at once: the disk margin {disk:.3g} covers +-{gm:.3g} dB and +-{pm:.3g} "
        f"deg, less than {req.gain_db:g} dB, {req.phase_deg:g} deg"
    ]


MU_TOL = 1e-5
"""Relative widening of the D-scaling upper bound of mu (its solver's accuracy)."""


def _disk(alpha: float) -> tuple[float, float]:
    """Simultaneous gain [dB] and phase [deg] variations of a balanced disk of size alpha."""
    gm = 20 * np.log10((2 + alpha) / (2 - alpha)) if alpha < 2 else np.inf
    return float(gm), float(np.degrees(2 * np.arctan(alpha / 2))) if alpha > 0 else 0.0


def _scaled_bound(M: np.ndarray, sweeps: int = 12) -> np.ndarray:
    """Upper bounds of mu (complex scalar blocks) of a stack of square matrices ``M[t]``: the
    largest singular value of ``D M D^-1`` with ``D`` from Osborne's balancing."""
    m = M.shape[1]
    d = np.ones(M.shape[:2])
    absM = np.abs(M)
    off = 1.0 - np.eye(m)
    for _ in range(sweeps):
        for i in range(m):
            scaled = absM * d[:, :, None] / d[:, None, :] * off
            r = np.sqrt(np.sum(scaled[:, i, :] ** 2, axis=1))
            c = np.sqrt(np.sum(scaled[:, :, i] ** 2, axis=1))
            ok = (r > 0) & (c > 0)
            d[ok, i] *= np.sqrt(c[ok] / r[ok])
    return np.linalg.svd(M * d[:, :, None] / d[:, None, :], compute_uv=False)[:, 0]


def _multiloop(A, B, C, theta: np.ndarray, dt: float, channels: dict) -> tuple[dict, dict]:
    """Simultaneous disk margin at all inputs and the input sensitivities on ``theta``."""
    m = B.shape[1]
    F = frequency_response(A, B, C)
    eye = np.eye(m)

    def S_of(th):
        return np.linalg.inv(eye[None] + F(th))

    S = S_of(theta)
    T = eye[None] - S
    sS = np.linalg.svd(S, compute_uv=False)[:, 0]
    sT = np.linalg.svd(T, compute_uv=False)[:, 0]
    hz = 1.0 / (2 * np.pi * dt)
    sens = {
        "omega": theta / dt,
        "S": sS,
        "T": sT,
        "peak_S": float(sS.max()),
        "peak_S_frequency": float(theta[int(np.argmax(sS))] * hz),
        "peak_T": float(sT.max()),
        "peak_T_frequency": float(theta[int(np.argmax(sT))] * hz),
    }
    stable = bool(np.max(np.abs(np.linalg.eigvals(A + B @ C))) < 1.0)
    if m == 1:
        ch = next(iter(channels.values()))
        alpha, f, method = ch.disk_margin, ch.disk_frequency, "exact (one input)"
    elif not stable:
        alpha, f, method = 0.0, None, "closed loop unstable"
    else:
        from slycot import ab13md

        blocks, kinds = np.ones(m, dtype=int), 2 * np.ones(m, dtype=int)

        def mu(th):
            M = S_of(np.array([th]))[0] - 0.5 * eye
            return float(ab13md(np.asarray(M, dtype=complex), blocks, kinds)[0])

        # mu <= the largest singular value of D M D^-1 for any positive diagonal D (Osborne's
        # balancing gives one close to the best): mu only where that bound can beat the best
        # mu so far, largest bound first (the grid's maximum of mu, few mu evaluations)
        bound = _scaled_bound(S - 0.5 * eye[None])
        peak, i = -np.inf, 0
        for k in np.argsort(-bound):
            if bound[k] <= peak:
                break
            v = mu(theta[k])
            if v > peak:
                peak, i = v, int(k)
        t_peak = theta[i]
        lo, hi = theta[max(i - 1, 0)], theta[min(i + 1, theta.size - 1)]
        if hi > lo:
            res = so.minimize_scalar(
                lambda t: -mu(t), bounds=(lo, hi), method="bounded", options={"xatol": 1e-13}
            )
            if -res.fun > peak:
                peak, t_peak = -res.fun, float(res.x)
        # ab13md's bound is found to about 1e-6 (measured 1.7e-6 below the exact mu on a sharp
        # peak, slycot with numpy 2.4): widened by MU_TOL, the margin stays guaranteed
        alpha, f = float(1.0 / (peak * (1 + MU_TOL))), float(t_peak * hz)
        method = "mu upper bound by D-scaling (slycot ab13md): a guaranteed margin"
    gm, pm = _disk(alpha)
    multi = {
        "disk_margin": alpha,
        "disk_gain_margin_db": gm,
        "disk_phase_margin_deg": pm,
        "frequency": f,
        "method": method,
    }
    return multi, sens


def loop_margins(
    plant,
    controller,
    *,
    delay: bool = False,
    requirement: MarginRequirement | None = None,
    measured_input: bool = False,
    sensors: bool = True,
    sample_rate: float | None = None,
    outputs: bool | None = None,
) -> LoopMargins:
    """Margins of the sampled loop at each plant input, each sensor and all inputs at once.

    Parameters
    ----------
    plant : control.StateSpace
        Continuous plant (filters included) with the controller's controls and sensors.
    controller
        A linear controller (:func:`aeroservo.design.as_controller`; a schedule is evaluated
        at the plant's speed, an MPC by its law without active constraints). A Python law is
        refused.
    delay : bool
        One-sample computational delay.
    requirement : MarginRequirement, optional
        Default MIL-F-9490D (6 dB both ways, 45 deg), judged at the plant inputs.
    measured_input : bool
        False (default): the controller is a black box from sensors to commands; True: the
        applied input is measured and fed to its estimator (see the module docstring).
    sensors : bool
        Also break the loop at each sensor (always when the requirement judges them).
    outputs : bool, optional
        Also the simultaneous disk margin at all sensors at once (mu over frequency: about
        0.7 s for three sensors of the shipped LQG). Default: when the requirement judges
        ``"multiloop"``; scenario reports ask for it.
    sample_rate : float, optional
        [Hz] for a continuous python-control compensator.

    Returns
    -------
    LoopMargins
    """
    from .closed_loop import linear_controller

    speed = float(getattr(plant, "speed", np.nan))
    ctrl = controller_at(linear_controller(controller, "loop_margins", sample_rate), speed)
    law = linear_law(ctrl, plant_states(plant))
    if not law.has_feedback:
        raise InputError("loop_margins: the controller has no feedback (open loop)")
    law = delayed(law) if delay else law
    sp = SampledPlant.from_statespace(plant, law.dt, list(law.controls), (), list(law.sensors))
    blocks = LoopBlocks(sp, law, bool(measured_input))
    A, B, C = blocks.at_inputs()
    channels = {}
    for j, name in enumerate(law.controls):
        others = [i for i in range(len(law.controls)) if i != j]
        Aj = A + B[:, others] @ C[others] if others else A
        channels[name] = channel_margins(Aj, B[:, [j]], C[[j]], name, law.dt)
    req = requirement or MarginRequirement()
    want_outputs = "multiloop" in req.at if outputs is None else bool(outputs)
    sensors = sensors or "sensors" in req.at
    at_sensors, multi_out = {}, {}
    if sensors:
        for j, name in enumerate(law.sensors):
            at_sensors[name] = channel_margins(*blocks.at_sensor(j), name, law.dt)
        if at_sensors and want_outputs:
            th = np.unique(np.concatenate([ch.omega * law.dt for ch in at_sensors.values()]))
            multi_out = _multiloop(*blocks.at_sensors(), th, law.dt, at_sensors)[0]
    theta = np.unique(np.concatenate([ch.omega * law.dt for ch in channels.values()]))
    multi, sens = _multiloop(A, B, C, theta, law.dt, channels)
    return LoopMargins(
        channels,
        speed,
        law.dt,
        bool(delay),
        req,
        sensors=at_sensors,
        multiloop=multi,
        sensitivity=sens,
        measured_input=bool(measured_input),
        law=law.source,
        multiloop_outputs=multi_out,
    )
