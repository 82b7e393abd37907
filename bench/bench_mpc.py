"""MPC benchmark; every figure is a ratio to a baseline measured in the same run.

Case: ``_control_case.py`` (Goland with the illustrative aileron, 10 elements, 1.1 V_f, 1 kHz).
MPC (horizon 20, magnitude and rate limits, 8-mode design model with the sensor filters,
Kalman-filter state), 1 s closed loop on the full plant: median and 99th percentile of the QP
solve time per step for each solver of ``aeroservo.design.model_predictive.SOLVERS`` that
works (a solver that hangs on the QPs of the first solver's run is reported and skipped);
target: median < 1 ms. Baseline: the same problem in do-mpc (discrete model, states as
variables, IPOPT) if ``do_mpc`` is importable, else casadi ``Opti`` + IPOPT on the same
condensed QP (``--opti`` forces it), at the estimated states of the first solver's run; IPOPT
is told to scale the objective by 1 / max diag(H) (its tolerances are absolute; the QP's
Hessian is ~1e-8).

Run: ``make bench`` (or ``python bench/bench_mpc.py``). Medians of repeated runs; on a shared
or loaded machine the 99th percentiles mostly measure scheduler preemption.
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np
from _control_case import CONTROL, DT, SENSORS, build, quiet_stdout

from aeroservo.design import (
    SampledPlant,
    bryson_weights,
    mpc,
)
from aeroservo.design.model_predictive import SOLVERS
from aeroservo.design.riccati import solve_dare
from aeroservo.simulate import simulate


class Recorder:
    """Wraps an MPC controller and records its state estimate and command at each sample."""

    def __init__(self, inner):
        self.inner = inner
        self.controls, self.sensors, self.dt = inner.controls, inner.sensors, inner.dt
        self.needs_state = False

    def reset(self) -> None:
        self.inner.reset()
        self.xi, self.u = [], []

    def command(self, y, x=None):
        u = self.inner.command(y, x)
        self.xi.append(self.inner.kf.x_post.copy())
        self.u.append(float(np.asarray(u)[0]))
        return u

    def update(self, y, u) -> None:
        self.inner.update(y, u)

    @property
    def last_status(self):
        return self.inner.last_status


def make_mpc(s: dict, solver: str):
    return mpc(
        s["design_f"],
        [CONTROL],
        SENSORS,
        limits=s["limits"],
        process_noise={"gust": 1.0},
        sensor_noise={"tip_le_accel": 10.0, "tip_te_accel": 10.0, "tip_twist": 1e-6},
        bryson=s["bryson"],
        horizon=20,
        solver=solver,
    )


def probe(ctrl, samples) -> str | None:
    """None unless the solver hangs on the QPs of these estimated states (cold started).

    Solved through a separate conic, so that a solver that hangs (HiGHS did, before it was
    dropped from the offered solvers) is reported rather than stalling the benchmark.
    """
    import casadi as ca

    opts = {
        k: (dict(v) if isinstance(v, dict) else v) for k, v in SOLVERS[ctrl.solver_name].items()
    }
    H, A = ca.DM(ctrl.H), ca.DM(ctrl.A_con)
    qp = ca.conic("probe", ctrl.solver_name, {"h": H.sparsity(), "a": A.sparsity()}, opts)
    for xi in samples:
        t0 = time.perf_counter()
        qp(
            h=H,
            a=A,
            **dict(zip(("g", "lbx", "ubx", "lba", "uba"), condensed_qp(ctrl, xi), strict=True)),
        )
        took = time.perf_counter() - t0
        if took > 1.0:
            return f"{qp.stats().get('return_status', '?')} after {took:.1f} s on one QP"
    return None


def condensed_qp(ctrl, xi):
    """``(g, lbx, ubx, lba, uba)`` of the controller's QP at an augmented estimate ``[x, h]``."""
    q = ctrl.qp(xi)
    return q["g"], q["lbx"], q["ubx"], q["lba"], q["uba"]


def baseline_opti(ctrl, samples):
    """Solve times and first moves of casadi Opti + IPOPT on the same condensed QPs."""
    import casadi as ca

    nv = ctrl.H.shape[0]
    scale = 1.0 / float(np.max(np.diag(ctrl.H)))  # IPOPT's tolerances are absolute
    opti = ca.Opti()
    U = opti.variable(nv)
    g, lbx, ubx, lba, uba = (opti.parameter(nv) for _ in range(5))
    opti.minimize(0.5 * U.T @ ca.DM(ctrl.H) @ U + g.T @ U)
    opti.subject_to(opti.bounded(lbx, U, ubx))
    opti.subject_to(opti.bounded(lba, ca.DM(ctrl.A_con) @ U, uba))
    opti.solver("ipopt", {"print_time": 0}, {"print_level": 0, "obj_scaling_factor": scale})
    times, moves = [], []
    for xi in samples:
        for par, val in zip((g, lbx, ubx, lba, uba), condensed_qp(ctrl, xi), strict=True):
            opti.set_value(par, val)
        t0 = time.perf_counter()
        sol = opti.solve()
        times.append(time.perf_counter() - t0)
        u = np.atleast_1d(sol.value(U))
        moves.append(u[0])
        opti.set_initial(U, np.r_[u[1:], u[-1]])
    return np.array(times), np.array(moves)


def baseline_do_mpc(s: dict, ctrl, samples):
    """Solve times (``make_step``) and first moves of the same MPC problem in do-mpc.

    Discrete model ``x+ = Phi x + Gu u`` of the sampled design model plus the previous command
    as a state (for the rate limit); stage cost ``x'Q x + 2 x'N u + u'R u`` and terminal cost
    ``x'P x`` with the controller's matrices; magnitude bounds on u and the rate limit as two
    nonlinear (here linear) constraints. IPOPT (do-mpc's solver) with output suppressed and the
    objective scaled as for Opti.
    """
    import casadi as ca

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import do_mpc

    sp = SampledPlant.from_statespace(s["design_f"], DT, [CONTROL], ("gust",), SENSORS)
    Q, R, N = bryson_weights(s["design_f"], [CONTROL], s["bryson"])
    Qd, Rd, Nd = Q * DT, R * DT, N * DT
    rn = np.linalg.solve(Rd, Nd.T)
    P = solve_dare(sp.Phi - sp.Gu @ rn, sp.Gu, Qd - Nd @ rn, Rd)  # as in design.model_predictive
    n, m = sp.Gu.shape
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = do_mpc.model.Model("discrete")
        x = model.set_variable("_x", "x", shape=(n, 1))
        up = model.set_variable("_x", "u_prev", shape=(m, 1))
        u = model.set_variable("_u", "u", shape=(m, 1))
        model.set_rhs("x", ca.DM(sp.Phi) @ x + ca.DM(sp.Gu) @ u)
        model.set_rhs("u_prev", u)
        model.setup()
        dm = do_mpc.controller.MPC(model)
        dm.settings.n_horizon = ctrl.horizon
        dm.settings.t_step = DT
        dm.settings.store_full_solution = False
        dm.settings.nlpsol_opts = {
            "ipopt.print_level": 0,
            "ipopt.sb": "yes",
            "print_time": 0,
            "ipopt.obj_scaling_factor": 1.0 / float(np.max(np.diag(ctrl.H))),
        }
        lterm = x.T @ ca.DM(Qd) @ x + 2 * x.T @ ca.DM(Nd) @ u + u.T @ ca.DM(Rd) @ u
        dm.set_objective(lterm=lterm, mterm=x.T @ ca.DM(P) @ x)
        dm.bounds["lower", "_u", "u"] = -ctrl.u_max
        dm.bounds["upper", "_u", "u"] = ctrl.u_max
        du = ctrl.du_max * DT
        dm.set_nl_cons("rate_up", u - up, ub=du)
        dm.set_nl_cons("rate_down", up - u, ub=du)
        dm.setup()
        times, moves = [], []
        for k, xi in enumerate(samples):
            xk = xi.reshape(-1, 1)
            if k == 0:
                dm.x0 = xk
                dm.set_initial_guess()
            t0 = time.perf_counter()
            u0 = dm.make_step(xk)
            times.append(time.perf_counter() - t0)
            moves.append(float(np.asarray(u0).ravel()[0]))
    return np.array(times), np.array(moves)


def bench_mpc(s: dict, force_opti: bool, n_baseline: int) -> None:
    plant, limits, x0 = s["plant_f"], s["limits"], s["x0_f"]
    print(
        f"  MPC, horizon 20, 1 s closed loop ({plant.nstates}-state plant, "
        f"{s['design_f'].nstates}-state design model): QP solve time per step"
    )
    first = None
    rows = {}
    for name in SOLVERS:
        with quiet_stdout():
            rec = Recorder(make_mpc(s, name))
            why = None
            if first is not None:  # the QPs of the first solver's run, before any closed loop
                why = probe(rec.inner, first.xi[:: max(1, len(first.xi) // 25)])
            if why is None:
                simulate(plant, rec, duration=0.02, x0=x0, limits=limits)  # warm-up
                r = simulate(plant, rec, duration=1.0, x0=x0, limits=limits)
        if why is not None:
            print(f"    {name:8s}: does not work here ({why}); skipped")
            continue
        st = np.array(rec.inner.solve_times)
        u = r.applied[CONTROL]
        rows[name] = st
        rate_lim = np.mean(np.abs(np.diff(u)) >= limits.rate[CONTROL] * DT * (1 - 1e-9))
        print(
            f"    {name:8s} median {np.median(st) * 1e3:6.3f} ms, p99 "
            f"{np.percentile(st, 99) * 1e3:6.2f} ms, max {st.max() * 1e3:5.1f} ms; "
            f"{rec.inner.fallbacks} fallbacks; loop {r.wall_time / len(st) * 1e3:.2f} ms/step"
        )
        print(
            f"             on limits {r.saturated_fraction[CONTROL]:.1%} of samples, "
            f"rate-limited {rate_lim:.1%}"
        )
        if first is None:
            first = rec
    if first is None:
        print("    no conic solver works: no baseline")
        return

    samples = np.array(first.xi[:n_baseline])
    use_do_mpc = not force_opti
    if use_do_mpc:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                import do_mpc  # noqa: F401
        except ImportError:
            print("    do-mpc is not installed: baseline casadi Opti + IPOPT on the condensed QP")
            use_do_mpc = False
    with quiet_stdout():
        if use_do_mpc:
            label = "do-mpc, same problem, states as variables, IPOPT (make_step)"
            t_base, moves = baseline_do_mpc(s, first.inner, samples)
        else:
            label = "casadi Opti, same condensed QP, IPOPT (opti.solve)"
            t_base, moves = baseline_opti(first.inner, samples)
    base = np.median(t_base)
    dmove = np.max(np.abs(moves - np.array(first.u[:n_baseline]))) / limits.magnitude[CONTROL]
    print(f"    baseline: {label}")
    print(
        f"      median {base * 1e3:.1f} ms over the first {len(samples)} samples of the "
        f"{first.inner.solver_name} run (first moves agree to {dmove:.1e} of the limit)"
    )
    for name, st in rows.items():
        ref = np.median(st[: len(samples)])
        print(
            f"      {name:8s} 1/{base / ref:.0f} x baseline (median {ref * 1e3:.3f} ms "
            f"over the first {len(samples)} samples of its own run)"
        )


def main() -> None:
    force_opti = "--opti" in sys.argv
    print("aeroservo MPC benchmark (medians; ratios to baselines of the same run)")
    s = build()
    print(f"  Goland with aileron, 10 elements, 1.1 V_f = {1.1 * s['vf']:.2f} m/s, 1 kHz")
    bench_mpc(s, force_opti=force_opti, n_baseline=40)


if __name__ == "__main__":
    main()
