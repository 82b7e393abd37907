"""Concentrated masses (issue 27): references computed here, independently of the assembly.

* rigid-body properties (total mass, static moments, inertias about the root and the elastic
  axis, flap inertia about the hinge) of the kinetic energy of rigid motions, by hand;
* a mass is the limit of a short heavy segment; at a node and between nodes it converges to a
  refined mesh;
* the classical frequency equations of a uniform cantilever with a tip mass (bending) and a
  tip disk (torsion);
* the classical trend of store flutter on the Goland wing: ahead of the elastic axis raises the
  flutter speed, aft lowers it.
"""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
import scipy.linalg as sla
from conftest import ROOT
from scipy.optimize import brentq

import aeroservo as aes
from aeroservo.cli import main
from aeroservo.errors import InputError
from aeroservo.files import load_wing
from aeroservo.files.wing_file import wing_toml
from aeroservo.structure.examples import goland
from aeroservo.structure.wing import ConcentratedMass, ControlSurface, Segment, Wing

GOLAND_SPAN = 6.096


def with_masses(wing: Wing, *masses: ConcentratedMass) -> Wing:
    return dataclasses.replace(wing, masses=tuple(masses))


def frequencies(wing: Wing, n_elements: int, n: int = 6) -> np.ndarray:
    return aes.AeroelasticModel(wing, n_elements).natural_modes(n).frequencies


# -- rigid-body properties ------------------------------------------------------------------
def random_wing(rng: np.random.Generator) -> tuple[Wing, int]:
    """A two-segment wing with a flap on the outer part and 1-4 masses (some on the flap, one
    exactly on a node), all outside the first element; with its number of elements."""
    span = rng.uniform(2.0, 12.0)
    x1 = rng.uniform(0.3, 0.6) * span
    segs = []
    for i, (x0, xe) in enumerate(((0.0, x1), (x1, span))):
        b = rng.uniform(0.2, 0.8) * span / 8
        a = rng.uniform(-0.5, 0.0)
        m = rng.uniform(5.0, 50.0)
        x_a = rng.uniform(-0.2, 0.3)
        ia = m * (x_a * b) ** 2 + m * b**2 * rng.uniform(0.1, 0.4)
        ei, gj = m * span**4 * rng.uniform(5, 50), ia * span**2 * rng.uniform(200, 2000)
        segs.append(Segment(x0, xe, b, a, m, x_a, ia, ei, gj, name=f"s{i}"))
    flap = ControlSurface(
        "flap",
        x1,
        span,
        hinge=0.5,
        static_moment=0.05,
        inertia=0.02,
        GJ=1e3,
        hinge_stiffness=rng.uniform(1e2, 1e3),
    )
    n_el = int(rng.integers(8, 16))
    wing = Wing(span, tuple(segs), (flap,))
    nodes = aes.AeroelasticModel(wing, n_el).mesh.nodes
    masses = []
    for k in range(int(rng.integers(1, 5))):
        on_flap = rng.random() < 0.4
        lo = x1 if on_flap else nodes[1]
        station = rng.uniform(lo, span) if k else nodes[rng.integers(2, nodes.size)]
        if on_flap and station < x1:
            station = rng.uniform(x1, span)
        b = wing.segment_at(station).semichord
        masses.append(
            ConcentratedMass(
                station=float(station),
                mass=rng.uniform(1.0, 200.0),
                offset=rng.uniform(-1.0, 1.0) * b,
                inertia=rng.uniform(0.0, 5.0),
                vertical_offset=rng.uniform(-0.3, 0.3) * b,
                surface="flap" if on_flap else None,
                name=f"m{k}",
            )
        )
    return with_masses(wing, *masses), n_el


def rigid_energy_reference(wing: Wing) -> np.ndarray:
    """Kinetic-energy matrix (2T = u^T R u) of the rigid motions u = (W, R, P, D): plunge W,
    rotation about the root R (w = W + R x), pitch P about the elastic axis, flap rotation D
    about the hinge, by hand: a point at y aft of the EA moves up by w - y P (docs/conventions.md),
    a point of the flap y_f aft of the hinge by a further -y_f D; a mass at height z moves aft by
    z (P [+ D]) and turns with P [+ D]."""
    out = np.zeros((4, 4))
    for s in wing.segments:
        mom = [(s.end ** (k + 1) - s.start ** (k + 1)) / (k + 1) for k in range(3)]  # int x^k
        vw = np.array([1.0, 0, 0, 0]), np.array([0, 1.0, 0, 0])  # w = W + R x
        ww = (
            np.outer(vw[0], vw[0]) * mom[0]
            + (np.outer(vw[0], vw[1]) + np.outer(vw[1], vw[0])) * mom[1]
            + np.outer(vw[1], vw[1]) * mom[2]
        )
        out += s.mass * ww
        wx = np.zeros((4, 4))  # int w dx as a bilinear form with P
        wx[0, 2] = wx[2, 0] = mom[0]
        wx[1, 2] = wx[2, 1] = mom[1]
        out -= s.static_moment * wx
        out[2, 2] += s.inertia * mom[0]
    for cs in wing.control_surfaces:
        s = wing.segment_at(0.5 * (cs.start + cs.end))
        y_h = s.semichord * (cs.hinge - s.a)
        mom = [(cs.end ** (k + 1) - cs.start ** (k + 1)) / (k + 1) for k in range(2)]
        out[0, 3] -= cs.static_moment * mom[0]
        out[1, 3] -= cs.static_moment * mom[1]
        out[2, 3] += (cs.inertia + y_h * cs.static_moment) * mom[0]
        out[3, 0], out[3, 1], out[3, 2] = out[0, 3], out[1, 3], out[2, 3]
        out[3, 3] += cs.inertia * mom[0]
    for pm in wing.masses:
        if pm.surface is None:
            v = np.array([1.0, pm.station, -pm.offset, 0.0])  # vertical velocity
            r = np.array([0.0, 0.0, 1.0, 0.0])  # rotation
        else:
            s = wing.segment_at(pm.station)
            y_h = s.semichord * (wing.surface(pm.surface).hinge - s.a)
            v = np.array([1.0, pm.station, -(y_h + pm.offset), -pm.offset])
            r = np.array([0.0, 0.0, 1.0, 1.0])
        out += pm.mass * np.outer(v, v) + (pm.inertia + pm.mass * pm.vertical_offset**2) * np.outer(
            r, r
        )
    return out


def root_block(seg: Segment, length: float) -> np.ndarray:
    """Consistent mass matrix of the root node (w, theta, phi) of a uniform first element of a
    cubic Hermite bending / linear torsion beam (Przemieniecki, Theory of Matrix Structural
    Analysis, 1968, eq. 11.30: m L/420 [156, 22 L; 22 L, 4 L^2]; linear twist I L/3; coupling
    -S int N_w (1 - xi) dx = -S [7 L/20, L^2/20])."""
    m, s, i, L = seg.mass, seg.static_moment, seg.inertia, length
    return np.array(
        [
            [156 * m * L / 420, 22 * m * L**2 / 420, -7 * s * L / 20],
            [22 * m * L**2 / 420, 4 * m * L**3 / 420, -s * L**2 / 20],
            [-7 * s * L / 20, -s * L**2 / 20, i * L / 3],
        ]
    )


def rigid_energy_model(wing: Wing, n_el: int) -> np.ndarray:
    """2T of the rigid motions with the model's matrices: free part Ms, root rows (the root
    reactions' mass matrix) and the root block of the first element (no mass in it)."""
    model = aes.AeroelasticModel(wing, n_el)
    mesh, am = model.mesh, model.matrices
    n_q = am.Ms.shape[0]
    x = mesh.nodes
    qf, qr = np.zeros((n_q, 4)), np.zeros((3, 4))
    for k, (dofs, vals) in enumerate(
        (
            ((mesh.dof_w,), (np.ones_like(x),)),
            ((mesh.dof_w, mesh.dof_theta), (x, np.ones_like(x))),
            ((mesh.dof_phi,), (np.ones_like(x),)),
            ((mesh.dof_delta[0],), (np.ones_like(x),)),
        )
    ):
        for d, v in zip(dofs, vals, strict=True):
            qf[d[d >= 0], k] = v[d >= 0]
    qr[:, 0] = [1.0, 0.0, 0.0]  # root node: w, theta, phi
    qr[:, 1] = [0.0, 1.0, 0.0]
    qr[:, 2] = [0.0, 0.0, 1.0]
    ms, ms_r = am.Ms.toarray(), am.root.Ms.toarray()
    mrr = root_block(wing.segments[0], mesh.lengths[0])
    return qf.T @ ms @ qf + qr.T @ ms_r @ qf + qf.T @ ms_r.T @ qr + qr.T @ mrr @ qr


@pytest.mark.parametrize("seed", range(12))
def test_rigid_body_properties(seed):
    """Total mass (W W), first moment about the root (W R), inertia about the root (R R),
    static moments about the EA (W P, R P), pitch inertia about the EA (P P) and the flap's
    static moment and inertia about the hinge (. D) of random wings with masses, against the
    hand sums: the consistent interpolation reproduces rigid motions exactly, so the rounding
    of a few hundred terms is the only error."""
    wing, n_el = random_wing(np.random.default_rng(seed))
    ref = rigid_energy_reference(wing)
    got = rigid_energy_model(wing, n_el)
    scale = np.sqrt(np.outer(np.diag(ref), np.diag(ref)))
    np.testing.assert_allclose(got / scale, ref / scale, atol=1e-12)
    assert got[0, 0] == pytest.approx(wing.mass, rel=1e-13)  # total mass, masses included


def test_no_masses_leaves_the_matrices_unchanged():
    """A wing without masses assembles exactly as before (the point-mass blocks add 0.0)."""
    from aeroservo.system.assembly import assemble
    from aeroservo.system.point_masses import point_mass_blocks

    wing = aes.examples.goland_aileron()
    model = aes.AeroelasticModel(wing, 12)
    assert point_mass_blocks(wing, model.mesh) == 0.0
    assert (assemble(wing, model.mesh).Ms != model.matrices.Ms).nnz == 0


# -- convergence ----------------------------------------------------------------------------
STORE = dict(mass=60.0, offset=-0.25, inertia=3.0)


def test_point_mass_is_the_limit_of_a_short_heavy_segment():
    """A 60 kg store with 3 kg m^2 about its CG 0.25 m ahead of the EA at 70 % span of the
    Goland wing, against a segment of length eps carrying the same mass, static moment and
    inertia on top of the wing's: the frequencies converge to the point mass's as eps shrinks.
    The convergence is first order: the heavy segment is as flexible in torsion as the wing, and
    the torque of its inertia passes through a length of order eps of it (a shift of order
    eps omega^2 I / GJ); 120 elements on both.  Measured: 6.1e-3, 3.0e-3, 1.6e-3, 1.0e-3,
    5.0e-4 at eps = 0.4 ... 0.025 m."""
    base = goland()
    seg = base.segments[0]
    xs, n_el = 0.7 * GOLAND_SPAN, 120
    point = frequencies(with_masses(base, ConcentratedMass(xs, **STORE)), n_el)
    errors = []
    for eps in (0.4, 0.2, 0.1, 0.05, 0.025):
        m_add = STORE["mass"] / eps
        s_add = STORE["mass"] * STORE["offset"] / eps
        i_add = (STORE["inertia"] + STORE["mass"] * STORE["offset"] ** 2) / eps
        m_tot = seg.mass + m_add
        s_tot = seg.static_moment + s_add
        heavy = dataclasses.replace(
            seg,
            start=xs - eps / 2,
            end=xs + eps / 2,
            mass=m_tot,
            x_alpha=s_tot / (m_tot * seg.semichord),
            inertia=seg.inertia + i_add,
            name="heavy",
        )
        parts = (
            dataclasses.replace(seg, end=xs - eps / 2, name="in"),
            heavy,
            dataclasses.replace(seg, start=xs + eps / 2, name="out"),
        )
        f = frequencies(Wing(base.span, parts), n_el)
        errors.append(np.max(np.abs(f / point - 1)))
    errors = np.array(errors)
    assert np.all(np.diff(errors) < 0), errors
    assert errors[-1] < 7e-4, errors
    assert errors[0] / errors[-1] > 8.0, errors  # 16 times shorter: first order


@pytest.mark.parametrize("where", ["node", "between"])
def test_mass_at_a_node_or_between_converges_to_a_refined_mesh(where):
    """A store at a node (60 % span is node 6 of 10) or between nodes (63 %): the six lowest
    frequencies with 10, 20 and 40 elements converge to those of 160 elements at the rate of the
    linear twist elements (error / 4 per halving; measured ratios 4.0-4.2 at the node and
    between), so a mass off the nodes costs no accuracy."""
    xs = (0.6 if where == "node" else 0.63) * GOLAND_SPAN
    wing = with_masses(goland(), ConcentratedMass(xs, **STORE))
    ref = frequencies(wing, 160)
    err = [np.max(np.abs(frequencies(wing, n) / ref - 1)) for n in (10, 20, 40)]
    assert err[0] / err[1] > 3.5 and err[1] / err[2] > 3.5, err
    assert err[2] < 4e-3, err


# -- classical closed forms -----------------------------------------------------------------
L_U, M_U, EI_U, GJ_U, I_U = 6.0, 30.0, 1.0e7, 1.0e6, 8.0  # uniform wing, x_alpha = 0


def uniform() -> Wing:
    return Wing(L_U, (Segment(0.0, L_U, 0.9, -0.2, M_U, 0.0, I_U, EI_U, GJ_U),))


def roots(fun, hi: float, n: int) -> np.ndarray:
    xs = np.linspace(1e-3, hi, 20000)
    v = fun(xs)
    idx = np.flatnonzero(np.sign(v[:-1]) != np.sign(v[1:]))
    out = [brentq(fun, xs[i], xs[i + 1]) for i in idx]
    return np.array(out[:n])


@pytest.mark.parametrize("ratio", [0.25, 1.0, 4.0])
def test_tip_mass_bending_frequency_equation(ratio):
    """Uniform cantilever with a tip mass M (no offset, no inertia, x_alpha = 0): bending
    frequencies omega = (beta L)^2 sqrt(EI / (m L^4)) with beta L the roots of

        1 + cos(bL) cosh(bL) + (M / (m L)) bL (cos(bL) sinh(bL) - sin(bL) cosh(bL)) = 0

    (Blevins, Formulas for Natural Frequency and Mode Shape, 1979, table 8-8 case "cantilever
    with tip mass"; Karnovsky & Lebed, Formulas for Structural Dynamics, 2001, ch. 5; from
    w(0) = w'(0) = w''(L) = 0, EI w'''(L) = -omega^2 M w(L)). The sign form was checked here
    first against a 200-element mesh. The torsion frequencies do not move (the mass is on the
    elastic axis): (2k - 1) pi / (2 L) sqrt(GJ / I_alpha)."""
    r = ratio

    def eq(x):
        return (
            1 + np.cos(x) * np.cosh(x) + r * x * (np.cos(x) * np.sinh(x) - np.sin(x) * np.cosh(x))
        )

    bl = roots(eq, 9.0, 2)
    f_bend = bl**2 * np.sqrt(EI_U / (M_U * L_U**4)) / (2 * np.pi)
    wing = with_masses(uniform(), ConcentratedMass(L_U, r * M_U * L_U))
    model = aes.AeroelasticModel(wing, 60)
    modes = model.natural_modes(5)
    bend = [f for f, lab in zip(modes.frequencies, modes.labels, strict=True) if "bending" in lab]
    tors = [f for f, lab in zip(modes.frequencies, modes.labels, strict=True) if "torsion" in lab]
    np.testing.assert_allclose(bend[:2], f_bend, rtol=2e-6)  # FE error of 60 cubic elements
    clean = aes.AeroelasticModel(uniform(), 60)
    modes0 = clean.natural_modes(5)
    tors0 = [
        f for f, lab in zip(modes0.frequencies, modes0.labels, strict=True) if "torsion" in lab
    ]
    # the dense eigensolver's rounding: eps * largest eigenvalue / this one (omega^2)
    w2_max = sla.eigh(clean.matrices.Ks.toarray(), clean.matrices.Ms.toarray())[0].max()
    rtol = 100 * np.finfo(float).eps * w2_max / (2 * np.pi * np.array(tors0[:2])) ** 2
    assert np.all(np.abs(np.array(tors[:2]) / tors0[:2] - 1) < rtol)


@pytest.mark.parametrize("ratio", [0.25, 1.0, 4.0])
def test_tip_inertia_torsion_frequency_equation(ratio):
    """Uniform shaft with a disk of inertia I_t at the free end (the same mass at the tip with
    pitch inertia only, via I + m z^2 with no mass moving: a 1e-3 kg mass keeps the bending
    frequencies to 1e-5): phi = sin(lambda x), lambda^2 = omega^2 I_alpha / GJ, and the tip
    equation I_t phi_tt = -GJ phi'(L) gives

        lambda L tan(lambda L) = I_alpha L / I_t

    (Meirovitch, Fundamentals of Vibrations, 2001, sec. 8.6, shaft with an end disk; derived
    here). Twist is linear in each element, so the FE frequencies converge as 1/n^2: 200
    elements give 1e-5."""
    i_t = I_U * L_U / ratio

    def eq(x):
        return x * np.sin(x) - ratio * np.cos(x)

    ll = roots(eq, 8.0, 2)
    f_tors = ll / L_U * np.sqrt(GJ_U / I_U) / (2 * np.pi)
    wing = with_masses(uniform(), ConcentratedMass(L_U, 1e-3, inertia=i_t))
    modes = aes.AeroelasticModel(wing, 200).natural_modes(6)
    tors = [f for f, lab in zip(modes.frequencies, modes.labels, strict=True) if "torsion" in lab]
    np.testing.assert_allclose(tors[:2], f_tors, rtol=3e-5)


# -- store flutter --------------------------------------------------------------------------
def goland_flutter(offset: float | None) -> float:
    wing = goland()
    if offset is not None:
        wing = with_masses(wing, ConcentratedMass(GOLAND_SPAN, 20.0, offset=offset, inertia=0.5))
    return aes.flutter_boundary(aes.AeroelasticModel(wing, 10), 1.225).flutter_speed


def test_store_ahead_raises_and_aft_lowers_goland_flutter():
    """A 20 kg tip store (0.5 kg m^2) on the Goland wing, sea level, 10 elements: the further
    forward its CG, the higher the flutter speed (the classical mass-balance result: it moves
    the section CG forward and lowers the torsion frequency less than the bending one, e.g.
    Bisplinghoff, Ashley & Halfman, Aeroelasticity, 1955, sec. 9-5); 0.3 m ahead of the EA it
    raises the clean wing's 137.8 m/s, 0.6 m aft it lowers it. Measured: 233.4, 173.6, 155.8,
    144.5, 134.2 m/s at -0.6, -0.3, 0, 0.3, 0.6 m."""
    clean = goland_flutter(None)
    v = np.array([goland_flutter(y) for y in (-0.6, -0.3, 0.0, 0.3, 0.6)])
    assert np.all(np.diff(v) < 0), v
    assert v[1] > 1.2 * clean and v[-1] < 0.99 * clean, (clean, v)


# -- files and bad input --------------------------------------------------------------------
GOLAND_FILE = (ROOT / "scenarios" / "goland.toml").read_text()


def store_file(table: str) -> str:
    return GOLAND_FILE.replace("[analysis]", f"[[wing.masses]]\n{table}\n\n[analysis]", 1)


def test_wing_file_round_trip(tmp_path):
    """[[wing.masses]] is read and written back by wing_toml exactly (repr numbers)."""
    store = ConcentratedMass(4.5, 120.0, offset=-0.2, inertia=6.0, vertical_offset=-0.3, name="s")
    weight = ConcentratedMass(5.0, 1.5, offset=-0.1, surface="aileron", name="balance")
    wing = with_masses(aes.examples.goland_aileron(), store, weight)
    path = tmp_path / "w.toml"
    path.write_text(wing_toml(wing))
    back, _ = load_wing(path)
    assert back.masses == wing.masses


@pytest.mark.parametrize(
    "table,fragment",
    [
        ("station = 0.0\nmass = 10.0", "wing.masses[0].station = 0: allowed range is (0,"),
        ("station = 7.0\nmass = 10.0", "wing.masses[0].station = 7: outside the wing"),
        ("station = 3.0\nmass = -1.0", "wing.masses[0].mass = -1: allowed range is [0, 1e+06]"),
        ("station = 3.0\nmass = 1e9", "wing.masses[0].mass = 1e+09: allowed range is [0, 1e+06]"),
        ("station = 3.0\nmass = 1.0\ninertia = -2.0", "wing.masses[0].inertia = -2"),
        ("station = 3.0\nmass = 1.0\noffset = 250.0", "wing.masses[0].offset = 250: allowed"),
        (
            "station = 3.0\nmass = 1.0\noffset = nan",
            "wing.masses[0].offset = nan: must be a finite number",
        ),
        ("station = 3.0\nmass = 1.0\nvertical_offset = -9.0", "vertical_offset = -9: allowed"),
        ("station = 3.0\nmass = 1.0\nsurface = 'flap'", "surface = 'flap': unknown; this wing"),
        ("station = 3.0\nmass = 'heavy'", "wing.masses[0].mass = 'heavy': expected a real"),
        ("station = 3.0\nweight = 1.0", "wing.masses[0].weight: unknown key"),
        ("mass = 1.0", "wing.masses[0].station: missing required key"),
        ("station = 3.0\nmass = 1.0\nname = 'pod'\noffset = 1e3", "mass 'pod'.offset = 1000"),
    ],
)
def test_bad_mass_tables(table, fragment, tmp_path, capsys):
    """One line naming the key and the value, from the file reader and from the CLI."""
    path = tmp_path / "w.toml"
    path.write_text(store_file(table))
    with pytest.raises(InputError, match=re.escape(fragment)) as err:
        load_wing(path)
    assert fragment in str(err.value) and "\n" not in str(err.value)
    assert main(["modes", str(path)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and fragment in lines[0], lines


def test_mass_not_on_its_flap():
    """A balance weight at a station the surface does not cover is refused."""
    with pytest.raises(
        InputError, match=r"mass 'bw'.station = 1: not on control surface 'aileron'"
    ):
        with_masses(
            aes.examples.goland_aileron(), ConcentratedMass(1.0, 1.0, surface="aileron", name="bw")
        )


# -- downstream: state space, saved results ------------------------------------------------
def test_masses_reach_the_first_order_system():
    """The state matrix at rest in near vacuum has the in-vacuo frequencies of the wing with
    its store (its eigenvalues +-i omega up to the apparent mass of rho = 1e-4)."""
    wing = with_masses(goland(), ConcentratedMass(4.0, 80.0, offset=-0.3, inertia=4.0))
    model = aes.AeroelasticModel(wing, 8)
    f_vac = model.natural_modes(3).frequencies
    lam = np.linalg.eigvals(model.state_matrix(0.0, 1e-4))
    f = np.sort(np.abs(lam.imag[lam.imag > 1.0])) / (2 * np.pi)
    np.testing.assert_allclose(f[:3], f_vac, rtol=1e-4)
    clean = aes.AeroelasticModel(goland(), 8).natural_modes(3).frequencies
    assert np.all(np.abs(f_vac / clean - 1) > 1e-2)  # the store does move them


def test_shipped_store_example():
    """scenarios/goland_store.toml is the built-in goland_store (same matrices), listed by
    `aeroservo examples`; its aft store lowers the Goland flutter speed (128.3 against 137.8
    m/s, sea level, 10 elements)."""
    wing, _ = load_wing(ROOT / "scenarios" / "goland_store.toml")
    ref = aes.examples.goland_store()
    assert wing.masses == ref.masses and wing.name == ref.name
    m1, m2 = aes.AeroelasticModel(wing, 10), aes.AeroelasticModel(ref, 10)
    for a, b in ((m1.matrices.Ms, m2.matrices.Ms), (m1.matrices.Ks, m2.matrices.Ks)):
        assert (a != b).nnz == 0
    assert aes.flutter_boundary(m2, 1.225).flutter_speed == pytest.approx(128.296, rel=1e-4)


def test_examples_lists_the_store_wing(capsys):
    assert main(["examples"]) == 0
    assert "goland_store" in capsys.readouterr().out


def test_mode_plot_marks_the_masses():
    """The mode-shape figure draws a marker and a legend entry at each mass's station."""
    model = aes.AeroelasticModel(aes.examples.goland_store(), 8)
    fig = aes.plots.plot_mode_shapes(model, model.natural_modes(2), n=2)
    texts = [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().texts]
    assert sum("mass: store (4.57 m)" in t for t in texts) == 2
