"""SYNC explored a frontier at a time: the explicit engine's fast path.

The same aggregated automaton as :func:`synth.validation.sync.synchronous_product`, node
for node, edge for edge and in the same order, built by numpy passes over the whole
breadth-first frontier instead of one interpreted step per state: a node is a pair of
integers (situation number, plant code: the flat code, or on a plant of 2^40 states or
more the number of the state in the order met, :mod:`synth.validation.words`); the
frontier's uncontrollable moves come from the element-local transition tables
(:class:`~synth.validation.regions.PlantCodes`); the Grafcet reacts on rows of bits
(:class:`~synth.grafcet.vector.VectorMachine`); the regions entered are searched many at
once (:func:`~synth.validation.regions.regions`), and nodes, regions and situations are
found again through sorted integer keys.

The machine itself still runs what the rows do not carry: the timers' events (per
node), a reaction that fires an OR divergence's conflict (its rounds are noted) or evolves
longer than :data:`~synth.grafcet.vector.ROUNDS` rounds. A Grafcet the rows cannot carry
at all (:func:`reason` says why), or anything unusual met on the way (a transient cycle,
an event that changes several inputs, keys past 64 bits, two wide plant states under one
key), is explored by the machine's path from the start, which also gives the same error
at the same place. The machine's path runs alone first, until its queue goes wide
(:data:`~synth.validation.sync.WIDE`): :func:`synth.validation.validate.explore` chooses,
and imports this module only then.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> from synth.validation.sync import synchronous_product
>>> rs, p, g = load_model(_plants("../grafcets/tri_missing_order.g7"), _plants("tri.rules"))
>>> fast = explore_frontier(p, rs.constraints, GrafcetMachine(g))
>>> slow = synchronous_product(p, rs.constraints, GrafcetMachine(g))
>>> fast.nodes == slow.nodes, fast.edges == slow.edges, fast.sync_states == slow.sync_states
(True, True, True)
"""

from __future__ import annotations

import time
from typing import Callable, Sequence, TypeVar

import numpy as np

from synth.errors import InputError
from synth.grafcet.machine import GrafcetMachine, Situation
from synth.grafcet.vector import VectorMachine, unsupported
from synth.logic.events import Event
from synth.plant.composition import Plant
from synth.plant.rules import Constraint
from synth.sup.constraints import CompiledConstraints
from synth.validation.conflicts import Conflict, ConflictLog
from synth.validation.keys import ROW_BITS, Collision, SortedKeys, distinct, distinct_rows, occurrences, row_codes, slices
from synth.validation.regions import PlantCodes, Regions, regions
from synth.validation.sync import Edge, Exploration, Node, Partial, Sync, many_edges, many_nodes, synchronous_product

__all__ = ["explore_wide", "reason", "explore_frontier", "Unsupported"]

Rounds = tuple[tuple, ...]


class Unsupported(Exception):
    """The frontier path met what it leaves to the machine's path (the message says what)."""


def reason(p: Plant, machine: GrafcetMachine) -> str | None:
    """Why SYNC of ``machine`` against ``p`` is explored by the machine state by state
    rather than a frontier at a time; None when the frontier path runs."""
    why = unsupported(machine)
    if why is not None:
        return why
    missing = [n for n in machine.inputs if n not in p.owner]
    if missing:
        return f"input {missing[0]} is not a plant variable"
    return None


def explore_wide(
    p: Plant,
    constraints: Sequence[Constraint],
    machine: GrafcetMachine,
    how: Exploration = Exploration(),
    *,
    partial: Partial | None = None,
) -> Sync:
    """SYNC of a model whose search went wide (:data:`~synth.validation.sync.WIDE`): a
    frontier at a time when :func:`reason` allows it, else (or when the frontier path
    meets what it leaves to the machine) by the machine's path from the start;
    ``partial``: how far the machine's path went before it went wide; ``how.watch``:
    after each frontier (or state, on the machine's path) expanded."""
    if reason(p, machine) is None:
        try:
            return explore_frontier(p, constraints, machine, how, partial=partial)
        except Unsupported:
            pass
    return synchronous_product(p, constraints, machine, how)


class _Situations:
    """The situations met, numbered; their bits for the rows."""

    def __init__(self, vm: VectorMachine, size: int) -> None:
        self.vm, self.size = vm, size
        self.items: list[Situation] = []
        self.timers: list[tuple[Event, ...]] = []
        self.timed = np.zeros(0, dtype=bool)  # the situations with timers to fire
        self._ids: dict[int | bytes, int] = {}
        self.A = np.zeros((0, len(vm.step_names)), dtype=bool)
        self.T = np.zeros((0, vm.memory), dtype=bool)
        self.O = np.zeros((0, len(vm.order_names)), dtype=bool)  # the orders the situation emits whatever the inputs

    def number(self, A: np.ndarray, T: np.ndarray, given: list[Situation] | None = None) -> np.ndarray:
        """The numbers of the rows' situations (a new one numbered when first met)."""
        bits = np.concatenate([A, T], axis=1)
        first, inverse, keys = _distinct_keys(bits)
        ids = np.empty(len(first), dtype=np.int64)
        fresh: list[int] = []
        for u, (r, b) in enumerate(zip(first.tolist(), keys)):
            hit = self._ids.get(b)
            if hit is None:
                hit = self._ids[b] = len(self.items) + len(fresh)
                fresh.append(r)
            ids[u] = hit
        out = ids[inverse]
        if fresh:
            made = [given[r] for r in fresh] if given is not None else self.vm.situations(A[fresh], T[fresh])
            self.items.extend(made)
            self.timers.extend(self.vm.machine.timers(sit) for sit in made)
            self.A = np.vstack([self.A, A[fresh]])
            self.T = np.vstack([self.T, T[fresh]])
            self.O = np.vstack([self.O, self.vm.situation_orders(A[fresh], T[fresh])])
            self.timed = np.concatenate([self.timed, np.array([bool(t) for t in self.timers[len(self.timed):]], dtype=bool)])
            if len(self.items) * self.size >= 1 << 62:
                raise Unsupported("node keys past 64 bits")
        return out

    def of(self, sits: list[Situation]) -> np.ndarray:
        """The numbers of ``sits`` (each distinct one made a row once)."""
        at: dict[Situation, int] = {}
        where = [at.setdefault(s, len(at)) for s in sits]
        distinct_sits = list(at)
        A, T = self.vm.rows(distinct_sits)
        return self.number(A, T, distinct_sits)[where]


def explore_frontier(
    p: Plant,
    constraints: Sequence[Constraint],
    machine: GrafcetMachine,
    how: Exploration = Exploration(),
    *,
    partial: Partial | None = None,
) -> Sync:
    """SYNC a frontier at a time (see module doc), from the start or going on from where
    the machine's path stopped (``partial``); :class:`Unsupported` when it meets what it
    leaves to the machine's path."""
    why = reason(p, machine)
    if why is not None:
        raise Unsupported(why)
    oracle = partial.oracle if partial is not None else CompiledConstraints(p, constraints)
    if not oracle.kept(p.initial):
        return Sync(p, oracle, machine)
    try:
        return _Explorer(p, oracle, machine, how).run(partial)
    except Collision as err:
        raise Unsupported(str(err)) from None


T_ = TypeVar("T_")


def _distinct_keys(bits: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[int | bytes]]:
    """:func:`~synth.validation.keys.distinct_rows` of ``bits``, and each distinct row's
    key for a dictionary: its integer code up to :data:`~synth.validation.keys.ROW_BITS`
    columns, else its packed bytes."""
    if bits.shape[1] <= ROW_BITS:
        codes = row_codes(bits)
        first, inverse = distinct(codes)
        keys: list[int | bytes] = codes[first].tolist()
        return first, inverse, keys
    first, inverse = distinct_rows(bits)
    return first, inverse, [r.tobytes() for r in np.packbits(bits[first], axis=1)]


def _per_row(bits: np.ndarray, make: Callable[[np.ndarray], T_], made: dict[int | bytes, T_]) -> list[T_]:
    """``make`` of each row of ``bits``, called once per distinct row (``made``: the rows
    met before)."""
    first, inverse, keys = _distinct_keys(bits)
    out = []
    for r, key in zip(first.tolist(), keys):
        hit = made.get(key)
        if hit is None:
            hit = made[key] = make(bits[r])
        out.append(hit)
    return [out[i] for i in inverse.tolist()]


class _Explorer:
    def __init__(self, p: Plant, oracle: CompiledConstraints, machine: GrafcetMachine, how: Exploration) -> None:
        self.p, self.oracle, self.machine, self.how = p, oracle, machine, how
        self.vm = VectorMachine(machine)
        self.pc = PlantCodes(p, oracle)
        self.P = self.pc.P
        self.sits = _Situations(self.vm, self.P)
        self.regions = Regions()
        self.entered = SortedKeys()  # (situation, entry) -> region
        self.by_wanted = SortedKeys()  # (wanted orders, entry) -> region
        self._wanted: dict[int | bytes, int] = {}
        self.index = SortedKeys()  # (situation, plant) -> node
        self.nodes: list[Node] = []
        self.node_sit = np.empty(0, dtype=np.int64)
        self.node_code = np.empty(0, dtype=np.int64)
        self.edges: list[Edge] = []
        self.sources: list[np.ndarray] = []  # the edges' sources and targets, batch by batch
        self.targets: list[np.ndarray] = []
        self.conflicts: list[Conflict] = []
        self.log = ConflictLog()
        self._orders: dict[int | bytes, tuple[frozenset[str], tuple[str, ...]]] = {}  # a node's orders, per row of bits
        self.pairs: list[np.ndarray] = []  # (situation, member) keys of the regions entered
        # the Grafcet's order columns in the regions' order of the plant's orders
        self._move_events = [t.event for t in self.pc.uncontrollable]
        self._order_cols = [self.vm.order_names.index(o) if o in self.vm.order_names else -1 for o in self.pc.orders]

    # ------------------------------------------------------------------ helpers
    def inputs(self, codes: np.ndarray) -> np.ndarray:
        return self.pc.values(self.machine.inputs, self.pc.digits(codes))

    def as_dict(self, bits: np.ndarray) -> dict[str, bool]:
        return dict(zip(self.machine.inputs, bits.tolist()))

    def orders(self, sid: np.ndarray, codes: np.ndarray) -> np.ndarray:
        out = self.sits.O[sid]  # what the situations decide alone, read once per situation
        if self.vm.conditional:
            self.vm.add_conditional(out, self.sits.A[sid], self.sits.T[sid], self.inputs(codes))
        return out

    def region_of(self, sid: np.ndarray, entry: np.ndarray) -> np.ndarray:
        """The region entered at each (situation, entry), searched when new."""
        keys = sid * self.P + entry
        found = self.entered.find(keys)
        if (found < 0).any():
            miss = (found < 0).nonzero()[0]
            first, again = occurrences(keys[miss])
            first = miss[first]
            emitted = self.orders(sid[first], entry[first])
            wanted = np.concatenate([emitted, np.zeros((len(first), 1), dtype=bool)], axis=1)[:, self._order_cols]
            _, inverse, rows = _distinct_keys(wanted)
            wid = np.array([self._wanted.setdefault(w, len(self._wanted)) for w in rows], dtype=np.int64)[inverse]
            if len(self._wanted) * self.P >= 1 << 62:
                raise Unsupported("region keys past 64 bits")
            wkeys = wid * self.P + entry[first]
            gid = self.by_wanted.find(wkeys)
            unknown = (gid < 0).nonzero()[0]
            if unknown.size:
                new, same = occurrences(wkeys[unknown])
                new = unknown[new]
                base = self.regions.count
                try:
                    regions(self.pc, self.regions, entry[first][new], wanted[new])
                except OverflowError as err:
                    raise Unsupported(str(err)) from None
                self.by_wanted.add(wkeys[new], base + np.arange(new.size))
                gid[unknown] = base + same
            self.entered.add(keys[first], gid)
            counts, at = slices(self.regions.member_starts, gid)
            self.pairs.append(sid[first].repeat(counts) * self.P + self.regions.members[at])
            found[miss] = gid[again]
        return found

    def enter(self, sid: np.ndarray, entry: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The nodes of the settled states of each region entered (new ones made), and for
        each of them the candidate it comes from."""
        gid = self.region_of(sid, entry)
        counts, at = slices(self.regions.settled_starts, gid)
        src = np.arange(len(gid)).repeat(counts)
        q, proh = self.regions.settled[at], self.regions.settled_proh[at]
        tsid = sid[src]
        keys = tsid * self.P + q
        node = self.index.find(keys)
        miss = (node < 0).nonzero()[0]
        if miss.size:
            first, again = occurrences(keys[miss])
            first = miss[first]
            ids = len(self.nodes) + np.arange(first.size)
            self.make_nodes(tsid[first], q[first], proh[first])
            self.index.add(keys[first], ids)
            node[miss] = ids[again]
        return node, src

    def make_nodes(self, sid: np.ndarray, q: np.ndarray, proh: np.ndarray) -> None:
        emitted = self.orders(sid, q)
        digits = self.pc.digits(q)
        names = self.vm.order_names
        k = len(names)

        def made(row: np.ndarray) -> tuple[frozenset[str], tuple[str, ...]]:  # the orders emitted, and those set
            return frozenset(names[i] for i in row[:k].nonzero()[0]), tuple(names[i] for i in row[k:].nonzero()[0])

        wanted, set_ = zip(*_per_row(np.concatenate([emitted, emitted & self.pc.values(names, digits)], axis=1), made,
                                     self._orders))
        items, prohs = self.sits.items, self.regions.prohibitions
        self.nodes.extend(many_nodes([items[s] for s in sid.tolist()], map(tuple, digits.full().T.tolist()), wanted, set_,
                                     [prohs[pr] for pr in proh.tolist()]))
        self.node_sit = np.concatenate([self.node_sit, sid])
        self.node_code = np.concatenate([self.node_code, q])
        self.how.over(len(self.nodes))

    # ------------------------------------------------------------------ the search
    def resume(self, partial: Partial) -> tuple[tuple[int, ...], int]:
        """Take over from the machine's path (its nodes, edges, conflicts, regions and SYNC
        states met): the initial nodes and the first node left to expand."""
        P = self.P
        nodes = partial.nodes
        sid = self.sits.of([n.situation for n in nodes])
        code = self.pc.encode([n.plant for n in nodes])
        self.nodes = list(nodes)
        self.node_sit, self.node_code = sid, code
        self.index.add(sid * P + code, np.arange(len(nodes)))
        self.edges = list(partial.edges)
        if self.edges:
            self.sources.append(np.array([e.source for e in self.edges], dtype=np.int64))
            self.targets.append(np.array([e.target for e in self.edges], dtype=np.int64))
        self.conflicts, self.log = list(partial.conflicts), partial.log
        if partial.regions:  # the regions entered, their settled states (members: in ``seen``)
            keys = list(partial.regions)
            rsid = self.sits.of([k[0] for k in keys])
            entry = self.pc.encode([k[1] for k in keys])
            settled = [partial.regions[k] for k in keys]
            base = self.regions.count
            self.regions.append(np.empty(0, dtype=np.int64), np.zeros(len(keys), dtype=np.int64),
                                self.pc.encode([q for s in settled for q, _ in s]),
                                np.array([self.regions.proh_id(pr) for s in settled for _, pr in s], dtype=np.int64),
                                np.array([len(s) for s in settled], dtype=np.int64))
            self.entered.add(rsid * P + entry, base + np.arange(len(keys)))
        if partial.seen:
            seen = list(partial.seen)
            self.pairs.append(self.sits.of([s for s, _ in seen]) * P
                              + self.pc.encode([m for _, m in seen]))
        return partial.initial, partial.next

    def run(self, partial: Partial | None = None) -> Sync:
        if partial is not None:
            initial, lo = self.resume(partial)
        else:
            init = self.pc.encode([self.p.initial])
            sit0 = self.machine.initial(self.as_dict(self.inputs(init)[0]))
            node, _ = self.enter(self.sits.of([sit0]), init)
            initial, lo = tuple(node.tolist()), 0
        last = time.monotonic()
        while lo < len(self.nodes):
            hi = len(self.nodes)
            self.expand(lo, hi)
            lo = hi
            if self.how.watch is not None:
                self.how.watch(len(self.nodes), len(self.nodes) - lo)
            if self.how.progress is not None and time.monotonic() - last > 0.5:
                self.how.progress(len(self.nodes), len(self.nodes) - lo)
                last = time.monotonic()
        states = len(distinct(np.concatenate(self.pairs))[0]) if self.pairs else 0
        arrays = (np.concatenate(self.sources), np.concatenate(self.targets)) if self.sources else None
        return Sync(self.p, self.oracle, self.machine, tuple(self.nodes), tuple(self.edges), initial,
                    tuple(self.conflicts), states, arrays)

    def expand(self, lo: int, hi: int) -> None:
        """Every event from the nodes ``lo:hi``, in the machine's path's order."""
        sid, codes = self.node_sit[lo:hi], self.node_code[lo:hi]
        row, rank, entry = self.pc.successors(codes)
        inputs = self.inputs(np.concatenate([codes, entry]))  # before and after, one pass
        before, after = inputs[:len(codes)], inputs[len(codes):]
        changed = before[row] ^ after
        count = changed.sum(axis=1)
        if (count > 1).any():
            raise Unsupported("an event that changes several inputs")
        col = changed.argmax(axis=1)
        E = np.where(count == 1, 2 * col + after[np.arange(len(row)), col], -1)
        A2, T2, moved, pending = self.vm.react(self.sits.A[sid[row]], self.sits.T[sid[row]], after, E)
        nsid = sid[row]
        moved &= ~pending
        nsid[moved] = self.sits.number(A2[moved], T2[moved])
        traced: dict[int, Rounds] = {}  # candidate -> rounds fired, where the machine reacted
        items = self.sits.items
        for c in pending.nonzero()[0].tolist():
            sit, traced[c] = self._machine(lambda: self.machine.react_with_trace(
                items[sid[row[c]]], self.as_dict(before[row[c]]), self.as_dict(after[c])))
            nsid[c] = self.sits.of([sit])[0]
        # each candidate's event, as an index into ``table``: the uncontrollable moves' own,
        # then one per timer candidate
        table, evid = list(self._move_events), [rank]
        rows, ranks, entries, sids = [row], [rank], [entry], [nsid]
        first_timer, candidates = len(self.pc.uncontrollable), len(row)
        for r in self.sits.timed[sid].nonzero()[0].tolist():
            for j, timer in enumerate(self.sits.timers[sid[r]]):
                sit, rounds = self._machine(lambda: self.machine.fire_timer_with_trace(
                    items[sid[r]], timer, self.as_dict(before[r])))
                traced[candidates] = rounds
                candidates += 1
                evid.append(np.array([len(table)]))
                table.append(timer)
                rows.append(np.array([r]))
                ranks.append(np.array([first_timer + j]))
                entries.append(codes[r:r + 1])
                sids.append(self.sits.of([sit]))
        if len(rows) > 1:  # timers: their candidates put in the order of their nodes
            row, rank, entry, nsid, ev = (np.concatenate(x) for x in (rows, ranks, entries, sids, evid))
            order = (row * (int(rank.max()) + 1) + rank).argsort(kind="stable")  # by node, then rank
        else:  # the moves alone, sorted by node then rank already
            ev, order = rank, None
        if traced:
            where = np.arange(len(row))
            if order is not None:
                where[order] = np.arange(len(order))
            for c in sorted(traced, key=lambda c: where[c]):
                i = lo + int(row[c])
                self.conflicts.extend(Conflict(i, table[ev[c]], st, names) for st, names in self.log.fresh(traced[c]))
        if order is not None:
            row, entry, nsid, ev = row[order], entry[order], nsid[order], ev[order]
        node, src = self.enter(nsid, entry)
        self.sources.append(lo + row[src])
        self.targets.append(node)
        self.edges.extend(many_edges(self.sources[-1].tolist(), [table[e] for e in ev[src].tolist()], node.tolist()))

    @staticmethod
    def _machine(call: Callable[[], tuple[Situation, Rounds]]) -> tuple[Situation, Rounds]:
        """One evolution by the machine; a transient cycle is for the machine's path to report."""
        try:
            return call()
        except InputError:
            raise Unsupported("a transient cycle") from None
