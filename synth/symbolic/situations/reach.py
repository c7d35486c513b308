"""Verdicts on the symbolic SYNC: coreachability, blocking components, shortest traces.

The same reading as :mod:`synth.validation.analysis`, on sets of nodes (a BDD per
situation) instead of node lists:

- ``coreachable``: backward fixpoint from the home nodes;
- *stuck* nodes (reachable, not coreachable); their terminal strongly connected
  components: every deadlock is one; the other candidates are found by descending
  (pick a node, its forward set; if that lies in its backward set it is a terminal
  component, else descend into the part that cannot come back);
- *held* nodes (no node with other active steps reachable) with a prohibited order;
- distances from the onion rings; the node the explicit engine would number first at
  a distance is the one whose shortest path is smallest in the explicit exploration's
  order (element, variable, then timers); the trace to a node is the shortest path
  whose events are smallest by name, as the explicit breadth-first search sorts them.

Example
-------
>>> # see tests/test_symbolic.py: every result is compared with the explicit analysis
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Sequence, TypeVar

from synth.errors import LimitExceeded
from synth.logic.bdd import Function
from synth.logic.events import Event
from synth.symbolic.situations.graph import Bundle, NodeSet
from synth.symbolic.situations.sync import SymbolicSync

if TYPE_CHECKING:  # pragma: no cover - the explicit order needs the explicit engine's region search
    from synth.symbolic.ties import Settled

__all__ = ["Path", "coreachable", "stuck_nodes", "held_nodes", "terminal_components", "first_node", "shortest_trace",
           "prohibited_nodes", "listed", "MAX_LISTED", "node_held", "path_key"]

MAX_LISTED = 100_000
"""At most this many nodes of one component are listed for the diagnosis."""


@dataclass(frozen=True)
class Path:
    """A path of the aggregated automaton: nodes as (situation, plant state) and events."""

    nodes: tuple[tuple[int, tuple[int, ...]], ...]
    events: tuple[Event, ...]


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


def coreachable(sync: SymbolicSync, homes: NodeSet) -> NodeSet:
    """Nodes from which a home node is reachable."""
    return sync.backward(homes)


def stuck_nodes(sync: SymbolicSync, back: NodeSet) -> NodeSet:
    """Reachable nodes that are not coreachable."""
    return _minus(sync.nodes(), back, sync.false)


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


def _deepest(sync: SymbolicSync, u: NodeSet) -> NodeSet:
    """One node of ``u`` from the farthest onion ring meeting it (terminal components lie deep)."""
    rings = sync.onion_rings()
    for ring in reversed(rings):
        for s in sorted(ring):
            v = u.get(s, sync.false) & ring[s]
            if v != sync.false:
                return {s: sync.enc.state(sync.enc.one(v))}
    raise ValueError("no node of the set is reachable")


def terminal_components(sync: SymbolicSync, stuck: NodeSet) -> list[NodeSet]:
    """The terminal strongly connected components of the stuck nodes.

    Descent: from a node ``v``, ``F`` = its forward set (closed under successors); ``F``
    is a terminal component iff every node of ``F`` reaches ``v`` back (a backward
    fixpoint inside ``F`` only); otherwise continue from a node of ``F`` that cannot
    reach ``v``. Once a component is found, it and every node that can reach it leave
    the candidates (none of them is in another terminal component)."""
    false = sync.false
    comps: list[NodeSet] = []
    candidates = dict(stuck)
    while not _empty(candidates, false):
        v = _deepest(sync, candidates)
        while True:
            fwd = sync.forward(v)
            back = sync.backward(v, within=fwd)
            below = _minus(fwd, back, false)
            if _empty(below, false):
                comps.append(fwd)
                break
            v = _deepest(sync, below)
        candidates = _minus(candidates, sync.backward(comps[-1], within=candidates), false)
    return comps


def _key(sync: SymbolicSync, b: Bundle) -> tuple[int, int, int]:
    """The explicit exploration's order of an event from a node: plant moves by element
    and variable, then timers."""
    if b.move is None:
        return (1, b.key[1], 0)
    e = sync.plant.elements[b.move.axis]
    return (0, b.move.axis, e.variables.index(b.move.variable))


def _layers(sync: SymbolicSync, target: NodeSet, depth: int) -> list[NodeSet]:
    """For k ≤ depth, the ring-k nodes from which ``target`` is reachable in depth−k steps."""
    rings = sync.onion_rings()
    layers: list[NodeSet] = [dict() for _ in range(depth + 1)]
    layers[depth] = {s: u & rings[depth].get(s, sync.false) for s, u in target.items()}
    for k in range(depth - 1, -1, -1):
        pre: NodeSet = {}
        for t, u in layers[k + 1].items():
            if u == sync.false:
                continue
            for s, v in sync.pre({t: u}, sync.into(t)).items():
                pre[s] = pre.get(s, sync.false) | v
        layers[k] = {s: u & rings[k].get(s, sync.false) for s, u in pre.items()}
        layers[k] = {s: u for s, u in layers[k].items() if u != sync.false}
    return layers


Key = TypeVar("Key", tuple[int, int, int], Event)  # how events are ordered: by plant transition, or by name


def _greedy(sync: SymbolicSync, layers: list[NodeSet], order: Callable[[Bundle], Key], settled: "Settled | None" = None,
            ) -> tuple[list[NodeSet], list[Event], list[Key], list[int]]:
    """Forward through ``layers``, taking at each step the smallest event (by ``order``):
    the nodes chosen per layer, the events and their keys; with ``settled``, each layer's
    nodes narrowed to the one the explicit engine enters first, and its rank
    (:func:`_first_of`)."""
    current = layers[0]
    ranks: list[int] = []
    if settled is not None:
        current, rank = _first_of(sync, current, None, settled)
        ranks.append(rank)
    chosen = [current]
    events: list[Event] = []
    keys: list[Key] = []
    for k in range(1, len(layers)):
        options: dict[Key, tuple[Event, NodeSet, list[Bundle]]] = {}
        for s, u in current.items():
            for b in sync.out_bundles(s):
                if b.target not in layers[k]:
                    continue
                v = sync.post({s: u}, b) & layers[k][b.target]
                if v == sync.false:
                    continue
                key = order(b)
                ev, nxt, taken = options.get(key, (b.event, {}, []))
                nxt[b.target] = nxt.get(b.target, sync.false) | v
                taken.append(b)
                options[key] = (ev, nxt, taken)
        best = min(options)
        ev, current, taken = options[best]
        if settled is not None:
            current, rank = _first_of(sync, current, (_pick(sync, chosen[-1]), taken), settled)
            ranks.append(rank)
        events.append(ev)
        keys.append(best)
        chosen.append(current)
    return chosen, events, keys, ranks


def _first_of(sync: SymbolicSync, u: NodeSet, via: "tuple[tuple[int, tuple[int, ...]], list[Bundle]] | None",
              settled: "Settled") -> tuple[NodeSet, int]:
    """The node of ``u`` the explicit engine numbers first, ``u`` being nodes the region
    entered from node ``via[0]`` by the event of bundles ``via[1]`` settles in (None: the
    initial region), and its rank among that region's settled states (0 where it settles
    in one; 0 and the smallest node past :data:`~synth.symbolic.ties.REGION_LIMIT`)."""
    false = sync.false
    if via is None:
        entered, event, move, parent = sync.initial, None, None, None
    else:
        parent, bundles = via
        source = {parent[0]: sync.enc.state(parent[1])}
        entered = {}
        for b in bundles:
            if b.source == parent[0] and (v := sync.post(source, b)) != false:
                entered[b.target] = entered.get(b.target, false) | v
        event, move = bundles[0].event, bundles[0].move
    if sum(sync.enc.count(v) for v in entered.values()) == 1:
        return u, 0
    found = settled.first(parent, event, move,
                          lambda key: (sync.enc.state(key[1]) & u.get(key[0], false)) != false)
    (s, local), rank = (_pick(sync, u), 0) if found is None else found  # too large to run: the smallest node
    return {s: sync.enc.state(local)}, rank


def path_key(keys: Sequence[tuple[int, int, int]], ranks: Sequence[int]) -> tuple[tuple[int, ...], ...]:
    """A first node's path in the explicit engine's order: the events' keys, each with the
    rank of the node it enters when ranks are known (the initial node's rank first).

    >>> path_key([(0, 1, 0)], []), path_key([(0, 1, 0)], [1, 0])
    (((0, 1, 0),), ((1,), (0, 1, 0, 0)))
    """
    if not ranks:
        return tuple(keys)
    return ((ranks[0],),) + tuple(k + (r,) for k, r in zip(keys, ranks[1:]))


def _pick(sync: SymbolicSync, u: NodeSet) -> tuple[int, tuple[int, ...]]:
    s = min(s for s, v in u.items() if v != sync.false)
    return s, sync.enc.one(u[s])


def first_node(sync: SymbolicSync, candidates: NodeSet, settled: "Settled | None" = None,
               ) -> tuple[int, tuple[int, ...], int, tuple[tuple[int, ...], ...]]:
    """The candidate the explicit engine numbers first: smallest distance, then smallest
    path in exploration order (with ``settled``, ties broken as the explicit engine
    breaks them: :mod:`synth.symbolic.ties`). Returns (situation, plant state, distance,
    path key)."""
    rings = sync.onion_rings()
    for depth, ring in enumerate(rings):
        hit = {s: u & ring[s] for s, u in candidates.items() if s in ring and (u & ring[s]) != sync.false}
        if hit:
            break
    else:
        raise ValueError("no candidate is reachable")
    layers = _layers(sync, hit, depth)
    chosen, _, keys, ranks = _greedy(sync, layers, lambda b: _key(sync, b), settled)  # keys: to sort first nodes
    s, local = _pick(sync, chosen[-1])
    return s, local, depth, path_key(keys, ranks)


def shortest_trace(sync: SymbolicSync, s: int, local: tuple[int, ...]) -> Path:
    """The shortest path from an initial node to node (``s``, ``local``) whose events are
    smallest by name (the explicit breadth-first search's parent choice)."""
    node = sync.enc.state(local)
    depth = sync.depth(s, node)
    if depth is None:
        raise ValueError("node not reachable")
    layers = _layers(sync, {s: node}, depth)
    chosen, events, _, _ = _greedy(sync, layers, lambda b: b.event)
    # one concrete node per layer, backwards from the target
    nodes = [(s, local)]
    for k in range(depth - 1, -1, -1):
        t, loc = nodes[-1]
        target = {t: sync.enc.state(loc)}
        pre: NodeSet = {}
        arcs = [b for b in sync.in_bundles(t) if b.event == events[k]]
        for src, u in sync.pre(target, arcs).items():
            v = u & chosen[k].get(src, sync.false)
            if v != sync.false:
                pre[src] = v
        nodes.append(_pick(sync, pre))
    nodes.reverse()
    return Path(tuple(nodes), tuple(events))


def listed(sync: SymbolicSync, u: NodeSet, limit: int = MAX_LISTED) -> list[tuple[int, tuple[int, ...]]]:
    """The nodes of ``u``, situation by situation."""
    out: list[tuple[int, tuple[int, ...]]] = []
    for s in sorted(u):
        for local in sync.enc.states(u[s], limit - len(out)):
            out.append((s, local))
    if len(out) > limit:  # pragma: no cover - states() raises first
        raise LimitExceeded(f"more than {limit} nodes to list")
    return out

