"""Analytic sensitivities to concentrated masses against central finite differences.

The derivatives of the flutter and divergence speeds with respect to each mass's ``mass``,
``station``, ``offset``, ``inertia`` and ``vertical_offset`` (and, for a mass on a control
surface, the change of its matrix with the segment's ``a`` and ``semichord`` and the surface's
``hinge``: its distance from the elastic axis is ``b (c - a) + offset``) are compared with
central differences of the speeds computed by the engine itself, with the step, tolerance and
floor of ``tests/test_sensitivity.py`` (rtol 1e-12, relative step 2e-5, 1e-4 relative on the
normalized derivatives ``p / V dV/dp``; the justification is there). Wings: the Goland wing
(geometry of reference case ``goland_clean_flutter_strip_sea_level``) with a tip store, the
shipped ``goland_store`` and ``goland_aileron`` wings with masses drawn at random (stations off
the mesh nodes, some on the aileron).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from test_sensitivity import FLOOR, RTOL, TOL, _check, central

import aeroservo as aes
from aeroservo.stability.sensitivity import flutter_sensitivities, parameter_values
from aeroservo.structure.examples import goland, goland_aileron, goland_store
from aeroservo.structure.wing import ConcentratedMass
from aeroservo.studies.optimize import with_parameters
from aeroservo.system.assembly import assemble
from aeroservo.system.derivatives import matrix_derivative

COUPLED = ("segments[0].a", "segments[0].semichord", "control_surfaces[0].hinge")
"""The wing parameters that move a mass on a control surface."""


def balanced_aileron() -> aes.Wing:
    """Goland with aileron and a balance weight on the aileron, 0.15 m ahead of the hinge line,
    between the mesh nodes (4.877 and 5.486 m for 10 elements)."""
    w = goland_aileron()
    weight = ConcentratedMass(
        station=5.3,
        mass=8.0,
        offset=-0.15,
        inertia=0.2,
        vertical_offset=0.05,
        surface="aileron",
        name="balance",
    )
    return replace(w, masses=(weight,))


def tip_store() -> aes.Wing:
    """Goland with a tip store (Goland and Luke's "uniform wing with tip weights")."""
    store = ConcentratedMass(
        station=goland().span, mass=40.0, offset=0.15, inertia=3.0, vertical_offset=-0.1
    )
    return replace(goland(), masses=(store,), name="goland tip store")


def random_wing(seed: int) -> aes.Wing:
    """Goland with aileron and two to three masses at random: one or two on the wing box, one
    on the aileron (a balance weight or a trailing mass); stations off the mesh nodes."""
    rng = np.random.default_rng(seed)
    w = goland_aileron()
    span, cs = w.span, w.control_surfaces[0]
    masses = []
    for k in range(int(rng.integers(1, 3))):
        x = span * (rng.uniform(0.1, 0.95))
        masses.append(
            ConcentratedMass(
                station=x if abs(x / (span / 10) - round(x / (span / 10))) > 0.05 else x + 0.1,
                mass=float(rng.uniform(5.0, 50.0)),
                offset=float(rng.uniform(-0.4, 0.4)),
                inertia=float(rng.uniform(0.0, 4.0)),
                vertical_offset=float(rng.uniform(-0.3, 0.3)),
                name=f"m{k}",
            )
        )
    x = cs.start + (cs.end - cs.start) * float(rng.choice([0.15, 0.4, 0.6, 0.9]))
    masses.append(
        ConcentratedMass(
            station=x,
            mass=float(rng.uniform(1.0, 10.0)),
            offset=float(rng.uniform(-0.2, 0.1)),
            inertia=float(rng.uniform(0.0, 0.3)),
            vertical_offset=float(rng.uniform(-0.05, 0.05)),
            surface=cs.name,
            name="flap_mass",
        )
    )
    return replace(w, masses=tuple(masses), name=f"random masses {seed}")


def _compare(wing, names, density=1.225):
    model = aes.AeroelasticModel(wing)
    s = flutter_sensitivities(model, density, names, rtol=RTOL)
    assert s.flutter_speed is not None and s.non_differentiable is None
    worst = 0.0
    for p in names:
        assert p not in s.undefined, s.undefined.get(p)
        dv, df, dd = central(model, density, p, s.values[p], None)
        x = s.values[p]
        _check(s.d_flutter_speed[p], dv, x, s.flutter_speed, f"{wing.name} dV_f/d{p}")
        _check(s.d_flutter_frequency[p], df, x, s.flutter_frequency, f"{wing.name} df_f/d{p}")
        scale = (abs(x) or 1.0) / s.flutter_speed
        worst = max(worst, abs(s.d_flutter_speed[p] - dv) * scale / (abs(dv) * scale + FLOOR))
        if dd is not None:
            _check(s.d_divergence_speed[p], dd, x, s.divergence_speed, f"dV_d/d{p}")
    return s, worst


def test_mass_on_the_aileron_moves_with_a_semichord_and_hinge():
    """The bug of issue 27: the derivatives in ``a``, ``semichord`` and ``hinge`` left out the
    balance weight's matrix (its lever arm b (c - a) + offset). Matrix level (against central
    differences of two assemblies, relative step 1e-6) and flutter speed level."""
    wing = balanced_aileron()
    model = aes.AeroelasticModel(wing)
    table = parameter_values(wing)
    for name in COUPLED:
        owner, idx, key, value = table[name]
        got = matrix_derivative(wing, model.mesh, owner, idx, key).Ms.toarray()
        h = 1e-6 * abs(value)
        hi, lo = (assemble(with_parameters(wing, {name: value + t}), model.mesh) for t in (h, -h))
        ref = ((hi.Ms - lo.Ms) / (2 * h)).toarray()
        np.testing.assert_allclose(got, ref, atol=1e-7 * abs(ref).max(), err_msg=name)
    s, worst = _compare(wing, list(COUPLED))
    assert worst < TOL


MASS_KEYS = ("mass", "station", "offset", "inertia", "vertical_offset")


def test_goland_store_against_central_differences():
    """The shipped store wing: every mass parameter (station 4.572 m, mid-element)."""
    names = [f"masses[0].{k}" for k in MASS_KEYS]
    s, worst = _compare(goland_store(), names)
    assert worst < TOL
    assert all(s.d_divergence_speed[n] == 0.0 for n in names)  # no mass in the static problem
    # the classical result: the store's CG moved aft lowers the flutter speed
    assert s.d_flutter_speed["masses[0].offset"] < 0


def test_tip_store_against_central_differences():
    """A tip store: mass, offset, inertia, vertical offset two-sided; the station sits on its
    bound (the tip) and has only the inward derivative, equal to the second-order backward
    difference of the engine's flutter speed."""
    wing = tip_store()
    names = [f"masses[0].{k}" for k in MASS_KEYS if k != "station"]
    _, worst = _compare(wing, names)
    assert worst < TOL
    name = "masses[0].station"
    s = flutter_sensitivities(aes.AeroelasticModel(wing), 1.225, [name], rtol=RTOL)
    why = s.undefined[name]
    assert "at the tip" in why and "inward" in why and name not in s.d_flutter_speed
    got = float(why.split("dV_f/dp = ")[1].split()[0])
    x0 = wing.span
    h = 2e-5 * x0
    v = [
        aes.flutter_boundary(
            aes.AeroelasticModel(with_parameters(wing, {name: x0 - k * h})), 1.225, rtol=RTOL
        ).flutter_speed
        for k in (0, 1, 2)
    ]
    ref = (3 * v[0] - 4 * v[1] + v[2]) / (2 * h)
    assert abs(got - ref) * x0 / v[0] <= TOL * abs(ref) * x0 / v[0] + FLOOR


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.slow
def test_random_masses_against_central_differences(seed):
    """Random masses (some on the aileron): every mass parameter and the parameters that move
    the aileron's masses."""
    wing = random_wing(seed)
    names = [f"masses[{i}].{k}" for i in range(len(wing.masses)) for k in MASS_KEYS]
    _, worst = _compare(wing, [*names, *COUPLED])
    assert worst < TOL


@pytest.mark.parametrize("surface", [False, True])
def test_station_on_a_node_has_two_one_sided_derivatives(surface):
    """A mass on an interior mesh node (4.8768 m, on the aileron or not): the twist and flap
    shape functions are linear per element, so the mass matrix has a kink in the station; each
    side's derivative equals that side's one-sided difference of the assembly, the two differ,
    and the sensitivities name the kink with both one-sided values."""
    w = goland_aileron()
    pm = ConcentratedMass(
        station=4.8768, mass=10.0, offset=-0.1 if surface else 0.3, inertia=0.5,
        surface="aileron" if surface else None,
    )  # fmt: skip
    wing = replace(w, masses=(pm,))
    model = aes.AeroelasticModel(wing)
    name = "masses[0].station"
    m0, h = assemble(wing, model.mesh).Ms, 1e-7
    sides = []
    for side in (1, -1):
        d = matrix_derivative(wing, model.mesh, "mass", (0,), "station", side=side).Ms
        m1 = assemble(with_parameters(wing, {name: pm.station + side * h}), model.mesh).Ms
        one_sided = ((m1 - m0) / (side * h)).toarray()
        np.testing.assert_allclose(d.toarray(), one_sided, atol=1e-5 * abs(one_sided).max())
        sides.append(d.toarray())
    assert abs(sides[0] - sides[1]).max() > 1e-3 * abs(sides[0]).max()
    s = flutter_sensitivities(model, 1.225, [name, "masses[0].mass"])
    assert name not in s.d_flutter_speed and "kink" in s.undefined[name]
    assert "inboard" in s.undefined[name] and "outboard" in s.undefined[name]
    assert "masses[0].mass" in s.d_flutter_speed


def test_mass_parameters_are_listed_and_settable():
    """Every mass offers its five parameters, named as in the wing file, and
    ``with_parameters`` sets them (re-validated: a station off the wing is refused)."""
    wing = goland_store()
    table = parameter_values(wing)
    assert [n for n in table if n.startswith("masses")] == [f"masses[0].{k}" for k in MASS_KEYS]
    moved = with_parameters(wing, {"masses[0].mass": 80.0, "masses[0].offset": -0.2})
    assert moved.masses[0].mass == 80.0 and moved.masses[0].offset == -0.2
    with pytest.raises(aes.InputError, match="station"):
        with_parameters(wing, {"masses[0].station": 7.0})


def test_cli_lists_and_plots_mass_sensitivities(tmp_path, capsys):
    import json

    from aeroservo.cli import main

    png = tmp_path / "s.png"
    assert main(["sensitivity", "goland_store", "--json", "--plot", str(png)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["d_flutter_speed"]["masses[0].offset"] < 0
    assert "masses[0].station" in out["normalized_flutter_speed"]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_masses_on_a_cranked_swept_wing():
    """A crank (sweep 0 then 0.35 rad at 3 m) turns element unknowns into nodal ones; the mass
    derivatives go through the same transform: matrix level against central differences of the
    assembly (relative step 1e-6), flutter speed against central differences of the engine."""
    w = goland_aileron()
    s0 = w.segments[0]
    wing = replace(
        w,
        segments=(replace(s0, end=3.0), replace(s0, start=3.0, sweep=0.35)),
        masses=(
            ConcentratedMass(station=5.3, mass=8.0, offset=-0.15, inertia=0.2, surface="aileron"),
            ConcentratedMass(station=4.0, mass=30.0, offset=0.2, inertia=1.0, vertical_offset=0.1),
        ),
        name="cranked",
    )
    model = aes.AeroelasticModel(wing)
    for name, (owner, idx, key, value) in parameter_values(wing).items():
        if owner != "mass" and key not in ("a", "semichord", "hinge"):
            continue
        got = matrix_derivative(wing, model.mesh, owner, idx, key).Ms.toarray()
        h = 1e-6 * (abs(value) or 1.0)
        hi, lo = (assemble(with_parameters(wing, {name: value + t}), model.mesh) for t in (h, -h))
        ref = ((hi.Ms - lo.Ms) / (2 * h)).toarray()
        np.testing.assert_allclose(got, ref, atol=1e-7 * max(abs(ref).max(), 1.0), err_msg=name)
    names = ["masses[0].offset", "masses[1].station", "segments[1].a", "control_surfaces[0].hinge"]
    _, worst = _compare(wing, names)
    assert worst < TOL


def test_mass_on_a_flap_at_a_segment_boundary_has_no_station_derivative():
    """A balance weight exactly where the elastic axis moves (segments of different ``a``):
    its lever arm b (c - a) + offset jumps with the station, so there is no derivative, and
    the result says why (its other parameters keep theirs)."""
    w = goland_aileron()
    s0 = w.segments[0]
    x = 4.8768  # a node of the 10-element mesh
    pm = ConcentratedMass(station=x, mass=8.0, offset=-0.15, surface="aileron")
    segs = (replace(s0, end=x), replace(s0, start=x, a=-0.3))
    wing = replace(w, segments=segs, masses=(pm,))
    s = flutter_sensitivities(
        aes.AeroelasticModel(wing), 1.225, ["masses[0].station", "masses[0].mass"]
    )
    assert "jumps" in s.undefined["masses[0].station"] and "masses[0].mass" in s.d_flutter_speed
