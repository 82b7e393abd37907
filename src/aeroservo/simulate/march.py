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
from ..design.plant import Limits, SampledPlant
from ..errors import RANGES, InputError, check_int, check_number
from ..linear.models import SAMPLE_RATES, check_continuous
from ..linear.signals import check_names, describe
from .result import SimulationResult

__all__ = ["simulate", "MAX_SAMPLES", "MAX_BYTES"]

MAX_SAMPLES = 10_000_000
"""Most samples of one simulation (duration x sample rate of the controller)."""
MAX_BYTES = 1 << 30
"""Largest memory [bytes] of the recorded arrays of one simulation (1 GiB)."""

_PROTOCOL = ("dt", "controls", "reset", "command", "update")
"""Attributes of a sampled controller."""


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
) -> SimulationResult:
    """Simulate a sampled controller on a continuous linear plant.

    Parameters
    ----------
    plant : control.StateSpace
        Continuous plant with the controller's control inputs (and ``"gust"`` if a gust
        disturbance is given) and the controller's sensors among its outputs.
    controller : StateFeedback, OutputFeedback, GainSchedule, MPCController or OpenLoop
        Sampled controller (its ``dt`` sets the sample period); a gain schedule is evaluated
        at the plant's speed; :class:`aeroservo.design.OpenLoop` runs the open loop.
    duration : float
        [s]; at most :data:`MAX_SAMPLES` samples, and :data:`MAX_BYTES` of recorded arrays.
    x0 : ndarray, optional
        Initial plant state (default zero).
    disturbance : callable, optional
        ``w(t, speed)`` gust velocity [m/s], e.g. :class:`aeroservo.aero.gusts.OneMinusCosine`.
    limits : Limits, optional
        Actuator magnitude and rate limits.
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

    Returns
    -------
    SimulationResult
    """
    check_continuous("plant", plant)
    if hasattr(controller, "at"):  # a gain schedule: the controller at the plant's speed
        controller = controller.at(float(getattr(plant, "speed", np.nan)))
    if not all(hasattr(controller, a) for a in _PROTOCOL):
        raise InputError(
            f"controller = {describe(controller)}: expected a sampled controller (StateFeedback, "
            "OutputFeedback, GainSchedule, MPCController or OpenLoop)"
        )
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
    sensors = list(getattr(controller, "sensors", ()))
    out_names = list(dict.fromkeys(rec + sensors))
    n_steps = _samples(
        duration, dt, plant.nstates, len(rec), len(controls), len(dist), len(sensors), record_states
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
    mag, rate = limits.arrays(controls)
    s_idx = [out_names.index(s) for s in sensors]
    rec_idx = [i for i, n in enumerate(out_names) if n in rec]
    noise = None
    if sensor_noise:
        rng = np.random.default_rng(seed)
        sd = np.array([sensor_noise.get(s, 0.0) for s in sensors])
        noise = rng.standard_normal((n_steps + 1, len(sensors))) * sd

    controller.reset()
    fixed_gain = (
        getattr(controller, "gain", None) if getattr(controller, "needs_state", False) else None
    )
    t0 = time.perf_counter()
    Y, X, U, Cmd, status = _march(
        sp,
        controller,
        fixed_gain,
        x,
        d,
        noise,
        s_idx,
        rec_idx,
        mag,
        rate * dt,
        delay,
        n_steps,
        record_states,
    )
    wall = time.perf_counter() - t0
    units = dict(getattr(plant, "signal_units", {}))
    return SimulationResult(
        t=t,
        outputs={out_names[i]: Y[:, j] for j, i in enumerate(rec_idx)},
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


_BLOCK = 1024
"""Samples marched per block: the working array stays in cache whatever the duration."""


def _rows_times(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """``A @ B.T`` for a long ``A``, by ``np.einsum`` (no BLAS threads started: waking a
    multithreaded BLAS pool costs more than these products, and its spinning workers then slow
    the single-threaded loop that follows)."""
    return np.einsum("ij,kj->ik", A, B)


def _march(
    sp,
    controller,
    fixed_gain,
    x0,
    d,
    noise,
    s_idx,
    rec_idx,
    mag,
    rate_dt,
    delay,
    n_steps,
    record_states,
):
    """The sampled loop: ``(outputs, states or None, applied, commands, status)`` per sample.

    Each row of the working array ``Z`` is ``[x_k, s_k, u_k, d_k]``, where ``s_k`` is what the
    controller reads: ``gain x_k`` (state feedback ``c = -gain x``) or the sensors without
    their disturbance feedthrough and noise (``C_s x_k + Du_s u_{k-1}``). One matrix-vector
    product per sample gives both ``x_{k+1}`` and ``s_{k+1}`` from row k. With one control the
    limits are applied on Python floats (the same comparisons as ``np.maximum``/``np.minimum``,
    without the overhead of ufunc calls on one-element arrays). The recorded outputs are
    computed per block of samples from the states, ``y[k] = C x[k] + Du u[k-1] + Dd d[k]``.
    """
    Phi, Gu, Gd = sp.Phi, sp.Gu, sp.Gd
    n, m = Gu.shape
    nd = Gd.shape[1]
    fixed = fixed_gain is not None
    if fixed:
        S = np.asarray(fixed_gain, dtype=float)
        Su = np.zeros((S.shape[0], m))
        s_add = np.zeros((n_steps + 1, 0))
    else:
        S, Su = sp.C[s_idx], sp.Du[s_idx]
        s_add = _rows_times(d, sp.Dd[s_idx])  # disturbance feedthrough (and noise) per sample
        if noise is not None:
            s_add += noise
    p = S.shape[0]
    iu, idd = n + p, n + p + m
    M = np.zeros((n + p, idd + nd))
    M[:n, :n], M[:n, iu:idd], M[:n, idd:] = Phi, Gu, Gd
    M[n:, :n], M[n:, iu:idd], M[n:, idd:] = S @ Phi, S @ Gu + Su, S @ Gd
    C = sp.C[rec_idx]

    Y = np.empty((n_steps + 1, len(rec_idx)))
    X = np.empty((n_steps + 1, n)) if record_states else None
    U = np.empty((n_steps + 1, m))
    Cmd = np.empty((n_steps + 1, m))
    status: list = []
    Z = np.empty((_BLOCK + 1, idd + nd))
    Z[0, :n] = x0
    Z[0, n:iu] = S @ x0
    head = Z[:, :iu]  # the part of each row the product writes
    dot, array, minimum, maximum = np.dot, np.array, np.minimum, np.maximum
    scalar = m == 1
    if scalar:
        h, pending, mg, r = 0.0, 0.0, float(mag[0]), float(rate_dt[0])
        cmd: list = []
        record = cmd.append
    else:
        h, pending, neg_mag = np.zeros(m), np.zeros(m), -mag
    if not fixed:  # command and update of the controller's protocol
        pending = np.zeros(m)
        command, update, append = controller.command, controller.update, status.append
    for k0 in range(0, n_steps + 1, _BLOCK):
        nb = min(_BLOCK, n_steps + 1 - k0)
        Z[:nb, idd:] = d[k0 : k0 + nb]
        if scalar and fixed:
            for zk, zk1 in zip(Z[:nb], head[1 : nb + 1], strict=True):
                c = -zk.item(n)
                if delay:
                    c, pending = pending, c
                lo, hi = h - r, h + r
                u = lo if c < lo else c
                u = hi if u > hi else u
                u = -mg if u < -mg else u
                u = mg if u > mg else u
                record(c)
                zk[iu] = u
                dot(M, zk, zk1)
                h = u
        elif scalar:
            rows = zip(
                Z[:nb], head[1 : nb + 1], Z[:nb, :n], Z[:nb, n:iu], s_add[k0 : k0 + nb], strict=True
            )
            for k, (zk, zk1, xk, sk, ak) in enumerate(rows, k0):
                ys = sk + ak
                c = command(ys, xk.copy())
                if delay:
                    c, pending = pending, c
                Cmd[k] = c
                c = Cmd.item(k)
                lo, hi = h - r, h + r
                u = lo if c < lo else c
                u = hi if u > hi else u
                u = -mg if u < -mg else u
                u = mg if u > mg else u
                update(ys, array((u,)))
                st = getattr(controller, "last_status", None)
                if st is not None:
                    append(st)
                zk[iu] = u
                dot(M, zk, zk1)
                h = u
        else:
            rows = zip(
                Z[:nb],
                head[1 : nb + 1],
                Z[:nb, :n],
                Z[:nb, n:iu],
                s_add[k0 : k0 + nb],
                Cmd[k0 : k0 + nb],
                strict=True,
            )
            for zk, zk1, xk, sk, ak, ck in rows:
                if fixed:
                    c = -sk
                else:
                    ys = sk + ak
                    c = command(ys, xk.copy())
                if delay:
                    c, pending = pending, c
                u = minimum(maximum(c, h - rate_dt), h + rate_dt)
                u = minimum(maximum(u, neg_mag), mag)
                if not fixed:
                    update(ys, u)
                    st = getattr(controller, "last_status", None)
                    if st is not None:
                        append(st)
                ck[:] = c
                zk[iu:idd] = u
                dot(M, zk, zk1)
                h = u
        Y[k0 : k0 + nb] = _rows_times(Z[:nb, :n], C)
        if X is not None:
            X[k0 : k0 + nb] = Z[:nb, :n]
        U[k0 : k0 + nb] = Z[:nb, iu:idd]
        Z[0, :iu] = Z[nb, :iu]
    if scalar and fixed:
        Cmd[:, 0] = cmd
    Y[1:] += _rows_times(U[:-1], sp.Du[rec_idx])
    Y += _rows_times(d, sp.Dd[rec_idx])
    return Y, X, U, Cmd, status
