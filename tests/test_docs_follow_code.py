"""The documentation follows the code (issue 39 item 5): what the README and ``docs/*.md`` name
exists, what they tell you to type runs, and what the package ships is listed.

* **Python names.** Every dotted name that starts with ``aeroservo.`` or ``aes.`` (the docs'
  ``import aeroservo as aes``) in a code span or a Python code block exists: the longest prefix
  that is a module is imported and the rest is looked up with ``getattr``. Python blocks must
  parse; their ``import`` / ``from aeroservo... import`` statements are checked too. Names that
  do not start with the package (``res.plot()``, ``control.lqr``) are not checked.
* **Command lines.** Every line of a shell block that starts with ``aeroservo`` is split as the
  shell splits it (``shlex``, comments dropped, ``\\`` continuations joined) and parsed by the
  real parser, ``aeroservo.cli._parser()``; its one-line usage error fails the test. An unquoted
  shell operator (``|``, ``;``, ``&`` ...) fails too: ``--kind vg|vf`` is a pipe when pasted.
  A ``>`` redirection ends the command. The README's quick start must run as pasted. The other
  documents write synopses: there ``[...]`` is an optional part and ``[a | b]`` alternatives,
  so each line is parsed without its optional parts and with each alternative of each part in
  turn, and the placeholders of :data:`PLACEHOLDERS` are replaced by values of their type.
* **Examples.** Every scenario kind has a shipped scenario and every controller-file type a
  shipped controller (a gain schedule too); every ``controllers/*.toml`` and every
  ``scenarios/*.toml`` loads with its loader (scenario, optimization, co-design or wing file),
  without running anything.
* **Docstrings.** Every cross-reference by full name in the package's docstrings
  (``:func:`aeroservo.stability.matched.flutter_at```) exists.
* **Layout.** Every module of ``src/aeroservo`` is named in the row of its folder in the
  README's layout table and in the row of its stage in ``docs/architecture.md``; every notebook,
  every document and every file of ``controllers/`` is named in the README's layout; every
  repository path in a code span exists; every ``package-data`` glob of ``pyproject.toml``
  matches a file.
"""

from __future__ import annotations

import ast
import importlib
import re
import shlex
import tomllib
from pathlib import Path

import pytest
from conftest import ROOT

from aeroservo.cli import _parser
from aeroservo.design.spec import CONTROLLER_TYPES
from aeroservo.errors import InputError
from aeroservo.studies.kinds import KINDS

README = ROOT / "README.md"
DOCS = sorted((ROOT / "docs").glob("*.md"))
DOC_FILES = [README, *DOCS]
SRC = ROOT / "src" / "aeroservo"
SCENARIOS = ROOT / "scenarios"
CONTROLLERS = ROOT / "controllers"

FENCE = re.compile(r"^```(\w*)[ \t]*\n(.*?)^```[ \t]*$", re.S | re.M)
SPAN = re.compile(r"`([^`\n]+)`")
DOTTED = re.compile(r"(?<![\w./-])(aeroservo|aes)((?:\.[A-Za-z_]\w*)+)")
SHELL = ("sh", "bash", "shell", "console")
PYTHON = ("python", "py")
REPO_PATH = re.compile(
    r"(scenarios|controllers|docs|notebooks|tests|bench|examples|matlab|src)/[\w./-]*"
)

PLACEHOLDERS = {
    "FILE": "scenarios/goland_aileron.toml",
    "ADDR": "tcp://host:8786",
    "ADDRESS": "tcp://host:8786",
    "M": "0.3",
}
"""Placeholders of the synopses and a value of their type (``--mach M`` takes a float)."""

OPERATORS = {"|", "||", "&", "&&", ";", ";;", "<", "(", ")"}
REDIRECTIONS = {">", ">>"}


def _rel(path: Path) -> str:
    return str(path.relative_to(ROOT))


def _text(path: Path) -> str:
    return path.read_text(encoding="utf-8")


def _blocks(path: Path, languages: tuple[str, ...]) -> list[str]:
    return [m.group(2) for m in FENCE.finditer(_text(path)) if m.group(1) in languages]


def _spans(path: Path) -> list[str]:
    """Inline code spans outside the fenced blocks."""
    return SPAN.findall(FENCE.sub("", _text(path)))


# -- Python names ------------------------------------------------------------------------------
def resolve(name: str) -> object:
    """The object a dotted ``aeroservo...`` name denotes (AttributeError or ImportError if none)."""
    parts = name.split(".")
    for i in range(len(parts), 0, -1):
        module = ".".join(parts[:i])
        try:
            obj = importlib.import_module(module)
        except ModuleNotFoundError as exc:
            if exc.name is None or not module.startswith(exc.name):
                raise  # a module the package imports is missing, not this name
            continue
        for attr in parts[i:]:
            obj = getattr(obj, attr)
        return obj
    raise ImportError(name)


def _chain(node: ast.AST) -> str | None:
    """``a.b.c`` of an attribute chain on a bare name, else None."""
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if isinstance(node, ast.Name):
        return ".".join([node.id, *reversed(parts)])
    return None


def python_names(source: str) -> set[str]:
    """The package names a Python block uses: imports and ``aes.`` / ``aeroservo.`` chains."""
    names = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            names |= {a.name for a in node.names if a.name.split(".")[0] == "aeroservo"}
        elif isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "aeroservo":
            names |= {f"{node.module}.{a.name}" for a in node.names if a.name != "*"}
        elif isinstance(node, ast.Attribute):
            chain = _chain(node)
            if chain and chain.split(".")[0] in ("aes", "aeroservo"):
                names.add(chain)
    return names


def documented_names() -> dict[str, set[str]]:
    """Every package name of the docs -> the files that name it (``aes.`` read as the package)."""
    found: dict[str, set[str]] = {}

    def add(name: str, path: Path) -> None:
        name = "aeroservo" + name[len("aes") :] if name.startswith("aes.") else name
        found.setdefault(name, set()).add(_rel(path))

    for path in DOC_FILES:
        for span in _spans(path):
            for m in DOTTED.finditer(span):
                add(m.group(1) + m.group(2), path)
        for block in _blocks(path, PYTHON):
            for name in python_names(block):
                add(name, path)
        for block in _blocks(path, ("",)):  # untyped blocks: text, formulas, messages
            for m in DOTTED.finditer(block):
                add(m.group(1) + m.group(2), path)
    return found


NAMES = documented_names()


def test_documented_names_found():
    assert len(NAMES) > 60, sorted(NAMES)  # the extraction works


@pytest.mark.parametrize("path", DOC_FILES, ids=_rel)
def test_python_blocks_parse(path):
    for block in _blocks(path, PYTHON):
        ast.parse(block)


def test_documented_names_exist():
    missing = []
    for name, where in sorted(NAMES.items()):
        try:
            resolve(name)
        except (AttributeError, ImportError) as exc:
            missing.append(f"{name} ({', '.join(sorted(where))}): {type(exc).__name__}: {exc}")
    assert not missing, "\n".join(missing)


def test_resolve_refuses_what_does_not_exist():
    assert resolve("aeroservo.stability.matched.flutter_at")
    assert resolve("aeroservo.examples.goland")  # a lazy package attribute
    for name in ("aeroservo.stability.matched.flutter_at_altitude", "aeroservo.nothing.here"):
        with pytest.raises((AttributeError, ImportError)):
            resolve(name)


# -- command lines -----------------------------------------------------------------------------
def shell_commands(path: Path) -> list[str]:
    """The ``aeroservo`` lines of the shell blocks of a document (continuations joined)."""
    out = []
    for block in _blocks(path, SHELL):
        for line in re.sub(r"\\\n[ \t]*", " ", block).splitlines():
            if line.strip().startswith("aeroservo ") or line.strip() == "aeroservo":
                out.append(line.strip())
    return out


def expand(line: str) -> list[str]:
    """A synopsis without its ``[...]`` parts, and with each alternative of each part in turn."""
    groups = list(re.finditer(r"\[([^\[\]]*)\]", line))
    bare = re.sub(r"\[[^\[\]]*\]", " ", line)
    out = [bare]
    for g in groups:
        for alt in g.group(1).split("|"):
            out.append(line[: g.start()] + alt + line[g.end() :])
    return [re.sub(r"\[[^\[\]]*\]", " ", x) for x in out]


def tokens(line: str) -> list[str]:
    """The words of a command line as the shell splits them, up to a ``>`` redirection."""
    lex = shlex.shlex(line, posix=True, punctuation_chars=True)
    lex.whitespace_split = True
    lex.commenters = "#"
    words = list(lex)
    for i, w in enumerate(words):
        if w in REDIRECTIONS:
            return words[:i]
        if w in OPERATORS or set(w) <= set("|&;<>()"):
            raise AssertionError(f"{line!r}: unquoted shell operator {w!r} (a pipe when pasted)")
    return words


def parse(line: str) -> None:
    words = tokens(line)
    assert words[0] == "aeroservo", line
    try:
        _parser().parse_args(words[1:])
    except InputError as exc:  # the parser's one-line usage error
        raise AssertionError(f"{line!r}: {exc}") from None
    except SystemExit as exc:  # --help, --version
        raise AssertionError(f"{line!r}: exits ({exc.code}) instead of running") from None


def test_readme_commands_found():
    assert len(shell_commands(README)) >= 20


@pytest.mark.parametrize("line", shell_commands(README))
def test_readme_command_parses_as_pasted(line):
    parse(line)


SYNOPSES = [(_rel(p), line) for p in DOCS for line in shell_commands(p)]


@pytest.mark.parametrize(
    ("doc", "line"), SYNOPSES, ids=[f"{d}:{i}" for i, (d, _) in enumerate(SYNOPSES)]
)
def test_docs_command_parses(doc, line):
    for variant in expand(line):
        words = [PLACEHOLDERS.get(w, w) for w in tokens(variant)]
        parse(shlex.join(words))


def test_command_check_catches_mistakes():
    with pytest.raises(AssertionError, match="shell operator"):
        parse("aeroservo plot sweep.npz --kind modes|vf --out fig.png")
    with pytest.raises(AssertionError, match="invalid choice"):
        parse("aeroservo plot sweep.npz --kind 'modes|vf'")
    with pytest.raises(AssertionError, match="unrecognized arguments"):
        parse("aeroservo trade scenarios/trade_aileron.toml [--scheduler tcp://host:8786]")
    parse("aeroservo flutter goland --json > out.json  # a redirection ends the command")
    variants = expand("aeroservo lco s.toml [--workers 2 | --scheduler ADDR] [--quiet]")
    assert [" ".join(v.split()[2:]) for v in variants] == [
        "s.toml",
        "s.toml --workers 2",
        "s.toml --scheduler ADDR",
        "s.toml --quiet",
    ]


# -- shipped examples --------------------------------------------------------------------------
SCENARIO_FILES = sorted(SCENARIOS.glob("*.toml"))
CONTROLLER_FILES = sorted(CONTROLLERS.glob("*.toml"))


def load_example(path: Path):
    """A file of ``scenarios/`` read by its loader: (what it is, the object)."""
    from aeroservo.files.optimize_file import load_codesign, load_optimization
    from aeroservo.files.scenario_file import is_scenario_file, load_scenario
    from aeroservo.files.toml_tables import read_toml
    from aeroservo.files.wing_model import load_model

    if is_scenario_file(path):
        return "scenario", load_scenario(path)
    top = read_toml(path)
    if "codesign" in top:
        return "codesign", load_codesign(path)
    if "optimize" in top:
        return "optimize", load_optimization(path)
    assert "wing" in top, f"{_rel(path)}: not a scenario, optimization, co-design or wing file"
    return "wing", load_model(path)


@pytest.fixture(scope="module")
def shipped_scenarios() -> dict:
    return {p.name: load_example(p) for p in SCENARIO_FILES}


@pytest.fixture(scope="module")
def shipped_controllers() -> dict:
    from aeroservo.files.controller_file import load_controller

    return {p.name: load_controller(p) for p in CONTROLLER_FILES}


def test_every_scenario_kind_is_shipped(shipped_scenarios):
    kinds = {obj.kind for what, obj in shipped_scenarios.values() if what == "scenario"}
    assert set(tuple(KINDS)) <= kinds, f"no scenario of kind {set(tuple(KINDS)) - kinds}"
    whats = {what for what, _ in shipped_scenarios.values()}
    assert whats == {"scenario", "optimize", "codesign", "wing"}


def test_every_controller_type_is_shipped(shipped_controllers):
    types = {spec.type for spec in shipped_controllers.values()}
    assert set(CONTROLLER_TYPES) <= types, f"no controller of type {set(CONTROLLER_TYPES) - types}"
    scheduled = {spec.type for spec in shipped_controllers.values() if spec.schedule}
    assert scheduled == {"lqr", "lqg"}  # a gain schedule of each type that has one


def test_brought_controllers_are_complete(shipped_controllers):
    """The brought examples carry what their loops need: the saved compensator's signals, the
    gain's matrix, the Python law's function (called once on zero sensors)."""
    by_type = {spec.type: spec for spec in shipped_controllers.values()}
    lin = by_type["linear"].linear
    assert lin["inputs"] == ["tip_le_accel", "tip_te_accel", "tip_twist"]
    assert lin["outputs"] == ["aileron_hinge_moment"] and lin["sign"] == 1
    assert lin["dt"] == pytest.approx(1e-3) and lin["A"].shape[0] == lin["B"].shape[0] > 0
    gain = by_type["gain"].gain
    assert gain["controls"] == ["aileron_hinge_moment"] and len(gain["K"][0]) == 3
    law = by_type["python"].python
    assert list(law["function"](0.0, [0.0, 0.0, 0.0])) == [0.0]


# -- layout ------------------------------------------------------------------------------------
def _section(text: str, heading: str) -> str:
    start = text.index(heading)
    end = text.find("\n## ", start + len(heading))
    return text[start : end if end >= 0 else len(text)]


def table_rows(text: str) -> list[list[str]]:
    """The cells of every table row of a markdown text (header and rule included)."""
    return [
        [c.strip() for c in line.strip().strip("|").split("|")]
        for line in text.splitlines()
        if line.lstrip().startswith("|")
    ]


LAYOUT = table_rows(_section(_text(README), "## Layout"))
README_ROWS = {row[1]: " ".join(row) for row in LAYOUT if len(row) == 3}
"""README layout, package table: path cell -> the row's text."""
README_PATHS = {row[0]: row[1] for row in LAYOUT if len(row) == 2}
"""README layout, other folders: path cell -> contents."""
ARCHITECTURE = [
    row for row in table_rows(_text(ROOT / "docs" / "architecture.md")) if len(row) == 4
]
"""docs/architecture.md, stage table: stage, folder / module, owns, may import."""


def _named(row: str, *names: str) -> bool:
    spans = set(SPAN.findall(row))
    return any(n in spans for n in names)


MODULES = sorted(
    p.relative_to(SRC)
    for p in SRC.rglob("*.py")
    if p.name != "__init__.py" or p.parent == SRC  # a subpackage's __init__: its folder's row
)


def test_modules_in_readme_layout():
    missing = []
    for module in MODULES:
        if len(module.parts) == 1:
            folder = "cli" if module.stem in ("__init__", "__main__") else None
        else:
            folder = module.parts[0]
        key = f"`src/aeroservo/{folder}/`" if folder else "`src/aeroservo/`"
        if not _named(README_ROWS.get(key, ""), module.stem, module.name):
            missing.append(f"{module} (row {key})")
    assert len(MODULES) > 200
    assert not missing, f"README layout: modules not named in their folder's row: {missing}"


def test_modules_in_architecture():
    missing = []
    for module in MODULES:
        if len(module.parts) == 1:
            top = module.stem in ("__init__", "__main__")
            marker = "`__init__.py`" if top else f"`{module.name}`"
        else:
            marker = f"`{module.parts[0]}/`"
        rows = [" ".join(r) for r in ARCHITECTURE if marker in r[1]]
        assert len(rows) == 1, f"docs/architecture.md: {len(rows)} stage rows for {marker}"
        if not _named(rows[0], module.stem, module.name):
            missing.append(f"{module} (row {marker})")
    assert not missing, f"docs/architecture.md: modules not named in their stage's row: {missing}"


DOC_ROLE = re.compile(r":(?:func|class|mod|meth|attr|data|obj|exc):`~?(aeroservo(?:\.\w+)+)`")


def test_docstring_references_exist():
    """Cross-references by full name in the package's docstrings (``:func:`aeroservo...```)."""
    missing, n = [], 0
    for path in sorted(SRC.rglob("*.py")):
        for m in DOC_ROLE.finditer(_text(path)):
            n += 1
            try:
                resolve(m.group(1))
            except (AttributeError, ImportError):
                missing.append(f"{path.relative_to(SRC)}: {m.group(1)}")
    assert n > 100
    assert not missing, f"docstrings name what does not exist: {missing}"


def test_layout_lists_notebooks_documents_and_controllers():
    notebooks = README_PATHS["`notebooks/`"]
    listing = _text(ROOT / "notebooks" / "README.md")
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        number = nb.name.split("_")[0]
        assert re.search(rf"(^|[ ,]){number} ", notebooks), f"README layout: notebook {number}"
        assert f"`{nb.name}`" in listing, f"notebooks/README.md: {nb.name}"
    for doc in DOCS:
        assert f"`{doc.name}`" in README_PATHS["`docs/`"], f"README layout: docs/{doc.name}"
    controllers = README_PATHS["`controllers/`"]
    for path in sorted(CONTROLLERS.iterdir()):
        assert _named(controllers, path.stem, path.name), f"README layout: controllers/{path.name}"


@pytest.mark.parametrize("path", [*DOC_FILES, ROOT / "notebooks" / "README.md"], ids=_rel)
def test_repository_paths_exist(path):
    missing = [
        s for s in SPAN.findall(_text(path)) if REPO_PATH.fullmatch(s) and not (ROOT / s).exists()
    ]
    assert not missing, f"{_rel(path)} names files that do not exist: {missing}"


def test_package_data_exists():
    project = tomllib.loads(_text(ROOT / "pyproject.toml"))
    data = project.get("tool", {}).get("setuptools", {}).get("package-data", {})
    for package, globs in data.items():
        folder = ROOT / "src" / Path(*package.split("."))
        for pattern in globs:
            assert list(folder.glob(pattern)), f"pyproject.toml: package-data {pattern!r} is empty"
