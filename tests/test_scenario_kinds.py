"""The registry of scenario kinds (issue 39 item 1): every per-kind part of the package comes
from it (the file reader, the writer of a run's files, the command line), the commands have the
same options, no scenario-kind comparison is written outside it, and the flutter analysis at a
flight condition is one code path for the ``flutter`` command and a flutter scenario."""

from __future__ import annotations

import ast
import contextlib
import io
import json
from pathlib import Path

import pytest

from aeroservo.cli import _parser, main
from aeroservo.cli.scenarios import REPORTS, _commands
from aeroservo.errors import InputError
from aeroservo.files.outputs import WRITERS
from aeroservo.files.scenario_file import KIND_TABLES, TOP, load_scenario
from aeroservo.studies.kinds import KINDS, Run, run_scenario, scenario_kind
from aeroservo.studies.scenario import quick

ROOT = Path(__file__).resolve().parent.parent
SRC = ROOT / "src" / "aeroservo"
SCENARIOS = ROOT / "scenarios"


@pytest.mark.parametrize(
    "table", [KIND_TABLES, WRITERS, REPORTS], ids=["file tables", "writers", "reports"]
)
def test_every_per_kind_table_covers_the_registry_exactly(table):
    assert set(table) == set(KINDS)


@pytest.mark.parametrize("kind", list(KINDS))
def test_each_kind_is_described_whole(kind):
    k = KINDS[kind]
    assert callable(k.runner_function())
    assert set(k.tables) <= set(TOP) and "scenario" in k.tables
    assert k.result in Run.__dataclass_fields__
    assert k.command in _commands()
    if k.options is not None:
        assert callable(k.options.quick)
    assert any(
        load_scenario(p).kind == kind
        for p in sorted(SCENARIOS.glob("*.toml"))
        if "[scenario]" in p.read_text() and f'kind = "{kind}"' in p.read_text()
    ), f"no shipped scenario of kind {kind!r}"


def test_an_unknown_kind_is_one_clear_error():
    with pytest.raises(InputError, match=r"scenario kind 'flutters': expected one of"):
        scenario_kind("flutters")


def _kind_literals(node: ast.AST) -> bool:
    """Whether ``node`` is a kind's name, or a tuple / list / set with one."""
    if isinstance(node, ast.Constant):
        return node.value in KINDS
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return any(_kind_literals(e) for e in node.elts)
    return False


def _mentions_kind(node: ast.AST) -> bool:
    return any(
        (isinstance(n, ast.Attribute) and n.attr == "kind")
        or (isinstance(n, ast.Name) and n.id == "kind")
        for n in ast.walk(node)
    )


def test_no_scenario_kind_comparison_outside_the_registry():
    """``kind == "trade"``, ``scenario.kind in ("gust_loads", "lco")`` and the like are written
    only in ``studies/kinds.py``; everywhere else the registry's entries decide."""
    found = []
    for path in sorted(SRC.rglob("*.py")):
        if path.name == "kinds.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.Compare):
                continue
            sides = [node.left, *node.comparators]
            if any(_kind_literals(s) for s in sides) and any(_mentions_kind(s) for s in sides):
                found.append(f"{path.relative_to(SRC)}:{node.lineno}")
    assert not found, f"scenario kinds compared outside studies/kinds.py: {found}"


def test_the_checker_sees_a_kind_comparison():
    """The check above finds what it looks for (it is given one)."""
    tree = ast.parse('if scenario.kind == "lco":\n    pass\nok = kind in ("trade", "x")')
    hits = [
        n
        for n in ast.walk(tree)
        if isinstance(n, ast.Compare)
        and any(_kind_literals(s) for s in [n.left, *n.comparators])
        and any(_mentions_kind(s) for s in [n.left, *n.comparators])
    ]
    assert len(hits) == 2


def _options(command: str) -> set[str]:
    sub = next(a for a in _parser()._actions if a.dest == "command")
    return {o for a in sub.choices[command]._actions for o in a.option_strings}


def test_the_scenario_commands_have_the_same_options():
    """``run`` and each kind's command: the same options; those of the studies on Dask with
    ``--workers`` and ``--scheduler`` (one of the two)."""
    common = {"--out", "--json", "--quick", "--no-plots", "--progress", "--no-progress"}
    common |= {"--quiet", "--aero", "--boxes", "--mach", "-h", "--help"}
    dask = {"--workers", "--scheduler"}
    for command, (_help, kinds) in _commands().items():
        want = common | (dask if any(k.on_dask for k in kinds) else set())
        assert _options(command) == want, command
    assert {"simulate", "trade", "loads", "lco", "run"} <= set(_commands())


def _cli(argv: list) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


@pytest.mark.parametrize(
    "extra, option",
    [(["--workers", "2"], "--workers = 2"), (["--scheduler", "tcp://h:1"], "--scheduler = ")],
)
def test_dask_options_refused_for_a_kind_not_on_dask(extra, option, tmp_path):
    """A simulation does not run on Dask: one line naming the option, the kinds that take it
    and the file; nothing written."""
    src = SCENARIOS / "goland_aileron_open_loop.toml"
    code, _, err = _cli(["run", str(src), "--out", str(tmp_path / "o"), *extra])
    assert code == 2 and err.count("\n") == 1, err
    assert option in err and "only the studies on Dask (trade, gust_loads, lco)" in err
    assert str(src) in err
    assert not (tmp_path / "o").exists()


def test_run_scenario_refuses_dask_options_through_the_api():
    sc = load_scenario(SCENARIOS / "goland_flutter.toml")
    with pytest.raises(InputError, match=r"workers = 0: only the studies on Dask"):
        run_scenario(sc, workers=0)


@pytest.mark.parametrize("command", ["simulate", "loads", "lco", "trade"])
def test_a_kind_command_refuses_another_kind(command, tmp_path):
    """Each kind's command names the command of the scenario it was given."""
    code, _, err = _cli([command, str(SCENARIOS / "goland_flutter.toml"), "--out", str(tmp_path)])
    assert code == 2 and "scenario.kind = 'flutter': use 'aeroservo run' for it" in err, err


def test_quick_options_come_from_each_study():
    """``quick`` of a scenario applies its study's own quick options (typed, frozen)."""
    for name in ("trade_aileron", "goland_aileron_gust_loads", "conner_freeplay_lco"):
        sc = load_scenario(SCENARIOS / f"{name}.toml")
        q = quick(sc)
        assert type(q.options) is KINDS[sc.kind].options and q.options == sc.options.quick()
        with pytest.raises(AttributeError):
            sc.options.workers = 3  # frozen: parsed and validated once


def test_flutter_record_is_one_code_path(tmp_path):
    """The ``flutter`` command on a flutter scenario and ``run`` of it give the same record
    (time-domain boundary, p-k check, aerodynamics): the flight-condition choice is written
    once (studies/flight_condition.flutter_analysis)."""
    src = str(SCENARIOS / "goland_flutter.toml")
    code1, out1, _ = _cli(["flutter", src, "--json", "--pk"])
    code2, out2, _ = _cli(["run", src, "--json", "--out", str(tmp_path)])
    assert code1 == code2 == 0
    a, b = json.loads(out1), json.loads(out2)
    for key in ("scenario", "kind", "files"):
        b.pop(key, None)
    assert a == b
    assert b["pk_exact_theodorsen"]["flutter_speed"] == pytest.approx(b["flutter_speed"], rel=0.02)
