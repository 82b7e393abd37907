"""Scenario and controller files: the malformed corpus, the shipped files, and fuzzing.

Every problem in a scenario or controller file must raise :class:`aeroservo.errors.InputError`
(and nothing else) with a one-line message that names the file, the key and the value.

* ``tests/data/malformed/``: one small file per kind of mistake, with the expected message
  fragments in ``EXPECTED.toml`` (``ctrl_*.toml`` are controller files, the others scenarios;
  ``_*.toml`` and the CSV are helpers the scenarios refer to);
* every shipped ``scenarios/*.toml`` with a ``[scenario]`` table and every
  ``controllers/*.toml`` loads;
* hypothesis mutates the shipped examples (drop, replace, rename and nest keys and values),
  builds random documents and random bytes, and checks that only InputError comes out.
"""

from __future__ import annotations

import copy
import datetime as dt
import math
import os
import re
import shutil
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from aeroservo.design.spec import CONTROLLER_TYPES
from aeroservo.errors import InputError
from aeroservo.files import load_controller, load_scenario
from aeroservo.files.controller_file import controller_from_dict
from aeroservo.files.scenario_file import TOP, is_scenario_file, scenario_from_dict

ROOT = Path(__file__).parent.parent
SCENARIOS = ROOT / "scenarios"
CONTROLLERS = ROOT / "controllers"
MALFORMED = Path(__file__).parent / "data" / "malformed"
EXPECTED: dict[str, list[str]] = tomllib.loads((MALFORMED / "EXPECTED.toml").read_text())

# AEROSERVO_FUZZ_EXAMPLES=5000 for a longer search
FUZZ = settings(
    max_examples=int(os.environ.get("AEROSERVO_FUZZ_EXAMPLES", "150")),
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


def _loader(path: Path):
    return load_controller if path.name.startswith("ctrl_") else load_scenario


def _check_message(exc: InputError, *names: str) -> str:
    """The message of an InputError: one line that names each of ``names``."""
    msg = str(exc)
    assert len(msg.splitlines()) == 1 and "\n" not in msg, f"not one line: {msg!r}"
    for name in names:
        assert name in msg, f"{name!r} not named in {msg!r}"
    return msg


# -- the malformed corpus ---------------------------------------------------------------------
def test_corpus_is_listed():
    """Every corpus file has expected fragments, every listed file exists; at least 40."""
    files = {
        p.name
        for p in MALFORMED.glob("*.toml")
        if p.name != "EXPECTED.toml" and not p.name.startswith("_")
    }
    assert files == set(EXPECTED)
    assert len(files) >= 40
    assert all(EXPECTED.values()), "every file needs at least one fragment"


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_malformed_file(name):
    path = MALFORMED / name
    with pytest.raises(InputError, match=re.escape(EXPECTED[name][0])) as info:
        _loader(path)(path)
    assert type(info.value) is InputError
    _check_message(info.value, name, *EXPECTED[name])


def test_helpers_are_valid_alone():
    """The helper controllers are fine on their own: the scenarios' errors are cross-checks."""
    for path in MALFORMED.glob("_ctrl_*.toml"):
        load_controller(path)


# -- the shipped files ------------------------------------------------------------------------
SHIPPED_SCENARIOS = sorted(p.name for p in SCENARIOS.glob("*.toml") if is_scenario_file(p))
SHIPPED_CONTROLLERS = sorted(p.name for p in CONTROLLERS.glob("*.toml"))


def test_shipped_files_found():
    assert len(SHIPPED_SCENARIOS) >= 5 and len(SHIPPED_CONTROLLERS) >= 5


@pytest.mark.parametrize("name", SHIPPED_SCENARIOS)
def test_shipped_scenario_loads(name):
    s = load_scenario(SCENARIOS / name)
    assert s.name and s.kind in ("flutter", "simulate", "trade", "gust_loads", "lco")
    if s.kind == "simulate":
        assert s.controller is not None
    if s.kind == "trade":
        assert s.trade.parameters


@pytest.mark.parametrize("name", SHIPPED_CONTROLLERS)
def test_shipped_controller_loads(name):
    spec = load_controller(CONTROLLERS / name)
    assert spec.type in CONTROLLER_TYPES


# -- fuzzing: strategies ----------------------------------------------------------------------
def _read(path: Path) -> dict:
    return tomllib.loads(path.read_text())


SCENARIO_EXAMPLES = {name: _read(SCENARIOS / name) for name in SHIPPED_SCENARIOS}
CONTROLLER_EXAMPLES = {name: _read(CONTROLLERS / name) for name in SHIPPED_CONTROLLERS}

# names that occur in the schema: renaming a key to one of them, or using one as a value, gets
# past the unknown-key check more often than random text
WORDS = sorted(
    set(
        """
        scenario wing flight model signals disturbance controller simulation analysis output
        trade name kind description builtin file density speed speed_factor elements wagner
        design_modes gust v_max pk controls sensors outputs sensor_filter filter_order
        initial_tip length amplitude start sigma scale seed spec duration sample_rate delay
        sensor_noise closed_loop_boundary v_max_factor n_grid result plots parameters workers
        type weights limits estimator mpc schedule inputs state_weight magnitude rate
        process_noise horizon solver soft_outputs slack_weight speed_factors segments hinf margins
        order sensitivity_peak sensitivity_floor bandwidth control_weight complementary_peak
        roll_off gamma_factor gain_db phase_deg disk_alpha margin_speeds expect_unstable
        control_surfaces span EI GJ
        simulate flutter lqr lqg mpc hinf none goland goland_aileron series one_minus_cosine turbulence
        kussner upwash rt_jones dryden tip_disp tip_twist tip_le_accel tip_accel modal_3
        aileron_hinge_moment aileron_command aileron_deflection aileron_start aileron_chord
        hinge_stiffness bryson_hinge_moment goland_aileron.toml ../controllers/lqr.toml
        ../controllers/mpc.toml ../controllers/lqg.toml ../controllers/open_loop.toml
        """.split()
    )
)

keys = st.one_of(st.sampled_from(WORDS), st.text(max_size=12))
numbers = st.one_of(
    st.integers(),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, 1, -1, 0.0, -0.0, 1e-300, 1e300, 2, 3, 10, 0.5, 1.1, 2**63 - 1]),
)
scalars = st.one_of(
    numbers,
    st.booleans(),
    st.text(max_size=20),
    st.sampled_from(WORDS),
    st.datetimes(),
    st.dates(),
    st.times(),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=4), st.dictionaries(keys, inner, max_size=4)),
    max_leaves=10,
)


def _containers(node, path=()):
    """Paths of every dict and list in a document (the top level included)."""
    out = [path] if isinstance(node, (dict, list)) else []
    items = (
        node.items()
        if isinstance(node, dict)
        else enumerate(node)
        if isinstance(node, list)
        else ()
    )
    for k, v in items:
        out += _containers(v, path + (k,))
    return out


def _at(doc, path):
    for k in path:
        doc = doc[k]
    return doc


def _mutate_once(data: st.DataObject, doc) -> None:
    """Apply one random change somewhere in ``doc`` (in place)."""
    node = _at(doc, data.draw(st.sampled_from(_containers(doc)), label="where"))
    if isinstance(node, list):
        op = data.draw(st.sampled_from(["drop", "replace", "append", "nest"]), label="op")
        if op == "append" or not node:
            node.append(data.draw(values, label="value"))
            return
        i = data.draw(st.integers(0, len(node) - 1), label="index")
        if op == "drop":
            del node[i]
        elif op == "replace":
            node[i] = data.draw(values, label="value")
        else:
            node[i] = [node[i]]
        return
    op = data.draw(st.sampled_from(["drop", "replace", "rename", "add", "nest"]), label="op")
    if op == "add" or not node:
        node[data.draw(keys, label="key")] = data.draw(values, label="value")
        return
    key = data.draw(st.sampled_from(sorted(node, key=str)), label="key")
    if op == "drop":
        del node[key]
    elif op == "replace":
        node[key] = data.draw(values, label="value")
    elif op == "rename":
        node[data.draw(keys, label="new key")] = node.pop(key)
    else:
        wrap = data.draw(st.sampled_from(["dict", "list", "same key"]), label="nest as")
        node[key] = {"dict": {"x": node[key]}, "list": [node[key]], "same key": {key: node[key]}}[
            wrap
        ]


def _mutated(data: st.DataObject, examples: dict) -> tuple[str, dict]:
    name = data.draw(st.sampled_from(sorted(examples)), label="example")
    doc = copy.deepcopy(examples[name])
    for _ in range(data.draw(st.integers(1, 3), label="changes")):
        _mutate_once(data, doc)
    return name, doc


def _only_input_error(call, *names: str):
    """Run ``call``; it may succeed or raise InputError (one line, naming ``names``)."""
    try:
        call()
    except InputError as exc:
        _check_message(exc, *names)


# -- fuzzing: dictionaries ------------------------------------------------------------------
@FUZZ
@given(data=st.data())
def test_fuzz_scenario_from_dict_mutated(data):
    name, doc = _mutated(data, SCENARIO_EXAMPLES)
    file = str(SCENARIOS / name)
    _only_input_error(lambda: scenario_from_dict(doc, file=file, base=SCENARIOS), file)


def _random_documents(head: st.SearchStrategy, table_names: list[str]) -> st.SearchStrategy:
    """Random documents: anything at all, random tables, and random tables under a valid
    ``head`` (e.g. a scenario table and a wing) so that more of the loader is reached."""
    tables = st.dictionaries(keys, values, max_size=6)
    named_tables = st.dictionaries(st.sampled_from(table_names), tables, max_size=len(table_names))
    return st.one_of(
        values,
        st.dictionaries(keys, st.one_of(tables, values), max_size=8),
        st.builds(lambda rest, fixed: {**rest, **fixed}, named_tables, head),
        st.builds(lambda rest, fixed: {**rest, **fixed}, named_tables, head),
    )


SCENARIO_HEAD = st.fixed_dictionaries(
    {
        "scenario": st.fixed_dictionaries(
            {"name": st.text(max_size=8), "kind": st.sampled_from(["flutter", "simulate", "trade"])}
        ),
        "wing": st.sampled_from(
            [{"builtin": "goland_aileron"}, {"builtin": "goland"}, {"file": "goland_aileron.toml"}]
        ),
        "flight": st.fixed_dictionaries({"density": st.floats(0.1, 2.0)}),
    }
)
SCENARIO_TABLES = list(TOP[3:])  # the optional tables, after scenario/wing/flight
CONTROLLER_HEAD = st.fixed_dictionaries(
    {"type": st.sampled_from(["none", "lqr", "lqg", "mpc", "hinf"])}
)
CONTROLLER_TABLES = ["weights", "limits", "estimator", "mpc", "schedule"]


@FUZZ
@given(doc=_random_documents(SCENARIO_HEAD, SCENARIO_TABLES))
def test_fuzz_scenario_from_dict_random(doc):
    file = str(SCENARIOS / "random.toml")
    _only_input_error(lambda: scenario_from_dict(doc, file=file, base=SCENARIOS), file)


@FUZZ
@given(data=st.data())
def test_fuzz_controller_from_dict_mutated(data):
    name, doc = _mutated(data, CONTROLLER_EXAMPLES)
    file = str(CONTROLLERS / name)
    _only_input_error(lambda: controller_from_dict(doc, file=file), file)


@FUZZ
@given(doc=_random_documents(CONTROLLER_HEAD, CONTROLLER_TABLES))
def test_fuzz_controller_from_dict_random(doc):
    file = "controllers/random.toml"
    _only_input_error(lambda: controller_from_dict(doc, file=file), file)


# -- fuzzing: files ---------------------------------------------------------------------------
_BARE = re.compile(r"[A-Za-z0-9_-]+")


def _toml_string(s: str) -> str:
    out = []
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04x}")
        elif 0xD800 <= ord(ch) <= 0xDFFF:
            out.append("?")  # lone surrogates cannot be written as UTF-8
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _toml_value(v) -> str:
    """``v`` as an inline TOML value."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, (dt.datetime, dt.date, dt.time)):
        return v.isoformat()
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return "{" + ", ".join(f"{_toml_key(k)} = {_toml_value(x)}" for k, x in v.items()) + "}"


def _toml_key(k: str) -> str:
    return k if _BARE.fullmatch(k) else _toml_string(k)


def _toml(doc: dict) -> str:
    return "".join(f"{_toml_key(k)} = {_toml_value(v)}\n" for k, v in doc.items())


def test_toml_writer_round_trip():
    for doc in list(SCENARIO_EXAMPLES.values()) + list(CONTROLLER_EXAMPLES.values()):
        assert tomllib.loads(_toml(doc)) == doc


GUST_CSV = "time, velocity\n0.0, 0.0\n0.1, 2.5\n0.2, 5.0\n0.3, 0.0\n"


@pytest.fixture(scope="module")
def tree(tmp_path_factory) -> Path:
    """A copy of scenarios/ and controllers/ so that relative references resolve, with two
    scenarios that read the fuzzed wing file and gust series."""
    root = tmp_path_factory.mktemp("tree")
    shutil.copytree(SCENARIOS, root / "scenarios")
    shutil.copytree(CONTROLLERS, root / "controllers")
    lqr = (SCENARIOS / "goland_aileron_lqr.toml").read_text()
    (root / "scenarios" / "uses_fuzz_wing.toml").write_text(
        lqr.replace('file = "goland_aileron.toml"', 'file = "fuzz_wing.toml"')
    )
    gust = lqr.replace(
        "initial_tip = 0.01", 'gust = "series"\nfile = "fuzz_gust.csv"\ninitial_tip = 0.01'
    )
    (root / "scenarios" / "uses_fuzz_gust.toml").write_text(gust)
    for name in ("uses_fuzz_wing.toml", "uses_fuzz_gust.toml"):  # valid with the originals
        shutil.copy(SCENARIOS / "goland_aileron.toml", root / "scenarios" / "fuzz_wing.toml")
        (root / "scenarios" / "fuzz_gust.csv").write_text(GUST_CSV)
        load_scenario(root / "scenarios" / name)
    return root


# what is fuzzed: name -> (original text, file written, file loaded, loader)
TEXT_EXAMPLES = {
    name: ((SCENARIOS / name).read_text(), "scenarios/fuzz.toml", "scenarios/fuzz.toml")
    for name in SHIPPED_SCENARIOS
}
TEXT_EXAMPLES["controllers/lqg.toml"] = (
    (CONTROLLERS / "lqg.toml").read_text(),
    "controllers/fuzz.toml",
    "controllers/fuzz.toml",
)
TEXT_EXAMPLES["wing file"] = (
    (SCENARIOS / "goland_aileron.toml").read_text(),
    "scenarios/fuzz_wing.toml",
    "scenarios/uses_fuzz_wing.toml",
)
TEXT_EXAMPLES["gust series"] = (
    GUST_CSV,
    "scenarios/fuzz_gust.csv",
    "scenarios/uses_fuzz_gust.toml",
)


@st.composite
def edited_text(draw) -> tuple[str, bytes]:
    """A shipped file with a few lines deleted, duplicated, cut, replaced or inserted."""
    name = draw(st.sampled_from(sorted(TEXT_EXAMPLES)))
    lines = TEXT_EXAMPLES[name][0].splitlines()
    for _ in range(draw(st.integers(1, 3))):
        i = draw(st.integers(0, len(lines) - 1))
        op = draw(st.sampled_from(["delete", "duplicate", "cut", "replace", "insert"]))
        if op == "delete":
            del lines[i]
        elif op == "duplicate":
            lines.insert(i, lines[i])
        elif op == "cut":
            lines[i] = lines[i][: draw(st.integers(0, len(lines[i])))]
        elif op == "replace":
            lines[i] = draw(st.text(max_size=30))
        elif name == "gust series":
            lines.insert(i, ", ".join(_toml_value(draw(scalars)) for _ in range(2)))
        else:
            lines.insert(i, f"{_toml_key(draw(keys))} = {_toml_value(draw(values))}")
        if not lines:
            lines = [""]
    return name, "\n".join(lines).encode("utf-8", "surrogatepass")


@FUZZ
@given(
    case=st.one_of(
        edited_text(),
        st.tuples(st.sampled_from(sorted(TEXT_EXAMPLES)), st.binary(max_size=300)),
    )
)
def test_fuzz_files(tree, case):
    """Edited or random files: scenarios, a controller, a wing file and a gust series."""
    name, content = case
    _, written, loaded = TEXT_EXAMPLES[name]
    (tree / written).write_bytes(content)
    path = tree / loaded
    load = load_controller if loaded.startswith("controllers/") else load_scenario
    _only_input_error(lambda: load(path), str(path))


@FUZZ
@given(data=st.data())
def test_fuzz_load_scenario_mutated(tree, data):
    """Mutated example documents written as TOML: the file path and the folder matter."""
    _, doc = _mutated(data, SCENARIO_EXAMPLES)
    path = tree / "scenarios" / "fuzz_doc.toml"
    path.write_text(_toml(doc), encoding="utf-8")
    _only_input_error(lambda: load_scenario(path), str(path))


def test_controller_file_margin_requirement(tmp_path):
    """`[margins] delay_ms` and `at` (issue 38): read into the requirement; an unknown break
    point is one line naming the key."""
    from aeroservo.files.controller_file import load_controller

    path = tmp_path / "c.toml"
    path.write_text(
        'type = "lqr"\n[weights]\noutputs = { tip_disp = 0.01 }\n'
        "inputs = { aileron_hinge_moment = 100.0 }\n"
        '[margins]\ndelay_ms = 10.0\nat = ["inputs", "sensors"]\n'
    )
    req = load_controller(path).margins
    assert req.delay_ms == 10.0 and req.at == ("inputs", "sensors")
    path.write_text(path.read_text().replace('"sensors"', '"actuators"'))
    with pytest.raises(InputError, match=r"margins.at = .*allowed break points"):
        load_controller(path)
