"""The shape of the code base (docs/architecture.md): no import cycle among synth's modules
nor between its rooms (packages), counting the imports made inside functions and under
``TYPE_CHECKING``; every room imports only what lies below it in the documented order; no
module reads another object's private members; no module grows past the size one concept
fills; the CLI modules only parse, call and print.

The imports are read from the source with :mod:`ast` (every ``import`` and ``from … import``
anywhere in a module, relative ones resolved), so a deferred import cannot hide a cycle.
"""

from __future__ import annotations

import ast
import functools
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


@functools.cache
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


# The documented order of the rooms (docs/architecture.md), bottom first. The ground floor's
# modules import no room (the chooser's enum, the errors, the frozen dataclasses, lark's shared scanner,
# the lazy re-exports, the version);
# ``syntax`` builds the expressions of ``logic`` (its shared expression rules), so it stands
# right above it. ``synth`` itself (an empty package) and ``__main__`` (``python -m synth``)
# stand on top.
GROUND = ("synth.choices", "synth.errors", "synth.frozen", "synth.lexing", "synth._lazy", "synth.version")
ORDER = ("synth.logic", "synth.syntax", "synth.plant", "synth.sup", "synth.grafcet", "synth.validation",
         "synth.symbolic", "synth.probe", "synth.engines", "synth.filter", "synth.codegen", "synth.output", "synth.commission",
         "synth.line", "synth.cli", "synth.__main__", "synth")
LEVEL = {**{r: 0 for r in GROUND}, **{r: i for i, r in enumerate(ORDER, 1)}}

# room → rooms it may not import (its own or any of their modules): every room above it
FORBIDDEN = {room: tuple(r for r in LEVEL if LEVEL[r] > LEVEL[room]) for room in LEVEL}
# and below it, where a room may use only part of a lower one: the filter's closed loop on BDDs
# (synth.filter.loop.symbolic) encodes the plant with the symbolic engine's BDD layer, and only
# with it (issue 23, build 2); the rest of the symbolic engine stays out of the filter
FORBIDDEN["synth.filter"] += ("synth.symbolic",)
ALLOWED = {("synth.filter", "synth.symbolic.encoding"), ("synth.filter", "synth.symbolic.relation")}


def room_of(module: str) -> str:
    """The room of a module: ``synth.x`` for every module of the package ``synth/x/``, the
    module itself for a module directly in ``synth/``."""
    return ".".join(module.split(".")[:2])


def room_graph(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """Who imports whom among the rooms (an import between two of a room's modules is not an edge)."""
    out: dict[str, set[str]] = {}
    for m, targets in graph.items():
        out.setdefault(room_of(m), set()).update(room_of(t) for t in targets if room_of(t) != room_of(m))
    return out


def test_every_room_has_its_place_in_the_order() -> None:
    assert set(room_graph(import_graph())) == set(LEVEL)


def test_no_import_cycle_between_rooms() -> None:
    rooms = room_graph(import_graph())
    assert len(rooms) == len(LEVEL) and sum(map(len, rooms.values())) > 30  # the walk is not vacuous
    assert cycles(rooms) == []


def test_the_room_cycle_finder_sees_a_cycle_through_deferred_imports(tmp_path) -> None:
    """A circle made only of imports inside a function and under ``TYPE_CHECKING``."""
    (tmp_path / "a.py").write_text("def f():\n    from synth.b.y import g\n", encoding="utf-8")
    (tmp_path / "b.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import synth.a.x\n",
                                   encoding="utf-8")
    known = {"synth.a.x", "synth.b.y"}
    graph = {"synth.a.x": imports_of("synth.a.x", tmp_path / "a.py", known),
             "synth.b.y": imports_of("synth.b.y", tmp_path / "b.py", known)}
    assert cycles(room_graph(graph)) == [["synth.a", "synth.b"]]


@pytest.mark.parametrize("room", sorted(FORBIDDEN))
def test_rooms_import_only_what_lies_below(room: str) -> None:
    graph = import_graph()
    bad = sorted(
        (m, t) for m, ts in graph.items() if room_of(m) == room
        for t in ts if room_of(t) in FORBIDDEN[room] and (room, t) not in ALLOWED
    )
    assert bad == []


def test_no_module_over_the_size_of_one_concept() -> None:
    sizes = {n: len(p.read_text(encoding="utf-8").splitlines()) for n, p in modules().items()}
    assert {n: s for n, s in sizes.items() if s > MAX_LINES} == {}


# --------------------------------------------------------------------------- privates

def private_reaches(name: str, source: str) -> list[str]:
    """Every ``x._private`` of the module ``name`` (read or written; ``__dunder__`` names
    are public) whose ``x`` is not ``self`` or ``cls`` nor one of the module's own
    module-level names: its own classes' members stay inside the module (the ST
    interpreter's class-level dispatch tables, ``ExpressionCompiler._boolean``, are of
    this kind), anything else reaches into another module's object."""
    tree = ast.parse(source)
    own = {"self", "cls"}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            own.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            for target in node.targets if isinstance(node, ast.Assign) else [node.target]:
                own.update(n.id for n in ast.walk(target) if isinstance(n, ast.Name))
    return sorted(
        f"{name}: {ast.unparse(node)}" for node in ast.walk(tree)
        if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.endswith("__")
        and not (isinstance(node.value, ast.Name) and node.value.id in own))


def test_the_private_scan_sees_a_reach_and_spares_self_and_own_names() -> None:
    source = ("class K:\n    _table = {}\n    def f(self, other):\n        return self._a, K._table, other._b\n"
              "def g(m):\n    m._c = 1\n    return m.__class__, cls_of(m)._d\n")
    assert private_reaches("synth.x", source) == ["synth.x: cls_of(m)._d", "synth.x: m._c", "synth.x: other._b"]


# The one module allowed to reach into another library's internals: synth.logic.native calls
# CUDD's combined and-abstract on dd's own nodes (dd has no call that takes a ready-made cube),
# so it converts between dd's variables, indices and node pointers with dd's private helpers;
# it checks dd's object layout first and falls back to dd's public calls when it differs.
THIRD_PARTY_INTERNALS = ["synth.logic.native: bdd._index_of_var", "synth.logic.native: bdd._var_with_index",
                         "synth.logic.native: self.bdd._add_int"]


def test_no_module_reads_another_objects_private_members() -> None:
    found = [r for n, p in modules().items() for r in private_reaches(n, p.read_text(encoding="utf-8"))]
    assert found == THIRD_PARTY_INTERNALS


def test_the_tests_share_one_root() -> None:
    """Every test module takes ``ROOT`` from conftest.py instead of computing its own."""
    own = [p.name for p in sorted((ROOT / "tests").glob("*.py"))
           if p.name != "conftest.py" and any(line.startswith("ROOT = ") for line in p.read_text("utf-8").splitlines())]
    assert own == []


def test_no_module_imports_another_modules_private_names() -> None:
    """``from synth.x import _name`` reaches into another module as ``obj._name`` does."""
    found = sorted(
        f"{n}: from {node.module} import {a.name}" for n, p in modules().items()
        for node in ast.walk(ast.parse(p.read_text(encoding="utf-8")))
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("synth")
        for a in node.names if a.name.startswith("_") and not a.name.startswith("__"))
    assert found == []


def test_families_live_in_folders_not_in_name_prefixes() -> None:
    """No folder holds four or more modules whose names start alike over four letters or more
    (``plcopen_*``, ``step*``): a family of four gets a folder of its own (a language's model,
    reader and checker are three)."""
    crowded = {}
    for folder in sorted({p.parent for p in SYNTH.rglob("*.py")}):
        stems = [p.stem for p in folder.glob("*.py") if p.stem != "__init__"]
        for prefix in {s[:4] for s in stems if len(s) >= 4}:
            family = sorted(s for s in stems if s.startswith(prefix))
            if len(family) >= 4:
                crowded[f"{folder.relative_to(ROOT)}/{prefix}*"] = family
    assert crowded == {}
