"""Constrained linear MPC for flutter suppression, solved as a QP with casadi.

At each sample the state of the (reduced) design model is estimated by the Kalman filter of
:mod:`aeroservo.design.output_feedback`, then the condensed quadratic program

``min_U  sum_{k=0}^{N-1} (x_k'Q x_k + 2 x_k'N u_k + u_k'R u_k) + x_N'P x_N + w_s |S|^2``

subject to the hard limits ``|u_k| <= u_max`` and ``|u_k - u_{k-1}| <= du_max dt`` and the soft
output limits ``|z_k| <= z_max + s_k`` (slack ``s_k >= 0``, so the problem is never
infeasible) is solved over the horizon N. P is the discrete Riccati solution (stabilizing
terminal cost). The QP is warm-started from the previous, shifted solution.

Failure handling: if the solver reports anything but success, the controller applies the
**saturated terminal LQR law** ``u = sat(-K_P x)`` (rate and magnitude limits respected),
records ``fallback=True`` with the solver's status for that sample, and carries on.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .._c_stdout import c_stdout_silenced
from .._threads import blas_limited
from ..errors import InputError, check_int, check_number, check_quantity
from .law import LinearLaw
from .output_feedback import KalmanFilter, estimator_law, kalman_filter
from .plant import Limits, SampledPlant, select
from .riccati import solve_dare
from .state_feedback import Bryson, cost_weights

__all__ = ["MPCController", "mpc", "SOLVERS"]

SOLVERS = {
    "qpoases": {"printLevel": "none", "sparse": False, "error_on_fail": False},
    "osqp": {
        "osqp": {"verbose": False, "eps_abs": 1e-7, "eps_rel": 1e-7, "polish": True},
        "warm_start_primal": True,
        "warm_start_dual": True,
        "error_on_fail": False,
    },
    "daqp": {"error_on_fail": False},
}
"""casadi conic solvers offered and their options. ``bench/bench_mpc.py`` measures them on the
Goland-with-aileron MPC (horizon 20, 1 kHz, limits active on 28 % of the samples), called
through casadi's zero-copy buffers: DAQP (dual active set) median 0.05 ms, p99 0.12 ms, the
default; qpOASES (primal active set) 0.06 / 0.17 ms; OSQP (ADMM) 0.46 / 1.2 ms. (Called with
numpy arguments, the conversions alone cost ~0.25 ms per step.) HiGHS was tried and dropped:
its QP solver cycled on this problem (millions of iterations without progress), so a step never
returned."""


@dataclass
class MPCController:
    """Sampled MPC controller (use :func:`mpc` to build one; built with its solver, it is
    ready to use: ``command`` works before ``reset``).

    Attributes
    ----------
    horizon : int
    controls, sensors : tuple of str
    dt : float
    solver_name : str
    solve_times : list of float
        Wall time of each QP solve [s].
    statuses : list of str
        Solver return status of each sample.
    fallbacks : int
        Samples at which the fallback law was applied.
    """

    horizon: int
    controls: tuple
    sensors: tuple
    dt: float
    kf: KalmanFilter
    n_x: int
    H: np.ndarray
    G: np.ndarray
    A_con: np.ndarray
    Tx_out: np.ndarray
    z_max: np.ndarray
    u_max: np.ndarray
    du_max: np.ndarray
    K_fallback: np.ndarray
    solver_name: str
    solver: object = None
    needs_state: bool = False
    is_linear: bool = False
    solve_times: list = field(default_factory=list)
    statuses: list = field(default_factory=list)
    fallbacks: int = 0

    def __post_init__(self) -> None:
        if self.solver is not None:  # built ready to use: the solver's buffers bound
            self.reset()

    def reset(self) -> None:
        self.kf.reset()
        self.solve_times = []
        self.statuses = []
        self.fallbacks = 0
        self.last_status = None
        self._bind()

    def _bind(self) -> None:
        """Bind numpy arrays to the solver's inputs and outputs (casadi's zero-copy buffers:
        converting numpy arguments cost ~40 us each, four times the QP's own solve time).

        Constant inputs (H, A, the magnitude bounds) are set once; per sample only the linear
        term, the rate and soft-output bounds and the warm start change, in place.
        """
        N, m = self.horizon, self.u_max.size
        nu, ns = N * m, self.z_max.size * N
        self._nu, self._ns = nu, ns
        du = np.tile(self.du_max * self.dt, N)
        zm = np.tile(self.z_max, N)
        self._du0 = du[:m].copy()
        self._zm = zm
        values = {
            "h": np.asarray(self.H, dtype=float).ravel(order="F"),
            "a": np.asarray(self.A_con, dtype=float).ravel(order="F"),
            "g": np.zeros(nu + ns),
            "lbx": np.r_[np.tile(-self.u_max, N), np.zeros(ns)],
            "ubx": np.r_[np.tile(self.u_max, N), np.full(ns, np.inf)],
            "lba": np.r_[-du, np.full(ns, -np.inf), -zm],
            "uba": np.r_[du, zm, np.full(ns, np.inf)],
        }
        buf, self._eval = self.solver.buffer()
        self._buf, self._in, self._out = buf, {}, {}
        for k, name in enumerate(self.solver.name_in()):
            arr = values.get(name)
            if arr is None:
                arr = np.zeros(self.solver.sparsity_in(k).nnz())
            self._in[name] = arr
            buf.set_arg(k, memoryview(arr))
        for k, name in enumerate(self.solver.name_out()):
            self._out[name] = np.zeros(self.solver.sparsity_out(k).nnz())
            buf.set_res(k, memoryview(self._out[name]))

    def _fill(self, xi: np.ndarray, a: dict) -> tuple[np.ndarray, np.ndarray]:
        """Write the estimate-dependent terms of the QP at ``xi = [x, h]`` into ``a`` (the
        linear term, the first rate bounds, the soft-output bounds); returns ``(x, h)``."""
        x0, h = xi[: self.n_x], xi[self.n_x :]
        m, nu, ns = self.u_max.size, self._nu, self._ns
        np.dot(self.G, x0, out=a["g"][:nu])
        a["g"][:nu] *= 2.0
        a["lba"][:m] = h - self._du0
        a["uba"][:m] = h + self._du0
        if ns:
            zfree = self.Tx_out @ x0
            np.subtract(self._zm, zfree, out=a["uba"][nu : nu + ns])
            np.subtract(-self._zm, zfree, out=a["lba"][nu + ns :])
        return x0, h

    def qp(self, xi: np.ndarray) -> dict:
        """The QP solved at an augmented estimate ``xi = [x, h]``: ``h, a`` (dense arrays) and
        ``g, lbx, ubx, lba, uba`` (vectors), in the solver's (scaled) cost units."""
        out = {k: self._in[k].copy() for k in ("g", "lbx", "ubx", "lba", "uba")}
        self._fill(xi, out)
        out["h"], out["a"] = np.asarray(self.H), np.asarray(self.A_con)
        return out

    def _solve(self) -> tuple[bool, str]:
        """Solve the bound QP in place; ``(success, solver status)``."""
        if self.solver_name == "osqp":  # OSQP prints "Polishing not needed ..." on C stdout
            with c_stdout_silenced():
                self._eval()
        else:
            self._eval()
        stats = self._buf.stats()
        return bool(stats.get("success", False)), str(stats.get("return_status", "unknown"))

    def command(self, y: np.ndarray, x: np.ndarray | None = None) -> np.ndarray:
        a, o = self._in, self._out
        x0, h = self._fill(self.kf.correct(y), a)
        m, nu = self.u_max.size, self._nu
        t0 = time.perf_counter()
        ok, status = self._solve()
        dt_solve = time.perf_counter() - t0
        U = o["x"]
        if ok and np.all(np.isfinite(U)):
            u0 = U[:m].copy()
            w = a["x0"]  # warm start: the solution shifted by one sample
            w[: nu - m] = U[m:nu]
            w[nu - m : nu] = U[nu - m : nu]
            w[nu:] = U[nu:]
            a["lam_x0"][:] = o["lam_x"]
            a["lam_a0"][:] = o["lam_a"]
            fallback = False
        else:
            u_lqr = -(self.K_fallback @ x0)
            u0 = np.clip(u_lqr, h - self.du_max * self.dt, h + self.du_max * self.dt)
            u0 = np.clip(u0, -self.u_max, self.u_max)
            for name in ("x0", "lam_x0", "lam_a0"):  # cold start next time
                a[name][:] = 0.0
            self.fallbacks += 1
            fallback = True
        self.solve_times.append(dt_solve)
        self.statuses.append(status)
        self.last_status = {"status": status, "solve_time": dt_solve, "fallback": fallback}
        return u0

    def update(self, y: np.ndarray, u: np.ndarray) -> None:
        self.kf.predict(u)

    def law(self, states=()) -> LinearLaw:
        """Its law without active constraints: the LQG whose gain is the first move of the
        unconstrained QP (what the linear analyses of an MPC loop use)."""
        return estimator_law(
            self.unconstrained_gain(),
            self.kf,
            self.controls,
            self.sensors,
            self.dt,
            "MPC without active constraints (its LQG)",
        )

    def unconstrained_gain(self) -> np.ndarray:
        """Gain ``K`` with ``c = -K xi+`` of the MPC without active constraints (its first move
        as a linear function of the estimate: the MPC's loop as an LQG)."""
        nu = self.horizon * self.u_max.size
        m = self.u_max.size
        k0 = 2.0 * np.linalg.solve(self.H[:nu, :nu], self.G)[:m]
        return np.hstack([k0, np.zeros((m, self.kf.Ad.shape[0] - self.n_x))])


def _condensed(Phi, Gu, Q, R, N, P, horizon):
    """Matrices of the condensed QP: J = U'HU + 2 x0'G'U + const (G: (N m, n))."""
    n, m = Gu.shape
    # X_all = [x_0..x_N] = Tx x0 + Tu U
    Tx = np.zeros(((horizon + 1) * n, n))
    Tu = np.zeros(((horizon + 1) * n, horizon * m))
    Tx[:n] = np.eye(n)
    powers = [np.eye(n)]
    for k in range(1, horizon + 1):
        powers.append(Phi @ powers[-1])
        Tx[k * n : (k + 1) * n] = powers[k]
        for j in range(k):
            Tu[k * n : (k + 1) * n, j * m : (j + 1) * m] = powers[k - 1 - j] @ Gu
    Qb = np.zeros(((horizon + 1) * n,) * 2)
    Nb = np.zeros(((horizon + 1) * n, horizon * m))
    for k in range(horizon):
        if k > 0:
            Qb[k * n : (k + 1) * n, k * n : (k + 1) * n] = Q
        Nb[k * n : (k + 1) * n, k * m : (k + 1) * m] = N
    Qb[horizon * n :, horizon * n :] = P
    Rb = np.kron(np.eye(horizon), R)
    H = Tu.T @ Qb @ Tu + Rb + Tu.T @ Nb + Nb.T @ Tu
    G = Tu.T @ Qb @ Tx + Nb.T @ Tx
    return 0.5 * (H + H.T), G, Tx, Tu


@blas_limited
def mpc(
    sys,
    controls: Sequence[str],
    sensors: Sequence[str],
    *,
    limits: Limits,
    process_noise: dict,
    sensor_noise: dict,
    input_noise: dict | None = None,
    horizon: int = 20,
    bryson: Bryson | None = None,
    Q: np.ndarray | None = None,
    R: np.ndarray | None = None,
    soft_outputs: dict | None = None,
    slack_weight: float = 1e4,
    sample_rate: float = 1000.0,
    solver: str = "daqp",
) -> MPCController:
    """Build a constrained MPC controller on a (reduced) continuous design model.

    Parameters
    ----------
    sys : control.StateSpace
        Continuous design model (e.g. a modal truncation, with the same sensor filters as the
        plant) with the controls, the disturbance inputs of ``process_noise`` and the sensors.
    controls, sensors : sequence of str
    limits : Limits
        Hard magnitude and rate limits of every control (both are required).
    process_noise, sensor_noise : dict
        Kalman filter noise variances (see :func:`aeroservo.design.output_feedback.kalman_filter`).
    input_noise : dict, optional
        Loop transfer recovery at the plant input
        (:func:`aeroservo.design.output_feedback.kalman_filter`).
    horizon : int
        Prediction horizon N [samples].
    bryson, Q, R :
        Stage cost weights (see :func:`aeroservo.design.state_feedback.lqr_controller`).
    soft_outputs : dict, optional
        ``{output name: limit}`` soft limits on outputs without direct feedthrough.
    slack_weight : float
        Weight of the squared slack, relative to the largest diagonal entry of the Hessian.
    sample_rate : float
        [Hz].
    solver : str
        casadi conic solver: ``"daqp"`` (default: dual active set, warm started, fastest
        measured), ``"qpoases"`` or ``"osqp"`` (see :data:`SOLVERS`).

    Returns
    -------
    MPCController
    """
    import casadi as ca

    horizon = check_int("horizon", horizon, lo=1, hi=500)
    rate = check_quantity("sample_rate", sample_rate, "sample_rate")
    check_number("slack_weight", slack_weight, lo=0.0, lo_open=True)
    if solver not in SOLVERS:
        raise InputError(f"solver = {solver!r}: choose one of {sorted(SOLVERS)}")
    dt = 1.0 / rate
    u_max, du_max = limits.arrays(controls)
    if not (np.all(np.isfinite(u_max)) and np.all(np.isfinite(du_max))):
        raise InputError("mpc: limits must give a magnitude and a rate limit for every control")
    A, B, _, _ = select(sys, controls, [])
    n, m = B.shape
    Q, R, Ncross = cost_weights(sys, controls, Q, R, bryson, "mpc")
    sp = SampledPlant.from_statespace(sys, dt, controls, tuple(process_noise), list(sensors))
    kf = kalman_filter(sp, sensors, process_noise, sensor_noise, input_noise)
    Qd, Rd, Nd = Q * dt, R * dt, Ncross * dt
    # terminal cost: DARE with the cross term removed by a change of input
    Rinv_Nt = np.linalg.solve(Rd, Nd.T)
    P = solve_dare(sp.Phi - sp.Gu @ Rinv_Nt, sp.Gu, Qd - Nd @ Rinv_Nt, Rd)
    K_fb = np.linalg.solve(Rd + sp.Gu.T @ P @ sp.Gu, sp.Gu.T @ P @ sp.Phi + Nd.T)
    H, G, Tx, Tu = _condensed(sp.Phi, sp.Gu, Qd, Rd, Nd, P, horizon)

    names = list(soft_outputs or {})
    _, _, Cz, Dz = select(sys, controls, names)
    if names and np.any(Dz != 0):
        raise InputError(
            f"soft_outputs: {names} must not have a direct feedthrough from the controls"
        )
    z_max = np.array(
        [check_number(f"soft_outputs[{k!r}]", soft_outputs[k], lo=0.0, lo_open=True) for k in names]
    )
    p = len(names)
    nu = horizon * m
    ns = horizon * p
    Hs = np.zeros((nu + ns, nu + ns))
    Hs[:nu, :nu] = H
    if ns:
        Hs[nu:, nu:] = slack_weight * np.max(np.diag(H)) * np.eye(ns)
    # rate rows
    Dm = np.eye(nu) - np.eye(nu, k=-m)
    rows = [np.hstack([Dm, np.zeros((nu, ns))])]
    Tx_out = np.zeros((ns, n))
    if ns:
        Czb = np.kron(np.eye(horizon), Cz)
        Tu_out = Czb @ Tu[n:]  # outputs at x_1..x_N
        Tx_out = Czb @ Tx[n:]
        rows.append(np.hstack([Tu_out, -np.eye(ns)]))
        rows.append(np.hstack([Tu_out, np.eye(ns)]))
    A_con = np.vstack(rows)
    # the cost is scaled so that the largest Hessian diagonal is 1 (it is ~1e-8 in SI units,
    # below the absolute tolerances of iterative solvers); the minimizer does not change
    cost_scale = 1.0 / max(float(np.max(np.diag(Hs))), 1e-300)
    H_full = 2.0 * cost_scale * Hs
    G = cost_scale * G
    with c_stdout_silenced():  # qpOASES prints a licence banner on stdout at creation
        conic = ca.conic(
            "aeroservo_mpc",
            solver,
            {"h": ca.DM(H_full).sparsity(), "a": ca.DM(A_con).sparsity()},
            SOLVERS[solver],
        )
    return MPCController(
        horizon=horizon,
        controls=tuple(controls),
        sensors=tuple(sensors),
        dt=dt,
        kf=kf,
        n_x=n,
        H=H_full,
        G=G,
        A_con=A_con,
        Tx_out=Tx_out,
        z_max=z_max,
        u_max=u_max,
        du_max=du_max,
        K_fallback=K_fb,
        solver_name=solver,
        solver=conic,
    )
