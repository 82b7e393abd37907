"""Trade-study figures (issue 25, item 7): which case is best and why, a heat map per metric
that matters through the best case (small multiples for a few further values), markers for
saturated and unstable cases, a labelled Pareto front, ``aeroservo plot DIR --metric NAME
--slice P=V`` with one-line errors, and the file names a run really writes.

Most tests draw synthetic results (no Dask, milliseconds); one shipped scenario runs once with
``--quick`` (8 cases on a 2-worker LocalCluster) for the files and the command line.
"""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest
from conftest import ROOT
from matplotlib.patches import Rectangle

from aeroservo.cli import main
from aeroservo.errors import InputError
from aeroservo.studies.trade import load_trade
from aeroservo.studies.trade.plots import HEATMAP_METRICS
from aeroservo.studies.trade.ranking import BEST_CRITERION
from aeroservo.studies.trade.results import _assemble

NAN = float("nan")


def _rows(parameters: dict, closed_loop: bool = True) -> list[dict]:
    """One successful case per grid point with made-up but distinct metrics: margin rising
    with the flat index, peak hinge moment falling, nothing saturated."""
    rows = []
    for k, combo in enumerate(itertools.product(*parameters.values())):
        r = {
            "case_id": f"c{k:03d}",
            **dict(zip(parameters, combo, strict=True)),
            "status": "ok",
            "failed_stage": "",
            "error": "",
            "open_loop_flutter_speed": 130.0 + k,
            "open_loop_flutter_frequency": 10.0,
        }
        if closed_loop:
            v_ol = r["open_loop_flutter_speed"]
            r.update(
                design_speed=1.1 * v_ol,
                closed_loop_v_max=2.0 * v_ol,
                stable_at_design=1.0,
                closed_loop_flutter_speed=v_ol * (1.2 + 0.01 * k),
                suppression_margin=0.2 + 0.01 * k,
                hinge_moment_peak=1500.0 - 10.0 * k,
                hinge_moment_saturation=0.0,
                tip_accel_peak=50.0 + k,
                disk_margin=0.8,
            )
        rows.append(r)
    return rows


def _result(parameters: dict, rows: list[dict], closed_loop: bool = True):
    return _assemble("synthetic", parameters, rows, {"closed_loop": closed_loop})


THREE = {
    "aileron_start": (0.5, 0.6),
    "aileron_chord": (0.15, 0.2, 0.25),
    "speed_factor": (1.1, 1.2),
}


def _index(parameters: dict, **values) -> int:
    idx = tuple(parameters[n].index(values[n]) for n in parameters)
    return int(np.ravel_multi_index(idx, tuple(len(v) for v in parameters.values())))


# -- the best case ----------------------------------------------------------------------------


def test_best_case_counts_the_bound_and_skips_unstable_and_failed():
    rows = _rows(THREE)
    last = len(rows) - 1  # the highest finite margin
    rows[last].update(stable_at_design=0.0)  # ... but unstable at the design speed
    rows[last - 1].update(status="failed", error="x")  # the next one failed
    for k in (1, 2):  # stable to the end of the search: margin >= 2 - 1, a tie ...
        rows[k].update(closed_loop_flutter_speed=None, suppression_margin=None)
    rows[2]["hinge_moment_peak"] = 100.0  # ... won by the lower peak hinge moment
    r = _result(THREE, rows)
    best = r.best_case()
    assert best["case_id"] == "c002" and r.best_criterion == BEST_CRITERION[True]
    assert "suppression margin" in r.best_criterion


def test_best_case_of_an_open_loop_study_and_of_no_success():
    rows = _rows(THREE, closed_loop=False)
    rows[3]["open_loop_flutter_speed"] = 500.0
    r = _result(THREE, rows, closed_loop=False)
    assert r.best_case()["case_id"] == "c003" and "open-loop flutter" in r.best_criterion
    for row in rows:
        row.update(status="failed")
    assert _result(THREE, rows, closed_loop=False).best_case() is None


# -- heat maps ----------------------------------------------------------------------------------


def _panels(fig) -> list:
    return [ax for ax in fig.axes if ax.images and ax.get_visible()]


def _outlined(ax) -> bool:
    return any(isinstance(p, Rectangle) and not p.get_fill() for p in ax.patches)


def test_heatmap_small_multiples_through_the_best_case():
    """Three parameters, the third with two values: one panel per value on one colour
    scale, the best case outlined in its panel, named with the criterion in the title."""
    rows = _rows(THREE)
    best = _index(THREE, aileron_start=0.6, aileron_chord=0.25, speed_factor=1.1)
    rows[best]["suppression_margin"] = 5.0
    fig = _result(THREE, rows).heatmap("suppression_margin")
    panels = _panels(fig)
    assert [ax.get_title() for ax in panels] == ["speed_factor = 1.1", "speed_factor = 1.2"]
    assert [_outlined(ax) for ax in panels] == [True, False]
    clims = {ax.images[0].get_clim() for ax in panels}
    assert len(clims) == 1  # one colour scale
    title = fig.get_suptitle()
    assert BEST_CRITERION[True].split(";")[0] in title.replace("\n", " ")
    assert "aileron_start = 0.6, aileron_chord = 0.25, speed_factor = 1.1" in title.replace(
        "\n", " "
    )
    assert panels[0].get_xlabel() == "aileron_start [-]"


def test_heatmap_holds_many_values_at_the_best_case():
    params = {**THREE, "speed_factor": tuple(1.05 + 0.05 * i for i in range(13))}
    rows = _rows(params)
    best = _index(
        params, aileron_start=0.5, aileron_chord=0.2, speed_factor=params["speed_factor"][7]
    )
    rows[best]["suppression_margin"] = 5.0
    fig = _result(params, rows).heatmap("tip_accel_peak")
    [ax] = _panels(fig)
    assert _outlined(ax)
    title = fig.get_suptitle().replace("\n", " ")
    assert "held at the best case: speed_factor = 1.4" in title


def test_heatmap_marks_saturated_unstable_bound_and_failed_cells():
    two = {"aileron_start": (0.5, 0.6, 0.7), "aileron_chord": (0.15, 0.2)}
    rows = _rows(two)
    rows[0].update(closed_loop_flutter_speed=None, suppression_margin=None)  # stable to v_max
    rows[1].update(hinge_moment_saturation=0.03)
    rows[2].update(hinge_moment_saturation=0.01)
    rows[3].update(stable_at_design=0.0)
    rows[4].update(status="failed", hinge_moment_saturation=0.5, suppression_margin=None)
    r = _result(two, rows)
    fig = r.heatmap("suppression_margin")
    [ax] = _panels(fig)
    markers = [ln.get_marker() for ln in ax.lines]
    assert markers.count("v") == 2 and markers.count("X") == 1  # the failed case not marked
    texts = [t.get_text() for t in ax.texts]
    assert "\u22651" in texts and "failed" in texts  # margin >= v_max / V_ol - 1 = 1
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert legend[:3] == [
        "best case",
        "actuator saturated in the gust",
        "closed loop unstable at the design speed",
    ]
    assert _outlined(ax)  # the bound case is the best (margin >= 1)


def test_heatmap_options_and_errors():
    r = _result(THREE, _rows(THREE))
    fig = r.heatmap("hinge_moment_peak", speed_factor=1.2)
    [ax] = _panels(fig)
    assert "slice: speed_factor = 1.2" in fig.get_suptitle()
    fig = r.heatmap("disk_margin", x="aileron_chord", y="speed_factor")
    assert [ax.get_title() for ax in _panels(fig)] == ["aileron_start = 0.5", "aileron_start = 0.6"]
    assert _panels(fig)[0].get_xlabel() == "aileron_chord [-]"
    with pytest.raises(InputError, match="metric = 'nope'"):
        r.heatmap("nope")


# -- Pareto -------------------------------------------------------------------------------------


def test_pareto_labels_the_front_and_marks_saturation():
    two = {"aileron_chord": (0.15, 0.2, 0.25), "bryson_hinge_moment": (250.0, 500.0)}
    rows = _rows(two)
    # margin and peak both rise with k: every case is on the front except those we spoil
    for k, row in enumerate(rows):
        row.update(suppression_margin=0.2 + 0.05 * k, hinge_moment_peak=500.0 + 100.0 * k)
    rows[2].update(suppression_margin=0.1)  # dominated by case 1
    rows[4].update(hinge_moment_saturation=0.02, hinge_moment_peak=2000.0)
    rows[5].update(hinge_moment_saturation=0.04, hinge_moment_peak=2000.0)  # dominates 4
    fig = _result(two, rows).pareto()
    ax = fig.axes[0]
    labels = sorted(t.get_text() for t in ax.texts)
    expected = [
        f"{rows[k]['aileron_chord']:.4g} / {rows[k]['bryson_hinge_moment']:.4g}"
        for k in (0, 1, 3, 5)
    ]
    assert labels == sorted(expected)
    legend = {t.get_text() for t in ax.get_legend().get_texts()}
    assert {"Pareto front", "actuator saturated in the gust", "best case"} <= legend
    sat = [c for c in ax.collections if c.get_label() == "actuator saturated in the gust"]
    assert len(sat) == 1 and len(sat[0].get_offsets()) == 2
    assert "aileron_chord [-] / bryson_hinge_moment [N m]" in ax.get_title()


def test_figures_a_run_writes():
    r = _result(THREE, _rows(THREE))
    assert list(r.figures()) == [f"heatmap_{m}.png" for m in HEATMAP_METRICS[True]] + ["pareto.png"]
    ol = _result(THREE, _rows(THREE, closed_loop=False), closed_loop=False)
    assert list(ol.figures()) == [
        "heatmap_open_loop_flutter_speed.png",
        "heatmap_open_loop_flutter_frequency.png",
    ]
    one = {"aileron_chord": (0.15, 0.2)}
    assert list(_result(one, _rows(one)).figures()) == ["pareto.png"]


# -- a real run and the command line -----------------------------------------------------------


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    out = tmp_path_factory.mktemp("trade")
    argv = ["trade", str(ROOT / "scenarios" / "trade_aileron.toml"), "--quick", "--out", str(out)]
    assert main([*argv, "--workers", "2", "--no-progress"]) == 0
    return out / "trade_aileron"


@pytest.mark.slow
def test_run_writes_one_heatmap_per_metric(folder):
    names = {p.name for p in folder.iterdir()}
    assert names == {
        "cases",
        "study.json",
        "summary.json",
        "trade_aileron.csv",  # <result>.csv and .nc, <result> from [output]
        "trade_aileron.nc",
        "pareto.png",
        *(f"heatmap_{m}.png" for m in HEATMAP_METRICS[True]),
    }
    summary = json.loads((folder / "summary.json").read_text())
    best = load_trade(folder).best_case()
    assert summary["best_case"]["case_id"] == best["case_id"]
    assert summary["best_case_criterion"] == BEST_CRITERION[True]
    assert set(summary["files"]) == {
        "csv",
        "netcdf",
        "pareto",
        *(f"heatmap_{m}" for m in HEATMAP_METRICS[True]),
    }


@pytest.mark.slow
def test_plot_metric_and_slice(folder, tmp_path, capsys):
    png = tmp_path / "h.png"
    argv = ["plot", str(folder), "--metric", "tip_accel_peak", "--out", str(png)]
    assert main([*argv, "--slice", "bryson_hinge_moment=500,aileron_start=0.6"]) == 2
    assert "two parameters left free" in capsys.readouterr().err
    assert main([*argv, "--slice", "bryson_hinge_moment=500"]) == 0
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert main(["plot", str(folder), "--kind", "heatmap", "--out", str(png)]) == 0


@pytest.mark.parametrize(
    "options,fragment",
    [
        (["--metric", "flutter"], "valid are open_loop_flutter_speed, "),
        (["--slice", "chord=0.15"], "swept are aileron_start, aileron_chord, bryson_hinge_moment"),
        (["--slice", "aileron_chord=0.17"], "its values are 0.15, 0.2"),
        (["--slice", "aileron_chord"], "expected PARAM=VALUE[,PARAM=VALUE]"),
        (["--kind", "pareto", "--metric", "disk_margin"], "apply to the heat map"),
    ],
)
@pytest.mark.slow
def test_plot_errors_are_one_line(folder, tmp_path, capsys, options, fragment):
    assert main(["plot", str(folder), *options, "--out", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err
    assert fragment in err and len(err.splitlines()) == 1
    assert not (tmp_path / "x.png").exists()
