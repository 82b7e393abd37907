"""Wing files: the shipped examples equal the built-in wings; malformed files get clear errors."""

import textwrap

import numpy as np
import pytest
from conftest import ROOT

import aeroservo as aes
from aeroservo.files import load_wing, resolve_wing
from aeroservo.files.wing_file import AnalysisOptions


@pytest.mark.parametrize(
    "file,builtin",
    [("goland.toml", aes.examples.goland), ("goland_aileron.toml", aes.examples.goland_aileron)],
)
def test_shipped_files_equal_builtins(file, builtin):
    wing, opts = load_wing(ROOT / "scenarios" / file)
    ref = builtin()
    assert wing.span == ref.span and wing.name == ref.name
    m1, m2 = aes.AeroelasticModel(wing, 10), aes.AeroelasticModel(ref, 10)
    for a, b in ((m1.matrices.Ms, m2.matrices.Ms), (m1.matrices.Ks, m2.matrices.Ks)):
        np.testing.assert_allclose(a.toarray(), b.toarray(), rtol=1e-12)
    assert opts == AnalysisOptions(density=1.225, elements=10, wagner="rt_jones")


GOOD = """
[wing]
span = 4.0
[[wing.segments]]
start = 0.0
end = 4.0
semichord = 0.5
a = -0.3
mass = 10.0
x_alpha = 0.1
inertia = 1.0
EI = 1e6
GJ = 1e5
[[wing.control_surfaces]]
name = "flap"
start = 2.0
end = 4.0
hinge = 0.5
static_moment = 0.05
inertia = 0.02
[[wing.control_surfaces.actuators]]
station = 3.0
stiffness = 1e3
[analysis]
density = 1.0
wagner = { A = [0.5], b = [0.2] }
"""


def write(tmp_path, text):
    p = tmp_path / "wing.toml"
    p.write_text(textwrap.dedent(text))
    return p


def test_good_file(tmp_path):
    wing, opts = load_wing(write(tmp_path, GOOD))
    assert wing.control_surfaces[0].actuators[0].station == 3.0
    assert opts.density == 1.0 and opts.wagner == {"A": [0.5], "b": [0.2]}


@pytest.mark.parametrize(
    "old,new,match",
    [
        ("EI = 1e6", "EI = -1e6", r"wing.toml: wing.segments\[0\].EI = -1e\+06: allowed range"),
        ("EI = 1e6", 'EI = "stiff"', r"wing.segments\[0\].EI = 'stiff': expected a real number"),
        ("GJ = 1e5", "GJ = 1e5\nJG = 3", r"wing.segments\[0\].JG: unknown key"),
        ("mass = 10.0\n", "", r"wing.segments\[0\].mass: missing required key"),
        ("end = 4.0\nhinge", "end = 5.0\nhinge", "outside the wing"),
        ("station = 3.0", "station = 1.0", r"actuators\[0\].station = 1"),
        ("density = 1.0", "density = 0.0", "analysis.density = 0"),
        ("density = 1.0", "density = 1.0\nmachs = 0.5", "analysis.machs: unknown key"),
        ("wagner = { A = [0.5], b = [0.2] }", 'wagner = "fancy"', "unknown set"),
        ("span = 4.0", "span = [4.0]", r"wing.span = \[4.0\]: expected a real number"),
        (
            "[analysis]",
            "[analysis]\nelements = 2.5",
            "analysis.elements = 2.5: expected an integer",
        ),
        ("[wing]", "[wing]\ncolor = 'red'", "wing.color: unknown key"),
        ("static_moment = 0.05", "static_moment = 0.05\nstatic_moment = 0.06", "not valid TOML"),
    ],
)
def test_bad_files(tmp_path, old, new, match):
    assert old in GOOD
    with pytest.raises(aes.InputError, match=match):
        load_wing(write(tmp_path, GOOD.replace(old, new, 1)))


def test_missing_file(tmp_path):
    with pytest.raises(aes.InputError, match="no such file"):
        load_wing(tmp_path / "nope.toml")


def test_resolve_wing():
    assert resolve_wing("goland")[0] == aes.examples.goland()
    with pytest.raises(aes.InputError, match="not a built-in wing"):
        resolve_wing("cessna")
