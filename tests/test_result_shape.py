"""One result shape (issue 39, item 3): every result has ``summary()`` (text), ``table`` (a
pandas DataFrame), ``plot(kind)`` (a Figure for each of its kinds; an unknown kind is one
InputError that lists them), ``to_json()`` (standard JSON: no bare NaN) and ``save()``, which
``load_result`` reads back with the same table (exactly) and the same summary.

The results are built small: Goland's wing with its aileron on 6 elements, the shipped LQR
scenario with ``--quick`` settings (its simulation, closed-loop boundary, loop margins and
margin sweep), a gust-loads study of one flight point with a static gain, the shipped
freeplay scenario with ``--quick`` settings, a trade study's table assembled from made-up
cases (no Dask), a two-altitude envelope and a recoverable set of the shipped H-infinity
loop at two limits.
"""

from __future__ import annotations

import io
import itertools
import json

import matplotlib
import numpy as np
import pandas as pd
import pytest
from conftest import ROOT
from matplotlib.figure import Figure

import aeroservo as aes
from aeroservo.design.interface import static_gain
from aeroservo.errors import InputError
from aeroservo.files import load_scenario
from aeroservo.files.flutter_table import flutter_table
from aeroservo.linear.hinge_plant import section_plant
from aeroservo.result_shape import Result
from aeroservo.simulate.hinges.march import march_hinges
from aeroservo.stability.boundary import flutter_boundary
from aeroservo.structure.hinge_laws import Freeplay
from aeroservo.studies.envelope import flutter_envelope
from aeroservo.studies.gust.run import run_gust_loads
from aeroservo.studies.gust.study import FlightPoint, GustLoadsStudy
from aeroservo.studies.recovery import recoverable_set
from aeroservo.studies.runs import run_scenario
from aeroservo.studies.scenario import quick
from aeroservo.studies.trade.results import _assemble
from aeroservo.system.hinge_elements import NonlinearHinge
from aeroservo.system.section import CONNER, conner_section

matplotlib.use("Agg")

HM = "aileron_hinge_moment"
MEMBERS = ("summary", "table", "plot", "to_json", "save")


@pytest.fixture(scope="module")
def model():
    return aes.AeroelasticModel(aes.examples.goland_aileron(), n_elements=6)


@pytest.fixture(scope="module")
def lqr_run():
    return run_scenario(quick(load_scenario(ROOT / "scenarios" / "goland_aileron_lqr.toml")))


def _trade():
    params = {"aileron_start": (0.5, 0.6), "aileron_chord": (0.15, 0.2, 0.25)}
    rows = []
    for k, (a, c) in enumerate(itertools.product(*params.values())):
        v_ol = 130.0 + k
        ok = k != 4
        rows.append(
            {
                "case_id": f"c{k:03d}",
                "aileron_start": a,
                "aileron_chord": c,
                "status": "ok" if ok else "failed",
                "failed_stage": "" if ok else "design",
                "error": "" if ok else "InputError: made up",
                "open_loop_flutter_speed": v_ol,
                "open_loop_flutter_frequency": 10.0 + 0.1 * k,
                "design_speed": 1.1 * v_ol if ok else np.nan,
                "closed_loop_v_max": 2.0 * v_ol,
                "stable_at_design": 1.0 if ok else np.nan,
                "closed_loop_flutter_speed": v_ol * (1.2 + 0.01 * k) if ok else np.nan,
                "suppression_margin": 0.2 + 0.01 * k if ok else np.nan,
                "hinge_moment_peak": 1500.0 - 10.0 * k if ok else np.nan,
                "hinge_moment_saturation": 0.0,
                "tip_accel_peak": 50.0 + k,
                "disk_margin": 0.8,
            }
        )
    return _assemble("made_up", params, rows, {"closed_loop": True})


def _gust():
    study = GustLoadsStudy(
        mass_cases={"nominal": aes.examples.goland_aileron()},
        points=(FlightPoint(0.0, 100.0, "V_C", "nominal"),),
        loads=("root_shear", "root_bending_moment", "root_torque"),
        load_stations=(3.0,),
        controls=(HM,),
        sensors=("tip_twist",),
        controller=static_gain([[3e4]], [HM], sensors=["tip_twist"], sample_rate=1000.0),
        elements=4,
        n_gradients=3,
        sensor_filter=None,
        name="small",
    )
    return run_gust_loads(study)


def _recovery():
    sc = quick(load_scenario(ROOT / "scenarios" / "goland_aileron_hinf.toml"))
    m = sc.model()
    vf = flutter_boundary(m, sc.density).flutter_speed
    loop = sc.loop(m)
    v = sc.speed_factor * vf
    ctrl = loop.design_controller(sc.controller, v, sc.sample_rate, vf)
    return recoverable_set(loop, ctrl, v, [0.005, 0.02], [300.0, 2000.0], duration=0.5)


def _hinges():
    plant = section_plant(
        conner_section(), [NonlinearHinge("flap", Freeplay(CONNER["gap"]))], 15.0, 1.225
    )
    return march_hinges(plant, duration=0.2, dt=1e-3, x0=plant.initial_state(2 * CONNER["gap"]))


@pytest.fixture(scope="module")
def results(model, lqr_run):
    """Every result type once, by name."""
    r = flutter_boundary(model, 1.225)
    lco_sc = quick(load_scenario(ROOT / "scenarios" / "conner_freeplay_lco.toml"))
    out = {
        "FlutterResult": r,
        "SimulationResult": lqr_run.simulation,
        "HingeSimulation": _hinges(),
        "ClosedLoopBoundary": lqr_run.boundary,
        "LoopMargins": lqr_run.margins,
        "MarginSweep": lqr_run.margin_sweep,
        "GustLoadsResult": _gust(),
        "LCOResult": run_scenario(lco_sc).lco,
        "TradeResult": _trade(),
        "Envelope": flutter_envelope(model, [0.0, 3000.0], vd=120.0),
        "RecoverableSet": _recovery(),
    }
    for name, res in out.items():
        assert type(res).__name__ == name, name
    return out


NAMES = [
    "FlutterResult",
    "SavedFlutter",
    "SimulationResult",
    "HingeSimulation",
    "ClosedLoopBoundary",
    "LoopMargins",
    "MarginSweep",
    "GustLoadsResult",
    "LCOResult",
    "TradeResult",
    "Envelope",
    "RecoverableSet",
]
SUFFIX = {"GustLoadsResult": ".json", "LCOResult": ".json", "Envelope": ".json", "TradeResult": ""}


def _save(name, res, folder, model):
    """``res.save`` to a file named after its type (a flutter sweep's needs the model)."""
    path = folder / f"{name.lower()}{SUFFIX.get(name, '.npz')}"
    kw = {"model": model} if name == "FlutterResult" else {}
    written = res.save(path, **kw)
    assert written == path and path.exists()
    return path


@pytest.fixture(scope="module")
def shaped(results, model, tmp_path_factory):
    """``{name: (result, saved path)}``, a saved sweep read back as the SavedFlutter."""
    folder = tmp_path_factory.mktemp("shape")
    out = {}
    for name, res in results.items():
        out[name] = (res, _save(name, res, folder, model))
    saved = aes.load_result(out["FlutterResult"][1])
    out["SavedFlutter"] = (saved, _save("SavedFlutter", saved, folder, model))
    return out


def _no_constant(name):
    raise AssertionError(f"bare {name} in the JSON")


def _close(fig):
    import sys

    plt = sys.modules.get("matplotlib.pyplot")
    if plt is not None:
        plt.close(fig)


@pytest.mark.parametrize("name", NAMES)
def test_members_summary_table_json(shaped, name):
    res, _path = shaped[name]
    assert isinstance(res, Result)
    for m in MEMBERS:
        assert hasattr(res, m), m
    text = res.summary()
    assert isinstance(text, str) and text.strip() and not text.endswith("\n")
    table = res.table
    assert isinstance(table, pd.DataFrame) and len(table) > 0
    doc = json.loads(res.to_json(), parse_constant=_no_constant)
    assert isinstance(doc, dict) and doc


def test_tables_have_the_rows_expected(shaped):
    t = {name: shaped[name][0].table for name in NAMES}
    r = shaped["FlutterResult"][0]
    assert len(t["FlutterResult"]) == r.eigenvalues.size
    csv = pd.read_csv(io.StringIO(flutter_table(r)))  # the f06-like CSV, as text
    assert list(t["FlutterResult"].columns) == list(csv.columns[:-1])  # all but "method"
    for col in t["FlutterResult"].columns:
        a, b = t["FlutterResult"][col].to_numpy(), csv[col].to_numpy()
        if a.dtype.kind in "fc":
            np.testing.assert_allclose(a, b, rtol=1e-7, atol=1e-12, err_msg=col)
        else:
            np.testing.assert_array_equal(a, b, err_msg=col)
    sim = shaped["SimulationResult"][0]
    assert len(t["SimulationResult"]) == sim.t.size
    np.testing.assert_array_equal(t["SimulationResult"][f"applied.{HM}"], sim.applied[HM])
    assert len(t["ClosedLoopBoundary"]) == shaped["ClosedLoopBoundary"][0].speeds.size
    lm = shaped["LoopMargins"][0]
    assert len(t["LoopMargins"]) == len(lm.channels) + len(lm.sensors)
    assert t["LoopMargins"]["gain_margin_db"].iloc[0] == lm.channels[HM].gain_margin_db
    sw = shaped["MarginSweep"][0]
    assert len(t["MarginSweep"]) == sw.speeds.size * len(sw.controls)
    np.testing.assert_array_equal(
        t["MarginSweep"]["phase_margin_deg"], sw.table_for(HM)["phase_margin_deg"]
    )
    lco = shaped["LCOResult"][0]
    assert len(t["LCOResult"]) == len(lco.rows)
    assert t["LCOResult"].to_dict(orient="records")[0].keys() == lco.table_rows()[0].keys()
    assert len(t["TradeResult"]) == 6
    assert "null" in shaped["TradeResult"][0].to_json()  # the failed case's NaN metrics
    assert list(t["Envelope"]["altitude"]) == [0.0, 3000.0]
    rs = shaped["RecoverableSet"][0]
    assert len(t["RecoverableSet"]) == rs.deflections.size * rs.magnitudes.size


@pytest.mark.parametrize("name", NAMES)
def test_every_kind_is_a_figure(shaped, name):
    res, _path = shaped[name]
    assert res.figure_kinds and set(res.figure_kinds) <= set(res.FIGURES)
    for kind in [None, *res.figure_kinds]:
        fig = res.plot(kind)
        assert isinstance(fig, Figure) and fig.axes, kind
        _close(fig)
    with pytest.raises(InputError, match="kind = 'nonsense': .* draws " + ", ".join(res.FIGURES)):
        res.plot("nonsense")


@pytest.mark.parametrize("name", NAMES)
def test_save_and_load_give_the_same_table_and_summary(shaped, name):
    res, path = shaped[name]
    back = aes.load_result(path)
    kind = {"FlutterResult": "SavedFlutter", "HingeSimulation": "SimulationResult"}
    assert type(back).__name__ == kind.get(name, name)
    pd.testing.assert_frame_equal(back.table, res.table, check_exact=True)
    assert back.summary() == res.summary()
    assert back.to_json() == res.to_json() or name in (
        "FlutterResult",  # the saved sweep's record adds its p-k sweep (none here)
        "HingeSimulation",  # read back without its hinge rotations and moments
        "TradeResult",  # read back from the CSV: its types are the file's
    )


def test_deprecated_names_still_answer(shaped):
    for name in ("GustLoadsResult", "LCOResult"):
        res = shaped[name][0]
        with pytest.warns(DeprecationWarning, match="summary_text"):
            assert res.summary_text() == res.summary()


def test_save_refuses_options_of_other_results(shaped, tmp_path):
    res = shaped["Envelope"][0]
    with pytest.raises(InputError, match="model = ...: options of a FlutterResult"):
        res.save(tmp_path / "e.json", model=None)
    with pytest.raises(InputError, match="summary = ...: not stored with a Envelope"):
        aes.save_result(res, tmp_path / "e.json", summary={})
    with pytest.raises(InputError, match="give wing_text= or model="):
        shaped["FlutterResult"][0].save(tmp_path / "f.npz")
