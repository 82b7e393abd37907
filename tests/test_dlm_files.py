"""The aerodynamic model choice at every user-facing entry point (issue 36): wing files
(``[analysis]`` ``aero``/``mach`` and ``[dlm]``), scenario files (``[model]`` and
``[model.dlm]``), optimization files, and the command line (``--aero``, ``--boxes``, ``--mach``,
``--compressibility matched``); strip theory stays the default, unchanged; bad input is one line,
exit 2, nothing written. Coarse lattices (4 chordwise boxes) and few elements keep it cheap."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from conftest import ROOT

import aeroservo as aes
from aeroservo.aero.dlm_settings import DoubletLattice
from aeroservo.cli import main
from aeroservo.files.scenario_file import load_scenario, scenario_from_dict
from aeroservo.files.wing_file import load_wing
from aeroservo.files.wing_model import load_model

GOLAND = ROOT / "scenarios" / "goland.toml"
COARSE = {"chordwise": 4, "spanwise": 8}


@pytest.fixture(scope="module")
def aic_cache(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("aics")


@pytest.fixture(autouse=True)
def _cache(monkeypatch, aic_cache):
    """The AICs of these tests in a folder of their own."""
    monkeypatch.setenv("AEROSERVO_CACHE", str(aic_cache))


@pytest.fixture
def panelaero():
    return pytest.importorskip("panelaero", reason="PanelAero is not installed (aeroservo[dlm])")


def _wing_file(tmp_path: Path, extra: str, name: str = "w.toml") -> Path:
    """Goland's wing file with ``extra`` in place of its ``[analysis]`` table."""
    text = GOLAND.read_text(encoding="utf-8").split("[analysis]")[0]
    path = tmp_path / name
    path.write_text(text + extra, encoding="utf-8")
    return path


def _run(capsys, *argv) -> tuple[int, str, str]:
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


# --- wing files --------------------------------------------------------------------------------


def test_wing_file_dlm_round_trip(tmp_path, panelaero):
    path = _wing_file(
        tmp_path,
        '[analysis]\ndensity = 1.0\nelements = 6\naero = "dlm"\nmach = 0.3\n\n'
        '[dlm]\nchordwise = 4\nspanwise = 8\nlags = 3\nkernel = "parabolic"\n',
    )
    _wing, opts = load_wing(path)
    expected = DoubletLattice(chordwise=4, spanwise=8, lags=3, kernel="parabolic")
    assert opts.aero == expected and opts.mach == 0.3
    case = load_model(path)
    assert case.model.aero == expected and case.model.aero_model == "dlm"
    assert case.model.dlm.grid.n_boxes == 32
    assert case.mach_at(150.0) == 0.3
    r = case.flutter()
    assert r.mach == 0.3 and r.compressibility == "dlm" and r.density == 1.0


def test_wing_file_strip_fixed_mach_is_prandtl_glauert(tmp_path):
    path = _wing_file(tmp_path, '[analysis]\naero = "strip"\nmach = 0.5\nelements = 4\n')
    _wing, opts = load_wing(path)
    assert opts.aero is None and opts.mach == 0.5
    case = load_model(path)
    assert case.model.aero is None
    r = case.flutter()
    assert r.mach == 0.5 and r.compressibility == "prandtl-glauert"
    ref = aes.flutter_boundary(aes.AeroelasticModel(aes.examples.goland(), 4), 1.225, mach=0.5)
    assert r.flutter_speed == ref.flutter_speed


def test_wing_file_matched_compressibility_allowed(tmp_path):
    path = _wing_file(tmp_path, '[analysis]\naltitude = 3000.0\ncompressibility = "matched"\n')
    _wing, opts = load_wing(path)
    assert opts.compressibility == "matched" and opts.mach is None


@pytest.mark.parametrize(
    "extra,fragment",
    [
        ('[analysis]\naero = "dlm"\n[dlm]\nchordwise = 0\n', "w.toml: dlm.chordwise = 0: "),
        ('[analysis]\naero = "dlm"\n[dlm]\nlags = "x"\n', "w.toml: dlm.lags = 'x': "),
        ('[analysis]\naero = "dlm"\n[dlm]\nboxes = 4\n', "w.toml: dlm.boxes = 4: unknown key"),
        ("[dlm]\nchordwise = 4\n", "w.toml: dlm: doublet-lattice settings need analysis.aero"),
        ('[analysis]\naero = "vlm"\n', "w.toml: analysis.aero = 'vlm': allowed values"),
        ('[analysis]\naero = "dlm"\nmach = 1.2\n', "w.toml: analysis.mach = 1.2: "),
        ("[analysis]\nmach = 0.95\n", "w.toml: analysis.mach = 0.95: the Prandtl-Glauert"),
        (
            '[analysis]\naltitude = 1000.0\ncompressibility = "matched"\nmach = 0.3\n',
            "w.toml: analysis.mach = 0.3: give a fixed Mach number",
        ),
        ('[analysis]\ncompressibility = "matched"\n', "needs altitude"),
    ],
)
def test_wing_file_bad_aero_keys(tmp_path, extra, fragment):
    path = _wing_file(tmp_path, extra)
    with pytest.raises(aes.InputError, match=re.escape(fragment)) as err:
        load_wing(path)
    msg = str(err.value)
    assert fragment in msg and "\n" not in msg


def test_wing_file_bad_dlm_on_the_command_line(tmp_path, capsys):
    path = _wing_file(tmp_path, '[analysis]\naero = "dlm"\n[dlm]\nlags = "x"\n')
    plot = tmp_path / "vg.png"
    code, out, err = _run(capsys, "flutter", str(path), "--plot", str(plot))
    assert code == 2 and out == "" and not plot.exists()
    assert err.strip().count("\n") == 0 and "dlm.lags = 'x'" in err and str(path) in err


# --- scenario files ----------------------------------------------------------------------------


def _scenario(model: dict, kind: str = "flutter", **top) -> dict:
    data = {
        "scenario": {"name": "s", "kind": kind},
        "wing": {"builtin": "goland"},
        "flight": {"density": 1.225},
        "model": {"elements": 6, **model},
    }
    data.update(top)
    return data


def test_scenario_dlm_round_trip(tmp_path, panelaero):
    sc = scenario_from_dict(
        _scenario({"aero": "dlm", "mach": 0.2, "dlm": {**COARSE, "rfa": "minimum-state"}}),
        "s.toml",
    )
    expected = DoubletLattice(**COARSE, rfa="minimum-state")
    assert sc.aero == expected and sc.mach == 0.2
    model = sc.model()
    assert model.aero == expected and model.dlm.grid.n_boxes == 32
    from aeroservo.studies.runs import run_flutter

    run = run_flutter(sc)
    s = run.summary
    assert s["aero"] == "dlm" and s["mach"] == 0.2 and s["mach_source"] == "fixed"
    assert s["dlm"]["n_boxes"] == 32 and s["dlm"]["settings"]["rfa"] == "minimum-state"
    assert s["dlm"]["fit"]["mach"] == 0.2


def test_scenario_strip_default_unchanged():
    sc = scenario_from_dict(_scenario({}), "s.toml")
    assert sc.aero is None and sc.mach is None and sc.model().aero is None


def test_scenario_file_and_command_line_overrides(tmp_path, capsys, panelaero):
    path = tmp_path / "f.toml"
    path.write_text(
        '[scenario]\nname = "f"\nkind = "flutter"\n[wing]\nbuiltin = "goland"\n'
        '[flight]\ndensity = 1.225\n[model]\nelements = 4\naero = "dlm"\n'
        "[model.dlm]\nchordwise = 4\nspanwise = 6\n",
        encoding="utf-8",
    )
    sc = load_scenario(path)
    assert sc.aero == DoubletLattice(chordwise=4, spanwise=6)
    code, out, _ = _run(capsys, "run", str(path), "--out", str(tmp_path / "o"), "--json")
    assert code == 0
    s = json.loads(out)
    assert s["aero"] == "dlm" and s["mach"] == 0.0 and s["mach_source"] == "default"
    code, out, _ = _run(
        capsys, "run", str(path), "--out", str(tmp_path / "o2"), "--json", "--aero", "strip"
    )
    assert code == 0 and json.loads(out)["aero"] == "strip"


@pytest.mark.parametrize(
    "model,kind,fragment",
    [
        ({"aero": "dlm", "dlm": {"chordwise": 0}}, "flutter", "s.toml: model.dlm.chordwise = 0"),
        ({"aero": "dlm", "dlm": {"lags": "x"}}, "flutter", "s.toml: model.dlm.lags = 'x'"),
        ({"aero": "dlm", "dlm": {"foo": 1}}, "flutter", "s.toml: model.dlm.foo = 1: unknown key"),
        ({"dlm": {"chordwise": 4}}, "flutter", "s.toml: model.dlm: doublet-lattice settings"),
        ({"aero": "dlm", "mach": 1.2}, "flutter", "s.toml: model.mach = 1.2"),
        ({"aero": "dlm", "mach": 0.3}, "simulate", "s.toml: model.mach = 0.3: only flutter"),
    ],
)
def test_scenario_bad_aero_keys(model, kind, fragment):
    flight = {"flight": {"density": 1.225, "speed": 100.0}}
    with pytest.raises(aes.InputError, match=re.escape(fragment)) as err:
        scenario_from_dict(_scenario(model, kind, **flight), "s.toml")
    assert fragment in str(err.value) and "\n" not in str(err.value)


def test_typical_section_refuses_the_doublet_lattice(tmp_path, capsys):
    src = ROOT / "scenarios" / "conner_freeplay_lco.toml"
    out = tmp_path / "out"
    code, stdout, err = _run(capsys, "lco", str(src), "--aero", "dlm", "--out", str(out))
    assert code == 2 and stdout == "" and not out.exists()
    assert "typical section" in err and "strip aerodynamics only" in err
    assert err.strip().count("\n") == 0


# --- the command line --------------------------------------------------------------------------


def test_cli_flutter_dlm_json_matches_the_api(capsys, panelaero):
    code, out, _ = _run(
        capsys, "flutter", "goland", "--aero", "dlm", "--boxes", "4,8", "--elements", "6", "--json"
    )
    assert code == 0
    d = json.loads(out)
    assert d["aero"] == "dlm" and d["mach"] == 0.0 and d["mach_source"] == "default"
    assert d["dlm"]["settings"] == DoubletLattice(**COARSE).to_dict()
    assert d["dlm"]["n_boxes"] == 32
    assert d["dlm"]["fit"]["mach"] == 0.0 and isinstance(d["dlm"]["warnings"], list)
    model = aes.AeroelasticModel(aes.examples.goland(), n_elements=6, aero=dict(COARSE))
    ref = aes.flutter_boundary(model, 1.225)
    assert d["flutter_speed"] == pytest.approx(ref.flutter_speed, rel=0.01)


def test_cli_flutter_dlm_text_and_fixed_mach(capsys, panelaero):
    code, out, _ = _run(
        capsys, "flutter", "goland", "--aero", "dlm", "--boxes", "4,8", "--elements", "6",
        "--mach", "0.4",
    )  # fmt: skip
    assert code == 0
    assert "doublet lattice" in out and "Mach 0.4 (fixed)" in out


def test_cli_fit_warning_once_on_stderr(tmp_path, capsys, panelaero):
    path = _wing_file(
        tmp_path,
        '[analysis]\nelements = 6\naero = "dlm"\n[dlm]\nchordwise = 4\nspanwise = 8\n'
        "lags = 1\nk_max = 3.0\n",
    )
    code, out, err = _run(capsys, "flutter", str(path), "--json")
    assert code == 0
    assert json.loads(out)["dlm"]["warnings"]
    assert err.count("rational-function approximation") == 1


def test_cli_strip_default_unchanged(capsys):
    code, plain, _ = _run(capsys, "flutter", "goland", "--json")
    assert code == 0
    code, strip, _ = _run(capsys, "flutter", "goland", "--json", "--aero", "strip")
    assert code == 0
    assert json.loads(plain) == json.loads(strip)
    d = json.loads(plain)
    assert d["aero"] == "strip" and d["mach"] == 0.0 and "dlm" not in d


def test_cli_matched_compressibility(capsys):
    code, out, _ = _run(
        capsys, "flutter", "goland", "--altitude", "5000", "--compressibility", "matched", "--json"
    )
    assert code == 0
    d = json.loads(out)
    assert d["compressibility"] == "prandtl-glauert" and d["mach_source"] == "matched"
    code, out2, _ = _run(
        capsys,
        "flutter", "goland", "--altitude", "5000", "--compressibility", "prandtl-glauert",
        "--json",
    )  # fmt: skip
    assert json.loads(out2)["flutter_speed"] == d["flutter_speed"]


def test_cli_sensitivity_says_finite_differences(capsys, panelaero):
    code, out, _ = _run(
        capsys, "sensitivity", "goland", "--aero", "dlm", "--boxes", "4,8", "--elements", "4"
    )
    assert code == 0 and "finite differences" in out.splitlines()[0]


def test_cli_planform_and_export_with_dlm(tmp_path, capsys, panelaero):
    png = tmp_path / "p.png"
    code, _, _ = _run(
        capsys, "modes", "goland_aileron", "--aero", "dlm", "--boxes", "4", "--planform", str(png)
    )
    assert code == 0 and png.read_bytes()[:4] == b"\x89PNG"
    npz = tmp_path / "m.npz"
    code, out, _ = _run(
        capsys, "export", "goland", "--aero", "dlm", "--boxes", "4,8", "--elements", "6",
        "--speed", "100", "--mach", "0.3", "--out", str(npz),
    )  # fmt: skip
    assert code == 0 and npz.exists() and "doublet lattice at Mach 0.3" in out


@pytest.mark.parametrize(
    "argv,fragment",
    [
        (["--aero", "dlm", "--mach", "1.2"], "--mach = 1.2: the doublet-lattice method"),
        (["--mach", "0.95"], "--mach = 0.95: the Prandtl-Glauert"),
        (["--aero", "dlm", "--boxes", "0"], "--boxes: '0'"),
        (["--aero", "dlm", "--boxes", "abc"], "--boxes: 'abc'"),
        (["--aero", "dlm", "--boxes", "1"], "--boxes NC = 1"),
        (["--boxes", "4"], "--boxes = 4: box counts of the doublet lattice"),
        (["--aero", "vlm"], "--aero: invalid choice"),
        (
            ["--altitude", "3000", "--compressibility", "matched", "--mach", "0.3"],
            "not both",
        ),
        (["--aero", "dlm", "--compressibility", "matched"], "needs the speed of sound"),
    ],
)
def test_cli_bad_aero_options(argv, fragment, tmp_path, capsys):
    plot = tmp_path / "vg.png"
    code, out, err = _run(capsys, "flutter", "goland", *argv, "--plot", str(plot))
    assert code == 2 and out == "" and not plot.exists()
    assert fragment in err and err.strip().count("\n") == 0 and "Traceback" not in err


def test_cli_scenario_override_errors_name_the_option(tmp_path, capsys):
    src = ROOT / "scenarios" / "goland_aileron_lqr.toml"
    out = tmp_path / "out"
    for argv, fragment in (
        (["--mach", "0.3"], "--mach = 0.3: only flutter scenarios"),
        (["--aero", "dlm", "--boxes", "1"], "--boxes NC = 1"),
    ):
        code, stdout, err = _run(capsys, "simulate", str(src), "--out", str(out), *argv)
        assert code == 2 and stdout == "" and not out.exists()
        assert fragment in err and err.strip().count("\n") == 0


# --- trade studies and optimization files -------------------------------------------------------


def test_trade_case_ids_keep_strip_and_change_with_dlm():
    from aeroservo.studies.trade.grid import study_settings
    from aeroservo.studies.trade.study import TradeStudy

    base = {
        "base_wing": aes.examples.goland_aileron(),
        "parameters": {"aileron_start": [0.5]},
        "closed_loop": False,
    }
    strip = TradeStudy(**base)
    assert strip.aero is None and "aero" not in study_settings(strip)
    dlm = TradeStudy(**base, aero={"chordwise": 4})
    assert dlm.aero == DoubletLattice(chordwise=4)
    assert study_settings(dlm)["aero"]["chordwise"] == 4


def test_optimization_file_dlm_keys_and_wing_text(tmp_path):
    from aeroservo.files.aero_tables import dlm_toml
    from aeroservo.files.optimize_file import load_optimization

    wing = GOLAND.read_text(encoding="utf-8").split("[analysis]")[0]
    path = tmp_path / "o.toml"
    path.write_text(
        '[optimize]\ndensity = 1.225\naero = "dlm"\nmach = 0.2\n[dlm]\nchordwise = 4\n'
        'lag_roots = [0.1, 0.5]\n[variables]\n"segments[0].GJ" = [5e5, 2e6]\n'
        '[objective]\nmaximize = "flutter_speed"\n[constraints]\n' + wing,
        encoding="utf-8",
    )
    op = load_optimization(path)
    assert op.aero == DoubletLattice(chordwise=4, lag_roots=(0.1, 0.5)) and op.mach == 0.2
    # the optimum's wing file reads back the same settings
    back = _wing_file(
        tmp_path,
        '[analysis]\naero = "dlm"\n' + "\n".join(dlm_toml(op.aero)) + "\n",
        "back.toml",
    )
    assert load_wing(back)[1].aero == op.aero
