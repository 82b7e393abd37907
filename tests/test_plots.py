"""Figures are built and contain what they claim (no display needed)."""

import numpy as np

from aeroservo.plots import plot_mode_shapes, plot_root_locus, plot_vg


def test_vg_plot_marks_flutter(goland10_flutter):
    fig = plot_vg(goland10_flutter)
    ax_f, ax_g = fig.axes[:2]
    assert len(ax_g.get_lines()) >= len(goland10_flutter.mode_labels)
    marked = [ln for ln in ax_g.get_lines() if ln.get_marker() == "o"]
    assert marked and np.isclose(marked[0].get_xdata()[0], goland10_flutter.flutter_speed)
    assert "flutter" in " ".join(t.get_text() for t in ax_g.texts)


def test_root_locus_and_modes(goland10, goland10_flutter):
    assert plot_root_locus(goland10_flutter).axes
    fig = plot_mode_shapes(goland10, goland10.natural_modes(3), n=3)
    assert "1st bending" in fig.axes[0].get_title()


def test_margin_figures(tmp_path):
    """Nyquist/Bode and margin-sweep figures of the shipped LQR loop: labelled axes with units,
    the margins' frequencies marked, the requirement drawn, files written."""
    from conftest import ROOT
    from ideal_loops import ideal

    from aeroservo.design.margin_sweep import margins_over_speed
    from aeroservo.design.margins import loop_margins
    from aeroservo.files import load_scenario
    from aeroservo.plots import plot_loop_margins, plot_margin_sweep
    from aeroservo.stability.boundary import flutter_boundary

    sc = ideal(load_scenario(ROOT / "scenarios" / "goland_aileron_lqr.toml"))
    model = sc.model()
    vf = flutter_boundary(model, sc.density).flutter_speed
    loop = sc.loop(model)
    ctrl = loop.design_controller(sc.controller, 1.1 * vf, sc.sample_rate, vf)
    m = loop_margins(loop.plant(1.1 * vf), ctrl)
    fig = plot_loop_margins(m, title=sc.name)
    ax_n, ax_m, ax_p, ax_s = fig.axes[:4]
    assert ax_n.get_xlabel() == "Re L" and ax_m.get_ylabel() == "|L| [dB]"
    assert ax_s.get_xlabel() == "frequency [Hz]" and ax_s.get_ylabel() == "plant input [dB]"
    # issue 24: S and T at the plant input with their peaks, and the break point named
    s_labels = [t.get_text() for t in ax_s.get_legend().get_texts()]
    assert any(t.startswith("|S = ") and "peak" in t for t in s_labels)
    assert any(t.startswith("|T = ") for t in s_labels)
    assert "black box" in fig.get_suptitle()
    labels = [t.get_text() for t in ax_m.get_legend().get_texts()]
    assert any("phase 62" in t for t in labels) and any("gain reduction" in t for t in labels)
    assert "requirement: 6 dB, 45 deg" in [t.get_text() for t in ax_n.get_legend().get_texts()]
    fig.savefig(tmp_path / "m.png")
    sw = margins_over_speed(
        loop.plant, ctrl, [1.0 * vf, 1.1 * vf, 1.2 * vf], reference_speed=1.1 * vf
    )
    fig = plot_margin_sweep(sw)
    assert [a.get_ylabel() for a in fig.axes] == [
        "gain margin [dB]",
        "phase margin [deg]",
        "disk margin alpha [-]",
    ]
    assert fig.axes[-1].get_xlabel() == "airspeed V [m/s]"
    fig.savefig(tmp_path / "s.png")
    assert (tmp_path / "m.png").stat().st_size > 10_000 and (tmp_path / "s.png").is_file()
