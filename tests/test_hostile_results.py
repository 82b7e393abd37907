"""Hostile inputs on re-plotting saved results and on brought linear controllers (issue 40,
item 2).

The rule, checked for every case of the corpus below through the command line, run in-process
(``aeroservo.cli.main``), and through the Python API:

* exit code 2 and exactly one line on stderr, naming the damaged file (and the key or array
  where there is one), no ``Traceback`` and no "internal error";
* nothing written or overwritten: the folder of the inputs is as it was (names, sizes and
  modification times), no output folder is made;
* the API (:func:`aeroservo.load_result`, :func:`aeroservo.files.load_controller`) raises an
  :class:`~aeroservo.errors.InputError` naming the file;
* bounded memory: an archive whose directory or arrays claim more than the limits is refused
  before anything is inflated (measured with :mod:`tracemalloc` on a genuine member of zeros
  compressed a thousand times), and a JSON text whose objects would not fit is refused before
  it is parsed.

The good results are small real runs (an open-loop gust-loads study at one flight point, a
shortened Conner limit-cycle study, a flutter sweep of a 4-element Goland wing) and a
simulation written by hand in its documented format; the corpus damages copies of them.
A brought compensator in a trade study (which the scenario loader refused against the docs) is
checked against the numbers ``docs/controllers.md`` gives for it.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
import shutil
import struct
import tracemalloc
import zipfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

import aeroservo as aes
from aeroservo.cli import main
from aeroservo.errors import InputError
from aeroservo.files import linear_controller, user_files
from aeroservo.files.controller_file import load_controller

GUST, LCO, FLUTTER, SIM = "gust/gust.json", "lco/sec.json", "flutter/sweep.npz", "sim/sim.npz"
LCO_NPZ = "lco/sec_histories.npz"


def _run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def _state(folder: Path) -> dict:
    """Every file under ``folder`` with its size and modification time."""
    return {
        str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns)
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


# -- the good inputs ---------------------------------------------------------------------------


def _simulation(path: Path) -> None:
    """A simulation result in its format (``aeroservo-simulation-1``), written by hand."""
    t = np.linspace(0.0, 1.0, 201)
    meta = {
        "units": {"tip_disp": "m", "aileron_hinge_moment": "N m"},
        "speed": 150.0,
        "density": 1.225,
        "limits": {"magnitude": {"aileron_hinge_moment": 2000.0}, "rate": {}},
        "summary": {},
        "format": "aeroservo-simulation-1",
    }
    np.savez_compressed(
        path,
        t=t,
        **{
            "outputs.tip_disp": 0.01 * np.sin(20 * t),
            "commands.aileron_hinge_moment": 100 * np.cos(20 * t),
            "applied.aileron_hinge_moment": 100 * np.cos(20 * t),
            "meta": np.array(json.dumps(meta)),
        },
    )


@pytest.fixture(scope="module")
def goods(tmp_path_factory) -> Path:
    """A folder of small good results: gust loads, limit cycles, a flutter sweep, a simulation
    and a brought compensator (``.npz``, ``.mat``) with its controller and scenario files."""
    from scipy.io import savemat

    from aeroservo.files.scenario_file import load_scenario
    from aeroservo.studies.gust.run import run_gust_loads
    from aeroservo.studies.gust.study import FlightPoint, GustLoadsStudy

    d = tmp_path_factory.mktemp("goods")
    for sub in ("gust", "flutter", "sim", "ctrl"):
        (d / sub).mkdir()
    wing = load_scenario(ROOT / "scenarios" / "goland_aileron_lqr.toml").wing
    study = GustLoadsStudy(
        {"nominal": wing},
        (FlightPoint(0.0, 100.0, "V_C", "nominal"),),
        ("root_shear", "root_bending_moment", "root_torque"),
        n_gradients=3,
        elements=4,
        name="gust",
    )
    aes.save_result(run_gust_loads(study), d / GUST)
    lco = (
        (ROOT / "scenarios" / "conner_freeplay_lco.toml")
        .read_text()
        .replace("speeds = { start = 4.0, stop = 26.0, num = 23 }", "speeds = [14.0]")
        .replace("amplitudes = [0.0185, 0.0740, 0.2220]", "amplitudes = [0.0740]")
        .replace("duration = 30.0 ", "duration = 1.0 ")
        .replace("history = 2.0 ", "history = 0.5 ")
        .replace('result = "conner_freeplay_lco"', 'result = "sec"')
    )
    (d / "sec.toml").write_text(lco)
    code, _out, err = _run(["lco", str(d / "sec.toml"), "--out", str(d / "lco")])
    assert code == 0, err
    for png in (d / "lco").glob("*.png"):
        png.unlink()
    model = aes.AeroelasticModel(aes.examples.goland_aileron(), n_elements=4)
    aes.save_result(aes.flutter_boundary(model, 1.225), d / FLUTTER, model=model)
    _simulation(d / SIM)
    # the shipped compensator (72 states), as .npz and as MATLAB .mat
    with np.load(ROOT / "controllers" / "linear_lqg.npz") as z:
        k = {name: z[name] for name in z.files}
    np.savez(d / "ctrl" / "k.npz", **k)
    savemat(
        d / "ctrl" / "k.mat",
        {
            **{m: k[m] for m in "ABCD"},
            "Ts": float(k["dt"]),
            "InputName": np.array(list(k["inputs"]), dtype=object),
            "OutputName": np.array(list(k["outputs"]), dtype=object),
        },
    )
    scenario = (ROOT / "scenarios" / "goland_aileron_lqr.toml").read_text()
    scenario = scenario.replace('file = "goland_aileron.toml"', 'file = "wing.toml"')
    scenario = re.sub(r'spec = "[^"]*"', 'spec = "c.toml"', scenario)
    shutil.copy(ROOT / "scenarios" / "goland_aileron.toml", d / "ctrl" / "wing.toml")
    for suffix in ("npz", "mat"):
        (d / "ctrl" / f"{suffix}.toml").write_text(scenario.replace("c.toml", f"c_{suffix}.toml"))
        (d / "ctrl" / f"c_{suffix}.toml").write_text(
            f'type = "linear"\nname = "brought"\nfile = "k.{suffix}"\nsign = 1\n'
        )
    return d


# -- ways of damaging a file -------------------------------------------------------------------


def edit_json(rel: str, change: Callable[[dict], object]) -> Callable[[Path], None]:
    def do(folder: Path) -> None:
        path = folder / rel
        doc = json.loads(path.read_text())
        change(doc)
        path.write_text(json.dumps(doc, indent=1))

    return do


def edit_text(rel: str, change: Callable[[str], str]) -> Callable[[Path], None]:
    def do(folder: Path) -> None:
        path = folder / rel
        path.write_text(change(path.read_text()))

    return do


def put_bytes(rel: str, data: bytes | Callable[[bytes], bytes]) -> Callable[[Path], None]:
    def do(folder: Path) -> None:
        path = folder / rel
        path.write_bytes(data(path.read_bytes()) if callable(data) else data)

    return do


def edit_npz(rel: str, change: Callable[[dict], object]) -> Callable[[Path], None]:
    def do(folder: Path) -> None:
        path = folder / rel
        with np.load(path) as z:
            arrays = {k: z[k] for k in z.files}
        change(arrays)
        with open(path, "wb") as fh:
            np.savez_compressed(fh, **arrays)

    return do


def remove(rel: str) -> Callable[[Path], None]:
    return lambda folder: (folder / rel).unlink()


def _npy(array: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, array)
    return buf.getvalue()


def _zip_lying(path: Path, lie: str, claimed: int = 0xFFFF_0000) -> None:
    """Rewrite the archive ``path`` so that the directory entry of its member ``lie`` claims
    ``claimed`` bytes inflated (its data left as it was)."""
    raw = bytearray(path.read_bytes())
    name = (lie + ".npy").encode()
    at = raw.find(b"PK\x01\x02" + b"")  # first central-directory entry
    while at >= 0:
        n = struct.unpack("<H", raw[at + 28 : at + 30])[0]
        if raw[at + 46 : at + 46 + n] == name:
            raw[at + 24 : at + 28] = struct.pack("<I", claimed)
            path.write_bytes(bytes(raw))
            return
        at = raw.find(b"PK\x01\x02", at + 4)
    raise AssertionError(f"no member {lie} in {path}")


def lying_member(rel: str, member: str) -> Callable[[Path], None]:
    """The directory claims some 4 GiB for ``member`` (its data is small)."""
    return lambda folder: _zip_lying(folder / rel, member)


def added_member(rel: str, name: str, data: bytes, compress: int) -> Callable[[Path], None]:
    def do(folder: Path) -> None:
        with zipfile.ZipFile(folder / rel, "a", compression=compress) as zf:
            zf.writestr(name + ".npy", data)

    return do


def header_lie(rel: str, member: str) -> Callable[[Path], None]:
    """``member``'s ``.npy`` header claims 10^12 numbers (its data is 16 bytes)."""

    def do(folder: Path) -> None:
        buf = io.BytesIO()
        np.lib.format.write_array_header_1_0(
            buf, {"descr": "<f8", "fortran_order": False, "shape": (10**12,)}
        )
        _replace_member(folder / rel, member, buf.getvalue() + bytes(16))

    return do


def _replace_member(path: Path, member: str, data: bytes) -> None:
    with zipfile.ZipFile(path) as zf:
        items = {i.filename: zf.read(i) for i in zf.infolist()}
    items[member + ".npy"] = data
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, value in items.items():
            zf.writestr(name, value)


def pickled(rel: str, member: str) -> Callable[[Path], None]:
    """``member`` replaced by an array of Python objects (pickled)."""

    def do(folder: Path) -> None:
        buf = io.BytesIO()
        np.save(buf, np.array([{"x": 1}], dtype=object), allow_pickle=True)
        _replace_member(folder / rel, member, buf.getvalue())

    return do


def _first_history(doc: dict) -> str:
    return doc["records"][0]["histories"]["root_shear"]["max"]


def gust_array(end: str, change: Callable[[np.ndarray], np.ndarray]):
    """Change the array ``<key><end>`` of the gust result's first critical gust."""

    def do(folder: Path) -> None:
        key = _first_history(json.loads((folder / GUST).read_text())) + end
        edit_npz("gust/gust.npz", lambda a: a.__setitem__(key, change(a[key])))(folder)

    return do


def record(change: Callable[[dict], object]):
    return edit_json(GUST, lambda d: change(d["records"][0]))


def load_entry(change: Callable[[dict], object], load: str = "root_shear"):
    return record(lambda r: change(r["loads"][load]))


def lco_row(change: Callable[[dict], object]):
    return edit_json(LCO, lambda d: change(d["rows"][0]))


def sim_meta(change: Callable[[dict], object]):
    def edit(a: dict) -> None:
        meta = json.loads(str(a["meta"]))
        change(meta)
        a["meta"] = np.array(json.dumps(meta))

    return edit_npz(SIM, edit)


# -- the corpus --------------------------------------------------------------------------------


@dataclass
class Case:
    """A damaged input: ``target`` (relative to the copied goods) is what the command and the
    API are given; ``named`` the text the one line must hold (the damaged file's name, and the
    key or array); ``patch`` lowers a module's limit (``(module, name, value)``); ``loads``:
    the file is valid, only its figures cannot be drawn (the API reads it, ``plot`` refuses)."""

    id: str
    target: str
    damage: Callable[[Path], None]
    named: tuple[str, ...]
    patch: tuple = ()
    command: tuple = ("plot",)
    loads: bool = False


def _deep(n: int) -> str:
    return "[" * n + "]" * n


CASES = [
    # gust-loads JSON
    Case("gust-json-truncated", GUST, put_bytes(GUST, lambda b: b[:200]), ("gust.json", "not JSON")),
    Case("gust-json-not-utf8", GUST,
         put_bytes(GUST, lambda b: b.replace(b'"scenario"', b'"sc\xffenario"')),
         ("gust.json", "UTF-8")),
    Case("gust-json-top-list", GUST,
         put_bytes(GUST, b'[{"format": "aeroservo-gust-loads-2"}]'), ("gust.json", "format")),
    Case("gust-json-deep", GUST,
         edit_text(GUST, lambda t: t.replace('"notes": []', '"notes": ' + _deep(100_000), 1)),
         ("gust.json", "not JSON")),
    Case("gust-records-table", GUST, edit_json(GUST, lambda d: d.update(records={})),
         ("gust.json", "records = {}")),
    Case("gust-records-empty", GUST, edit_json(GUST, lambda d: d.update(records=[])),
         ("gust.json", "no loads (no flight point was computed"), loads=True),
    Case("gust-histories-number", GUST, record(lambda r: r.update(histories=5)),
         ("gust.json", "records[0].histories = 5")),
    Case("gust-load-text", GUST, record(lambda r: r["loads"].update(root_shear="x")),
         ("gust.json", "records[0].loads.root_shear = 'x'")),
    Case("gust-load-no-max", GUST, load_entry(lambda v: v.pop("max")),
         ("gust.json", "records[0].loads.root_shear.max")),
    Case("gust-load-sign-2", GUST, load_entry(lambda v: v.update(max_sign=2)),
         ("gust.json", "max_sign = 2")),
    Case("gust-point-text", GUST, record(lambda r: r.update(point="zero")),
         ("gust.json", "records[0].point = 'zero'")),
    Case("gust-loop-unknown", GUST, record(lambda r: r.update(loop="sideways")),
         ("gust.json", "records[0].loop = 'sideways'")),
    Case("gust-gradients-empty", GUST, record(lambda r: r.update(gradients=[])),
         ("gust.json", "records[0].gradients = []")),
    Case("gust-amplitudes-text", GUST, record(lambda r: r.update(amplitudes="x")),
         ("gust.json", "records[0].amplitudes = 'x'")),
    Case("gust-tuning-short", GUST,
         record(lambda r: r["tuning"]["root_torque"].update(up_max=[1.0])),
         ("gust.json", "records[0].tuning.root_torque.up_max = [1.0]")),
    Case("gust-covariance-ragged", GUST,
         record(lambda r: r["covariance"].update(matrix=[[1.0]])),
         ("gust.json", "records[0].covariance.matrix")),
    Case("gust-time-at-limit-text", GUST,
         record(lambda r: r.update(time_at_limit={"aileron": "long"})),
         ("gust.json", "records[0].time_at_limit.aileron = 'long'")),
    Case("gust-notes-number", GUST, record(lambda r: r.update(notes=3)),
         ("gust.json", "records[0].notes = 3")),
    Case("gust-correlated-missing", GUST,
         load_entry(lambda v: v.update(min_correlated={}), "root_torque"),
         ("gust.json", "records[0].loads.root_torque.min_correlated = []")),
    Case("gust-record-twice", GUST,
         edit_json(GUST, lambda d: d["records"].append(d["records"][0])),
         ("gust.json", "records[1]", "each once")),
    Case("gust-history-loads-short", GUST, record(lambda r: r.update(history_loads=["x"])),
         ("gust.json", "records[0].history_loads = ['x']")),
    Case("gust-altitude-nan", GUST, record(lambda r: r.update(altitude=float("nan"))),
         ("gust.json", "records[0].altitude = nan")),
    Case("gust-eas-huge", GUST,
         edit_text(GUST, lambda t: re.sub(r'"eas": [^,]*,', '"eas": 1e999,', t, count=1)),
         ("gust.json", "records[0].eas = inf")),
    Case("gust-trim-text", GUST, record(lambda r: r.update(trim={"alpha_rad": "x"})),
         ("gust.json", "records[0].trim.alpha_rad = 'x'")),
    Case("gust-skipped-points", GUST,
         edit_json(GUST, lambda d: d["settings"].update(skipped_points=3)),
         ("gust.json", "settings.skipped_points = 3")),
    Case("gust-limits-text", GUST,
         edit_json(GUST, lambda d: d["settings"].update(limits={"magnitude": "x"})),
         ("gust.json", "settings.limits.magnitude = 'x'")),
    Case("gust-units-list", GUST, edit_json(GUST, lambda d: d.update(units=[])),
         ("gust.json", "units = []")),
    Case("gust-name-number", GUST, edit_json(GUST, lambda d: d.update(name=5)),
         ("gust.json", "'name' = 5")),
    Case("gust-arrays-path", GUST, edit_json(GUST, lambda d: d.update(arrays="../gust.npz")),
         ("gust.json", "'arrays' = '../gust.npz'")),
    Case("gust-json-too-large", GUST, lambda f: None, ("gust.json", "larger than"),
         (user_files, "MAX_RESULT_JSON_BYTES", 4096)),
    Case("gust-json-many-lists", GUST,
         edit_json(GUST, lambda d: d["settings"].update(junk=[[]] * 40_000)),
         ("gust.json", "MiB of memory"), (user_files, "MAX_JSON_MEMORY", 4 * 2**20)),
    # gust-loads NPZ
    Case("gust-npz-missing", GUST, remove("gust/gust.npz"), ("gust.npz", "no such file")),
    Case("gust-npz-truncated", GUST, put_bytes("gust/gust.npz", lambda b: b[: len(b) // 2]),
         ("gust.npz",)),
    Case("gust-npz-empty", GUST, put_bytes("gust/gust.npz", b""), ("gust.npz",)),
    Case("gust-npz-text", GUST, put_bytes("gust/gust.npz", b"hello\n"), ("gust.npz",)),
    Case("gust-npz-directory-lie", GUST, lambda f: _zip_lying(
        f / "gust/gust.npz", _first_history(json.loads((f / GUST).read_text())) + "_y"),
         ("gust.npz", "inflate to", "MiB")),
    Case("gust-npz-header-lie", GUST, lambda f: header_lie(
        "gust/gust.npz", _first_history(json.loads((f / GUST).read_text())) + "_t")(f),
         ("gust.npz", "larger than its")),
    Case("gust-npz-pickled", GUST, lambda f: pickled(
        "gust/gust.npz", _first_history(json.loads((f / GUST).read_text())) + "_gust")(f),
         ("gust.npz", "Python objects")),
    Case("gust-npz-zeros", GUST, added_member(
        "gust/gust.npz", "zeros", _npy(np.zeros(4 * 2**20)), zipfile.ZIP_DEFLATED),
         ("gust.npz", "inflate to 32 MiB"), (user_files, "MAX_ARRAY_BYTES", 16 * 2**20)),
    Case("gust-npz-y-columns", GUST, gust_array("_y", lambda a: a[:, :1]),
         ("gust.npz", "_y (5195, 1)", "history_loads")),
    Case("gust-npz-t-2d", GUST, gust_array("_t", lambda a: a[:, None]),
         ("gust.npz", "_t'", "expected 1-D")),
    Case("gust-npz-text-array", GUST, gust_array("_gust", lambda a: a.astype(str)),
         ("gust.npz", "_gust'", "expected 1-D real")),
    # limit cycles
    Case("lco-speeds-empty", LCO, edit_json(LCO, lambda d: d["settings"].update(speeds=[])),
         ("sec.json", "settings.speeds = []")),
    Case("lco-rows-empty", LCO, edit_json(LCO, lambda d: d.update(rows=[])),
         ("sec.json", "'rows' is empty")),
    Case("lco-row-speed-text", LCO, lco_row(lambda r: r.update(speed="fast")),
         ("sec.json", "rows[0].speed = 'fast'")),
    Case("lco-reference-number", LCO,
         edit_json(LCO, lambda d: d["settings"].update(reference=5)),
         ("sec.json", "settings.reference = 5")),
    Case("lco-branches-table", LCO,
         edit_json(LCO, lambda d: d["branches"].update(table=[{"x": 1}])), ("sec.json",)),
    Case("lco-json-truncated", LCO, put_bytes(LCO, lambda b: b[:100]), ("sec.json", "not JSON")),
    Case("lco-arrays-path", LCO, edit_json(LCO, lambda d: d.update(arrays="/etc/x.npz")),
         ("sec.json", "'arrays' = '/etc/x.npz'")),
    Case("lco-npz-truncated", LCO, put_bytes(LCO_NPZ, lambda b: b[:-30]),
         ("sec_histories.npz",)),
    Case("lco-npz-directory-lie", LCO, lying_member(LCO_NPZ, "row0/t"),
         ("sec_histories.npz", "inflate to")),
    Case("lco-npz-2d", LCO, edit_npz(LCO_NPZ, lambda a: a.update({"row0/t": a["row0/t"][:, None]})),
         ("sec_histories.npz", "row0/t")),
    # flutter sweeps
    Case("flutter-truncated", FLUTTER, put_bytes(FLUTTER, lambda b: b[: len(b) // 3]),
         ("sweep.npz",)),
    Case("flutter-empty", FLUTTER, put_bytes(FLUTTER, b""), ("sweep.npz", "not a .npz")),
    Case("flutter-json-text", FLUTTER, put_bytes(FLUTTER, b'{"format": 1}'),
         ("sweep.npz", "a JSON summary?")),
    Case("flutter-directory-lie", FLUTTER, lying_member(FLUTTER, "eigenvalues"),
         ("sweep.npz", "'eigenvalues'", "inflate to")),
    Case("flutter-header-lie", FLUTTER, header_lie(FLUTTER, "speeds"),
         ("sweep.npz", "'speeds'", "larger than its")),
    Case("flutter-pickled", FLUTTER, pickled(FLUTTER, "speeds"), ("sweep.npz", "Python objects")),
    Case("flutter-meta-not-json", FLUTTER,
         edit_npz(FLUTTER, lambda a: a.update(meta=np.array("{no"))), ("sweep.npz", "header")),
    Case("flutter-meta-deep", FLUTTER,
         edit_npz(FLUTTER, lambda a: a.update(meta=np.array(_deep(100_000)))),
         ("sweep.npz", "header")),
    Case("flutter-eigenvalues-shape", FLUTTER,
         edit_npz(FLUTTER, lambda a: a.update(eigenvalues=a["eigenvalues"][:3])),
         ("sweep.npz", "eigenvalues")),
    Case("flutter-modes-shape", FLUTTER,
         edit_npz(FLUTTER, lambda a: a.update({"modes.w": a["modes.w"][:2]})),
         ("sweep.npz", "modes.w")),
    # simulations
    Case("sim-t-2d", SIM, edit_npz(SIM, lambda a: a.update(t=a["t"][:, None])),
         ("sim.npz", "'t'")),
    Case("sim-signal-short", SIM,
         edit_npz(SIM, lambda a: a.update({"outputs.tip_disp": a["outputs.tip_disp"][:5]})),
         ("sim.npz", "outputs.tip_disp")),
    Case("sim-limits-text", SIM, sim_meta(lambda m: m.update(limits="none")),
         ("sim.npz", "header")),
    Case("sim-format-unknown", SIM, sim_meta(lambda m: m.update(format="x-1")),
         ("sim.npz", "format 'x-1'")),
    # brought linear controllers, through a simulation scenario and load_controller
    Case("ctrl-npz-truncated", "ctrl/npz.toml", put_bytes("ctrl/k.npz", lambda b: b[:-40]),
         ("k.npz",), command=("simulate",)),
    Case("ctrl-npz-empty", "ctrl/npz.toml", put_bytes("ctrl/k.npz", b""),
         ("k.npz", "empty"), command=("simulate",)),
    Case("ctrl-npz-text", "ctrl/npz.toml", put_bytes("ctrl/k.npz", b"A = [1]\n"),
         ("k.npz", "not a .npz"), command=("simulate",)),
    Case("ctrl-npz-pickled", "ctrl/npz.toml", pickled("ctrl/k.npz", "A"),
         ("k.npz", "Python objects"), command=("simulate",)),
    Case("ctrl-npz-directory-lie", "ctrl/npz.toml", lying_member("ctrl/k.npz", "A"),
         ("k.npz", "'A'", "inflate to"), command=("simulate",)),
    Case("ctrl-npz-inputs-twice", "ctrl/npz.toml",
         edit_npz("ctrl/k.npz", lambda a: a.update(inputs=np.array(["tip_twist"] * 3))),
         ("k.npz", "inputs", "'tip_twist' named more than once"), command=("simulate",)),
    Case("ctrl-npz-too-many-states", "ctrl/npz.toml", lambda f: None,
         ("k.npz", "variable A is 72x72", "at most 50 states"),
         (linear_controller, "MAX_STATES", 50), command=("simulate",)),
    Case("ctrl-mat-text", "ctrl/mat.toml", put_bytes("ctrl/k.mat", b"A = [1 2; 3 4]\n" * 20),
         ("k.mat", "-v7"), command=("simulate",)),
    Case("ctrl-mat-octave-text", "ctrl/mat.toml", put_bytes(
        "ctrl/k.mat", b"# Created by Octave 8.4.0\n# name: A\n# type: matrix\n# rows: 1\n"
        b"# columns: 1\n 1\n" * 5), ("k.mat", "Octave", "-v7"), command=("simulate",)),
    Case("ctrl-mat-v73", "ctrl/mat.toml",
         put_bytes("ctrl/k.mat", b"MATLAB 7.3 MAT-file, Platform: GLNXA64".ljust(512, b"\0")),
         ("k.mat", "v7.3", "-v7"), command=("simulate",)),
    Case("ctrl-mat-truncated", "ctrl/mat.toml", put_bytes("ctrl/k.mat", lambda b: b[:300]),
         ("k.mat",), command=("simulate",)),
    Case("ctrl-mat-inflating", "ctrl/mat.toml", lambda f: _mat_zeros(f / "ctrl/k.mat"),
         ("k.mat", "variable A inflates"), (linear_controller, "MAX_BYTES", 2**20),
         command=("simulate",)),
    Case("ctrl-mat-too-many-states", "ctrl/mat.toml", lambda f: None,
         ("k.mat", "variable A is 72x72"), (linear_controller, "MAX_STATES", 50),
         command=("simulate",)),
    Case("ctrl-mat-outputs-twice", "ctrl/mat.toml", lambda f: _mat_two_outputs(f / "ctrl/k.mat"),
         ("k.mat", "OutputName", "named more than once"), command=("simulate",)),
]  # fmt: skip


def _mat_zeros(path: Path) -> None:
    """``A`` a 400 x 400 matrix of zeros (1.3 MB inflated, some kB in the file)."""
    from scipy.io import loadmat, savemat

    data = {k: v for k, v in loadmat(path).items() if not k.startswith("__")}
    data["A"] = np.zeros((400, 400))
    savemat(path, data, do_compression=True)


def _mat_two_outputs(path: Path) -> None:
    from scipy.io import loadmat, savemat

    data = {k: v for k, v in loadmat(path).items() if not k.startswith("__")}
    data["C"] = np.vstack([data["C"], data["C"]])
    data["D"] = np.vstack([data["D"], data["D"]])
    data["OutputName"] = np.array(["aileron_hinge_moment"] * 2, dtype=object)
    savemat(path, data)


@pytest.fixture
def case_folder(goods, tmp_path) -> Path:
    folder = tmp_path / "in"
    shutil.copytree(goods, folder)
    return folder


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_hostile_input_is_one_line_naming_the_file(case, case_folder, tmp_path, monkeypatch):
    if case.patch:
        monkeypatch.setattr(*case.patch)
    case.damage(case_folder)
    target = case_folder / case.target
    before = _state(tmp_path)
    out = tmp_path / "out"
    argv = [*case.command, str(target)] + (
        ["--out", str(out)] if "plot" not in case.command else []
    )
    code, _stdout, err = _run(argv)
    lines = err.splitlines()
    assert code == 2 and len(lines) == 1, err
    assert "Traceback" not in err and "internal error" not in err, err
    for text in case.named:
        assert text in lines[0], (text, lines[0])
    assert _state(tmp_path) == before and not out.exists()  # nothing written, nothing left
    with pytest.raises(InputError) as exc:
        if case.target.startswith("ctrl/"):
            load_controller(target.parent / f"c_{target.stem}.toml")
        elif case.loads:
            aes.load_result(target).plot()
        else:
            aes.load_result(target)
    assert "\n" not in str(exc.value)
    assert case.named[0] in str(exc.value) or case.loads
    assert _state(tmp_path) == before


@pytest.mark.parametrize("target", [GUST, LCO, FLUTTER, SIM])
def test_the_good_results_redraw(goods, tmp_path, target):
    """The corpus damages these: as written they load and redraw (every figure kind)."""
    folder = tmp_path / "in"
    shutil.copytree(goods, folder)
    code, out, err = _run(["plot", str(folder / target)])
    assert code == 0 and not err, err
    assert "plot written to" in out
    assert aes.load_result(folder / target).figure_kinds


def test_open_loop_gust_loads_redraw_every_figure_kind(goods, tmp_path):
    """Issue 40: an open-loop gust-loads result drew no figure ('gust load alleviation needs
    both loops'); each kind it has redraws, the one it has not is one line naming the file."""
    folder = tmp_path / "in"
    shutil.copytree(goods, folder)
    res = aes.load_result(folder / GUST)
    assert res.loops == ["open"]
    for kind in res.figure_kinds:
        code, _out, err = _run(
            ["plot", str(folder / GUST), "--kind", kind, "--out", str(tmp_path / f"{kind}.png")]
        )
        assert code == 0, err
    code, _out, err = _run(["plot", str(folder / GUST), "--kind", "spanwise"])
    assert code == 2 and "gust.json" in err and len(err.splitlines()) == 1


def test_null_numbers_read_back_as_nan(goods, tmp_path):
    """JSON has no NaN: aeroservo writes a number that is not finite as null, and a result
    with such numbers (a turbulence load, a correlated load) reads back and redraws."""
    folder = tmp_path / "in"
    shutil.copytree(goods, folder)

    def nulls(r: dict) -> None:
        r["loads"]["root_torque"]["turbulence"] = None
        r["loads"]["root_shear"]["max_correlated"]["root_torque"] = None

    record(nulls)(folder)
    res = aes.load_result(folder / GUST)
    assert np.isnan(res.records[0]["loads"]["root_torque"]["turbulence"])
    code, _out, err = _run(["plot", str(folder / GUST)])
    assert code == 0, err


def _peak_bytes(fn) -> int:
    tracemalloc.start()
    try:
        with contextlib.suppress(InputError):
            fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_inflating_member_refused_before_it_is_inflated(goods, tmp_path, monkeypatch):
    """A genuine member of 64 MiB of zeros (some 64 kB compressed) against a limit of 16 MiB:
    refused, and the reading never holds more than a few MiB."""
    monkeypatch.setattr(user_files, "MAX_ARRAY_BYTES", 16 * 2**20)
    folder = tmp_path / "in"
    shutil.copytree(goods, folder)
    added_member("gust/gust.npz", "zeros", _npy(np.zeros(8 * 2**20)), zipfile.ZIP_DEFLATED)(folder)
    assert (folder / "gust/gust.npz").stat().st_size < 2 * 2**20
    with pytest.raises(InputError, match="inflate to 64 MiB"):
        aes.load_result(folder / GUST)
    assert _peak_bytes(lambda: aes.load_result(folder / GUST)) < 4 * 2**20
    assert _peak_bytes(lambda: aes.load_result(folder / LCO)) < 16 * 2**20  # a good one reads


def test_huge_json_refused_before_it_is_parsed(goods, tmp_path):
    """A JSON text of small lists that would take some 40 times its size as objects: refused
    by the estimate (no limit lowered), in a fraction of the memory parsing would take."""
    folder = tmp_path / "in"
    shutil.copytree(goods, folder)
    n = user_files.MAX_JSON_MEMORY // 150  # lists of three bytes, 164 bytes each estimated
    text = (folder / GUST).read_text().replace('"notes": []', '"notes": [' + "[]," * n + "[]]", 1)
    (folder / GUST).write_text(text)
    size = (folder / GUST).stat().st_size
    assert size < user_files.MAX_RESULT_JSON_BYTES
    with pytest.raises(InputError, match="MiB of memory"):
        aes.load_result(folder / GUST)
    assert _peak_bytes(lambda: aes.load_result(folder / GUST)) < 3 * size


def test_unused_members_are_neither_read_nor_counted(goods, tmp_path):
    """A compensator file with another variable claiming 3 GiB (an .npz member) or inflating
    to 64 MiB (a compressed .mat variable): the compensator reads, in little memory."""
    from scipy.io import loadmat, savemat

    folder = tmp_path / "in"
    shutil.copytree(goods, folder)
    npz = folder / "ctrl" / "k.npz"
    added_member("ctrl/k.npz", "junk", _npy(np.zeros(1000)), zipfile.ZIP_DEFLATED)(folder)
    _zip_lying(npz, "junk", 3 * 2**30)
    k = linear_controller.read_linear_controller(npz)
    assert k["A"].shape == (72, 72)
    mat = folder / "ctrl" / "k.mat"
    data = {k: v for k, v in loadmat(mat).items() if not k.startswith("__")}
    savemat(mat, {**data, "junk": np.zeros((2048, 4096))}, do_compression=True)
    assert mat.stat().st_size < 2**20
    peak = _peak_bytes(lambda: linear_controller.read_linear_controller(mat))
    assert peak < 8 * 2**20
    assert linear_controller.read_linear_controller(mat)["inputs"] == k["inputs"]


def test_trade_study_takes_a_brought_compensator(tmp_path):
    """docs/scenarios.md: a trade's controller may be any type with a linear law, a brought
    compensator (``linear``) too; the scenario loader refused it. The compensator is fixed, the
    same in every case: on the loop it was designed for (the LQG scenario's sensors, filters,
    servo and delay) at the design wing, the case gives what docs/controllers.md gives for it
    (+6.06 / -6.92 dB, 59.5 deg at 1.1 V_f, stable from 85 to 186 m/s)."""
    from aeroservo.files.scenario_file import load_scenario
    from aeroservo.studies.trade.cases import evaluate_case
    from aeroservo.studies.trade.scenario import study_from_scenario

    lqg = (ROOT / "scenarios" / "goland_aileron_lqg.toml").read_text()
    signals = lqg[lqg.index("[model]") : lqg.index("[disturbance]")]
    signals = signals.replace('"root_bending_moment"]', '"root_bending_moment", "tip_accel"]')
    text = f"""[scenario]
name = "a brought compensator over aileron spans"
kind = "trade"
[wing]
file = "{ROOT / "scenarios" / "goland_aileron.toml"}"
[flight]
density = 1.225
{signals}
[simulation]
sample_rate = 1000.0
[trade]
controller = "{ROOT / "controllers" / "linear.toml"}"
speed_factor = 1.1
[trade.parameters]
aileron_start = [0.6, 0.7]
"""
    (tmp_path / "t.toml").write_text(text)
    study = study_from_scenario(load_scenario(tmp_path / "t.toml"))
    assert study.controller.type == "linear"
    case = evaluate_case(study, {"aileron_start": 0.6})
    assert case["status"] == "ok", case
    assert case["gain_margin_db"] == pytest.approx(6.06, abs=0.01)
    assert case["gain_reduction_margin_db"] == pytest.approx(-6.92, abs=0.01)
    assert case["phase_margin_deg"] == pytest.approx(59.5, abs=0.1)
    assert case["closed_loop_lower_speed"] == pytest.approx(85.2, abs=0.5)
    assert case["closed_loop_flutter_speed"] == pytest.approx(185.6, abs=0.5)
    bryson = text.replace("aileron_start = [0.6, 0.7]", "bryson_hinge_moment = [250.0, 500.0]")
    (tmp_path / "b.toml").write_text(bryson)
    with pytest.raises(InputError, match="bryson_hinge_moment"):
        study_from_scenario(load_scenario(tmp_path / "b.toml"))


def test_trade_refuses_a_law_without_a_linear_loop(tmp_path):
    """A Python law has no closed-loop boundary: one line saying which types a trade takes."""
    (tmp_path / "law.py").write_text("def law(t, y):\n    return [0.0]\n")
    (tmp_path / "c.toml").write_text(
        'type = "python"\nname = "p"\nfile = "law.py"\nfunction = "law"\n'
    )
    text = (ROOT / "scenarios" / "trade_aileron.toml").read_text()
    text = text.replace(
        'file = "goland_aileron.toml"', f'file = "{ROOT}/scenarios/goland_aileron.toml"'
    )
    text = text.replace('controller = "../controllers/lqr.toml"', 'controller = "c.toml"')
    text = re.sub(r"bryson_hinge_moment = .*\n", "", text)
    (tmp_path / "t.toml").write_text(text)
    code, _out, err = _run(["trade", str(tmp_path / "t.toml"), "--out", str(tmp_path / "o")])
    assert code == 2 and len(err.splitlines()) == 1, err
    assert "t.toml" in err and "'linear'" in err and "this one is 'python'" in err
    assert not (tmp_path / "o").exists()
