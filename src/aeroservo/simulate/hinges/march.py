"""Time marching with nonlinear hinges (freeplay, bilinear, cubic), open or closed loop.

The plant is the linear model with every spring closed plus the moments of its nonlinear hinges
(:class:`aeroservo.linear.hinge_plant.NonlinearPlant`). The loop is the one of
:func:`aeroservo.simulate.simulate`: a sampled controller (any of the controller interface),
its command held between samples (zero-order hold), the actuator rate limit and saturation,
optionally one sample of delay.

* **Piecewise-linear laws** (freeplay, bilinear): between samples the plant is linear on each
  region of its laws; a sample is one matrix product (the linear march) unless a rotation
  leaves its piece, or its interpolant predicts a graze, in that sample; the sample is then
  marched exactly through each switch, the switch time located by Brent's method on the
  closed-form motion (:mod:`aeroservo.simulate.hinges.regions`).
* **Smooth laws** (cubic): an error-controlled integrator (DOP853, ``rtol`` 1e-10) per sample.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..._threads import blas_limited
from ...design.interface import as_controller, controller_at
from ...design.law import delayed
from ...design.plant import Limits
from ...design.protocol import steps_its_law
from ...design.sampled_loop import linear_law, plant_states
from ...design.user_code import law_session
from ...errors import InputError, check_number
from ...linear.signals import describe
from ..result import SimulationResult
from ..stepping import _checked, _law_matrix
from .exact_motion import leaves
from .regions import Regions

__all__ = ["march_hinges", "HingeSimulation", "MAX_HINGE_SAMPLES"]

MAX_HINGE_SAMPLES = 5_000_000
"""Most samples of one nonlinear march."""


@dataclass
class HingeSimulation(SimulationResult):
    """Time histories of a march with nonlinear hinges (see :class:`SimulationResult`).

    Attributes
    ----------
    rotations, hinge_moments : dict
        Per element: its rotation [rad] and the moment of its law [N m] at the samples.
    switches : ndarray
        Times [s] a rotation crossed an edge of its law (piecewise-linear laws).
    gaps : dict
        Per element: total gap [rad] of its law (None for a cubic).
    method : str
    """

    rotations: dict = field(default_factory=dict)
    hinge_moments: dict = field(default_factory=dict)
    switches: np.ndarray = field(default_factory=lambda: np.zeros(0))
    gaps: dict = field(default_factory=dict)
    method: str = ""


@blas_limited
def march_hinges(
    nplant,
    controller=None,
    *,
    duration: float,
    dt: float = 1e-3,
    x0: np.ndarray | None = None,
    rotation0=None,
    limits: Limits | None = None,
    delay: bool = False,
    sample_rate: float | None = None,
) -> HingeSimulation:
    """March a plant with nonlinear hinges.

    Parameters
    ----------
    nplant : NonlinearPlant
        From :func:`aeroservo.linear.hinge_plant.nonlinear_plant` or ``section_plant``.
    controller : optional
        Any controller :func:`aeroservo.design.as_controller` accepts (its ``dt`` sets the
        sample period); None: the open loop, recorded every ``dt``.
    duration : float
        [s].
    dt : float
        Record step of the open loop [s] (default 1 ms).
    x0 : ndarray, optional
        Initial state (in the plant's states); or
    rotation0 : float or sequence, optional
        Initial rotation [rad] of the elements, the structure at rest
        (:meth:`NonlinearPlant.initial_state`).
    limits, delay, sample_rate
        As :func:`aeroservo.simulate.simulate`.
    """
    from ...linear.hinge_plant import NonlinearPlant

    if not isinstance(nplant, NonlinearPlant):
        raise InputError(f"nplant = {describe(nplant)}: expected a NonlinearPlant")
    plant = nplant.plant
    law = None
    if controller is None:
        controls, sensors = [], []
        dt = check_number("dt", dt, unit="s", lo=1e-6, hi=1.0)
    else:
        controller = controller_at(as_controller(controller, sample_rate=sample_rate), plant.speed)
        if steps_its_law(controller):
            law = linear_law(controller, plant_states(plant))
            law = delayed(law) if delay else law
        dt = check_number("controller.dt", controller.dt, unit="s", lo=1e-6, hi=1.0)
        controls = list(controller.controls)
        sensors = list(law.sensors if law is not None else getattr(controller, "sensors", ()))
    duration = check_number("duration", duration, unit="s", lo=0.0, lo_open=True)
    n_steps = int(round(duration / dt))
    if n_steps > MAX_HINGE_SAMPLES or n_steps < 1:
        raise InputError(
            f"duration = {duration:g} s at {dt:g} s: {n_steps} samples; allowed 1 to "
            f"{MAX_HINGE_SAMPLES}"
        )
    if limits is not None and not isinstance(limits, Limits):
        raise InputError(f"limits = {describe(limits)}: expected an aeroservo.design.Limits")
    limits = limits or Limits()
    labels_in, labels_out = list(plant.input_labels), list(plant.output_labels)
    for c in controls:
        if c not in labels_in:
            raise InputError(f"controller control {c!r}: not an input of the plant {labels_in}")
    for s in sensors:
        if s not in labels_out:
            raise InputError(f"controller sensor {s!r}: not an output of the plant {labels_out}")
    A, B, C, D = (np.asarray(v, dtype=float) for v in (plant.A, plant.B, plant.C, plant.D))
    iu = [labels_in.index(c) for c in controls]
    isn = [labels_out.index(s) for s in sensors]
    Bu = B[:, iu]
    n = A.shape[0]
    if x0 is not None and rotation0 is not None:
        raise InputError("give x0 or rotation0, not both")
    if rotation0 is not None:
        x = nplant.initial_state(rotation0)
    elif x0 is not None:
        x = np.asarray(x0, dtype=float).reshape(-1)
        if x.shape != (n,) or not np.all(np.isfinite(x)):
            raise InputError(f"x0: expected {n} finite numbers, got shape {x.shape}")
    else:
        x = np.zeros(n)
    if not nplant.elements.piecewise_linear:
        from .smooth_laws import march_smooth

        method = "DOP853 per sample (rtol 1e-10)"
        march = march_smooth
    else:
        method = "exact between switches (located by Brent's method)"
        march = _march_piecewise
    mag, rate = limits.arrays(controls)
    t0 = time.perf_counter()
    with law_session(controller):  # a Python law's budget (design/user_code)
        if controller is not None:
            controller.reset()
        X, U, Cmd, switches = march(
            nplant, Bu, C[isn], D[np.ix_(isn, iu)], nplant.d_n[isn], dt, x, n_steps,
            controller, law, mag, rate * dt, delay,
        )  # fmt: skip
    wall = time.perf_counter() - t0
    S = X @ nplant.c_n.T
    phi = nplant.elements.correction(S.T).T
    Y = X @ C.T + phi @ nplant.d_n.T
    Y[1:] += U[:-1] @ D[:, iu].T
    t = np.arange(n_steps + 1) * dt
    el = nplant.elements
    return HingeSimulation(
        t=t,
        outputs={name: Y[:, i] for i, name in enumerate(labels_out)},
        commands={c: Cmd[:, i] for i, c in enumerate(controls)},
        applied={c: U[:, i] for i, c in enumerate(controls)},
        disturbance={},
        status=[],
        limits=limits,
        units=dict(getattr(plant, "signal_units", {})),
        speed=float(plant.speed),
        density=float(getattr(plant, "density", np.nan)),
        states=X,
        wall_time=wall,
        rotations={name: S[:, j] for j, name in enumerate(el.names)},
        hinge_moments=dict(zip(el.names, el.moment(S.T), strict=True)),
        switches=np.asarray(switches),
        gaps={name: getattr(law, "gap", None) for name, law in zip(el.names, el.laws, strict=True)},
        method=method,
    )


def _march_piecewise(nplant, Bu, Cs, Ds, Dns, dt, x, n_steps, controller, law, mag, rate_dt, delay):
    """The sampled loop with region switching: ``(X, U, Cmd, switches)``.

    Row ``z`` of the working vector holds the plant state first: ``[x, u, 1]`` (open loop and
    protocol controllers) or the row of :func:`aeroservo.simulate.stepping._law_matrix` (a
    linear law, with the affine term of the region as its disturbance ``d = 1``).
    """
    reg = Regions(nplant, Bu, Cs, Dns, dt)
    cn2 = np.vstack([nplant.c_n, nplant.c_rate])
    e = nplant.elements.n
    n, m = Bu.shape
    X = np.empty((n_steps + 1, n))
    U = np.zeros((n_steps + 1, m))
    Cmd = np.zeros((n_steps + 1, m))
    switches: list = []
    cache: dict = {}

    def region(r):
        if r not in cache:
            Phi, Gu, g, Cr, er = reg.sampled(r)
            lo, hi = reg.bounds(r)
            tol = 1e-12 * reg.scale
            entry = [None, Cr, er, (lo - tol).tolist(), (hi + tol).tolist()]
            if law is not None:
                from ...design.plant import SampledPlant

                sp = SampledPlant(Phi, Gu, g[:, None], Cr, Ds, er[:, None], dt, (), (), ())
                M, sl, (Cm, Bl, Cl, Dl) = _law_matrix(sp, law, list(range(Cr.shape[0])))
                a = np.zeros(Bl.shape[1]) if law.state_feedback else er
                Dm = np.zeros((Cm.shape[0], m)) if law.state_feedback else Ds
                entry[0] = M[: sl[4].start]
                entry += [Cm, Dm, Bl, Cl, Dl, Bl @ a, Dl @ a, sl]
            else:
                entry[0] = np.hstack([Phi, Gu, g[:, None]])
            cache[r] = entry
        return cache[r]

    v = (cn2 @ x).tolist()
    r = reg.locate(v[:e])
    ent = region(r)
    if law is not None:
        ix, i_s, irb, iq, iu, idd, iab, iad = ent[12]  # the row's layout (every region's)
        z = np.zeros(iad.stop)
        z[ix] = x
        mz = ent[5] @ x
        z[irb], z[iq] = ent[7] @ mz, ent[9] @ mz
        z[idd], z[iab], z[iad] = 1.0, ent[10], ent[11]
    else:
        ix, iu = slice(0, n), slice(n, n + m)
        z = np.zeros(n + m + 1)
        z[ix], z[-1] = x, 1.0
    head = iu.start
    bufs = [z, np.zeros_like(z)]

    def set_tail(ent):  # the region's constants in the tail of both working rows
        for b in bufs:
            if law is not None:
                b[idd], b[iab], b[iad] = 1.0, ent[10], ent[11]
            else:
                b[-1] = 1.0

    set_tail(ent)
    views = [(b, b[:head], b[ix]) for b in bufs]
    h, pending = np.zeros(m), np.zeros(m)
    X[0] = x
    dot = np.dot
    scalar = law is not None and m == 1
    if scalar:
        q0, a0, i0 = iq.start, iad.start, iu.start
        mg, rt, hs = float(mag[0]), float(rate_dt[0]), 0.0
    for k in range(n_steps + 1):  # the last pass computes the command at the end only
        z, _, xz = views[k & 1]
        z1, z1h, x1 = views[(k + 1) & 1]
        if scalar:
            c = z.item(q0) + z.item(a0)
            lo_r, hi_r = hs - rt, hs + rt
            uf = lo_r if c < lo_r else c
            uf = hi_r if uf > hi_r else uf
            uf = -mg if uf < -mg else uf
            uf = mg if uf > mg else uf
            Cmd[k, 0], U[k, 0] = c, uf
            z[i0] = hs = uf
            u = U[k]
        elif m:
            if law is not None:
                c = z[iq] + z[iad]
            else:
                ys = ent[1] @ xz + Ds @ h + ent[2]
                c = _checked(controller.command(ys, xz.copy()), m, controller)
                if delay:
                    c, pending = pending, c
            u = np.minimum(np.maximum(c, h - rate_dt), h + rate_dt)
            u = np.minimum(np.maximum(u, -mag), mag)
            if law is None:
                controller.update(ys, u)
            Cmd[k], U[k] = c, u
            z[iu] = h = u
        else:
            u = h
        if k == n_steps:
            break
        dot(ent[0], z, z1h)
        v1 = dot(cn2, x1).tolist()
        if leaves(v, v1, e, ent[3], ent[4], dt):
            xe, r1 = reg.interval(xz.copy(), r, u, dt, switches, k * dt)
            if r1 != r:
                r, ent = r1, region(r1)
                set_tail(ent)
            x1[:] = xe
            if law is not None:
                mz = ent[5] @ xe + ent[6] @ u
                z1[irb], z1[iq] = ent[7] @ mz, ent[8] @ z1[i_s] + ent[9] @ mz
            v1 = dot(cn2, xe).tolist()
        X[k + 1] = x1
        v = v1
    return X, U, Cmd, switches
