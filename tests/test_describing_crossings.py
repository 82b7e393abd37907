"""Crossings the count of growing roots does not see, and branches that stop (issue 40 item 4;
:mod:`aeroservo.stability.describing_checks`).

1. Synthetic loops and systems whose rates are set here: two root pairs crossing in opposite
   directions within one grid interval (the number of growing roots is the same at both ends)
   are both found, at the speeds a fine grid finds; crossings closer than the bisections can
   separate are said in a note.
2. The Goland LQR loop with 1 deg of freeplay at 0.62 gap: the 11.5 Hz root recovers at
   130.27 m/s and the buzz starts at 134.2 m/s; on a grid of 5 m/s both fall in [130, 135]
   and were missed. Against the same amplitude on a 0.25 m/s grid.
3. The buzz branch is flat (its speed moves 10 m/s per 0.01 gap near 0.65 gap): where it
   stops, a note names the amplitude, the speed and why.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

import aeroservo as aes
from aeroservo.design import ControlLoop
from aeroservo.design import hinge_describing as hd
from aeroservo.design.hinge_describing import loop_describing_branches
from aeroservo.files import load_controller
from aeroservo.stability import equivalent_system as es
from aeroservo.stability.describing_checks import search_intervals, stop_notes
from aeroservo.structure.hinge_laws import Freeplay
from aeroservo.system.hinge_elements import NonlinearHinge

DT = 1e-3


def rotation(r: float, f: float) -> np.ndarray:
    th = 2 * np.pi * f * DT
    return r * np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])


class SyntheticLoop:
    """A sampled loop with a rising pair (22 Hz, rate ``0.1 (V - v_up)`` 1/s) and a falling
    pair (11.4 Hz, rate ``-0.1 (V - v_down)``), and a damped real root."""

    dt = DT
    rates = hd.EquivalentLoop.rates

    def __init__(self, v_up: float, v_down: float):
        self.v_up, self.v_down = v_up, v_down

    def matrices(self, speeds, dk, keep=False):
        out = np.zeros((len(speeds), 5, 5))
        for i, v in enumerate(speeds):
            out[i, :2, :2] = rotation(np.exp(0.1 * (v - self.v_up) * DT), 22.0)
            out[i, 2:4, 2:4] = rotation(np.exp(-0.1 * (v - self.v_down) * DT), 11.4)
            out[i, 4, 4] = 0.5
        return out


class SyntheticSystem:
    """The continuous counterpart: roots ``0.1 (V - v_up) +- 138j``, ``-0.1 (V - v_down) +-
    71.6j`` and -3 [1/s]."""

    def __init__(self, v_up: float, v_down: float):
        self.v_up, self.v_down = v_up, v_down

    def matrix(self, base, v):
        M = np.zeros((5, 5))
        M[:2, :2] = [[0.1 * (v - self.v_up), -138.0], [138.0, 0.1 * (v - self.v_up)]]
        s = -0.1 * (v - self.v_down)
        M[2:4, 2:4] = [[s, -71.6], [71.6, s]]
        M[4, 4] = -3.0
        return M

    def eigvals(self, base, speeds):
        return np.linalg.eigvals(np.array([self.matrix(base, v) for v in speeds]))


def loop_crossings(eq, speeds, notes=None):
    return [(v, np.angle(mu) / (2 * np.pi * DT)) for v, mu, _ in hd.crossings(eq, None, speeds,
            1e-10, notes=notes)]  # fmt: skip


def system_crossings(eq, speeds, notes=None):
    return [(v, lam.imag) for v, lam, _ in es.crossings(eq, None, np.asarray(speeds), 1e-10,
            notes)]  # fmt: skip


# 1. Synthetic ---------------------------------------------------------------------------------
@pytest.mark.parametrize(("v_up", "v_down"), [(130.7, 130.3), (129.9, 131.3), (131.45, 129.52)])
@pytest.mark.parametrize("kind", ["loop", "system"])
def test_two_roots_crossing_within_one_interval_are_found(kind, v_up, v_down):
    """The grid [129.5, 131.5] m/s: the count of growing roots is 2 at both ends (the old
    method found nothing); both crossings are found at the speeds and frequencies of a grid
    of 0.05 m/s (1e-9), with no note."""
    eq = SyntheticLoop(v_up, v_down) if kind == "loop" else SyntheticSystem(v_up, v_down)
    find = loop_crossings if kind == "loop" else system_crossings
    coarse = [129.5, 131.5]
    if kind == "loop":
        rates = eq.rates(eq.matrices(coarse, None))
    else:
        rates = eq.eigvals(None, np.array(coarse)).real
    assert (rates[0] > 0).sum() == (rates[1] > 0).sum() == 2
    notes: list[str] = []
    got = sorted(find(eq, coarse, notes))
    ref = sorted(find(eq, np.linspace(129.5, 131.5, 41)))
    assert len(got) == len(ref) == 2 and notes == []
    np.testing.assert_allclose(got, ref, rtol=1e-9)
    np.testing.assert_allclose([v for v, _ in got], sorted([v_up, v_down]), rtol=1e-9)


@pytest.mark.parametrize("kind", ["loop", "system"])
def test_crossings_too_close_to_separate_are_noted(kind):
    """0.6 mm/s apart: the bisections (6, down to 3.1 cm/s) do not separate them; a note names
    the interval and says to refine the speeds."""
    eq = (
        SyntheticLoop(130.5013, 130.5007) if kind == "loop" else SyntheticSystem(130.5013, 130.5007)
    )
    find = loop_crossings if kind == "loop" else system_crossings
    notes: list[str] = []
    assert find(eq, [129.5, 131.5], notes) == []
    assert notes == ["two roots cross within [130.5, 130.531] m/s: refine speeds"]


def test_agreeing_intervals_are_the_count_alone():
    """Where every root's own sign change agrees with the count, the intervals are the grid
    intervals where the count changes, with no bisection."""
    eq = SyntheticLoop(130.7, 125.0)
    speeds = np.linspace(120.0, 140.0, 11)
    w = np.linalg.eigvals(eq.matrices(speeds, None))
    calls = []

    def at(v):
        calls.append(v)
        return np.linalg.eigvals(eq.matrices([v], None)[0])

    found, lost = search_intervals(speeds, w, lambda r: np.abs(r) > 1.0, at)
    assert calls == [] and lost == []
    assert found == [(124.0, 126.0, 2, 0), (130.0, 132.0, 0, 2)]


def test_stop_notes_name_a_flat_branch():
    """A branch whose speed moved by more than 5 % over its last step and that stops before the
    last amplitude: one note; one that moves little or reaches the last amplitude: none; two of
    one frequency that stop together, their speeds converging (a fold in amplitude, flat or
    not): none; one whose extrapolated speed is off the grid: none (a note on a wider grid)."""

    class P:
        def __init__(self, speed, frequency):
            self.speed, self.frequency = speed, frequency

    gap = 0.02
    amps = gap * np.array([0.63, 0.64, 0.65, 0.66, 0.67])
    points = [
        [P(140.0, 23.7), P(130.2, 11.49), P(150.0, 31.0), P(120.0, 31.2), P(150.0, 40.0)],
        [P(147.3, 24.9), P(130.2, 11.48), P(145.0, 31.1), P(125.0, 31.3), P(145.0, 40.0)],
        [P(156.9, 26.3), P(130.2, 11.48), P(138.0, 31.2), P(132.0, 31.3), P(130.0, 40.0)],
        [P(130.1, 11.47)],
        [],
    ]
    ids = [[0, 1, 2, 3, 4], [0, 1, 2, 3, 4], [0, 1, 2, 3, 4], [1], []]
    for row, bs, vs in zip(
        points[:3], ids[:3], [(100.0, 121.0), (106.0, 120.0), (114.0, 119.0)], strict=True
    ):
        row += [P(vs[0], 12.0), P(vs[1], 12.2)]  # a flat branch folding with a steep one
        bs += [5, 6]
    notes = stop_notes(amps, points, ids, np.linspace(100.0, 160.0, 9), gap)
    assert notes == [
        "branch 4 (40 Hz) stops at 0.65 gap, 130 m/s: flat (its speed changed by -15 m/s from "
        "0.64 gap; extrapolated to 115 m/s at 0.66 gap, where it is not found): refine the "
        "amplitudes between 0.65 gap and 0.66 gap"
    ]
    wider = stop_notes(amps, points, ids, np.linspace(100.0, 170.0, 9), gap)
    assert len(wider) == 2 and wider[0].startswith("branch 0 (26.3 Hz) stops at 0.65 gap, 156.9")


# 2-3. The Goland LQR loop ------------------------------------------------------------------
RHO = 1.225
FP = np.radians(1.0)
AILERON = [NonlinearHinge("aileron", Freeplay(FP))]


@pytest.fixture(scope="module")
def goland():
    """The loop of tests/test_loop_describing.py: LQR at 1.1 x the flutter speed, 1 kHz."""
    model = aes.AeroelasticModel(aes.examples.goland_aileron(), n_elements=10)
    loop = ControlLoop(
        model, RHO, ["aileron_hinge_moment"], ["tip_le_accel", "tip_te_accel", "tip_twist"],
        ["tip_disp"],
    )  # fmt: skip
    vf = aes.flutter_boundary(model, RHO).flutter_speed
    spec = load_controller(ROOT / "controllers" / "lqr.toml")
    return loop, loop.design_controller(spec, 1.1 * vf, 1000.0)


@pytest.mark.slow
def test_goland_loop_recovery_and_buzz_in_one_interval(goland):
    """At 0.62 gap on [130, 135] m/s: the 11.5 Hz root that recovers and the buzz that starts,
    as on a grid of 0.25 m/s (speeds 1e-8, frequencies 1e-8, the same stability)."""
    loop, lqr = goland
    a = [0.62 * FP]
    got = loop_describing_branches(loop, AILERON, lqr, a, [130.0, 135.0], tol=1e-10)
    ref = loop_describing_branches(loop, AILERON, lqr, a, np.linspace(130.0, 135.0, 21), tol=1e-10)
    assert got.speed.size == ref.speed.size == 2 and got.notes == ref.notes == ()
    i, j = np.argsort(got.speed), np.argsort(ref.speed)
    np.testing.assert_allclose(got.speed[i], ref.speed[j], rtol=1e-8)
    np.testing.assert_allclose(got.frequency[i], ref.frequency[j], rtol=1e-8)
    np.testing.assert_array_equal(got.stable[i], ref.stable[j])
    assert 130.2 < got.speed[i][0] < 130.3 and 11.4 < got.frequency[i][0] < 11.6
    assert 134.0 < got.speed[i][1] < 134.4 and 22.5 < got.frequency[i][1] < 23.0


@pytest.mark.slow
def test_goland_buzz_branch_stop_is_noted(goland):
    """The buzz at 0.63, 0.64, 0.65 gap (140.1, 147.3, 156.9 m/s), none near it at 0.66 gap on
    [125, 175] m/s: a note names 0.65 gap and 156.9 m/s, a flat branch."""
    loop, lqr = goland
    amps = FP * np.array([0.63, 0.64, 0.65, 0.66])
    b = loop_describing_branches(loop, AILERON, lqr, amps, np.linspace(125.0, 175.0, 11))
    buzz = [n for n in b.notes if "stops at 0.65 gap, 156.9" in n]
    assert len(buzz) == 1 and "flat (its speed changed by +9.6" in buzz[0], b.notes
    assert "refine the amplitudes between 0.65 gap and 0.66 gap" in buzz[0]
