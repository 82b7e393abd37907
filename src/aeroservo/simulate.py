"""Closed-loop time marching: continuous plant, sampled controller, actuator limits.

The plant is advanced exactly between samples (zero-order hold on commands and disturbances);
at each sample the sensors are read before the new command is applied (see
:mod:`aeroservo.design.plant`), the controller computes a command, the actuator rate limit and
then the saturation are applied, and the controller is told the command actually applied.
An optional computational delay applies each command one sample late.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .design.plant import Limits, SampledPlant
from .errors import InputError, check_int, check_number

__all__ = ["simulate", "SimulationResult", "tip_deflection_state"]


@dataclass
class SimulationResult:
    """Time histories of a closed-loop simulation (SI units).

    Attributes
    ----------
    t : ndarray (n,)
        Sample times [s].
    outputs : dict
        Plant outputs by name (as measured, before sensor noise).
    commands, applied : dict
        Controller commands and the inputs actually applied (after limits), by control name.
    disturbance : dict
        Disturbance inputs by name (e.g. ``"gust"`` [m/s]).
    status : list of dict
        Controller status per sample (MPC: solver status, solve time [s], fallback used).
    limits : Limits
    units : dict
        Signal units.
    speed, density : float
    states : ndarray (n, n_states) or None
        Plant states, if recorded.
    """

    t: np.ndarray
    outputs: dict
    commands: dict
    applied: dict
    disturbance: dict
    status: list
    limits: Limits
    units: dict = field(default_factory=dict)
    speed: float = float("nan")
    density: float = float("nan")
    states: np.ndarray | None = None
    wall_time: float = 0.0

    def signal(self, name: str) -> np.ndarray:
        """Any recorded signal by name."""
        for group in (self.outputs, self.applied, self.disturbance):
            if name in group:
                return group[name]
        known = list(self.outputs) + list(self.applied) + list(self.disturbance)
        raise InputError(f"signal {name!r}: not recorded; known: {known}")

    def saturated_fraction(self) -> dict:
        """Share of samples at which each control sat on its magnitude limit."""
        mag, _ = self.limits.arrays(list(self.applied))
        return {
            c: float(np.mean(np.abs(u) >= mag[i] * (1 - 1e-12)))
            for i, (c, u) in enumerate(self.applied.items())
        }

    def plot(
        self, tip: str | None = None, control: str | None = None, deflection: str | None = None
    ):
        """Tip response, control input with its limits, and surface deflection (Figure)."""
        from matplotlib.figure import Figure

        tip = tip or next(
            (n for n in self.outputs if n.startswith("tip_")), next(iter(self.outputs))
        )
        control = control or next(iter(self.applied))
        deflection = deflection or next(
            (n for n in self.outputs if n.endswith("_deflection")), None
        )
        rows = 3 if deflection else 2
        fig = Figure(layout="constrained", figsize=(7.5, 2.3 * rows))
        axes = fig.subplots(rows, 1, sharex=True)
        axes[0].plot(self.t, self.outputs[tip])
        axes[0].set_ylabel(f"{tip} [{self.units.get(tip, '')}]")
        axes[1].plot(self.t, self.applied[control], label="applied")
        axes[1].plot(self.t, self.commands[control], "--", lw=0.8, label="commanded")
        mag = self.limits.magnitude.get(control)
        if mag is not None:
            for s in (-1, 1):
                axes[1].axhline(s * mag, color="r", lw=0.8, ls=":")
        axes[1].set_ylabel(f"{control} [{self.units.get(control, '')}]")
        axes[1].legend(fontsize=8)
        if deflection:
            axes[2].plot(self.t, np.degrees(self.outputs[deflection]))
            axes[2].set_ylabel(f"{deflection} [deg]")
        axes[-1].set_xlabel("time [s]")
        for ax in axes:
            ax.grid(True, alpha=0.3)
        fig.suptitle(f"closed loop at {self.speed:.4g} m/s")
        return fig


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
    controller : StateFeedback, OutputFeedback, MPCController or None
        Sampled controller (its ``dt`` sets the sample period); None runs the open loop
        (then give ``dt`` through ``plant`` with a controller-free call: use
        :class:`aeroservo.design.OpenLoop`).
    duration : float
        [s].
    x0 : ndarray, optional
        Initial plant state (default zero).
    disturbance : callable, optional
        ``w(t, speed)`` gust velocity [m/s], e.g. :class:`aeroservo.gusts.OneMinusCosine`.
    limits : Limits, optional
        Actuator magnitude and rate limits.
    delay : bool
        One-sample computational delay.
    sensor_noise : dict, optional
        ``{sensor: standard deviation}`` added to the measurements the controller reads
        (seeded).
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
    dt = check_number("controller.dt", controller.dt, unit="s", lo=0.0, lo_open=True)
    duration = check_number("duration", duration, unit="s", lo=0.0, lo_open=True)
    check_int("seed", seed, lo=0)
    limits = limits or Limits()
    controls = list(controller.controls)
    dist = ["gust"] if disturbance is not None else []
    rec = list(plant.output_labels) if outputs is None else list(outputs)
    sensors = list(getattr(controller, "sensors", ()))
    out_names = list(dict.fromkeys(rec + sensors))
    sp = SampledPlant.from_statespace(plant, dt, controls, dist, out_names)
    n_steps = int(round(duration / dt))
    t = np.arange(n_steps + 1) * dt
    speed = float(getattr(plant, "speed", np.nan))
    d = np.zeros((n_steps + 1, len(dist)))
    if disturbance is not None:
        if not np.isfinite(speed):
            raise InputError("simulate: the plant has no 'speed' attribute (needed by gusts)")
        d[:, 0] = disturbance(t, speed)
    x = np.zeros(sp.n_states) if x0 is None else np.asarray(x0, dtype=float).copy()
    if x.shape != (sp.n_states,):
        raise InputError(f"x0: expected {sp.n_states} states, got shape {x.shape}")
    mag, rate = limits.arrays(controls)
    m = len(controls)
    s_idx = [out_names.index(s) for s in sensors]
    noise = np.zeros((n_steps + 1, len(sensors)))
    if sensor_noise:
        rng = np.random.default_rng(seed)
        sd = np.array([sensor_noise.get(s, 0.0) for s in sensors])
        noise = rng.standard_normal(noise.shape) * sd

    Phi, Gu, Gd, C, Du, Dd = sp.Phi, sp.Gu, sp.Gd, sp.C, sp.Du, sp.Dd
    Y = np.empty((n_steps + 1, len(out_names)))
    U = np.empty((n_steps + 1, m))
    Cmd = np.empty((n_steps + 1, m))
    X = np.empty((n_steps + 1, sp.n_states)) if record_states else None
    status: list = []
    h = np.zeros(m)  # command held over the previous interval
    pending = np.zeros(m)
    controller.reset()
    fixed_gain = (
        getattr(controller, "gain", None) if getattr(controller, "needs_state", False) else None
    )
    rate_dt = rate * dt
    t0 = time.perf_counter()
    for k in range(n_steps + 1):
        y = C @ x + Du @ h + Dd @ d[k]
        Y[k] = y
        if X is not None:
            X[k] = x
        if fixed_gain is not None:
            c = -(fixed_gain @ x)
        else:
            ys = y[s_idx] + noise[k]
            c = controller.command(ys, x)
        if delay:
            c, pending = pending, c
        u = np.minimum(np.maximum(c, h - rate_dt), h + rate_dt)
        u = np.minimum(np.maximum(u, -mag), mag)
        if fixed_gain is None:
            controller.update(ys, u)
            st = getattr(controller, "last_status", None)
            if st is not None:
                status.append(st)
        Cmd[k] = c
        U[k] = u
        x = Phi @ x + Gu @ u + Gd @ d[k]
        h = u
    wall = time.perf_counter() - t0
    units = dict(getattr(plant, "signal_units", {}))
    return SimulationResult(
        t=t,
        outputs={n: Y[:, i] for i, n in enumerate(out_names) if n in rec},
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


def tip_deflection_state(builder, tip: float) -> np.ndarray:
    """Initial state: the static shape under a tip load, scaled to a tip deflection ``tip`` [m].

    Rates, lag, gust and servo states are zero. ``builder`` is the plant's
    :class:`~aeroservo.statespace.StateSpaceBuilder` (full model).
    """
    check_number("tip", tip, unit="m")
    if builder.n_modes is not None:
        raise InputError("tip_deflection_state: use the full-model builder of the plant")
    model = builder.model
    f = np.zeros(model.n_dofs)
    f[model.mesh.dof_w[-1]] = 1.0
    q = np.linalg.solve(model.matrices.Ks.toarray(), f)
    x = np.zeros(builder.n_states)
    x[: model.n_dofs] = q * (tip / q[model.mesh.dof_w[-1]])
    return x
