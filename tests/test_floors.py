"""Three floors, imports pointing down only: the core (toolkit/) imports no plugin and no command line; the plugins
import the core and not the command line; the top floor (likeme/) may import both. No cycle between rooms, and none
between the core's modules (a run-time cycle: an import inside a function counts, one for type checkers does not).

Read from the source with ``ast``: every ``import`` and ``from ... import`` statement, at any level.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import networkx as nx
import pytest

from tests.conftest import ROOT

PACKAGES = ("toolkit", "plugins", "likeme")


def _module(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module(p): p for package in PACKAGES for p in sorted((ROOT / package).rglob("*.py"))}


def _resolve(name: str) -> str | None:
    """The repository's module a dotted name is in (``toolkit.recordings.bvh.BVH`` -> ``toolkit.recordings.bvh``)."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def _imports(module: str) -> list[tuple[str, bool]]:
    """The repository's modules ``module`` imports, each with whether only for type checkers (``TYPE_CHECKING``)."""
    path = MODULES[module]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    typing_only = {id(n) for node in ast.walk(tree) if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
                   for n in ast.walk(node)}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
                base = ".".join(package[: len(package) - node.level + 1] + ([node.module] if node.module else []))
            names = [base] + [f"{base}.{a.name}" for a in node.names]
        else:
            continue
        for name in names:
            target = _resolve(name) if name.split(".")[0] in PACKAGES else None
            if target and target != module:
                found.append((target, id(node) in typing_only))
    return found


EDGES = sorted({(m, target, typing) for m in MODULES for target, typing in _imports(m)})


def _room(module: str) -> str:
    """The room a module is in: ``toolkit``, ``likeme``, ``plugins.ROOM`` (``plugins`` for the package itself)."""
    parts = module.split(".")
    return ".".join(parts[:2]) if parts[0] == "plugins" and len(parts) > 2 else parts[0]


def test_the_modules_are_found():
    assert {"toolkit.components", "toolkit.recordings.bvh", "plugins.matchers.dtw", "likeme.cli"} <= set(MODULES)
    assert ("likeme.cli", "toolkit.arguments", False) in EDGES


@pytest.mark.parametrize("floor, above", [("toolkit", ("plugins", "likeme")), ("plugins", ("likeme",))])
def test_a_floor_imports_nothing_above_it(floor, above):
    up = [f"{a} -> {b}" for a, b, _ in EDGES if a.split(".")[0] == floor and b.split(".")[0] in above]
    assert not up, f"{floor} imports from above it: {up}"


def test_no_line_of_the_core_imports_a_plugin():
    """The issue's own check: ``grep -rE "^\\s*(from|import) plugins" toolkit/`` finds nothing."""
    pattern = re.compile(r"^\s*(from|import) (plugins|likeme)\b", re.M)
    found = [str(p.relative_to(ROOT)) for m, p in MODULES.items() if m.startswith("toolkit")
             and pattern.search(p.read_text(encoding="utf-8"))]
    assert not found


def test_no_cycle_between_rooms():
    rooms = nx.DiGraph((_room(a), _room(b)) for a, b, typing in EDGES if not typing and _room(a) != _room(b))
    cycles = [sorted(c) for c in nx.strongly_connected_components(rooms) if len(c) > 1]
    assert not cycles, cycles


def test_no_cycle_between_the_cores_modules_at_run_time():
    core = nx.DiGraph((a, b) for a, b, typing in EDGES if not typing and a.startswith("toolkit") and b.startswith("toolkit"))
    core.remove_nodes_from(["toolkit"])  # the package's lazy public names (PEP 562): each imported when first used
    cycles = [sorted(c) for c in nx.strongly_connected_components(core) if len(c) > 1]
    assert not cycles, cycles
