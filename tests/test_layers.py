"""The package's layers import only downward, and no module imports itself back through a cycle.

Layers, lowest first (docs/architecture.md)::

    utils < core < config < sim < render < envs < policies < evaluation < training
          < experiments < cli

Every ``import`` counts, at module top or inside a function. The package root
(``frontier_marl/__init__.py``, ``__main__.py``) is the public face and may import any layer.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "frontier_marl"
LAYERS = (
    "utils",
    "core",
    "config",
    "sim",
    "render",
    "envs",
    "policies",
    "evaluation",
    "training",
    "experiments",
    "cli",
)
ROOT_MODULES = {"frontier_marl", "frontier_marl.__main__"}


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_modules(path: Path) -> list[tuple[int, str]]:
    """(line, module) of every frontier_marl import in ``path``, top-level or not."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module.startswith("frontier_marl"):
                for alias in node.names:
                    # "from frontier_marl.x import y" may import submodule y
                    found.append((node.lineno, f"{node.module}.{alias.name}"))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("frontier_marl"):
                    found.append((node.lineno, alias.name))
    return found


def layer_of(module: str) -> int | None:
    parts = module.split(".")
    if len(parts) < 2 or parts[1] not in LAYERS:
        return None
    return LAYERS.index(parts[1])


def modules() -> dict[str, Path]:
    return {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def resolve(target: str, known: dict[str, Path]) -> str | None:
    """The package module that ``target`` (maybe ``module.attribute``) names."""
    while target and target not in known:
        target = target.rpartition(".")[0]
    return target or None


def test_every_module_belongs_to_a_layer():
    strays = [m for m in modules() if m not in ROOT_MODULES and layer_of(m) is None]
    assert not strays, f"modules outside the layers {LAYERS}: {strays}"


def test_layers_import_only_downward():
    known = modules()
    upward = []
    for name, path in known.items():
        if name in ROOT_MODULES:
            continue
        own = layer_of(name)
        for line, target in imported_modules(path):
            other = layer_of(resolve(target, known) or "")
            if other is not None and other > own:
                upward.append(f"{path.relative_to(PACKAGE.parent)}:{line} imports {target}")
    assert not upward, "upward imports:\n" + "\n".join(upward)


def test_no_import_cycles():
    known = modules()
    graph = {
        name: {resolve(t, known) for _, t in imported_modules(path)} - {None, name}
        for name, path in known.items()
    }
    cycles = find_cycles(graph)
    assert not cycles, "import cycles:\n" + "\n".join(" -> ".join(c) for c in cycles)


def find_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """One cycle per strongly connected component with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(graph.get(node, ())):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                components.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return components


@pytest.mark.parametrize(
    ("graph", "expected"),
    [
        ({"a": {"b"}, "b": {"c"}, "c": set()}, []),
        ({"a": {"b"}, "b": {"a"}}, [["a", "b"]]),
        ({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}, [["a", "b", "c"]]),
    ],
)
def test_find_cycles_on_small_graphs(graph, expected):
    assert find_cycles(graph) == expected
