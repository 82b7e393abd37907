"""Trade studies on a real Dask LocalCluster (2 worker processes on loopback).

One small closed-loop study (2 actuator stations x 2 Bryson hinge moments, one station outside
the aileron so that two variants fail validation) runs once on a module-scoped cluster; the
tests check its files, its failures, its agreement with an in-process evaluation, the re-run
(skip) and resume behaviour, case ids, plots and input validation.
"""

from __future__ import annotations

import dataclasses
import json
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from matplotlib.figure import Figure

import aeroservo as aes
from aeroservo.errors import InputError
from aeroservo.files import load_controller
from aeroservo.studies import trade
from aeroservo.studies.trade.cluster import _worker_probe

ROOT = Path(__file__).parent.parent
GOOD, BAD = 0.8, 0.3  # actuator stations [fraction of span]: on / off the aileron (0.6-1.0)


@pytest.fixture(scope="module")
def study() -> trade.TradeStudy:
    return trade.TradeStudy(
        base_wing=aes.examples.goland_aileron(),
        controller=load_controller(ROOT / "controllers" / "lqr.toml"),
        parameters={"actuator_station": (BAD, GOOD), "bryson_hinge_moment": (300.0, 600.0)},
        gust_duration=0.2,
        n_grid=11,
        name="small",
    )


@pytest.fixture(scope="module")
def cluster():
    with trade.local_cluster(2, timeout=60.0) as c:
        yield c


@pytest.fixture(scope="module")
def run(study, cluster, tmp_path_factory):
    out = tmp_path_factory.mktemp("trade")
    result = trade.run_trade(study, out, scheduler=cluster.scheduler_address, progress=False)
    return out, result


@pytest.mark.slow
def test_workers_are_single_threaded(cluster):
    from distributed import Client

    with Client(cluster.scheduler_address, timeout="30s") as client:
        info = client.run(_worker_probe)
    assert len(info) == 2
    for w in info.values():
        assert w["OMP_NUM_THREADS"] == w["OPENBLAS_NUM_THREADS"] == w["MKL_NUM_THREADS"] == "1"


@pytest.mark.slow
def test_files_written_and_round_trip(run, study):
    out, r = run
    assert r.n_cases == 4 and r.n_skipped == 0
    assert r.csv_path == out / "small.csv" and r.csv_path.is_file()
    assert r.netcdf_path == out / "small.nc" and r.netcdf_path.is_file()
    cases = trade.trade_cases(study)
    assert sorted(p.stem for p in (out / "cases").glob("*.json")) == sorted(
        c["case_id"] for c in cases
    )
    assert not list(out.rglob(".*"))  # no temporary files left behind
    with xr.open_dataset(r.netcdf_path, engine="scipy") as ds:
        assert ds.sizes == {"actuator_station": 2, "bryson_hinge_moment": 2}
        np.testing.assert_array_equal(ds["actuator_station"], [BAD, GOOD])
        assert ds["closed_loop_flutter_speed"].attrs["units"] == "m/s"
        v = ds["closed_loop_flutter_speed"].values.ravel()
        np.testing.assert_array_equal(v, r.table["closed_loop_flutter_speed"].to_numpy())
        assert list(ds["status"].values.ravel()) == list(r.table["status"])
        assert list(ds["case_id"].values.ravel()) == [c["case_id"] for c in cases]
    csv = pd.read_csv(r.csv_path)
    assert list(csv["case_id"]) == list(r.table["case_id"])
    np.testing.assert_array_equal(csv["suppression_margin"], r.table["suppression_margin"])


@pytest.mark.slow
def test_bad_variant_recorded_others_succeed(run):
    out, r = run
    t = r.table
    assert r.n_failed == 2
    bad = t[t["actuator_station"] == BAD]
    assert (bad["status"] == "failed").all() and (bad["failed_stage"] == "wing").all()
    for msg in bad["error"]:
        assert "actuators[0].station = 1.8288" in msg and "allowed range" in msg
    good = t[t["actuator_station"] == GOOD]
    assert (good["status"] == "ok").all()
    assert (good["closed_loop_flutter_speed"] > good["open_loop_flutter_speed"]).all()
    assert (good["suppression_margin"] > 0).all() and (good["stable_at_design"] == 1).all()
    assert (good["hinge_moment_peak"] > 0).all() and (good["tip_accel_rms"] > 0).all()
    # the limits of lqr.toml apply
    assert (good["hinge_moment_peak"] <= 2000.0 + 1e-9).all()
    rec = json.loads((out / "cases" / f"{bad['case_id'].iloc[0]}.json").read_text())
    assert rec["status"] == "failed" and "station" in rec["error"]


@pytest.mark.slow
def test_cluster_result_equals_in_process(run, study):
    _, r = run
    row = r.table[(r.table["actuator_station"] == GOOD) & (r.table["bryson_hinge_moment"] == 600)]
    direct = trade.evaluate_case(study, {"actuator_station": GOOD, "bryson_hinge_moment": 600})
    assert direct["status"] == "ok"
    assert direct["case_id"] == row["case_id"].iloc[0]
    assert direct["closed_loop_flutter_speed"] == pytest.approx(
        row["closed_loop_flutter_speed"].iloc[0], rel=1e-9
    )
    assert direct["open_loop_flutter_speed"] == pytest.approx(
        row["open_loop_flutter_speed"].iloc[0], rel=1e-9
    )


@pytest.mark.slow
def test_rerun_skips_and_resume_runs_only_missing(run, study, cluster):
    out, first = run
    t0 = time.perf_counter()
    again = trade.run_trade(study, out, progress=False)  # no cluster needed: nothing to do
    assert time.perf_counter() - t0 < 5.0
    assert again.n_skipped == 4 and again.n_failed == 2
    pd.testing.assert_frame_equal(again.table, first.table)
    # an interrupted run: only the missing case is evaluated again
    lost = first.table["case_id"].iloc[-1]
    (out / "cases" / f"{lost}.json").unlink()
    resumed = trade.run_trade(study, out, scheduler=cluster.scheduler_address, progress=False)
    assert resumed.n_skipped == 3
    assert (out / "cases" / f"{lost}.json").is_file()
    np.testing.assert_allclose(
        resumed.table["closed_loop_flutter_speed"],
        first.table["closed_loop_flutter_speed"],
        rtol=1e-9,
    )


@pytest.mark.slow
def test_load_and_plots(run, tmp_path):
    out, r = run
    loaded = trade.load_trade(out)
    assert loaded.parameters == r.parameters
    np.testing.assert_array_equal(loaded.table["hinge_moment_peak"], r.table["hinge_moment_peak"])
    assert list(loaded.table["error"]) == list(r.table["error"])
    for fig in (
        loaded.heatmap("closed_loop_flutter_speed"),
        loaded.heatmap("tip_accel_peak", x="bryson_hinge_moment", y="actuator_station"),
        loaded.pareto(),
    ):
        assert isinstance(fig, Figure)
        fig.savefig(tmp_path / "f.png")
    from aeroservo.cli import main  # the command line redraws the folder (issue 13)

    for kind in ("pareto", "heatmap"):
        assert main(["plot", str(out), "--kind", kind, "--out", str(tmp_path / f"{kind}.png")]) == 0
        assert (tmp_path / f"{kind}.png").stat().st_size > 5_000
    assert main(["plot", str(out), "--kind", "vg", "--out", str(tmp_path / "x.png")]) == 2
    with pytest.raises(InputError, match="metric = 'nope'"):
        loaded.heatmap("nope")
    with pytest.raises(InputError, match="x = 'speed_factor'"):
        loaded.heatmap(x="speed_factor")


@pytest.mark.slow
def test_default_local_cluster_open_loop(tmp_path):
    st = trade.TradeStudy(
        base_wing=aes.examples.goland_aileron(),
        parameters={"aileron_chord": (0.2, 0.25), "hinge_stiffness": (500.0,)},
        closed_loop=False,
        name="ol",
    )
    r = trade.run_trade(st, tmp_path, workers=2, progress=False)
    assert r.n_failed == 0 and r.n_cases == 2
    assert r.table["open_loop_flutter_speed"].iloc[0] == pytest.approx(137.3708, rel=1e-5)
    assert r.table["closed_loop_flutter_speed"].isna().all()


def test_case_ids(study):
    ids = [c["case_id"] for c in trade.trade_cases(study)]
    assert len(set(ids)) == 4 and all(len(i) == 12 for i in ids)
    assert ids == [c["case_id"] for c in trade.trade_cases(study)]  # stable
    same = dataclasses.replace(
        study, name="renamed", controller=dataclasses.replace(study.controller, source="x.toml")
    )
    assert [c["case_id"] for c in trade.trade_cases(same)] == ids
    for change in ({"gust_length": 30.0}, {"n_grid": 12}, {"speed_factor": 1.2}):
        other = dataclasses.replace(study, **change)
        assert not set(c["case_id"] for c in trade.trade_cases(other)) & set(ids), change


def test_variant_wing():
    st = trade.TradeStudy(
        base_wing=aes.examples.goland_aileron(),
        parameters={"aileron_chord": (0.3,)},
        closed_loop=False,
    )
    base = st.surface
    w = trade.variant_wing(
        st, {"aileron_start": 0.5, "aileron_chord": 0.3, "actuator_station": 0.75}
    )
    cs = w.control_surfaces[0]
    assert cs.start == pytest.approx(0.5 * w.span) and cs.end == w.span
    assert cs.hinge == pytest.approx(0.4)
    assert cs.static_moment == pytest.approx(base.static_moment * 1.5**2)
    assert cs.inertia == pytest.approx(base.inertia * 1.5**3)
    assert len(cs.actuators) == 1 and cs.actuators[0].stiffness == pytest.approx(16e3)
    assert cs.actuators[0].station == pytest.approx(0.75 * w.span)
    with pytest.raises(InputError, match="hinge"):
        trade.variant_wing(st, {"aileron_chord": 0.9})  # hinge ahead of the elastic axis
    rec = trade.evaluate_case(st, {"no_such": 1.0})
    assert rec["status"] == "failed" and rec["failed_stage"] == "input"
    assert "no_such" in rec["error"]


def test_pareto_front():
    m = [0.1, 0.3, 0.2, 0.3, np.nan]
    h = [100.0, 300.0, 300.0, 200.0, 50.0]
    assert list(trade.pareto_front(m, h)) == [True, False, False, True, False]


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"parameters": {"flap_size": (1.0,)}}, "parameters.flap_size: unknown"),
        ({"parameters": {"aileron_start": ()}}, r"parameters.aileron_start = \[\]"),
        ({"parameters": {"aileron_start": (0.5, 0.5)}}, "repeated values"),
        ({"parameters": {"hinge_stiffness": (float("nan"),)}}, "finite"),
        ({"parameters": {"aileron_start": (1.2,)}}, r"aileron_start\[0\] = 1.2: allowed range"),
        ({"parameters": {"speed_factor": (1.1, 2.5)}}, r"speed_factor\[1\] = 2.5"),
        ({"parameters": {}}, "at least one swept parameter"),
        ({"density": -1.0}, "density = -1: allowed range"),
        ({"n_grid": 2}, "n_grid = 2: allowed range is"),
        ({"gust_duration": 0.0}, "gust_duration = 0"),
        ({"name": "a/b"}, "name = 'a/b'"),
        ({"wagner": "nope"}, "wagner = 'nope'"),
        ({"outputs": ("tip_disp",)}, "tip_accel"),
        ({"controller": None}, "controller = None"),
        ({"base_wing": aes.examples.goland()}, "exactly one control surface"),
    ],
)
def test_invalid_study(study, change, match):
    kw = {f.name: getattr(study, f.name) for f in dataclasses.fields(study)}
    kw.update(change)
    with pytest.raises(InputError, match=match):
        trade.TradeStudy(**kw)


def test_controller_without_linear_law_rejected(study, tmp_path):
    """Issue 24: a Python law has no closed-loop boundary, so a trade study refuses it; an MPC
    is accepted (judged by its law without active constraints, its gust flown as an MPC)."""
    from aeroservo.files.controller_file import controller_from_dict

    (tmp_path / "law.py").write_text("def law(t, y):\n    return [0.0]\n")
    spec = controller_from_dict(
        {"type": "python", "file": "law.py", "function": "law"}, str(tmp_path / "c.toml")
    )
    with pytest.raises(InputError, match="controller.type = 'python'"):
        dataclasses.replace(study, controller=spec)
    mpc = load_controller(ROOT / "controllers" / "mpc.toml")
    assert dataclasses.replace(study, controller=mpc).controller.type == "mpc"


def test_bad_scheduler_address(study, tmp_path):
    with pytest.raises(InputError, match="scheduler = 'localhost'"):
        trade.run_trade(study, tmp_path, scheduler="localhost")
