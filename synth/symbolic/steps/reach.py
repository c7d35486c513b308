"""Findings on the SYNC over (steps, plant state): components, first nodes, shortest traces.

The reading of :mod:`synth.symbolic.situations.reach`, on one BDD per set instead of one BDD
per situation (:class:`~synth.symbolic.steps.sync.StepSync`):

- the onion rings are the exploration's levels (a level is exactly the nodes one edge
  beyond the previous ones not met before);
- *terminal components* of the stuck nodes by descent (from a node of the deepest ring,
  its forward set is terminal iff every node of it comes back);
- the *first node* of a set: least distance, then the shortest path smallest in the
  explicit exploration's order of events (element, variable), layer by layer; the
  *trace* to a node: the shortest path smallest by event name (the explicit
  breadth-first search's parent choice);
- a node is named ``(situation index, plant state)`` for
  :class:`~synth.symbolic.explicit.ExplicitNodes`, the situations numbered as they are
  named (the initial one first); where several nodes tie (the known differences of
  docs/symbolic.md), the smallest situation by its active steps (false before true,
  step declaration order), then the smallest plant state (declaration order) is taken.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> from synth.grafcet.machine import GrafcetMachine
>>> from synth.symbolic.steps.sync import step_sync
>>> rs, p, g = load_model(_plants("../tests/data/home/no_restart.g7"), _plants("../tests/data/home/cylinder.rules"))
>>> r = StepReach(step_sync(p, rs.constraints, GrafcetMachine(g)))
>>> stuck = r.s.nodes & ~r.s.backward(r.s.initial)
>>> [len(r.listed(c)) for c in r.terminal_components(stuck)]
[2]
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable, TypeVar

from synth.errors import LimitExceeded
from synth.grafcet.machine import Situation
from synth.logic.bdd import Function
from synth.logic.events import Event
from synth.symbolic.encoding import Copy, first_path
from synth.symbolic.explicit import Key, PathKey
from synth.symbolic.situations.reach import MAX_LISTED, Path, path_key
from synth.symbolic.relation import Move
from synth.symbolic.steps.encoding import step_name
from synth.symbolic.steps.sync import StepSync

if TYPE_CHECKING:  # pragma: no cover - the explicit order needs the explicit engine's region search
    from synth.symbolic.ties import Settled

__all__ = ["StepReach"]

Order = TypeVar("Order", tuple[int, int, int], Event)  # how events are ordered: by plant transition, or by name


class StepReach:
    """Named nodes and the searches the findings need, on an explored :class:`StepSync`."""

    def __init__(self, s: StepSync) -> None:
        self.s = s
        self.false = s.false
        self.situations: list[Situation] = s.helper.situations  # the explicit nodes' numbering
        self._cubes: dict[Key, Function] = {}
        self.settled: Settled | None = None
        """When set, first nodes are the explicit engine's where a region settles in
        several states (:mod:`synth.symbolic.ties`); else the smallest (:meth:`pick`)."""
        assert s.initial_situation is not None
        s.helper.situation(s.initial_situation)  # situation 0

    # ---- naming nodes
    def steps_of(self, u: Function) -> Function:
        """The situations of ``u`` (the plant state quantified)."""
        return self.s.enc.exists(u, Copy.CURRENT)

    def situations_of(self, u: Function) -> list[Situation]:
        """The situations of ``u``, sorted."""
        st = self.s.steps
        found = [st.situation({st.engine.name_of(v): bool(b) for v, b in point.items()})
                 for point in st.engine.bdd.pick_iter(self.steps_of(u), care_vars=st.names(Copy.CURRENT))]
        return sorted(found)

    def cube(self, key: Key) -> Function:
        """The node ``key`` as a BDD (cached: traces and listings ask for a node again and again)."""
        hit = self._cubes.get(key)
        if hit is None:
            s, local = key
            hit = self._cubes[key] = self.s.steps.cube(self.situations[s]) & self.s.enc.state(local)
        return hit

    def within(self, u: Function, sit: Situation) -> Function:
        """The plant states of ``u`` in situation ``sit``."""
        return self.s.steps.exists(u & self.s.steps.cube(sit), Copy.CURRENT)

    def pick(self, u: Function) -> Key:
        """The node of ``u`` (not empty) with the smallest situation, then the smallest state."""
        st = self.s.steps
        if self.s.count(u, self.s._current) == 1:  # one node: its path to 1 sets every variable
            values = first_path(self.s.engine, u)
            key = self.s.helper.situation(st.situation(values)), self.s.enc.local(values)
            self._cubes.setdefault(key, u)
            return key
        f = self.steps_of(u)
        active: dict[str, bool] = {}
        for name in st.steps:
            low = f & ~st.var(name)
            active[step_name(name)] = low == self.false
            f = low if low != self.false else f & st.var(name)
        sit = st.situation(active)
        return self.s.helper.situation(sit), self.s.enc.one(self.within(u, sit))

    def listed(self, u: Function, limit: int = MAX_LISTED) -> list[Key]:
        """The nodes of ``u``, situation by situation (sorted), states in declaration order."""
        out: list[Key] = []
        for sit in self.situations_of(u):
            if len(out) > limit:
                break
            s = self.s.helper.situation(sit)
            out += [(s, local) for local in self.s.enc.states(self.within(u, sit), limit - len(out))]
        if len(out) > limit:  # pragma: no cover - states() raises first
            raise LimitExceeded(f"more than {limit} nodes to list")
        return out

    # ---- sets
    def held(self) -> Function:
        """Nodes from which no node with other active steps is reachable."""
        s = self.s
        other = ~s.steps.equal(Copy.CURRENT, Copy.NEXT)
        changers = self.false
        for e in s._edge_relations:
            changers |= s.engine.and_exists(e, other, s._next)
        return s.nodes & ~s.backward(changers)

    def prohibited(self) -> dict[tuple[tuple[str, ...], Event], Function]:
        """Per (active steps, refused order event), the nodes where SUP refuses it."""
        out: dict[tuple[tuple[str, ...], Event], Function] = {}
        for event, refused in self.s.refused_by.items():
            hit = self.s.nodes & refused
            if hit == self.false:
                continue
            for sit in self.situations_of(hit):
                out[(sit.steps, event)] = hit & self.s.steps.cube(sit)
        return dict(sorted(out.items()))

    def _deepest(self, u: Function) -> Function:
        """One node of ``u`` from the farthest ring meeting it."""
        for ring in reversed(self.s.rings):
            v = u & ring
            if v != self.false:
                return self.cube(self.pick(v))
        raise ValueError("no node of the set is reachable")

    def terminal_components(self, stuck: Function) -> list[Function]:
        """The terminal strongly connected components of ``stuck`` (descent, as
        :func:`synth.symbolic.situations.reach.terminal_components`)."""
        comps: list[Function] = []
        candidates = stuck
        while candidates != self.false:
            v = self._deepest(candidates)
            while True:
                fwd = self.s.forward(v)
                below = fwd & ~self.s.backward(v, within=fwd)
                if below == self.false:
                    comps.append(fwd)
                    break
                v = self._deepest(below)
            candidates &= ~self.s.backward(comps[-1], within=candidates)
        return comps

    # ---- paths
    def _layers(self, target: Function, depth: int) -> list[Function]:
        rings = self.s.rings
        layers = [self.false] * (depth + 1)
        layers[depth] = target & rings[depth]
        for k in range(depth - 1, -1, -1):
            layers[k] = self.s.pre(layers[k + 1], within=rings[k])
        return layers

    def _greedy(self, layers: list[Function], order: Callable[[Move], Order], settled: "Settled | None" = None,
                ) -> tuple[list[Function], list[Event], list[Order], list[int]]:
        """Forward through ``layers``, the smallest move (by ``order``) at each ring; with
        ``settled``, each ring's set narrowed to the node the explicit engine enters first
        (:meth:`first_of`), and its rank there."""
        current = layers[0]
        ranks: list[int] = []
        if settled is not None:
            current, rank = self.first_of(current, None, settled)
            ranks.append(rank)
        chosen, events, keys = [current], [], []
        for k in range(1, len(layers)):
            options: dict[Order, tuple[Move, Function, Function]] = {}
            target = self.s._primed(layers[k])
            for m, e in self.s.edges:
                v = self.s.image(current, m, e) & target
                if v != self.false:
                    options[order(m)] = (m, e, v)
            best = min(options)
            m, e, current = options[best]
            current = self.s.unprimed(current)
            if settled is not None:
                current, rank = self.first_of(current, (self.pick(chosen[-1]), m, e), settled)
                ranks.append(rank)
            events.append(m.event)
            keys.append(best)
            chosen.append(current)
        return chosen, events, keys, ranks

    def first_of(self, u: Function, via: "tuple[Key, Move, Function] | None", settled: "Settled") -> tuple[Function, int]:
        """The node of ``u`` the explicit engine numbers first, ``u`` being nodes the
        region entered from node ``via[0]`` by move ``via[1]`` (edges ``via[2]``) settles
        in (None: the initial region), and its rank among that region's settled states
        (0 where it settles in one: no region is run explicitly; 0 and the smallest
        node past :data:`~synth.symbolic.ties.REGION_LIMIT` states)."""
        entered = self.s.initial if via is None else self.s.unprimed(self.s.image(self.cube(via[0]), via[1], via[2]))
        if self.s.count(entered, self.s._current) == 1:
            return u, 0
        parent, move = (None, None) if via is None else via[:2]
        found = settled.first(parent, None if move is None else move.event, move,
                              lambda key: (self.cube(key) & u) != self.false)
        if found is None:  # a region too large to run explicitly: the smallest node
            return self.cube(self.pick(u)), 0
        return self.cube(found[0]), found[1]

    def _key(self, m: Move) -> tuple[int, int, int]:
        return (0, m.axis, self.s.plant.elements[m.axis].variables.index(m.variable))

    def depth(self, u: Function) -> int | None:
        for k, ring in enumerate(self.s.rings):
            if (ring & u) != self.false:
                return k
        return None

    def first_node(self, candidates: Function) -> tuple[Key, int, PathKey]:
        """The candidate the explicit engine numbers first: (node, distance, path key).
        With :attr:`settled` the path key holds each ring's rank (:mod:`synth.symbolic.ties`),
        without it the smallest node of the last ring is taken (:meth:`pick`)."""
        depth = self.depth(candidates)
        if depth is None:
            raise ValueError("no candidate is reachable")
        chosen, _, keys, ranks = self._greedy(self._layers(candidates, depth), self._key, self.settled)
        return self.pick(chosen[-1]), depth, path_key(keys, ranks)

    def shortest_trace(self, key: Key) -> Path:
        """The shortest path from an initial node to ``key`` whose events are smallest by name."""
        node = self.cube(key)
        depth = self.depth(node)
        if depth is None:
            raise ValueError("node not reachable")
        chosen, events, _, _ = self._greedy(self._layers(node, depth), lambda m: m.event)
        nodes = [key]
        for k in range(depth - 1, -1, -1):
            arcs = [(m, e) for m, e in self.s.edges if m.event == events[k]]
            nodes.append(self.pick(self.s.pre(self.cube(nodes[-1]), arcs) & chosen[k]))
        nodes.reverse()
        return Path(tuple(nodes), tuple(events))

