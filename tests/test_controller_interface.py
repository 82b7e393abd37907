"""Issue 24: one controller interface for every analysis.

Case: the Goland wing with aileron (``aes.examples.goland_aileron``), 10 elements, sea-level
density, hinge moment commanded, tip sensors (two accelerometers behind 30 Hz Butterworth filters
and the tip twist), sampled at 1000 Hz; open-loop flutter at 137.37 m/s. The references here are
computed in the tests: the closed loop assembled from the plant's own matrices sampled by a
zero-order hold written here (``scipy.linalg.expm``), and its dense eigenvalues.
"""

from __future__ import annotations

import json
import shutil
import warnings

import control
import numpy as np
import pytest
import scipy.io
import scipy.linalg as sla
from conftest import ROOT

import aeroservo as aes
from aeroservo import cli
from aeroservo.design import (
    DiscreteCompensator,
    Limits,
    as_controller,
    closed_loop_boundary,
    closed_loop_matrix,
    judge_loop,
    loop_margins,
    python_law,
    static_gain,
)
from aeroservo.files import load_scenario
from aeroservo.simulate import simulate
from aeroservo.studies import quick
from aeroservo.studies.runs import run_simulation
from aeroservo.studies.verdict import EXIT_UNSTABLE

RHO = 1.225
HM = "aileron_hinge_moment"
CONTROLS = (HM,)
SENSORS = ("tip_le_accel", "tip_te_accel", "tip_twist")
RATE = 1000.0
DT = 1.0 / RATE
VF = 137.37  # open-loop flutter speed [m/s], checked by the fixture


@pytest.fixture(scope="module")
def setup():
    """The shipped H-infinity scenario's loop, the open-loop flutter speed and the shipped
    H-infinity compensator designed at 1.1 V_f (as the scenario designs it)."""
    sc = load_scenario(ROOT / "scenarios" / "goland_aileron_hinf.toml")
    model = sc.model()
    loop = sc.loop(model)
    vf = aes.flutter_boundary(model, RHO).flutter_speed
    assert vf == pytest.approx(VF, abs=0.01)
    hinf = loop.design_controller(sc.controller, 1.1 * vf, sc.sample_rate, vf)
    assert isinstance(hinf, DiscreteCompensator) and hinf.dt == DT
    assert hinf.controls == CONTROLS and hinf.sensors == SENSORS
    return sc, loop, vf, hinf


# -- the reference: the sampled loop assembled here ---------------------------------------------


class SampledReference:
    """The plant of a loop at a speed sampled by a zero-order hold written here, and the closed
    loop with a compensator ``(Ac, Bc, Cc, Dc)`` (commands ``c = Cc s + Dc y``).

    Loop state ``[x, h, s]``: plant state, input held over the last interval (the sensors'
    feedthrough sees it: ``y_k = C x_k + Du h_k``), compensator state; ``u_k = c_k``."""

    def __init__(self, loop, dt: float = DT):
        self.loop, self.dt, self.cache = loop, dt, {}

    def sampled(self, v: float):
        v = float(v)
        if v not in self.cache:
            p = self.loop.plant(v)
            ii = [list(p.input_labels).index(c) for c in CONTROLS]
            oo = [list(p.output_labels).index(s) for s in SENSORS]
            A, B = np.asarray(p.A), np.asarray(p.B)[:, ii]
            C, D = np.asarray(p.C)[oo], np.asarray(p.D)[np.ix_(oo, ii)]
            n, m = B.shape
            M = np.zeros((n + m, n + m))
            M[:n, :n], M[:n, n:] = A, B
            E = sla.expm(M * self.dt)
            self.cache[v] = (E[:n, :n], E[:n, n:], C, D)
        return self.cache[v]

    def closed(self, v: float, mats) -> np.ndarray:
        Phi, G, C, Du = self.sampled(v)
        Ac, Bc, Cc, Dc = mats
        n, m, ns = Phi.shape[0], G.shape[1], Ac.shape[0]
        K = np.hstack([Dc @ C, Dc @ Du, Cc])  # u = K [x, h, s]
        Z = np.zeros((n + m + ns, n + m + ns))
        Z[:n, :n] = Phi
        Z[:n] += G @ K
        Z[n : n + m] = K
        Z[n + m :, :n] = Bc @ C
        Z[n + m :, n : n + m] = Bc @ Du
        Z[n + m :, n + m :] = Ac
        return Z

    def eig(self, v: float, mats) -> complex:
        """The eigenvalue of largest modulus of the closed sampled loop."""
        lam = np.linalg.eigvals(self.closed(v, mats))
        return complex(lam[np.argmax(np.abs(lam))])

    def measure(self, v: float, mats) -> float:
        return abs(self.eig(v, mats)) - 1.0

    def crossings(self, mats, speeds: np.ndarray, g: np.ndarray, rtol: float = 1e-6) -> list:
        """Every sign change of ``|lambda|max - 1`` on the grid, bisected to ``rtol``:
        ``(speed, kind, frequency [Hz])``."""
        out = []
        for i in np.nonzero(np.sign(g[:-1]) != np.sign(g[1:]))[0]:
            lo, hi, glo = speeds[i], speeds[i + 1], g[i]
            while hi - lo > rtol * lo:
                mid = 0.5 * (lo + hi)
                gm = self.measure(mid, mats)
                if np.sign(gm) == np.sign(glo):
                    lo, glo = mid, gm
                else:
                    hi = mid
            v = 0.5 * (lo + hi)
            lam = self.eig(v, mats)
            freq = abs(np.angle(lam)) / (2 * np.pi * self.dt)
            out.append((v, "onset" if g[i] < 0 else "recovery", freq))
        return out


def reference_intervals(crossings: list, first_stable: bool, lo: float, hi: float) -> list:
    """Stable intervals of ``[lo, hi]`` from the reference crossings."""
    edges = [lo] + [c[0] for c in crossings] + [hi]
    out, ok = [], first_stable
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        if ok:
            out.append((a, b))
        ok = not ok
    return out


# -- 1. randomized compensators: boundary against dense eigenvalues ------------------------------


def _series(comp, filt):
    """The compensator followed by a filter on its command."""
    Ac, Bc, Cc, Dc = comp
    Af, Bf, Cf, Df = filt
    n, nf = Ac.shape[0], Af.shape[0]
    A = np.block([[Ac, np.zeros((n, nf))], [Bf @ Cc, Af]])
    return A, np.vstack([Bc, Bf @ Dc]), np.hstack([Df @ Cc, Cf]), Df @ Dc


def _random_filter(rng):
    """A random stable filter with unit static gain (a first-order lag, a damped pole pair, a
    lead-lag), discretised by Tustin's method: random stable poles added to the loop."""
    s = control.tf("s")
    w1 = 2 * np.pi * rng.uniform(60.0, 300.0)
    H = w1 / (s + w1)
    kind = rng.integers(0, 3)
    if kind >= 1:
        w2, z = 2 * np.pi * rng.uniform(40.0, 250.0), rng.uniform(0.3, 0.9)
        H = H * w2**2 / (s**2 + 2 * z * w2 * s + w2**2)
    if kind == 2:
        a, w3 = rng.uniform(0.7, 1.4), 2 * np.pi * rng.uniform(5.0, 40.0)
        H = H * (s / w3 + 1) / (s / (a * w3) + 1)
    d = control.ss(control.c2d(control.ss(H), DT, method="tustin"))
    return tuple(np.asarray(x, dtype=float) for x in (d.A, d.B, d.C, d.D))


def _similar(rng, Ac, Bc, Cc):
    """A random similarity transform of the compensator's state (same transfer function)."""
    n = Ac.shape[0]
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    T = Q @ np.diag(np.exp(rng.uniform(-1.0, 1.0, n)))
    Ti = np.linalg.inv(T)
    return T @ Ac @ Ti, T @ Bc, Cc @ Ti


def random_compensator(rng, hinf, family: int):
    """``(A, B, C, D)`` of a random compensator from the shipped H-infinity one (families 0 to
    2), or of a random static gain ``u = D y`` (family 3)."""
    Ac, Bc, Cc, Dc = (np.array(x, dtype=float) for x in hinf.compensator_matrices())
    if family == 3:
        K = rng.standard_normal((1, 3)) * np.array([1.0, 1.0, 1e4]) * np.exp(rng.uniform(-3, 3))
        return np.zeros((0, 0)), np.zeros((0, 3)), np.zeros((1, 0)), K
    gain = np.exp(rng.uniform(-1.2, 1.2))
    sens = np.exp(rng.uniform(-0.5, 0.5, size=3))
    Bc, Cc, Dc = Bc * sens, gain * Cc, gain * Dc * sens
    Ac, Bc, Cc = _similar(rng, Ac, Bc, Cc)
    if family == 1:  # a lightly damped pole pair in parallel
        f, zeta = rng.uniform(3.0, 40.0), rng.uniform(0.005, 0.05)
        z = np.exp((-zeta + 1j * np.sqrt(1 - zeta**2)) * 2 * np.pi * f * DT)
        Ae = np.array([[z.real, -z.imag], [z.imag, z.real]])
        Be = rng.standard_normal((2, 3)) * np.abs(Bc).max(axis=0) * rng.uniform(0.002, 0.03)
        Ce = rng.standard_normal((1, 2)) * np.abs(Cc).max()
        return sla.block_diag(Ac, Ae), np.vstack([Bc, Be]), np.hstack([Cc, Ce]), Dc
    return _series((Ac, Bc, Cc, Dc), _random_filter(rng))


def as_given(mats, family: int, i: int):
    """The compensator in one of the forms the analyses accept."""
    A, B, C, D = mats
    if family == 3:
        return static_gain(-D, CONTROLS, sensors=SENSORS, sample_rate=RATE)
    if i % 2:
        return control.ss(A, B, C, D, DT, inputs=list(SENSORS), outputs=list(CONTROLS))
    return DiscreteCompensator(A, B, C, D, CONTROLS, SENSORS, DT)


@pytest.mark.slow
def test_random_compensators_boundary_matches_dense_eigenvalues(setup):
    """20 random linear controllers on the Goland-with-aileron plant (the shipped H-infinity
    compensator rescaled, its state transformed, random stable poles added in series or a
    lightly damped pair in parallel; random static gains on the sensors), kept when stable at a
    reference speed (1.1 V_f; 0.7 V_f for the static gains). ``closed_loop_boundary`` finds
    exactly the crossings of the reference (the dense eigenvalues of the closed sampled loop
    assembled here, on a 301-point grid, each sign change bisected to 1e-6 relative), each to
    1e-5 relative, with its kind and frequency, and the same stable intervals."""
    _sc, loop, vf, hinf = setup
    ref = SampledReference(loop)
    v_min, v_max = 0.1 * vf, 2.0 * vf
    speeds = np.linspace(v_min, v_max, 301)
    rng = np.random.default_rng(20240624)
    kept, tries = [], 0
    while len(kept) < 20:
        tries += 1
        assert tries < 200, "too few random controllers are stable at their reference speed"
        family = len(kept) % 4
        mats = random_compensator(rng, hinf, family)
        v_ref = (0.7 if family == 3 else 1.1) * vf
        if ref.measure(v_ref, mats) < 0:
            kept.append((family, mats, v_ref))
    worst, worst_freq, n_cross = 0.0, 0.0, []
    for i, (family, mats, v_ref) in enumerate(kept):
        g = np.array([ref.measure(v, mats) for v in speeds])
        expected = ref.crossings(mats, speeds, g)
        b = closed_loop_boundary(
            loop, as_given(mats, family, i), v_max, v_min=v_min, n_grid=31, reference_speed=v_ref
        )
        found = [(c["speed"], c["kind"], c["frequency"]) for c in b.crossings]
        what = f"controller {i} (family {family}): found {found}, expected {expected}"
        assert len(found) == len(expected), what
        for (v, kind, f), (v0, kind0, f0) in zip(found, expected, strict=True):
            assert v == pytest.approx(v0, rel=1e-5), what
            assert kind == kind0, what
            assert f == pytest.approx(f0, rel=1e-4, abs=1e-3), what
            worst = max(worst, abs(v / v0 - 1))
            worst_freq = max(worst_freq, abs(f - f0))
        assert b.stable_at_reference
        stable = reference_intervals(expected, g[0] < 0, v_min, v_max)
        got = b.stable_intervals()
        assert len(got) == len(stable), what
        for (a, c), (a0, c0) in zip(got, stable, strict=True):
            assert (a, c) == pytest.approx((a0, c0), rel=1e-5), what
        n_cross.append(len(expected))
    print(
        f"20 controllers ({tries} drawn), crossings per controller {n_cross}: worst relative "
        f"speed error {worst:.2e}, worst frequency error {worst_freq:.2e} Hz"
    )


# -- 2. stable at the design speed, unstable lower: the verdict fails ---------------------------


def scenario_copy(tmp_path, scenario: str, *edits, controller: str | None = None):
    """A shipped scenario (and every shipped controller) copied to ``tmp_path`` and edited:
    ``(old, new)`` text replacements in the scenario file; ``controller`` replaces the text of
    the controller file it refers to by a new file ``controllers/brought.toml``."""
    shutil.copytree(ROOT / "scenarios", tmp_path / "scenarios", dirs_exist_ok=True)
    shutil.copytree(ROOT / "controllers", tmp_path / "controllers", dirs_exist_ok=True)
    path = tmp_path / "scenarios" / f"{scenario}.toml"
    text = path.read_text()
    if controller is not None:
        (tmp_path / "controllers" / "brought.toml").write_text(controller)
        old = next(line for line in text.splitlines() if line.startswith("spec = "))
        edits = ((old, 'spec = "../controllers/brought.toml"'), *edits)
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new)
    path.write_text(text)
    return path


def test_judge_loop_fails_a_loop_unstable_below_its_design_speed(setup):
    """The shipped H-infinity compensator with 3 x its gain, brought as a python-control
    ``StateSpace``, is stable at 1.1 V_f and unstable at 0.4 V_f (the reference eigenvalues):
    judged over 0.4-1.1 V_f it does not pass, with one unstable interval from 0.4 V_f to the
    recovery speed of the reference (1e-5 relative), named by its kind (oscillatory flutter at
    the frequency of the reference eigenvalue there), and the failure line says so."""
    _sc, loop, vf, hinf = setup
    Ac, Bc, Cc, Dc = hinf.compensator_matrices()
    sys = control.ss(Ac, Bc, 3 * Cc, 3 * Dc, DT, inputs=list(SENSORS), outputs=list(CONTROLS))
    ctrl = as_controller(sys, sample_rate=RATE)
    mats = ctrl.compensator_matrices()
    ref = SampledReference(loop)
    assert ref.measure(1.1 * vf, mats) < 0 < ref.measure(0.4 * vf, mats)
    lo, top = 0.4 * vf, 1.15 * 1.1 * vf
    speeds = np.linspace(lo, top, 121)
    expected = ref.crossings(mats, speeds, np.array([ref.measure(v, mats) for v in speeds]))
    assert [kind for _, kind, _ in expected] == ["recovery"]
    v_up, _, f_up = expected[0]

    j = judge_loop(loop, ctrl, (0.4 * vf, 1.1 * vf), margin_speeds=3)
    assert j.passed is False and j.stable is False and j.to_dict()["passed"] is False
    assert len(j.unstable) == 1
    u = j.unstable[0]
    assert u["from"] == pytest.approx(lo, rel=1e-12)
    assert u["to"] == pytest.approx(v_up, rel=1e-5)
    assert u["static"] is False and u["frequency"] == pytest.approx(f_up, rel=1e-4)
    assert u["kind"] == f"oscillatory flutter at {f_up:.3g} Hz"
    assert j.boundary.lower_speed == pytest.approx(v_up, rel=1e-5)
    line = j.lines()[0]
    assert f"{lo:.4g}-{v_up:.4g} m/s ({u['kind']})" in line


def test_scenario_unstable_in_its_engaged_range_fails_and_exits_3(tmp_path, capsys):
    """The shipped LQR (designed at 1.1 V_f, unstable below 43.5 m/s) engaged from 0.3 V_f: the
    run at 1.1 V_f is stable there, but its verdict is "unstable" and it does not pass; the
    command line exits 3 with one line on stderr naming the unstable speeds and the kind of the
    loss; with ``simulation.expect_failure = true`` it exits 0 and says nothing."""
    path = scenario_copy(
        tmp_path,
        "goland_aileron_lqr",
        ("engaged_speed_factors = [0.95, 1.1]", "engaged_speed_factors = [0.3, 1.1]"),
    )
    s = run_simulation(quick(load_scenario(path))).summary
    vf = s["open_loop_flutter_speed"]
    assert s["spectral_radius"] < 1.0  # stable at the scenario's speed
    assert s["verdict"] == "unstable" and s["passed"] is False
    (u,) = s["engaged"]["unstable_intervals"]
    assert u["from"] == pytest.approx(0.3 * vf, rel=1e-12)
    assert u["to"] == pytest.approx(43.5, abs=0.1) and u["to"] == s["closed_loop"]["lower_speed"]
    assert u["kind"].startswith("oscillatory flutter at")
    where = f"{u['from']:.4g}-{u['to']:.4g} m/s ({u['kind']})"
    assert where in s["hint"]
    # the lower end against the eigenvalues of the state-feedback loop assembled here
    sc = quick(load_scenario(path))
    loop = sc.loop()
    lqr = loop.design_controller(sc.controller, s["speed"], sc.sample_rate, vf)
    K = lqr.law(loop.state_labels).D  # c = K x on the plant's states

    def g(v):
        Phi, G, _, _ = SampledReference(loop).sampled(v)
        return np.max(np.abs(np.linalg.eigvals(Phi + G @ K))) - 1.0

    a, b = 0.3 * vf, 0.4 * vf
    assert g(a) > 0 > g(b)
    while b - a > 1e-7 * a:
        a, b = ((a + b) / 2, b) if g((a + b) / 2) > 0 else (a, (a + b) / 2)
    assert u["to"] == pytest.approx(a, rel=1e-5)

    out = tmp_path / "out"
    code = cli.main(["run", str(path), "--quick", "--json", "--out", str(out)])
    cap = capsys.readouterr()
    assert code == EXIT_UNSTABLE
    assert json.loads(cap.out)["verdict"] == "unstable"
    lines = cap.err.strip().splitlines()
    assert len(lines) == 1 and where in lines[0], cap.err

    text = path.read_text().replace("[simulation]\n", "[simulation]\nexpect_failure = true\n")
    path.write_text(text)
    code = cli.main(["run", str(path), "--quick", "--json", "--out", str(out)])
    cap = capsys.readouterr()
    assert code == 0 and cap.err == ""
    s = json.loads(cap.out)
    assert s["verdict"] == "unstable" and s["passed"] is False and s["expect_failure"] is True


# -- 3. not a controller: an InputError from every entry point ----------------------------------


class Protocol:
    """A nonlinear law through the sampled-controller protocol (no linear law)."""

    dt = DT
    controls = CONTROLS
    sensors = SENSORS

    def reset(self):
        pass

    def command(self, y, x=None):
        return np.array([-2e4 * y[2]])

    def update(self, y, u):
        pass


def _not_controllers():
    """``(id, object)``: things that are not controllers of a 1000 Hz loop."""
    A, B, C, D = np.array([[0.5]]), np.ones((1, 3)), np.ones((1, 1)), np.zeros((1, 3))
    named = {"inputs": list(SENSORS), "outputs": list(CONTROLS)}
    slow = Protocol()
    slow.dt = "fast"
    return [
        ("object", object()),
        ("none", None),
        ("string", "hinf"),
        ("dict", {"A": A, "B": B, "C": C, "D": D, "dt": DT}),
        ("array", np.ones((1, 3))),
        ("list", [[1.0, 2.0, 3.0]]),
        ("number", 5.0),
        ("function", lambda t, y: [0.0]),
        ("ss_unnamed", control.ss(A, B, C, D, DT)),
        ("tf_unnamed", control.tf([1.0], [1.0, -0.5], DT)),
        ("ss_wrong_period", control.ss(A, B, C, D, 2 * DT, **named)),
        ("tf_wrong_period", control.tf([1.0], [1.0, -0.5], 2 * DT, inputs="tip_twist", outputs=HM)),
        ("protocol_bad_dt", slow),
    ]


NOT_CONTROLLERS = _not_controllers()

ENTRY_POINTS = {
    "simulate": lambda loop, plant, c: simulate(plant, c, duration=0.01, sample_rate=RATE),
    "closed_loop_boundary": lambda loop, plant, c: closed_loop_boundary(
        loop, c, 200.0, n_grid=5, sample_rate=RATE
    ),
    "closed_loop_matrix": lambda loop, plant, c: closed_loop_matrix(plant, c, sample_rate=RATE),
    "loop_margins": lambda loop, plant, c: loop_margins(plant, c, sample_rate=RATE),
    "judge_loop": lambda loop, plant, c: judge_loop(
        loop, c, (70.0, 150.0), margin_speeds=0, sample_rate=RATE
    ),
    "as_controller": lambda loop, plant, c: as_controller(c, sample_rate=RATE),
}


@pytest.fixture(scope="module")
def plant(setup):
    """The plant at 1.1 V_f."""
    return setup[1].plant(1.1 * setup[2])


@pytest.mark.parametrize("entry", ENTRY_POINTS)
@pytest.mark.parametrize("obj", [o for _, o in NOT_CONTROLLERS], ids=[i for i, _ in NOT_CONTROLLERS])
def test_not_a_controller_is_an_input_error_everywhere(setup, plant, entry, obj):
    """Objects that are not controllers (an object, None, a string, a dict, a gain matrix or a
    function without signal names, python-control systems with unnamed signals or another
    sample period, a protocol object whose ``dt`` is not a period) are refused with an
    ``InputError`` (never an AttributeError or TypeError) by the simulator, the closed-loop
    boundary and matrix, the margins, the judgement and ``as_controller``, in one line."""
    with pytest.raises(aes.InputError) as info:
        ENTRY_POINTS[entry](setup[1], plant, obj)
    assert "\n" not in str(info.value) and str(info.value)


@pytest.mark.parametrize("entry", [e for e in ENTRY_POINTS if e != "as_controller"])
def test_signals_the_plant_lacks_are_input_errors(setup, plant, entry):
    """A compensator whose inputs are not sensors of the plant, and a static state gain on
    states the plant does not have, are refused with an ``InputError`` naming the signal."""
    sys = control.ss([[0.5]], [[1.0]], [[1.0]], [[0.0]], DT, inputs=["tip_yaw"], outputs=[HM])
    with pytest.raises(aes.InputError, match="tip_yaw"):
        ENTRY_POINTS[entry](setup[1], plant, sys)
    gain = static_gain([[1.0]], CONTROLS, states=["no_such_state"], sample_rate=RATE)
    with pytest.raises(aes.InputError, match="no_such_state"):
        ENTRY_POINTS[entry](setup[1], plant, gain)


def test_continuous_or_unperiodic_systems_need_the_sample_rate(plant):
    """A continuous python-control compensator, or a discrete one without a period, needs the
    loop's sample rate (an ``InputError`` without it); with it, it is discretised (Tustin) or
    takes the loop's period."""
    named = {"inputs": list(SENSORS), "outputs": list(CONTROLS)}
    cont = control.ss([[-50.0]], [[0.0, 0.0, 50.0]], [[1.0]], [[0.0, 0.0, 0.0]], **named)
    free = control.ss([[0.5]], [[0.0, 0.0, 1.0]], [[1.0]], [[0.0, 0.0, 0.0]], True, **named)
    for sys in (cont, free):
        with pytest.raises(aes.InputError, match="sample_rate"):
            as_controller(sys)
        with pytest.raises(aes.InputError, match="sample_rate"):
            closed_loop_matrix(plant, sys)
        assert as_controller(sys, sample_rate=RATE).dt == DT
        A, dt = closed_loop_matrix(plant, sys, sample_rate=RATE)
        assert dt == DT and A.shape == (plant.nstates + 2, plant.nstates + 2)
    d = as_controller(cont, sample_rate=RATE)
    pole = (1 - 50 * DT / 2) / (1 + 50 * DT / 2)  # Tustin's image of s = -50
    assert d.Ac[0, 0] == pytest.approx(pole, rel=1e-12)


@pytest.mark.parametrize("kind", ["python_law", "protocol"])
def test_a_nonlinear_law_is_simulated_but_refused_by_linear_analyses(setup, plant, kind):
    """A Python law (and a protocol object) is accepted by ``as_controller`` as it is and
    simulated: its run is that of the static gain it computes (1e-9), not the open loop; the
    linear analyses refuse it with an ``InputError`` saying it is not linear."""
    _sc, loop, vf, _ = setup
    k = 2e4  # N m per rad of tip twist
    if kind == "python_law":
        law = python_law(lambda t, y: [-k * y[2]], CONTROLS, SENSORS, sample_rate=RATE)
    else:
        law = Protocol()
    assert as_controller(law, sample_rate=RATE) is law
    x0 = loop.initial_state(0.01)
    gain = static_gain([[0.0, 0.0, k]], CONTROLS, sensors=SENSORS, sample_rate=RATE)
    run = simulate(plant, law, duration=0.3, x0=x0)
    lin = simulate(plant, gain, duration=0.3, x0=x0)
    open_loop = simulate(plant, aes.design.OpenLoop(CONTROLS, DT), duration=0.3, x0=x0)
    hm = run.applied[HM]
    assert np.max(np.abs(hm)) > 1.0
    assert np.allclose(hm, lin.applied[HM], rtol=0, atol=1e-9 * np.max(np.abs(hm)))
    tip = run.outputs["tip_twist"]
    assert np.allclose(tip, lin.outputs["tip_twist"], rtol=0, atol=1e-9 * np.max(np.abs(tip)))
    assert not np.allclose(tip, open_loop.outputs["tip_twist"], rtol=1e-3)
    for entry in ("closed_loop_boundary", "closed_loop_matrix", "loop_margins", "judge_loop"):
        with pytest.raises(aes.InputError, match="not linear"):
            ENTRY_POINTS[entry](loop, plant, law)
