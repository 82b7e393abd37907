"""Figures of a gust-loads study (``aeroservo.studies.gust.plots``), drawn from a
``GustLoadsResult`` alone.

Independent checks, in this file:

* the turbulence design ellipse against its definition ``z^T S^-1 z = U_sigma^2`` (S the 2 x 2
  covariance of the two loads per unit gust variance, built by hand in the test), its extremes
  ``+-U_sigma sqrt(S_ii)`` and its design points as the support points ``U_sigma S e /
  sqrt(e^T S e)`` of the ellipse in the directions of the axes (Lagrange's conditions for the
  largest ``e . z`` on the ellipse, not the parametrisation the package draws);
* every number drawn (bar heights, GLA, discrete correlated points, extremes and their times,
  tuning curves) against the record it comes from, in the display units (kN, kN m);
* one-line errors listing the valid loads, points and loops.
"""

from __future__ import annotations

import copy
import inspect
import re

import matplotlib
import numpy as np
import pytest
from conftest import ROOT
from matplotlib.figure import Figure

from aeroservo.errors import InputError
from aeroservo.files.scenario_file import load_scenario
from aeroservo.studies.gust import plots as gp
from aeroservo.studies.gust.run import run_gust_loads
from aeroservo.studies.gust.study import FlightPoint, GustLoadsStudy
from aeroservo.studies.gust.turbulence import turbulence_response

matplotlib.use("Agg")

LOADS = ("root_shear", "root_bending_moment", "root_torque", "tip_le_accel")
CONTROL = "aileron_hinge_moment"
KILO = 1e-3  # N -> kN, N m -> kN m
# the closed loop's turbulence (turbulence_response with a controller) when it is available
TURBULENCE = "controller" in inspect.signature(turbulence_response).parameters


@pytest.fixture(scope="module")
def result():
    """Goland wing with aileron and its LQR loop, 6 elements, 4 gradients: sea level V_C (both
    loops) and 3000 m V_D (the closed loop is unstable there: open loop only)."""
    sc = load_scenario(ROOT / "scenarios" / "goland_aileron_lqr.toml")
    points = (
        FlightPoint(0.0, 100.0, "V_C", "nominal"),
        FlightPoint(3000.0, 125.0, "V_D", "nominal"),
    )
    study = GustLoadsStudy(
        {"nominal": sc.wing},
        points,
        LOADS,
        controls=(CONTROL,),
        sensors=sc.sensors,
        outputs=sc.outputs,
        controller=sc.controller,
        design_density=1.225,
        design_speed_factor=1.1,
        turbulence=TURBULENCE,
        n_gradients=4,
        elements=6,
        name="small",
    )
    return run_gust_loads(study)


A_X, A_Y, RHO = 3.0e4, 900.0, -0.55  # N m per m/s: bending and torque RMS per unit gust RMS


@pytest.fixture(scope="module")
def turbulent(result):
    """The result with a covariance made by hand in every record (bending and torque)."""
    r = copy.deepcopy(result)
    outs = ["root_bending_moment", "root_torque", "root_shear"]
    s = np.array([[A_X**2, RHO * A_X * A_Y, 0.0], [RHO * A_X * A_Y, A_Y**2, 0.0], [0, 0, 1e6]])
    for rec in r.records:
        rec["covariance"] = {"outputs": outs, "matrix": s.tolist()}
    return r


def _axes(fig: Figure) -> list:
    return [ax for ax in fig.axes if ax.get_visible() and ax.axison]


def _ellipses(ax) -> list:
    return [ln for ln in ax.lines if len(ln.get_xdata()) > 100]


@pytest.mark.slow
def test_every_figure_has_its_panels(result, tmp_path):
    assert result.loops == ["open", "closed"]
    loads = result.loads
    assert CONTROL in loads  # the control the loop applied is a load of the closed loop
    figs = {
        "envelope": (gp.plot_envelope(result), len(loads)),
        "correlated": (gp.plot_correlated(result), 2),  # one panel per flight point
        "correlated_one": (gp.plot_correlated(result, point=0, loop="closed"), 1),
        "history": (gp.plot_gust_history(result, 0, "root_bending_moment"), 3),
        "history_open_only": (gp.plot_gust_history(result, 1, "root_torque", "min"), 2),
        "critical": (gp.plot_critical_gusts(result), len(loads)),
        "critical_two": (gp.plot_critical_gusts(result, ["root_torque", CONTROL], "closed"), 2),
        "tuning": (gp.plot_tuning(result, 0, "root_bending_moment"), 2),  # one per loop
        "tuning_open_only": (gp.plot_tuning(result, 1, "tip_le_accel"), 1),
    }
    for name, (fig, n) in figs.items():
        assert isinstance(fig, Figure), name
        assert len(_axes(fig)) == n, name
        fig.savefig(tmp_path / f"{name}.png", dpi=50)
    env = figs["envelope"][0]
    titles = [ax.get_title() for ax in _axes(env)]
    assert sorted(t.split(" ")[0] for t in titles) == sorted(loads)
    assert f"{CONTROL} (closed loop only)" in titles
    assert "clamped wing" in env.get_suptitle() and "incremental" in env.get_suptitle()
    units = {ax.get_title().split(" ")[0]: ax.get_ylabel() for ax in _axes(env)}
    assert units["root_shear"] == "limit load [kN]"
    assert units["root_bending_moment"] == "limit load [kN m]"
    assert units["tip_le_accel"] == "limit load [m/s^2]"
    hist = _axes(figs["history"][0])
    assert hist[0].get_ylabel() == "gust velocity\n[m/s TAS]"
    assert hist[2].get_ylabel() == "applied control\n[kN m]"
    assert "leading edge" in hist[2].get_xlabel()
    # the methods of the result delegate to the same figures
    assert len(_axes(result.plot_envelope())) == len(loads)
    assert len(_axes(result.plot_correlated(point=1))) == 1
    assert len(_axes(result.plot_gust_history(0, "root_torque"))) == 3
    assert len(_axes(result.plot_critical_gusts(loop="open"))) == len(loads)
    assert len(_axes(result.plot_tuning(0, "root_torque"))) == 2


def test_envelope_bars_and_alleviation(result):
    fig = gp.plot_envelope(result)
    ax = next(a for a in _axes(fig) if a.get_title() == "root_bending_moment")
    bars = sorted(ax.patches, key=lambda b: b.get_x())
    t = result.table
    t = t[t["load"] == "root_bending_moment"]
    want = [
        t[(t["point"] == 0) & (t["loop"] == "open")]["limit"].item(),
        t[(t["point"] == 0) & (t["loop"] == "closed")]["limit"].item(),
        t[(t["point"] == 1) & (t["loop"] == "open")]["limit"].item(),
    ]
    assert len(bars) == 3  # no closed loop at point 1 (unstable)
    assert [b.get_height() for b in bars] == pytest.approx([KILO * w for w in want], rel=1e-12)
    gla = 100 * (1 - want[1] / want[0])
    texts = [tx.get_text() for tx in ax.texts]
    assert f"GLA\n{gla:.1f} %" in texts
    assert " no closed loop" in texts
    a = result.alleviation
    raised = a[(a["point"] == 0) & (a["load"] == "root_bending_moment")]["raised"].item()
    red = matplotlib.colors.to_rgba("tab:red")
    assert (tuple(bars[1].get_edgecolor()) == red) == raised
    notes = fig.get_supxlabel()
    assert "point 1" in notes and "unstable" in notes  # why the closed loop is missing
    assert ("continuous turbulence not computed" in notes) == (not TURBULENCE)


def test_correlated_discrete_points_are_the_records(result):
    x, y = "root_bending_moment", "root_torque"
    fig = gp.plot_correlated(result, x, y, point=0, loop="closed")
    (ax,) = _axes(fig)
    rec = result.record(0, "closed")
    drawn = {
        ln.get_marker(): (ln.get_xdata()[0], ln.get_ydata()[0])
        for ln in ax.lines
        if ln.get_marker() in (">", "<", "^", "v")
    }
    vx, vy = rec["loads"][x], rec["loads"][y]
    want = {
        ">": (vx["max"], vx["max_correlated"][y]),
        "<": (vx["min"], vx["min_correlated"][y]),
        "^": (vy["max_correlated"][x], vy["max"]),
        "v": (vy["min_correlated"][x], vy["min"]),
    }
    for m, (wx, wy) in want.items():
        assert drawn[m] == pytest.approx((KILO * wx, KILO * wy), rel=1e-12), m
    if not TURBULENCE:
        assert "turbulence covariance not computed" in fig.get_supxlabel()
        assert not _ellipses(ax)


def test_design_ellipse_geometry(turbulent):
    """The ellipse drawn is ``z^T S^-1 z = U_sigma^2`` with its extremes at the turbulence
    limit loads and its design points the support points in the axis directions."""
    fig = gp.plot_correlated(turbulent, point=0)
    (ax,) = _axes(fig)
    assert "turbulence covariance not computed" not in (fig.get_supxlabel() or "")
    s = np.array([[A_X**2, RHO * A_X * A_Y], [RHO * A_X * A_Y, A_Y**2]])
    for loop, ellipse in zip(turbulent.loops, _ellipses(ax), strict=True):
        u = turbulent.record(0, loop)["u_sigma"]
        z = np.vstack([ellipse.get_xdata(), ellipse.get_ydata()]) / KILO
        q = np.einsum("in,ij,jn->n", z, np.linalg.inv(s), z)
        assert q == pytest.approx(u**2, rel=1e-12)
        # extremes at +-U_sigma A: sampled every 1 deg, exact to (pi/180)^2 / 2 = 1.5e-4
        assert z[0].max() == pytest.approx(u * A_X, rel=1e-12)  # t = 0 is a sample
        assert z[0].min() == pytest.approx(-u * A_X, rel=1e-12)
        assert z[1].max() == pytest.approx(u * A_Y, rel=2e-4)
        assert z[1].min() == pytest.approx(-u * A_Y, rel=2e-4)
        assert z[1].max() <= u * A_Y * (1 + 1e-12)
        # design points: the largest e.z on the ellipse, z = U S e / sqrt(e^T S e)
        design = next(
            ln
            for ln in ax.lines
            if ln.get_marker() == "o" and ln.get_markeredgecolor() == ellipse.get_color()
        )
        got = np.column_stack([design.get_xdata(), design.get_ydata()]) / KILO
        for e, row in zip(([1, 0], [-1, 0], [0, 1], [0, -1]), got, strict=True):
            e = np.array(e, dtype=float)
            assert row == pytest.approx(u * s @ e / np.sqrt(e @ s @ e), rel=1e-12)
    # the function itself: rho = +-1 degenerates to a segment, |rho| > 1 is clipped
    x, y, d = gp.design_ellipse(2.0, 3.0, 1.0, 1.5)
    assert np.allclose(y, 1.5 * x)
    assert gp.design_ellipse(2.0, 3.0, 1.0 + 1e-15, 1.5)[2] == pytest.approx(d)


def test_gust_history_marks_the_extremes(result):
    fig = gp.plot_gust_history(result, 0, "root_torque", "min")
    ax_gust, ax_load, ax_ctrl = _axes(fig)
    for loop in ("open", "closed"):
        v = result.record(0, loop)["loads"]["root_torque"]
        star = next(
            ln
            for ln in ax_load.lines
            if ln.get_marker() == "*" and ln.get_color() == gp.LOOP_COLORS[loop]
        )
        assert (star.get_xdata()[0], star.get_ydata()[0]) == pytest.approx(
            (v["min_time"], KILO * v["min"]), rel=1e-12
        )
        label = next(t.get_text() for t in ax_load.get_legend().get_texts() if loop in t.get_text())
        assert f"{KILO * v['min']:.4g} kN m at t = {v['min_time']:.3f} s" in label
        gust = next(t.get_text() for t in ax_gust.get_legend().get_texts() if loop in t.get_text())
        assert f"H = {v['min_gradient']:.1f} m" in gust and "U_ds" in gust
    at_limit = result.record(0, "closed")["time_at_limit"][CONTROL]
    # without a limit stored (an older result): the share in the legend, no line
    bare = copy.copy(result)
    bare.settings = {k: v for k, v in result.settings.items() if k != "limits"}
    ax_ctrl = _axes(gp.plot_gust_history(bare, 0, "root_torque", "min"))[2]
    text = ax_ctrl.get_legend().get_texts()[0].get_text()
    assert (f"{at_limit:.3g} s" in text) == (at_limit > 0)
    assert not any(ln.get_linestyle() == "--" for ln in ax_ctrl.lines)
    # with the limit in the settings, +-limit drawn (it is within 3 x the signal)
    r = copy.copy(result)
    r.settings = {**result.settings, "limits": {"magnitude": {CONTROL: 2000.0}}}
    ax_ctrl = _axes(gp.plot_gust_history(r, 0, "root_torque", "min"))[2]
    dashed = sorted(ln.get_ydata()[0] for ln in ax_ctrl.lines if ln.get_linestyle() == "--")
    assert dashed == [-2.0, 2.0]  # kN m
    r.settings = {**result.settings, "limits": {"magnitude": {CONTROL: 1e7}}}  # far: not drawn
    ax_ctrl = _axes(gp.plot_gust_history(r, 0, "root_torque", "min"))[2]
    assert not any(ln.get_linestyle() == "--" for ln in ax_ctrl.lines)


def test_critical_gusts_at_the_worst_point(result):
    fig = gp.plot_critical_gusts(result, ["root_shear"], "open")
    (ax,) = _axes(fig)
    t = result.table
    t = t[(t["loop"] == "open") & (t["load"] == "root_shear")]
    worst = int(t.loc[t[["discrete_max", "discrete_min"]].abs().max(axis=1).idxmax(), "point"])
    assert f"worst at point {worst}" in ax.get_title()
    v = result.record(worst, "open")["loads"]["root_shear"]
    (star,) = [ln for ln in ax.lines if ln.get_marker() == "*"]
    assert abs(star.get_ydata()[0]) == pytest.approx(KILO * max(v["max"], -v["min"]), rel=1e-12)


def test_tuning_curves_and_tuned_extremes(result):
    fig = gp.plot_tuning(result, 0, "root_bending_moment")
    for ax, loop in zip(_axes(fig), result.loops, strict=True):
        rec = result.record(0, loop)
        curves = [ln for ln in ax.lines if len(ln.get_xdata()) == len(rec["gradients"])]
        assert len(curves) == 4
        assert ax.get_xscale() == "log"
        for ln, key in zip(curves, ("up_max", "up_min", "down_max", "down_min"), strict=True):
            assert ln.get_xdata() == pytest.approx(rec["gradients"])
            assert ln.get_ydata() == pytest.approx(
                KILO * np.array(rec["tuning"]["root_bending_moment"][key]), rel=1e-12
            )
        stars = [ln for ln in ax.lines if ln.get_marker() == "*"]
        v = rec["loads"]["root_bending_moment"]
        got = sorted((s.get_ydata()[0], s.get_xdata()[0]) for s in stars)
        want = sorted([(KILO * v["max"], v["max_gradient"]), (KILO * v["min"], v["min_gradient"])])
        assert np.array(got) == pytest.approx(np.array(want), rel=1e-12)
        # the tuned extremes are at least the best of the scan
        scan = KILO * np.array(list(rec["tuning"]["root_bending_moment"].values()))
        assert KILO * v["max"] >= scan.max() * (1 - 1e-12)
        assert KILO * v["min"] <= scan.min() * (1 - 1e-12)


@pytest.mark.parametrize(
    ("call", "needles"),
    [
        (lambda r: gp.plot_correlated(r, "root_moment"), ["x = 'root_moment'", "root_torque"]),
        (lambda r: gp.plot_correlated(r, y="tip"), ["y = 'tip'", "root_bending_moment"]),
        (lambda r: gp.plot_correlated(r, "root_torque", "root_torque"), ["two different"]),
        (lambda r: gp.plot_correlated(r, loop="shut"), ["loop = 'shut'", "'open', 'closed'"]),
        (lambda r: gp.plot_correlated(r, point=1, loop="closed"), ["point 1", "'closed'"]),
        (lambda r: gp.plot_gust_history(r, 7, "root_torque"), ["point = 7", "0: nominal / 0 m"]),
        (lambda r: gp.plot_gust_history(r, True, "root_torque"), ["point = True"]),
        (lambda r: gp.plot_gust_history(r, 0, "lift"), ["load = 'lift'", "root_shear"]),
        (lambda r: gp.plot_gust_history(r, 0, "root_torque", "peak"), ["side = 'peak'"]),
        (lambda r: gp.plot_critical_gusts(r, ["root_torque", "drag"]), ["load = 'drag'"]),
        (lambda r: gp.plot_critical_gusts(r, loop="both"), ["loop = 'both'"]),
        (lambda r: gp.plot_tuning(r, -1, "root_torque"), ["point = -1", "1: nominal / 3000 m"]),
        (lambda r: gp.plot_tuning(r, 0, "tip"), ["load = 'tip'", "tip_le_accel"]),
        (lambda r: r.plot_tuning(0, "tip"), ["load = 'tip'"]),
    ],
)
def test_bad_arguments_are_one_line(result, call, needles):
    with pytest.raises(InputError, match=re.escape(needles[0])) as err:
        call(result)
    msg = str(err.value)
    assert "\n" not in msg
    for n in needles:
        assert n in msg
