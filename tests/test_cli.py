"""The command line: JSON contract, overrides, plots, exit codes."""

import json
import subprocess
import sys

import pytest
from conftest import ROOT

import aeroservo as aes
from aeroservo.cli import main


def run_json(capsys, *argv):
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_flutter_json_matches_python_api(capsys, goland10_flutter):
    out = run_json(capsys, "flutter", "goland")
    for key in (
        "flutter_speed",
        "flutter_frequency",
        "divergence_speed",
        "n_states",
        "density",
        "n_elements",
    ):
        assert key in out
    assert out["flutter_speed"] == pytest.approx(goland10_flutter.flutter_speed, rel=1e-9)
    assert out["flutter_frequency"] == pytest.approx(goland10_flutter.flutter_frequency, rel=1e-9)
    assert out["n_states"] == 82 and out["n_elements"] == 10 and out["density"] == 1.225


def test_flutter_wing_file_and_overrides(capsys):
    path = str(ROOT / "scenarios" / "goland.toml")
    base = run_json(capsys, "flutter", path)
    out = run_json(
        capsys, "flutter", path, "--density", "1.02", "--elements", "12", "--wagner", "fit4"
    )
    assert out["density"] == 1.02 and out["n_elements"] == 12 and out["wagner"] == "fit4"
    assert out["n_states"] == 2 * 36 + 4 * 13
    assert out["flutter_speed"] > base["flutter_speed"]  # thinner air flutters later


def test_pk_option(capsys):
    out = run_json(capsys, "flutter", "goland", "--pk")
    assert out["pk_exact_theodorsen"]["flutter_speed"] == pytest.approx(137.46, rel=1e-3)


def test_plot_written_atomically(tmp_path, capsys):
    png = tmp_path / "vg.png"
    assert main(["flutter", "goland", "--plot", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["vg.png"]  # no temporary left behind
    assert "flutter:" in capsys.readouterr().out


def test_plot_into_missing_folder_fails_cleanly(tmp_path, capsys):
    assert main(["flutter", "goland", "--plot", str(tmp_path / "no" / "vg.png")]) == 2
    assert "does not exist" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv,msg",
    [
        (["flutter", "cessna"], "not a built-in wing"),
        (["flutter", "goland", "--wagner", "foo"], "unknown set"),
        (["flutter", "missing.toml"], "no such file"),
    ],
)
def test_input_errors_exit_2(argv, msg, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert msg in err and err.count("\n") == 1


@pytest.mark.parametrize(
    "argv",
    [
        ["flutter", "goland", "--density", "-1"],
        ["flutter"],
        ["nonsense"],
        ["flutter", "goland", "--no-such-option"],
        [],
    ],
)
def test_usage_errors_exit_2_in_one_line(argv, capsys):
    """argparse's usage errors are one line too (not the usage dump), exit 2."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and err.startswith("aeroservo: error: ")
    assert "--help" in err


def test_modes_and_examples(capsys):
    out = run_json(capsys, "modes", "goland", "-n", "3")
    assert out["labels"][:2] == ["1st bending", "1st torsion"]
    assert main(["examples"]) == 0
    assert "goland_aileron" in capsys.readouterr().out


def test_console_script_runs():
    """The installed entry point, as a user types it (python -m for the same code path)."""
    proc = subprocess.run(
        [sys.executable, "-m", "aeroservo", "flutter", "goland_aileron", "--json"],
        capture_output=True,
        text=True,
        check=True,
    )
    out = json.loads(proc.stdout)
    assert out["wing"] == aes.examples.goland_aileron().name
    assert 130 < out["flutter_speed"] < 145


_RUN_AND_LIST_MODULES = (
    "import sys, contextlib, io\n"
    "from aeroservo.cli import main\n"
    "with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):\n"
    "    code = main(sys.argv[1:])\n"
    "print(code)\n"
    "print(' '.join(sorted(sys.modules)))\n"
)

#: What ``aeroservo flutter goland --json`` may import (issue 17): numpy, scipy.linalg and
#: scipy.sparse, and these aeroservo modules. A new top-level import that drags another
#: module into the flutter path fails here; add it only if the flutter path needs it.
FLUTTER_MODULES = {
    "aeroservo",
    "aeroservo._lazy",
    "aeroservo._threads",
    "aeroservo._version",
    "aeroservo.errors",
    "aeroservo.result_shape",  # the shape of every result (issue 39): no numpy at import
    *(
        f"aeroservo.aero{m}"
        for m in (
            "",
            ".atmosphere",
            ".dlm",  # numpy only: the doublet-lattice settings and their checks
            ".dlm_settings",
            ".indicial",
            ".lattice",
            ".rfa",
            ".swept_strip",
            ".theodorsen",
        )
    ),
    *(
        f"aeroservo.cli{m}"
        for m in (
            "",
            ".aero_options",
            ".analysis",
            ".envelope",
            ".importing",
            ".options",
            ".optimize",
            ".results",
            ".scenarios",
            ".sensitivity",
        )
    ),
    *(
        f"aeroservo.files{m}"
        for m in ("", ".mass_tables", ".toml_tables", ".user_files", ".wing_file")
    ),
    *(
        f"aeroservo.stability{m}"
        for m in (
            "",
            ".assignment",
            ".boundary",
            ".branches",
            ".brent",
            ".certificate",
            ".crossings",
            ".divergence",
            ".near_critical",
            ".matched",
            ".modal",
            ".result",
            ".tracking",
        )
    ),
    "aeroservo.studies",
    "aeroservo.studies.flight_condition",
    "aeroservo.studies.kinds",  # the registry of scenario kinds: the scenario commands' parsers
    "aeroservo.studies.study_options",
    *(
        f"aeroservo.structure{m}"
        for m in ("", ".beam_element", ".examples", ".masses", ".mesh", ".wing")
    ),
    *(
        f"aeroservo.system{m}"
        for m in (
            "",
            ".aeroelastic",
            ".assembly",
            ".damping",
            ".dof_damping",  # per-DOF viscous damping: part of the damping's definition
            ".first_order",
            ".matrices",
            ".point_masses",
            ".swept_assembly",
        )
    ),
}
HEAVY = (
    "matplotlib",
    "control",
    "casadi",
    "dask",
    "distributed",
    "xarray",
    "pandas",
    "tqdm",
    "scipy.optimize",
    "scipy.special",
    "scipy.signal",
    "scipy.integrate",
    "scipy.interpolate",
    "scipy.io",
)


def _modules_of(*argv: str) -> tuple[int, set]:
    proc = subprocess.run(
        [sys.executable, "-c", _RUN_AND_LIST_MODULES, *argv],
        capture_output=True,
        text=True,
        check=True,
    )
    code, mods = proc.stdout.strip().splitlines()
    return int(code), set(mods.split())


def test_flutter_command_imports_only_what_it_needs():
    """The set of modules ``aeroservo flutter goland --json`` imports is pinned."""
    code, mods = _modules_of("flutter", "goland", "--json")
    assert code == 0
    assert {m for m in mods if m.startswith("aeroservo")} == FLUTTER_MODULES
    assert [m for m in HEAVY if m in mods] == []


@pytest.mark.parametrize(
    "argv",
    [
        ("flutter", "no_such_wing.toml"),
        ("flutter", "goland", "--density", "-1"),
        ("flutter", "goland", "--plot", "v.xyz"),
        ("envelope", "goland"),  # --altitudes missing
    ],
)
def test_input_errors_answer_before_numpy(argv):
    """A missing file, a bad option or an unknown figure format is reported (exit 2) before
    numpy is imported."""
    code, mods = _modules_of(*argv)
    assert code == 2
    assert "numpy" not in mods


def test_help_and_import_load_no_numerics():
    """``import aeroservo`` and ``aeroservo --help`` import neither numpy nor scipy (the public
    names load on first use): the help answers in a tenth of a second."""
    code = (
        "import sys, contextlib, io\n"
        "import aeroservo, aeroservo.cli\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    try:\n"
        "        aeroservo.cli.main(['--help'])\n"
        "    except SystemExit:\n"
        "        pass\n"
        "heavy = [m for m in ('numpy', 'scipy', 'matplotlib', 'control', 'casadi')\n"
        "         if m in sys.modules]\n"
        "print(heavy)\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert proc.stdout.strip() == "[]"
    assert aes.flutter_boundary is aes.stability.boundary.flutter_boundary
    assert "flutter_boundary" in dir(aes)
    with pytest.raises(AttributeError, match="no attribute 'nonexistent'"):
        aes.nonexistent  # noqa: B018
