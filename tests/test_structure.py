"""The shape of the code base (docs/architecture.md): no import cycle among synth's modules,
counting the imports made inside functions; the rooms import only what lies below them; no
module grows past the size one concept fills; the CLI modules only parse, call and print.

The imports are read from the source with :mod:`ast` (every ``import`` and ``from … import``
anywhere in a module, relative ones resolved), so a deferred import cannot hide a cycle.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from conftest import ROOT

SYNTH = ROOT / "synth"
MAX_LINES = 450


def module_name(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def modules() -> dict[str, Path]:
    return {module_name(p): p for p in sorted(SYNTH.rglob("*.py"))}


def imports_of(name: str, path: Path, known: set[str]) -> set[str]:
    """The synth modules ``name`` imports (``from synth.x import y`` counts ``synth.x.y``
    when that is a module, else ``synth.x``); package ``__init__`` re-exports are not
    followed (they are lazy: see synth/_lazy.py)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = package.split(".")
                up = up[: len(up) - node.level + 1]
                base = ".".join(up + ([base] if base else []))
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in node.names]
        else:
            continue
        for t in targets:
            while t and t not in known:
                t = t.rpartition(".")[0]
            if t.startswith("synth") and t != name:
                out.add(t)
    return out


def import_graph() -> dict[str, set[str]]:
    mods = modules()
    known = set(mods)
    return {n: imports_of(n, p, known) for n, p in mods.items()}


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (networkx, a test
    dependency: no third hand-written Tarjan beside ``validation/analysis.py``)."""
    import networkx as nx

    g = nx.DiGraph()
    g.add_nodes_from(graph)
    g.add_edges_from((a, b) for a, targets in graph.items() for b in targets if b in graph)
    return sorted(sorted(c) for c in nx.strongly_connected_components(g) if len(c) > 1)


def test_the_cycle_finder_finds_a_cycle() -> None:
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_cycle_among_synth_modules() -> None:
    graph = import_graph()
    assert len(graph) > 50  # the walk is not vacuous
    assert cycles(graph) == []


# room → rooms it may not import (its own or any of their modules)
FORBIDDEN = {
    "synth.validation": ("synth.symbolic", "synth.filter", "synth.codegen", "synth.output", "synth.cli"),
    "synth.symbolic": ("synth.filter", "synth.codegen", "synth.output", "synth.cli"),
    "synth.logic": ("synth.plant", "synth.sup", "synth.grafcet", "synth.validation", "synth.symbolic",
                    "synth.filter", "synth.codegen", "synth.output", "synth.cli"),
    "synth.filter": ("synth.codegen", "synth.output", "synth.cli", "synth.symbolic"),
    "synth.output": ("synth.cli", "synth.commission"),
    "synth.commission": ("synth.cli",),
}

# (room, module) exceptions: the symbolic closed loop of ``filter verify`` (synth.filter.symbolic_*)
# encodes the plant with the symbolic engine's BDD layer, and only with it (issue 23, build 2)
ALLOWED = {("synth.filter", "synth.symbolic.encoding"), ("synth.filter", "synth.symbolic.relation")}


@pytest.mark.parametrize("room", sorted(FORBIDDEN))
def test_rooms_import_only_what_lies_below(room: str) -> None:
    graph = import_graph()
    bad = sorted(
        (m, t) for m, ts in graph.items() if m == room or m.startswith(room + ".")
        for t in ts if any(t == f or t.startswith(f + ".") for f in FORBIDDEN[room]) and (room, t) not in ALLOWED
    )
    assert bad == []


def test_no_module_over_the_size_of_one_concept() -> None:
    sizes = {n: len(p.read_text(encoding="utf-8").splitlines()) for n, p in modules().items()}
    assert {n: s for n, s in sizes.items() if s > MAX_LINES} == {}
