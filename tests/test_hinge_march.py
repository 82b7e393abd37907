"""Independent checks of the time march with nonlinear hinges (freeplay, bilinear, cubic).

Reference case: the freeplay section of Conner, Tang, Dowell & Virgin (1997), J. Fluids Struct.
11, 89-109 (``shared/reference/README.md`` "Freeplay section"; plunge inertia m_t, as in
:func:`aeroservo.system.section.conner_section`), total gap 4.24 deg (0.0740 rad), undamped
unless stated. Gap closed: linear flutter 23.74 m/s (R. T. Jones lag states; reference 23.73).

The references never use the march's own machinery (regions, switch location, sampled
matrices): the Lur'e form ``x' = A x + b_n phi(c_n x)`` is written here from the section's
first-order system (``A = E^-1 (A0 + V A1 + V^2 A2)``, ``b_n = E^-1 [0; e_flap; 0]``) with
the law's moment ``phi(s) = k s - M(s)`` written here too, and integrated by scipy's DOP853
restarted at every edge crossing (terminal events), or marched linearly by ``expm``; energies
are computed from the structural matrices; the linear closed loop by
:func:`aeroservo.simulate.simulate`.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from conftest import ROOT
from scipy.integrate import solve_ivp

import aeroservo as aes
from aeroservo.design import ControlLoop
from aeroservo.design.hinge_loop import loop_hinge_plant
from aeroservo.design.plant import OpenLoop
from aeroservo.errors import InputError
from aeroservo.files import load_controller
from aeroservo.linear.hinge_plant import nonlinear_plant, section_plant
from aeroservo.simulate import simulate
from aeroservo.simulate.hinges.march import march_hinges
from aeroservo.structure.hinge_laws import Bilinear, Cubic, Freeplay
from aeroservo.system import TypicalSection
from aeroservo.system.hinge_elements import NonlinearHinge
from aeroservo.system.section import CONNER, conner_section

RHO = 1.225
GAP = CONNER["gap"]  # rad, total
K_FLAP = CONNER["k_beta"]  # N m/rad per m
U_F = 23.74  # m/s, gap closed, this model (R. T. Jones lag states)
N_Q = 3  # plunge, pitch, flap

REF_RTOL = 1e-12
"""Relative tolerance of the reference integrator (DOP853, atol 1e-15 of the state's scale)."""
TRAJ_TOL = 1e-9
"""Marches through switches against the reference, relative to each signal's peak. The
reference commits about ``REF_RTOL`` per step; over ~2000 steps and ~100 restarts of a
lightly damped system the global error is a few 1e-11 (measured at most 2.6e-11), the march
itself is exact to rounding between switches (switch times located to 1e-15 s): 1e-9."""
SWITCH_TOL = 1e-10
"""Switch times [s]: a rotation error ``REF_RTOL``-sized divided by its rate at the edge
(measured at most 1.1e-12 s)."""


# --- independent ingredients --------------------------------------------------------------
def lure(section, speed):
    """``(A, b_n)`` of the section written from its first-order system (not the plant's)."""
    system = section.system(RHO)
    E = system.E.toarray()
    f = np.zeros(E.shape[0])
    f[N_Q + 2] = 1.0  # the flap moment enters the flap row of M v' = ...
    return system.state_matrix(speed), np.linalg.solve(E, f)


def pieces(gap, offset, inner_ratio, k=K_FLAP):
    """Edges ``(lo, hi)`` and ``phi = a s + c`` on the three pieces below, in, above the band.

    The spring: ``M = k_in (s - offset)`` inside the band, ``k (s - hi) + k_in gap/2`` above,
    ``k (s - lo) - k_in gap/2`` below; ``phi = k s - M``.
    """
    lo, hi = offset - gap / 2, offset + gap / 2
    k_in = inner_ratio * k
    return (lo, hi), [
        (0.0, k * lo + k_in * gap / 2),
        (k - k_in, k_in * offset),
        (0.0, k * hi - k_in * gap / 2),
    ]


def reference_march(section, speed, law, x0, duration, dt):
    """DOP853 with terminal events at the edges, restarted in the new piece at each crossing.

    Returns the states at the samples ``k dt`` and the crossing times [s].
    """
    A, b_n = lure(section, speed)
    (lo, hi), pcs = pieces(law.gap, law.offset, law.inner_ratio)
    ts = np.arange(int(round(duration / dt)) + 1) * dt
    out = np.full((ts.size, A.shape[0]), np.nan)
    piece = 0 if x0[2] < lo else (2 if x0[2] > hi else 1)
    t, x, switches = 0.0, np.array(x0, dtype=float), []
    atol = 1e-15 * np.abs(x0).max()

    def upper(_t, y):
        return y[2] - hi

    def lower(_t, y):
        return y[2] - lo

    upper.terminal = lower.terminal = True
    while t < ts[-1]:
        a, c = pcs[piece]
        Ar, g = A + a * np.outer(b_n, np.eye(A.shape[0])[2]), c * b_n
        # events on the edges of this piece, in the direction that leaves it
        upper.direction = 1 if piece == 1 else -1
        lower.direction = -1 if piece == 1 else 1
        events = {0: [lower], 1: [upper, lower], 2: [upper]}[piece]
        sol = solve_ivp(
            lambda _t, y, Ar=Ar, g=g: Ar @ y + g,
            (t, ts[-1]),
            x,
            method="DOP853",
            rtol=REF_RTOL,
            atol=atol,
            events=events,
            dense_output=True,
        )
        assert sol.success
        end = sol.t[-1]
        m = (ts >= t) & (ts <= end)
        out[m] = sol.sol(ts[m]).T
        if sol.status == 1:
            hit = events[next(i for i, te in enumerate(sol.t_events) if te.size)]
            switches.append(end)
            piece = {(1, True): 2, (1, False): 0, (2, True): 1, (0, False): 1}[
                (piece, hit is upper)
            ]
        t, x = end, sol.y[:, -1]
    return ts, out, np.array(switches)


def expm_march(A, x0, dt, n_steps):
    """``x_{k+1} = expm(A dt) x_k``."""
    Phi = sla.expm(A * dt)
    X = np.empty((n_steps + 1, A.shape[0]))
    X[0] = x0
    for k in range(n_steps):
        X[k + 1] = Phi @ X[k]
    return X


def rel_err(a, b):
    """Largest error per column relative to the column's peak of ``b`` (a column of zeros
    must be matched exactly)."""
    return np.abs(a - b).max(axis=0) / np.maximum(np.abs(b).max(axis=0), 1e-300)


def flap_plant(law, speed, section=None):
    return section_plant(section or conner_section(), [NonlinearHinge("flap", law)], speed, RHO)


# 1. Through switches against solve_ivp with events ----------------------------------------
CASES = {
    "freeplay-10": (10.0, Freeplay(GAP)),
    "freeplay-15": (15.0, Freeplay(GAP)),
    "freeplay-20": (20.0, Freeplay(GAP)),
    "preload-15": (15.0, Freeplay(GAP, offset=0.5 * GAP)),
    "bilinear-15": (15.0, Bilinear(GAP, inner_ratio=0.3)),
}


@pytest.mark.parametrize("case", list(CASES))
def test_march_through_switches_matches_solve_ivp(case):
    """2 s from the flap at twice the gap, ~100 edge crossings: plunge, pitch, flap and the
    crossing times equal an event-restarted DOP853 of the same equations."""
    speed, law = CASES[case]
    nplant = flap_plant(law, speed)
    x0 = nplant.initial_state(2 * GAP)
    ts, X, switches = reference_march(conner_section(), speed, law, x0, 2.0, 1e-3)
    res = march_hinges(nplant, duration=2.0, dt=1e-3, x0=x0)
    assert switches.size > 50
    assert res.switches.size == switches.size
    np.testing.assert_allclose(res.switches, switches, rtol=0, atol=SWITCH_TOL)
    np.testing.assert_allclose(res.t, ts, rtol=0, atol=1e-12)
    assert rel_err(res.states[:, :N_Q], X[:, :N_Q]).max() < TRAJ_TOL
    for j, name in enumerate(["plunge", "pitch", "flap_rotation"]):
        assert rel_err(res.outputs[name][:, None], X[:, j : j + 1])[0] < TRAJ_TOL, name
    np.testing.assert_array_equal(res.rotations["flap"], res.outputs["flap_rotation"])


# 2. A zero gap is the linear march -----------------------------------------------------
LINEAR_TOL = 1e-10
"""The same linear system marched by the same zero-order-hold formula (or by ``expm``): the
only differences are rounding in the sampled matrices, propagated over 2000 steps of a stable
system (measured below 1e-12)."""


@pytest.mark.parametrize("speed", [10.0, 20.0])
def test_zero_gap_is_the_linear_march(speed):
    """``Freeplay(0)`` on the Conner flap: the march equals ``simulate`` of the plant with the
    open loop and ``x_{k+1} = expm(A dt) x_k``, and no switch is recorded."""
    nplant = flap_plant(Freeplay(0.0), speed)
    x0 = nplant.initial_state(0.05)
    x0[N_Q + 1] = 0.3  # a pitch rate too [rad/s]
    dt, n = 1e-3, 2000
    res = march_hinges(nplant, duration=n * dt, dt=dt, x0=x0)
    assert res.switches.size == 0
    A, _ = lure(conner_section(), speed)
    X = expm_march(A, x0, dt, n)
    assert rel_err(res.states, X).max() < LINEAR_TOL
    lin = simulate(
        nplant.plant, OpenLoop(("flap_hinge_moment",), dt), duration=n * dt, x0=x0,
        record_states=True,
    )  # fmt: skip
    assert rel_err(res.states, lin.states).max() < LINEAR_TOL
    for name in lin.outputs:
        assert rel_err(res.outputs[name][:, None], lin.outputs[name][:, None])[0] < LINEAR_TOL
    np.testing.assert_array_equal(res.hinge_moments["flap"], K_FLAP * res.rotations["flap"])


@pytest.fixture(scope="module")
def goland_loop():
    """The Goland wing with its aileron, the LQR of ``controllers/lqr.toml`` at 120 m/s
    (open-loop flutter 137 m/s) sampled at 1 kHz."""
    model = aes.AeroelasticModel(aes.examples.goland_aileron())
    loop = ControlLoop(
        model, RHO, ["aileron_hinge_moment"], ["tip_le_accel", "tip_te_accel"],
        ["tip_twist", "tip_disp"],
    )  # fmt: skip
    spec = load_controller(ROOT / "controllers" / "lqr.toml")
    return loop, spec, loop.design_controller(spec, 120.0, 1000.0)


def test_zero_gap_closed_loop_is_simulate(goland_loop):
    """Goland + LQR with ``Freeplay(0)`` on both aileron actuators: the nonlinear march equals
    :func:`simulate` of the loop's linear plant (same states, same controller) to rounding."""
    loop, spec, ctrl = goland_loop
    nplant = loop_hinge_plant(loop, [NonlinearHinge("aileron", Freeplay(0.0))], 120.0)
    x0 = nplant.initial_state(0.01)
    res = march_hinges(nplant, ctrl, duration=1.0, x0=x0, limits=spec.limits)
    lin = simulate(
        loop.plant(120.0), ctrl, duration=1.0, x0=x0, limits=spec.limits, record_states=True
    )
    assert res.switches.size == 0
    assert rel_err(res.states, lin.states).max() < LINEAR_TOL
    for name in lin.outputs:
        assert rel_err(res.outputs[name][:, None], lin.outputs[name][:, None])[0] < LINEAR_TOL
    # every sample's command, the last one computed from the final state as simulate does
    for name in lin.applied:
        a, b = res.applied[name], lin.applied[name]
        assert np.abs(a - b).max() < LINEAR_TOL * np.abs(b).max(), name
        a, b = res.commands[name], lin.commands[name]
        assert np.abs(a - b).max() < LINEAR_TOL * np.abs(b).max(), name


# 3. Inside the gap: the flap-free section -----------------------------------------------
@pytest.mark.parametrize("speed, fraction", [(3.0, 0.6), (5.0, 0.3)])
def test_inside_the_gap_is_the_flap_free_section(speed, fraction):
    """Below the flap-free flutter speed (6.49 m/s) a flap started inside the gap stays there:
    the march equals ``conner_section(k_flap=0)`` marched by ``expm`` to rounding, with no
    switch."""
    nplant = flap_plant(Freeplay(GAP), speed)
    x0 = nplant.initial_state(fraction * GAP / 2)
    dt, n = 1e-3, 2000
    res = march_hinges(nplant, duration=n * dt, dt=dt, x0=x0)
    A_free, _ = lure(conner_section(k_flap=0.0), speed)
    X = expm_march(A_free, x0, dt, n)
    assert res.switches.size == 0
    assert np.abs(X[:, 2]).max() < GAP / 2
    assert rel_err(res.states, X).max() < LINEAR_TOL
    assert np.all(res.hinge_moments["flap"] == 0.0)


# 4. Homogeneity in the gap ---------------------------------------------------------------
@pytest.mark.parametrize(
    "law, speed",
    [
        (Freeplay(GAP), 15.0),
        (Bilinear(GAP, inner_ratio=0.3), 12.0),
        (Freeplay(GAP, 0.3 * GAP), 18.0),
    ],
)
def test_homogeneous_in_the_gap(law, speed):
    """The equations are homogeneous in (gap, offset, state): gap 2g from 2 x0 gives twice the
    rotations (1e-9 relative: only the root finder's and eigen-solutions' rounding differ) and
    the same switch times."""
    double = type(law)(2 * law.gap, 2 * law.offset, law.inner_ratio)
    p1, p2 = flap_plant(law, speed), flap_plant(double, speed)
    x0 = p1.initial_state(1.7 * law.gap)
    x0[N_Q + 1] = 0.2  # pitch rate [rad/s]
    r1 = march_hinges(p1, duration=2.0, x0=x0)
    r2 = march_hinges(p2, duration=2.0, x0=2 * x0)
    assert r1.switches.size > 20
    np.testing.assert_allclose(r2.switches, r1.switches, rtol=0, atol=1e-12)
    s1, s2 = r1.rotations["flap"], r2.rotations["flap"]
    assert np.abs(s2 - 2 * s1).max() < 1e-9 * np.abs(2 * s1).max()
    assert rel_err(r2.states, 2 * r1.states).max() < 1e-9


# 5. Limit cycles of the Conner section ----------------------------------------------------
RATIOS = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]


def crossings(t, y):
    """Upward crossings of the mean of ``y`` [s], linearly interpolated between samples."""
    y = y - y.mean()
    i = np.flatnonzero((y[:-1] < 0) & (y[1:] >= 0))
    return t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i])


@pytest.fixture(scope="module")
def lco_table():
    """Per ``U / U_F``: 40 s from the flap at twice the gap; the last 10 s and the 10 s before."""
    rows = {}
    for ratio in RATIOS:
        res = march_hinges(flap_plant(Freeplay(GAP), ratio * U_F), duration=40.0, rotation0=2 * GAP)
        t, s = res.t, res.rotations["flap"]
        last, before = t >= 30.0, (t >= 20.0) & (t < 30.0)
        w = s[last] - s[last].mean()
        spec = np.abs(np.fft.rfft(w * np.hanning(w.size)))
        periods = np.diff(crossings(t[last], res.outputs["pitch"][last]))
        rows[ratio] = {
            "rms": np.sqrt(np.mean(s[last] ** 2)) / GAP,
            "rms_before": np.sqrt(np.mean(s[before] ** 2)) / GAP,
            "peak": np.abs(s[last]).max() / GAP,
            "f_fft": np.fft.rfftfreq(w.size, res.t[1])[np.argmax(spec)],
            "f_cross": 1.0 / periods.mean(),
            "jitter": periods.std() / periods.mean(),
            "switches": res.switches.size,
        }
    return rows


@pytest.mark.slow
def test_conner_lco_table(lco_table):
    """Between the flap-free (6.49 m/s) and the gap-closed (23.74 m/s) flutter speeds the
    flap neither comes to rest in the gap nor diverges: after 30 s its RMS is steady (1 %
    over 10 s), its peak O(gap) beyond the gap's half-width; from 0.4 U_F the motion is
    periodic (pitch periods equal to 1e-3; at 0.3 U_F it is irregular, and reported only)."""
    print("\nU/U_F  U [m/s]  flap RMS/gap  peak/gap  f_fft [Hz]  f_cross [Hz]  jitter  switches")
    for ratio, r in lco_table.items():
        print(
            f"{ratio:5.2f}  {ratio * U_F:7.2f}  {r['rms']:12.4f}  {r['peak']:8.4f}  "
            f"{r['f_fft']:10.2f}  {r['f_cross']:12.3f}  {r['jitter']:6.1e}  {r['switches']:8d}"
        )
        assert r["rms"] == pytest.approx(r["rms_before"], rel=0.01), ratio
        assert 0.5 < r["peak"] < 2.0, ratio
        assert r["switches"] > 100, ratio
        if ratio >= 0.4:
            assert r["jitter"] < 1e-3, ratio
            assert r["f_fft"] == pytest.approx(r["f_cross"], abs=0.1), ratio  # FFT bin 0.1 Hz


def test_above_the_gap_closed_flutter_speed_it_diverges():
    """At 26 m/s (> U_F) the system outside the gap is the unstable linear one: the flap
    grows without bound (x1000 in 5 s; linear growth rate 2.8 /s)."""
    res = march_hinges(flap_plant(Freeplay(GAP), 26.0), duration=5.0, rotation0=2 * GAP)
    s = np.abs(res.rotations["flap"])
    assert np.all(np.isfinite(res.states))
    assert s[res.t >= 4.0].max() > 1e3 * s[res.t <= 1.0].max()


# 6. Energy balance over a cycle ----------------------------------------------------------
def energy_terms(section, speed, law, states, rates_of):
    """Structural energy ``T + V`` [J/m] (hinge potential of the law: 0 inside the gap,
    ``k (|s| - gap/2)^2 / 2`` outside) and the powers [W/m] of the aerodynamic forces and of
    the structural damping, from the states.

    Aerodynamic generalized forces from the pencil: ``M v' = P_v x`` (the velocity rows of
    ``A0 + V A1 + V^2 A2``, ``M = Ms + rho Mnc``) gives
    ``F_aero = P_v x + Ks q + Cs v - rho Mnc v'`` with ``v'`` from the states' derivative.
    """
    system = section.system(RHO)
    P = system.pencil(speed).toarray()
    Ms, Ks = section.mass_matrix(), system.Ks.toarray()
    Cs = system.Cs.toarray() if system.Cs is not None else np.zeros((N_Q, N_Q))
    q, v = states[:, :N_Q], states[:, N_Q : 2 * N_Q]
    vdot = rates_of(states)[:, N_Q : 2 * N_Q]
    F = (states @ P.T)[:, N_Q : 2 * N_Q] + q @ Ks.T + v @ Cs.T - vdot @ (system.M.toarray() - Ms).T
    s, h = q[:, 2], law.gap / 2
    K_open = Ks.copy()
    K_open[2, 2] = 0.0
    hinge = np.where(np.abs(s) > h, 0.5 * K_FLAP * (np.abs(s) - h) ** 2, 0.0)
    energy = (
        0.5 * np.einsum("ij,jk,ik->i", v, Ms, v)
        + 0.5 * np.einsum("ij,jk,ik->i", q, K_open, q)
        + hinge
    )
    return energy, np.einsum("ij,ij->i", F, v), np.einsum("ij,jk,ik->i", v, Cs, v)


def cumulative(p, dt):
    """Trapezoid rule: the integral of ``p`` from the first sample to each sample."""
    return np.concatenate([[0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * dt)])


@pytest.mark.parametrize("damped", [False, True])
def test_energy_balance_over_lco_cycles(damped):
    """Conner section at 14 m/s on its limit cycle (20 s from twice the gap, then 0.5 s at
    0.1 ms): (a) the aerodynamic work minus the damping's dissipation equals the change of
    structural energy at every sample (trapezoid rule: ``(2 omega dt)^2 / 12`` ~ 2e-5 of the
    energy exchanged, 1e-4 allowed); (b) over each cycle (between upward zero crossings of the
    pitch) the net aerodynamic work equals the energy dissipated by structural damping, zero
    when undamped, to 1e-4 of the aerodynamic energy put in per cycle."""
    section = conner_section(damped=damped)
    speed, law = 14.0, Freeplay(GAP)
    nplant = flap_plant(law, speed, section)
    settle = march_hinges(nplant, duration=20.0, rotation0=2 * GAP)
    dt = 1e-4
    res = march_hinges(nplant, duration=0.5, dt=dt, x0=settle.states[-1])
    A, b_n = lure(section, speed)
    (lo, hi), _ = pieces(law.gap, 0.0, 0.0)

    def rates_of(X):
        s = X[:, 2]
        phi = K_FLAP * np.clip(s, lo, hi)  # k s - M(s) of the freeplay
        return X @ A.T + np.outer(phi, b_n)

    energy, p_aero, p_damp = energy_terms(section, speed, law, res.states, rates_of)
    work = cumulative(p_aero - p_damp, dt)
    put_in = cumulative(np.maximum(p_aero, 0.0), dt)
    tc = crossings(res.t, res.outputs["pitch"])
    assert tc.size >= 4
    per_cycle = np.diff(np.interp(tc, res.t, put_in))
    assert np.abs(work - (energy - energy[0])).max() < 1e-4 * per_cycle.min()
    net_aero = np.diff(np.interp(tc, res.t, cumulative(p_aero, dt)))
    dissipated = np.diff(np.interp(tc, res.t, cumulative(p_damp, dt)))
    assert np.abs(net_aero - dissipated).max() < 1e-4 * per_cycle.min()
    if damped:
        assert dissipated.min() > 1e-3 * per_cycle.min()  # the damping matters
    else:
        np.testing.assert_array_equal(dissipated, 0.0)


# 7. Cubic hardening ----------------------------------------------------------------------
CUBIC_K, CUBIC_C, CUBIC_U = 0.8, 427.0, 10.0
"""A soft flap spring (0.8 N m/rad per m) puts the linear section's pitch-flap flutter at 2.6
m/s; at 10 m/s it is unstable (growth 1.2 /s) and a hardening ``427 s^3`` N m limits it. (On
the Conner flap, k = 3.9, the flutter at 23.74 m/s is a pitch-plunge one that the flap
stiffness hardly moves - 24.07 m/s at k = 100 - so no hardening spring bounds it at 26 m/s.)"""


def critical_stiffness(speed, lo=1.0, hi=1.6):
    """Flap stiffness [N m/rad per m] where the linear section is neutrally stable at
    ``speed`` (bisection on the largest real part, stable above)."""
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        stable = np.linalg.eigvals(lure(conner_section(k_flap=mid), speed)[0]).real.max() < 0
        lo, hi = (lo, mid) if stable else (mid, hi)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("start", [0.01, 0.08])
@pytest.mark.slow
def test_cubic_hardening_lco(start):
    """From below and from above, the flap settles on one cycle whose amplitude the describing
    function ``k + 3/4 c A^2 = k_crit`` predicts (to 2 %: the one-harmonic approximation), and
    the smooth march equals an independent DOP853 (rtol 1e-13) to 1e-7 (the march's own rtol
    1e-10 accumulated over 10 s of a neutral cycle's phase; measured 7e-9)."""
    section = conner_section(k_flap=CUBIC_K)
    nplant = flap_plant(Cubic(CUBIC_C), CUBIC_U, section)
    x0 = nplant.initial_state(start)
    res = march_hinges(nplant, duration=10.0, x0=x0)
    A, b_n = lure(section, CUBIC_U)
    sol = solve_ivp(
        lambda _t, x: A @ x - b_n * CUBIC_C * x[2] ** 3,  # phi = k s - (k s + c s^3)
        (0.0, 10.0), x0, method="DOP853", t_eval=res.t, rtol=1e-13, atol=1e-16,
    )  # fmt: skip
    assert sol.success
    assert rel_err(res.states[:, :N_Q], sol.y.T[:, :N_Q]).max() < 1e-7
    s = res.rotations["flap"]
    a1, a2 = np.abs(s[(res.t >= 6) & (res.t < 8)]).max(), np.abs(s[res.t >= 8]).max()
    assert a2 == pytest.approx(a1, rel=1e-3)
    k_crit = critical_stiffness(CUBIC_U)
    amp_df = np.sqrt((k_crit - CUBIC_K) / (0.75 * CUBIC_C))
    assert a2 == pytest.approx(amp_df, rel=0.02)
    np.testing.assert_allclose(
        res.hinge_moments["flap"], CUBIC_K * s + CUBIC_C * s**3, rtol=1e-12, atol=0
    )


# 8. Closed loop on Goland with freeplay ---------------------------------------------------
@pytest.mark.parametrize("start", [2.0, 0.3])
def test_goland_closed_loop_with_freeplay(goland_loop, start):
    """1 deg of freeplay on both aileron actuators, LQR at 120 m/s with the spec's limits,
    from ``start`` x the gap: finite, switches, the applied moment within its limits, and each
    actuator's moment is the law's (zero inside the gap, ``k (|s| - gap/2)`` outside)."""
    loop, spec, ctrl = goland_loop
    gap = np.radians(1.0)
    nplant = loop_hinge_plant(loop, [NonlinearHinge("aileron", Freeplay(gap))], 120.0)
    assert nplant.elements.names == ("actuator1", "actuator2")
    res = march_hinges(nplant, ctrl, duration=2.0, rotation0=start * gap, limits=spec.limits)
    assert np.all(np.isfinite(res.states))
    assert res.switches.size > 0
    assert np.all(np.diff(res.switches) >= 0)
    u = res.applied["aileron_hinge_moment"]
    assert np.abs(u).max() <= spec.limits.magnitude["aileron_hinge_moment"]
    for name, k in zip(nplant.elements.names, nplant.elements.stiffness, strict=True):
        s, M = res.rotations[name], res.hinge_moments[name]
        np.testing.assert_allclose(s, res.outputs[f"{name}_rotation"], rtol=0, atol=1e-15)
        inside = np.abs(s) < gap / 2
        assert inside.any() and (~inside).any()
        assert np.all(M[inside] == 0.0)
        expected = k * np.sign(s) * (np.abs(s) - gap / 2)
        np.testing.assert_allclose(M[~inside], expected[~inside], rtol=1e-12, atol=0)


# 9. Bad input ---------------------------------------------------------------------------
def test_bad_inputs_name_the_value():
    nplant = flap_plant(Freeplay(GAP), 10.0)
    with pytest.raises(InputError, match="x0 or rotation0, not both"):
        march_hinges(nplant, duration=1.0, x0=np.zeros(8), rotation0=0.01)
    with pytest.raises(InputError, match=r"x0: expected 8 finite numbers, got shape \(7,\)"):
        march_hinges(nplant, duration=1.0, x0=np.zeros(7))
    with pytest.raises(InputError, match=r"freeplay\.gap = -0\.01: allowed range"):
        Freeplay(-0.01)
    with pytest.raises(InputError, match=r"actuator1, actuator2, aileron"):
        nonlinear_plant(
            aes.examples.goland_aileron(), [NonlinearHinge("elevator", Freeplay(0.01))], 100.0, RHO
        )
    two_dof = TypicalSection(
        semichord=0.127, a=-0.5, mass=3.3843, x_alpha=0.2, inertia=0.01347, k_plunge=2818.8,
        k_pitch=37.34,
    )  # fmt: skip
    with pytest.raises(InputError, match="the section has no flap"):
        section_plant(two_dof, [NonlinearHinge("flap", Freeplay(GAP))], 10.0, RHO)
    with pytest.raises(InputError, match=r"target 'flap'; got \['aileron'\]"):
        section_plant(conner_section(), [NonlinearHinge("aileron", Freeplay(GAP))], 10.0, RHO)
