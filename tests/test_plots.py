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
