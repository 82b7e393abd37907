"""Gradient-based tailoring (aeroservo.studies.optimize, ``aeroservo optimize``).

The shipped case (``scenarios/optimize_goland_torsion.toml``): least torsion-box material
(GJ x length) of a two-segment Goland wing for a flutter speed of at least 149.5 m/s. Checked
independently of the optimizer: the optimum satisfies its constraint on a fresh analysis, the
same problem solved with central-difference gradients reaches the same design in more flutter
boundaries, and the Lagrange condition holds with central differences of the flutter speed
(the objective's gradient is parallel to the constraint's).
"""

from __future__ import annotations

import json
import re

import pytest
from conftest import ROOT

import aeroservo as aes
from aeroservo.cli import main
from aeroservo.errors import InputError
from aeroservo.files.optimize_file import load_optimization
from aeroservo.studies.optimize import optimize_wing, with_parameters

CASE = ROOT / "scenarios" / "optimize_goland_torsion.toml"


@pytest.fixture(scope="module")
def problem():
    return load_optimization(CASE)


@pytest.fixture(scope="module")
def solutions(problem):
    p = problem
    return {
        g: optimize_wing(p.wing, p.density, p.variables, p.objective, p.constraints, gradients=g)
        for g in ("analytic", "central")
    }


def test_same_optimum_fewer_boundaries(solutions):
    a, c = solutions["analytic"], solutions["central"]
    assert a.success and c.success
    for n in a.variables:
        assert a.variables[n] == pytest.approx(c.variables[n], rel=1e-6)
    assert a.n_boundaries < c.n_boundaries
    assert a.active == ["flutter_speed_min"] and len(a.iterations) >= 2


def test_constraint_holds_on_a_fresh_analysis(problem, solutions):
    best = solutions["analytic"].variables
    model = aes.AeroelasticModel(with_parameters(problem.wing, best), problem.elements)
    vf = aes.flutter_boundary(model, problem.density).flutter_speed
    assert vf == pytest.approx(149.5, rel=1e-6) and vf >= 149.5 * (1 - 1e-6)
    # the root half carries more stiffness: torsion near the root moves V_f most
    assert best["segments[0].GJ"] > 0.99e6 > best["segments[1].GJ"]


def test_lagrange_condition_by_central_differences(problem, solutions):
    """At the optimum of a linear objective with one active constraint, w_i / (dV_f/dp_i)
    is the same for every variable (central differences, independent of the optimizer)."""
    best = solutions["analytic"].variables
    ratios = []
    for n, v in best.items():
        h = 1e-5 * v
        speeds = []
        for s in (1.0, -1.0):
            wing = with_parameters(problem.wing, {**best, n: v + s * h})
            m = aes.AeroelasticModel(wing, problem.elements)
            speeds.append(aes.flutter_boundary(m, problem.density, rtol=1e-12).flutter_speed)
        ratios.append(problem.objective[n] / ((speeds[0] - speeds[1]) / (2 * h)))
    assert ratios[0] == pytest.approx(ratios[1], rel=1e-4)


def test_maximize_flutter_speed_hits_the_bounds(problem):
    r = optimize_wing(problem.wing, problem.density, problem.variables, "flutter_speed", {})
    assert set(r.active) == {"bound segments[0].GJ", "bound segments[1].GJ"}
    assert all(v == pytest.approx(3.0e6) for v in r.variables.values())


def test_cli(capsys):
    assert main(["optimize", str(CASE), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["success"] and out["active_constraints"] == ["flutter_speed_min"]
    assert out["flutter_speed"] == pytest.approx(149.5, rel=1e-6)


@pytest.mark.parametrize(
    "old,new,fragment",
    [
        (
            '"segments[1].GJ" = [3.0e5, 3.0e6]',
            '"segments[2].GJ" = [3.0e5, 3.0e6]',
            "segments[2].GJ",
        ),
        ('"segments[1].GJ" = [3.0e5, 3.0e6]', '"segments[1].GJ" = [3.0e6, 3.0e5]', "lower < upper"),
        ("flutter_speed_min = 149.5", "flutter_sped_min = 149.5", "unknown key"),
        ("flutter_speed_min = 149.5", "flutter_speed_min = 1e308", "flutter_speed_min = 1e+308"),
        ("density = 1.225", "density = 5.0", "optimize.density = 5"),
    ],
)
def test_bad_files(tmp_path, old, new, fragment):
    text = CASE.read_text()
    assert old in text
    p = tmp_path / "o.toml"
    p.write_text(text.replace(old, new))
    with pytest.raises(InputError, match=re.escape(fragment)) as info:
        p2 = load_optimization(p)
        optimize_wing(p2.wing, p2.density, p2.variables, p2.objective, p2.constraints)
    msg = str(info.value)
    assert fragment in msg and len(msg.splitlines()) == 1


def test_bad_arguments(problem):
    with pytest.raises(InputError, match="gradients = 'forward'"):
        optimize_wing(
            problem.wing, 1.225, problem.variables, problem.objective, {}, gradients="forward"
        )
    with pytest.raises(InputError, match="not a design variable"):
        optimize_wing(problem.wing, 1.225, problem.variables, {"segments[0].EI": 1.0}, {})


@pytest.mark.slow
def test_codesign_shipped_case(capsys):
    """Aileron chord and LQR Bryson weight for the highest closed-loop flutter speed under a
    600 N m gust hinge-moment limit: a better design than the start, the limit met on a fresh
    case, and at the interior chord the closed-loop flutter speed is stationary (central
    differences with another step, independent of the optimizer's)."""
    from aeroservo.files.optimize_file import load_codesign
    from aeroservo.studies.runs import study_from_scenario
    from aeroservo.studies.trade.sensitivity import case_sensitivities

    assert main(["optimize", str(ROOT / "scenarios" / "codesign_aileron_lqr.toml"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["success"] and out["hinge_moment_peak"] <= 600.0 * (1 + 1e-3)
    assert out["closed_loop_flutter_speed"] > 1.1 * 192.1  # the start case: 192.1 m/s
    cd = load_codesign(ROOT / "scenarios" / "codesign_aileron_lqr.toml")
    chord = out["variables"]["aileron_chord"]
    assert 0.1 < chord < 0.3
    s = case_sensitivities(
        study_from_scenario(cd.scenario),
        {**cd.start, **out["variables"]},
        ["aileron_chord"],
        rel_step=3e-3,
    )
    slope = s.derivatives["closed_loop_flutter_speed"]["aileron_chord"]
    assert abs(slope * chord / out["closed_loop_flutter_speed"]) < 1e-2


# -- the shipped mass-balance case ---------------------------------------------------------------
BALANCE = ROOT / "scenarios" / "optimize_goland_mass_balance.toml"
S_BETA = "control_surfaces[0].static_moment"


@pytest.fixture(scope="module")
def balance():
    p = load_optimization(BALANCE)
    return p, {
        g: optimize_wing(
            p.wing,
            p.density,
            p.variables,
            p.objective,
            p.constraints,
            damping=p.damping,
            gradients=g,
        )
        for g in ("analytic", "central")
    }


@pytest.mark.slow
def test_mass_balance_least_balance_bracketed(balance):
    """The least balance (largest S_beta) with V_f >= 126.5 m/s (g = 0.02): the optimum meets
    the constraint on a fresh analysis, and 1e-3 kg m/m less balance breaks it (independent of
    the optimizer: the flutter speed falls as S_beta grows here)."""
    p, sol = balance
    a, c = sol["analytic"], sol["central"]
    assert a.success and c.success and a.active == ["flutter_speed_min"]
    assert a.variables[S_BETA] == pytest.approx(c.variables[S_BETA], abs=1e-6)
    assert a.n_boundaries < c.n_boundaries
    assert all(it["gradients"] == "analytic" for it in a.iterations)
    s = a.variables[S_BETA]
    assert -0.6 < s < -0.4 + 0.4  # inside the bounds: balance is needed, less than at the start

    def vf(x):
        model = aes.AeroelasticModel(with_parameters(p.wing, {S_BETA: x}), damping=p.damping)
        return aes.flutter_boundary(model, p.density).flutter_speed

    assert vf(s) >= 126.5 * (1 - 1e-6) and vf(s + 1e-3) < 126.5


@pytest.mark.slow
def test_negative_weights_keep_the_direction(balance):
    """A negative weight maximizes its variable, whatever the sign of the start (the
    objective is scaled by its magnitude, not its sign)."""
    p, sol = balance
    assert sol["analytic"].objective == pytest.approx(-sol["analytic"].variables[S_BETA])
    assert sol["analytic"].variables[S_BETA] > p.wing.control_surfaces[0].static_moment


def test_an_actuator_on_a_node_falls_back_to_central_differences():
    """The actuator station of the Goland aileron sits on a mesh node, where the analytic
    derivative does not exist: that iterate's gradient is a central difference, and says so."""
    wing = aes.examples.goland_aileron()
    name = "control_surfaces[0].actuators[0].station"
    r = optimize_wing(wing, 1.225, {name: (3.9, 4.6)}, "flutter_speed", {}, max_iterations=1)
    first = r.iterations[0]
    assert first["gradients"].startswith("central") and "mesh node" in first["gradients"]
