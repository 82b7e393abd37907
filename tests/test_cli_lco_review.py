"""Review of limit-cycle scenarios, ``aeroservo lco`` and LCO result files (issue 28): bad
values (one line naming the file, the key and the value; nothing left behind), the checks of
the march length and of a section's flap spring, keys only a closed loop uses, the controls a
controller may drive, the command line's options and interruptions, damaged result files,
the round trip with NaN fields, the CSV units, the note on a coarse step and the documented
keys and defaults against the code."""

import ast
import contextlib
import io
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

from aeroservo.cli import main
from aeroservo.errors import InputError
from aeroservo.files.hinge_tables import _KEYS
from aeroservo.files.lco_file import TABLE_UNITS, load_lco, write_lco
from aeroservo.files.lco_tables import SECTION_KEYS
from aeroservo.files.scenario_file import load_scenario
from aeroservo.studies.lco.result import TABLE_COLUMNS

SCENARIOS = ROOT / "scenarios"
CONTROLLERS = ROOT / "controllers"
STEM = "sec"

# the shipped Conner section, shortened: 2 speeds, 2 initial rotations, 1 s marches
SECTION = (
    (SCENARIOS / "conner_freeplay_lco.toml")
    .read_text()
    .replace("speeds = { start = 4.0, stop = 26.0, num = 23 }", "speeds = [14.0, 25.0]")
    .replace("amplitudes = [0.0185, 0.0740, 0.2220]", "amplitudes = [0.0740, 0.2220]")
    .replace("duration = 30.0 ", "duration = 1.0 ")
    .replace("history = 2.0 ", "history = 0.5 ")
    .replace('result = "conner_freeplay_lco"', f'result = "{STEM}"')
)
CONNER = 'builtin = "conner"            # aeroservo.system.section.conner_section(), gap closed'
PARAMS = (
    "semichord = 0.127\na = -0.5\nmass = 3.3843\nx_alpha = 0.2\ninertia = 0.01347\n"
    "k_plunge = 2818.8\nk_pitch = 37.34\nhinge = 0.5\nflap_inertia = 0.0003264\nk_flap = 3.9"
)
GAP_LINE = "gap = 0.0740                  # rad, total (4.24 deg)"
WING = (
    (SCENARIOS / "goland_aileron_freeplay_lco.toml")
    .read_text()
    .replace('"goland_aileron.toml"', f'"{SCENARIOS / "goland_aileron.toml"}"')
)
LQR = (
    (SCENARIOS / "goland_aileron_freeplay_lqr.toml")
    .read_text()
    .replace('"goland_aileron.toml"', f'"{SCENARIOS / "goland_aileron.toml"}"')
    .replace('"../controllers/lqr.toml"', f'"{CONTROLLERS / "lqr.toml"}"')
)


def _run(argv: list) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


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
    return a == b


def _edit(text: str, edits) -> str:
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new, 1)
    return text


def _one_line_error(path: Path, argv: list, message: str, out: Path) -> None:
    code, _, err = _run(argv)
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith(f"aeroservo: error: {path}: "), err
    assert message in err, err
    assert not out.exists()  # nothing written, not even the folder


# -- bad values of a section scenario -----------------------------------------------------------
BAD_SECTION = [
    # the march length: the nonlinear march takes 1 to 5 000 000 steps (was: 10 000 001 samples
    # accepted, every march then 'failed'; 0 steps accepted, every march 'failed')
    (
        [("duration = 1.0 ", "duration = 600.0 "), ("dt = 0.001 ", "dt = 0.0001 ")],
        "lco.duration = 600.0: 6000000 steps of 0.0001 s; a march takes 1 to 5000000",
    ),
    (
        [("duration = 1.0 ", "duration = 0.0004 "), ("history = 0.5 ", "history = 0.0 ")],
        "lco.duration = 0.0004: 0 steps of 0.001 s; a march takes 1 to 5000000",
    ),
    # a section's flap spring is the k of its hinge law (was: 'numerical failure: Singular
    # matrix', exit 1)
    (
        [(CONNER + "\ndamped = false", PARAMS.replace("k_flap = 3.9", "k_flap = 0.0"))],
        "section.k_flap = 0.0: the nonlinear hinge law acts on this spring",
    ),
    # already refused: strings, NaN, inf, out-of-range values, unknown keys and names
    ([(GAP_LINE, 'gap = "0.07"')], "lco.hinges[0].gap = '0.07': expected a number [rad]"),
    ([(GAP_LINE, "gap = nan")], "lco.hinges[0].gap = nan: must be a finite number [rad]"),
    ([(GAP_LINE, "gap = inf")], "lco.hinges[0].gap = inf: must be a finite number [rad]"),
    ([(GAP_LINE, "gap = 0.0")], "lco.hinges[0].gap = 0.0: allowed range is (0, 0.5] [rad]"),
    ([(GAP_LINE, "gap = 0.6")], "lco.hinges[0].gap = 0.6: allowed range is (0, 0.5] [rad]"),
    ([("offset = 0.0 ", "offset = 0.6 ")], "lco.hinges[0].offset = 0.6: allowed range"),
    (
        [("offset = 0.0 ", "inner_ratio = -0.1 ")],
        "lco.hinges[0].inner_ratio = -0.1: allowed range is [0, 100]",
    ),
    ([('law = "freeplay"', 'law = "Freeplay"')], "lco.hinges[0].law = 'Freeplay': allowed"),
    ([('target = "flap"', 'target = ""')], "lco.hinges[0].target = '': expected an actuator"),
    ([("offset = 0.0 ", "stiffness = 1.0 ")], "lco.hinges[0].stiffness = 1.0: unknown key"),
    (
        [("[output]", '[[lco.hinges]]\ntarget = "flap"\nlaw = "freeplay"\ngap = 0.01\n[output]')],
        "lco.hinges[1]: a typical section has one nonlinear hinge",
    ),
    ([("speeds = [14.0, 25.0]", "speeds = []")], "lco.speeds = []: expected a non-empty list"),
    ([("speeds = [14.0, 25.0]", "speeds = 14.0")], "lco.speeds = 14.0: expected a non-empty"),
    ([("speeds = [14.0, 25.0]", "speeds = [0.0, 14.0]")], "lco.speeds[0] = 0.0: allowed range"),
    ([("speeds = [14.0, 25.0]", 'speeds = ["14"]')], "lco.speeds[0] = '14': expected a number"),
    ([("speeds = [14.0, 25.0]", "speeds = [14.0, 14.0]")], "lco.speeds = [14.0, 14.0]: values"),
    (
        [("speeds = [14.0, 25.0]", "speeds = { start = 5.0, stop = 9.0, num = 1 }")],
        "lco.speeds.num = 1: allowed range is [2, 1000]",
    ),
    (
        [("speeds = [14.0, 25.0]", "speeds = { start = 5.0, stop = 9.0, step = 1.0 }")],
        "lco.speeds.step = 1.0: unknown key",
    ),
    ([("amplitudes = [0.0740, 0.2220]", "amplitudes = []")], "lco.amplitudes = []: expected"),
    ([("amplitudes = [0.0740, 0.2220]", "amplitudes = [0.0]")], "lco.amplitudes[0] = 0.0: all"),
    ([("amplitudes = [0.0740, 0.2220]", "amplitudes = [1.5]")], "lco.amplitudes[0] = 1.5: all"),
    ([("duration = 1.0 ", "duration = 0.0 ")], "lco.duration = 0.0: allowed range is (0, 600]"),
    ([("duration = 1.0 ", "duration = 1e9 ")], "lco.duration = 1000000000.0: allowed range"),
    ([("dt = 0.001 ", "dt = 0.0 ")], "lco.dt = 0.0: allowed range is [1e-06, 0.1] [s]"),
    ([("settle = 0.5 ", 'settle = "half" ')], "lco.settle = 'half': expected a number"),
    ([("settle = 0.5 ", "settle = -0.1 ")], "lco.settle = -0.1: allowed range is [0, 0.9]"),
    ([("workers = 0 ", "workers = 1.5 ")], "lco.workers = 1.5: expected an integer"),
    ([("workers = 0 ", "workers = 1000 ")], "lco.workers = 1000: allowed range is [0, 256]"),
    ([("[lco]", "[lco]\nhinge = 1")], "lco.hinge = 1: unknown key"),
    (
        [(CONNER + "\ndamped = false", PARAMS.replace("hinge = 0.5", "hinge = -0.6"))],
        "section.hinge = -0.6: allowed range is [-0.5, 1)",
    ),
    (
        [(CONNER + "\ndamped = false", PARAMS.replace("semichord = 0.127", "semichord = 0.0"))],
        "section.semichord = 0",
    ),
    (
        [(CONNER + "\ndamped = false", PARAMS.replace("k_flap = 3.9", "k_flap = -3.9"))],
        "section.k_flap = -3.9: allowed range",
    ),
    ([("[section]", '[wing]\nbuiltin = "goland"\n[section]')], "section = {"),
    (  # neither a wing nor a section
        [("[section]\n" + CONNER + "\ndamped = false", "")],
        "wing: missing required key (or [section], a typical section)",
    ),
    ([("[output]", "[analysis]\nn_grid = 5\n[output]")], "analysis = {'n_grid': 5}: not used"),
    ([("[output]", '[controller]\nspec = "x.toml"\n[output]')], "controller = {"),
]


@pytest.mark.parametrize("edits,message", BAD_SECTION, ids=[m[:40] for _e, m in BAD_SECTION])
def test_bad_section_values_one_line(edits, message, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(_edit(SECTION, edits))
    out = tmp_path / "out"
    _one_line_error(path, ["lco", str(path), "--out", str(out)], message, out)


# -- bad values of a wing scenario (open or closed loop) ----------------------------------------
HINGE_TARGET = 'target = "aileron"            # both of its actuators (or "actuator1", "actuator2")'
NO_ACTUATORS = (
    (SCENARIOS / "goland_aileron.toml").read_text().split("[[wing.control_surfaces.act")[0]
)
BAD_WING = [
    # keys the open loop has no use for (was: silently ignored)
    (WING, [("elements = 10", "elements = 10\ngust = 'upwash'")], "model.gust = 'upwash': only"),
    (WING, [("elements = 10", "elements = 10\ndesign_modes = 4")], "model.design_modes = 4: only"),
    (
        WING,
        [("[lco]", "[simulation]\nsample_rate = 500.0\n[lco]")],
        "simulation.sample_rate = 500.0: only with controller.spec",
    ),
    # a controller cannot drive the moment of a nonlinear hinge (was: 'inputs:
    # 'actuator1_nonlinear_moment' appears twice', naming no file nor key)
    (
        LQR,
        [('controls = ["aileron_hinge_moment"]', 'controls = ["actuator1_nonlinear_moment"]')],
        "signals.controls = ['actuator1_nonlinear_moment']: 'actuator1_nonlinear_moment' is "
        "driven by the hinge law of lco.hinges[0], not by a controller",
    ),
    # already refused: targets, duplicates, the closed loop's signals and keys
    (WING, [(HINGE_TARGET, 'target = "flap"')], "lco.hinges[0].target = 'flap': not an actuator"),
    (
        WING,
        [
            (
                "[output]",
                '[[lco.hinges]]\ntarget = "actuator1"\nlaw = "cubic"\ncoefficient = 1e5\n[output]',
            )
        ],
        "lco.hinges[1].target = 'actuator1': actuator 'actuator1' already has the law of "
        "lco.hinges[0]",
    ),
    (
        WING,
        [("density = 1.225 ", "density = 1.225\nspeed_factor = 1.1")],
        "flight.speed_factor = 1.1: only with controller.spec",
    ),
    (
        LQR,
        [('outputs = ["tip_disp"]', "outputs = []")],
        "controller.spec -> " + str(CONTROLLERS / "lqr.toml") + ": weights.outputs.tip_disp: not a",
    ),
    (
        LQR,
        [('controls = ["aileron_hinge_moment"]', 'controls = ["elevator_hinge_moment"]')],
        "signals.controls = ['elevator_hinge_moment']: 'elevator_hinge_moment' is not a control",
    ),
    (LQR, [("settle = 0.5 ", "settle = 0.5\ndt = 0.001 ")], "lco.dt = 0.001: the closed loop"),
    (LQR, [("speed_factor = 1.1 ", "#")], "flight.speed: missing; give speed [m/s] or speed_f"),
    (LQR, [("[lco]", "[simulation2]\n[lco]")], "simulation2 = {}: unknown key"),
]


@pytest.mark.parametrize("text,edits,message", BAD_WING, ids=[m[:40] for _t, _e, m in BAD_WING])
def test_bad_wing_values_one_line(text, edits, message, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(_edit(text, edits))
    out = tmp_path / "out"
    _one_line_error(path, ["lco", str(path), "--out", str(out)], message, out)


def test_surface_without_actuators(tmp_path):
    """A surface with no actuators has no nonlinear element: named in the wing file's terms."""
    wing = tmp_path / "wing.toml"
    wing.write_text(NO_ACTUATORS)
    path = tmp_path / "bad.toml"
    path.write_text(WING.replace(str(SCENARIOS / "goland_aileron.toml"), str(wing)))
    out = tmp_path / "out"
    message = "lco.hinges[0].target = 'aileron': the surface has no actuators"
    _one_line_error(path, ["lco", str(path), "--out", str(out)], message, out)


def test_controller_of_type_none_is_the_open_loop(tmp_path):
    """A controller of type 'none' makes the study open loop: lco.dt is its step (was refused:
    'the closed loop steps at 1/simulation.sample_rate') and no design speed is asked for."""
    spec = f'spec = "{CONTROLLERS / "open_loop.toml"}"'
    text = _edit(
        WING,
        [("[lco]", f"[controller]\n{spec}\n[lco]"), ("dt = 0.001 ", "dt = 0.0005 ")],
    )
    path = tmp_path / "none.toml"
    path.write_text(text)
    sc = load_scenario(path)
    assert sc.controller.type == "none" and sc.lco.dt == 0.0005 and sc.speed_factor is None
    path.write_text(text.replace("density = 1.225 ", "density = 1.225\nspeed = 140.0"))
    with pytest.raises(InputError, match=r"flight\.speed = 140\.0: only with controller\.spec of"):
        load_scenario(path)


# -- the command line -----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def scenario_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("scenario") / "sec.toml"
    path.write_text(SECTION)
    return path


@pytest.fixture(scope="module")
def result_dir(tmp_path_factory, scenario_file) -> Path:
    """``aeroservo lco`` on the shortened section (2 speeds, 2 rotations, both sweeps)."""
    out = tmp_path_factory.mktemp("lco")
    code, _, err = _run(["lco", str(scenario_file), "--out", str(out), "--no-plots"])
    assert code == 0, err
    return out


def _cli_cases(f: Path, tmp: Path):
    (tmp / "a_file").write_text("x")
    return [
        (["lco", str(tmp / "missing.toml")], f"{tmp / 'missing.toml'}: no such file"),
        (["lco", str(tmp)], f"{tmp}: is a folder, expected a TOML file"),
        (["lco", str(f), "--out", str(tmp / "a_file")], "--out = "),
        (["lco", str(f), "--out", str(tmp / "a_file" / "sub")], "Not a directory"),
        (["lco", str(f), "--workers", "2", "--scheduler", "tcp://x:1"], "not allowed with"),
        (["lco", str(f), "--workers", "-1"], "argument --workers: '-1': allowed range"),
        # 'aeroservo run' has the options of every study command (the registry of kinds):
        # one of the two, and the range checked when parsed
        (
            ["run", str(f), "--workers", "2", "--scheduler", "tcp://127.0.0.1:1", "--out", "o"],
            "argument --scheduler: not allowed with argument --workers",
        ),
        (
            ["run", str(f), "--workers", "1000", "--out", str(tmp / "o")],
            "argument --workers: '1000': allowed range is [0, 256]",
        ),
    ]


@pytest.mark.parametrize("case", range(8))
def test_command_line_errors_one_line(case, scenario_file, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv, message = _cli_cases(scenario_file, tmp_path)[case]
    code, _, err = _run(argv)
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert message in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]  # no output folder


def test_interrupted_run_leaves_nothing(scenario_file, tmp_path, monkeypatch):
    """Ctrl-C during the marches: exit 130, one line, no output folder."""
    import aeroservo.studies.lco.run as lco_run

    def interrupted(shared, task):
        raise KeyboardInterrupt

    monkeypatch.setattr(lco_run, "march_task", interrupted)
    out = tmp_path / "out"
    code, text, err = _run(["lco", str(scenario_file), "--out", str(out)])
    assert code == 130 and err.startswith("aeroservo: interrupted") and err.count("\n") == 1
    assert text == "" and not out.exists()


def test_examples_list_the_lco_scenarios():
    code, text, _ = _run(["examples"])
    assert code == 0
    for name in (
        "conner_freeplay_lco.toml",
        "goland_aileron_freeplay_lco.toml",
        "goland_aileron_freeplay_lqr.toml",
    ):
        assert re.search(rf"^  {re.escape(name)} +lco ", text, re.M), name


# -- damaged result files -------------------------------------------------------------------------
def _damaged(kind: str, doc: dict, npz: bytes) -> tuple[bytes, bytes | None]:
    """The JSON and NPZ of a damaged copy of a result (``kind`` says what is damaged)."""
    doc = {**doc, "arrays": "r_histories.npz"}
    row0 = doc["rows"][0]
    bad_rows = {
        "row_speed_text": {**row0, "speed": "fast"},
        "row_kind_number": {**row0, "kind": 5},
        "row_start_unknown": {**row0, "start": "sideways"},
        "row_amplitude_text": {**row0, "amplitude": "big"},
    }
    if kind in bad_rows:
        return json.dumps({**doc, "rows": [bad_rows[kind]] + doc["rows"][1:]}).encode(), None
    if kind == "rows_empty":  # issue 40: the summary's min() of no speed was an internal error
        return json.dumps({**doc, "rows": []}).encode(), None
    if kind == "settings_gap_text":
        return json.dumps({**doc, "settings": {**doc["settings"], "gap": "x"}}).encode(), None
    if kind == "settings_duration_text":
        bad = {**doc["settings"], "duration": "long"}
        return json.dumps({**doc, "settings": bad}).encode(), None
    text = json.dumps(doc).encode()
    if kind == "truncated":
        return text[: len(text) // 2], None
    if kind == "npz_corrupt":
        return text, npz[: len(npz) // 2]
    buf = io.BytesIO()
    t = np.linspace(0.0, 0.5, 5)
    arrays = {
        "npz_no_t": {"row0/flap_rotation": t, "row0/flap_hinge_moment": t},
        "npz_lengths_differ": {
            "row0/t": t,
            "row0/flap_rotation": t[:3],
            "row0/flap_hinge_moment": t,
        },
        "npz_text": {"row0/t": np.array(["a", "b"])},
        "npz_no_reference": {"row0/t": t},
    }[kind]
    np.savez(buf, **arrays)
    return text, buf.getvalue()


DAMAGED = {
    "truncated": "not a valid aeroservo limit-cycle result (not JSON",
    "row_speed_text": "rows[0].speed = 'fast': not what aeroservo writes",
    "row_kind_number": "rows[0].kind = 5: not what aeroservo writes",
    "row_start_unknown": "rows[0].start = 'sideways': not what aeroservo writes",
    "row_amplitude_text": "rows[0].amplitude = 'big': not what aeroservo writes",
    "rows_empty": "'rows' is empty: a limit-cycle result has at least one march",
    "settings_gap_text": "settings.gap = 'x': expected a positive gap [rad] or null",
    "settings_duration_text": "settings.duration = 'long': not what aeroservo writes",
    "npz_corrupt": "r_histories.npz: not a .npz archive",
    "npz_no_t": "r_histories.npz: row0/t: missing (the history of row 0)",
    "npz_lengths_differ": "r_histories.npz: row0/flap_rotation: 3 values, its row0/t 5",
    "npz_text": "r_histories.npz: array 'row0/t' of <U1 values: expected real numbers",
    "npz_no_reference": "r_histories.npz: row0/flap_rotation: missing",
}


@pytest.mark.parametrize("kind", list(DAMAGED))
def test_plot_of_a_damaged_result_one_line(kind, result_dir, tmp_path):
    """Every damaged file is one line naming it, exit 2, no figure (were, for the rows,
    the settings and the NPZ: figures of garbage or internal errors)."""
    doc = json.loads((result_dir / f"{STEM}.json").read_text())
    npz = (result_dir / f"{STEM}_histories.npz").read_bytes()
    text, arrays = _damaged(kind, doc, npz)
    (tmp_path / "r.json").write_bytes(text)
    if arrays is not None:
        (tmp_path / "r_histories.npz").write_bytes(arrays)
    before = sorted(p.name for p in tmp_path.iterdir())
    code, _, err = _run(["plot", str(tmp_path / "r.json")])
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith(f"aeroservo: error: {tmp_path}/r"), err
    assert DAMAGED[kind] in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_plot_of_another_kind_and_without_npz(result_dir, tmp_path):
    """A gust-loads JSON is not read as limit cycles; without its NPZ a result redraws the
    bifurcation diagram only."""
    gust = tmp_path / "gust.json"
    gust.write_text('{"format": "aeroservo-gust-loads-2"}')
    code, _, err = _run(["plot", str(gust)])
    assert code == 2 and "not a valid aeroservo gust-loads result" in err
    (tmp_path / "x.json").write_bytes((result_dir / f"{STEM}.json").read_bytes())
    code, text, err = _run(["plot", str(tmp_path / "x.json")])
    assert code == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "gust.json",
        "x.json",
        "x_bifurcation.png",
    ]


# -- round trip, NaN fields, CSV units ------------------------------------------------------------
def test_round_trip_with_nan_fields(result_dir, tmp_path):
    """NaN fields (the initial rotation of a continuation's rows) read back as NaN, as does a
    null written in their place (e.g. by a JSON tool that knows no NaN); the result rewrites
    into the same files."""
    res = load_lco(result_dir / f"{STEM}.json")
    sweeps = [r for r in res.rows if r["start"] != "point"]
    assert sweeps and any(math.isnan(r["initial"]) for r in sweeps)
    again = tmp_path / "again.json"
    write_lco(res, again)
    back = load_lco(again)
    assert _same(back.rows, res.rows) and back.summary() == res.summary()
    assert _same(back.branches.table(), res.branches.table())
    assert (tmp_path / "again.csv").read_text() == (result_dir / f"{STEM}.csv").read_text()
    doc = json.loads(again.read_text())
    for row in doc["rows"]:  # NaN -> null
        row.update({k: None for k, v in row.items() if isinstance(v, float) and math.isnan(v)})
    nulls = tmp_path / "nulls.json"
    nulls.write_text(json.dumps(doc, allow_nan=False))
    assert _same(load_lco(nulls).table_rows(), res.table_rows())


def test_csv_units_in_the_header(result_dir):
    """Every column of the table with its unit (SI, radians); the text columns without."""
    import csv

    with open(result_dir / f"{STEM}.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    head = rows[0]
    expected = [f"{k} [{TABLE_UNITS[k]}]" if k in TABLE_UNITS else k for k in TABLE_COLUMNS]
    assert head == expected
    assert set(TABLE_COLUMNS) - set(TABLE_UNITS) == {"start", "kind", "confidence", "reason"}
    assert TABLE_UNITS["amplitude"] == TABLE_UNITS["initial"] == "rad"
    res = load_lco(result_dir / f"{STEM}.json")
    assert len(rows) == 1 + len(res.rows)
    for line, r in zip(rows[1:], res.rows, strict=True):
        cells = dict(zip(TABLE_COLUMNS, line, strict=True))
        assert _same(float(cells["initial"]), r["initial"]) and cells["kind"] == r["kind"]


# -- a coarse step is noted -----------------------------------------------------------------------
def test_coarse_step_noted(tmp_path):
    """At 0.02 s the march of the 12 Hz limit cycle has 4 steps per cycle: switches are missed
    (the verdict is no longer lco), so the run says so; at 0.001 s it does not."""
    text = _edit(
        SECTION,
        [
            ("speeds = [14.0, 25.0]", "speeds = [14.0]"),
            ("amplitudes = [0.0740, 0.2220]", "amplitudes = [0.0740]"),
            ("duration = 1.0 ", "duration = 3.0 "),
            ("continuation = true", "continuation = false\ndescribing = false"),
        ],
    )
    notes = {}
    for dt in ("0.02", "0.001"):
        path = tmp_path / f"dt{dt}.toml"
        path.write_text(text.replace("dt = 0.001 ", f"dt = {dt} "))
        out = tmp_path / f"out{dt}"
        code, printed, err = _run(["lco", str(path), "--out", str(out), "--json", "--no-plots"])
        assert code == 0, err
        notes[dt] = [n for n in json.loads(printed)["notes"] if "coarse" in n]
    assert len(notes["0.02"]) == 1 and notes["0.001"] == []
    assert re.match(
        r"step 0\.02 s coarse: 4\.\d+ steps per cycle at 1[12](\.\d+)? Hz", notes["0.02"][0]
    )
    assert "lower lco.dt" in notes["0.02"][0]


# -- the documentation against the code -----------------------------------------------------------
def _doc_table(after: str) -> dict:
    """``{key: (unit, default)}`` of the first table after the line ``after`` in
    docs/scenarios.md."""
    text = (ROOT / "docs" / "scenarios.md").read_text()
    start = text.index(after)
    rows = {}
    for line in text[start:].splitlines()[1:]:
        if rows and not line.startswith("|"):
            break
        m = re.match(r"\| `([a-z_]+)`(?:, `([a-z_]+)`)? \| ([^|]*) \| ([^|]*) \|", line)
        if m:
            for key in filter(None, m.group(1, 2)):
                rows[key] = (m.group(3).strip(), m.group(4).strip())
    return rows


def test_docs_match_the_code(tmp_path):
    """Every key of [lco], [section] and the hinge tables is documented, and the documented
    defaults are the code's."""
    lco = _doc_table("**`[lco]`**")
    assert set(lco) == {
        "speeds",
        "amplitudes",
        "duration",
        "dt",
        "settle",
        "continuation",
        "history",
        "workers",
        "describing",
    }
    # the code's keys: an unknown one lists them
    path = tmp_path / "s.toml"
    path.write_text(SECTION.replace("[lco]", "[lco]\nzzz = 1"))
    with pytest.raises(
        InputError, match=r"s\.toml: lco\.zzz = 1: unknown key; allowed keys"
    ) as info:
        load_scenario(path)
    allowed = re.search(r"allowed keys are (\[.*\])", str(info.value)).group(1)
    assert set(ast.literal_eval(allowed)) == set(lco) | {"hinges"}
    # the defaults
    minimal = re.sub(
        r"\n(duration|dt|settle|continuation|history|workers) = [^\n]*", "", SECTION
    ).replace("describing = true", "")
    path.write_text(minimal)
    c = load_scenario(path).lco
    assert {k: lco[k][0] for k in ("speeds", "amplitudes", "duration", "dt", "history")} == {
        "speeds": "m/s",
        "amplitudes": "rad",
        "duration": "s",
        "dt": "s",
        "history": "s",
    }
    assert (c.duration, c.dt, c.settle) == (30.0, 0.001, 0.5)
    assert (lco["duration"][1], lco["dt"][1], lco["settle"][1]) == ("30", "0.001", "0.5")
    assert c.continuation is True and lco["continuation"][1] == "true"
    assert c.describing is True and lco["describing"][1] == "true"
    assert c.workers == 0 and lco["workers"][1] == "0"
    assert c.history == 2.0 and lco["history"][1] == "min(2, duration)"
    # [section]: every parameter and its unit as the code names them
    sec = _doc_table("**The model.**")
    assert set(sec) == set(SECTION_KEYS) | {"builtin", "damped"}
    from aeroservo.files.lco_tables import _UNITS

    for key, unit in _UNITS.items():
        assert sec[key][0] == unit or unit in sec[key][0].split(", "), key
    assert sec["flap_static_moment"][1] == "0" and sec["damped"][1] == "false"
    # the hinge keys, as docs/wing-file.md lists them
    wing_doc = (ROOT / "docs" / "wing-file.md").read_text()
    table = wing_doc[wing_doc.index("## `[[hinges]]`") :]
    keys = set(re.findall(r"^\| `([a-z_]+)` \|", table.split("\n## ")[0], re.M))
    code_keys = {"target", "law"} | {k for req, opt in _KEYS.values() for k in req + opt}
    assert keys == code_keys
