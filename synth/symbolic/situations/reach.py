"""The per-situation SYNC seen through :class:`~synth.symbolic.interface.SymbolicGraph`.

A set of nodes is a BDD of plant states per stable situation (``NodeSet``), a move a
:class:`~synth.symbolic.situations.graph.Bundle` of edges between two situations.
:class:`SituationReach` gives :class:`~synth.symbolic.situations.sync.SymbolicSync` the
interface the searches (:mod:`synth.symbolic.searches`) and the report
(:mod:`synth.symbolic.verdicts`) read; the sets only this representation computes its
own way are here: *held* nodes (no node with other active steps reachable), for the
whole SYNC or node by node, and the prohibited orders per situation.

Example
-------
>>> # tests/test_symbolic_interface.py checks every set against the explicit SYNC
"""

from __future__ import annotations

from typing import Collection, Iterable, Iterator, Sequence

from synth.errors import LimitExceeded
from synth.logic.bdd import Function
from synth.logic.events import Event
from synth.logic.expr import Expr, evaluate
from synth.symbolic.interface import Key, Steps
from synth.symbolic.relation import Move
from synth.symbolic.searches import MAX_LISTED
from synth.symbolic.situations.graph import Bundle, NodeSet
from synth.symbolic.situations.sync import SymbolicSync

__all__ = ["SituationReach", "held_nodes", "node_held", "prohibited_nodes", "listed"]


def _minus(a: NodeSet, b: NodeSet, false: Function) -> NodeSet:
    out = {}
    for s, u in a.items():
        other: Function = b.get(s, false)
        r = u & ~other
        if r != false:
            out[s] = r
    return out


def _empty(a: NodeSet, false: Function) -> bool:
    return all(u == false for u in a.values())


def held_nodes(sync: SymbolicSync) -> NodeSet:
    """Nodes from which no node with other active steps is reachable."""
    changers: NodeSet = {}
    for link in sync.links:
        if sync.situations[link.source].steps == sync.situations[link.target].steps:
            continue
        src = sync.pre({link.target: sync.regions[link.target].nodes}, [link])
        for s, u in src.items():
            changers[s] = changers.get(s, sync.false) | u
    return _minus(sync.nodes(), sync.backward(changers), sync.false)


def node_held(sync: SymbolicSync, s: int, local: tuple[int, ...]) -> bool:
    """Whether node (``s``, ``local``) is held (:func:`held_nodes` for one node): a forward
    search through the situations with its active steps, stopped at the first edge
    into other active steps."""
    steps = sync.situations[s].steps
    reached: NodeSet = {s: sync.enc.state(local)}
    work = [s]
    while work:
        a = work.pop()
        for link in sync.out_links(a):
            u = sync.post({a: reached[a]}, link)
            if u == sync.false:
                continue
            if sync.situations[link.target].steps != steps:
                return False
            old: Function = reached.get(link.target, sync.false)
            if (u & ~old) != sync.false:
                reached[link.target] = old | u
                if link.target not in work:
                    work.append(link.target)
    return True


def prohibited_nodes(sync: SymbolicSync) -> dict[tuple[tuple[str, ...], Event], NodeSet]:
    """Per (active steps, refused order event), the nodes where SUP refuses it."""
    out: dict[tuple[tuple[str, ...], Event], NodeSet] = {}
    for s, r in enumerate(sync.regions):
        steps = sync.situations[s].steps
        for wanted, nodes in r.by_orders.items():
            _, _, refused = sync.intra(wanted)
            for event, bad in refused.items():
                hit = nodes & bad
                if hit != sync.false:
                    d = out.setdefault((steps, event), {})
                    d[s] = d.get(s, sync.false) | hit
    return out


def listed(sync: SymbolicSync, u: NodeSet, limit: int = MAX_LISTED) -> list[tuple[int, tuple[int, ...]]]:
    """The nodes of ``u``, situation by situation."""
    out: list[tuple[int, tuple[int, ...]]] = []
    for s in sorted(u):
        for local in sync.enc.states(u[s], limit - len(out)):
            out.append((s, local))
    if len(out) > limit:  # pragma: no cover - states() raises first
        raise LimitExceeded(f"more than {limit} nodes to list")
    return out



class SituationReach:
    """:class:`~synth.symbolic.interface.SymbolicGraph` over an explored :class:`SymbolicSync`."""

    def __init__(self, sync: SymbolicSync) -> None:
        self.sync = sync
        self.numbering = sync
        self.false = sync.false

    # ---- node-set algebra
    @property
    def empty(self) -> NodeSet:
        return {}

    def union(self, a: NodeSet, b: NodeSet) -> NodeSet:
        out = dict(a)
        for s, u in b.items():
            out[s] = out.get(s, self.false) | u
        return out

    def join(self, sets: Iterable[NodeSet]) -> NodeSet:
        out: NodeSet = {}
        for u in sets:
            for s, v in u.items():
                out[s] = out.get(s, self.false) | v
        return out

    def meet(self, a: NodeSet, b: NodeSet) -> NodeSet:
        out = {}
        for s, u in a.items():
            if s in b and (v := u & b[s]) != self.false:
                out[s] = v
        return out

    def minus(self, a: NodeSet, b: NodeSet) -> NodeSet:
        return _minus(a, b, self.false)

    def is_empty(self, a: NodeSet) -> bool:
        return _empty(a, self.false)

    def count(self, a: NodeSet) -> int:
        return sum(self.sync.enc.count(u) for u in a.values())

    # ---- the explored graph
    @property
    def initial(self) -> NodeSet:
        return self.sync.initial

    @property
    def reached(self) -> NodeSet:
        return self.sync.nodes()

    def rings(self) -> Sequence[NodeSet]:
        return self.sync.onion_rings()

    def moves_from(self, u: NodeSet) -> Iterator[Bundle]:
        for s in u:
            yield from self.sync.out_bundles(s)

    def order(self, b: Bundle) -> tuple[int, int, int]:
        """Plant moves by element and variable, then timers (by rank in their situation)."""
        if b.move is None:
            return (1, b.key[1], 0)
        e = self.sync.plant.elements[b.move.axis]
        return (0, b.move.axis, e.variables.index(b.move.variable))

    def event(self, b: Bundle) -> Event:
        return b.event

    def plant_move(self, b: Bundle) -> Move | None:
        return b.move

    def post_by(self, u: NodeSet, b: Bundle, within: NodeSet | None = None) -> NodeSet:
        if within is not None and b.target not in within:
            return {}
        v = self.sync.post(u, b)
        if within is not None:
            v &= within[b.target]
        return {b.target: v} if v != self.false else {}

    def pre_by(self, u: NodeSet, b: Bundle) -> NodeSet:
        return self.sync.pre(u, [b])

    def pre(self, u: NodeSet, within: NodeSet) -> NodeSet:
        return self.meet(self.sync.pre(u), within)

    def forward(self, u: NodeSet) -> NodeSet:
        return self.sync.forward(u)

    def backward(self, u: NodeSet, within: NodeSet | None = None) -> NodeSet:
        return self.sync.backward(u, within)

    def held(self) -> NodeSet:
        return held_nodes(self.sync)

    def is_held(self, key: Key) -> bool:
        return node_held(self.sync, *key)

    # ---- one node
    def pick(self, u: NodeSet) -> Key:
        s = min(s for s, v in u.items() if v != self.false)
        return s, self.sync.enc.one(u[s])

    def cube(self, key: Key) -> NodeSet:
        return {key[0]: self.sync.enc.state(key[1])}

    def contains(self, u: NodeSet, key: Key) -> bool:
        s, local = key
        return s in u and (u[s] & self.sync.enc.state(local)) != self.false

    def listed(self, u: NodeSet, limit: int = MAX_LISTED) -> list[Key]:
        return listed(self.sync, u, limit)

    # ---- what the report asks
    def waited(self) -> NodeSet:
        """The initial nodes, and those of the situations with the initial situation's
        steps and stored actions (its timers elapsed) at the same plant states."""
        sync = self.sync
        homes: NodeSet = dict(sync.initial)
        for s0, u in sync.initial.items():
            key = (sync.situations[s0].steps, sync.situations[s0].stored)
            for s, r in enumerate(sync.regions):
                if s != s0 and (sync.situations[s].steps, sync.situations[s].stored) == key:
                    hit = u & r.nodes
                    if hit != self.false:
                        homes[s] = homes.get(s, self.false) | hit
        return homes

    def where(self, condition: Expr) -> NodeSet:
        """Per situation, its nodes where ``condition`` holds (a step variable is a constant there)."""
        engine, owner = self.sync.engine, self.sync.plant.owner
        out: NodeSet = {}
        for s, r in enumerate(self.sync.regions):
            steps = set(self.sync.situations[s].step_variables)

            def value(name: str, steps: set[str] = steps) -> Function:
                return engine.var(name) if name in owner else (engine.true if name in steps else engine.false)

            v = evaluate(condition, value)  # a condition folding to a constant (`1`, `X0 & 0`) is a bool
            hit = ((engine.true if v else engine.false) if isinstance(v, bool) else v) & r.nodes
            if hit != self.false:
                out[s] = hit
        return out

    def prohibited(self) -> dict[tuple[Steps, Event], NodeSet]:
        return prohibited_nodes(self.sync)

    def only_steps(self, u: NodeSet, steps: Collection[Steps]) -> bool:
        return all(self.sync.situations[s].steps in steps for s in u)

    def conflicts(self) -> list[tuple[NodeSet, Event, str, tuple[str, ...]]]:
        return [({s: sources}, event, step, names) for s, sources, event, step, names in self.sync.conflicts]

    def never_leaves(self) -> bool:
        first = self.sync.situations[self.pick(self.initial)[0]].steps
        return all(sit.steps == first for sit in self.sync.situations)

    def one_per_situation(self) -> list[Key]:
        return [(s, self.sync.enc.one(r.nodes)) for s, r in enumerate(self.sync.regions) if r.nodes != self.false]

    def reached_steps(self) -> frozenset[str]:
        return frozenset(st for sit in self.sync.situations for st in sit.steps)

    def stats(self) -> dict[str, int]:
        return {"sync_states": self.sync.sync_states, "aggregated_states": self.sync.aggregated_states,
                "aggregated_transitions": self.sync.aggregated_transitions}

    def situation_count(self) -> int:
        return len(self.sync.situations)
