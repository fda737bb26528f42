"""Imports flow one way, down the layer list of docs/architecture.md, and form no cycle.

Every ``import skyroute...`` is read from the source (module level and inside functions
alike, so an import moved into a function cannot hide a cycle or an upward step).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "skyroute"

# Bottom first. A module may import its own layer (without cycles) and the ones below.
LAYERS = [
    {"errors", "keywords", "result", "geo", "caches", "files", "lazy", "blas_probe", "version"},
    {"world"},
    {"search"},
    {"roadmap", "planner", "world_plan"},
    {"motion"},
    {"delivery", "fleet"},
    {"io"},
    {"bench", "jobs"},
    {"cli", "service", "__main__", "__init__"},
]
RANK = {name: i for i, names in enumerate(LAYERS) for name in names}


def module_name(path: Path) -> str:
    parts = path.relative_to(SRC.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict[str, Path]:
    return {module_name(p): p for p in sorted(SRC.rglob("*.py"))}


def resolve(name: str, known: dict[str, Path]) -> str:
    """The module an imported name lives in (a package's __init__ for a package)."""
    while name not in known and "." in name:
        name = name.rsplit(".", 1)[0]
    return name


def imports(path: Path, known: dict[str, Path]) -> set[str]:
    """The skyroute modules ``path`` imports anywhere in its body."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            # "from skyroute.search import heap" imports the module skyroute.search.heap
            names = [f"{node.module}.{a.name}" for a in node.names]
        else:
            continue
        out |= {resolve(n, known) for n in names if n.split(".")[0] == "skyroute"}
    return out


def layer_of(module: str) -> int:
    parts = module.split(".")
    top = parts[1] if len(parts) > 1 else "__init__"
    if top not in RANK:
        raise AssertionError(f"{module}: {top!r} is in no layer; add it to LAYERS and to "
                             "docs/architecture.md")
    return RANK[top]


def graph() -> dict[str, set[str]]:
    known = modules()
    return {m: imports(p, known) - {m} for m, p in known.items()}


def test_every_module_has_a_layer():
    for m in graph():
        layer_of(m)


def test_imports_never_go_up_a_layer():
    bad = [f"{m} (layer {layer_of(m)}) imports {d} (layer {layer_of(d)})"
           for m, deps in graph().items() for d in sorted(deps)
           if layer_of(d) > layer_of(m) and m != "skyroute"]
    assert not bad, "\n".join(bad)


def find_cycle(g: dict[str, set[str]]) -> list[str] | None:
    """One import cycle of ``g`` (a list of modules, first repeated last), or None."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(u: str) -> list[str] | None:
        state[u] = 1
        stack.append(u)
        for v in sorted(g.get(u, ())):
            if v == "skyroute":  # the package root re-exports; it imports everything
                continue
            if state.get(v) == 1:
                return [*stack[stack.index(v):], v]
            if v not in state and (c := visit(v)):
                return c
        state[u] = 2
        stack.pop()
        return None

    for u in sorted(g):
        if u not in state and (c := visit(u)):
            return c
    return None


def test_no_import_cycle():
    cycle = find_cycle(graph())
    assert cycle is None, " -> ".join(cycle)


@pytest.mark.parametrize("g, expected", [
    ({"a": {"b"}, "b": {"c"}, "c": {"a"}}, ["a", "b", "c", "a"]),
    ({"a": {"b"}, "b": {"c"}, "c": set()}, None),
])
def test_the_cycle_finder_finds_cycles(g, expected):
    assert find_cycle(g) == expected


def test_the_walk_sees_imports_inside_functions(tmp_path):
    known = modules()
    p = tmp_path / "m.py"
    p.write_text("def f():\n    from skyroute.cli import app\n    import skyroute.io.plot\n")
    assert imports(p, known) == {"skyroute.cli.app", "skyroute.io.plot"}
