"""Trade-study and optimisation variables for concentrated masses (issue 27).

The store-flutter carpet (``scenarios/trade_store_carpet.toml``: open-loop flutter speed of
``goland_store`` over store mass x chordwise CG position) on a tiny grid against direct
:func:`aeroservo.flutter_boundary` calls on the same wings, the scenario run end to end with
``--quick`` (a Dask LocalCluster of one worker), the validation of mass parameters, and a mass
as an optimisation variable.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pandas as pd
import pytest

import aeroservo as aes
from aeroservo.errors import InputError
from aeroservo.files import load_scenario
from aeroservo.structure.examples import goland_store
from aeroservo.studies import trade
from aeroservo.studies.runs import study_from_scenario
from aeroservo.studies.trade.cases import evaluate_case, variant_wing

ROOT = Path(__file__).parent.parent
CARPET = ROOT / "scenarios" / "trade_store_carpet.toml"


def carpet_study(**parameters) -> trade.TradeStudy:
    return trade.TradeStudy(
        base_wing=goland_store(),
        closed_loop=False,
        parameters=parameters or {"masses[0].mass": (30.0, 90.0), "masses[0].offset": (-0.2, 0.3)},
        name="carpet",
    )


def test_carpet_cases_equal_direct_flutter_boundaries():
    """Each case's open-loop flutter speed and frequency is the boundary of the wing with that
    store (``goland_store(mass, offset)``), to the last bit (same engine, same model); the
    classical trend holds: the store ahead of the elastic axis flutters later."""
    study = carpet_study()
    speeds = {}
    for case in trade.trade_cases(study):
        m, y = case["masses[0].mass"], case["masses[0].offset"]
        rec = evaluate_case(study, case)
        assert rec["status"] == "ok", rec["error"]
        ref = aes.flutter_boundary(aes.AeroelasticModel(goland_store(m, y)), 1.225)
        assert rec["open_loop_flutter_speed"] == ref.flutter_speed
        assert rec["open_loop_flutter_frequency"] == ref.flutter_frequency
        speeds[m, y] = ref.flutter_speed
    for m in (30.0, 90.0):
        assert speeds[m, -0.2] > speeds[m, 0.3]
    assert speeds[90.0, -0.2] - speeds[90.0, 0.3] > speeds[30.0, -0.2] - speeds[30.0, 0.3]


def test_variant_wing_sets_the_mass_and_keeps_the_rest():
    study = carpet_study()
    w = variant_wing(study, {"masses[0].mass": 90.0, "masses[0].offset": -0.2})
    assert w.masses[0] == replace(goland_store().masses[0], mass=90.0, offset=-0.2)
    assert w.segments == goland_store().segments and not w.control_surfaces


@pytest.mark.parametrize(
    "parameters,fragment",
    [
        ({"masses[1].mass": (10.0,)}, "has 1 concentrated masses"),
        ({"masses[0].mass": (0.0,)}, "parameters.masses[0].mass[0]"),
        ({"masses[0].station": (7.0,)}, "outside the wing"),
        ({"masses[0].offset": (9.0,)}, "parameters.masses[0].offset[0] = 9"),
        ({"masses[0].inertia": (1.0, 1.0)}, "repeated values"),
        ({"mass[0].mass": (1.0,)}, "unknown parameter"),
    ],
)
def test_bad_mass_parameters(parameters, fragment):
    with pytest.raises(InputError, match=fragment.replace("[", r"\[").replace("]", r"\]")):
        carpet_study(**parameters)


def test_a_closed_loop_or_aileron_study_still_needs_one_surface():
    with pytest.raises(InputError, match="exactly one control surface"):
        trade.TradeStudy(base_wing=goland_store(), parameters={"masses[0].mass": (1.0,)})
    with pytest.raises(InputError, match="exactly one control surface"):
        trade.TradeStudy(
            base_wing=goland_store(), closed_loop=False, parameters={"aileron_chord": (0.2,)}
        )


@pytest.mark.slow
def test_scenario_loads_and_runs_quick(tmp_path, capsys):
    """The shipped carpet scenario: an open-loop study of the store's mass and offset; with
    ``--quick`` (2 x 2 cases, one worker) it writes the table and the heatmap."""
    from aeroservo.cli import main

    sc = load_scenario(CARPET)
    study = study_from_scenario(sc)
    assert not study.closed_loop and study.controller is None
    assert list(study.parameters) == ["masses[0].mass", "masses[0].offset"]
    assert study.n_cases >= 20
    assert main(["trade", str(CARPET), "--quick", "--workers", "1", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "highest open-loop flutter speed" in out and "masses[0].mass = " in out
    folder = tmp_path / "trade_store_carpet"
    table = pd.read_csv(folder / "trade_store_carpet.csv")
    assert len(table) == 4 and (table["status"] == "ok").all()
    first = table.iloc[0]
    m, y = first["masses[0].mass"], first["masses[0].offset"]
    ref = aes.flutter_boundary(aes.AeroelasticModel(goland_store(m, y)), 1.225).flutter_speed
    assert first["open_loop_flutter_speed"] == pytest.approx(ref, rel=1e-12)
    png = folder / "heatmap_open_loop_flutter_speed.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_scenario_bad_mass_parameter(tmp_path):
    text = CARPET.read_text().replace('"masses[0].offset"', '"masses[2].offset"')
    text = text.replace(
        'file = "goland_store.toml"', f'file = "{ROOT / "scenarios"}/goland_store.toml"'
    )
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=r"parameters.masses\[2\].offset: the base wing has 1"):
        load_scenario(path)


def test_open_loop_trade_needs_no_controller_but_a_closed_loop_one_does(tmp_path):
    text = CARPET.read_text().replace("closed_loop = false", "closed_loop = true")
    text = text.replace(
        'file = "goland_store.toml"', f'file = "{ROOT / "scenarios"}/goland_store.toml"'
    )
    path = tmp_path / "closed.toml"
    path.write_text(text)
    with pytest.raises(InputError, match="controller"):
        load_scenario(path)


def test_mass_as_an_optimisation_variable():
    """Maximize the flutter speed over the store's chordwise position within [-0.2, 0.3] m:
    the optimum is the forward bound (the classical trend), reached with analytic gradients."""
    from aeroservo.studies.optimize import optimize_wing

    r = optimize_wing(
        goland_store(),
        1.225,
        {"masses[0].offset": (-0.2, 0.3)},
        "flutter_speed",
        {},
        max_iterations=10,
    )
    assert r.variables["masses[0].offset"] == pytest.approx(-0.2, abs=1e-6)
    ref = aes.flutter_boundary(aes.AeroelasticModel(goland_store(60.0, -0.2)), 1.225)
    assert r.history[-1]["flutter_speed"] == pytest.approx(ref.flutter_speed, rel=1e-6)
