"""The planform figure (issue 27: masses and sweep drawn on the planform): its geometry
against hand-computed points (stations along the elastic axis, sections normal to it)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import aeroservo as aes
from aeroservo.plots.planform import planform_points, plot_planform


def test_swept_tip_and_a_mass_are_where_the_geometry_puts_them():
    sweep = np.deg2rad(30.0)
    wing = aes.examples.goland_swept(sweep)
    seg = wing.segments[-1]
    tip = planform_points(wing, wing.span, 0.0)[0]
    np.testing.assert_allclose(tip, wing.span * np.array([np.sin(sweep), np.cos(sweep)]))
    te = planform_points(wing, wing.span, seg.semichord * (1 - seg.a))[0]
    # the trailing edge lies aft of the axis, normal to it
    np.testing.assert_allclose(
        te - tip, seg.semichord * (1 - seg.a) * np.array([np.cos(sweep), -np.sin(sweep)])
    )
    store = aes.examples.goland_store()
    (m,) = store.masses
    fig = plot_planform(store)
    (pts,) = [c for c in fig.axes[0].collections if c.get_offsets().shape[0] == 1][:1]
    np.testing.assert_allclose(pts.get_offsets()[0], [m.station, m.offset])
    assert any(m.name in t.get_text() for t in fig.axes[0].texts)


def test_cranked_wing_axis_is_continuous():
    base = aes.examples.goland()
    s0 = base.segments[0]
    half = base.span / 2
    segs = (
        dataclasses.replace(s0, end=half, sweep=0.0),
        dataclasses.replace(s0, start=half, sweep=np.deg2rad(-20.0)),
    )
    wing = aes.Wing(span=base.span, segments=segs, name="cranked")
    inner = planform_points(wing, half, 0.0)[0]
    np.testing.assert_allclose(inner, [0.0, half], atol=1e-12)
    tip = planform_points(wing, base.span, 0.0)[0]
    np.testing.assert_allclose(
        tip - inner, half * np.array([np.sin(-0.349066), np.cos(-0.349066)]), rtol=1e-5
    )
    fig = plot_planform(wing)
    assert fig.axes[0].get_aspect() == 1.0


def test_modes_command_writes_the_planform(tmp_path):
    from aeroservo.cli import main

    out = tmp_path / "pf.png"
    assert main(["modes", "goland_store", "-n", "1", "--planform", str(out)]) == 0
    assert out.stat().st_size > 1000
    assert main(["modes", "goland", "--planform", str(tmp_path / "x.txt")]) == 2
    assert not (tmp_path / "x.txt").exists()


@pytest.mark.parametrize("name", ["goland", "goland_aileron", "goland_swept", "goland_store"])
def test_every_builtin_wing_draws(name):
    plot_planform(getattr(aes.examples, name)())
