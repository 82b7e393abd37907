"""Flutter results as data (issue 13): saved sweeps, redrawn figures, mode shapes, the f06-like
table and the MATLAB export. Figures are rendered and checked for what a person would check."""

import json
import zipfile

import numpy as np
import pandas as pd
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from scipy.io import loadmat

import aeroservo as aes
from aeroservo.cli import main
from aeroservo.files.flutter_table import COLUMNS
from aeroservo.plots import plot_modes, plot_vg
from aeroservo.stability.pk import pk_flutter
from aeroservo.stability.result import Crossing, FlutterResult


@pytest.fixture(scope="module")
def sweep(tmp_path_factory, aileron10):
    """Goland with aileron: the sweep and its p-k, saved through the Python API."""
    r = aes.flutter_boundary(aileron10, 1.225)
    pk = pk_flutter(aileron10, 1.225, v_max=r.v_max)
    path = tmp_path_factory.mktemp("sweep") / "sweep.npz"
    aes.save_result(r, path, model=aileron10, pk=pk, title="Goland with aileron")
    return r, pk, path


def _lines(fig):
    return [ln.get_xydata() for ax in fig.axes for ln in ax.get_lines()]


def test_round_trip_keeps_every_array(sweep):
    r, pk, path = sweep
    saved = aes.load_result(path)
    for a, b in ((r, saved.result), (pk, saved.pk)):
        np.testing.assert_array_equal(a.speeds, b.speeds)
        np.testing.assert_array_equal(a.eigenvalues, b.eigenvalues)
        assert a.mode_labels == b.mode_labels
        assert a.crossings == b.crossings
        assert (a.divergence_speed, a.density, a.v_max) == (b.divergence_speed, b.density, b.v_max)
        assert a.flutter_speed == b.flutter_speed
    np.testing.assert_array_equal(r.exact, saved.result.exact)
    assert "[wing]" in saved.wing_text and "aileron" in saved.wing_text
    assert saved.meta["aeroservo_version"] == aes.__version__
    assert saved.meta["units"]["speed"] == "m/s"


def test_redrawn_figure_has_the_original_data(sweep):
    r, pk, path = sweep
    saved = aes.load_result(path)
    first = _lines(plot_vg(r, pk=pk, fmax=60.0))
    again = _lines(plot_vg(saved.result, pk=saved.pk, fmax=60.0))
    assert len(first) == len(again)
    for a, b in zip(first, again, strict=True):
        np.testing.assert_array_equal(a, b)


def _vg_checks(fig, result):
    FigureCanvasAgg(fig).draw()
    ax_f, ax_g = fig.axes[:2]
    assert "[Hz]" in ax_f.get_ylabel() and "[m/s]" in ax_g.get_xlabel()
    assert "g = -2" in ax_g.get_ylabel()
    assert fig.legends, "legend missing"
    box, page = fig.legends[0].get_window_extent(), fig.bbox
    assert page.x0 <= box.x0 and box.x1 <= page.x1 and page.y0 <= box.y0 and box.y1 <= page.y1
    for ax in (ax_f, ax_g):  # the legend does not cover the curves
        assert not box.overlaps(ax.get_window_extent())
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        for ln in ax.get_lines():
            xy = ln.get_xydata()
            xy = xy[np.all(np.isfinite(xy), axis=1)]
            if ln.get_transform() != ax.transData or xy.size == 0:
                continue
            assert np.all((xy[:, 0] >= x0) & (xy[:, 0] <= x1)), ln.get_label()
            assert np.all((xy[:, 1] >= y0) & (xy[:, 1] <= y1)), ln.get_label()
    marks = [
        ln.get_xydata()[0]
        for ln in ax_g.get_lines()
        if ln.get_marker() == "o" and ln.get_markerfacecolor() == "r" and len(ln.get_xdata())
    ]
    assert any(abs(x - result.flutter_speed) < 1e-9 and y == 0 for x, y in marks)


def test_vg_plot_is_readable(sweep):
    r, pk, _ = sweep
    fig = plot_vg(r, pk=pk)  # default: modes up to 3 x the flutter frequency, the rest counted
    _vg_checks(fig, r)
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    n_high = int(np.sum(r.frequencies[0] > 3 * r.flutter_frequency))
    assert n_high > 0 and f"{n_high} more modes not drawn" in texts
    _vg_checks(plot_vg(r, pk=pk, fmax=None), r)
    fig = plot_vg(r, fmax=20.0)
    _vg_checks(fig, r)
    labels = fig.legends[0].get_texts()
    modes = [t.get_text() for t in labels if t.get_text().split(":")[0].isdigit()]
    f0 = r.frequencies[0]
    assert len(modes) == int(np.sum(f0 <= 20.0)) and len(modes) < len(r.mode_labels)


def test_overdamped_stretch_is_drawn_as_such():
    """A branch that turns into a real pair is drawn at 0 Hz (dotted) and left out of the V-g
    panel; the line is broken, not joined to what follows."""
    V = np.linspace(0.0, 100.0, 11)
    lam = np.column_stack([-0.1 * V + 60j, -1.0 - 0.2 * V + 30j * (np.abs(V - 50) > 15)])
    r = FlutterResult(V, lam, ["1st bending", "1st torsion"], [], None, 1.225, 100.0, 4)
    fig = plot_vg(r)
    ax_f, ax_g = fig.axes[:2]
    real = np.abs(V - 50) <= 15
    g_line = [ln for ln in ax_g.get_lines() if ln.get_label().startswith("_")][1]
    assert np.all(np.isnan(g_line.get_ydata()[real]))
    dotted = [ln for ln in ax_f.get_lines() if ln.get_linestyle() == ":" and len(ln.get_xdata())]
    assert any(np.array_equal(np.isfinite(ln.get_ydata()), real) for ln in dotted)
    assert all(np.nanmax(np.abs(ln.get_ydata())) == 0 for ln in dotted if len(ln.get_ydata()))


def test_mode_shapes_in_metres_and_degrees(sweep, aileron10):
    _, _, path = sweep
    saved = aes.load_result(path)
    m = saved.modes
    natural = aileron10.natural_modes(m["frequency"].size)
    np.testing.assert_allclose(m["frequency"], natural.frequencies, rtol=1e-12)
    for j in range(m["frequency"].size):
        parts = [m["w"][:, j], m["phi"][:, j], m["delta_aileron"][:, j]]
        top = max(np.max(np.abs(p)) for p in parts)
        assert top == pytest.approx(1.0, rel=1e-12)  # largest deflection or rotation = 1
        fld = aileron10.nodal_fields(natural.shapes[:, j])  # an independent scaling
        k = int(np.argmax(np.abs(fld["w"])))
        np.testing.assert_allclose(m["w"][:, j] * fld["w"][k] / m["w"][k, j], fld["w"], atol=1e-12)
    fig = plot_modes(m, m["label"], m["frequency"], surfaces=saved.surfaces, modes=[0, 1])
    FigureCanvasAgg(fig).draw()
    panels = fig.axes[:2]
    # issue 25: each field divided by its own peak, named in m or deg in the legend
    assert all(ax.get_ylabel() == "field / its peak [-]" for ax in panels)
    labels = [ln.get_label() for ln in panels[0].get_lines()]
    assert any(t.startswith("bending w / ") and t.endswith(" m") for t in labels)
    assert any(t.startswith("twist") and t.endswith(" deg") for t in labels)
    flap = [ln for ln in panels[0].get_lines() if "aileron" in ln.get_label()][0]
    start, end = saved.surfaces["aileron"]
    outside = (m["x"] < start - 1e-9) | (m["x"] > end + 1e-9)
    assert outside.any() and np.all(np.isnan(flap.get_ydata()[outside]))
    assert all(ax.get_legend() is not None for ax in panels)


def test_flutter_mode_saved_at_the_flutter_speed(sweep, aileron10):
    r, _, path = sweep
    fm = aes.load_result(path).flutter_mode
    assert np.iscomplexobj(fm["w"])
    values = np.concatenate([fm["w"], fm["phi"], fm["delta_aileron"]])
    top = values[np.argmax(np.abs(values))]
    assert top == pytest.approx(1.0 + 0j, abs=1e-12)
    # independent check: the full model at the flutter speed has an eigenvalue on the axis at
    # the flutter frequency whose eigenvector has this shape
    lam, X = np.linalg.eig(aileron10.state_matrix(r.flutter_speed, 1.225))
    k = int(np.argmin(np.abs(lam - 2j * np.pi * r.flutter_frequency)))
    assert abs(lam[k].real) < 1e-5 * abs(lam[k])
    w = aileron10.nodal_fields(X[: aileron10.n_dofs, k])["w"]
    scale = w[-1] / fm["w"][-1]
    np.testing.assert_allclose(fm["w"] * scale, w, atol=1e-9 * np.max(np.abs(w)))


def test_table_reads_into_pandas(sweep, tmp_path, capsys):
    r, _, _ = sweep
    csv = tmp_path / "vg.csv"
    assert main(["flutter", "goland_aileron", "--pk", "--table", str(csv)]) == 0
    t = pd.read_csv(csv)
    assert tuple(t.columns) == COLUMNS
    td = t[t["method"] == "time-domain"]
    assert len(td) == r.speeds.size * len(r.mode_labels)
    one = td[td["mode"] == r.flutter.mode + 1]
    np.testing.assert_allclose(one["velocity_m_s"], r.speeds, rtol=1e-9)
    np.testing.assert_allclose(one["damping_g"], -2 * r.damping_ratio[:, r.flutter.mode], atol=1e-7)
    np.testing.assert_allclose(one["eas_m_s"], r.speeds * np.sqrt(1.225 / 1.225), rtol=1e-9)
    np.testing.assert_allclose(one["velocity_kt"], r.speeds / 0.514444, rtol=1e-5)
    assert (t["method"] == "p-k").any()


def _write_broken(kind: str, good, folder):
    path = folder / f"{kind}.npz"
    raw = good.read_bytes()
    with np.load(good) as z:
        data = {k: z[k] for k in z.files}
    meta = json.loads(str(data["meta"]))
    if kind == "truncated":
        path.write_bytes(raw[: len(raw) // 2])
        return path
    if kind == "json-summary":
        path = folder / "summary.json"
        path.write_text(json.dumps({"flutter_speed": 137.0}))
        return path
    if kind == "foreign":
        np.savez(path, x=np.arange(3))
        return path
    if kind == "pickled":
        np.savez(path, meta=np.array([{"a": 1}], dtype=object))
        return path
    if kind == "missing-key":
        del data["eigenvalues"]
    elif kind == "wrong-shape":
        data["eigenvalues"] = data["eigenvalues"][:, 0]
    elif kind == "wrong-rows":
        data["eigenvalues"] = data["eigenvalues"][:-1]
    elif kind == "bad-json":
        data["meta"] = np.array("{not json")
    elif kind == "meta-type":
        meta["sweep"] = [1, 2]
        data["meta"] = np.array(json.dumps(meta))
    elif kind == "labels":
        meta["sweep"]["mode_labels"] = ["one"]
        data["meta"] = np.array(json.dumps(meta))
    elif kind == "crossing-kind":
        data["crossing_kind"] = data["crossing_speed"]
    elif kind == "format":
        meta["format"] = "someone-else-1"
        data["meta"] = np.array(json.dumps(meta))
    np.savez(path, **data)
    return path


BROKEN = {
    "truncated": "not a .npz archive (no zip directory)",
    "json-summary": "a JSON summary?",
    "foreign": "no JSON header",
    "pickled": "array 'meta' holds Python objects (pickled)",
    "missing-key": "no array 'eigenvalues'",
    "wrong-shape": "'eigenvalues'",
    "wrong-rows": "rows for",
    "bad-json": "not valid JSON",
    "meta-type": "no 'sweep' table",
    "labels": "mode_labels",
    "crossing-kind": "'crossing_kind'",
    "format": "format 'someone-else-1'",
}


@pytest.mark.parametrize("kind", sorted(BROKEN))
def test_damaged_or_foreign_file_gives_one_line(kind, sweep, tmp_path, capsys):
    path = _write_broken(kind, sweep[2], tmp_path)
    out = tmp_path / "out.png"
    assert main(["plot", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("aeroservo: error:"), err
    assert BROKEN[kind] in err and str(path) in err
    assert not out.exists()


@pytest.mark.parametrize("kind", ["vg", "vf", "root-locus", "modes", "flutter-mode"])
def test_plot_command_kinds(kind, sweep, tmp_path, capsys):
    out = tmp_path / f"{kind}.png"
    argv = ["plot", str(sweep[2]), "--kind", kind, "--out", str(out), "--fmax", "30"]
    assert main(argv + (["--units", "knots", "--eas"] if kind == "vg" else [])) == 0
    assert out.stat().st_size > 10_000


def test_save_table_and_plot_are_one_set(tmp_path, capsys):
    """A failing output (a missing folder) leaves none of the others behind."""
    png, csv = tmp_path / "vg.png", tmp_path / "vg.csv"
    argv = ["flutter", "goland", "--plot", str(png), "--table", str(csv)]
    assert main(argv + ["--save", str(tmp_path / "no" / "s.npz")]) == 2
    assert not png.exists() and not csv.exists()
    assert main(["flutter", "goland", "--save", str(tmp_path / "s.txt")]) == 2
    assert "expected a .npz file name" in capsys.readouterr().err


def test_export_mat_for_matlab(tmp_path, capsys, aileron10):
    mat = tmp_path / "model.mat"
    argv = ["export", "goland_aileron", "--speed", "150", "--physical", "--out", str(mat)]
    assert main(argv + ["--inputs", "aileron_hinge_moment", "--outputs", "tip_twist"]) == 0
    d = loadmat(mat)
    ref = aes.statespace(
        aileron10, 150.0, 1.225, ["aileron_hinge_moment"], ["tip_twist"], balanced=False
    )
    np.testing.assert_array_equal(d["A"], np.asarray(ref.A))
    assert [str(x[0]) for x in d["input_names"][0]] == ["aileron_hinge_moment"]
    assert [str(x[0]) for x in d["output_units"][0]] == ["rad"]
    units = dict(zip((str(x[0]) for x in d["state_names"][0]), d["state_units"][0], strict=True))
    assert str(units["w_3"][0]) == "m" and str(units["phi_3_dot"][0]) == "rad/s"
    assert main(["export", "goland", "--speed", "150", "--out", str(tmp_path / "m.txt")]) == 2


def test_matlab_loader_ships():
    from pathlib import Path

    m = Path(__file__).resolve().parents[1] / "matlab" / "load_aeroservo.m"
    text = m.read_text()
    assert "function sys = load_aeroservo(file)" in text
    for field in ("StateName", "InputName", "OutputName", "InputUnit", "OutputUnit"):
        assert field in text


@pytest.mark.slow
def test_modes_command_plot_and_animation(tmp_path, capsys):
    from PIL import Image

    png, gif = tmp_path / "modes.png", tmp_path / "mode2.gif"
    argv = ["modes", "goland_aileron", "-n", "3", "--plot", str(png), "--animate", str(gif)]
    assert main(argv + ["--mode", "2"]) == 0
    assert png.stat().st_size > 10_000
    with Image.open(gif) as im:
        assert im.n_frames == 36
    assert main(["modes", "goland", "--animate", str(tmp_path / "m.png")]) == 2
    assert main(["modes", "goland", "--mode", "99", "--plot", str(png)]) == 2


def test_simulation_results_still_load(tmp_path):
    """The simulation format goes through the same reader (its own checks)."""
    bad = tmp_path / "sim.npz"
    meta = {"format": "aeroservo-simulation-1", "units": {}, "speed": 1.0, "density": 1.0}
    np.savez(bad, t=np.arange(3.0), meta=np.array(json.dumps(meta)), **{"outputs.y": np.ones(2)})
    with pytest.raises(aes.InputError, match="does not match the 3 times"):
        aes.load_result(bad)
    with zipfile.ZipFile(tmp_path / "empty.npz", "w"):
        pass
    with pytest.raises(aes.InputError, match="no JSON header"):
        aes.load_result(tmp_path / "empty.npz")
    with pytest.raises(aes.InputError, match="result = object: not an aeroservo result"):
        aes.save_result(object(), tmp_path / "x.npz")


def test_crossing_dataclass_round_trip_is_exact():
    c = Crossing(137.1, 11.0, 1, "onset")
    assert Crossing(float(c.speed), float(c.frequency), int(c.mode), str(c.kind)) == c


def test_envelope_saved_and_redrawn(tmp_path, capsys):
    saved, png = tmp_path / "env.json", tmp_path / "env.png"
    argv = ["envelope", "goland", "--altitudes", "0:4000:2000", "--vd", "110", "--save", str(saved)]
    assert main(argv) == 0
    env = aes.load_result(saved)
    data = json.loads(saved.read_text())
    assert [p.flutter_speed for p in env.points] == [p["flutter_speed"] for p in data["points"]]
    assert env.vd == 110.0 and env.margin_ok == data["margin_ok"]
    assert main(["plot", str(saved), "--out", str(png)]) == 0 and png.stat().st_size > 10_000
    assert main(["plot", str(saved), "--kind", "modes", "--out", str(png)]) == 2
    assert "is a flutter envelope" in capsys.readouterr().err


@pytest.mark.slow
def test_flutter_mode_animation_from_a_saved_sweep(sweep, tmp_path, capsys):
    from PIL import Image

    gif = tmp_path / "flutter.gif"
    assert main(["plot", str(sweep[2]), "--kind", "flutter-mode", "--out", str(gif)]) == 0
    with Image.open(gif) as im:
        assert im.n_frames == 36
    assert main(["plot", str(sweep[2]), "--kind", "vg", "--out", str(tmp_path / "v.gif")]) == 2
    assert "a .gif animates" in capsys.readouterr().err
