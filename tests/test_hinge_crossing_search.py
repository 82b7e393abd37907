"""The crossing search of the exact march with nonlinear hinges on the real modal basis
(issue 40 item 3: the cost per switch).

Each region's closed-form motion used every root of ``A_r``; it now keeps one root of each
conjugate pair with its mode doubled (:func:`aeroservo.simulate.hinges.regions.real_basis`),
evaluates the scan's exponentials as powers, and reuses the scanned rotations as the ends of
the bracket. The previous search (every root, the scan from the modal coordinates, the ends
of the bracket evaluated again) is run beside it on random marches: the same switches, their
times to 1e-12 s and the states to 1e-10 of their peak (both exact to rounding; the march
amplifies rounding only where the motion is chaotic, as at 8 m/s on the Conner section, not
marched here).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

import aeroservo as aes
from aeroservo.linear.hinge_plant import nonlinear_plant, section_plant
from aeroservo.simulate.hinges import regions
from aeroservo.simulate.hinges.exact_motion import GRID, rotations_at, scan_rows
from aeroservo.simulate.hinges.march import march_hinges
from aeroservo.structure.hinge_laws import Bilinear, Freeplay
from aeroservo.system.hinge_elements import NonlinearHinge
from aeroservo.system.section import CONNER, conner_section

RHO = 1.225


def full_basis(lam, V):
    """The previous basis: every root, weight 1."""
    return np.arange(lam.size), np.ones(lam.size)


def both(monkeypatch, nplant, **kw):
    """The march with the search as it is and as it was: every root, the scan's rows from the
    modal coordinates at each point (``rotations_at``), the bracket's ends evaluated again."""
    new = march_hinges(nplant, **kw)
    exits = regions.exits
    with monkeypatch.context() as m:
        m.setattr(regions, "real_basis", full_basis)
        m.setattr(regions, "scan_rows", lambda W, lam, y0, g, rest: rotations_at(W, lam, y0, g,
                  rest * GRID))  # fmt: skip
        m.setattr(regions, "exits", lambda *a: [c[:4] for c in exits(*a)])
        old = march_hinges(nplant, **kw)
    return new, old


def assert_same(new, old):
    assert new.switches.size == old.switches.size > 0
    np.testing.assert_allclose(new.switches, old.switches, rtol=0, atol=1e-12)
    peak = np.abs(old.states).max(axis=0)
    assert (np.abs(new.states - old.states) / np.maximum(peak, 1e-300)).max() < 1e-10


@pytest.mark.parametrize("seed", range(12))
def test_random_section_marches_match_the_previous_search(monkeypatch, seed):
    """The Conner section (8 states) at random speeds from 10 to 22 m/s (not the chaotic
    motion below), random freeplay or bilinear laws, gaps and offsets, and random initial
    states, 0.6 s at 1 ms."""
    rng = np.random.default_rng(seed)
    speed = rng.uniform(10.0, 22.0)
    gap = CONNER["gap"] * rng.uniform(0.3, 2.0)
    off = gap * rng.uniform(-0.3, 0.3)
    law = Freeplay(gap, offset=off) if seed % 2 else Bilinear(gap, offset=off, inner_ratio=0.3)
    nplant = section_plant(conner_section(), [NonlinearHinge("flap", law)], speed, RHO)
    x0 = nplant.initial_state(off + gap * rng.uniform(0.6, 3.0) * rng.choice([-1, 1]))
    x0 = x0 + 1e-3 * rng.standard_normal(x0.size) * np.abs(x0).max()
    assert_same(*both(monkeypatch, nplant, duration=0.6, x0=x0))


@pytest.fixture(scope="module")
def goland_plant():
    model = aes.AeroelasticModel(aes.examples.goland_aileron(), n_elements=10)
    gap = np.radians(1.0)
    return nonlinear_plant(model, [NonlinearHinge("aileron", Freeplay(gap))], 137.0, RHO), gap


@pytest.mark.parametrize("seed", range(3))
def test_random_wing_marches_match_the_previous_search(monkeypatch, goland_plant, seed):
    """The Goland wing with aileron (92 states, both actuators with 1 deg of freeplay, open
    loop at 137 m/s where the aileron knocks), from random rotations of 0.5 to 3 gaps, 0.3 s."""
    nplant, gap = goland_plant
    rng = np.random.default_rng(100 + seed)
    rot = gap * rng.uniform(0.5, 3.0, 2) * rng.choice([-1, 1], 2)
    assert_same(*both(monkeypatch, nplant, duration=0.3, rotation0=rot))


def test_real_basis_pairs_conjugate_roots_and_falls_back():
    """A real matrix: one root of each pair (weight 2) and the real roots (weight 1), and
    ``Re(V y) = Re(V[:, keep] w y[keep])`` for a real state; a complex matrix: the full basis."""
    rng = np.random.default_rng(7)
    A = rng.standard_normal((9, 9))
    lam, V = sla.eig(A)
    keep, w = regions.real_basis(lam, V)
    assert keep.size == np.count_nonzero(lam.imag >= 0) and w.sum() == 9
    x = rng.standard_normal(9)
    y = np.linalg.solve(V, x)
    np.testing.assert_allclose(((V[:, keep] * w) @ y[keep]).real, x, rtol=0, atol=1e-12)
    lam_c, V_c = sla.eig(A + 1j * rng.standard_normal((9, 9)))
    keep, w = regions.real_basis(lam_c, V_c)
    np.testing.assert_array_equal(keep, np.arange(9))
    np.testing.assert_array_equal(w, np.ones(9))


@pytest.mark.parametrize("n", [4, 40])
def test_scan_rows_are_the_closed_form(n):
    """The scan's rows (powers of one exponential for many modes) against the closed form at
    each point of the grid: 1e-13 of the rows' size."""
    rng = np.random.default_rng(n)
    lam = -rng.uniform(0.0, 30.0, n) + 1j * rng.uniform(-3e4, 3e4, n)
    y0 = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    gam = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    W = rng.standard_normal((3, n)) + 1j * rng.standard_normal((3, n))
    rest = 7.3e-4
    ref = rotations_at(W, lam, y0, gam, rest * GRID)
    got = scan_rows(W, lam, y0, gam, rest)
    assert np.abs(got - ref).max() < 1e-13 * np.abs(ref).max()
