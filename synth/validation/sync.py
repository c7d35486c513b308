"""SYNC: the Grafcet's stable situations running against SUP (docs/method.md, SYNC).

A SYNC state pairs a plant state of SUP with a stable situation. In a situation the
controller wants the orders it emits: the controllable transitions that change Z one
order at a time towards them, when SUP allows them, are *intra-region*; the states
so linked form the situation's *region*. The PLC writes its outputs at the end of a
cycle, before the plant can react, so the plant's uncontrollable events (sensor
edges, free inputs) and the Grafcet's timers leave a region from its *settled*
states: those where no allowed order change towards the emitted orders remains.
They are the *inter-region* transitions and lead to the next stable situation.

SUP membership is decided state by state (:class:`~synth.sup.constraints.CompiledConstraints`),
so the cost follows the reachable part of SYNC, never the size of the plant.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> from synth.grafcet.machine import GrafcetMachine
>>> rs, p, g = load_model(_plants("../grafcets/tri.g7"), _plants("tri.rules"))
>>> s = synchronous_product(p, rs.constraints, GrafcetMachine(g))
>>> s.nodes[0].situation.text()
'{X0, X100, X200, X300}'
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import InitVar, field
from typing import Callable, Iterable, Sequence

import numpy as np

from synth.errors import LimitExceeded
from synth.frozen import frozen
from synth.grafcet.language import Transition
from synth.grafcet.machine import GrafcetMachine, Situation
from synth.grafcet.situation import OutOfRange, with_trace
from synth.logic.events import Event
from synth.plant.composition import LocalTransition, Plant
from synth.plant.rules import Constraint
from synth.sup.constraints import CompiledConstraints
from synth.validation.conflicts import Conflict, ConflictLog

__all__ = ["WIDE", "WATCHED_WIDE", "Exploration", "Wide", "Partial", "Prohibition", "Node", "Edge", "many_nodes", "many_edges", "Sync", "synchronous_product", "region", "grafcet_inputs", "moves_by_order"]

Local = tuple[int, ...]


class Wide(Exception):
    """The search's queue grew past the ``wide`` asked of :func:`synchronous_product`;
    ``partial``: how far it went, for a frontier explorer to go on from."""

    def __init__(self, partial: Partial) -> None:
        super().__init__("wide")
        self.partial = partial


@frozen
class Partial:
    """The machine's path stopped after expanding nodes ``0 .. next - 1`` (the rest wait
    in its queue, in order): its nodes, edges and conflicts so far, the regions entered
    (settled states by (situation, entry)) and the SYNC states met."""

    oracle: CompiledConstraints
    nodes: list[Node]
    edges: list[Edge]
    conflicts: list[Conflict]
    log: ConflictLog
    initial: tuple[int, ...]
    next: int
    regions: dict[tuple[Situation, Local], list[tuple[Local, tuple[Prohibition, ...]]]]
    seen: set[tuple[Situation, Local]]


WIDE = 20
"""The explicit engine explores SYNC state by state until more than this many states wait
in its queue, then a frontier at a time from there (:mod:`synth.validation.frontier`):
below, a frontier's numpy passes (and the frontier's modules, imported then) cost more
than the states they carry. Measured (docs/performance.md, sessions 27 and 29): from 20
waiting rather than 32, par_5, steep_4, branches_3x3 and branches_4x2 validate 4-10 %
faster (the machine's path costs about 0.3 ms per aggregated state on the branches, a
frontier layer 0.5-1 ms); the bundled Grafcets (at most 15 to 20 waiting) stay on the
machine's path (tri_boxes, 17, took 25 ms more by frontiers)."""

WATCHED_WIDE = 32
""":data:`WIDE` for a watched run (``validate --engine auto``, :mod:`synth.probe`): the counts
it judges depend on where the frontier takes over; its shares were measured from 32."""


@frozen
class Exploration:
    """How SYNC is explored, whichever path explores it: past ``max_states`` aggregated
    states :class:`~synth.errors.LimitExceeded`; ``progress(met, waiting)`` now and then
    (aggregated states met, and those waiting to be expanded); ``watch(met, waiting)``
    after each state or frontier expanded (it may raise to stop the run: ``validate
    --engine auto``)."""

    max_states: int | None = None
    progress: Callable[[int, int], None] | None = None
    watch: Callable[[int, int], None] | None = None

    def over(self, met: int) -> None:
        if self.max_states is not None and met > self.max_states:  # the one message of both paths
            raise LimitExceeded(f"more than {self.max_states} aggregated states; raise --max-states or simplify the model")


@frozen(order=True)
class Prohibition:
    """An order change the situation asks for and SUP refuses: ``event`` is ``↑Z``/``↓Z``."""

    event: Event
    constraints: tuple[str, ...]

    @property
    def order(self) -> str:
        return self.event.name


@frozen
class Node:
    """A state of the aggregated automaton: a situation and the settled plant state of its region."""

    situation: Situation
    plant: Local
    emitted: frozenset[str]  # orders the situation emits
    ord: tuple[str, ...]  # emitted orders that are set (authorised by SUP)
    proh: tuple[Prohibition, ...]  # order changes SUP refuses here


@frozen
class Edge:
    """A transition of the aggregated SYNC: from node ``source`` to node ``target`` on ``event``."""

    source: int
    event: Event  # ↑v11, ↓dcy, 2s/X101
    target: int


def many_nodes(situations: list[Situation], plants: Iterable[Local], emitted: Sequence[frozenset[str]],
               ords: Sequence[tuple[str, ...]], prohs: list[tuple[Prohibition, ...]]) -> list[Node]:
    """``Node(*row)`` for each row of the columns given, made in bulk: the same objects,
    their attributes written once each without a call of ``__init__`` per node (a frontier
    makes thousands at once; the call was half their cost)."""
    new, out = object.__new__, []
    for a, b, c, d, e in zip(situations, plants, emitted, ords, prohs):
        node = new(Node)
        attrs = node.__dict__
        attrs["situation"], attrs["plant"], attrs["emitted"], attrs["ord"], attrs["proh"] = a, b, c, d, e
        out.append(node)
    return out


def many_edges(sources: list[int], events: list[Event], targets: list[int]) -> list[Edge]:
    """``Edge(*row)`` for each row of the columns given, made in bulk (as :func:`many_nodes`)."""
    new, out = object.__new__, []
    for a, b, c in zip(sources, events, targets):
        edge = new(Edge)
        attrs = edge.__dict__
        attrs["source"], attrs["event"], attrs["target"] = a, b, c
        out.append(edge)
    return out


@frozen
class Sync:
    """The aggregated view of SYNC, explored from the initial state (fully built:
    successors and predecessors are indexed on their first call)."""

    plant: Plant
    oracle: CompiledConstraints
    machine: GrafcetMachine
    nodes: tuple[Node, ...] = ()
    edges: tuple[Edge, ...] = ()
    initial: tuple[int, ...] = ()  # the initial region may settle in several plant states
    conflicts: tuple[Conflict, ...] = ()
    sync_states: int = 0  # SYNC states (all region members)
    _index: list[tuple[tuple[list[Edge], ...], tuple[list[Edge], ...]]] = field(init=False, repr=False, compare=False)
    _explored: bool = field(init=False, repr=False, compare=False)  # the arrays came from the explorer (sorted)
    _arrays: list[np.ndarray] = field(init=False, repr=False, compare=False)
    # the edges' sources and targets as arrays, when the explorer has them (the indexes are
    # then made by slicing, the edges grouped by source and target by sorting)
    arrays: InitVar[tuple[np.ndarray, np.ndarray] | None] = None

    def __post_init__(self, arrays: tuple[np.ndarray, np.ndarray] | None) -> None:
        if arrays is not None and arrays[0].size and (np.diff(arrays[0]) < 0).any():
            raise ValueError("edges not sorted by node")
        object.__setattr__(self, "_index", [])
        object.__setattr__(self, "_explored", arrays is not None)
        object.__setattr__(self, "_arrays", [] if arrays is None else list(arrays))

    def _indexed(self) -> tuple[tuple[list[Edge], ...], tuple[list[Edge], ...]]:
        """Each node's outgoing and incoming edges (made on the first call: a large SYNC's
        analysis reads the arrays instead)."""
        if not self._index:
            n = len(self.nodes)
            if not self._explored:
                out: tuple[list[Edge], ...] = tuple([] for _ in self.nodes)
                into: tuple[list[Edge], ...] = tuple([] for _ in self.nodes)
                for e in self.edges:
                    out[e.source].append(e)
                    into[e.target].append(e)
            else:
                src, dst = self._arrays
                out = _grouped(list(self.edges), src, n)
                by_target = np.argsort(dst, kind="stable")
                into = _grouped([self.edges[k] for k in by_target.tolist()], dst[by_target], n)
            self._index.append((out, into))
        return self._index[0]

    def edge_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """The edges' sources and targets as integer arrays (made on the first call)."""
        if not self._arrays:
            count = len(self.edges)
            self._arrays.append(np.fromiter((e.source for e in self.edges), dtype=np.int64, count=count))
            self._arrays.append(np.fromiter((e.target for e in self.edges), dtype=np.int64, count=count))
        return self._arrays[0], self._arrays[1]

    def successors(self, i: int) -> list[Edge]:
        return self._indexed()[0][i]

    def predecessors(self, i: int) -> list[Edge]:
        return self._indexed()[1][i]

    def inputs(self, local: Local) -> dict[str, bool]:
        """The Grafcet's inputs in plant state ``local``."""
        return grafcet_inputs(self.plant, self.machine, local)

    def vectors(self, i: int) -> tuple[str, str]:
        return self.plant.vectors(self.nodes[i].plant)


def _grouped(edges: list[Edge], keys: np.ndarray, n: int) -> tuple[list[Edge], ...]:
    """``edges``, sorted by ``keys`` (their sources or targets), cut into one list per node."""
    cuts = np.searchsorted(keys, np.arange(n + 1)).tolist()
    return tuple(edges[a:b] for a, b in zip(cuts, cuts[1:]))


def grafcet_inputs(p: Plant, machine: GrafcetMachine, local: Local) -> dict[str, bool]:
    """The values of the Grafcet's inputs in the plant state ``local`` (the symbolic engine's
    ties read them too)."""
    val = p.valuation(local)
    return {n: val[n] for n in machine.inputs if n in val}


def moves_by_order(p: Plant) -> dict[str, list[LocalTransition]]:
    """The plant's controllable moves by the order that starts them, in the explicit engine's
    order (both symbolic paths follow it when they make nodes explicit)."""
    moves: dict[str, list[LocalTransition]] = {}
    for t in p.transitions:
        if t.controllable:
            moves.setdefault(t.event.name, []).append(t)
    return moves


def region(
    p: Plant,
    oracle: CompiledConstraints,
    entry: Local,
    wanted: frozenset[str],
    order_moves: dict[str, list[LocalTransition]] | None = None,
    limit: int | None = None,
) -> tuple[list[Local], list[tuple[Local, tuple[Prohibition, ...]]]]:
    """The region entered at ``entry`` when the controller emits ``wanted``.

    Returns its members (entry first) and its settled states, each with the order
    changes SUP refuses there. ``limit``: raise :class:`~synth.errors.LimitExceeded`
    past this many members.
    """
    moves = order_moves if order_moves is not None else moves_by_order(p)
    members = [entry]
    seen = {entry}
    settled: list[tuple[Local, tuple[Prohibition, ...]]] = []
    queue = deque([entry])
    orders = sorted(moves)
    while queue:
        cur = queue.popleft()
        val = p.valuation(cur)
        progressed = False
        refused: list[Prohibition] = []
        ts = [t for order in orders if val[order] != (order in wanted) for t in moves[order] if t.src == cur[t.axis]]
        for t, (ok, why) in zip(ts, oracle.verdicts(ts, cur)):
            if not ok:
                refused.append(Prohibition(t.event, tuple(why)))
                continue
            progressed = True
            nxt = list(cur)
            nxt[t.axis] = t.dst
            n = tuple(nxt)
            if n not in seen:
                seen.add(n)
                members.append(n)
                queue.append(n)
                if limit is not None and len(members) > limit:
                    raise LimitExceeded(f"a region of more than {limit} states")
        if not progressed:
            settled.append((cur, tuple(sorted(refused))))
    return members, settled


def synchronous_product(
    p: Plant,
    constraints: Sequence[Constraint],
    machine: GrafcetMachine,
    how: Exploration = Exploration(),
    *,
    wide: int | None = None,
) -> Sync:
    """Explore SYNC from (initial plant state, initial situation), aggregated per region,
    state by state; :class:`Wide` once more than ``wide`` states wait in the queue (the
    frontier path, :mod:`synth.validation.frontier`, is then the faster); ``how.watch``
    after each aggregated state expanded."""
    oracle = CompiledConstraints(p, constraints)
    nodes: list[Node] = []
    edges: list[Edge] = []
    conflicts: list[Conflict] = []

    # per plant state, the Grafcet's inputs (and their values as a key); per situation and
    # input values, the orders: SYNC meets each many times (its plant states differ in the
    # orders, which the Grafcet does not read)
    seen_inputs: dict[Local, tuple[dict[str, bool], tuple[bool, ...]]] = {}

    def read(local: Local) -> tuple[dict[str, bool], tuple[bool, ...]]:
        hit = seen_inputs.get(local)
        if hit is None:
            values = grafcet_inputs(p, machine, local)
            hit = seen_inputs[local] = (values, tuple(values.values()))
        return hit

    def inputs(local: Local) -> dict[str, bool]:
        return read(local)[0]

    orders_cache: dict[tuple[Situation, tuple[bool, ...]], frozenset[str]] = {}

    def orders(sit: Situation, local: Local) -> frozenset[str]:
        values, key = read(local)
        hit = orders_cache.get((sit, key))
        if hit is None:
            hit = orders_cache[(sit, key)] = machine.orders(sit, values)
        return hit
    moves = moves_by_order(p)
    uncontrollable = [t for t in p.transitions if not t.controllable]
    index: dict[tuple[Situation, Local], int] = {}
    region_cache: dict[tuple[Situation, Local], list[tuple[Local, tuple[Prohibition, ...]]]] = {}
    sync_seen: set[tuple[Situation, Local]] = set()

    def enter(sit: Situation, entry: Local) -> list[int]:
        key = (sit, entry)
        if key not in region_cache:
            wanted = orders(sit, entry)
            members, settled = region(p, oracle, entry, wanted, moves)
            sync_seen.update((sit, m) for m in members)
            region_cache[key] = settled
        out = []
        for q, proh in region_cache[key]:
            nk = (sit, q)
            if nk not in index:
                wanted = orders(sit, q)
                val = p.valuation(q)
                ords = tuple(sorted(o for o in wanted if val.get(o, False)))
                index[nk] = len(nodes)
                nodes.append(Node(sit, q, frozenset(wanted), ords, proh))
                queue.append(index[nk])
                how.over(len(nodes))
            out.append(index[nk])
        return out

    log = ConflictLog()

    def note_conflicts(i: int, event: Event, rounds: Sequence[Sequence[Transition]]) -> None:
        conflicts.extend(Conflict(i, event, st, names) for st, names in log.fresh(rounds))

    queue: deque[int] = deque()
    if not oracle.kept(p.initial):
        return Sync(p, oracle, machine)
    happening: list[Event] = []  # the event being explored, for an assignment out of range

    def expand(i: int) -> None:
        node = nodes[i]
        cur = node.plant
        before = inputs(cur)
        for t in uncontrollable:
            if t.src != cur[t.axis] or not p.enabled(t, cur):
                continue
            nxt = list(cur)
            nxt[t.axis] = t.dst
            n = tuple(nxt)
            if not oracle.kept(n):  # cannot happen from a SUP state; kept for safety
                continue
            after = inputs(n)
            happening[:] = [t.event]
            sit, rounds = machine.react_with_trace(node.situation, before, after)
            note_conflicts(i, t.event, rounds)
            for j in enter(sit, n):
                edges.append(Edge(i, t.event, j))
        for timer in machine.timers(node.situation):
            happening[:] = [timer]
            sit, rounds = machine.fire_timer_with_trace(node.situation, timer, before)
            note_conflicts(i, timer, rounds)
            for j in enter(sit, cur):
                edges.append(Edge(i, timer, j))
        if machine.scans(node.situation, before):  # --semantics sfc: the PLC scans again
            happening[:] = [Event.scan()]
            sit, rounds = machine.scan(node.situation, before)
            note_conflicts(i, happening[0], rounds)
            for j in enter(sit, cur):
                edges.append(Edge(i, happening[0], j))

    try:
        sit0 = machine.initial(inputs(p.initial))
    except OutOfRange as err:
        raise with_trace(err, ()) from None
    initial = tuple(enter(sit0, p.initial))
    last = time.monotonic()
    i = 0
    try:
        while queue:
            i = queue.popleft()
            expand(i)
            if how.watch is not None:
                how.watch(len(nodes), len(queue))
            if wide is not None and len(queue) > wide:
                raise Wide(Partial(oracle, nodes, edges, conflicts, log, initial, i + 1, region_cache, sync_seen))
            if how.progress is not None and time.monotonic() - last > 0.5:
                how.progress(len(nodes), len(queue))
                last = time.monotonic()
    except OutOfRange as err:
        raise with_trace(err, [str(e) for e in path_events(edges, initial, i) + happening]) from None
    return Sync(p, oracle, machine, tuple(nodes), tuple(edges), initial, tuple(conflicts), len(sync_seen))


def path_events(edges: Sequence[Edge], initial: Sequence[int], target: int) -> list[Event]:
    """The events of a shortest path from an initial node to ``target``, on the edges of a
    breadth-first exploration (the first edge into a node comes from a node found earlier)."""
    first: dict[int, Edge] = {}
    for e in edges:
        if e.target not in first and e.target not in initial:
            first[e.target] = e
    out: list[Event] = []
    while target not in initial and target in first:
        e = first[target]
        out.append(e.event)
        target = e.source
    return out[::-1]
