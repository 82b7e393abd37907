"""Running scenarios from the command line: every shipped scenario, result files, re-plotting,
atomic writes and exit codes."""

import json

import numpy as np
import pytest
from conftest import ROOT

from aeroservo import cli
from aeroservo.files import load_result, load_scenario, write_run
from aeroservo.files.scenario_file import shipped_scenarios
from aeroservo.studies import quick
from aeroservo.studies.runs import run_simulation

SCENARIOS = [p for p, _kind, _name in shipped_scenarios()]
RUN_HERE = [p for p, kind, _name in shipped_scenarios() if kind != "gust_loads"]
"""The shipped gust-loads scenario's quick run is ``tests/test_cli_loads.py``'s (the same
``--quick`` run through ``aeroservo loads``, its files and figures checked there; ``aeroservo
run`` on a gust-loads scenario is tested there too): not run a second time here."""


def test_scenarios_are_shipped():
    kinds = {k for _p, k, _n in shipped_scenarios()}
    assert kinds == {"flutter", "simulate", "trade", "gust_loads", "lco"}
    names = {p.stem for p in SCENARIOS}
    for required in (
        "goland_flutter",
        "goland_aileron_lqr",
        "goland_aileron_lqg",
        "goland_aileron_mpc",
        "goland_aileron_gust",
        "trade_aileron",
    ):
        assert required in names


@pytest.mark.slow
@pytest.mark.parametrize("path", RUN_HERE, ids=[p.stem for p in RUN_HERE])
def test_every_shipped_scenario_runs(path, tmp_path, capsys):
    """Acceptance: each shipped scenario runs (fast settings) and writes its results."""
    code = cli.main(["run", str(path), "--quick", "--json", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert code == 0, out
    summary = json.loads(out)
    assert summary["kind"] in ("flutter", "simulate", "trade", "gust_loads", "lco")
    written = sorted(p.name for p in tmp_path.rglob("*") if p.is_file())
    assert written and not [n for n in written if n.startswith(".")]  # no temporary files
    if summary["kind"] == "simulate":
        res = load_result(tmp_path / f"{path.stem}.npz")
        assert res.t[-1] == pytest.approx(0.5)
        spec = load_scenario(path).controller
        # the verdict agrees with the eigenvalues of the sampled loop (issue 14)
        assert (summary["verdict"] == "stable") == (summary["spectral_radius"] < 1.0)
        if "closed_loop" in summary:
            assert summary["closed_loop"]["stable_at_reference"] == (summary["verdict"] == "stable")
        if spec.type != "none":
            assert summary["response"] == "decays" and summary["verdict"] == "stable"
            assert summary["open_loop_unstable"]
            # issue 24: every shipped loop passes over its engaged range, judged as a black box
            assert summary["passed"] and summary["engaged"]["stable_over_range"]
            assert summary["engaged"]["margins_over_range"]["meets"]
            assert "black box" in summary["margins"]["break_point"]
        else:
            assert summary["verdict"] == "unstable" and summary["expect_failure"]


@pytest.mark.slow
def test_simulation_summary_and_result_roundtrip(tmp_path):
    sc = quick(load_scenario(ROOT / "scenarios" / "goland_aileron_lqr.toml"))
    run = run_simulation(sc)
    write_run(run, tmp_path)
    res, summary = run.simulation, run.summary
    assert summary["speed"] == pytest.approx(1.1 * summary["open_loop_flutter_speed"])
    cl = summary["closed_loop"]
    assert cl["closed_loop_flutter_speed"] > summary["speed"]
    back = load_result(tmp_path / "goland_aileron_lqr.npz")
    np.testing.assert_array_equal(back.outputs["tip_disp"], res.outputs["tip_disp"])
    np.testing.assert_array_equal(
        back.applied["aileron_hinge_moment"], res.applied["aileron_hinge_moment"]
    )
    assert back.limits == res.limits and back.units == res.units and back.speed == res.speed
    assert (
        back.run_summary["closed_loop"]["closed_loop_flutter_speed"]
        == cl["closed_loop_flutter_speed"]
    )
    assert summary["signals"]["tip_disp"]["peak"] == pytest.approx(0.01)
    on_disk = json.loads((tmp_path / "goland_aileron_lqr.json").read_text())
    assert on_disk["speed"] == summary["speed"]


def test_plot_command_replots_a_result(tmp_path, capsys):
    sc = quick(load_scenario(ROOT / "scenarios" / "goland_aileron_open_loop.toml"))
    write_run(run_simulation(sc), tmp_path)
    npz = tmp_path / "goland_aileron_open_loop.npz"
    assert cli.main(["plot", str(npz)]) == 0
    png = npz.with_suffix(".png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert cli.main(["plot", str(tmp_path / "missing.npz")]) == 2
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    assert cli.main(["plot", str(tmp_path / "junk.npz")]) == 2
    err = capsys.readouterr().err
    assert "missing.npz: no such file" in err and "not an aeroservo result file" in err


def test_failed_write_leaves_no_partial_result(tmp_path, monkeypatch):
    sc = quick(load_scenario(ROOT / "scenarios" / "goland_aileron_open_loop.toml"))

    def broken(fh, **arrays):
        fh.write(b"PK partial")
        raise OSError("disk full")

    run = run_simulation(sc)
    monkeypatch.setattr(np, "savez_compressed", broken)
    with pytest.raises(OSError, match="disk full"):
        write_run(run, tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_exit_codes(tmp_path, capsys, monkeypatch):
    lqr = str(ROOT / "scenarios" / "goland_aileron_lqr.toml")
    # usage: wrong kind for the command
    assert cli.main(["trade", lqr, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "scenario.kind = 'simulate'" in err and len(err.strip().splitlines()) == 1
    # input error: a bad file
    bad = tmp_path / "bad.toml"
    bad.write_text('[scenario]\nname = "x"\nkind = "simulate"\n[wing]\nbuiltin = "concorde"\n')
    assert cli.main(["simulate", str(bad), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "wing.builtin = 'concorde'" in err and len(err.strip().splitlines()) == 1
    # numerical failure: exit 1 with a message
    import aeroservo.stability.boundary as stab

    def fails(*a, **k):
        raise RuntimeError("eigenvalue tracking failed near V = 1 m/s")

    monkeypatch.setattr(stab, "flutter_boundary", fails)
    assert cli.main(["simulate", lqr, "--quick", "--out", str(tmp_path)]) == 1
    assert "numerical failure: eigenvalue tracking failed" in capsys.readouterr().err


def test_examples_lists_wings_and_scenarios(capsys):
    assert cli.main(["examples"]) == 0
    out = capsys.readouterr().out
    assert "goland_aileron" in out and "goland_aileron_mpc.toml" in out and "trade" in out


def test_flutter_command_accepts_a_scenario(capsys):
    """`aeroservo flutter SCENARIO` uses the scenario's wing, density and model options."""
    path = ROOT / "scenarios" / "goland_aileron_lqr.toml"
    assert cli.main(["flutter", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    sc = load_scenario(path)
    assert out["density"] == sc.density and out["n_elements"] == sc.elements
    assert out["wing"] == sc.wing.name


def test_trade_study_keeps_the_scenario_loop_options():
    """filter_order and the gust model of a trade scenario reach the study and its case ids."""
    from dataclasses import replace

    from aeroservo.studies.runs import study_from_scenario
    from aeroservo.studies.trade import case_id

    sc = load_scenario(ROOT / "scenarios" / "trade_aileron.toml")
    base = study_from_scenario(sc)
    other = study_from_scenario(replace(sc, filter_order=4, gust_model="upwash"))
    assert (other.filter_order, other.gust_model) == (4, "upwash")
    params = {k: v[0] for k, v in base.parameters.items()}
    assert case_id(base, params) != case_id(other, params)
