"""Closed-loop LQR benchmark; every figure is a ratio to a baseline measured in the same run.

Goland wing with the illustrative aileron, 10 elements, 1.225 kg/m^3, 1.1 x its open-loop flutter
speed, 1 kHz, hinge-moment limits 2000 N m and 2e5 N m/s, initial state: the static shape with a
0.2 m tip deflection (enough for the limits to be hit).

10 s of closed-loop LQR on the full plant with ``aeroservo.simulate.simulate``: wall time of
   the whole call, target < 0.2 s. Baseline: the same loop with ``scipy.integrate.solve_ivp``
   (RK45, rtol 1e-6, atol 1e-9) on ``x' = A x + B u`` over each 1 ms interval, the command held,
   computed from the state at the start of the interval, rate limited then saturated. A whole
   run takes minutes, so solve_ivp is timed on windows (the first 50 intervals, then 20 from
   the simulator's state at t = 0.25, 0.5, 0.75, 1, 2, ..., 9 s) and its cost per interval
   extrapolated piecewise-constant (``--full-ivp`` runs it all: measured once at 189 s against
   146 s estimated). Sanity check: largest difference between the trajectories over the windows,
   and against DOP853 at rtol 1e-11 over the first intervals (the simulator's own error).

The MPC benchmark is ``bench_mpc.py``; the case is in ``_control_case.py``.

Run: ``make bench`` (or ``python bench/bench_control.py``). Medians of repeated runs.
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np
from _control_case import CONTROL, DT, TIP, build
from scipy.integrate import solve_ivp

from aeroservo.design.plant import select
from aeroservo.simulate import simulate

# ---------------------------------------------------------------------------------------------
# LQR: simulate versus solve_ivp


def ivp_window(A, B, gain, mag, rate, x, h, n, method="RK45", rtol=1e-6, atol=1e-9):
    """``n`` sample intervals of the sampled loop with solve_ivp: states at their ends, commands."""
    xs, us = [], []
    for _ in range(n):
        c = -(gain @ x)
        u = np.clip(np.clip(c, h - rate * DT, h + rate * DT), -mag, mag)
        bu = B @ u
        sol = solve_ivp(
            lambda t, z, bu=bu: A @ z + bu, (0.0, DT), x, method=method, rtol=rtol, atol=atol
        )
        x, h = sol.y[:, -1], u
        xs.append(x)
        us.append(u)
    return np.array(xs), np.array(us)


def bench_lqr(s: dict, repeats: int, full_ivp: bool) -> None:
    plant, ctrl, limits, x0 = s["plant"], s["lqr"], s["limits"], s["x0"]

    def run(**kw):
        return simulate(plant, ctrl, duration=10.0, x0=x0, limits=limits, **kw)

    run()  # warm-up
    calls, loops = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        r = run()
        calls.append(time.perf_counter() - t0)
        loops.append(r.wall_time)
    t_sim = statistics.median(calls)
    ref = run(record_states=True)
    X, Uref = ref.states, ref.applied[CONTROL]
    u_peak = np.max(np.abs(Uref))
    on_limit = ref.saturated_fraction[CONTROL]
    rate_lim = np.mean(np.abs(np.diff(Uref)) >= 2e5 * DT * (1 - 1e-9))

    A, B, _, _ = select(plant, [CONTROL], [])
    _, _, c_tip, _ = select(plant, [CONTROL], ["tip_disp"])
    gain = ctrl.gain
    mag, rate = limits.arrays([CONTROL])
    n_total = X.shape[0] - 1
    if full_ivp:
        windows = [(0, n_total, n_total)]  # (first sample, intervals run, intervals represented)
    else:
        starts = [0, 250, 500, 750, *range(1000, n_total, 1000)]
        spans = np.diff([*starts, n_total])
        windows = [
            (k, 50 if k == 0 else 20, int(span)) for k, span in zip(starts, spans, strict=True)
        ]
    t_ivp = 0.0
    dx = du = dtip = 0.0
    for k0, n, span in windows:
        h = Uref[k0 - 1 : k0] if k0 else np.zeros(1)
        t0 = time.perf_counter()
        xs, us = ivp_window(A, B, gain, mag, rate, X[k0].copy(), h, n)
        t_ivp += (time.perf_counter() - t0) * span / n
        dx = max(dx, np.max(np.abs(xs - X[k0 + 1 : k0 + n + 1])) / np.max(np.abs(X)))
        du = max(du, np.max(np.abs(us[:, 0] - Uref[k0 : k0 + n])) / u_peak)
        dtip = max(dtip, np.max(np.abs(c_tip @ (xs - X[k0 + 1 : k0 + n + 1]).T)))
    # the same first intervals with a tight integrator: what is left is the simulator's error
    xs, _ = ivp_window(A, B, gain, mag, rate, X[0].copy(), np.zeros(1), 10, "DOP853", 1e-11, 1e-14)
    dx_tight = np.max(np.abs(xs - X[1:11])) / np.max(np.abs(X))
    how = "whole run" if full_ivp else f"{sum(w[1] for w in windows)} intervals, extrapolated"
    print(
        f"  LQR, 10 s ({plant.nstates} states): {on_limit:.1%} of samples saturated, "
        f"{rate_lim:.1%} rate-limited"
    )
    print(
        f"    simulate {t_sim * 1e3:6.1f} ms per call (target < 200 ms; time marching "
        f"{statistics.median(loops) * 1e3:.1f} ms) = 1/{t_ivp / t_sim:.0f} x solve_ivp"
    )
    print(f"    solve_ivp RK45 interval by interval: {t_ivp:.1f} s ({how})")
    print(
        f"    sanity: max |x_ivp - x_sim| = {dx:.1e} of max |x|, |u| {du:.1e} of max |u|, "
        f"tip {dtip * 1e3:.1e} mm (initial {TIP * 1e3:.0f} mm)"
    )
    print(f"            (DOP853 at rtol 1e-11, first 10 intervals: |x| {dx_tight:.1e} of max |x|)")


def main() -> None:
    full_ivp = "--full-ivp" in sys.argv
    print("aeroservo closed-loop LQR benchmark (medians; ratios to baselines of the same run)")
    s = build()
    print(f"  Goland with aileron, 10 elements, 1.1 V_f = {1.1 * s['vf']:.2f} m/s, 1 kHz")
    bench_lqr(s, repeats=7, full_ivp=full_ivp)


if __name__ == "__main__":
    main()
