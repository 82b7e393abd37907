"""The march of smooth nonlinear hinges (cubic springs): an error-controlled integrator.

``x' = A x + B u + B_n phi(C_n x)`` is integrated by DOP853 (``rtol`` 1e-10, ``atol`` 1e-12
of the state's scale) over each sample with the command held; the open loop in one call with
the samples as output times. The controller is stepped as in :func:`aeroservo.simulate.simulate`
(the linear law's update with the input applied; a protocol controller's ``command`` then
``update``).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from ...errors import InputError
from ..stepping import _checked

__all__ = ["march_smooth", "RTOL", "DivergedMarch"]

RTOL = 1e-10
"""Relative tolerance of the integrator."""


class DivergedMarch(InputError):
    """The integrator could not go on: the motion diverged (a softening spring beyond its
    stiffness limit)."""


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

    def rhs(_t, xx, g):
        return A @ xx + b_n @ el.correction(c_n @ xx) + g

    t_span = np.arange(n_steps + 1) * dt
    if controller is None:
        sol = solve_ivp(
            rhs, (0.0, t_span[-1]), x, method="DOP853", t_eval=t_span, rtol=RTOL, atol=atol,
            args=(np.zeros(n),),
        )  # fmt: skip
        _check(sol)
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
        sol = solve_ivp(
            rhs, (0.0, dt), x, method="DOP853", rtol=RTOL, atol=atol, args=(Bu @ u,)
        )  # fmt: skip
        _check(sol, k * dt)
        x = sol.y[:, -1]
        X[k + 1] = x
        h = u
    return X, U, Cmd, []


def _check(sol, t0: float = 0.0) -> None:
    if not sol.success or not np.all(np.isfinite(sol.y)):
        t_end = t0 + float(sol.t[-1]) if len(sol.t) else t0
        raise DivergedMarch(
            f"nonlinear march: the motion diverges after t = {t_end:.6g} s (the integrator "
            f"stopped: {sol.message}); a softening spring beyond its stiffness limit?"
        )
