"""Issue 25, item 8 (plots) and the detached figure of item 10: figures checked for what an
engineer reads off them (axis limits, legend texts, labels, line data), and a figure made by
aeroservo is the current pyplot figure when pyplot is in use, shown once in a notebook."""

from __future__ import annotations

import dataclasses
import io

import matplotlib.pyplot as plt
import numpy as np
import pytest
from conftest import ROOT
from matplotlib.backends.backend_agg import FigureCanvasAgg
from test_notebooks import KERNEL, kernel_name  # noqa: F401  (a kernel of this Python)

import aeroservo as aes
from aeroservo._figures import detached
from aeroservo.design.plant import Limits
from aeroservo.plots import (
    plot_loop_margins,
    plot_mode_shapes,
    plot_modes,
    plot_root_locus,
    plot_vg,
)
from aeroservo.plots.modes import strain_energy_shares
from aeroservo.simulate.result import SimulationResult
from aeroservo.stability.result import Crossing, FlutterResult

HM = "aileron_hinge_moment"


@pytest.fixture(scope="module")
def lqr_run():
    """The shipped LQR scenario run (time histories, open-loop run, boundary, margins)."""
    from aeroservo.files import load_scenario
    from aeroservo.studies.runs import run_scenario

    return run_scenario(load_scenario(ROOT / "scenarios" / "goland_aileron_lqr.toml"))


@pytest.fixture(scope="module")
def aileron_flutter(aileron10):
    return aes.flutter_boundary(aileron10, 1.225)


def _legend_texts(ax) -> list[str]:
    leg = ax.get_legend()
    return [] if leg is None else [t.get_text() for t in leg.get_texts()]


def _ink(fig) -> float:
    """Share of non-white pixels of the figure saved as PNG (0: blank)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=40)
    buf.seek(0)
    img = plt.imread(buf)
    return float(np.mean(np.any(img[..., :3] < 0.95, axis=-1)))


def _history(peak: float = 200.0, rate=2.0e5, twist: bool = False) -> SimulationResult:
    """A synthetic decaying closed-loop run: tip displacement, deflection, hinge moment."""
    t = np.linspace(0.0, 2.0, 2001)
    decay = np.exp(-2.0 * t) * np.sin(2 * np.pi * 10 * t)
    outputs = {"tip_disp": 0.01 * decay, "aileron_deflection": 0.01 * decay}
    units = {"tip_disp": "m", "aileron_deflection": "rad", HM: "N m"}
    if twist:
        outputs["tip_twist"] = 0.02 * decay
        units["tip_twist"] = "rad"
    u = {HM: peak * decay}
    return SimulationResult(
        t=t,
        outputs=outputs,
        commands=dict(u),
        applied=dict(u),
        disturbance={},
        status=[],
        limits=Limits(magnitude={HM: 2000.0}, rate={HM: rate} if rate else {}),
        units=units,
        speed=150.0,
        density=1.225,
    )


# -- item 10: a figure is the current pyplot figure (plt.gcf().savefig is not blank) -----------


def test_boundary_plot_is_the_current_pyplot_figure(lqr_run):
    fig = lqr_run.boundary.plot()
    assert plt.gcf() is fig
    assert _ink(plt.gcf()) > 0.02  # what plt.savefig writes is the boundary, not a blank page


def test_every_figure_is_current_and_write_run_leaves_none(
    lqr_run, aileron10, aileron_flutter, tmp_path
):
    from aeroservo.files.outputs import write_run

    made = [
        lqr_run.simulation.plot(),
        plot_loop_margins(lqr_run.margins),
        plot_vg(aileron_flutter),
        plot_root_locus(aileron_flutter),
        plot_mode_shapes(aileron10, aileron10.natural_modes(3), n=3),
    ]
    for fig in made:
        assert fig.number in plt.get_fignums()
    assert plt.gcf() is made[-1]
    with detached():
        loose = plot_vg(aileron_flutter)
    assert plt.gcf() is made[-1]
    assert all(plt.figure(n) is not loose for n in plt.get_fignums())
    open_before = plt.get_fignums()
    write_run(lqr_run, tmp_path)  # figures written to files: none left in pyplot
    assert plt.get_fignums() == open_before
    assert (tmp_path / "goland_aileron_lqr.png").stat().st_size > 10_000


# -- time histories: axes scaled to the signal, limits named, open loop overlaid -------------


def test_hinge_moment_axis_scaled_to_the_signal_and_far_limit_named():
    fig = _history(peak=200.0).plot()
    ax = [a for a in fig.axes if a.get_ylabel().startswith(HM)][0]
    lo, hi = ax.get_ylim()
    assert 200.0 <= hi < 300.0 and -300.0 < lo <= -200.0  # not stretched to +-2000
    texts = _legend_texts(ax)
    assert "limit \u00b12000 N m, off scale" in texts
    assert any(t.startswith("rate limit \u00b12e+05 N m/s, reached at") for t in texts)
    drawn = [ln.get_ydata() for ln in ax.get_lines() if len(ln.get_ydata())]
    assert not [y for y in drawn if np.allclose(np.abs(y), 2000.0)]


def test_near_limit_is_drawn():
    fig = _history(peak=1000.0, rate=None).plot()
    ax = [a for a in fig.axes if a.get_ylabel().startswith(HM)][0]
    assert ax.get_ylim()[1] >= 2000.0
    limits = [ln for ln in ax.get_lines() if len(ln.get_ydata()) == 2]
    assert sorted(float(ln.get_ydata()[0]) for ln in limits) == [-2000.0, 2000.0]
    assert "limit \u00b12000 N m" in _legend_texts(ax)
    assert not any("rate" in t for t in _legend_texts(ax))


def test_angles_drawn_in_degrees():
    res = _history(twist=True)
    fig = res.plot(tip="tip_twist")
    ax = fig.axes[0]
    assert ax.get_ylabel() == "tip_twist [deg]"
    np.testing.assert_allclose(
        ax.get_lines()[0].get_ydata(), np.degrees(res.outputs["tip_twist"]), rtol=1e-12
    )


def test_open_loop_overlay_clipped_where_it_diverges():
    closed = _history()
    grow = dataclasses.replace(
        closed,
        outputs={k: 0.01 * np.exp(3.0 * closed.t) * np.sin(60 * closed.t) for k in closed.outputs},
    )
    fig = closed.plot(open_loop=grow)
    ax = fig.axes[0]
    (ol,) = [ln for ln in ax.get_lines() if ln.get_label() == "open loop"]
    peak = np.max(np.abs(closed.outputs["tip_disp"]))
    y = ol.get_ydata()
    assert np.max(np.abs(y)) <= 2.0 * peak and len(y) < closed.t.size  # cut, not rescaled
    assert ax.get_ylim()[1] < 3.0 * peak
    assert any("open loop leaves the scale" in t.get_text() for t in ax.texts)
    assert "open loop" in _legend_texts(ax) and "closed loop" in _legend_texts(ax)


def test_scenario_run_carries_its_open_loop(lqr_run):
    ol = lqr_run.open_loop
    assert ol is not None and not any(np.any(c) for c in ol.commands.values())
    np.testing.assert_array_equal(ol.t, lqr_run.simulation.t)
    assert ol.outputs["tip_disp"][0] == pytest.approx(lqr_run.simulation.outputs["tip_disp"][0])
    fig = lqr_run.simulation.plot(open_loop=ol)
    assert "open loop" in _legend_texts(fig.axes[0])


# -- margins: Bode range, Nyquist legend ---------------------------------------------------


def test_bode_magnitude_range_and_nyquist_legend(lqr_run):
    m = lqr_run.margins
    ch = m.channels[HM]
    f = ch.omega / ch.omega.max()
    deep = dataclasses.replace(ch, response=ch.response * f**12)  # down to -250 dB and below
    m2 = dataclasses.replace(m, channels={HM: deep})
    fig = plot_loop_margins(m2)
    FigureCanvasAgg(fig).draw()  # the mathtext of the legend renders
    ax_n, ax_m, ax_p = fig.axes[:3]
    db = 20 * np.log10(np.abs(deep.response[ch.omega > 0]))
    assert db.min() < -250.0
    top = max(db.max(), 0.0)
    assert ax_m.get_ylim()[0] >= top - 110.0
    phase = ax_p.get_lines()[0].get_ydata()
    assert np.all(np.isnan(phase[db < top - 100.0]))
    texts = _legend_texts(ax_n)
    assert any(t.startswith(r"$L(e^{j\omega T})$, loop broken at " + HM) for t in texts)
    assert any(r"T = 1 ms" in t for t in texts)


# -- V-g: divergence and overdamped legend only for what is drawn ---------------------------


def test_vg_divergence_is_a_labelled_line_without_a_fake_point(aileron_flutter):
    r = aileron_flutter
    assert any(c.kind == "divergence" for c in r.crossings)
    fig = plot_vg(r)
    ax_f, ax_g = fig.axes[:2]
    for ax in (ax_f, ax_g):
        assert not [ln for ln in ax.get_lines() if ln.get_marker() == "D"]
    texts = [t.get_text() for t in ax_f.texts]
    assert any(f"V_div = {r.divergence_speed:.4g} m/s" in t for t in texts)
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert not any("overdamped" in t for t in legend)  # nothing overdamped is drawn


def test_vg_divergence_marked_where_a_branch_is_overdamped():
    """A branch that turns into a real pair through zero: the divergence is marked at 0 Hz on
    its dotted stretch, and the "overdamped" legend entry is there."""
    V = np.linspace(0.0, 100.0, 11)
    lam = np.column_stack([-0.1 * V + 60j, -1.0 + 0.02 * V + 30j * (V < 45)])
    r = FlutterResult(
        V,
        lam,
        ["1st bending", "1st torsion"],
        [Crossing(50.0, 0.0, 1, "divergence")],
        50.0,
        1.225,
        100.0,
        4,
    )
    fig = plot_vg(r)
    ax_f, ax_g = fig.axes[:2]
    marks = [ln.get_xydata()[0] for ln in ax_f.get_lines() if ln.get_marker() == "D"]
    assert len(marks) == 1 and tuple(marks[0]) == (50.0, 0.0)
    assert not [ln for ln in ax_g.get_lines() if ln.get_marker() == "D"]
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "overdamped (real roots)" in legend


# -- mode shapes: each field on its own scale, energy shares, flutter mode as |.| and phase --


def test_mode_shapes_normalised_per_field_with_energy_shares(aileron10):
    modes = aileron10.natural_modes(4)
    shares = strain_energy_shares(aileron10, modes.shapes)
    total = sum(shares.values())
    np.testing.assert_allclose(total, 1.0, rtol=1e-12)
    kind = {"w": "bending", "phi": "torsion", "delta_aileron": "flap"}
    for j, label in enumerate(modes.labels):  # the label names the largest share
        top = max(shares, key=lambda k: shares[k][j])
        assert kind[top] in label
    fig = plot_mode_shapes(aileron10, modes, n=4)
    for j, ax in enumerate(fig.axes[:4]):
        assert ax.get_ylabel() == "field / its peak [-]"
        for ln in ax.get_lines()[:-1]:  # every field, the zero line excluded
            assert np.nanmax(np.abs(ln.get_ydata())) == pytest.approx(1.0, rel=1e-12)
        title = ax.get_title()
        assert modes.labels[j] in title and "strain energy: " in title
    texts = _legend_texts(fig.axes[2])
    assert any(t.startswith("twist \u03c6 / ") and t.endswith(" deg") for t in texts)
    assert any(t.startswith("bending w / ") and t.endswith(" m") for t in texts)
    assert any(t.startswith("aileron rotation \u03b4 / ") for t in texts)
    # the 37.7 Hz mode is torsion by energy, though its aileron turns furthest in radians
    assert "torsion 64%" in fig.axes[2].get_title()


def test_flutter_mode_as_magnitude_and_phase(aileron10, aileron_flutter):
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        path = f"{d}/s.npz"
        aes.save_result(aileron_flutter, path, model=aileron10)
        saved = aes.load_result(path)
    fm = {k: (v if k == "x" else v[:, None]) for k, v in saved.flutter_mode.items()}
    fig = plot_modes(fm, ["flutter mode"], [aileron_flutter.flutter_frequency])
    ax_m, ax_p = fig.axes[:2]
    assert ax_m.get_ylabel() == "|field| / its peak [-]"
    assert ax_p.get_ylabel().startswith("phase [deg]\nrel. to bending w\nat x = 6.1 m")
    w, phi = fm["w"][:, 0], fm["phi"][:, 0]
    i = int(np.argmax(np.abs(w)))
    twist_phase = ax_p.get_lines()[1].get_ydata()  # w, phi, delta_aileron: fields' order
    assert twist_phase[-1] == pytest.approx(np.degrees(np.angle(phi[-1] / w[i])), abs=1e-9)
    assert 90.0 < twist_phase[-1] < 150.0  # torsion leads bending: a flutter mode
    for ln in ax_m.get_lines():
        if len(ln.get_ydata()) > 2:
            assert np.nanmax(ln.get_ydata()) == pytest.approx(1.0)
    assert any("phase +" in t for t in _legend_texts(ax_m))


# -- notebook: shown once, current in pyplot -------------------------------------------------


@pytest.mark.usefixtures("kernel_name")
@pytest.mark.slow
def test_notebook_shows_each_figure_once():
    """In Jupyter (inline backend) a figure is shown once whether it is the cell's value,
    assigned, or the line ends with ';', and it is ``plt.gcf()`` in its cell."""
    import nbclient
    import nbformat

    cells = [
        "import matplotlib.pyplot as plt\nimport aeroservo as aes\n"
        "from aeroservo.plots import plot_vg\n"
        "r = aes.flutter_boundary(aes.AeroelasticModel(aes.examples.goland(), 4), 1.225)",
        "plot_vg(r)",
        "fig = plot_vg(r)",
        "fig = plot_vg(r)\nplt.gcf() is fig",
        "plot_vg(r);",
        "fig",
    ]
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in cells])
    nbclient.NotebookClient(nb, timeout=300, kernel_name=KERNEL).execute()
    for cell in nb.cells[1:]:
        images = [o for o in cell.outputs if "image/png" in o.get("data", {})]
        assert len(images) == 1, (cell.source, len(images))
    texts = [o["data"]["text/plain"] for o in nb.cells[3].outputs if "text/plain" in o["data"]]
    assert "True" in texts
