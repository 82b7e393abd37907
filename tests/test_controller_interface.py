"""Issue 24: one controller interface for every analysis.

Case: the Goland wing with aileron (``aes.examples.goland_aileron``), 10 elements, sea-level
density, hinge moment commanded, tip sensors (two accelerometers behind 30 Hz Butterworth filters
and the tip twist), sampled at 1000 Hz; open-loop flutter at 137.37 m/s. The references here are
computed in the tests: the closed loop assembled from the plant's own matrices sampled by a
zero-order hold written here (``scipy.linalg.expm``), and its dense eigenvalues.
"""

from __future__ import annotations

import json
import re
import shutil
import warnings

import control
import numpy as np
import pytest
import scipy.io
import scipy.linalg as sla
from conftest import ROOT
from ideal_loops import ideal, ideal_hinf_text, ideal_text

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
    sc = ideal(load_scenario(ROOT / "scenarios" / "goland_aileron_hinf.toml"))
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


def _parallel_pair(rng, Ac, Bc, Cc):
    """A lightly damped pole pair (3-40 Hz, 0.5-5 % damping) added in parallel."""
    f, zeta = rng.uniform(3.0, 40.0), rng.uniform(0.005, 0.05)
    z = np.exp((-zeta + 1j * np.sqrt(1 - zeta**2)) * 2 * np.pi * f * DT)
    Ae = np.array([[z.real, -z.imag], [z.imag, z.real]])
    Be = rng.standard_normal((2, 3)) * np.abs(Bc).max(axis=0) * rng.uniform(0.002, 0.03)
    Ce = rng.standard_normal((1, 2)) * np.abs(Cc).max()
    return sla.block_diag(Ac, Ae), np.vstack([Bc, Be]), np.hstack([Cc, Ce])


def random_compensator(rng, hinf, family: int):
    """``(A, B, C, D)`` of a random compensator from the shipped H-infinity one, its gain and
    sensors rescaled, its state transformed, and stable poles added: a filter in series on its
    command (family 0), a lightly damped pair in parallel (1), both (2); or a random static
    gain ``u = D y`` (family 3)."""
    Ac, Bc, Cc, Dc = (np.array(x, dtype=float) for x in hinf.compensator_matrices())
    if family == 3:
        K = rng.standard_normal((1, 3)) * np.array([1.0, 1.0, 1e4]) * np.exp(rng.uniform(-3, 3))
        return np.zeros((0, 0)), np.zeros((0, 3)), np.zeros((1, 0)), K
    gain = np.exp(rng.uniform(-1.2, 1.2))
    sens = np.exp(rng.uniform(-0.5, 0.5, size=3))
    Bc, Cc, Dc = Bc * sens, gain * Cc, gain * Dc * sens
    Ac, Bc, Cc = _similar(rng, Ac, Bc, Cc)
    if family >= 1:
        Ac, Bc, Cc = _parallel_pair(rng, Ac, Bc, Cc)
    if family != 1:
        Ac, Bc, Cc, Dc = _series((Ac, Bc, Cc, Dc), _random_filter(rng))
    return Ac, Bc, Cc, Dc


def as_given(mats, family: int):
    """The controller in one of the forms the analyses accept: a ``DiscreteCompensator``
    (family 0), a python-control ``StateSpace`` (1, 2), a ``static_gain`` (3)."""
    A, B, C, D = mats
    if family == 3:
        return static_gain(-D, CONTROLS, sensors=SENSORS, sample_rate=RATE)
    if family:
        return control.ss(A, B, C, D, DT, inputs=list(SENSORS), outputs=list(CONTROLS))
    return DiscreteCompensator(A, B, C, D, CONTROLS, SENSORS, DT)


@pytest.mark.slow
def test_random_compensators_boundary_matches_dense_eigenvalues(setup):
    """12 random linear controllers on the Goland-with-aileron plant (the shipped H-infinity
    compensator rescaled, its state transformed, random stable poles added: a filter in series,
    a lightly damped pair in parallel or both; random static gains on the sensors), given as a
    ``DiscreteCompensator``, a python-control ``StateSpace`` or a ``static_gain``, kept when
    stable at a reference speed (1.1 V_f; 0.7 V_f for the static gains). ``closed_loop_boundary`` finds
    exactly the crossings of the reference (the dense eigenvalues of the closed sampled loop
    assembled here, on a 301-point grid, each sign change bisected to 1e-6 relative), each to
    1e-5 relative, with its kind and frequency, and the same stable intervals."""
    _sc, loop, vf, hinf = setup
    ref = SampledReference(loop)
    v_min, v_max = 0.1 * vf, 2.0 * vf
    speeds = np.linspace(v_min, v_max, 301)
    rng = np.random.default_rng(20240624)
    kept, tries = [], 0
    while len(kept) < 12:  # three of each of the four families
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
            loop, as_given(mats, family), v_max, v_min=v_min, n_grid=31, reference_speed=v_ref
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
        got = b.stable_intervals
        assert len(got) == len(stable), what
        for (a, c), (a0, c0) in zip(got, stable, strict=True):
            assert (a, c) == pytest.approx((a0, c0), rel=1e-5), what
        n_cross.append(len(expected))
    print(
        f"12 controllers ({tries} drawn), crossings per controller {n_cross}: worst relative "
        f"speed error {worst:.2e}, worst frequency error {worst_freq:.2e} Hz"
    )


# -- 2. stable at the design speed, unstable lower: the verdict fails ---------------------------


def scenario_copy(tmp_path, scenario: str, *edits, controller: str | None = None):
    """A shipped scenario (and every shipped controller) copied to ``tmp_path`` and edited:
    ``(old, new)`` text replacements in the scenario file; ``controller`` replaces the text of
    the controller file it refers to by a new file ``controllers/brought.toml``. The copies are
    the ideal-actuator loops without delay (``ideal_loops``)."""
    shutil.copytree(ROOT / "scenarios", tmp_path / "scenarios", dirs_exist_ok=True)
    shutil.copytree(ROOT / "controllers", tmp_path / "controllers", dirs_exist_ok=True)
    hinf = tmp_path / "controllers" / "hinf.toml"  # the loops these tests were written for
    hinf.write_text(ideal_hinf_text(hinf.read_text()))
    path = tmp_path / "scenarios" / f"{scenario}.toml"
    text = ideal_text(path.read_text())
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


@pytest.mark.slow
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


WRONG_PERIOD = (
    r"the compensator is discrete with period 0\.002 s \(500 Hz\); the loop samples at 1000 Hz"
)


def _not_controllers():
    """``(id, object, message)``: things that are not controllers of a 1000 Hz loop, and a
    regular expression for the start of the message that refuses each."""
    A, B, C, D = np.array([[0.5]]), np.ones((1, 3)), np.ones((1, 1)), np.zeros((1, 3))
    named = {"inputs": list(SENSORS), "outputs": list(CONTROLS)}
    slow = Protocol()
    slow.dt = "fast"
    return [
        (
            "object",
            object(),
            r"controller = <object object .*>: expected a controller of aeroservo\.design",
        ),
        ("none", None, r"controller = None: expected a controller of aeroservo\.design"),
        ("string", "hinf", r"controller = 'hinf': expected a controller of aeroservo\.design"),
        (
            "dict",
            {"A": A, "B": B, "C": C, "D": D, "dt": DT},
            r"controller = \{'A': array.*: expected a controller of aeroservo\.design",
        ),
        (
            "array",
            np.ones((1, 3)),
            r"controller = array\(.*\): a gain matrix needs its signal names",
        ),
        ("list", [[1.0, 2.0, 3.0]], r"controller = \[\[1\.0, 2\.0, 3\.0\]\]: a gain matrix needs"),
        ("number", 5.0, r"controller = 5\.0: a gain matrix needs its signal names"),
        (
            "function",
            lambda t, y: [0.0],
            r"controller = <function .*: a Python function needs its signals",
        ),
        (
            "ss_unnamed",
            control.ss(A, B, C, D, DT),
            r"the compensator's inputs are not named \(\['u\[0\]', ",
        ),
        (
            "tf_unnamed",
            control.tf([1.0], [1.0, -0.5], DT),
            r"the compensator's inputs are not named \(\['u\[0\]'\]\)",
        ),
        ("ss_wrong_period", control.ss(A, B, C, D, 2 * DT, **named), WRONG_PERIOD),
        (
            "tf_wrong_period",
            control.tf([1.0], [1.0, -0.5], 2 * DT, inputs="tip_twist", outputs=HM),
            WRONG_PERIOD,
        ),
        ("protocol_bad_dt", slow, r"controller\.dt = 'fast': expected a sample period \[s\] > 0"),
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
@pytest.mark.parametrize(
    "obj,message", [c[1:] for c in NOT_CONTROLLERS], ids=[c[0] for c in NOT_CONTROLLERS]
)
def test_not_a_controller_is_an_input_error_everywhere(setup, plant, entry, obj, message):
    """Objects that are not controllers (an object, None, a string, a dict, a gain matrix or a
    function without signal names, python-control systems with unnamed signals or another
    sample period, a protocol object whose ``dt`` is not a period) are refused with an
    ``InputError`` (never an AttributeError or TypeError) by the simulator, the closed-loop
    boundary and matrix, the margins, the judgement and ``as_controller``, in one line."""
    with pytest.raises(aes.InputError, match=f"^{message}") as info:
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


# -- 4. anti-windup -----------------------------------------------------------------------------


def _integrator(plant, pole: float, anti_windup=None) -> DiscreteCompensator:
    """Integral action on the tip twist, ``s+ = pole s + dt twist``, ``c = -(ki / G0) s``
    (``G0`` the static twist per hinge moment, ki = 2 1/s); ``pole`` 1 is an integrator,
    above 1 an unstable compensator pole."""
    A, B = np.asarray(plant.A), np.asarray(plant.B)
    row = list(plant.output_labels).index("tip_twist")
    col = list(plant.input_labels).index(HM)
    G0 = float(-(np.asarray(plant.C)[row] @ np.linalg.solve(A, B[:, col])))
    return DiscreteCompensator(
        [[pole]], [[0.0, 0.0, DT]], [[-2.0 / G0]], np.zeros((1, 3)), CONTROLS, SENSORS, DT,
        anti_windup=anti_windup,
    )  # fmt: skip


def _steady_gust(t, speed):
    """A steady 5 m/s vertical gust: a persistent twist the integrator cannot remove through a
    tight hinge-moment limit."""
    return np.full(np.shape(t), 5.0)


@pytest.mark.parametrize("pole", [1.0, 1.0005], ids=["integrator", "unstable_pole"])
def test_anti_windup_bounds_the_commands_and_leaves_the_linear_loop_alone(setup, pole):
    """A compensator with an integrator (or an unstable pole) on the tip twist at 0.6 V_f, a
    steady gust and a hinge-moment limit at a fifth of what would cancel it: with the default
    anti-windup (``Ac - L Cc`` stable) the commands stay within twice the limit and
    ``windup()`` is empty (no warning), also with a computational delay; with
    ``anti_windup = 0`` the command runs away (``windup()`` reports it, ``simulate`` warns).
    With the limits far away the responses with and without anti-windup are identical (1e-12),
    with and without delay."""
    _sc, loop, vf, _ = setup
    plant = loop.plant(0.6 * vf)
    comp = _integrator(plant, pole)
    bare = _integrator(plant, pole, anti_windup=np.zeros((1, 1)))
    L = comp.anti_windup
    assert np.max(np.abs(np.linalg.eigvals(comp.Ac - L @ comp.Cc))) < 1.0
    A, _ = closed_loop_matrix(plant, comp)
    assert np.max(np.abs(np.linalg.eigvals(A))) < 1.0  # the linear loop is stable

    # what the hinge moment must be to cancel the gust's twist (linear run, no limits)
    free = simulate(plant, comp, duration=4.0, disturbance=_steady_gust)
    need = abs(free.commands[HM][-1])
    if pole == 1.0:  # integral action removes the twist
        twist = free.outputs["tip_twist"]
        assert abs(twist[-1]) < 1e-3 * np.max(np.abs(twist))
    tight = Limits(magnitude={HM: 0.2 * need})
    for delay in (False, True):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            r = simulate(
                plant, comp, duration=4.0, disturbance=_steady_gust, limits=tight, delay=delay
            )
        assert r.windup() == {}
        assert r.saturated_fraction[HM] > 0.9
        assert np.max(np.abs(r.commands[HM])) < 2 * 0.2 * need
        with pytest.warns(RuntimeWarning, match="windup"):
            w = simulate(
                plant, bare, duration=4.0, disturbance=_steady_gust, limits=tight, delay=delay
            )
        wound = w.windup()
        assert set(wound) == {HM} and wound[HM]["ratio"] > 10
        cmd = np.abs(w.commands[HM])
        assert cmd[-1] == np.max(cmd)  # still running away at the end

    far = Limits(magnitude={HM: 1e9}, rate={HM: 1e12})
    for delay in (False, True):
        a, b = (
            simulate(
                plant, c, duration=2.0, disturbance=_steady_gust, limits=far, delay=delay,
                record_states=True,
            )
            for c in (comp, bare)
        )  # fmt: skip
        assert np.array_equal(a.commands[HM], a.applied[HM])  # no limit acts
        # identical but for the round-off of L (u - c) = L u - L c, u = c, over 2000 samples
        for x, y, tol in (
            (a.states, b.states, 1e-12),
            (a.commands[HM], b.commands[HM], 1e-12),
            *((a.outputs[n], b.outputs[n], 1e-11) for n in a.outputs),
        ):
            assert np.max(np.abs(x - y)) <= tol * np.max(np.abs(x))


# -- 5. controller files: linear (.npz, .mat), gain, python -------------------------------------


def save_npz(path, mats, dt, **change):
    """A compensator saved the python-control way; ``change``: variables replaced (None: left
    out)."""
    A, B, C, D = mats
    data = {"A": A, "B": B, "C": C, "D": D, "dt": dt}
    data.update({"inputs": list(SENSORS), "outputs": list(CONTROLS)})
    data.update(change)
    np.savez(path, **{k: v for k, v in data.items() if v is not None})
    return path


def save_mat(path, mats, Ts, inputs=SENSORS, **change):
    """A compensator saved the MATLAB way, ``save('k.mat', 'A', 'B', 'C', 'D', 'Ts',
    'InputName', 'OutputName')``, the names as cell arrays; ``change`` as for
    :func:`save_npz`."""
    A, B, C, D = mats
    data = {"A": A, "B": B, "C": C, "D": D, "Ts": float(Ts)}
    data["InputName"] = np.array(list(inputs), dtype=object)
    data["OutputName"] = np.array(list(CONTROLS), dtype=object)
    data.update(change)
    scipy.io.savemat(path, {k: v for k, v in data.items() if v is not None})
    return path


def linear_spec(file: str, **keys) -> str:
    text = f'type = "linear"\nname = "brought"\nfile = "{file}"\n'
    keys = {"sign": 1} | keys  # the compensator's output is the command (python-control's K)
    return text + "".join(f"{k} = {json.dumps(v)}\n" for k, v in keys.items())


def inverse_tustin(mats, dt: float = DT):
    """A continuous compensator whose Tustin discretisation at ``dt`` is ``mats``
    (``z = (1 + s dt/2) / (1 - s dt/2)``; ``P = I + Ad``): ``A = (2/dt) P^-1 (Ad - I)``,
    ``B = P^-1 Bd``, ``C = (4/dt) Cd P^-1``, ``D = Dd - Cd P^-1 Bd``."""
    Ad, Bd, Cd, Dd = mats
    n = Ad.shape[0]
    Pi = np.linalg.inv(np.eye(n) + Ad)
    return (2 / dt) * Pi @ (Ad - np.eye(n)), Pi @ Bd, (4 / dt) * Cd @ Pi, Dd - Cd @ Pi @ Bd


def discrete_response(mats, f: np.ndarray, dt: float = DT) -> np.ndarray:
    """``C (zI - A)^-1 B + D`` at ``z = exp(j 2 pi f dt)``, shape ``(len(f), m, p)``."""
    A, B, C, D = mats
    z = np.exp(2j * np.pi * f * dt)
    n = A.shape[0]
    return np.array([C @ np.linalg.solve(zk * np.eye(n) - A, B) + D for zk in z])


def continuous_response(mats, f: np.ndarray) -> np.ndarray:
    A, B, C, D = mats
    n = A.shape[0]
    return np.array([C @ np.linalg.solve(2j * np.pi * fk * np.eye(n) - A, B) + D for fk in f])


FREQS = np.array([0.5, 2.0, 7.0, 11.0, 13.0, 25.0, 49.0, 120.0, 400.0])  # Hz, below Nyquist


def assert_same_numbers(a, b, rel: float, path: str = "") -> None:
    """Two JSON-like trees hold the same numbers (to ``rel``) and the same other values; the
    ``law`` entries (what the controller is called) are not compared."""
    if isinstance(a, dict):
        assert set(a) == set(b), path
        for k in a:
            if k != "law":
                assert_same_numbers(a[k], b[k], rel, f"{path}.{k}")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same_numbers(x, y, rel, f"{path}[{i}]")
    elif isinstance(a, float) and not isinstance(b, bool):
        assert b == pytest.approx(a, rel=rel, abs=1e-12), path
    else:
        assert a == b, path


@pytest.fixture(scope="module")
def builtin_hinf_run():
    """The shipped H-infinity scenario, quick settings."""
    return run_simulation(
        ideal(quick(load_scenario(ROOT / "scenarios" / "goland_aileron_hinf.toml")))
    )


def _brought(path):
    """The controller a scenario's controller file brings (at the scenario's loop)."""
    sc = quick(load_scenario(path))
    loop = sc.loop()
    return sc, loop.design_controller(sc.controller, 100.0, sc.sample_rate, VF)


@pytest.mark.slow
def test_brought_hinf_gives_the_margins_and_boundary_of_the_builtin_one(
    setup, builtin_hinf_run, tmp_path
):
    """The shipped H-infinity compensator saved to a ``.npz`` (python-control's way) and to a
    ``.mat`` (MATLAB's: ``Ts``, ``InputName``/``OutputName`` cell arrays) and brought by a
    controller file of type ``linear``: the scenario runs give the same margins, closed-loop
    boundary, engaged-range judgement and time histories as the built-in design (1e-9); saved
    continuous (``Ts = 0``, the inverse Tustin map) and brought with ``method = "tustin"`` it is
    the same compensator (frequency response 1e-9) with the same boundary and margins (1e-6)."""
    _sc, _loop, _vf, hinf = setup
    mats = hinf.compensator_matrices()
    ref = builtin_hinf_run
    save_npz(tmp_path / "k.npz", mats, DT)
    save_mat(tmp_path / "k.mat", mats, DT)
    save_mat(tmp_path / "kc.mat", inverse_tustin(mats), 0.0)
    H = discrete_response(mats, FREQS)
    for i, (file, rel) in enumerate((("k.npz", 1e-9), ("k.mat", 1e-9), ("kc.mat", 1e-6))):
        spec = linear_spec(f"../../{file}", method="tustin")
        path = scenario_copy(tmp_path / f"s{i}", "goland_aileron_hinf", controller=spec)
        _, brought = _brought(path)
        assert brought.info["continuous"] is (file == "kc.mat")
        Hb = discrete_response(brought.compensator_matrices(), FREQS)
        assert np.max(np.abs(Hb - H)) <= 1e-9 * np.max(np.abs(H))
        run = run_simulation(quick(load_scenario(path)))
        s = run.summary
        assert s["controller_type"] == "linear" and s["verdict"] == "stable" and s["passed"]
        for key in ("margins", "closed_loop", "engaged", "margin_sweep"):
            assert_same_numbers(ref.summary[key], s[key], rel, key)
        for name, y in ref.simulation.outputs.items():
            y2 = run.simulation.outputs[name]
            assert np.max(np.abs(y2 - y)) <= rel * np.max(np.abs(y)), name


def _own_zoh(mats, dt: float = DT):
    """The compensator discretised by a zero-order hold written here."""
    A, B, C, D = mats
    n, p = B.shape
    M = np.zeros((n + p, n + p))
    M[:n, :n], M[:n, n:] = A, B
    E = sla.expm(M * dt)
    return E[:n, :n], E[:n, n:], C, D


def _tustin_response(cont, f: np.ndarray, prewarp: float | None = None, dt: float = DT):
    """The response at ``f`` [Hz] of the Tustin discretisation of a continuous compensator:
    the continuous response at ``c tan(pi f dt)`` [rad/s], ``c = 2 / dt`` (or
    ``w0 / tan(w0 dt / 2)``, exact at the prewarp frequency ``w0``)."""
    c = 2 / dt if prewarp is None else 2 * np.pi * prewarp / np.tan(np.pi * prewarp * dt)
    return continuous_response(cont, c * np.tan(np.pi * f * dt) / (2 * np.pi))


def test_continuous_compensator_is_discretised_by_the_method_of_its_file(setup, tmp_path):
    """A continuous compensator (``dt = 0`` in a ``.npz``, ``Ts = 0`` in a ``.mat``) is
    discretised at the loop's rate by the file's ``method``: ``zoh`` gives the zero-order hold
    computed here, ``tustin`` (the default) the bilinear map, with ``prewarp`` exact at that
    frequency (frequency responses to 1e-9); ``sign = -1`` negates the output; MATLAB's
    ``Ts = -1`` (unspecified) is discrete at the loop's period; the anti-windup gain is zero
    unless ``anti_windup = true`` (issue 38: the measured default of a compensator)."""
    _sc, _loop, _vf, hinf = setup
    mats = hinf.compensator_matrices()
    cont = inverse_tustin(mats)
    H = discrete_response(mats, FREQS)
    # the inverse map is right: its Tustin image is the H-infinity compensator
    assert np.max(np.abs(_tustin_response(cont, FREQS) - H)) <= 1e-9 * np.max(np.abs(H))
    A, B, C, D = cont
    save_npz(tmp_path / "c.npz", cont, 0.0)
    save_npz(tmp_path / "neg.npz", (A, B, -C, -D), 0.0)
    save_mat(tmp_path / "c.mat", cont, 0.0)
    save_mat(tmp_path / "free.mat", mats, -1.0)
    zoh = discrete_response(_own_zoh(cont), FREQS)
    cases = [
        ("c.npz", {"method": "zoh"}, zoh),
        ("c.mat", {"method": "zoh"}, zoh),
        ("c.npz", {}, H),
        ("neg.npz", {"sign": -1}, H),
        ("c.mat", {"method": "tustin", "prewarp": 11.0}, _tustin_response(cont, FREQS, 11.0)),
        ("free.mat", {"anti_windup": False}, H),
        ("free.mat", {"anti_windup": True}, H),
    ]
    for file, keys, expected in cases:
        spec = linear_spec(f"../../{file}", **keys)
        path = scenario_copy(tmp_path / "s", "goland_aileron_hinf", controller=spec)
        _, brought = _brought(path)
        got = discrete_response(brought.compensator_matrices(), FREQS)
        assert np.max(np.abs(got - expected)) <= 1e-9 * np.max(np.abs(expected)), (file, keys)
        assert brought.dt == DT
        # anti-windup: off unless the file asks (the measured default of a compensator)
        assert bool(np.any(brought.anti_windup)) is keys.get("anti_windup", False), (file, keys)
        if "prewarp" in keys:  # exact at the prewarp frequency
            f0 = np.array([keys["prewarp"]])
            Hc = continuous_response(cont, f0)
            Hd = discrete_response(brought.compensator_matrices(), f0)
            assert np.max(np.abs(Hd - Hc)) <= 1e-9 * np.max(np.abs(Hc))


TWIST_GAIN = [[-0.5, -0.5, 2.0e4]]  # N m per (m/s^2, m/s^2, rad): u = -K y
LAW_PY = """\
K = {K}


def law(t, y):
    \"\"\"A twist and acceleration feedback, u = -K y.\"\"\"
    return [-sum(k * v for k, v in zip(K[0], y))]
"""


def test_gain_and_python_controller_files_run_in_a_scenario(setup, tmp_path):
    """A controller file of type ``gain`` (``u = -K y`` on named sensors) and one of type
    ``python`` (a function in a ``.py`` file computing the same law) run in the H-infinity
    scenario at 0.8 V_f: the gain's loop has the spectral radius of the reference loop
    assembled here (1e-12) and is judged by its eigenvalues and margins; the Python law is
    simulated (the same time histories as the gain, 1e-9), judged by time marching across the
    engaged range, and has no margins."""
    _sc, loop, vf, _ = setup
    gain = (
        'type = "gain"\nname = "twist gain"\nsign = -1\n[gain]\ncontrols = ["aileron_hinge_moment"]\n'
        f"sensors = {json.dumps(list(SENSORS))}\nmatrix = {json.dumps(TWIST_GAIN)}\n"
    )
    (tmp_path / "law.py").write_text(LAW_PY.format(K=TWIST_GAIN))
    python = 'type = "python"\nname = "law"\nfile = "../../law.py"\nfunction = "law"\n'
    runs = {}
    for kind, text in (("gain", gain), ("python", python)):
        path = scenario_copy(
            tmp_path / kind,
            "goland_aileron_hinf",
            ("speed_factor = 1.1", "speed_factor = 0.8"),
            controller=text,
        )
        runs[kind] = run_simulation(quick(load_scenario(path)))
    g, p = runs["gain"].summary, runs["python"].summary
    assert g["controller_type"] == "gain" and p["controller_type"] == "python"
    speed = g["speed"]
    assert speed == pytest.approx(0.8 * vf, rel=1e-9)
    mats = (np.zeros((0, 0)), np.zeros((0, 3)), np.zeros((1, 0)), -np.array(TWIST_GAIN))
    rho = 1.0 + SampledReference(loop).measure(speed, mats)
    assert g["spectral_radius"] == pytest.approx(rho, rel=1e-12) and rho < 1.0
    assert g["verdict"] == "stable" and "margins" in g and "margin_sweep" in g
    assert p["spectral_radius"] is None and "margins" not in p
    assert "time marching" in p["engaged"]["method"]
    assert p["engaged"]["margins_over_range"]["meets"] is None
    gs, ps = runs["gain"].simulation, runs["python"].simulation
    hm = gs.applied[HM]
    assert np.max(np.abs(hm)) > 10.0  # the law acts
    assert np.max(np.abs(ps.applied[HM] - hm)) <= 1e-9 * np.max(np.abs(hm))
    for name, y in gs.outputs.items():
        assert np.max(np.abs(ps.outputs[name] - y)) <= 1e-9 * np.max(np.abs(y)), name


def _fake_v73(path):
    """The 128-byte header of a MATLAB v7.3 (HDF5) file and the HDF5 signature."""
    text = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jun 24 12:00:00 2024 HDF5"
    path.write_bytes(text.ljust(116, b" ") + b"\0" * 8 + b"\0\2IM" + b"\x89HDF\r\n\x1a\n")
    return path


def _bad_files(tmp_path, mats):
    """``(controller file text, words the error must hold)`` for bad brought controllers."""
    A, B, C, D = mats
    n = A.shape[0]
    save_npz(tmp_path / "no_b.npz", mats, DT, B=None)
    save_npz(tmp_path / "shape.npz", mats, DT, B=B[:-1])
    save_npz(tmp_path / "text.npz", mats, DT, A=np.array([["a"] * n] * n))
    save_npz(tmp_path / "unnamed.npz", mats, DT, inputs=None)
    save_mat(tmp_path / "unnamed.mat", mats, DT, OutputName=None)
    save_mat(tmp_path / "count.mat", mats, DT, inputs=SENSORS[:2])
    save_mat(tmp_path / "ts.mat", mats, -0.5)
    save_npz(tmp_path / "ok.npz", mats, DT)
    _fake_v73(tmp_path / "v73.mat")
    (tmp_path / "k.txt").write_text("A = 1\n")
    return [
        (linear_spec("no_b.npz"), ["no_b.npz", "file = ", "variable B is missing"]),
        (linear_spec("shape.npz"), ["shape.npz", "variable B has shape", f"({n - 1}, 3)"]),
        (linear_spec("text.npz"), ["text.npz", "variable A"]),
        (linear_spec("unnamed.npz"), ["unnamed.npz", "inputs have no names", "InputName"]),
        (linear_spec("unnamed.mat"), ["unnamed.mat", "outputs have no names", "OutputName"]),
        (linear_spec("count.mat"), ["count.mat", "InputName has 2 names; D has 3 inputs"]),
        (linear_spec("ts.mat"), ["ts.mat", "Ts = -0.5"]),
        (linear_spec("v73.mat"), ["v73.mat", "v7.3", "-v7"]),
        (linear_spec("k.txt"), ["k.txt", "expected a .npz or .mat file"]),
        (linear_spec("missing.npz"), ["missing.npz", "no such file"]),
        (linear_spec("ok.npz", method="euler"), ["method = 'euler'", "tustin"]),
        (linear_spec("ok.npz", sign=2), ["sign = 2", "[-1, 1]"]),
        (linear_spec("ok.npz", anti_windup=1), ["anti_windup = 1", "expected true or false"]),
        (
            'type = "gain"\nsign = "minus"\n[gain]\ncontrols = ["aileron_hinge_moment"]\n'
            'sensors = ["tip_twist"]\nmatrix = [[1.0]]\n',
            ["sign = 'minus'"],
        ),
        (
            'type = "gain"\nsign = -1\nanti_windup = true\n[gain]\n'
            'controls = ["aileron_hinge_moment"]\nsensors = ["tip_twist"]\nmatrix = [[1.0]]\n',
            ["anti_windup = True", "a static gain has no state to wind up"],
        ),
        (linear_spec("ok.npz", sign=0), ["sign"]),
        (linear_spec("ok.npz", function="f"), ["function", "not used by a controller of type"]),
        ('type = "linear"\n', ["file", "missing"]),
        (
            'type = "gain"\nsign = -1\n[gain]\ncontrols = ["aileron_hinge_moment"]\n'
            'sensors = ["tip_twist"]\nmatrix = [[1.0, 2.0]]\n',
            ["gain.matrix", "row 0: expected 1 numbers"],
        ),
        (
            'type = "gain"\nsign = -1\n[gain]\ncontrols = ["aileron_hinge_moment"]\nmatrix = [[1.0]]\n',
            ["gain.sensors", "give sensors or states"],
        ),
        ('type = "python"\nfile = "law.py"\nfunction = "law"\n', ["file", "law.py"]),
        ('type = "python"\nfile = "ok.npz"\n', ["function", "missing"]),
    ]


def test_bad_controller_files_are_one_line_input_errors(setup, tmp_path):
    """Bad brought controllers (a variable missing, of the wrong shape or not numeric, signal
    names missing or miscounted, a negative sample time, a MATLAB v7.3 file, a file that is
    neither .npz nor .mat or does not exist, an unknown method, a bad sign, a key another type
    uses, a gain matrix of the wrong width, a Python file that does not exist) are refused when
    the controller file is read, by a one-line ``InputError`` naming the controller file, the
    data file and the variable or key at fault."""
    from aeroservo.files import load_controller

    for i, (text, words) in enumerate(_bad_files(tmp_path, setup[3].compensator_matrices())):
        path = tmp_path / f"bad{i}.toml"
        path.write_text(text)
        with pytest.raises(aes.InputError, match=re.escape(f"bad{i}.toml: ")) as info:
            load_controller(path)
        message = str(info.value)
        assert "\n" not in message and f"bad{i}.toml" in message, message
        for w in words:
            assert w in message, (w, message)


def test_brought_compensator_errors_at_design_name_the_controller_file(setup, tmp_path):
    """A discrete compensator saved at another sample period than the loop's, a prewarp with
    the ``zoh`` method, signal names the loop does not have, and the matched pole-zero method
    for a compensator of three sensors are refused when the scenario's controller is brought,
    naming the controller file."""
    mats = setup[3].compensator_matrices()
    save_npz(tmp_path / "slow.npz", mats, 2 * DT)
    save_npz(tmp_path / "cont.npz", inverse_tustin(mats), 0.0)
    save_npz(tmp_path / "yaw.npz", mats, DT, inputs=["tip_le_accel", "tip_te_accel", "tip_yaw"])
    for i, (text, words) in enumerate(
        (
            (linear_spec("../../slow.npz"), ["period 0.002 s", "discretise it again"]),
            (linear_spec("../../cont.npz", method="zoh", prewarp=10.0), ["prewarp", "zoh"]),
            (linear_spec("../../yaw.npz"), ["tip_yaw"]),
            (linear_spec("../../cont.npz", method="matched"), ["matched", "SISO"]),
        )
    ):
        path = scenario_copy(tmp_path / f"s{i}", "goland_aileron_hinf", controller=text)
        with pytest.raises(aes.InputError, match=re.escape(words[0])) as info:
            _brought(path)
        message = str(info.value)
        assert "\n" not in message and "brought.toml" in message, message
        for w in words:
            assert w in message, (w, message)


# -- bugs found while writing these tests (fixed in src) ----------------------------------------


@pytest.mark.parametrize(
    "change",
    [
        pytest.param({"dt": "fast"}, id="text_sample_time"),
        pytest.param({"dt": np.array([])}, id="empty_sample_time"),
        pytest.param({"A": np.eye(1) * (0.5 + 0.1j)}, id="complex_matrix"),
    ],
)
def test_bad_numbers_in_a_compensator_file_are_input_errors(tmp_path, change):
    """A sample time that is text or empty, or a complex matrix, in a compensator file is an
    ``InputError`` naming the file and the variable (not a ValueError or IndexError, and not a
    complex matrix silently made real)."""
    from aeroservo.files.linear_controller import read_linear_controller

    mats = (np.eye(1) * 0.5, np.ones((1, 3)), np.ones((1, 1)), np.zeros((1, 3)))
    key = next(iter(change))
    change = dict(change)
    path = save_npz(tmp_path / "k.npz", mats, change.pop("dt", DT), **change)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(aes.InputError, match=f"k.npz: .*{key}"):
            read_linear_controller(path)


def test_truncated_mat_file_is_an_input_error(tmp_path):
    """An empty (or truncated) ``.mat`` file is an ``InputError`` naming it, as a ``.mat``
    file of an unknown version is."""
    from aeroservo.files.linear_controller import read_linear_controller

    (tmp_path / "k.mat").write_bytes(b"")
    with pytest.raises(aes.InputError, match="k.mat"):
        read_linear_controller(tmp_path / "k.mat")


@pytest.mark.parametrize("out", [np.zeros(2), "abc"], ids=["two_commands", "text"])
def test_protocol_controller_returning_bad_commands_is_an_input_error(setup, plant, out):
    """A protocol object whose ``command`` returns the wrong number of commands, or text, is
    refused by ``simulate`` with an ``InputError``, as a ``python_law`` returning them is."""
    bad = Protocol()
    bad.command = lambda y, x=None: out
    with pytest.raises(
        aes.InputError,
        match=re.escape(f"controller Protocol: command returned {out!r}; expected 1 number(s)"),
    ):
        simulate(plant, bad, duration=0.01)


def schedule_compensator() -> control.StateSpace:
    """The python-control compensator ``ScheduleLike.at`` returns at every speed."""
    return control.ss(
        [[0.5]], [[0.0, 0.0, 1.0]], [[1.0]], [[0.0, 0.0, 0.0]], DT,
        inputs=list(SENSORS), outputs=list(CONTROLS),
    )  # fmt: skip


class ScheduleLike:
    """A gain schedule written by a user: ``at(speed)`` returns a python-control compensator
    (the speeds it was asked for are kept in ``speeds``)."""

    dt = DT
    controls = CONTROLS

    def __init__(self):
        self.speeds: list[float] = []

    def at(self, speed):
        self.speeds.append(float(speed))
        return schedule_compensator()


@pytest.mark.parametrize("entry", ["simulate", "closed_loop_matrix"])
def test_schedule_like_object_runs_as_its_compensator_at_the_plant_speed(setup, plant, entry):
    """A schedule-like object (``dt``, ``controls`` and ``at(speed)`` returning a
    python-control compensator) is evaluated at the plant's speed (1.1 V_f) and then runs as
    the compensator it returns there: the same time history (from a disturbed state, so that
    the commands are not zero) and the same closed-loop matrix as that compensator's."""
    schedule = ScheduleLike()
    if entry == "simulate":
        x0 = np.full(plant.nstates, 1e-3)
        got, ref = (
            simulate(plant, c, duration=0.01, sample_rate=RATE, x0=x0)
            for c in (schedule, schedule_compensator())
        )
        assert np.abs(ref.commands[HM]).max() > 0.0
        for name in (*SENSORS, "root_bending_moment"):
            np.testing.assert_array_equal(got.outputs[name], ref.outputs[name])
        np.testing.assert_array_equal(got.commands[HM], ref.commands[HM])
    else:
        got, ref = (
            closed_loop_matrix(plant, c, sample_rate=RATE)
            for c in (schedule, schedule_compensator())
        )
        np.testing.assert_array_equal(got[0], ref[0])
        assert got[1] == ref[1] == DT
    assert schedule.speeds and schedule.speeds == pytest.approx(
        [1.1 * setup[2]] * len(schedule.speeds), rel=1e-12
    )


def test_one_sign_rule_for_gain_and_linear_files(tmp_path):
    """Issue 38: a ``gain`` and a ``linear`` file mean the same thing, ``u = sign K y``: the
    same matrix with the same sign is the same law (its D, the static compensator's only
    matrix, equal to ``sign K``), and a file without ``sign`` is refused in one line naming
    the key (a gain file used to mean -1 and a linear one +1 without saying it)."""
    K = np.array(TWIST_GAIN)
    np.savez(
        tmp_path / "k.npz",
        A=np.zeros((0, 0)),
        B=np.zeros((0, 3)),
        C=np.zeros((1, 0)),
        D=K,
        dt=DT,
        inputs=np.array(SENSORS),
        outputs=np.array(CONTROLS),
    )
    gain_text = (
        'type = "gain"\nname = "g"\nsign = {s}\n[gain]\ncontrols = ["aileron_hinge_moment"]\n'
        f"sensors = {json.dumps(list(SENSORS))}\nmatrix = {json.dumps(TWIST_GAIN)}\n"
    )
    laws = {}
    for sign in (1, -1):
        for kind, text in (
            ("gain", gain_text.format(s=sign)),
            ("linear", linear_spec(str(tmp_path / "k.npz"), sign=sign)),
        ):
            path = scenario_copy(tmp_path / f"{kind}{sign}", "goland_aileron_hinf", controller=text)
            _sc, ctrl = _brought(path)
            laws[kind, sign] = np.asarray(ctrl.law().D)
        np.testing.assert_array_equal(laws["gain", sign], laws["linear", sign])
        np.testing.assert_array_equal(laws["gain", sign], sign * K)
    # the Python interface: static_gain's sign, -1 by default (control.lqr's K)
    g = static_gain(K, CONTROLS, sensors=SENSORS, sample_rate=RATE)
    np.testing.assert_array_equal(g.law().D, -K)
    g = static_gain(K, CONTROLS, sensors=SENSORS, sample_rate=RATE, sign=1)
    np.testing.assert_array_equal(g.law().D, K)
    with pytest.raises(aes.InputError, match="sign = 0"):
        static_gain(K, CONTROLS, sensors=SENSORS, sample_rate=RATE, sign=0)
    for kind, text in (
        ("gain", gain_text.replace("sign = {s}\n", "")),
        ("linear", linear_spec(str(tmp_path / "k.npz")).replace("sign = 1\n", "")),
    ):
        path = scenario_copy(tmp_path / f"nosign_{kind}", "goland_aileron_hinf", controller=text)
        with pytest.raises(
            aes.InputError, match=r"brought\.toml: sign: .*give sign = 1 .* or sign = -1"
        ):
            load_scenario(path)


def test_gain_bounds_and_unknown_states_name_the_file(tmp_path):
    """Issue 40: a gain of 1e300 through the API is refused as the file type refuses it, and
    a gain file on states the plant does not have names the file (it named nothing)."""
    with pytest.raises(aes.InputError, match=r"K has an entry of 1e\+300 in magnitude: at most"):
        static_gain([[1e300]], CONTROLS, sensors=["tip_twist"], sample_rate=RATE)
    text = (
        'type = "gain"\nname = "g"\nsign = -1\n[gain]\ncontrols = ["aileron_hinge_moment"]\n'
        'states = ["w_3", "no_such_state"]\nmatrix = [[1.0, 2.0]]\n'
    )
    path = scenario_copy(tmp_path / "s", "goland_aileron_hinf", controller=text)
    with pytest.raises(
        aes.InputError,
        match=r"brought\.toml: gain\.states = \['w_3', 'no_such_state'\]: \['no_such_state'\] "
        r"are not states of the plant",
    ) as info:
        _brought(path)
    message = str(info.value)
    assert "brought.toml" in message and "no_such_state" in message, message
    assert "not states of the plant" in message and "\n" not in message
