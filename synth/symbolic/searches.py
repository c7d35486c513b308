"""The searches on a symbolic SYNC, written once for both representations
(:class:`~synth.symbolic.interface.SymbolicGraph`).

The same reading as :mod:`synth.validation.analysis`, on sets of nodes:

- :func:`deepest`: one node of a set from the farthest onion ring meeting it;
- :func:`terminal_components` of the stuck nodes, by descent: from a node ``v`` of the
  deepest ring, ``F`` = its forward set; ``F`` is terminal iff every node of ``F``
  reaches ``v`` (a backward fixpoint inside ``F``); otherwise descend into a node of
  ``F`` that cannot reach ``v``. A component found and every node that reaches it leave
  the candidates;
- :func:`layers`: per ring ``k``, the nodes from which a target is reached in
  ``depth − k`` steps (backward from the target);
- :func:`greedy`: forward through the layers, taking at each ring the smallest event
  (in the explicit exploration's order, or by name), every move of that order's key;
  with :class:`~synth.symbolic.ties.Settled`, each ring narrowed to the node the
  explicit engine enters first (:func:`first_of`);
- :func:`first_node`: the node of a set the explicit engine numbers first (least
  distance, then the smallest path in its order, ties as it breaks them);
- :func:`shortest_trace`: the explicit breadth-first search's path to a node: ring by
  ring the smallest event by name, then the node it enters that the explicit engine
  numbers first (:func:`first_among`).

:class:`OneByOne` answers a report's findings with these, one target at a time; the
step path batches the same searches (:mod:`synth.symbolic.steps.batch`, checked equal).

Example
-------
>>> # tests/test_symbolic_interface.py runs them on both representations against the explicit SYNC
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Generic, Sequence, TypeVar

from synth.logic.events import Event
from synth.symbolic.interface import Key, M, Path, PathKey, S, SymbolicGraph

if TYPE_CHECKING:  # pragma: no cover - the explicit order needs the explicit engine's region search
    from synth.symbolic.ties import Settled

__all__ = ["Path", "MAX_LISTED", "path_key", "deepest", "terminal_components", "layers", "greedy", "first_of",
           "depth_of", "first_node", "first_among", "first_entered", "first_from", "shortest_trace", "OneByOne", "Walk"]

MAX_LISTED = 100_000
"""At most this many nodes of one component are listed for the diagnosis."""

Order = TypeVar("Order", tuple[int, int, int], Event)  # how events are ordered: by plant transition, or by name


@dataclass(frozen=True)
class Walk(Generic[S, M, Order]):
    """What :func:`greedy` found: the set chosen per ring, per step the order key and
    the moves taken, and with ranks (:mod:`synth.symbolic.ties`) each ring's rank."""

    chosen: list[S]
    keys: list[Order]
    taken: list[list[M]]
    ranks: list[int]


def path_key(keys: Sequence[tuple[int, int, int]], ranks: Sequence[int]) -> PathKey:
    """A first node's path in the explicit engine's order: the events' keys, each with the
    rank of the node it enters when ranks are known (the initial node's rank first).

    >>> path_key([(0, 1, 0)], []), path_key([(0, 1, 0)], [1, 0])
    (((0, 1, 0),), ((1,), (0, 1, 0, 0)))
    """
    if not ranks:
        return tuple(keys)
    return ((ranks[0],),) + tuple(k + (r,) for k, r in zip(keys, ranks[1:]))


def deepest(g: SymbolicGraph[S, M], u: S) -> S:
    """One node of ``u`` from the farthest onion ring meeting it (terminal components lie deep)."""
    for ring in reversed(g.rings()):
        v = g.meet(u, ring)
        if not g.is_empty(v):
            return g.cube(g.pick(v))
    raise ValueError("no node of the set is reachable")


def terminal_components(g: SymbolicGraph[S, M], stuck: S) -> list[S]:
    """The terminal strongly connected components of the nodes ``stuck`` (descent: see the module docstring)."""
    comps: list[S] = []
    candidates = stuck
    while not g.is_empty(candidates):
        v = deepest(g, candidates)
        while True:
            fwd = g.forward(v)
            below = g.minus(fwd, g.backward(v, within=fwd))
            if g.is_empty(below):
                comps.append(fwd)
                break
            v = deepest(g, below)
        candidates = g.minus(candidates, g.backward(comps[-1], within=candidates))
    return comps


def depth_of(g: SymbolicGraph[S, M], u: S) -> int | None:
    """The ring of the nodes of ``u`` nearest the initial nodes (None: none is reachable)."""
    for k, ring in enumerate(g.rings()):
        if not g.is_empty(g.meet(ring, u)):
            return k
    return None


def layers(g: SymbolicGraph[S, M], target: S, depth: int) -> list[S]:
    """For k ≤ depth, the ring-k nodes from which ``target`` is reachable in depth−k steps."""
    rings = g.rings()
    out = [g.empty] * (depth + 1)
    out[depth] = g.meet(target, rings[depth])
    for k in range(depth - 1, -1, -1):
        out[k] = g.pre(out[k + 1], within=rings[k])
    return out


def greedy(g: SymbolicGraph[S, M], steps: list[S], order: Callable[[M], Order],
           settled: "Settled | None" = None) -> Walk[S, M, Order]:
    """Forward through the layers ``steps``, taking at each ring the smallest key (by
    ``order``) with a move into the next layer, and every move of that key; with
    ``settled``, each ring's set narrowed to the node the explicit engine enters first,
    and its rank (:func:`first_of`)."""
    current = steps[0]
    walk: Walk[S, M, Order] = Walk([], [], [], [])
    if settled is not None:
        current, rank = first_of(g, current, None, settled)
        walk.ranks.append(rank)
    walk.chosen.append(current)
    for k in range(1, len(steps)):
        options: dict[Order, tuple[list[M], list[S]]] = {}
        for m in g.moves_from(current):
            v = g.post_by(current, m, steps[k])
            if not g.is_empty(v):
                taken, reached = options.setdefault(order(m), ([], []))
                taken.append(m)
                reached.append(v)
        best = min(options)
        taken, current = options[best][0], g.join(options[best][1])
        if settled is not None:
            current, rank = first_of(g, current, (g.pick(walk.chosen[-1]), taken), settled)
            walk.ranks.append(rank)
        walk.keys.append(best)
        walk.taken.append(taken)
        walk.chosen.append(current)
    return walk


def first_of(g: SymbolicGraph[S, M], u: S, via: tuple[Key, Sequence[M]] | None, settled: "Settled") -> tuple[S, int]:
    """The node of ``u`` the explicit engine numbers first, ``u`` being nodes the region
    entered from node ``via[0]`` by the moves ``via[1]`` settles in (None: the initial
    region), and its rank among that region's settled states (0 where it settles in
    one: no region is run explicitly; 0 and the smallest node past
    :data:`~synth.symbolic.ties.REGION_LIMIT` states)."""
    if via is None:
        entered, parent, event, move = g.initial, None, None, None
    else:
        parent, moves = via
        source = g.cube(parent)
        leaving = [(m, v) for m in moves if not g.is_empty(v := g.post_by(source, m))]
        entered = g.join(v for _, v in leaving)
        arc = leaving[0][0] if leaving else moves[0]
        event, move = g.event(arc), g.plant_move(arc)
    if g.count(entered) == 1:
        return u, 0
    found = settled.first(parent, event, move, lambda key: g.contains(u, key))
    if found is None:  # a region too large to run explicitly: the smallest node
        return g.cube(g.pick(u)), 0
    return g.cube(found[0]), found[1]


def first_node(g: SymbolicGraph[S, M], candidates: S, settled: "Settled | None" = None) -> tuple[Key, int, PathKey]:
    """The candidate the explicit engine numbers first: smallest distance, then smallest
    path in exploration order (with ``settled``, ties broken as the explicit engine
    breaks them: :mod:`synth.symbolic.ties`, the path key holding each ring's rank;
    without, the smallest node of the last ring). Returns (node, distance, path key)."""
    depth = depth_of(g, candidates)
    if depth is None:
        raise ValueError("no candidate is reachable")
    walk = greedy(g, layers(g, candidates, depth), g.order, settled)
    return g.pick(walk.chosen[-1]), depth, path_key(walk.keys, walk.ranks)


def shortest_trace(g: SymbolicGraph[S, M], key: Key, settled: "Settled | None" = None) -> Path:
    """The explicit breadth-first search's path from an initial node to ``key``: at each
    ring the smallest event by name with a move into the target's layers, then, of the
    nodes that event enters there, the one the explicit engine numbers first
    (:func:`first_among`). The explicit search takes each node's edges by event, then
    target number, and keeps the first parent it meets: its path is the smallest
    sequence of (event, node number) pairs, decided ring by ring."""
    node = g.cube(key)
    depth = depth_of(g, node)
    if depth is None:
        raise ValueError("node not reachable")
    steps = layers(g, node, depth)
    rings = g.rings()
    current = first_among(g, steps[0], settled)
    nodes, events = [g.pick(current)], []
    for k in range(1, depth + 1):
        options: dict[Event, list[S]] = {}
        for m in g.moves_from(current):
            v = g.post_by(current, m, steps[k])
            if not g.is_empty(v):
                options.setdefault(g.event(m), []).append(v)
        best = min(options)
        current = first_entered(g, g.join(options[best]), current, rings[k - 1], settled)
        nodes.append(g.pick(current))
        events.append(best)
    return Path(tuple(nodes), tuple(events))


def first_among(g: SymbolicGraph[S, M], u: S, settled: "Settled | None" = None) -> S:
    """The node of ``u`` (nodes of one ring) the explicit engine numbers first, as a set."""
    if g.count(u) == 1:
        return u
    return g.cube(first_node(g, u, settled)[0])


def first_entered(g: SymbolicGraph[S, M], u: S, parent: S, ring: S, settled: "Settled | None") -> S:
    """:func:`first_among` for nodes ``u`` of the ring after ``ring``, all successors of
    the single node ``parent``. Where no other node of ``ring`` leads into ``u``, the
    explicit engine numbered them all from ``parent`` (:func:`first_from`), no search from
    the initial nodes."""
    if g.count(u) == 1:
        return u
    if settled is not None and g.is_empty(g.minus(g.pre(u, within=ring), parent)):
        return first_from(g, u, parent, settled)
    return first_among(g, u, settled)


def first_from(g: SymbolicGraph[S, M], u: S, parent: S, settled: "Settled") -> S:
    """The node of ``u`` the explicit engine numbers first, ``u`` being nodes it found
    first from the single node ``parent``: by ``parent``'s moves in exploration order,
    then as their region settles (:func:`first_of`)."""
    by_key: dict[tuple[int, int, int], list[M]] = {}
    for m in g.moves_from(parent):
        by_key.setdefault(g.order(m), []).append(m)
    for key in sorted(by_key):
        v = g.meet(u, g.join(g.post_by(parent, m) for m in by_key[key]))
        if not g.is_empty(v):
            return first_of(g, v, (g.pick(parent), by_key[key]), settled)[0]
    return first_among(g, u, settled)  # pragma: no cover - every node of u is a successor of parent


class OneByOne(Generic[S, M]):
    """A report's first nodes and traces, one target at a time (the batched twin:
    :class:`~synth.symbolic.steps.batch.Batched`)."""

    def __init__(self, g: SymbolicGraph[S, M], settled: "Settled | None" = None) -> None:
        self.g = g
        self.settled = settled

    def firsts(self, sets: Sequence[S]) -> list[tuple[Key, int, PathKey]]:
        return [first_node(self.g, u, self.settled) for u in sets]

    def traces(self, keys: Sequence[Key]) -> list[Path]:
        return [shortest_trace(self.g, k, self.settled) for k in keys]
