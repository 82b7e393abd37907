"""Analytic flutter and divergence sensitivities against central finite differences.

Every analytic derivative (eigenvalue derivatives at the crossing, matrix derivatives from the
element integrals) is compared with a central difference of the speed computed by the engine
itself at a tight tolerance (rtol 1e-12, relative step 2e-5; see FLOOR and DIV_STEP), on the
Goland wing (its geometry as in reference case ``goland_clean_flutter_strip_sea_level``), the
Goland wing with its aileron, the HALE wing (reference case ``hale_patil_hodges_cesnik`` at its
20 km density, 0.0889 kg/m^3) with and without an aileron, and one randomized wing of each class
of the stability corpus (``tests/wing_corpus.py``). Agreement: 1e-4 relative on normalized
derivatives ``p / V dV/dp``.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_stability_named import HALE, hale_wing
from wing_corpus import corpus

import aeroservo as aes
from aeroservo.errors import InputError
from aeroservo.stability.divergence import divergence_speed
from aeroservo.stability.result import Crossing
from aeroservo.stability.sensitivity import flutter_sensitivities, parameter_values
from aeroservo.structure.examples import goland, goland_aileron
from aeroservo.studies.optimize import with_parameters
from aeroservo.system.assembly import assemble, structural_derivative

TOL = 1e-4
STEP = 2e-5
RTOL = 1e-12
DIV_STEP = 1e-2
FLOOR = 1e-6
"""Absolute floor on normalized derivatives: 40 x the noise of a central difference (engine
error about RTOL relative, over 2 STEP), about 1e-5 of the usual O(0.1-1) values. The step
keeps the truncation error below 3e-5 relative on the most curved case (flutter past
divergence, ``divergence_critical_01``: 8e-4 with a step of 1e-4, 8e-6 with 1e-5)."""


def perturbed(wing: aes.Wing, name: str, h: float) -> aes.Wing:
    """The wing with parameter ``name`` (wing-file name) moved by ``h``."""
    return with_parameters(wing, {name: parameter_values(wing)[name][3] + h})


def _moved(model, density, name, value, h):
    """(model, density) with parameter ``name`` moved by ``h``."""
    if name == "density":
        return model, density + h
    return aes.AeroelasticModel(perturbed(model.wing, name, h), model.n_elements), density


def central(model, density, name, value, v_max):
    """Central differences of (V_f, f_f, V_d) in parameter ``name``. The divergence speed is
    a direct solve, precise to about 1e-10 relative only: its step is DIV_STEP (smooth, so the
    truncation error stays near 1e-6)."""
    h = STEP * (abs(value) or 1.0)
    p, m = (
        aes.flutter_boundary(*_moved(model, density, name, value, s * h), rtol=RTOL, v_max=v_max)
        for s in (1.0, -1.0)
    )

    def d(attr):
        a, b = getattr(p, attr), getattr(m, attr)
        return None if a is None or b is None else (a - b) / (2 * h)

    dd = None
    if p.divergence_speed is not None:
        hd = DIV_STEP * (abs(value) or 1.0)
        a, b = (
            divergence_speed(mm.system(rho))
            for mm, rho in (_moved(model, density, name, value, s * hd) for s in (1.0, -1.0))
        )
        dd = None if a is None or b is None else (a - b) / (2 * hd)
    return d("flutter_speed"), d("flutter_frequency"), dd


def _named():
    hale = HALE["inputs"]
    return [
        ("goland", aes.AeroelasticModel(goland()), 1.225, None),
        ("goland_aileron", aes.AeroelasticModel(goland_aileron()), 1.225, None),
        ("hale", aes.AeroelasticModel(hale_wing()), hale["density_kg_m3"], None),
        ("hale_aileron", aes.AeroelasticModel(hale_wing(True)), hale["density_kg_m3"], None),
    ]


def _random():
    """One wing of each corpus class that has a control surface or several segments."""
    seen, out = set(), []
    for case in corpus():
        if case.klass in seen or case.klass in ("hale",):
            continue
        seen.add(case.klass)
        out.append((case.name, case.model, case.density, case.v_max))
    return out


CASES = _named() + _random()


def _check(got, ref, value, base, what):
    """Normalized derivatives ``p / V dV/dp`` agree within TOL relative, or within FLOOR where
    the parameter barely moves the speed (there the central difference is noise: the engine's
    relative error rtol over the relative step)."""
    if ref is None:
        return
    scale = (abs(value) or 1.0) / base
    n_got, n_ref = got * scale, ref * scale
    assert abs(n_got - n_ref) <= TOL * abs(n_ref) + FLOOR, (
        f"{what}: analytic {got:.8g}, central {ref:.8g} (normalized {n_got:.6g}, {n_ref:.6g})"
    )


@pytest.mark.parametrize("name,model,density,v_max", CASES, ids=[c[0] for c in CASES])
def test_against_central_differences(name, model, density, v_max):
    s = flutter_sensitivities(model, density, rtol=RTOL, v_max=v_max)
    assert s.flutter_speed is not None or s.divergence_speed is not None
    if s.non_differentiable:
        pytest.skip(s.non_differentiable)
    params = list(s.values)
    rng = np.random.default_rng(len(name))
    if len(params) > 8:  # a fixed random subset keeps the test short; density always
        params = [*rng.choice(params[:-1], 7, replace=False), "density"]
    for p in params:
        dv, df, dd = central(model, density, p, s.values[p], v_max)
        x = s.values[p]
        if s.flutter_speed is not None:
            _check(s.d_flutter_speed[p], dv, x, s.flutter_speed, f"{name} dV_f/d{p}")
            _check(s.d_flutter_frequency[p], df, x, s.flutter_frequency, f"{name} df_f/d{p}")
        if s.divergence_speed is not None:
            _check(s.d_divergence_speed[p], dd, x, s.divergence_speed, f"{name} dV_d/d{p}")


@pytest.mark.parametrize("name", list(parameter_values(goland_aileron())))
def test_matrix_derivatives_are_the_assembly_slope(name):
    """The structural matrices are linear in each parameter: the derivative from the element
    integrals equals the slope of two assemblies (a check of the integrals, not a source)."""
    wing = goland_aileron()
    model = aes.AeroelasticModel(wing)
    owner, idx, key, value = parameter_values(wing)[name]
    dM, dK = structural_derivative(wing, model.mesh, owner, idx, key)
    h = 0.01 * abs(value)
    a, b = assemble(wing, model.mesh), assemble(perturbed(wing, name, h), model.mesh)
    for d, x, y in ((dM, a.Ms, b.Ms), (dK, a.Ks, b.Ks)):
        slope = ((y - x) / h).toarray()
        np.testing.assert_allclose(d.toarray(), slope, atol=1e-10 * max(abs(slope).max(), 1.0))


def test_one_boundary_for_all_parameters(monkeypatch):
    """All derivatives cost one flutter boundary (never one per parameter)."""
    import aeroservo.stability.sensitivity as sens

    calls = []
    original = sens.flutter_boundary
    monkeypatch.setattr(
        sens, "flutter_boundary", lambda *a, **k: calls.append(1) or original(*a, **k)
    )
    s = flutter_sensitivities(aes.AeroelasticModel(goland_aileron()), 1.225)
    assert len(s.d_flutter_speed) == len(parameter_values(goland_aileron())) + 1
    assert len(calls) == 1


def test_mode_switch_is_reported_not_differentiated():
    """Two branches going unstable at nearly the same speed: no derivative, a reason."""
    model = aes.AeroelasticModel(goland())
    r = aes.flutter_boundary(model, 1.225)
    f = r.flutter
    other = Crossing(f.speed * (1 + 1e-4), f.frequency * 2, f.mode + 1, "onset")
    r.crossings = sorted([*r.crossings, other], key=lambda c: c.speed)
    s = flutter_sensitivities(model, 1.225, result=r)
    assert s.non_differentiable and "mode switch" in s.non_differentiable
    assert s.d_flutter_speed == {} and s.to_dict()["non_differentiable"]


def test_normalized_and_dict():
    s = flutter_sensitivities(aes.AeroelasticModel(goland()), 1.225, ["segments[0].GJ", "density"])
    n = s.normalized()
    assert set(n) == {"segments[0].GJ", "density"}
    assert n["segments[0].GJ"] == pytest.approx(
        0.99e6 * s.d_flutter_speed["segments[0].GJ"] / s.flutter_speed
    )
    d = s.to_dict()
    assert d["d_flutter_speed"].keys() == n.keys() and d["units"]


@pytest.mark.parametrize(
    "kwargs,fragment",
    [
        ({"parameters": ["segments[3].GJ"]}, "'segments[3].GJ' is not a parameter"),
        ({"parameters": "density"}, "expected a list"),
        ({"density": None}, "density = None"),
    ],
)
def test_bad_arguments(kwargs, fragment):
    kw = {"density": 1.225, **kwargs}
    with pytest.raises(InputError, match=fragment.replace("[", r"\[").replace("]", r"\]")):
        flutter_sensitivities(aes.AeroelasticModel(goland()), **kw)
    with pytest.raises(InputError, match="expected an aeroservo.AeroelasticModel"):
        flutter_sensitivities(goland(), 1.225)


# -- the command line ---------------------------------------------------------------------------
def test_cli_json_and_plot(tmp_path, capsys):
    import json

    from aeroservo.cli import main

    png = tmp_path / "s.png"
    assert main(["sensitivity", "goland_aileron", "--json", "--plot", str(png)]) == 0
    out = json.loads(capsys.readouterr().out)
    ref = flutter_sensitivities(aes.AeroelasticModel(goland_aileron()), 1.225)
    assert out["d_flutter_speed"].keys() == ref.d_flutter_speed.keys()
    for k, v in ref.d_flutter_speed.items():
        assert out["d_flutter_speed"][k] == pytest.approx(v, rel=1e-6)
    assert "control_surfaces[0].actuators[1].stiffness" in out["normalized_flutter_speed"]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["sensitivity", "goland"]) == 0
    assert "segments[0].GJ" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv,fragment",
    [
        (["sensitivity", "goland", "--plot", "s.foo"], "'foo'"),
        (["sensitivity", "goland", "--density", "9"], "--density"),
        (["sensitivity", "goland", "--top", "0"], "--top = 0"),
        (["sensitivity", "goland", "--structural-g", "0.02"], "undamped models only"),
    ],
)
def test_cli_bad_input(argv, fragment, tmp_path, monkeypatch, capsys):
    from aeroservo.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and fragment in err[0]
    assert list(tmp_path.iterdir()) == []


# -- closed loop: central differences of a trade case (documented as such) -----------------------
def test_closed_loop_case_sensitivities():
    """The shipped trade study's middle case (LQR, Bryson 500 N m): derivatives of the
    closed-loop flutter speed by central differences with two steps agree (1e-3 relative),
    so the step is in the flat region between truncation and boundary noise."""
    from conftest import ROOT

    from aeroservo.files import load_scenario
    from aeroservo.studies.runs import study_from_scenario
    from aeroservo.studies.trade.sensitivity import case_sensitivities

    study = study_from_scenario(load_scenario(ROOT / "scenarios" / "trade_aileron.toml"))
    case = {"aileron_start": 0.6, "aileron_chord": 0.2, "bryson_hinge_moment": 500.0}
    a = case_sensitivities(study, case, ["aileron_chord", "bryson_hinge_moment"], rel_step=1e-3)
    b = case_sensitivities(study, case, ["aileron_chord", "bryson_hinge_moment"], rel_step=3e-4)
    assert a.case["closed_loop_flutter_speed"] > a.case["open_loop_flutter_speed"]
    da, db = a.derivatives["closed_loop_flutter_speed"], b.derivatives["closed_loop_flutter_speed"]
    assert set(da) == {"aileron_chord", "bryson_hinge_moment"} and not a.unavailable
    for k in da:
        assert da[k] == pytest.approx(db[k], rel=1e-3)
    assert "finite differences" in a.to_dict()["method"]
    with pytest.raises(InputError, match="'hinge_stiffness' is not a parameter"):
        case_sensitivities(study, case, ["hinge_stiffness"])
