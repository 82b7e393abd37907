"""The package layout (docs/architecture.md), checked from the source with ``ast``.

* Every module belongs to one stage of the data flow; a module imports only from its own stage
  and the stages below it (the table ``MAY_IMPORT``), including imports inside functions.
* There is no import cycle between modules, counting the package ``__init__`` modules that an
  import runs (importing ``aeroservo.stability.pk`` also runs ``aeroservo/stability/__init__``).
* No module of ``src/`` is longer than 400 lines.
"""

import ast
from pathlib import Path

import pytest
from conftest import ROOT

SRC = ROOT / "src" / "aeroservo"
MAX_LINES = 400

BASE = (
    "aeroservo.errors",
    "aeroservo._threads",
    "aeroservo._version",
    "aeroservo.atomic",
    "aeroservo._c_stdout",
    "aeroservo._lazy",
    "aeroservo._figures",
    "aeroservo.result_shape",
)
ORDER = [
    "base",
    "structure",
    "aero",
    "system",
    "stability",
    "linear",
    "design",
    "simulate",
    "plots",
    "studies",
    "files",
    "cli",
]
BELOW = {s: set(ORDER[: i + 1]) for i, s in enumerate(ORDER)}
MAY_IMPORT = {
    **BELOW,
    # structure and aerodynamics are independent of each other; stability and linear models
    # are two uses of the same system, independent of each other
    "structure": {"base", "structure"},
    "aero": {"base", "aero"},
    "linear": {"base", "structure", "aero", "system", "linear"},
}
"""Stage -> stages its modules may import."""


def module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


MODULES = {module_name(p): p for p in sorted(SRC.rglob("*.py"))}


def stage(mod: str) -> str:
    if mod in BASE:
        return "base"
    if mod in ("aeroservo", "aeroservo.__main__") or mod.startswith("aeroservo.cli"):
        return "cli"
    if mod == "aeroservo.plots":
        return "plots"
    sub = mod.split(".")[1]
    assert sub in ORDER, f"{mod}: not in a stage of the layout (tests/test_architecture.py)"
    return sub


def _is_package(mod: str) -> bool:
    return MODULES[mod].name == "__init__.py"


def imports(mod: str) -> set[str]:
    """Modules of the package that importing ``mod`` runs directly (parents included)."""
    tree = ast.parse(MODULES[mod].read_text(encoding="utf-8"))
    here = mod if _is_package(mod) else mod.rsplit(".", 1)[0]
    found: set[str] = set()
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here.split(".")
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            targets = [target]
            for a in node.names:  # `from pkg import submodule`
                if f"{target}.{a.name}" in MODULES:
                    targets.append(f"{target}.{a.name}")
        for t in targets:
            if t != "aeroservo" and not t.startswith("aeroservo."):
                continue
            assert t in MODULES, f"{mod}: imports {t}, which does not exist"
            found.add(t)
            # the packages an import runs, except those already running (ancestors of mod)
            parts = t.split(".")
            for i in range(2, len(parts)):
                parent = ".".join(parts[:i])
                if not (mod == parent or mod.startswith(parent + ".")):
                    found.add(parent)
    found.discard(mod)
    return found


GRAPH = {m: imports(m) for m in MODULES}


def upward_imports(mod: str, targets) -> list[str]:
    """The imports of ``mod`` (the modules ``targets``) that its stage may not make, each as
    one message naming both modules and their stages."""
    s = stage(mod)
    return [
        f"{mod} ({s}) imports {t} ({stage(t)}); a {s} module may import only "
        f"{sorted(MAY_IMPORT[s])}"
        for t in sorted(targets)
        if stage(t) not in MAY_IMPORT[s]
    ]


def import_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components of a module graph that hold more than one
    module: the import cycles, each as its sorted modules."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    cycles = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return cycles


@pytest.mark.parametrize("mod", sorted(MODULES))
def test_imports_only_go_down_the_stages(mod):
    assert upward_imports(mod, GRAPH[mod]) == []


def test_no_import_cycles():
    """The module graph's strongly connected components: all of size one."""
    assert import_cycles(GRAPH) == []


def test_the_checker_sees_a_cycle_and_an_upward_import():
    """The checks above are not vacuous: the graph has the edges we know of, and the two
    checkers report a cycle and an upward import once one edge is added to the real graph."""
    low, high = "aeroservo.stability.boundary", "aeroservo.design.closed_loop"
    assert low in GRAPH[high]
    assert "aeroservo.stability" in GRAPH[high]  # package run
    assert stage("aeroservo.files.scenario_file") == "files"
    assert "studies" not in MAY_IMPORT["simulate"]

    # the stability boundary importing the closed-loop boundary, which imports it: one cycle,
    # through the two of them
    cyclic = {**GRAPH, low: GRAPH[low] | {high}}
    cycles = import_cycles(cyclic)
    assert len(cycles) == 1 and {low, high} <= set(cycles[0]), cycles
    # a ring of three modules, and a fourth that only enters it
    ring = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert import_cycles(ring) == [["a", "b", "c"]]

    # that edge is also an upward import: stability may not import design
    (message,) = upward_imports(low, cyclic[low])
    assert message.startswith(f"{low} (stability) imports {high} (design)")
    # and the import the layout forbids by name: simulate importing studies
    (message,) = upward_imports("aeroservo.simulate.march", {"aeroservo.studies.runs"})
    assert "(simulate) imports aeroservo.studies.runs (studies)" in message


@pytest.mark.parametrize("mod", sorted(MODULES))
def test_module_size(mod):
    n = len(MODULES[mod].read_text(encoding="utf-8").splitlines())
    assert n <= MAX_LINES, f"{MODULES[mod]}: {n} lines; split it by job (limit {MAX_LINES})"


def test_lazy_packages_have_no_name_shadowed_by_a_module():
    """A lazily exported name equal to a submodule's name would resolve to the module once the
    submodule is imported (PEP 562 ``__getattr__`` is then never called)."""
    import importlib

    for mod in MODULES:
        path = MODULES[mod]
        if path.name != "__init__.py" or "lazy_attributes" not in path.read_text():
            continue
        pkg = importlib.import_module(mod)
        submodules = {p.stem for p in path.parent.glob("*.py")} | {
            p.name for p in path.parent.iterdir() if (p / "__init__.py").exists()
        }
        clash = set(getattr(pkg, "_PUBLIC", {})) & submodules
        assert not clash, f"{mod}: lazy names shadowed by modules {sorted(clash)}"
