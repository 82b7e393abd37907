"""Issue 14: closed-loop verdicts that agree with the eigenvalues of the sampled loop and with the
growth of every recorded signal; exit status 3; rate limits reported; solvers silent on stdout.

Each test here failed before the fix: the verdict looked only at the envelope of the first
``tip_*`` signal and the command exited 0 whatever the loop did."""

import json
import shutil

import numpy as np
import pytest
from conftest import ROOT, designed_loop
from ideal_loops import ideal, ideal_text

from aeroservo import cli
from aeroservo.files import load_result, load_scenario
from aeroservo.studies import quick
from aeroservo.studies.runs import run_simulation
from aeroservo.studies.verdict import EXIT_UNSTABLE, signal_growth

OPTIMISTIC = (
    "tip_le_accel = 10.0, tip_te_accel = 10.0",
    "tip_le_accel = 1.0e-4, tip_te_accel = 1.0e-4",
)
FAST_FILTERS = ("sensor_filter = 30.0 ", "sensor_filter = 100.0")
EIGHT_MODES = ("design_modes = 20", "design_modes = 8 ")


def variant(tmp_path, scenario: str, controller: str, *edits) -> object:
    """A shipped scenario and its controller file copied to ``tmp_path`` and edited
    (``(old, new)`` text replacements, each must apply to one of the two files); the scenario
    with an ideal actuator and no delay (``ideal_loops``)."""
    shutil.copytree(ROOT / "scenarios", tmp_path / "scenarios")
    shutil.copytree(ROOT / "controllers", tmp_path / "controllers")
    files = [tmp_path / "scenarios" / f"{scenario}.toml", tmp_path / "controllers" / controller]
    files[0].write_text(ideal_text(files[0].read_text()))  # the loops these tests were made for
    for old, new in edits:
        hits = [f for f in files if old in f.read_text()]
        assert hits, old
        for f in hits:
            f.write_text(f.read_text().replace(old, new))
    return files[0]


def test_signal_growth():
    t = np.linspace(0, 1, 1001)
    assert signal_growth(np.exp(-3 * t) * np.sin(60 * t)) < 0.2
    assert signal_growth(np.exp(3 * t) * np.sin(60 * t)) > 1.5
    assert np.isnan(signal_growth(np.zeros(10)))


@pytest.mark.slow
def test_unstable_design_gets_verdict_results_and_exit_3(tmp_path, capsys):
    """An LQG on 8 design modes with optimistic accelerometer noise and 100 Hz filters is unstable
    on the full plant: verdict "unstable", spectral radius > 1, one line with a hint, results
    still written, exit status 3."""
    path = variant(
        tmp_path, "goland_aileron_lqg", "lqg.toml", OPTIMISTIC, FAST_FILTERS, EIGHT_MODES
    )
    out = tmp_path / "out"
    code = cli.main(["run", str(path), "--quick", "--json", "--out", str(out)])
    cap = capsys.readouterr()
    assert code == EXIT_UNSTABLE
    summary = json.loads(cap.out)
    assert summary["verdict"] == "unstable" and summary["spectral_radius"] > 1.0
    assert summary["closed_loop"]["stable_at_reference"] is False
    assert summary["response"] == "grows"
    lines = cap.err.strip().splitlines()
    assert len(lines) == 1 and "spectral radius" in lines[0] and "design modes" in lines[0]
    assert (out / "goland_aileron_lqg.npz").is_file()
    assert json.loads((out / "goland_aileron_lqg.json").read_text())["verdict"] == "unstable"
    load_result(out / "goland_aileron_lqg.npz")


def test_twelve_design_modes_no_longer_decays(tmp_path):
    """With 12 design modes the run used to print "response decays" while its own boundary
    said ``stable_at_reference: false`` and the hinge moment grew: now the verdict agrees with
    the eigenvalues and names the growing signals (controls included)."""
    path = variant(
        tmp_path,
        "goland_aileron_lqg",
        "lqg.toml",
        OPTIMISTIC,
        FAST_FILTERS,
        ("design_modes = 20", "design_modes = 12"),
    )
    s = run_simulation(quick(load_scenario(path))).summary
    assert s["verdict"] == "unstable"
    assert s["spectral_radius"] > 1.0
    assert s["closed_loop"]["stable_at_reference"] is False
    assert s["growing_signals"] and s["response"] == "grows"


def test_expected_instability_exits_0(capsys, tmp_path):
    """The shipped open-loop scenario sets ``simulation.expect_failure``: verdict unstable,
    exit 0, no hint on stderr."""
    path = ROOT / "scenarios" / "goland_aileron_open_loop.toml"
    code = cli.main(["run", str(path), "--quick", "--json", "--out", str(tmp_path)])
    cap = capsys.readouterr()
    summary = json.loads(cap.out)
    assert code == 0 and summary["verdict"] == "unstable" and summary["expect_failure"]
    assert summary["passed"] is False
    assert "no controller acts" in summary["hint"]
    assert cap.err == ""


def test_rate_limited_first_command_is_reported():
    """The first LQR command (-219 N m after a 1 cm tip deflection) is rate-limited to the
    200 N m a sample allows: ``rate_limited_fraction`` says so (saturation stays 0)."""
    sc = ideal(quick(load_scenario(ROOT / "scenarios" / "goland_aileron_lqr.toml")))
    run = run_simulation(sc)
    sim, s = run.simulation, run.summary
    c0 = sim.commands["aileron_hinge_moment"][0]
    u0 = sim.applied["aileron_hinge_moment"][0]
    assert c0 == pytest.approx(-219.0, abs=2.0)
    assert u0 == pytest.approx(-2.0e5 / sc.sample_rate, rel=1e-12)
    assert s["saturated_fraction"]["aileron_hinge_moment"] == 0.0
    assert s["rate_limited_fraction"]["aileron_hinge_moment"] == pytest.approx(1 / sim.t.size)
    assert s["verdict"] == "stable" and s["spectral_radius"] < 1.0


@pytest.mark.slow
def test_osqp_keeps_json_parseable(tmp_path, capfd):
    """``solver = "osqp"`` printed its banner on file descriptor 1, so ``--json`` did not
    parse. Captured at the file-descriptor level here."""
    path = variant(tmp_path, "goland_aileron_mpc", "mpc.toml", ('"daqp"', '"osqp"'))
    code = cli.main(["run", str(path), "--quick", "--json", "--out", str(tmp_path / "o")])
    out = capfd.readouterr().out
    assert code == 0
    summary = json.loads(out)
    assert summary["controller_type"] == "mpc" and summary["verdict"] == "stable"


@pytest.fixture(scope="module")
def lqr_at_design():
    """The shipped LQR scenario's plant and controller at its design speed."""
    return designed_loop("goland_aileron_lqr")


def test_hint_tells_a_wrong_sign_from_a_saturation_loss(lqr_at_design):
    """Issue 38: the shipped LQR with its gain's sign reversed is unstable and the same law
    with the right sign is stable: the hint says to check the sign; a stable linear loop
    whose signals still grow is a loss to the limits, and the hint says so (not the design
    advice). Keys the hints name exist (hinf.bandwidth, not weights.bandwidth)."""
    from dataclasses import replace

    from aeroservo.studies.verdict import _REMEDIES, loop_verdict

    plant, ctrl = lqr_at_design
    wrong = replace(ctrl, K=-ctrl.K, Kd=-ctrl.Kd)
    v = loop_verdict(plant, wrong, False, {"tip_disp": {"growth": 5.0}})
    assert v["verdict"] == "unstable" and "opposite sign is stable" in v["hint"]
    ok = loop_verdict(
        plant, ctrl, False, {"tip_disp": {"growth": 5.0}}, {"aileron_hinge_moment": 0.9}
    )
    assert ok["spectral_radius"] < 1 and "actuator limits lose it" in ok["hint"]
    assert "weights.bandwidth" not in " ".join(_REMEDIES.values())


def test_state_feedback_is_flagged_not_realisable(lqr_at_design, tmp_path, capsys):
    """Issue 38: the shipped LQR feeds back plant states no sensor measures, among them the
    two Kussner gust states (a perfect gust measurement): every simulate report says so, and
    a scenario with `controller.realisable = true` refuses it in one line. Counted here from
    the LQR's own gain on the plant state (u = -gain x) and the plant's state names."""
    import re

    from aeroservo.studies.verdict import loop_verdict

    plant, ctrl = lqr_at_design
    v = loop_verdict(plant, ctrl, False, {})
    names = list(plant.state_labels)
    gain = np.zeros((ctrl.gain.shape[0], len(names)))
    gain[:, : ctrl.gain.shape[1]] = ctrl.gain
    used = [n for n, col in zip(names, gain.T, strict=True) if np.any(col != 0)]
    gust = [n for n in used if re.match(r"g\d+_", n)]
    lag = [n for n in used if re.match(r"z\d+_", n)]
    assert len(gust) == 2 and lag
    assert v["realisable"] is False
    assert v["unmeasured_feedback"]["gust states"] == 2
    assert v["unmeasured_feedback"]["aerodynamic lag states"] == len(lag)
    assert "perfect gust measurement" in v["warnings"][0]
    path = variant(
        tmp_path,
        "goland_aileron_lqr",
        "lqr.toml",
        ("[controller]\n", "[controller]\nrealisable = true\n"),
    )
    code = cli.main(["run", str(path), "--quick", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "controller.realisable = true" in err[0], err
    assert not (tmp_path / "out").exists() or not list((tmp_path / "out").iterdir())
