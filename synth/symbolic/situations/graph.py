"""The aggregated automaton of a symbolic SYNC: its nodes (per situation, a BDD of plant
states), its edges (bundles per event, links per pair of situations) and the walks the
verdicts need (pre- and post-images, backward and forward fixpoints, onion rings).

:class:`~synth.symbolic.situations.sync.SymbolicSync` explores SYNC and fills a :class:`SyncGraph`;
:mod:`synth.symbolic.situations.reach` reads it.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> from synth.grafcet.machine import GrafcetMachine
>>> from synth.symbolic.situations.sync import symbolic_sync
>>> rs, p, g = load_model(_plants("../grafcets/tri.g7"), _plants("tri.rules"))
>>> s = symbolic_sync(p, rs.constraints, GrafcetMachine(g))
>>> s.backward(s.initial) == {k: u for k, u in s.nodes().items()}  # every node comes back home
True
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable

from synth.grafcet.machine import Situation
from synth.logic.bdd import Function
from synth.logic.events import Event
from synth.symbolic.encoding import Copy, PlantEncoding
from synth.symbolic.relation import Move

__all__ = ["NodeSet", "Bundle", "Link", "Region", "SyncGraph"]

NodeSet = dict[int, Function]  # situation index -> plant states (current copy)


@dataclass(frozen=True)
class Bundle:
    """Edges ``source --event--> target``: from the nodes of situation ``source`` whose
    move (or timer) leads to an entry in ``entries``, to the settled states of those
    entries' regions in situation ``target``. ``move`` is None for a timer."""

    source: int
    event: Event
    target: int
    entries: Function  # freed (false) once ``edges`` is computed
    move: Move | None
    key: tuple[int, int]  # exploration order of the event: (0, plant transition) or (1, timer rank)
    edges: Function | None = None  # (x, x'): node x of source --event--> node x' of target, once explored


@dataclass(frozen=True)
class Link:
    """Every edge from situation ``source`` to situation ``target``, whatever the event,
    as one pair relation ``edges(x, x')``."""

    source: int
    target: int
    edges: Function


@dataclass
class Region:
    """A situation's region relation and its sets (grown as new entries arrive)."""

    entered: Function
    pairs: Function  # reg(x, x'): entry x settles in x'
    members: Function
    nodes: Function
    by_orders: dict[frozenset[str], Function] = field(default_factory=dict)  # nodes per emitted orders


class SyncGraph:
    """Situations, their regions (whose ``nodes`` are the aggregated states) and the
    edges between them, once :meth:`link` has indexed the bundles."""

    def __init__(self, enc: PlantEncoding) -> None:
        self.enc = enc
        self.engine = enc.engine
        self.false = self.engine.false
        self.true = self.engine.true
        self.situations: list[Situation] = []
        self.regions: list[Region] = []
        self.bundles: list[Bundle] = []
        self.links: list[Link] = []
        self.rings: list[NodeSet] = []
        self.initial: NodeSet = {}
        self.edge_count = 0
        self._sync_states = 0
        self._into: dict[int, list[Link]] = {}
        self._from: dict[int, list[Link]] = {}
        self._out: dict[int, list[Bundle]] = {}

    def link(self, bundles: list[Bundle]) -> None:
        """Take the explored ``bundles`` (their pair relations computed): merge them per
        pair of situations into links, count the transitions, index both."""
        self.bundles = bundles
        links: dict[tuple[int, int], Function] = {}
        overlapping: set[tuple[int, int]] = set()  # links whose bundles share a pair of nodes
        for b in self.bundles:
            key = (b.source, b.target)
            old = links.get(key)
            if old is None:
                links[key] = b.edges
            else:
                if key not in overlapping and (old & b.edges) != self.false:
                    overlapping.add(key)
                links[key] = old | b.edges
        self.links = [Link(a, t, e) for (a, t), e in sorted(links.items())]
        # a transition per bundle and pair of nodes: one count per link whose bundles are disjoint
        self.edge_count = sum(self.enc.count(e, (Copy.CURRENT, Copy.NEXT)) for k, e in links.items() if k not in overlapping)
        self.edge_count += sum(self.enc.count(b.edges, (Copy.CURRENT, Copy.NEXT)) for b in self.bundles
                               if (b.source, b.target) in overlapping)
        for link in self.links:
            self._into.setdefault(link.target, []).append(link)
            self._from.setdefault(link.source, []).append(link)
        for b in self.bundles:
            self._out.setdefault(b.source, []).append(b)

    def post_pairs(self, sources: Function, pairs: Function) -> Function:
        """The x' of the pairs ``(x, x')`` whose x is in ``sources``, as current states."""
        return self.enc.rename(self.enc.and_exists(sources, pairs, Copy.CURRENT), Copy.NEXT, Copy.CURRENT)

    def onion_rings(self) -> list[NodeSet]:
        """The nodes by distance from the initial nodes (breadth-first over the links),
        computed once, on demand: only traces need them."""
        if self.rings or not self.initial:
            return self.rings
        seen: NodeSet = dict(self.initial)
        ring: NodeSet = dict(self.initial)
        while ring:
            self.rings.append(ring)
            new: NodeSet = {}  # targets in the next copy, renamed once per situation below
            for s in sorted(ring):
                for link in self.out_links(s):
                    u = self.enc.and_exists(link.edges, ring[s], Copy.CURRENT)
                    if u != self.false:
                        new[link.target] = new.get(link.target, self.false) | u
            ring = {}
            for s, u in new.items():
                known: Function = seen.get(s, self.false)
                u = self.enc.rename(u, Copy.NEXT, Copy.CURRENT) & ~known
                if u != self.false:
                    ring[s] = u
                    seen[s] = seen.get(s, self.false) | u
        return self.rings

    # ------------------------------------------------------------------ counts
    @property
    def sync_states(self) -> int:
        return self._sync_states

    @property
    def aggregated_states(self) -> int:
        return sum(self.enc.count(r.nodes) for r in self.regions)

    @property
    def aggregated_transitions(self) -> int:
        return self.edge_count

    # ------------------------------------------------------------------ the aggregated graph
    def pre(self, targets: NodeSet, arcs: Iterable[Link | Bundle] | None = None) -> NodeSet:
        """Nodes with an edge (of ``arcs``: links or bundles, default every link) into ``targets``."""
        out: NodeSet = {}
        if arcs is None:
            arcs = [link for t in targets for link in self._into.get(t, ())]
        primed: NodeSet = {}  # each target renamed once, whatever the number of arcs into it
        for a in arcs:
            t = primed.get(a.target)
            if t is None:
                t = targets.get(a.target)
                if t is None or t == self.false:
                    continue
                t = primed[a.target] = self.enc.rename(t, Copy.CURRENT, Copy.NEXT)
            src = self.enc.and_exists(a.edges, t, Copy.NEXT)
            if src != self.false:
                out[a.source] = out.get(a.source, self.false) | src
        return out

    def post(self, sources: NodeSet, a: Link | Bundle) -> Function:
        """Targets (nodes of ``a.target``) of the edges of ``a`` from ``sources``."""
        src = sources.get(a.source)
        if src is None or src == self.false:
            return self.false
        return self.post_pairs(src, a.edges)

    def into(self, target: int) -> list[Link]:
        return self._into.get(target, [])

    def out_bundles(self, source: int) -> list[Bundle]:
        return self._out.get(source, [])

    def out_links(self, source: int) -> list[Link]:
        return self._from.get(source, [])

    def backward(self, targets: NodeSet, within: NodeSet | None = None) -> NodeSet:
        """Nodes from which ``targets`` can be reached (targets included): a worklist
        fixpoint over the situations whose set grew."""
        reached: NodeSet = {s: u for s, u in targets.items() if u != self.false}
        work = sorted(reached)
        while work:
            s = work.pop()
            for t, u in self.pre({s: reached[s]}, self.into(s)).items():
                if within is not None:
                    u &= within.get(t, self.false)
                old: Function = reached.get(t, self.false)
                grown = u & ~old
                if grown != self.false:
                    reached[t] = old | grown
                    if t not in work:
                        work.append(t)
        return reached

    def forward(self, sources: NodeSet) -> NodeSet:
        """Nodes reachable from ``sources`` (included)."""
        reached: NodeSet = {s: u for s, u in sources.items() if u != self.false}
        work = sorted(reached)
        while work:
            s = work.pop()
            for link in self.out_links(s):
                u = self.post({s: reached[s]}, link)
                old: Function = reached.get(link.target, self.false)
                grown = u & ~old
                if grown != self.false:
                    reached[link.target] = old | grown
                    if link.target not in work:
                        work.append(link.target)
        return reached

    def nodes(self) -> NodeSet:
        return {s: r.nodes for s, r in enumerate(self.regions) if r.nodes != self.false}
