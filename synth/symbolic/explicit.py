"""The explicit nodes and edges a symbolic report shows.

Both symbolic paths decide on BDDs (:mod:`synth.symbolic.verdicts`), then make explicit
:class:`~synth.validation.sync.Node` objects of the few nodes a report shows (initial
nodes, trace nodes, component members), numbered as they are asked for, so the existing diagnosis and output run on a small
:class:`~synth.validation.sync.Sync` unchanged.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> from synth.grafcet.machine import GrafcetMachine
>>> from synth.sup.constraints import CompiledConstraints
>>> from synth.symbolic.situations.sync import symbolic_sync
>>> rs, p, g = load_model(_plants("../grafcets/tri.g7"), _plants("tri.rules"))
>>> s = symbolic_sync(p, rs.constraints, GrafcetMachine(g))
>>> ex = ExplicitNodes(s, CompiledConstraints(p, rs.constraints))
>>> ex.node((0, p.initial)), ex.node((0, p.initial)), len(ex.nodes)
(0, 0, 1)
"""

from __future__ import annotations

from typing import Callable

from synth.plant.composition import Plant
from synth.sup.constraints import CompiledConstraints
from synth.symbolic.interface import Key, Numbered, Path, PathKey
from synth.validation.analysis import Trace
from synth.validation.sync import Edge, Node, Prohibition, moves_by_order

__all__ = ["ExplicitNodes", "Blocking"]

Blocking = tuple[list[int], dict[int, tuple[int, ...]], dict[int, Trace], dict[int, int]]


class ExplicitNodes:
    """The explicit nodes and edges a report needs, numbered as they are asked for."""

    def __init__(self, numbering: Numbered, oracle: CompiledConstraints) -> None:
        self.numbering = numbering
        self.p: Plant = numbering.plant
        self.oracle = oracle
        self.moves = moves_by_order(self.p)
        self.nodes: list[Node] = []
        self.index: dict[Key, int] = {}
        self.edges: list[Edge] = []
        self._edges: set[tuple[int, str, int]] = set()

    def node(self, key: Key) -> int:
        i = self.index.get(key)
        if i is not None:
            return i
        s, local = key
        sit = self.numbering.situations[s]
        machine = self.numbering.machine
        inputs = {n: v for n, v in self.p.valuation(local).items() if n in machine.inputs}
        wanted = machine.orders(sit, inputs)
        val = self.p.valuation(local)
        refused: list[Prohibition] = []
        for order in sorted(self.moves):
            if val[order] == (order in wanted):
                continue
            for t in self.moves[order]:
                if t.src != local[t.axis]:
                    continue
                ok, why = self.oracle.move(t, local)
                if not ok:
                    refused.append(Prohibition(t.event, tuple(why)))
        ords = tuple(sorted(o for o in wanted if val.get(o, False)))
        self.index[key] = len(self.nodes)
        self.nodes.append(Node(sit, local, frozenset(wanted), ords, tuple(sorted(refused))))
        return self.index[key]

    def blocking(self, found: list[tuple[int, PathKey, Key, list[Key]]], trace: Callable[[Key], Trace],
                 comes_back: Callable[[Key], bool]) -> Blocking:
        """The blocking findings (distance, then path, then their node), made explicit: the
        nodes, each one's component, its trace, and the first node of that trace from which
        home cannot be reached again."""
        found.sort(key=lambda f: (f[0], f[1]))
        blocking: list[int] = []
        components: dict[int, tuple[int, ...]] = {}
        traces: dict[int, Trace] = {}
        no_return: dict[int, int] = {}
        for _, _, key, members in found:
            b = self.node(key)
            blocking.append(b)
            components[b] = tuple(sorted(self.node(k) for k in members))
            traces[b] = trace(key)
            keys = {v: k for k, v in self.index.items()}
            no_return[b] = next((n for n in traces[b].nodes if not comes_back(keys[n])), b)
        return blocking, components, traces, no_return

    def trace_of(self, path: Path) -> Trace:
        """``path`` (symbolic nodes and events) as a trace, its nodes and edges made explicit."""
        ids = [self.node(k) for k in path.nodes]
        for a, e, b in zip(ids, path.events, ids[1:]):
            if (a, e, b) not in self._edges:
                self._edges.add((a, e, b))
                self.edges.append(Edge(a, e, b))
        return Trace(tuple(ids), tuple(path.events))
