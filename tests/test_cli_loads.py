"""Gust-loads scenarios (``kind = "gust_loads"``) and ``aeroservo loads``: the shipped example
through the command line against the Python API, result files that read back equal and re-plot,
one-line errors for bad keys with no files left, an open-loop study with a second mass case."""

import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from conftest import ROOT

from aeroservo.cli import main
from aeroservo.errors import InputError
from aeroservo.files.gust_loads_file import load_gust_loads, write_gust_loads
from aeroservo.files.scenario_file import load_scenario
from aeroservo.studies.gust.scenario import gust_study
from aeroservo.studies.runs import run_scenario
from aeroservo.studies.scenario import quick

EXAMPLE = ROOT / "scenarios" / "goland_aileron_gust_loads.toml"
STEM = "goland_aileron_gust_loads"
FIGURES = ("envelope", "correlated", "critical_gusts", "spanwise")
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def cli_run(tmp_path_factory):
    """The example with --quick through ``aeroservo loads``: (folder, stdout)."""
    out = tmp_path_factory.mktemp("loads")
    capture = tmp_path_factory.mktemp("stdout") / "out.txt"
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["loads", str(EXAMPLE), "--quick", "--out", str(out)])
    capture.write_text(buf.getvalue())
    assert code == 0, buf.getvalue()
    return out, buf.getvalue()


@pytest.fixture(scope="module")
def api_run():
    """The same scenario and settings through the Python API."""
    return run_scenario(quick(load_scenario(EXAMPLE)))


def test_quick_settings():
    sc = load_scenario(EXAMPLE)
    q = quick(sc)
    assert len(sc.gust_loads.points) == 4 and sc.gust_loads.n_gradients == 20
    assert q.gust_loads.points == sc.gust_loads.points[:2]
    assert q.gust_loads.n_gradients == 5
    study = gust_study(sc)
    assert study.design_density == 1.225 and study.design_speed_factor == 1.1
    assert study.controller.limits.magnitude == {"aileron_hinge_moment": 2000.0}
    assert study.loads == (
        "root_shear",
        "root_bending_moment",
        "root_torque",
        "tip_le_accel",
        "tip_te_accel",
        "aileron_aero_hinge_moment",
        "aileron_deflection",
        *(
            f"{q}_at_{mm}mm"
            for mm in (1219, 2438, 3658, 4877)
            for q in ("shear", "bending_moment", "torque")
        ),
    )
    assert study.load_stations == (1.2192, 2.4384, 3.6576, 4.8768)
    assert (study.v_c, study.v_d) == (100.0, 125.0)


@pytest.mark.slow
def test_loads_command_writes_the_set(cli_run):
    out, text = cli_run
    names = sorted(p.name for p in out.iterdir())
    expected = [f"{STEM}.csv", f"{STEM}.json", f"{STEM}.npz", f"{STEM}_alleviation.csv"]
    expected += [f"{STEM}_histories.csv"]
    expected += [f"{STEM}_{f}.png" for f in FIGURES]
    assert names == sorted(expected)  # no temporary file left
    for f in FIGURES:
        assert (out / f"{STEM}_{f}.png").read_bytes()[:8] == PNG
    assert "open loop, worst limit load" in text and "closed loop, worst limit load" in text
    # issue 38: the example's loop is an LQG on the tip sensors; the report says what it measures
    assert "the closed loop feeds back its sensors: tip_le_accel, tip_te_accel, tip_twist" in text
    doc = json.loads((out / f"{STEM}.json").read_text())
    assert sorted(Path(p).name for p in doc["files"].values()) == sorted(expected)
    for name in expected:
        assert "wrote " in text and str(out / name) in text


@pytest.mark.slow
def test_files_match_the_python_api(cli_run, api_run):
    out, _ = cli_run
    res = api_run.loads
    table = pd.read_csv(out / f"{STEM}.csv", keep_default_na=True)
    pd.testing.assert_frame_equal(table, res.table, check_dtype=False, check_exact=True)
    gla = pd.read_csv(out / f"{STEM}_alleviation.csv")
    pd.testing.assert_frame_equal(gla, res.alleviation, check_dtype=False, check_exact=True)
    doc = json.loads((out / f"{STEM}.json").read_text())
    assert doc["kind"] == "gust_loads" and doc["loops"] == ["open", "closed"]
    for loop in ("open", "closed"):
        worst = res.worst(loop)
        assert set(doc["worst"][loop]) == set(worst.index)
        for load, row in worst.iterrows():
            assert doc["worst"][loop][load]["limit"] == row["limit"]
            assert doc["worst"][loop][load]["point"] == row["point"]
    assert doc["raised_loads"] == res.raised_loads()
    assert len(doc["records"]) == len(res.records) == 4  # 2 points x 2 loops
    strip = ("elapsed",)  # wall times differ between the two runs
    for a, b in zip(doc["records"], res.records, strict=True):
        assert {k: v for k, v in a.items() if k not in strip} == {
            k: v for k, v in b.items() if k not in strip
        }
    back = load_gust_loads(out / f"{STEM}.json")
    assert back.arrays.keys() == res.arrays.keys()
    for k, v in res.arrays.items():
        np.testing.assert_array_equal(back.arrays[k], v)


@pytest.mark.slow
def test_round_trip_is_equal(api_run, tmp_path):
    res = api_run.loads
    files = write_gust_loads(res, tmp_path / "r.json")
    assert sorted(Path(p).name for p in files.values()) == [
        "r.csv",
        "r.json",
        "r.npz",
        "r_alleviation.csv",
        "r_histories.csv",
    ]
    # the histories CSV holds the critical gusts as the NPZ does, 9 digits (issue 38)
    hist = pd.read_csv(tmp_path / "r_histories.csv")
    one = hist[(hist["point"] == 0) & (hist["loop"] == "closed")]
    rb = res.record(0, "closed")["loads"]["root_bending_moment"]
    crit = one[
        np.isclose(one["gradient_m"], rb["max_gradient"], rtol=1e-6)
        & (one["gust_sign"] == rb["max_sign"])
    ]
    t0, _g, y0 = res.history(0, "closed", "root_bending_moment")
    np.testing.assert_allclose(crit["t_s"], t0, rtol=1e-6, atol=1e-9)
    scale = np.abs(y0["root_bending_moment"]).max()
    np.testing.assert_allclose(
        crit["root_bending_moment"], y0["root_bending_moment"], rtol=0, atol=1e-6 * scale
    )
    assert crit["root_bending_moment"].max() == pytest.approx(rb["max"], rel=1e-4)
    back = load_gust_loads(tmp_path / "r.json")
    assert back.records == res.records and back.name == res.name
    assert back.units == res.units and back.settings == json.loads(json.dumps(res.settings))
    assert back.arrays.keys() == res.arrays.keys()
    for k, v in res.arrays.items():
        assert back.arrays[k].dtype == v.dtype
        np.testing.assert_array_equal(back.arrays[k], v)
    pd.testing.assert_frame_equal(back.table, res.table)
    assert back.summary() == res.summary()
    t, gust, y = back.history(0, "closed", "root_bending_moment")
    t0, gust0, y0 = res.history(0, "closed", "root_bending_moment")
    np.testing.assert_array_equal(t, t0)
    np.testing.assert_array_equal(y["root_torque"], y0["root_torque"])


@pytest.mark.slow
def test_damaged_result_files(api_run, tmp_path):
    write_gust_loads(api_run.loads, tmp_path / "r.json")
    with pytest.raises(InputError, match="expected a .json file name"):
        write_gust_loads(api_run.loads, tmp_path / "r.npz")
    (tmp_path / "r.npz").unlink()
    with pytest.raises(InputError, match=r"r\.npz: no such file"):
        load_gust_loads(tmp_path / "r.json")
    (tmp_path / "other.json").write_text('{"format": "aeroservo-envelope-1"}')
    with pytest.raises(InputError, match="not a valid aeroservo gust-loads result"):
        load_gust_loads(tmp_path / "other.json")


@pytest.mark.slow
def test_plot_redraws_the_figures(cli_run, capsys):
    out, _ = cli_run
    src = out / f"{STEM}.json"
    for f in FIGURES:
        (out / f"{STEM}_{f}.png").unlink()
    assert main(["plot", str(src)]) == 0
    for f in FIGURES:
        assert (out / f"{STEM}_{f}.png").read_bytes()[:8] == PNG
    one = out / "torque.png"
    assert main(["plot", str(src), "--kind", "correlated", "--out", str(one)]) == 0
    assert one.read_bytes()[:8] == PNG
    one.unlink()
    capsys.readouterr()
    assert main(["plot", str(src), "--kind", "time"]) == 2
    err = capsys.readouterr().err
    assert "is gust loads; use envelope, correlated, critical-gusts" in err
    assert err.count("\n") == 1


# -- bad input: one line naming the file, the key and the value; nothing written -------------
BAD = [
    ("[gust_loads]\n", "[gust_loads]\nfoo = 1\n", "gust_loads.foo = 1: unknown key"),
    (
        'speed_name = "V_C"\n\n[[gust_loads.points]]\naltitude = 3000.0',
        'speed_name = "V_X"\n\n[[gust_loads.points]]\naltitude = 3000.0',
        "gust_loads.points[0].speed_name = 'V_X': allowed values are ['V_C', 'V_D', '']",
    ),
    (
        'speed_name = "V_C"\n\n[[gust_loads.points]]\naltitude = 3000.0',
        'speed_name = "V_C"\nmass_case = "store"\n\n[[gust_loads.points]]\naltitude = 3000.0',
        "gust_loads.points[0].mass_case = 'store': not a mass case; they are ['nominal']",
    ),
    (
        '"aileron_deflection"]',
        '"root_moment"]',
        "gust_loads.loads[6] = 'root_moment': not an output of the model; known outputs: tip_",
    ),
    ("f_g = 1.0 ", "f_g = 1.5 ", "gust_loads.f_g = 1.5: allowed range is (0, 1]"),
    ("f_g = 1.0 ", "f_g = 0.0 ", "gust_loads.f_g = 0.0: allowed range is (0, 1]"),
    (
        "f_g = 1.0 ",
        "weights = { mlw = 1.0, mzfw = 1.0, mtow = 2.0, z_mo = 1.0e4 }\nf_g = 1.0 ",
        "gust_loads.weights = {",
    ),
    (
        "f_g = 1.0 ",
        "weights = { mlw = 3.0, mzfw = 1.0, mtow = 2.0, z_mo = 1.0e4 }\n",
        "gust_loads.weights.mlw = 3.0: must not exceed mtow = 2 kg",
    ),
    ("n_gradients = 20", "n_gradients = 2", "gust_loads.n_gradients = 2: allowed range is [3,"),
    ("altitude = 0.0 ", "altitude = 20000.0 ", "gust_loads.points[0].altitude = 20000.0:"),
    ("workers = 0 ", "workers = -1 ", "gust_loads.workers = -1: allowed range is [0, 256]"),
    ("turbulence = true", "turbulence = 1", "gust_loads.turbulence = 1: expected true or false"),
    ("[simulation]\n", "[simulation]\nduration = 2.0\n", "simulation.duration = 2.0: not used"),
    ("speed_factor = 1.1 ", "#", "flight.speed: missing; give speed [m/s] or speed_factor"),
    (
        "[output]",
        '[[gust_loads.mass_cases]]\nname = "nominal"\nwing = "goland_aileron.toml"\n[output]',
        "gust_loads.mass_cases[0].name = 'nominal': already the name of the [wing]",
    ),
    (
        "[output]",
        '[[gust_loads.mass_cases]]\nname = "heavy"\nwing = "missing.toml"\n[output]',
        "gust_loads.mass_cases[0].wing = 'missing.toml': no such wing file",
    ),
    (
        "[output]",
        '[[gust_loads.mass_cases]]\nname = "clean"\nwing = "goland.toml"\n[output]',
        "gust_loads.loads[5] = 'aileron_aero_hinge_moment': not an output of the model (mass case "
        "'clean'); known outputs:",  # a wing without an aileron
    ),
    (
        "density = 1.225                # kg/m^3\nspeed_factor = 1.1",
        "# no design point",
        "flight: missing required table (the controller's design point",
    ),
    (
        'spec = "../controllers/lqg.toml"',
        'design_mass_case = "nominal"',
        "controller.design_mass_case = 'nominal': needs controller.spec",
    ),
    (
        'spec = "../controllers/lqg.toml"',
        'spec = "../controllers/lqg.toml"\ndesign_mass_case = "x"',
        "controller.design_mass_case = 'x': not a mass case; they are ['nominal']",
    ),
    ("[output]", "[disturbance]\ninitial_tip = 0.01\n[output]", "disturbance = {"),
    (
        'spec = "../controllers/lqg.toml"',
        'spec = "../controllers/lqg.toml"\nengaged_speeds = [50.0, 150.0]',
        "controller.engaged_speeds = [50.0, 150.0]: unknown key",
    ),
    # issue 38: load stations, V_C / V_D, the 1 g trim
    (
        "stations = [1.2192, 2.4384, 3.6576, 4.8768]",
        "stations = [2.4384, 1.2192]",
        "gust_loads.stations = [2.4384, 1.2192]: values must increase",
    ),
    (
        "stations = [1.2192, 2.4384, 3.6576, 4.8768]",
        "stations = [1.0, 7.0]",
        "gust_loads.stations[1] = 7.0: allowed range is [0, 6.096] [m]",
    ),
    ("stations = [1.2192, 2.4384, 3.6576, 4.8768]", "stations = []", "gust_loads.stations = []"),
    (
        "stations = [1.2192, 2.4384, 3.6576, 4.8768]",
        "stations = [1.2192, 1.2202]",
        "gust_loads.stations = [1.2192, 1.2202]: closer than 2 mm",
    ),
    (
        "stations = [1.2192, 2.4384, 3.6576, 4.8768]",
        'stations = ["root"]',
        "gust_loads.stations[0] = 'root'",
    ),
    ("v_d = 125.0 ", "v_d = 90.0 ", "gust_loads.v_d = 90.0: must exceed v_c = 100 m/s EAS"),
    ("v_c = 100.0 ", "v_c = 105.0 ", "gust_loads.points[0].speed = 100.0: the point is named V_C"),
    ("v_c = 100.0 ", "v_c = -1.0 ", "gust_loads.v_c = -1.0: allowed range is (0, 1000]"),
    (
        "aircraft_mass = 2000.0 ",
        "aircraft_mass = 0.0 ",
        "gust_loads.aircraft_mass = 0.0: allowed range is (0, 1e+07] [kg]",
    ),
    (
        "aircraft_mass = 2000.0 ",
        "aircraft_mass = 2000.0\nlift_share = 1.5",
        "gust_loads.lift_share = 1.5: allowed range is (0, 1]",
    ),
    (
        "aircraft_mass = 2000.0 ",
        'aircraft_mass = "heavy" ',
        "gust_loads.aircraft_mass = 'heavy'",
    ),
]


def _absolute(text: str) -> str:
    """A scenario's text with the shipped files it names as absolute paths."""
    for name in ("goland_aileron.toml", "goland.toml"):
        text = text.replace(f'"{name}"', f'"{ROOT / "scenarios" / name}"')
    return text.replace('"../controllers/lqg.toml"', f'"{ROOT / "controllers" / "lqg.toml"}"')


@pytest.mark.parametrize("old,new,message", BAD, ids=[m[:40] for _o, _n, m in BAD])
def test_bad_keys_one_line_exit_2(old, new, message, tmp_path, capsys):
    text = EXAMPLE.read_text()
    assert text.count(old) >= 1
    path = tmp_path / "bad.toml"
    path.write_text(_absolute(text.replace(old, new, 1)))
    out = tmp_path / "out"
    assert main(["loads", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"aeroservo: error: {path}: "), err
    assert message in err, err
    assert not out.exists()  # nothing written, not even the folder


def test_wrong_command_for_the_kind(tmp_path, capsys):
    assert main(["simulate", str(EXAMPLE), "--out", str(tmp_path)]) == 2
    assert "scenario.kind = 'gust_loads': use 'aeroservo loads'" in capsys.readouterr().err
    lqr = ROOT / "scenarios" / "goland_aileron_lqr.toml"
    assert main(["loads", str(lqr), "--out", str(tmp_path)]) == 2
    assert "scenario.kind = 'simulate': use 'aeroservo simulate'" in capsys.readouterr().err
    assert main(["loads", str(EXAMPLE), "--workers", "-1"]) == 2
    assert list(tmp_path.iterdir()) == []


# -- open loop only, two mass cases, through 'aeroservo run' -------------------------------------
OPEN_LOOP = """
[scenario]
name = "open loop, two mass cases"
kind = "gust_loads"
[wing]
file = "{wing}"
[gust_loads]
loads = ["root_bending_moment", "root_torque", "aileron_deflection"]
n_gradients = 4
turbulence = false
weights = {{ mlw = 1800.0, mzfw = 1500.0, mtow = 2000.0, z_mo = 6000.0 }}
[[gust_loads.points]]
altitude = 1000.0
speed = 90.0
[[gust_loads.points]]
altitude = 1000.0
speed = 90.0
{store}[output]
result = "ol"
"""
STORE = """[[gust_loads.points]]
altitude = 1000.0
speed = 90.0
mass_case = "store"
[[gust_loads.mass_cases]]
name = "store"
wing = "store.toml"
"""


@pytest.mark.slow
def test_open_loop_scenario_with_mass_cases(tmp_path, capsys):
    wing = (ROOT / "scenarios" / "goland_aileron.toml").read_text()
    store = wing.replace(
        "[analysis]",
        '[[wing.masses]]\nname = "store"\nstation = 4.572\nmass = 60.0\noffset = 0.3\n\n[analysis]',
    )
    (tmp_path / "store.toml").write_text(store)
    path = tmp_path / "ol.toml"
    path.write_text(OPEN_LOOP.format(wing=ROOT / "scenarios" / "goland_aileron.toml", store=STORE))
    sc = load_scenario(path)
    study = gust_study(sc)
    assert study.controller is None and study.f_g is None
    assert list(study.mass_cases) == ["nominal", "store"]
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["kind"] == "gust_loads" and summary["loops"] == ["open"]
    assert "records" not in summary and "alleviation_pct" not in summary
    names = sorted(p.name for p in out.iterdir())
    files = ["ol.json", "ol.npz", "ol.csv", "ol_histories.csv"]
    # no load stations: no spanwise figure
    assert names == sorted(files + [f"ol_{f}.png" for f in FIGURES if f != "spanwise"])
    back = load_gust_loads(out / "ol.json")
    assert back.loops == ["open"]
    recs = {r["mass_case"]: r for r in back.records}
    assert set(recs) == {"nominal", "store"}
    # F_g from the weights at 1000 m (CS-25.341(a)(6)), the same for both mass cases
    r1, r2 = 1800.0 / 2000.0, 1500.0 / 2000.0
    f_g0 = 0.5 * (1.0 - 6000.0 / (250000.0 * 0.3048) + np.sqrt(r2 * np.tan(np.pi * r1 / 4.0)))
    f_g = f_g0 + (1.0 - f_g0) * 1000.0 / 6000.0
    for r in recs.values():
        assert r["f_g"] == pytest.approx(f_g, rel=1e-12)
    # the store changes the loads
    a = recs["nominal"]["loads"]["root_torque"]["discrete"]
    b = recs["store"]["loads"]["root_torque"]["discrete"]
    assert not np.isclose(a, b, rtol=1e-3)
    assert re.search(r"store 1000 m V_C 90 m/s EAS", back.summary())
    # issue 40: an open-loop result re-plots in every kind it has (its alleviation raises, and
    # hasattr on it used to crash the command); the spanwise kind says what it needs
    for kind in ("envelope", "correlated", "critical-gusts"):
        png = tmp_path / f"re_{kind}.png"
        assert main(["plot", str(out / "ol.json"), "--kind", kind, "--out", str(png)]) == 0
        assert png.read_bytes()[:8] == PNG
    capsys.readouterr()
    png = tmp_path / "re_spanwise.png"
    assert main(["plot", str(out / "ol.json"), "--kind", "spanwise", "--out", str(png)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "loads at two or more stations" in err and not png.exists()


def test_failed_write_leaves_nothing(tmp_path, monkeypatch):
    from aeroservo.files.outputs import write_run

    path = tmp_path / "ol.toml"
    path.write_text(OPEN_LOOP.format(wing=ROOT / "scenarios" / "goland_aileron.toml", store=""))
    run = run_scenario(load_scenario(path))

    def broken(fh, **arrays):
        fh.write(b"PK partial")
        raise OSError("disk full")

    monkeypatch.setattr(np, "savez_compressed", broken)
    out = tmp_path / "out"
    out.mkdir()
    with pytest.raises(OSError, match="disk full"):
        write_run(run, out)
    assert list(out.iterdir()) == []


def test_no_loads_at_any_point_is_an_input_error(tmp_path, capsys):
    """Open loop only, above the flutter speed at every point: nothing to tabulate."""
    path = tmp_path / "above.toml"
    text = OPEN_LOOP.format(wing=ROOT / "scenarios" / "goland_aileron.toml", store="")
    path.write_text(text.replace("speed = 90.0", "speed = 150.0"))
    out = tmp_path / "out"
    assert main(["loads", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"{path}: gust_loads.points: no flight point has loads: the open loop is unstable" in err
    assert not out.exists()  # the folder this failed run made is removed
