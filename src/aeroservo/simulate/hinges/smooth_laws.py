"""The march of smooth nonlinear hinges (cubic springs): an error-controlled integrator.

``x' = A x + B u + B_n phi(C_n x)`` is integrated by DOP853 (``rtol`` 1e-10, ``atol`` 1e-12
of the state's scale) over each sample with the command held; the open loop in one call with
the samples as output times. The controller is stepped as in :func:`aeroservo.simulate.simulate`
(the linear law's update with the input applied; a protocol controller's ``command`` then
``update``).

A diverging motion ends the march (:class:`DivergedMarch`, with the time) instead of running
on: once a rotation exceeds :data:`CAP` times its reference scale (an event of the integrator),
or once the integrator has spent :data:`EVALUATIONS` right-hand sides a sample (plus
:data:`MIN_EVALUATIONS`) with a rotation beyond its reference scale. Without these a hardening
spring above the flutter speed of the mode it hardly stiffens never ends: the motion grows, the
spring's frequency grows with it and the steps shrink (the Conner section with a 100 N m/rad^3
hardening flap at 30 m/s: 2 s of march took 1.8 s, 3 s took 15 s, 4 s did not end in 100 s).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from ...errors import InputError
from ..stepping import _checked

__all__ = ["march_smooth", "RTOL", "DivergedMarch", "CAP", "EVALUATIONS", "reference_scales"]

RTOL = 1e-10
"""Relative tolerance of the integrator."""
CAP = 10.0
"""A rotation beyond this many times its reference scale (:func:`reference_scales`) is a
divergence: the march stops there."""
EVALUATIONS = 200
"""Right-hand sides a sample the integrator may spend on average (a settled cubic limit cycle
at 1 ms takes about 6) ..."""
MIN_EVALUATIONS = 100_000
"""... plus this many; beyond, the march stops: a divergence if a rotation has left its
reference scale, else an error (a law too stiff for the march)."""


class DivergedMarch(InputError):
    """The march could not go on: the motion diverged (a softening spring beyond its stiffness
    limit, or a rotation beyond :data:`CAP` times its reference scale)."""


class _Budget(Exception):
    """The integrator spent its evaluations (internal)."""


def reference_scales(elements, x0_rotations) -> np.ndarray:
    """The reference scale [rad] of each element's rotation: the larger of its initial
    magnitude and its law's own scale (a cubic's ``sqrt(k / |c|)``, where the cubic term
    equals the linear one; a gap's half width and offset)."""
    out = np.abs(np.asarray(x0_rotations, dtype=float)).copy()
    for i, (law, k) in enumerate(zip(elements.laws, elements.stiffness, strict=True)):
        c = getattr(law, "coefficient", None)
        if c:
            out[i] = max(out[i], float(np.sqrt(abs(k) / abs(c))))
        gap = getattr(law, "gap", None)
        if gap:
            out[i] = max(out[i], 0.5 * gap + abs(getattr(law, "offset", 0.0)))
    return out


def march_smooth(nplant, Bu, Cs, Ds, Dns, dt, x, n_steps, controller, law, mag, rate_dt, delay):
    """``(X, U, Cmd, switches)`` of the smooth march (no switches)."""
    A = np.asarray(nplant.plant.A, dtype=float)
    b_n, c_n, el = nplant.b_n, nplant.c_n, nplant.elements
    n, m = Bu.shape
    X = np.empty((n_steps + 1, n))
    U = np.zeros((n_steps + 1, m))
    Cmd = np.zeros((n_steps + 1, m))
    X[0] = x
    atol = 1e-12 * max(float(np.abs(x).max()), 1e-9)
    scale = reference_scales(el, c_n @ x)
    cap = CAP * np.where(scale > 0.0, scale, np.inf)
    budget = EVALUATIONS * n_steps + MIN_EVALUATIONS
    seen = {"n": 0, "x": x}

    def rhs(_t, xx, g):
        seen["n"] += 1
        if seen["n"] > budget:
            seen["x"] = xx
            raise _Budget
        return A @ xx + b_n @ el.correction(c_n @ xx) + g

    def beyond(_t, xx, _g):  # crosses zero when a rotation reaches its cap
        return 1.0 - float(np.max(np.abs(c_n @ xx) / cap))

    beyond.terminal = True
    beyond.direction = -1
    kw = dict(method="DOP853", rtol=RTOL, atol=atol, events=beyond)
    ctx = (el, c_n, scale, budget)
    t_span = np.arange(n_steps + 1) * dt
    if controller is None:
        try:
            sol = solve_ivp(rhs, (0.0, t_span[-1]), x, t_eval=t_span, args=(np.zeros(n),), **kw)
        except _Budget:
            _spent(seen["x"], ctx)
        _check(sol, ctx=ctx)
        X[:] = sol.y.T
        return X, U, Cmd, []
    h, pending = np.zeros(m), np.zeros(m)
    xs = np.zeros(law.n_states) if law is not None else None
    for k in range(n_steps + 1):  # the last pass computes the command at the end only
        ys = x if (law is not None and law.state_feedback) else (
            Cs @ x + Ds @ h + Dns @ el.correction(c_n @ x)
        )  # fmt: skip
        if law is not None:
            c = law.C @ xs + law.D @ ys
        else:
            c = _checked(controller.command(ys, x.copy()), m, controller)
            if delay:
                c, pending = pending, c
        u = np.minimum(np.maximum(c, h - rate_dt), h + rate_dt)
        u = np.minimum(np.maximum(u, -mag), mag)
        if law is not None:
            xs = law.A @ xs + law.B @ ys + law.L @ (u - c)
        else:
            controller.update(ys, u)
        Cmd[k], U[k] = c, u
        if k == n_steps:
            break
        try:
            sol = solve_ivp(rhs, (0.0, dt), x, args=(Bu @ u,), **kw)
        except _Budget:
            _spent(seen["x"], ctx, k * dt)
        _check(sol, k * dt, ctx)
        x = sol.y[:, -1]
        X[k + 1] = x
        h = u
    return X, U, Cmd, []


def _check(sol, t0: float = 0.0, ctx=None) -> None:
    """A DivergedMarch if the integrator stopped (at a cap: the rotation's time and size) or
    returned non-finite states."""
    if sol.status == 1:  # the event: a rotation reached its cap
        el, c_n, scale, _budget = ctx
        xe = sol.y_events[0][0]
        t_end = t0 + float(sol.t_events[0][0])
        i = int(np.argmax(np.abs(c_n @ xe) / scale))
        s = float(abs(c_n[i] @ xe))
        raise DivergedMarch(
            f"nonlinear march: the motion diverges after t = {t_end:.6g} s (the rotation of "
            f"{el.names[i]!r} reached {s:.3g} rad, {CAP:g} x its reference {scale[i]:.3g} rad: "
            f"the march stopped there); {_hint(el)}"
        )
    if not sol.success or not np.all(np.isfinite(sol.y)):
        t_end = t0 + float(sol.t[-1]) if len(sol.t) else t0
        raise DivergedMarch(
            f"nonlinear march: the motion diverges after t = {t_end:.6g} s (the integrator "
            f"stopped: {sol.message}); a softening spring beyond its stiffness limit?"
        )


def _spent(x, ctx, t0: float = 0.0):
    """The error when the integrator spent its evaluations (the state it had reached)."""
    el, c_n, scale, budget = ctx
    ratio = np.abs(c_n @ x) / scale
    i = int(np.argmax(ratio))
    what = (
        f"nonlinear march: the integrator spent {budget} evaluations (in the sample from t = "
        f"{t0:.6g} s; its steps shrink), the rotation of {el.names[i]!r} at "
        f"{float(abs(c_n[i] @ x)):.3g} rad, {float(ratio[i]):.3g} x its reference "
        f"{scale[i]:.3g} rad"
    )
    if ratio[i] > 1.0:
        raise DivergedMarch(f"{what}: the motion diverges; {_hint(el)}")
    raise InputError(f"{what}: a law too stiff for the march; shorten it or soften the law")


def _hint(el) -> str:
    """What makes a smooth law's march diverge."""
    if any(getattr(law, "coefficient", 0.0) < 0.0 for law in el.laws):
        return "a softening spring beyond its stiffness limit?"
    return (
        "a hardening spring does not bound it (above the flutter speed of a mode it hardly "
        "stiffens?)"
    )
