"""Closed-loop time marching: continuous plant, sampled controller, actuator limits.

The plant is advanced exactly between samples (zero-order hold on commands and disturbances);
at each sample the sensors are read before the new command is applied (see
:mod:`aeroservo.design.plant`), the controller computes a command, the actuator rate limit and
then the saturation are applied, and the controller is told the command actually applied.
An optional computational delay applies each command one sample late.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence

import numpy as np

from .._threads import blas_limited
from ..design.interface import as_controller, controller_at
from ..design.law import delayed
from ..design.plant import Limits, SampledPlant
from ..design.protocol import steps_its_law
from ..design.sampled_loop import linear_law, plant_states
from ..design.user_code import law_session
from ..errors import RANGES, InputError, check_int, check_number
from ..linear.models import SAMPLE_RATES, check_continuous
from ..linear.signals import check_names, describe
from .actuator_limits import ActuatorLimits
from .result import SimulationResult, windup_text
from .stepping import march_loop

__all__ = ["simulate", "MAX_SAMPLES", "MAX_BYTES"]

MAX_SAMPLES = 10_000_000
"""Most samples of one simulation (duration x sample rate of the controller)."""
MAX_BYTES = 1 << 30
"""Largest memory [bytes] of the recorded arrays of one simulation (1 GiB)."""


@blas_limited
def simulate(
    plant,
    controller,
    *,
    duration: float,
    x0: np.ndarray | None = None,
    disturbance=None,
    limits: Limits | None = None,
    delay: bool = False,
    sensor_noise: dict | None = None,
    seed: int = 0,
    record_states: bool = False,
    outputs: Sequence[str] | None = None,
    sample_rate: float | None = None,
) -> SimulationResult:
    """Simulate a sampled controller on a continuous linear plant.

    Linear controllers are marched from their law
    (:class:`~aeroservo.design.law.LinearLaw`): the state update uses the input actually
    applied (anti-windup for compensators, the estimator's prediction for LQG); nonlinear ones
    (MPC, a Python law) through their ``command`` and ``update``.

    Parameters
    ----------
    plant : control.StateSpace
        Continuous plant with the controller's control inputs (and ``"gust"`` if a gust
        disturbance is given) and the controller's sensors among its outputs.
    controller
        Any controller :func:`aeroservo.design.as_controller` accepts (its ``dt`` sets the
        sample period); a gain schedule is evaluated at the plant's speed;
        :class:`aeroservo.design.OpenLoop` runs the open loop.
    duration : float
        [s]; at most :data:`MAX_SAMPLES` samples, and :data:`MAX_BYTES` of recorded arrays.
    x0 : ndarray, optional
        Initial plant state (default zero).
    disturbance : callable, optional
        ``w(t, speed)`` gust velocity [m/s], e.g. :class:`aeroservo.aero.gusts.OneMinusCosine`.
    limits : Limits, optional
        Magnitude and rate limits of each control: on its command, or, where the plant has an
        actuator on it (:mod:`aeroservo.design.actuator`), on the actuator's output (position
        and rate, :mod:`aeroservo.simulate.actuator_limits`), the command keeping the
        magnitude limit.
    delay : bool
        One-sample computational delay.
    sensor_noise : dict, optional
        ``{sensor: standard deviation}`` added to the measurements the controller reads
        (seeded); names are outputs of the plant, values finite and >= 0.
    seed : int
        Seed of the sensor noise.
    record_states : bool
        Keep the plant state history.
    outputs : sequence of str, optional
        Outputs to record (default: all).
    sample_rate : float, optional
        [Hz], to discretise a continuous python-control compensator (Tustin).

    Returns
    -------
    SimulationResult
        With the commands computed and the inputs applied; a command far beyond its limit
        is reported by :meth:`SimulationResult.windup` (and a warning).
    """
    check_continuous("plant", plant)
    controller = as_controller(controller, sample_rate=sample_rate)
    # a gain schedule: the controller at the plant's speed
    controller = controller_at(controller, float(getattr(plant, "speed", np.nan)))
    law = None
    if steps_its_law(controller):
        law = linear_law(controller, plant_states(plant))
        law = delayed(law) if delay else law
    lo, hi = SAMPLE_RATES
    dt = check_number("controller.dt", controller.dt, unit="s", lo=1.0 / hi, hi=1.0 / lo)
    duration = check_number("duration", duration, unit="s", lo=0.0, lo_open=True)
    check_int("seed", seed, lo=0)
    for name, flag in (("delay", delay), ("record_states", record_states)):
        if not isinstance(flag, (bool, np.bool_)):
            raise InputError(f"{name} = {describe(flag)}: expected True or False")
    if disturbance is not None and not callable(disturbance):
        raise InputError(f"disturbance = {describe(disturbance)}: expected a callable w(t, speed)")
    if limits is not None and not isinstance(limits, Limits):
        raise InputError(f"limits = {describe(limits)}: expected an aeroservo.design.Limits")
    limits = limits or Limits()
    controls = check_names("controller.controls", controller.controls)
    dist = ["gust"] if disturbance is not None else []
    rec = list(plant.output_labels) if outputs is None else check_names("outputs", outputs)
    sensors = list(law.sensors if law is not None else getattr(controller, "sensors", ()))
    out_names = list(dict.fromkeys(rec + sensors))
    n_law = 0 if law is None else 2 * law.n_states + len(controls)
    n_steps = _samples(
        duration,
        dt,
        plant.nstates,
        len(rec),
        len(controls) + n_law,
        len(dist),
        len(sensors),
        record_states,
    )
    _check_noise(sensor_noise, plant.output_labels)
    sp = SampledPlant.from_statespace(plant, dt, controls, dist, out_names)
    t = np.arange(n_steps + 1) * dt
    speed = float(getattr(plant, "speed", np.nan))
    d = np.zeros((n_steps + 1, len(dist)))
    if disturbance is not None:
        if not np.isfinite(speed):
            raise InputError("simulate: the plant has no 'speed' attribute (needed by gusts)")
        try:
            w = np.asarray(disturbance(t, speed))
        except TypeError as exc:
            raise InputError(
                f"disturbance = {describe(disturbance)}: calling it as w(t, speed) failed ({exc})"
            ) from None
        lo, hi = RANGES["gust_velocity"].lo, RANGES["gust_velocity"].hi
        if (
            w.dtype.kind not in "iuf"
            or w.shape not in ((), t.shape)
            or not np.all(np.isfinite(w))
            or not np.all((w >= lo) & (w <= hi))
        ):
            raise InputError(
                f"disturbance: returned {w.dtype} values of shape {w.shape}; expected finite "
                f"gust velocities in [{lo:g}, {hi:g}] m/s of shape {t.shape}"
            )
        d[:, 0] = w
    x = np.zeros(sp.n_states) if x0 is None else _initial_state(x0, sp.n_states)
    act = None
    bounds = limits.arrays(controls)
    mag, rate, actuated = ActuatorLimits.command_limits(plant, controls, *bounds)
    if actuated:  # the limits bound the actuator outputs
        act = ActuatorLimits(plant, controls, *bounds, dt)
        act = act if act.parts else None
    s_idx = [out_names.index(s) for s in sensors]
    rec_idx = [i for i, n in enumerate(out_names) if n in rec]
    noise = None
    if sensor_noise:
        rng = np.random.default_rng(seed)
        sd = np.array([sensor_noise.get(s, 0.0) for s in sensors])
        noise = rng.standard_normal((n_steps + 1, len(sensors))) * sd

    t0 = time.perf_counter()
    with law_session(controller):  # a Python law's budget (design/user_code)
        controller.reset()
        Y, X, U, Cmd, status = march_loop(
            sp, controller, law, x, d, noise, s_idx, rec_idx, mag, rate * dt, delay, n_steps,
            record_states, act,
        )  # fmt: skip
    wall = time.perf_counter() - t0
    units = dict(getattr(plant, "signal_units", {}))
    recorded = {out_names[i]: Y[:, j] for j, i in enumerate(rec_idx)}
    if act is not None:
        act.recorded_rates(recorded)
    result = SimulationResult(
        t=t,
        outputs=recorded,
        commands={c: Cmd[:, i] for i, c in enumerate(controls)},
        applied={c: U[:, i] for i, c in enumerate(controls)},
        disturbance={n: d[:, i] for i, n in enumerate(dist)},
        status=status,
        limits=limits,
        units=units,
        speed=speed,
        density=float(getattr(plant, "density", np.nan)),
        states=X,
        wall_time=wall,
    )
    wound = result.windup()
    if wound:
        import warnings

        warnings.warn(f"simulate: {windup_text(wound)}", RuntimeWarning, stacklevel=2)
    return result


def _samples(duration, dt, n, n_rec, m, nd, n_sens, record_states) -> int:
    """Number of steps of a run, refused above :data:`MAX_SAMPLES` or :data:`MAX_BYTES`."""
    n_steps = int(round(duration / dt))
    if n_steps < 1:
        raise InputError(f"duration = {duration:g}: shorter than one sample period ({dt:g} s)")
    if n_steps + 1 > MAX_SAMPLES:
        raise InputError(
            f"duration = {duration:g}: {n_steps + 1} samples at {1 / dt:g} Hz, above the limit "
            f"of {MAX_SAMPLES} samples"
        )
    per_sample = 1 + n_rec + (n if record_states else 0) + 2 * m + nd + 2 * n_sens
    need = 8 * (n_steps + 1) * per_sample
    if need > MAX_BYTES:
        raise InputError(
            f"duration = {duration:g}: {n_steps + 1} samples x {per_sample} recorded values "
            f"need {need / 2**30:.3g} GiB, above the limit of {MAX_BYTES / 2**30:g} GiB; "
            "shorten the run or record fewer signals"
        )
    return n_steps


def _check_noise(noise, outputs) -> None:
    if noise is None:
        return
    if not isinstance(noise, Mapping):
        raise InputError(
            f"sensor_noise = {describe(noise)}: expected a mapping of sensor name -> standard "
            "deviation"
        )
    for name, sd in noise.items():
        if name not in outputs:
            raise InputError(
                f"sensor_noise: {describe(name)} is not an output of the plant {list(outputs)}"
            )
        # a standard deviation: the square root of the variance range
        check_number(f"sensor_noise[{name!r}]", sd, lo=0.0, hi=RANGES["variance"].hi ** 0.5)


def _initial_state(x0, n: int) -> np.ndarray:
    try:
        x = np.array(x0)
    except ValueError:  # ragged nesting
        x = np.array(None)
    if x.dtype.kind not in "iuf":
        raise InputError(f"x0 = {describe(x0)}: expected a real array of {n} states")
    if x.shape != (n,):
        raise InputError(f"x0: expected {n} states, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise InputError("x0: has NaN or infinite entries")
    return x.astype(float)
