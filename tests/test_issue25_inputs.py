"""What a new user trips over (issue 25): damping typed as a percentage, a semichord in
millimetres, the Mach number of an export, the one-call model of a wing file, V_D vs the
divergence speed, API consistency and long names. Each test failed before the fix."""

from __future__ import annotations

import argparse
import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

import aeroservo as aes
from aeroservo.cli import _parser, main
from aeroservo.errors import MAX_ELEMENTS, InputError
from aeroservo.files.wing_file import load_wing
from aeroservo.linear.models import tip_deflection_state
from aeroservo.system.damping import StructuralDamping

GOLAND = (ROOT / "scenarios" / "goland.toml").read_text()


def run(capsys, *argv) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def wing_file(tmp_path: Path, extra: str = "", name: str = "w.toml", body: str = GOLAND) -> Path:
    p = tmp_path / name
    p.write_text(body + "\n" + extra, encoding="utf-8")
    return p


# ---- item 2: plausibility of damping, units of the chord, Mach of an export ----------------


@pytest.mark.parametrize(
    ("table", "hint"), [("g = 1.0", "g = 0.01"), ("ratio = 0.5", "ratio = 0.005")]
)
def test_damping_typed_as_a_percentage_is_warned(tmp_path, capsys, table, hint):
    p = wing_file(tmp_path, f"[damping]\n{table}\n")
    with pytest.warns(UserWarning, match="percentage") as rec:
        load_wing(p)
    assert str(p) in str(rec[0].message) and hint in str(rec[0].message)
    code, _out, err = run(capsys, "flutter", p, "--v-max", "150")
    assert code == 0 and "percentage" in err and hint in err


@pytest.mark.parametrize(
    "damping", [StructuralDamping.structural(0.2), StructuralDamping.modal(0.1)]
)
def test_plausible_damping_is_not_warned(damping):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        StructuralDamping(damping.kind, damping.ratios, g=damping.g)


def test_semichord_in_millimetres_names_the_chord(tmp_path):
    p = wing_file(tmp_path, body=GOLAND.replace("semichord = 0.9144", "semichord = 914.4"))
    with pytest.raises(InputError, match="semichord 914.4 m") as exc:
        load_wing(p)
    msg = str(exc.value)
    assert "inertia" in msg and "semichord 914.4 m" in msg and "millimetres, write 0.9144" in msg


def test_a_chord_longer_than_the_span_is_warned():
    seg = aes.examples.goland().segments[0]
    import dataclasses

    wide = dataclasses.replace(seg, semichord=914.4, x_alpha=0.0)
    with pytest.warns(UserWarning, match="millimetres"):
        aes.Wing(span=6.096, segments=(wide,))


def test_export_beyond_mach_07_is_warned(tmp_path, capsys):
    code, _out, err = run(
        capsys, "export", "goland_aileron", "--speed", "900", "--out", tmp_path / "m.npz"
    )
    assert code == 0 and "Mach 2.645" in err and "strip theory does not apply" in err
    code, _out, err = run(
        capsys, "export", "goland_aileron", "--speed", "100", "--out", tmp_path / "n.npz"
    )
    assert code == 0 and "Mach" not in err


# ---- item 4: the model as the wing file describes it --------------------------------------


SETTINGS = """[analysis]
density = 1.0
elements = 14
wagner = "fit4"
[damping]
g = 0.02
"""


def test_load_model_is_what_the_cli_computes(tmp_path, capsys):
    p = wing_file(tmp_path, SETTINGS, body=GOLAND.split("[analysis]")[0])
    code, out, _ = run(capsys, "flutter", p, "--json")
    cli = json.loads(out)
    case = aes.load_model(p)
    assert case.model.n_elements == 14 and case.density == 1.0
    assert case.model.damping.g == 0.02 and case.model.wagner.name == "fit4"
    r = case.flutter()
    assert r.flutter_speed == pytest.approx(cli["flutter_speed"], rel=1e-12)
    # the README's old route dropped the settings: a different answer
    wing = load_wing(p)[0]
    old = aes.flutter_boundary(aes.AeroelasticModel(wing), 1.225)
    assert abs(old.flutter_speed / r.flutter_speed - 1) > 1e-3
    # and the export is the same damped model
    code, _out, _ = run(capsys, "export", p, "--speed", "100", "--out", tmp_path / "m.npz")
    assert code == 0
    exported = np.load(tmp_path / "m.npz")
    sys = case.statespace(100.0)
    assert exported["A"].shape == (sys.nstates, sys.nstates)
    np.testing.assert_allclose(exported["A"], sys.A, rtol=1e-12, atol=1e-12 * abs(sys.A).max())


def test_load_model_with_an_altitude(tmp_path, capsys):
    p = wing_file(tmp_path, "[analysis]\naltitude = 3000.0\n", body=GOLAND.split("[analysis]")[0])
    case = aes.load_model(p)
    assert case.atmosphere is not None and case.atmosphere.altitude == 3000.0
    code, out, _ = run(capsys, "flutter", p, "--json")
    assert json.loads(out)["flutter_speed"] == pytest.approx(
        case.flutter().flutter_speed, rel=1e-12
    )
    assert case.flutter().flutter_mach is not None


def test_load_model_of_a_builtin_wing_and_bad_input():
    assert aes.load_model("goland").model.n_elements == 10
    with pytest.raises(InputError, match="path = 3"):
        aes.load_model(3)


# ---- item 5: V_D is the dive speed, V_div the divergence speed -----------------------------


def test_envelope_table_names_divergence_v_div(capsys):
    code, out, _ = run(capsys, "envelope", "goland", "--altitudes", "0", "--vd", "150")
    assert code == 0
    assert "Vdiv EAS" in out and "VD EAS" not in out


@pytest.mark.parametrize("notebook", ["01_goland_flutter", "05_flutter_clearance"])
def test_notebooks_do_not_call_divergence_v_d(notebook):
    cells = json.loads((ROOT / "notebooks" / f"{notebook}.ipynb").read_text())["cells"]
    for c in cells:
        text = "".join(c["source"])
        for line in text.splitlines():
            assert not ("V_D" in line and "diverg" in line.lower()), line
            assert "V_D [m/s]" not in line and "V_D EAS P-G" not in line and "q_D" not in line


# ---- item 10: a consistent API and true docs ------------------------------------------------


@pytest.mark.parametrize(
    ("cls", "name"),
    [
        ("aeroservo.design.boundary_result:ClosedLoopBoundary", "flutter_speed"),
        ("aeroservo.design.boundary_result:ClosedLoopBoundary", "stable_intervals"),
        ("aeroservo.simulate.result:SimulationResult", "saturated_fraction"),
        ("aeroservo.simulate.result:SimulationResult", "rate_limited_fraction"),
    ],
)
def test_values_without_arguments_are_properties(cls, name):
    import importlib

    mod, attr = cls.split(":")
    assert isinstance(getattr(getattr(importlib.import_module(mod), attr), name), property)


@pytest.mark.parametrize("balanced", [True, False])
def test_tip_deflection_state_takes_the_statespace(balanced):
    wing = aes.examples.goland_aileron()
    sys = aes.statespace(wing, 100.0, 1.225, balanced=balanced)
    builder = aes.StateSpaceBuilder(aes.AeroelasticModel(wing, 10), 1.225)
    x_sys = tip_deflection_state(sys, 0.01)
    x_b = tip_deflection_state(builder, 0.01, balanced=balanced)
    np.testing.assert_allclose(x_sys, x_b, rtol=1e-12, atol=0)
    assert (sys.state_scaling * x_sys)[:2].shape == (2,)
    with pytest.raises(InputError, match="StateSpace"):
        tip_deflection_state(np.eye(2), 0.01)


def test_every_modes_option_has_help():
    parser = _parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    modes = sub.choices["modes"]
    for action in modes._actions:
        assert action.help, action.dest


def test_wing_file_docs_state_the_element_limit():
    text = (ROOT / "docs" / "wing-file.md").read_text()
    assert f"at most {MAX_ELEMENTS} elements" in text and f"<= {MAX_ELEMENTS} |" in text


def test_notebook_03_names_the_solver_it_runs():
    text = (ROOT / "notebooks" / "03_mpc_vs_saturated_lqr.ipynb").read_text()
    assert "qpOASES |" not in text and "DAQP" in text


# ---- item 11: bad input ---------------------------------------------------------------------


def test_a_huge_modal_output_number_is_an_input_error(tmp_path, capsys):
    name = "modal_" + "1" * 5000
    with pytest.raises(InputError, match="mode number must be in") as exc:
        aes.statespace(aes.examples.goland_aileron(), 100.0, 1.225, outputs=[name])
    assert len(str(exc.value)) < 300
    code, _out, err = run(
        capsys,
        "export",
        "goland_aileron",
        "--speed",
        "100",
        "--outputs",
        name,
        "--out",
        tmp_path / "m.npz",
    )
    assert code == 2 and "mode number" in err and len(err) < 400
    assert not (tmp_path / "m.npz").exists()


def test_duration_times_rate_over_the_limit_names_file_and_keys(tmp_path, capsys):
    text = (ROOT / "scenarios" / "goland_aileron_lqr.toml").read_text()
    (tmp_path / "goland_aileron.toml").write_text(
        (ROOT / "scenarios" / "goland_aileron.toml").read_text()
    )
    import re

    text = re.sub(r"(?m)^duration = .*$", "duration = 600.0", text)
    text = re.sub(r"(?m)^sample_rate = .*$", "sample_rate = 20000.0", text)
    p = tmp_path / "long.toml"
    p.write_text(text)
    code, _out, err = run(capsys, "simulate", p, "--out", tmp_path / "out")
    assert code == 2
    assert str(p) in err and "simulation.duration" in err and "simulation.sample_rate" in err
    assert not (tmp_path / "out").exists()


def test_export_with_compressibility_is_the_flutter_commands_model(tmp_path, capsys):
    """Review finding: a file asking for Prandtl-Glauert was exported incompressible. At 200 m/s
    and 10 km (Mach 0.668) the corrected model is unstable (flutter 198.07 m/s) and the
    incompressible one is not."""
    body = GOLAND.split("[analysis]")[0]
    pg = wing_file(
        tmp_path,
        '[analysis]\naltitude = 10000.0\ncompressibility = "prandtl-glauert"\n',
        "pg.toml",
        body,
    )
    code, out, _ = run(capsys, "flutter", pg, "--json")
    assert code == 0 and json.loads(out)["flutter_speed"] < 200.0
    code, out, _ = run(capsys, "export", pg, "--speed", "200", "--out", tmp_path / "pg.npz")
    assert code == 0 and "Prandtl-Glauert at Mach 0.6679" in out
    A = np.load(tmp_path / "pg.npz")["A"]
    assert np.linalg.eigvals(A).real.max() > 0  # unstable above its flutter speed
    case = aes.load_model(pg)
    np.testing.assert_allclose(case.statespace(200.0).A, A, rtol=1e-12, atol=1e-12 * abs(A).max())
    beta = np.sqrt(1 - case.mach_at(200.0) ** 2)
    assert case.mach_at(200.0) == pytest.approx(200.0 / case.atmosphere.speed_of_sound)
    assert 0 < beta < 1
    plain = aes.statespace(case.model, 200.0, case.density)
    assert np.linalg.eigvals(plain.A).real.max() < 0  # the incompressible model differs
