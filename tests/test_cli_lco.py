"""Limit-cycle scenarios (``kind = "lco"``) and ``aeroservo lco``: a shortened Conner section
through the command line, result files that read back equal and re-plot, one-line errors for
bad keys with nothing left behind, hinges from a wing file, a closed-loop smoke run, and Dask
workers that give the serial answer."""

import contextlib
import io
import json
import math
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

from aeroservo.cli import main
from aeroservo.errors import InputError
from aeroservo.files.lco_file import load_lco, write_lco
from aeroservo.files.results import load_result
from aeroservo.files.scenario_file import load_scenario
from aeroservo.files.wing_file import load_hinges, load_wing, wing_from_dict, wing_toml
from aeroservo.stability.describing_function import DescribingBranches
from aeroservo.structure.examples import goland_aileron
from aeroservo.structure.hinge_laws import Cubic, Freeplay
from aeroservo.studies.lco.result import TABLE_COLUMNS
from aeroservo.studies.lco.scenario import lco_setup
from aeroservo.studies.runs import run_scenario
from aeroservo.studies.scenario import quick
from aeroservo.system.hinge_elements import NonlinearHinge

SHIPPED = ROOT / "scenarios" / "conner_freeplay_lco.toml"
STEM = "sec"
PNG = b"\x89PNG\r\n\x1a\n"
FILES = [
    f"{STEM}.json",
    f"{STEM}.csv",
    f"{STEM}_branches.csv",
    f"{STEM}_histories.npz",
    f"{STEM}_summary.txt",
    f"{STEM}_bifurcation.png",
    f"{STEM}_histories.png",
]
GAP = 0.0740

# the shipped Conner scenario, shortened: 3 speeds (decay, limit cycle, divergence), 2 initial
# rotations, 4 s marches
SECTION = (
    SHIPPED.read_text()
    .replace("speeds = { start = 4.0, stop = 26.0, num = 23 }", "speeds = [5.0, 14.0, 25.0]")
    .replace("amplitudes = [0.0185, 0.0740, 0.2220]", "amplitudes = [0.0740, 0.2220]")
    .replace("duration = 30.0 ", "duration = 4.0 ")
    .replace("history = 2.0 ", "history = 1.0 ")
    .replace('result = "conner_freeplay_lco"', f'result = "{STEM}"')
)


def _run(argv: list) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def section_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("scenario") / "sec.toml"
    path.write_text(SECTION)
    return path


@pytest.fixture(scope="module")
def cli_run(tmp_path_factory, section_file):
    """``aeroservo lco`` on the shortened section: (folder, stdout)."""
    out = tmp_path_factory.mktemp("lco")
    code, text, err = _run(["lco", str(section_file), "--out", str(out)])
    assert code == 0, err
    return out, text


def _no_constant(name: str):
    raise AssertionError(f"the JSON holds {name}, which is not JSON")


def _same(a, b) -> bool:
    """Equal, NaN equal to NaN, arrays element by element (exactly)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    if isinstance(a, float) and math.isnan(a) and b is None:  # the JSON writes NaN as null
        return True
    return a == b


def test_shipped_scenarios_load():
    sc = load_scenario(SHIPPED)
    assert sc.kind == "lco" and sc.wing is None and sc.section.k_flap == pytest.approx(3.9)
    assert sc.lco.speeds == tuple(float(v) for v in range(4, 27))
    assert sc.lco.hinges == (NonlinearHinge("flap", Freeplay(GAP)),)
    setup, sweep = lco_setup(quick(sc))
    assert sweep.speeds == (4.0, 15.0, 26.0) and sweep.amplitudes == (0.0185, 0.222)
    assert sweep.duration == 2.0 and setup.elements.names == ("flap",)
    ol = load_scenario(ROOT / "scenarios" / "goland_aileron_freeplay_lco.toml")
    assert ol.controller is None and len(ol.lco.speeds) == 8
    lqr = load_scenario(ROOT / "scenarios" / "goland_aileron_freeplay_lqr.toml")
    assert lqr.controller.type == "lqr" and lqr.speed_factor == 1.1
    for s in (ol, lqr):  # both aileron actuators, named as in the built-in wing
        assert s.lco.hinges == (NonlinearHinge("aileron", Freeplay(0.01745)),)
        names = [a.name for cs in s.wing.control_surfaces for a in cs.actuators]
        assert names == [a.name for a in goland_aileron().control_surfaces[0].actuators]


def test_lco_command_writes_the_set(cli_run):
    out, text = cli_run
    assert sorted(p.name for p in out.iterdir()) == sorted(FILES)  # no temporary file left
    for name in FILES:
        if name.endswith(".png"):
            assert (out / name).read_bytes()[:8] == PNG
        assert "wrote " in text and str(out / name) in text
    assert "sustained oscillations at 14 m/s" in text and "\n  periodic at 14 m/s:" in text
    assert "divergent motion from 25 m/s" in text
    assert "describing function: stable limit cycles" in text
    assert re.search(r"linear flutter speed, open loop with every spring closed: 23\.7\d m/s", text)
    doc = json.loads((out / f"{STEM}.json").read_text())
    assert doc["kind"] == "lco" and doc["lco_onset"] == 14.0 and doc["diverged_from"] == 25.0
    assert list(doc["lco_classes"]) == ["periodic"] and doc["lco_classes"]["periodic"][
        "speeds"
    ] == [14.0]
    assert sorted(Path(p).name for p in doc["files"].values()) == sorted(FILES)
    assert len(doc["rows"]) == 3 * 2 + 2 * 3 and "history" not in doc["rows"][0]
    assert (out / f"{STEM}_summary.txt").read_text() == doc["summary_text"] + "\n"
    head = (out / f"{STEM}.csv").read_text().splitlines()[0]
    assert head.startswith(
        "start,speed [m/s],initial [rad],kind,confidence,frequency [Hz],modulation [Hz],"
    )
    branches = (out / f"{STEM}_branches.csv").read_text().splitlines()
    assert branches[0] == (
        "branch,element,amplitude [rad],amplitude_per_gap [-],speed [m/s],frequency [Hz],"
        "stable,others_stable,ratio_flap [-]"
    )
    assert len(branches) == 1 + len(doc["branches"]["table"]) > 10


def test_files_read_back_equal(cli_run):
    """The JSON, CSV and NPZ of the command against what they read back as."""
    out, _ = cli_run
    res = load_result(out / f"{STEM}.json")
    # standard JSON (issue 40): no bare NaN or Infinity, a number that is not finite is null
    doc = json.loads((out / f"{STEM}.json").read_text(), parse_constant=_no_constant)
    assert _same([{k: v for k, v in r.items() if k != "history"} for r in res.rows], doc["rows"])
    assert _same(res.branches.table(), doc["branches"]["table"])
    assert res.summary() == doc["summary_text"]
    csv = (out / f"{STEM}.csv").read_text().splitlines()[1:]
    assert len(csv) == len(res.rows)
    first = dict(zip(TABLE_COLUMNS, csv[0].split(","), strict=False))
    assert float(first["speed"]) == res.rows[0]["speed"] and first["kind"] == res.rows[0]["kind"]
    with np.load(out / f"{STEM}_histories.npz") as z:
        for i, r in enumerate(res.rows):
            assert r["history"].keys() == {
                k.split("/", 1)[1] for k in z.files if k.startswith(f"row{i}/")
            }
            for k, v in r["history"].items():
                np.testing.assert_array_equal(z[f"row{i}/{k}"], v)
    assert "flap_rotation" in res.rows[0]["history"] and "t" in res.rows[0]["history"]


def test_round_trip_is_equal(tmp_path):
    sc = load_scenario(SHIPPED)
    res = run_scenario(quick(sc)).lco
    files = write_lco(res, tmp_path / "r.json")
    assert sorted(Path(p).name for p in files.values()) == sorted(
        ["r.json", "r.csv", "r_histories.npz", "r_summary.txt"]  # quick: no describing function
    )
    back = load_lco(tmp_path / "r.json")
    assert _same(back.rows, res.rows) and back.branches is None
    assert back.settings == json.loads(json.dumps(res.settings))
    assert back.table_rows() == res.table_rows() or _same(back.table_rows(), res.table_rows())
    assert back.summary() == res.summary()
    # without the NPZ: the verdicts without histories
    (tmp_path / "r_histories.npz").unlink()
    bare = load_lco(tmp_path / "r.json")
    assert all(r["history"] == {} for r in bare.rows) and _same(bare.table_rows(), res.table_rows())
    with pytest.raises(InputError, match="expected a .json file name"):
        write_lco(res, tmp_path / "r.npz")
    (tmp_path / "other.json").write_text('{"format": "aeroservo-gust-loads-2"}')
    with pytest.raises(InputError, match="not a valid aeroservo limit-cycle result"):
        load_lco(tmp_path / "other.json")


def test_describing_branches_from_table(cli_run):
    out, _ = cli_run
    b = load_result(out / f"{STEM}.json").branches
    again = DescribingBranches.from_table(b.table(), gap=b.gap, element=b.element, names=b.names)
    for name in ("amplitude", "speed", "frequency", "stable", "branch", "ratios", "others_stable"):
        np.testing.assert_array_equal(getattr(again, name), getattr(b, name))
        assert getattr(again, name).dtype == getattr(b, name).dtype
    assert (again.gap, again.element, again.names) == (GAP, "flap", ("flap",))
    empty = DescribingBranches.from_table([], gap=None, element="flap")
    assert empty.speed.shape == (0,) and empty.ratios.shape == (0, 1)
    with pytest.raises(InputError, match="describing-function table: not valid"):
        DescribingBranches.from_table([{"branch": 0}], gap=GAP, element="flap")


def test_plot_redraws_the_figures(cli_run, capsys, tmp_path):
    out, _ = cli_run
    src = out / f"{STEM}.json"
    for name in ("bifurcation", "histories"):
        (out / f"{STEM}_{name}.png").unlink()
    assert main(["plot", str(src)]) == 0
    for name in ("bifurcation", "histories"):
        assert (out / f"{STEM}_{name}.png").read_bytes()[:8] == PNG
    one = tmp_path / "h.png"
    assert main(["plot", str(src), "--kind", "histories", "--out", str(one)]) == 0
    assert one.read_bytes()[:8] == PNG
    capsys.readouterr()
    assert main(["plot", str(src), "--kind", "time"]) == 2
    err = capsys.readouterr().err
    assert "is limit cycles; use bifurcation, histories" in err and err.count("\n") == 1
    # the JSON alone: the bifurcation diagram only
    alone = tmp_path / "alone"
    alone.mkdir()
    (alone / "x.json").write_bytes(src.read_bytes())
    assert main(["plot", str(alone / "x.json")]) == 0
    assert sorted(p.name for p in alone.iterdir()) == ["x.json", "x_bifurcation.png"]
    capsys.readouterr()
    assert main(["plot", str(alone / "x.json"), "--kind", "histories"]) == 2
    err = capsys.readouterr().err
    assert "has no time histories" in err and err.count("\n") == 1


# -- bad input: one line naming the file, the key and the value; nothing written -------------
HINGE = (
    'law = "freeplay"\ngap = 0.0740                  # rad, total (4.24 deg)\n'
    "offset = 0.0                  # rad, centre of the gap"
)
NO_HINGES = ('[[lco.hinges]]\ntarget = "flap"\n' + HINGE, "")
BAD = [
    ('law = "freeplay"', 'law = "backlash"', "lco.hinges[0].law = 'backlash': allowed values"),
    ("gap = 0.0740 ", "gap = -0.01 ", "lco.hinges[0].gap = -0.01: allowed range is (0, 0.5] [rad]"),
    (
        'target = "flap"',
        'target = "aileron"',
        "lco.hinges[0].target = 'aileron': a typical section",
    ),
    (HINGE, 'law = "cubic"', "lco.hinges[0].coefficient: missing required key"),
    (
        HINGE,
        'law = "cubic"\ncoefficient = 10.0\ngap = 0.0740',
        "lco.hinges[0].gap = 0.074: not used by law 'cubic'",
    ),
    (
        HINGE,
        'law = "cubic"\ncoefficient = 0.0',
        "lco.hinges[0].coefficient = 0.0: 0 is the linear",
    ),
    (HINGE, 'law = "bilinear"\ngap = 0.0740', "lco.hinges[0].inner_ratio: missing required key"),
    (HINGE, HINGE + "\ncoefficient = 1.0", "lco.hinges[0].coefficient = 1.0: not used by law 'fre"),
    (*NO_HINGES, "lco.hinges: missing; give [[lco.hinges]] tables"),
    (*NO_HINGES, "lco.hinges = 3: expected [[lco.hinges]] tables"),
    (
        "speeds = [5.0, 14.0, 25.0]",
        "speeds = [5.0, 25.0, 14.0]",
        "lco.speeds = [5.0, 25.0, 14.0]: values must increase",
    ),
    (
        "speeds = [5.0, 14.0, 25.0]",
        "speeds = { start = 20.0, stop = 10.0, num = 5 }",
        "lco.speeds.stop = 10.0: must be above start = 20 m/s",
    ),
    (
        "amplitudes = [0.0740,",
        "amplitudes = [-0.0740,",
        "lco.amplitudes[0] = -0.074: allowed range",
    ),
    ("amplitudes = [0.0740,", "amplitudes = [0.2220,", "lco.amplitudes = [0.222, 0.222]: values"),
    ("duration = 4.0 ", "duration = 4.0 \nfoo = 1", "lco.foo = 1: unknown key"),
    ("dt = 0.001 ", "dt = 0.5 ", "lco.dt = 0.5: allowed range is [1e-06, 0.1] [s]"),
    ("settle = 0.5 ", "settle = 1.0 ", "lco.settle = 1.0: allowed range is [0, 0.9]"),
    ("history = 1.0 ", "history = 10.0 ", "lco.history = 10.0: allowed range is [0, 4] [s]"),
    ("workers = 0 ", "workers = -1 ", "lco.workers = -1: allowed range is [0, 256]"),
    ('builtin = "conner"', 'builtin = "theodorsen"', "section.builtin = 'theodorsen': allowed"),
    ("damped = false", "damped = true\n[damping]\ng = 0.02", "section.damped = True: give section"),
    ("density = 1.225 ", "density = 1.225 \nspeed = 20.0", "flight.speed = 20.0: only with"),
    ("[section]", '[wing]\nbuiltin = "goland"\n[section]', "section = {"),
    ("[model]\n", "[model]\nelements = 4\n", "model.elements = 4: not used with a [section]"),
    ("[output]", '[controller]\nspec = "x.toml"\n[output]', "controller = {"),
    ("[output]", "[simulation]\nseed = 1\n[output]", "simulation = {'seed': 1}: a typical sect"),
    (
        'builtin = "conner"            # aeroservo.system.section.conner_section(), gap closed\n'
        "damped = false",
        "semichord = 0.127\na = -0.5\nmass = 3.3843\nx_alpha = 0.2\ninertia = 0.01347\n"
        "k_plunge = 2818.8\nk_pitch = 37.34\nhinge = 0.5\nflap_inertia = 0.0003264\n"
        "k_flap = -3.9",
        "section.k_flap = -3.9: allowed range",
    ),
    ("[section]", "[section]\nfoo = 1", "section.foo = 1: unknown key"),
    ('kind = "lco"', 'kind = "lco"\n[signals]\noutputs = []', "signals = {"),
]


@pytest.mark.parametrize("old,new,message", BAD, ids=[m[:40] for _o, _n, m in BAD])
def test_bad_keys_one_line_exit_2(old, new, message, tmp_path, capsys):
    assert SECTION.count(old) >= 1, old
    text = SECTION.replace(old, new, 1)
    if "hinges = 3" in message:
        text = text.replace("[lco]\n", "[lco]\nhinges = 3\n")
    path = tmp_path / "bad.toml"
    path.write_text(text)
    out = tmp_path / "out"
    assert main(["lco", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"aeroservo: error: {path}: "), err
    assert message in err, err
    assert not out.exists()  # nothing written, not even the folder


def test_wrong_command_for_the_kind(section_file, tmp_path, capsys):
    assert main(["loads", str(section_file), "--out", str(tmp_path)]) == 2
    assert "scenario.kind = 'lco': use 'aeroservo lco'" in capsys.readouterr().err
    gust = ROOT / "scenarios" / "goland_aileron_gust_loads.toml"
    assert main(["lco", str(gust), "--out", str(tmp_path)]) == 2
    assert "scenario.kind = 'gust_loads': use 'aeroservo loads'" in capsys.readouterr().err
    assert main(["lco", str(section_file), "--workers", "2", "--scheduler", "tcp://x:1"]) == 2
    assert "not allowed with argument" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_failed_write_leaves_nothing(section_file, tmp_path, monkeypatch, capsys):
    def broken(fh, **arrays):
        fh.write(b"PK partial")
        raise OSError("disk full")

    monkeypatch.setattr(np, "savez_compressed", broken)
    out = tmp_path / "out"
    text = section_file.read_text().replace("[5.0, 14.0, 25.0]", "[14.0]")
    short = tmp_path / "short.toml"
    short.write_text(
        text.replace("duration = 4.0 ", "duration = 0.5 ").replace(
            "history = 1.0 ", "history = 0.5 "
        )
    )
    assert main(["lco", str(short), "--out", str(out), "--quick"]) == 2
    assert "disk full" in capsys.readouterr().err
    assert not out.exists()


# -- hinges from a wing file; a closed loop ------------------------------------------------------
WING_HINGES = """
[[hinges]]
target = "actuator2"          # the outboard actuator only
law = "freeplay"
gap = 0.01745                 # rad (1 deg)
offset = 0.002                # rad
"""

ON_WING = """
[scenario]
name = "wing-file hinges"
kind = "lco"
[wing]
file = "{wing}"
[flight]
density = 1.225
[lco]
speeds = [130.0]
amplitudes = [0.01745]
duration = 0.3
history = 0.1
continuation = false
describing = false
{hinges}[output]
result = "w"
"""


def test_hinges_from_a_wing_file(tmp_path, capsys):
    wing = tmp_path / "wing.toml"
    wing.write_text((ROOT / "scenarios" / "goland_aileron.toml").read_text() + WING_HINGES)
    assert load_hinges(wing) == (NonlinearHinge("actuator2", Freeplay(0.01745, 0.002)),)
    plain = load_wing(ROOT / "scenarios" / "goland_aileron.toml")[0]
    assert load_wing(wing)[0] == plain  # the hinges are not part of the linear model
    assert load_hinges(ROOT / "scenarios" / "goland_aileron.toml") == ()
    path = tmp_path / "w.toml"
    path.write_text(ON_WING.format(wing=wing, hinges=""))
    sc = load_scenario(path)
    assert sc.lco.hinges == load_hinges(wing)
    assert sc.lco.hinges_source == f"{wing} [[hinges]]"
    out = tmp_path / "out"
    assert main(["lco", str(path), "--out", str(out), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["settings"]["elements"] == ["actuator2"] and doc["reference"] == "actuator2"
    assert doc["settings"]["hinges_source"] == f"{wing} [[hinges]]"
    assert doc["marches"] == 1 and "describing_onset" not in doc
    assert "describing function: not computed (lco.describing = false)" in doc["notes"]
    # the scenario's hinges win over the wing file's, and say so
    cubic = '[[lco.hinges]]\ntarget = "aileron"\nlaw = "cubic"\ncoefficient = 1.0e5\n'
    path.write_text(ON_WING.format(wing=wing, hinges=cubic))
    sc = load_scenario(path)
    assert sc.lco.hinges == (NonlinearHinge("aileron", Cubic(1.0e5)),)
    setup, _ = lco_setup(sc)
    assert setup.elements.names == ("actuator1", "actuator2")
    # a bad table in the wing file names the wing file and its key, whoever reads it
    wing.write_text(wing.read_text().replace('target = "actuator2"', 'target = "flap"'))
    path.write_text(ON_WING.format(wing=wing, hinges=""))
    for argv in (["lco", str(path), "--out", str(out)], ["flutter", str(wing)]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1, err
        assert f"{wing}: hinges[0].target = 'flap': not an actuator or control surface" in err


def test_wing_file_actuators_are_signal_names(tmp_path):
    """Actuators of a wing file are named actuator1, actuator2, ... along the wing (or by their
    ``name``): their names make signals such as ``actuator1_rotation``."""
    wing, _ = load_wing(ROOT / "scenarios" / "goland_aileron.toml")
    assert [a.name for a in wing.control_surfaces[0].actuators] == ["actuator1", "actuator2"]
    text = (ROOT / "scenarios" / "goland_aileron.toml").read_text()
    named = text.replace("station = 5.4864", 'name = "outboard"\nstation = 5.4864')
    path = tmp_path / "named.toml"
    path.write_text(named)
    acts = load_wing(path)[0].control_surfaces[0].actuators
    assert [a.name for a in acts] == ["actuator1", "outboard"]
    back = wing_from_dict(tomllib.loads(wing_toml(load_wing(path)[0]))["wing"])
    assert back == load_wing(path)[0]  # wing_toml keeps a name that is not the default
    path.write_text(text.replace("station = 5.4864", 'name = "actuator1"\nstation = 5.4864'))
    with pytest.raises(InputError, match=r"actuators\[1\]\.name = 'actuator1': another actuator"):
        load_wing(path)
    path.write_text(text.replace("station = 5.4864", 'name = "out board"\nstation = 5.4864'))
    with pytest.raises(InputError, match=r"actuators\[1\]\.name = 'out board': expected a name"):
        load_wing(path)


LQR = (
    (ROOT / "scenarios" / "goland_aileron_freeplay_lqr.toml")
    .read_text()
    .replace('"goland_aileron.toml"', f'"{ROOT / "scenarios" / "goland_aileron.toml"}"')
    .replace('"../controllers/lqr.toml"', f'"{ROOT / "controllers" / "lqr.toml"}"')
)


@pytest.mark.slow
def test_closed_loop_smoke(tmp_path, capsys):
    """The shipped LQR scenario, shortened, through 'aeroservo run'."""
    path = tmp_path / "lqr.toml"
    path.write_text(
        LQR.replace(
            "speeds = [120.0, 130.0, 137.0, 140.0, 145.0, 150.0, 155.0, 160.0]", "speeds = [150.0]"
        )
        .replace("amplitudes = [0.0043625, 0.01745, 0.05235]", "amplitudes = [0.01745]")
        .replace("duration = 10.0 ", "duration = 1.0 ")
        .replace("history = 2.0 ", "history = 0.5 ")
        .replace("continuation = true", "continuation = false")
    )
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "[lco]" in text and "designed at 151.1 m/s, held fixed at every speed" in text
    res = load_result(out / "goland_aileron_freeplay_lqr.json")
    s = res.settings
    assert s["closed_loop"] and s["controller"].startswith("LQR (Bryson")
    assert s["design_speed"] == pytest.approx(1.1 * s["open_loop_flutter_speed"], rel=1e-12)
    assert s["dt"] == pytest.approx(1e-3) and res.branches is not None  # of the sampled loop
    assert len(res.rows) == 1 and res.rows[0]["kind"] != "failed"
    assert "actuator1_rotation" in res.rows[0]["history"]
    names = sorted(p.name for p in out.iterdir())
    assert "goland_aileron_freeplay_lqr_branches.csv" in names and len(names) == 7
    bad = path.read_text().replace("speed_factor = 1.1 ", "# no design speed")
    path.write_text(bad)
    assert main(["lco", str(path), "--out", str(tmp_path / "o2")]) == 2
    err = capsys.readouterr().err
    assert "flight.speed: missing; give speed [m/s] or speed_factor" in err
    path.write_text(LQR.replace('target = "aileron"', 'target = "elevator"'))
    assert main(["lco", str(path), "--out", str(tmp_path / "o2")]) == 2
    err = capsys.readouterr().err
    assert "lco.hinges[0].target = 'elevator': not an actuator or control surface" in err
    assert "known: actuator1, actuator2, aileron" in err
    assert not (tmp_path / "o2").exists()


@pytest.mark.slow
def test_dask_workers_equal_serial(cli_run, section_file):
    """Two local Dask workers give the serial march verdicts, exactly."""
    out, _ = cli_run
    serial = load_result(out / f"{STEM}.json")
    run = run_scenario(load_scenario(section_file), workers=2)
    assert run.lco.settings["workers"] == 2
    assert _same(run.lco.rows, serial.rows)
    assert _same(run.lco.branches.table(), serial.branches.table())
