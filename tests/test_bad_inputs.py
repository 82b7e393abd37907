"""Hostile and malformed inputs on the command line: one clear line, exit 2, nothing written.

Each case of ``CASES`` runs ``aeroservo`` in process on files written for it (wing files that
are not UTF-8 TOML, numbers at the edge of floating point, sizes with no bound, damaged or
foreign result files, output names the file system refuses, options out of range). The run
must exit with the expected code and print exactly one line to stderr that contains the
expected fragments (the file, the key and the value), with no traceback, no "internal error",
and no file left behind. The Python API has its own corpus (``test_api_inputs.py``); scenario
and controller files theirs (``test_scenario_files.py``, ``tests/data/malformed/``).

Also here: byte-order marks are read, not refused; the one reader refuses pipes and devices;
a run that fails while writing leaves no file; outputs follow the umask; hypothesis fuzzing
of the wing-file loader and of the number checks.
"""

from __future__ import annotations

import io
import json
import os
import re
import stat
import warnings
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from aeroservo.cli import main
from aeroservo.errors import RANGES, InputError, check_quantity
from aeroservo.files import load_wing
from aeroservo.files.user_files import read_text

GOLAND = (ROOT / "scenarios" / "goland.toml").read_text()
AILERON = (ROOT / "scenarios" / "goland_aileron.toml").read_text()
SCENARIO = (ROOT / "scenarios" / "goland_aileron_lqr.toml").read_text()
TRADE = "aeroservo-trade/2"  # the trade study's manifest format
PNG = b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 4


def sub(text: str, key: str, value: str, count: int = 1) -> str:
    """``text`` with the first ``count`` assignments of ``key`` set to ``value``."""
    out, n = re.subn(rf"(?m)^{re.escape(key)} = [^\n#]*", f"{key} = {value}", text, count=count)
    assert n, key
    return out


def analysis(text: str, line: str) -> str:
    """A wing file with ``key = value`` set in its [analysis] table."""
    key, value = (s.strip() for s in line.split("=", 1))
    if re.search(rf"(?m)^{re.escape(key)} = ", text):
        return sub(text, key, value)
    return text.replace("[analysis]\n", f"[analysis]\n{line}\n", 1)


def npz(**arrays) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def case(id_, argv, files=None, fragments=(), rc=2):
    return pytest.param(argv, files or {}, rc, fragments, id=id_)


W = "w.toml"
A = "a.toml"
FLUTTER = ["flutter", W]
AIL = ["flutter", A]

# -- wing files that are not clean UTF-8 TOML ------------------------------------------------
FILES = [
    case(
        "utf8-invalid", FLUTTER, {W: b'[wing]\nname = "\xff"\n'}, ["w.toml", "not a UTF-8", "0xff"]
    ),
    case("binary", FLUTTER, {W: bytes(range(256))}, ["w.toml", "not a UTF-8"]),
    case("png-as-toml", FLUTTER, {W: PNG}, ["w.toml", "a PNG image"]),
    case("png-as-png", ["flutter", "w.png"], {"w.png": PNG}, ["w.png", "a PNG image"]),
    case("pdf", FLUTTER, {W: b"%PDF-1.4\n%\xe2\xe3"}, ["w.toml", "a PDF document"]),
    case("zip", FLUTTER, {W: npz(x=np.zeros(2))}, ["w.toml", "zip archive"]),
    case("nul-bytes", FLUTTER, {W: GOLAND.replace("[analysis]", "\x00[analysis]")}, ["NUL"]),
    case("empty", FLUTTER, {W: ""}, ["w.toml", "wing: missing required key"]),
    case("bad-syntax", FLUTTER, {W: "[wing\nspan = 1"}, ["w.toml", "not valid TOML"]),
    case("bigint", FLUTTER, {W: analysis(GOLAND, "elements = " + "9" * 5000)}, ["4300 digits"]),
    case("int-64bit", FLUTTER, {W: analysis(GOLAND, "elements = " + "9" * 30)}, ["64-bit"]),
    case(
        "nested",
        FLUTTER,
        {W: analysis(GOLAND, "x = " + "[" * 1000 + "]" * 1000)},
        ["w.toml", "nested too deeply"],
    ),
    case("folder", ["flutter", "d.toml"], {"d.toml/x": "a"}, ["d.toml", "is a folder"]),
    case("dev-null", ["flutter", "/dev/null"], {}, ["/dev/null", "not a regular file"]),
    case("dev-zero", ["flutter", "/dev/zero"], {}, ["/dev/zero", "not a regular file"]),
    case("fifo", ["flutter", "pipe.toml"], {"pipe.toml": "FIFO"}, ["pipe.toml", "not a regular"]),
    case("huge", FLUTTER, {W: GOLAND + "#" * (17 * 2**20)}, ["w.toml", "larger than 16 MiB"]),
    case("missing", ["flutter", "nope.toml"], {}, ["nope.toml", "no such file"]),
    case("not-builtin", ["flutter", "nope"], {}, ["'nope'", "not a built-in wing"]),
    case(
        "name-too-long", ["flutter", "x" * 300 + ".toml"], {}, ["cannot read the file", "too long"]
    ),
    case("scenario-binary", ["run", "s.toml"], {"s.toml": b"\x00\x01\xfe"}, ["s.toml", "UTF-8"]),
    case("scenario-fifo", ["run", "pipe.toml"], {"pipe.toml": "FIFO"}, ["not a regular file"]),
    case("scenario-png", ["run", "s.toml"], {"s.toml": PNG}, ["s.toml", "a PNG image"]),
]

# -- numbers at the edge of floating point, in every key of a wing file ------------------------
NUMBERS = []
for key in ("EI", "GJ", "mass", "inertia", "semichord"):
    for value, what in (("1e308", "allowed range"), ("1e-300", "allowed range"), ("nan", "finite")):
        NUMBERS.append(
            case(f"{key}-{value}", FLUTTER, {W: sub(GOLAND, key, value)}, [f"{key} = ", what])
        )
    NUMBERS.append(case(f"{key}-string", FLUTTER, {W: sub(GOLAND, key, '"1"')}, [f"{key} = '1'"]))
NUMBERS += [
    case(
        "span-1e308",
        FLUTTER,
        {W: sub(sub(GOLAND, "span", "1e308"), "end", "1e308")},
        ["end = 1e+308", "allowed range"],
    ),
    case(
        "span-1e-300",
        FLUTTER,
        {W: sub(sub(GOLAND, "span", "1e-300"), "end", "1e-300")},
        ["= 1e-300", "allowed range"],
    ),
    case("span-inf", FLUTTER, {W: sub(GOLAND, "span", "inf")}, ["span = inf", "finite"]),
    case("bool-EI", FLUTTER, {W: sub(GOLAND, "EI", "true")}, ["EI = True", "real number"]),
    case(
        "unit-error",
        FLUTTER,
        {W: sub(sub(GOLAND, "EI", "1e13"), "mass", "1e-6")},
        ["first bending frequency", "check the units"],
    ),
    case("torsion-units", FLUTTER, {W: sub(GOLAND, "GJ", "1e-6")}, ["torsion frequency"]),
    case("a-outside", FLUTTER, {W: sub(GOLAND, "a", "1.5")}, ["a = 1.5", "allowed range"]),
    case("density-5", FLUTTER, {W: sub(GOLAND, "density", "5.0")}, ["analysis.density = 5"]),
    case("density-tiny", FLUTTER, {W: sub(GOLAND, "density", "1e-300")}, ["density = 1e-300"]),
    case("v_max-huge", FLUTTER, {W: analysis(GOLAND, "v_max = 1e308")}, ["v_max = 1e+308"]),
    case("v_max-tiny", FLUTTER, {W: analysis(GOLAND, "v_max = 1e-300")}, ["v_max = 1e-300"]),
    case("elements-1e5", FLUTTER, {W: analysis(GOLAND, "elements = 100000")}, ["[1, 300]"]),
    case("elements-0", FLUTTER, {W: analysis(GOLAND, "elements = 0")}, ["elements = 0"]),
    case("n_modes-500", FLUTTER, {W: analysis(GOLAND, "n_modes = 500")}, ["n_modes = 500"]),
    case(
        "altitude-huge",
        FLUTTER,
        {W: sub(GOLAND, "density", "1.0").replace("density = 1.0", "altitude = 1e308")},
        ["altitude = 1e+308"],
    ),
    case(
        "wagner-strings",
        FLUTTER,
        {W: analysis(GOLAND, 'wagner = {A = "0.165", b = "0.0455"}')},
        ["analysis.wagner.A", "list of numbers"],
    ),
    case(
        "wagner-bool",
        FLUTTER,
        {W: analysis(GOLAND, "wagner = {A = [true], b = [0.1]}")},
        ["analysis.wagner.A[0] = True"],
    ),
    case(
        "wagner-huge",
        FLUTTER,
        {W: analysis(GOLAND, "wagner = {A = [0.165, 0.335], b = [1e308, 0.3]}")},
        ["wagner.b[0] = 1e+308", "allowed range"],
    ),
    case(
        "wagner-tiny",
        FLUTTER,
        {W: analysis(GOLAND, "wagner = {A = [0.165, 0.335], b = [1e-300, 0.3]}")},
        ["wagner.b[0] = 1e-300"],
    ),
    case("damping-g", FLUTTER, {W: GOLAND + "\n[damping]\ng = 1e308\n"}, ["damping.g = 1e+308"]),
    case("damping-nan", FLUTTER, {W: GOLAND + "\n[damping]\nratio = nan\n"}, ["damping.ratio"]),
]
# control surfaces and actuators
for key, value, fragment in (
    ("hinge_stiffness", "1e308", "hinge_stiffness = 1e+308"),
    ("static_moment", "1e308", "static_moment = 1e+308"),
    ("GJ", "1e308", "GJ = 1e+308"),
    ("stiffness", "1e308", "stiffness = 1e+308"),
    ("stiffness", "-1.0", "stiffness = -1"),
    ("station", "1e308", "station = 1e+308"),
    ("hinge", "-2.0", "hinge = -2"),
):
    text = AILERON
    if key == "GJ":  # the aileron's, not the wing's
        text = text.replace("GJ = 2.0e4", f"GJ = {value}")
    else:
        text = sub(text, key, value)
    NUMBERS.append(case(f"surface-{key}-{value}", AIL, {A: text}, [fragment]))
NUMBERS.append(
    case(
        "surface-inertia-1e308",
        AIL,
        {A: AILERON.replace("inertia = 0.089177", "inertia = 1e308")},
        ["inertia = 1e+308"],
    )
)

# -- options out of range ----------------------------------------------------------------------
OPTIONS = [
    case("density-1e308", ["flutter", "goland", "--density", "1e308"], {}, ["--density", "1e+308"]),
    case("density-1e-300", ["flutter", "goland", "--density", "1e-300"], {}, ["allowed range"]),
    case("density-5", ["flutter", "goland", "--density", "5"], {}, ["[0.0001, 2]"]),
    case("density-nan", ["flutter", "goland", "--density", "nan"], {}, ["finite"]),
    case("density-text", ["flutter", "goland", "--density", "dense"], {}, ["not a number"]),
    case("v-max-1e308", ["flutter", "goland", "--v-max", "1e308"], {}, ["--v-max", "1e+308"]),
    case("v-max-1e-300", ["flutter", "goland", "--v-max", "1e-300"], {}, ["--v-max"]),
    case("v-max-inf", ["flutter", "goland", "--v-max", "inf"], {}, ["finite"]),
    case("elements-1e5", ["flutter", "goland", "--elements", "100000"], {}, ["[1, 300]"]),
    case("elements-0", ["flutter", "goland", "--elements", "0"], {}, ["--elements", ">= 1"]),
    case("elements-float", ["flutter", "goland", "--elements", "1.5"], {}, ["not an integer"]),
    case("modes-0", ["flutter", "goland", "--modes", "0"], {}, ["--modes"]),
    case("modes-500", ["flutter", "goland", "--modes", "500"], {}, ["--modes = 500"]),
    case("g-1e308", ["flutter", "goland", "--structural-g", "1e308"], {}, ["g = 1e+308"]),
    case("ratio-nan", ["flutter", "goland", "--damping-ratio", "nan"], {}, ["ratio"]),
    case("rayleigh-3", ["flutter", "goland", "--rayleigh", "1,2,3"], {}, ["ALPHA,BETA"]),
    case("altitude-1e308", ["flutter", "goland", "--altitude", "1e308"], {}, ["altitude"]),
    case("altitude-ft-nan", ["flutter", "goland", "--altitude-ft", "nan"], {}, ["finite"]),
    case("wagner-unknown", ["flutter", "goland", "--wagner", "jones"], {}, ["wagner = 'jones'"]),
    case("unknown-option", ["flutter", "goland", "--nope"], {}, ["unrecognized", "--help"]),
    case("no-command", [], {}, ["COMMAND"]),
    case("bad-choice", ["flutter", "goland", "--units", "furlongs"], {}, ["furlongs"]),
    case("modes-n-0", ["modes", "goland", "-n", "0"], {}, ["-n"]),
    case("modes-mode-99", ["modes", "goland", "--mode", "99"], {}, ["--mode = 99"]),
    case("modes-animate-png", ["modes", "goland", "--animate", "m.png"], {}, ["--animate", ".gif"]),
    case(
        "export-speed-1e308",
        ["export", "goland", "--speed", "1e308", "--out", "m.npz"],
        {},
        ["--speed"],
    ),
    case(
        "export-speed-neg", ["export", "goland", "--speed", "-5", "--out", "m.npz"], {}, ["--speed"]
    ),
    case(
        "export-out-txt",
        ["export", "goland", "--speed", "100", "--out", "m.txt"],
        {},
        [".mat or .npz"],
    ),
    case(
        "export-signal",
        ["export", "goland_aileron", "--speed", "100", "--inputs", "foo", "--out", "m.npz"],
        {},
        ["'foo'"],
    ),
    case(
        "export-design-modes",
        ["export", "goland", "--speed", "100", "--design-modes", "0", "--out", "m.npz"],
        {},
        ["--design-modes = 0"],
    ),
    case(
        "envelope-alt-huge", ["envelope", "goland", "--altitudes", "0:1e308:1"], {}, ["--altitudes"]
    ),
    case("envelope-alt-step0", ["envelope", "goland", "--altitudes", "0:1000:0"], {}, ["step > 0"]),
    case(
        "envelope-alt-many",
        ["envelope", "goland", "--altitudes", "0:40000:0.001"],
        {},
        ["1000 points"],
    ),
    case(
        "envelope-vd-1e308",
        ["envelope", "goland", "--altitudes", "0", "--vd", "1e308"],
        {},
        ["vd = 1e+308"],
    ),
]

# -- outputs the file system refuses, checked before the computation ----------------------------
LONG = "x" * 300
ENV = ["envelope", "goland", "--altitudes", "0"]
LQR_SCENARIO = SCENARIO.replace(
    'file = "goland_aileron.toml"', 'builtin = "goland_aileron"'
).replace('"../controllers/lqr.toml"', f'"{ROOT / "controllers" / "lqr.toml"}"')
OUTPUTS = [
    case("plot-format", ["flutter", "goland", "--plot", "x.foo"], {}, ["--plot", "'foo'"]),
    case(
        "plot-long", ["flutter", "goland", "--plot", LONG + ".png"], {}, ["--plot", "file name of"]
    ),
    case("save-long", ["flutter", "goland", "--save", LONG + ".npz"], {}, ["--save", "file name"]),
    case("save-suffix", ["flutter", "goland", "--save", "x.txt"], {}, ["--save", ".npz"]),
    case("table-long", ["flutter", "goland", "--table", LONG + ".csv"], {}, ["--table"]),
    case("plot-no-folder", ["flutter", "goland", "--plot", "nope/x.png"], {}, ["does not exist"]),
    case(
        "plot-is-folder",
        ["flutter", "goland", "--save", "d.npz"],
        {"d.npz/x": "a"},
        ["is a folder"],
    ),
    case("modes-plot-long", ["modes", "goland", "--plot", LONG + ".png"], {}, ["--plot"]),
    case("envelope-csv-long", [*ENV, "--csv", LONG + ".csv"], {}, ["--csv"]),
    case("envelope-save-suffix", [*ENV, "--save", "e.npz"], {}, [".json"]),
    case(
        "export-long", ["export", "goland", "--speed", "100", "--out", LONG + ".npz"], {}, ["--out"]
    ),
    case(
        "result-name-long",
        ["run", "s.toml"],
        {"s.toml": LQR_SCENARIO.replace('"goland_aileron_lqr"', f'"{"r" * 250}"')},
        ["output.result", "at most 200"],
    ),
]


# -- damaged or foreign result files given to `aeroservo plot` ---------------------------------
def _saved_sweep() -> dict:
    """The arrays of a saved flutter sweep, made once (module level, a 0.3 s computation)."""
    import tempfile

    from aeroservo.files.flutter_file import flutter_writer, open_npz
    from aeroservo.files.wing_file import wing_toml
    from aeroservo.stability.boundary import flutter_boundary
    from aeroservo.structure.examples import goland
    from aeroservo.system.aeroelastic import AeroelasticModel

    model = AeroelasticModel(goland())
    result = flutter_boundary(model, 1.225)
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "f.npz"
        flutter_writer(result, model=model, wing_text=wing_toml(model.wing))(p)
        return open_npz(p)[0]


SWEEP = _saved_sweep()


def _sweep_without(key: str) -> bytes:
    return npz(**{k: v for k, v in SWEEP.items() if k != key})


def _sweep_with(key: str, value) -> bytes:
    return npz(**{**SWEEP, key: value})


GOOD_NPZ = npz(**SWEEP)
PLOTS = [
    case("npz-truncated", ["plot", "f.npz"], {"f.npz": GOOD_NPZ[: len(GOOD_NPZ) // 2]}, ["f.npz"]),
    case("npz-empty", ["plot", "f.npz"], {"f.npz": b""}, ["f.npz", "not"]),
    case("npz-text", ["plot", "f.npz"], {"f.npz": "hello"}, ["f.npz", "not an aeroservo result"]),
    case("npz-json", ["plot", "f.npz"], {"f.npz": '{"a": 1}'}, ["a JSON summary?"]),
    case("npz-no-arrays", ["plot", "f.npz"], {"f.npz": npz()}, ["f.npz", "meta"]),
    case("npz-foreign", ["plot", "f.npz"], {"f.npz": npz(x=np.zeros(3))}, ["f.npz", "meta"]),
    case(
        "npz-meta-number",
        ["plot", "f.npz"],
        {"f.npz": _sweep_with("meta", np.array(3.0))},
        ["meta"],
    ),
    case(
        "npz-meta-bad-json",
        ["plot", "f.npz"],
        {"f.npz": _sweep_with("meta", np.array("{x"))},
        ["JSON"],
    ),
    case(
        "npz-meta-list",
        ["plot", "f.npz"],
        {"f.npz": _sweep_with("meta", np.array("[1]"))},
        ["JSON object"],
    ),
    case(
        "npz-object",
        ["plot", "f.npz"],
        {"f.npz": _sweep_with("x", np.array([{}], dtype=object))},
        ["f.npz"],
    ),
    case("plot-dev-zero", ["plot", "/dev/zero"], {}, ["not a regular file"]),
    case(
        "plot-kind", ["plot", "f.npz", "--kind", "time"], {"f.npz": GOOD_NPZ}, ["--kind = 'time'"]
    ),
    case(
        "plot-out-format",
        ["plot", "f.npz", "--out", "x.foo"],
        {"f.npz": GOOD_NPZ},
        ["--out", "'foo'"],
    ),
    case(
        "plot-out-long", ["plot", "f.npz", "--out", LONG + ".png"], {"f.npz": GOOD_NPZ}, ["--out"]
    ),
    case("plot-modes-99", ["plot", "f.npz", "--modes", "99"], {"f.npz": GOOD_NPZ}, ["99"]),
    case("plot-fmax-neg", ["plot", "f.npz", "--fmax", "-1"], {"f.npz": GOOD_NPZ}, ["--fmax"]),
    case(
        "plot-g-1e308", ["plot", "f.npz", "--g-required", "1e308"], {"f.npz": GOOD_NPZ}, ["[0, 2)"]
    ),
    case("flutter-g-required", ["flutter", "goland", "--g-required", "5"], {}, ["--g-required"]),
    case(
        "envelope-json-cut",
        ["plot", "e.json"],
        {"e.json": '{"format": "aeroser'},
        ["e.json", "JSON"],
    ),
    case("envelope-json-list", ["plot", "e.json"], {"e.json": "[1, 2]"}, ["e.json"]),
    case("envelope-binary", ["plot", "e.json"], {"e.json": b"\xff\xfe\x00\xd8"}, ["e.json"]),
    case(
        "envelope-vd-string",
        ["plot", "e.json"],
        {"e.json": json.dumps({"format": "aeroservo-envelope-1", "points": [], "vd_eas": "x"})},
        ["vd_eas = 'x'"],
    ),
    case(
        "envelope-point-string",
        ["plot", "e.json"],
        {
            "e.json": json.dumps(
                {"format": "aeroservo-envelope-1", "points": [{"altitude": "high"}]}
            )
        },
        ["points[0].altitude = 'high'"],
    ),
    case("trade-empty-folder", ["plot", "tdir"], {"tdir/x": "a"}, ["study.json"]),
    case("trade-manifest-list", ["plot", "t"], {"t/study.json": "[1]"}, ["not a trade-study"]),
    case("trade-manifest-binary", ["plot", "t"], {"t/study.json": PNG}, ["study.json"]),
    case(
        "trade-manifest-keys",
        ["plot", "t"],
        {"t/study.json": json.dumps({"format": TRADE})},
        ["t: not a readable trade study", "KeyError"],
    ),
    case(
        "trade-damaged-files",
        ["plot", "t"],
        {
            "t/study.json": json.dumps(
                {"format": TRADE, "csv": "t.csv", "netcdf": "t.nc", "name": "t", "parameters": {}}
            ),
            "t/t.csv": "case_id\n\x01,2,3\n",
            "t/t.nc": PNG,
        },
        ["t: not a readable trade study"],
    ),
]
for key in ("speeds", "eigenvalues", "crossing_speed", "crossing_kind", "wing_text"):
    name = "wing text" if key == "wing_text" else key
    without = _sweep_without(key)
    PLOTS.append(case(f"npz-without-{key}", ["plot", "f.npz"], {"f.npz": without}, [name]))
    wrong = _sweep_with(key, np.zeros((2, 3, 4)))
    PLOTS.append(case(f"npz-{key}-wrong-shape", ["plot", "f.npz"], {"f.npz": wrong}, [name]))

# -- scenario and controller numbers the other corpus does not hold ------------------------------
LQR_CTRL = (ROOT / "controllers" / "lqr.toml").read_text()
GUST_SCENARIO = (
    (ROOT / "scenarios" / "goland_aileron_gust.toml")
    .read_text()
    .replace('file = "goland_aileron.toml"', 'builtin = "goland_aileron"')
    .replace('"../controllers/lqg.toml"', f'"{ROOT / "controllers" / "lqg.toml"}"')
)
SERIES_SCENARIO = re.sub(
    r'gust = "one_minus_cosine"[^[]*', 'gust = "series"\nfile = "g.csv"\n\n', GUST_SCENARIO
)
RUN = ["run", "s.toml", "--quick"]


def with_controller(ctrl: str) -> dict:
    """The LQR scenario with its controller file replaced by ``ctrl``."""
    spec = f'"{ROOT / "controllers" / "lqr.toml"}"'
    return {"s.toml": LQR_SCENARIO.replace(spec, '"c.toml"'), "c.toml": ctrl}


SCENARIOS = [
    case(
        "speed-tiny", RUN, {"s.toml": sub(LQR_SCENARIO, "speed_factor", "1e-300")}, ["speed_factor"]
    ),
    case(
        "speed-1e-300",
        RUN,
        {"s.toml": LQR_SCENARIO.replace("speed_factor = 1.1", "speed = 1e-300")},
        ["flight.speed = 1e-300", "[0.1, 1000]"],
    ),
    case("density-2.5", RUN, {"s.toml": sub(LQR_SCENARIO, "density", "2.5")}, ["flight.density"]),
    case(
        "wagner-tiny-scenario",
        RUN,
        {"s.toml": sub(LQR_SCENARIO, "wagner", "{A = [0.165, 0.335], b = [1e-300, 0.3]}")},
        ["model.wagner", "b[0] = 1e-300"],
    ),
    case("gust-start-huge", RUN, {"s.toml": sub(GUST_SCENARIO, "start", "1e308")}, ["start"]),
    case("gust-length-tiny", RUN, {"s.toml": sub(GUST_SCENARIO, "length", "1e-300")}, ["length"]),
    case(
        "gust-series-huge",
        RUN,
        {"s.toml": SERIES_SCENARIO, "g.csv": "0,0\n0.1,1e308\n0.2,0\n"},
        ["g.csv", "velocity"],
    ),
    case(
        "gust-series-utf16-bad",
        RUN,
        {"s.toml": SERIES_SCENARIO, "g.csv": b"\xff\xfe\x00\xd8\x00"},
        ["g.csv"],
    ),
    case("gust-series-fifo", RUN, {"s.toml": SERIES_SCENARIO, "g.csv": "FIFO"}, ["g.csv"]),
    case(
        "weight-1e308",
        RUN,
        with_controller(LQR_CTRL.replace("tip_disp = 0.05", "tip_disp = 1e308")),
        ["c.toml", "tip_disp = 1e+308", "allowed range"],
    ),
    case(
        "weight-1e-300",
        RUN,
        with_controller(LQR_CTRL.replace("tip_disp = 0.05", "tip_disp = 1e-300")),
        ["c.toml", "tip_disp = 1e-300"],
    ),
    case(
        "input-weight-1e-300",
        RUN,
        with_controller(LQR_CTRL.replace("hinge_moment = 500.0", "hinge_moment = 1e-300")),
        ["aileron_hinge_moment = 1e-300"],
    ),
    case(
        "limit-1e308",
        RUN,
        with_controller(LQR_CTRL.replace("hinge_moment = 2000.0", "hinge_moment = 1e308")),
        ["magnitude", "1e+308"],
    ),
    case(
        "state-weight-huge",
        RUN,
        with_controller(LQR_CTRL.replace("[weights]", "[weights]\nstate_weight = 1e308")),
        ["state_weight = 1e+308"],
    ),
    case(
        "schedule-huge",
        RUN,
        with_controller(LQR_CTRL + "\n[schedule]\nspeed_factors = [1.0, 1e308]\n"),
        ["speed_factors[1] = 1e+308"],
    ),
]

# -- found by an adversarial review (helper probe of 775 inputs) --------------------------------
LQG_CTRL = (ROOT / "controllers" / "lqg.toml").read_text()
HINF_CTRL = (ROOT / "controllers" / "hinf.toml").read_text()
REVIEW = [
    case(
        "rayleigh-huge",
        ["flutter", "goland", "--rayleigh", "1e300,1e300"],
        {},
        ["--rayleigh ALPHA"],
    ),
    case("rayleigh-beta-inf", ["flutter", "goland", "--rayleigh", "0,inf"], {}, ["finite"]),
    case(
        "damping-ratio-empty",
        ["flutter", "goland", "--damping-ratio", "0.01,,0.02"],
        {},
        ["commas"],
    ),
    case(
        "damping-ratio-negative",
        ["flutter", "goland", "--damping-ratio", "0.01,-0.02"],
        {},
        ["--damping-ratio"],
    ),
    case(
        "structural-g-negative",
        ["flutter", "goland", "--structural-g", "-0.1"],
        {},
        ["--structural-g"],
    ),
    case(
        "beta-in-file",
        FLUTTER,
        {W: GOLAND + "\n[damping]\nbeta = 1e10\n"},
        ["damping.beta = 1e+10"],
    ),
    case("elements-400", ["flutter", "goland", "--elements", "400"], {}, ["[1, 300]"]),
    case("altitude-underscore", ["flutter", "goland", "--altitude", "1_000"], {}, ["not a number"]),
    case(
        "altitude-fullwidth",
        ["flutter", "goland", "--altitude", "\uff11\uff10"],
        {},
        ["not a number"],
    ),
    case(
        "altitudes-high",
        ["envelope", "goland", "--altitudes", "0:50000:10000"],
        {},
        ["--altitudes", "50000 m"],
    ),
    case(
        "altitudes-ft-high",
        ["envelope", "goland", "--altitudes-ft", "0:200000:50000"],
        {},
        ["--altitudes-ft"],
    ),
    case("altitudes-nan", ["envelope", "goland", "--altitudes", "nan,1000"], {}, ["--altitudes"]),
    case(
        "altitudes-repeat", ["envelope", "goland", "--altitudes", "0,0,0"], {}, ["must not repeat"]
    ),
    case("altitudes-blank", ["envelope", "goland", "--altitudes", "0, ,1000"], {}, ["--altitudes"]),
    case("modes-n-1000", ["modes", "goland", "-n", "1000"], {}, ["-n = 1000"]),
    case("out-empty", ["run", "s.toml", "--out", ""], {"s.toml": LQR_SCENARIO}, ["--out = ''"]),
    case(
        "out-is-file", ["run", "s.toml", "--out", "s.toml"], {"s.toml": LQR_SCENARIO}, ["is a file"]
    ),
    case(
        "scheduler-not-trade",
        ["run", "s.toml", "--scheduler", "tcp://127.0.0.1:1"],
        {"s.toml": LQR_SCENARIO},
        ["--scheduler", "simulate scenario"],
    ),
    case(
        "sensor-filter-tiny",
        RUN,
        {"s.toml": sub(LQR_SCENARIO, "sensor_filter", "1e-300")},
        ["signals.sensor_filter"],
    ),
    case(
        "wagner-many-terms",
        RUN,
        {
            "s.toml": sub(
                LQR_SCENARIO,
                "wagner",
                "{A = ["
                + ", ".join(["0.0005"] * 1000)
                + "], b = ["
                + ", ".join(["0.1"] * 1000)
                + "]}",
            )
        },
        ["1000 terms", "at most 12"],
    ),
    case(
        "schedule-long",
        RUN,
        with_controller(
            LQR_CTRL
            + "\n[schedule]\nspeed_factors = ["
            + ", ".join(f"{1 + k * 1e-3:.3f}" for k in range(100))
            + "]\n"
        ),
        ["speed_factors", "at most 50"],
    ),
    case(
        "estimator-zero-noise",
        RUN,
        {
            "s.toml": GUST_SCENARIO.replace(f'"{ROOT / "controllers" / "lqg.toml"}"', '"c.toml"'),
            "c.toml": re.sub(
                r"process_noise = \{[^}]*\}", "process_noise = { gust = 0.0 }", LQG_CTRL
            ),
        },
        ["c.toml", "estimator.process_noise", "gust = 0"],
    ),
    case(
        "hinf-floor-above-peak",
        RUN,
        with_controller(sub(HINF_CTRL, "sensitivity_floor", "3.0")),
        ["sensitivity_floor = 3", "below"],
    ),
    case(
        "gust-series-3-columns",
        RUN,
        {"s.toml": SERIES_SCENARIO, "g.csv": "0.0,1.0,2.0\n0.1,1.0,2.0\n"},
        ["g.csv", "line 2"],
    ),
    case(
        "gust-series-underscore",
        RUN,
        {"s.toml": SERIES_SCENARIO, "g.csv": "0,0\n0.1,1_0\n0.2,0\n"},
        ["g.csv", "line 2"],
    ),
    case(
        "npz-nan-speeds",
        ["plot", "f.npz"],
        {"f.npz": _sweep_with("speeds", np.full_like(SWEEP["speeds"], np.nan))},
        ["speeds are not finite"],
    ),
    case(
        "envelope-negative",
        ["plot", "e.json"],
        {
            "e.json": json.dumps(
                {"format": "aeroservo-envelope-1", "points": [{"altitude": 0.0, "density": -1e308}]}
            )
        },
        ["points[0].density", ">= 0"],
    ),
]

CASES = FILES + NUMBERS + OPTIONS + OUTPUTS + PLOTS + SCENARIOS + REVIEW


def test_corpus_size():
    """At least 150 hostile inputs here (the API and scenario corpora come on top)."""
    assert len(CASES) >= 150


def _write(folder: Path, files: dict) -> None:
    for name, content in files.items():
        p = folder / name
        p.parent.mkdir(parents=True, exist_ok=True)
        if content == "FIFO":
            os.mkfifo(p)
        elif isinstance(content, bytes):
            p.write_bytes(content)
        else:
            p.write_text(content, encoding="utf-8")


def _tree(folder: Path) -> set:
    return {p.relative_to(folder) for p in folder.rglob("*")}


@pytest.mark.parametrize("argv,files,rc,fragments", CASES)
def test_bad_input(argv, files, rc, fragments, tmp_path, monkeypatch, capsys):
    _write(tmp_path, files)
    monkeypatch.chdir(tmp_path)
    before = _tree(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # no floating-point trouble either
        code = main(argv)
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert code == rc, err
    assert len(lines) == 1, f"expected one line, got:\n{err}"
    assert lines[0].startswith("aeroservo: error: "), lines[0]
    for fragment in fragments:
        assert fragment in lines[0], f"{fragment!r} not in {lines[0]!r}"
    assert "Traceback" not in err and "internal error" not in err
    assert _tree(tmp_path) == before, "a failed run left files behind"


# -- what the reader accepts --------------------------------------------------------------------
@pytest.mark.parametrize("encoding", ["utf-8-sig", "utf-16", "utf-16-be", "utf-32"])
def test_byte_order_marks_are_read(tmp_path, encoding):
    """Notepad's UTF-16 and UTF-8 with a byte-order mark read the same as plain UTF-8."""
    p = tmp_path / "w.toml"
    raw = GOLAND.encode(encoding)
    if encoding == "utf-16-be":
        raw = b"\xfe\xff" + raw
    p.write_bytes(raw)
    wing, opts = load_wing(p)
    ref, ref_opts = load_wing(ROOT / "scenarios" / "goland.toml")
    assert wing == ref and opts == ref_opts


def test_reader_refuses_what_is_not_a_regular_file(tmp_path):
    os.mkfifo(tmp_path / "pipe")
    for path in (tmp_path / "pipe", Path("/dev/zero"), tmp_path):
        with pytest.raises(InputError, match="not a regular file|is a folder"):
            read_text(path)
    with pytest.raises(InputError, match="expected the path"):
        read_text(5)


# -- a failed run leaves no file; outputs follow the umask --------------------------------------
def test_failed_write_leaves_no_file(tmp_path, monkeypatch, capsys):
    """The figure fails after the sweep and table were written: none of the three remains."""
    import matplotlib.figure

    def broken(self, *a, **kw):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", broken)
    monkeypatch.chdir(tmp_path)
    code = main(["flutter", "goland", "--save", "f.npz", "--table", "t.csv", "--plot", "vg.png"])
    err = capsys.readouterr().err
    assert code == 2 and "No space left" in err and len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_failed_scenario_run_leaves_no_file(tmp_path, monkeypatch, capsys):
    import matplotlib.figure

    def broken(self, *a, **kw):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", broken)
    out = tmp_path / "out"
    code = main(["run", str(ROOT / "scenarios" / "goland.toml"), "--quick", "--out", str(out)])
    assert code == 2, capsys.readouterr().err
    assert not out.exists() or list(out.iterdir()) == []


@pytest.mark.parametrize("umask", [0o022, 0o077, 0o002])
def test_outputs_follow_the_umask(tmp_path, monkeypatch, umask):
    monkeypatch.chdir(tmp_path)
    old = os.umask(umask)
    try:
        assert main(["flutter", "goland", "--save", "f.npz", "--table", "t.csv"]) == 0
    finally:
        os.umask(old)
    for name in ("f.npz", "t.csv"):
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o666 & ~umask


# -- fuzzing ------------------------------------------------------------------------------------
FUZZ = settings(
    max_examples=int(os.environ.get("AEROSERVO_FUZZ_EXAMPLES", "120")),
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
WING_KEYS = ["span", "semichord", "a", "mass", "x_alpha", "inertia", "EI", "GJ", "density"]
ODD = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.sampled_from(["1.0", "true", "[1, 2]", "{a = 1}", '"x"', "1e308", "-0.0", "1e-320"]),
)


def _toml_value(v) -> str:
    if isinstance(v, float):
        return (
            "nan" if v != v else ("inf" if v > 0 else "-inf") if abs(v) == float("inf") else repr(v)
        )
    return str(v)


@FUZZ
@given(key=st.sampled_from(WING_KEYS), value=ODD)
def test_fuzz_wing_file_numbers(tmp_path_factory, key, value):
    """Any value of any number in a wing file: a wing, or an InputError (nothing else)."""
    p = tmp_path_factory.mktemp("fuzz") / "w.toml"
    p.write_text(sub(GOLAND, key, _toml_value(value)))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        try:
            load_wing(p)
        except InputError as exc:
            assert len(str(exc).splitlines()) == 1 and "w.toml" in str(exc)


@FUZZ
@given(raw=st.binary(max_size=400))
def test_fuzz_wing_file_bytes(tmp_path_factory, raw):
    p = tmp_path_factory.mktemp("fuzz") / "w.toml"
    p.write_bytes(raw)
    try:
        load_wing(p)
    except InputError as exc:
        assert len(str(exc).splitlines()) == 1


@FUZZ
@given(
    quantity=st.sampled_from(sorted(RANGES)), value=st.one_of(ODD, st.none(), st.lists(st.floats()))
)
def test_fuzz_number_checks(quantity, value):
    """A checked number is a finite float in its documented range, or an InputError."""
    r = RANGES[quantity]
    try:
        v = check_quantity("x", value, quantity)
    except InputError as exc:
        assert str(exc).startswith("x = ") and len(str(exc).splitlines()) == 1
        return
    assert isinstance(v, float) and np.isfinite(v)
    assert (r.lo < v if r.lo_open else r.lo <= v) and (v < r.hi if r.hi_open else v <= r.hi)


def test_ranges_are_documented():
    """docs/conventions.md lists every range of errors.RANGES, as the code has it."""
    doc = (ROOT / "docs" / "conventions.md").read_text()
    for name, r in RANGES.items():
        assert f"| `{name}` | {r.text()} |" in doc, f"{name}: {r.text()} not in conventions.md"


# -- messages name the option or the key the value came from -------------------------------------
AILERON_1 = analysis(AILERON, "elements = 1")
NAMED = [
    case(
        "elements-option", ["flutter", "goland_aileron", "--elements", "1"], {}, ["--elements = 1"]
    ),
    case("elements-key", AIL, {A: AILERON_1}, ["a.toml: analysis.elements = 1"]),
    case("modes-option", ["flutter", "goland", "--modes", "500"], {}, ["--modes = 500"]),
    case("modes-command", ["modes", "goland_aileron", "--elements", "1"], {}, ["--elements = 1"]),
    case(
        "wagner-sum",
        FLUTTER,
        {W: analysis(GOLAND, "wagner = {A = [0.9, 0.3], b = [0.1, 0.2]}")},
        ["analysis.wagner: sum(A) = 1.2"],
    ),
]


@pytest.mark.parametrize("argv,files,rc,fragments", NAMED)
def test_message_names_the_source(argv, files, rc, fragments, tmp_path, monkeypatch, capsys):
    """Not the API argument (``n_elements = 1``) nor a default set name (``indicial set``)."""
    test_bad_input(argv, files, rc, fragments, tmp_path, monkeypatch, capsys)


ARRAYS = st.one_of(
    st.just(np.zeros(0)),
    st.just(np.array("text")),
    st.just(np.array(["a", "b"])),
    st.just(np.zeros((3, 2, 2))),
    st.just(np.full(4, np.nan)),
    st.just(np.array([1, 2, 3], dtype=np.int8)),
    st.just(np.array(1e308)),
    st.just(np.array('{"format": "aeroservo-flutter-1"}')),
)


@FUZZ
@given(raw=st.binary(max_size=2000), suffix=st.sampled_from([".npz", ".json"]))
def test_fuzz_result_bytes(tmp_path_factory, raw, suffix):
    """Random bytes as a result file: an InputError (nothing else)."""
    from aeroservo.files.results import load_result

    p = tmp_path_factory.mktemp("fuzz") / f"r{suffix}"
    p.write_bytes(raw)
    # the file named, and what it is not (an aeroservo result file, an envelope, UTF-8 text)
    with pytest.raises(InputError, match=rf"^{re.escape(str(p))}: .*\bnot\b"):
        load_result(p)


@FUZZ
@given(
    drop=st.lists(st.sampled_from(sorted(SWEEP)), max_size=3),
    replace=st.dictionaries(st.sampled_from(sorted(SWEEP)), ARRAYS, max_size=3),
)
def test_fuzz_saved_sweep(tmp_path_factory, drop, replace):
    """A saved sweep with keys dropped or replaced: a result or an InputError; plotting it
    (V-g) too."""
    import matplotlib.pyplot as plt

    from aeroservo.files.results import load_result
    from aeroservo.plots.flutter import plot_vg

    arrays = {k: v for k, v in {**SWEEP, **replace}.items() if k not in drop}
    p = tmp_path_factory.mktemp("fuzz") / "f.npz"
    p.write_bytes(npz(**arrays))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        try:
            saved = load_result(p)
        except InputError:
            return
        plt.close(plot_vg(saved.result))
