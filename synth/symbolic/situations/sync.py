"""SYNC on BDDs: situations explicit, plant states symbolic, regions as relations.

The Grafcet's stable situations stay explicit objects (:class:`~synth.grafcet.machine.Situation`,
computed by the one :class:`~synth.grafcet.machine.GrafcetMachine`), the plant states of
each situation are BDDs. This is what explodes in the explicit engine: N cylinders moving
at once give every interleaving of their moves as SYNC states, while the situations stay
few (about 2·2^N here against ~3^N·2^N plant states).

For one situation ``σ`` (semantics of :mod:`synth.validation.sync`, outputs first):

- the orders it emits ``W`` may depend on the inputs (conditional actions); the *region*
  moves are the controllable moves SUP allows that flip an order towards ``W``
  (``intra``), a relation per element;
- ``reg[σ](x, x')``: entry state ``x`` of the region, ``x'`` one of its *settled* states
  (no region move left), a forward closure over pairs (three variable copies);
- the aggregated nodes of ``σ`` are the settled states; from them the plant's
  uncontrollable moves and the situation's timers lead to entries of the next situations.

*The reaction of the Grafcet* to a plant move is computed by the explicit machine on one
state of the image, with an input mapping that records which inputs the machine read:
the result holds for every state agreeing on those inputs (a cube), which is cut off, and
so on until the image is covered. Each explicit call thus stands for a whole set of
states, and the reading of IEC 60848 stays the one of the machine.

The exploration is breadth-first over the aggregated automaton, level by level: the
levels (*onion rings*) give the distances the explicit analysis sorts by, and the
shortest traces. Edges are kept as *bundles* (source situation, event, target
situation, the entry states), counted exactly, and merged per pair of situations into
pair relations over (node, node') for backward fixpoints.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> from synth.grafcet.machine import GrafcetMachine
>>> rs, p, g = load_model(_plants("../grafcets/tri.g7"), _plants("tri.rules"))
>>> s = symbolic_sync(p, rs.constraints, GrafcetMachine(g))
>>> s.aggregated_states == 0
False
"""

from __future__ import annotations

from functools import partial
from typing import Callable, Sequence, TypeVar

from synth.grafcet.language import ON_EVENT, Transition
from synth.grafcet.machine import GrafcetMachine, Situation
from synth.grafcet.recorder import InputRecorder
from synth.logic.bdd import Function
from synth.logic.events import Event
from synth.logic.expr import Edge as ExprEdge, names
from synth.plant.composition import Plant
from synth.plant.rules import Constraint
from synth.symbolic.encoding import Copy, NodeBudget, live_nodes
from synth.symbolic.regions import ElementRegions
from synth.symbolic.situations.graph import Bundle, NodeSet, Region, SyncGraph
from synth.symbolic.relation import Move, image, pair_preimage, preimage
from synth.symbolic.supervisor import SymbolicSupervisor
from synth.validation.conflicts import ConflictLog

__all__ = ["SymbolicSync", "symbolic_sync"]

R = TypeVar("R")  # what the machine answers
Rounds = tuple[tuple[Transition, ...], ...]  # the transitions fired, round by round



class SymbolicSync(SyncGraph):
    """The explored SYNC (see module docstring): the aggregated graph it fills, and the
    exploration's own state (regions' relations, caches, the conflicts met)."""

    def __init__(self, sup: SymbolicSupervisor, machine: GrafcetMachine, *, progress: Callable[[str], None] | None = None) -> None:
        super().__init__(sup.enc)
        self.sup = sup
        self.plant: Plant = sup.plant
        self.machine = machine
        self._index: dict[Situation, int] = {}
        self._bundles: dict[tuple[int, tuple[int, int], int], Bundle] = {}
        self._batch: NodeSet = {}
        self.conflicts: list[tuple[int, Function, Event, str, tuple[str, ...]]] = []
        self._conflict_log = ConflictLog()
        self._inputs = tuple(n for n in machine.inputs if n in self.plant.owner)
        self._intra: dict[frozenset[str], tuple[tuple[Function, ...], Function, dict[Event, Function]]] = {}
        self._domain_cache: dict[frozenset[str], tuple[Function, ...]] = {}
        self._unread_cache: dict[Situation, frozenset[str]] = {}
        self._products: dict[frozenset[str], tuple[Function, Function] | None] = {}
        self._pieces: dict[tuple[int, frozenset[str]], Function | None] = {}  # None: reads other elements' orders
        self.closures = ElementRegions(sup)  # per element: region moves and closures
        self.progress = progress

    # ------------------------------------------------------------------ helpers
    def situation(self, sit: Situation) -> int:
        i = self._index.get(sit)
        if i is None:
            i = len(self.situations)
            self._index[sit] = i
            self.situations.append(sit)
            self.regions.append(Region(self.false, self.false, self.false, self.false))
        return i

    def values(self, u: Function) -> dict[str, bool]:
        """The Grafcet's inputs in one state of ``u``."""
        val = self.enc.pick(u)
        assert val is not None
        return {n: val[n] for n in self._inputs}

    def partition(self, states: Function, answer: Callable[[InputRecorder], R]) -> list[tuple[R, Function]]:
        """``states`` cut into cells on which ``answer`` (a call of the machine on recorded
        inputs) gives one result; results in the order first met."""
        out: list[tuple[R, Function]] = []
        rest = states
        while rest != self.false:
            rec = InputRecorder(partial(self.values, rest))
            result = answer(rec)
            part = rest & self.engine.cube(rec.cell())
            rest = rest & ~part
            for k, (r, u) in enumerate(out):
                if r == result:
                    out[k] = (r, u | part)
                    break
            else:
                out.append((result, part))
        return out

    def intra(self, wanted: frozenset[str]) -> tuple[tuple[Function, ...], Function, dict[Event, Function]]:
        """For emitted orders ``wanted``: per element the region moves as a relation over
        (member x', next member x''), the states with a region move left, and per order
        event the states where SUP refuses that move."""
        hit = self._intra.get(wanted)
        if hit is not None:
            return hit
        rel = []
        progress = self.false
        refused: dict[Event, Function] = {}
        for axis in range(self.plant.ndim):
            r, can, bad = self.closures.intra(axis, self.closures.own(axis, wanted))
            rel.append(r)
            progress |= can
            refused.update(bad)
        hit = (tuple(rel), progress, refused)
        self._intra[wanted] = hit
        return hit

    def _product_region(self, wanted: frozenset[str]) -> tuple[Function, Function] | None:
        """When no element's region moves read another element's orders, a region is the
        product of the elements' own regions (inputs do not change in a region): the
        pairs (entry x, member x') and (entry x, settled x') as products of per-element
        closures, cached per element and emitted orders; None otherwise."""
        if wanted in self._products:
            return self._products[wanted]
        rel, progress, _ = self.intra(wanted)
        pieces = []
        for axis, r in enumerate(rel):
            key = (axis, self.closures.own(axis, wanted))
            if key not in self._pieces:
                self._pieces[key] = None if self.closures.reads_others(axis, r) else self.closures.closure(axis, r)
            piece = self._pieces[key]
            if piece is None:
                self._products[wanted] = None
                return None
            pieces.append(piece)
        members = self.engine.conjunction(pieces)
        hit = (members, members & ~self.enc.rename(progress, Copy.CURRENT, Copy.NEXT))
        self._products[wanted] = hit
        return hit

    def _domains(self, wanted: frozenset[str]) -> tuple[Function, ...]:
        """Per element, the members (next copy) from which it has a region move."""
        hit = self._domain_cache.get(wanted)
        if hit is None:
            rel, _, _ = self.intra(wanted)
            hit = tuple(self.enc.exists(r, Copy.AUX, names) for r, names in zip(rel, self.enc.element_variables))
            self._domain_cache[wanted] = hit
        return hit

    def region_pairs(self, entries: Function, wanted: frozenset[str]) -> tuple[Function, Function, Function]:
        """``(reg, members, settled)`` for ``entries`` under emitted orders ``wanted``:
        ``reg(x, x')`` pairs an entry with a settled state (forward closure of the region
        moves over pairs, restricted to settled x'), the members and the settled states
        (current copy)."""
        rel, progress, _ = self.intra(wanted)
        if (entries & progress) == self.false:  # already settled: the region is its entry
            return entries & self.closures.equal, entries, entries
        product = self._product_region(wanted)
        if product is not None:
            members, settled = product
            members = self.post_pairs(entries, members)
            return entries & settled, members, members & ~progress  # settled: members with no region move left
        domains = self._domains(wanted)
        reach = entries & self.closures.equal
        frontier = reach
        while frontier != self.false:
            new = self.false
            for axis, r in enumerate(rel):
                if r == self.false or (frontier & domains[axis]) == self.false:
                    continue
                names = self.enc.element_variables[axis]
                step = self.enc.and_exists(frontier, r, Copy.NEXT, names)
                new |= self.enc.rename(step, Copy.AUX, Copy.NEXT, names)
            frontier = new & ~reach
            reach |= frontier
        members = self.post_pairs(self.true, reach)
        return reach & ~self.enc.rename(progress, Copy.CURRENT, Copy.NEXT), members, members & ~progress

    def enter(self, s: int, entries: Function) -> Function:
        """Enter situation ``s`` at ``entries``; returns the settled states not seen before."""
        reg = self.regions[s]
        new_entries = entries & ~reg.entered
        if new_entries == self.false:
            return self.false
        reg.entered |= new_entries
        sit = self.situations[s]
        fresh = self.false
        for wanted, part in self.partition(new_entries, lambda rec: self.machine.orders(sit, rec)):
            pairs, members, settled = self.region_pairs(part, wanted)
            reg.pairs |= pairs
            reg.members |= members
            reg.by_orders[wanted] = reg.by_orders.get(wanted, self.false) | settled
            fresh |= settled & ~reg.nodes
            reg.nodes |= settled
        self.enc.check(f"entering situation {sit.text()}")
        return fresh

    # ------------------------------------------------------------------ exploration
    def _successors(self, s: int, nodes: Function, pending: NodeSet) -> None:
        sit = self.situations[s]
        machine = self.machine
        unread = self._unread(sit)
        for m in self.sup.moves:
            if m.controllable:
                continue
            entries = image(self.enc, nodes, m) & self.sup.kept
            if entries == self.false:
                continue
            if m.variable in unread:  # the machine would answer: same situation, nothing fired
                self._bundle(s, m.event, s, entries, m, (0, m.key), pending)
                continue
            event = m.event if m.variable in self._inputs else None

            def react(rec: InputRecorder, event: Event | None = event) -> tuple[Situation, Rounds]:
                return machine.react_event(sit, event, rec)

            for (target, rounds), part in self.partition(entries, react):
                t = self.situation(target)
                found = self._conflict_log.fresh(rounds) if rounds else []
                if found:
                    sources = preimage(self.enc, part, m) & nodes
                    self.conflicts += [(s, sources, m.event, st, fired) for st, fired in found]
                self._bundle(s, m.event, t, part, m, (0, m.key), pending)
        for rank, timer in enumerate(machine.timers(sit)):
            def fire(rec: InputRecorder, timer: Event = timer) -> tuple[Situation, Rounds]:
                return machine.fire_timer_with_trace(sit, timer, rec)

            for (target, rounds), part in self.partition(nodes, fire):
                t = self.situation(target)
                found = self._conflict_log.fresh(rounds) if rounds else []
                self.conflicts += [(s, part, timer, st, fired) for st, fired in found]
                self._bundle(s, timer, t, part, None, (1, rank), pending)

    def _unread(self, sit: Situation) -> frozenset[str]:
        """Plant variables whose change cannot change ``sit``: not read by an enabled
        transition nor by an event action of an active step (``relevant_inputs``), when no
        enabled receptivity has an edge and no active step has event actions (the node's
        situation is stable at its input levels, so nothing can fire). Empty otherwise."""
        hit = self._unread_cache.get(sit)
        if hit is None:
            machine = self.machine
            enabled = machine.awaited(sit)
            has_edges = any(isinstance(n, ExprEdge) for t in enabled for n in names(t.receptivity))
            has_events = any(machine.event_inputs(st) or any(getattr(a, "when", None) == ON_EVENT for a in machine.grafcet.step(st).actions)
                             for st in sit.steps)
            if has_edges or has_events:
                hit = frozenset()
            else:
                hit = frozenset(self.enc.variables) - machine.relevant_inputs(sit)
            self._unread_cache[sit] = hit
        return hit

    def _bundle(self, s: int, event: Event, t: int, entries: Function, move: Move | None, key: tuple[int, int],
                pending: NodeSet) -> None:
        """Record the edges; the target's region is entered once per turn (``_enter_batch``)."""
        self._batch[t] = self._batch.get(t, self.false) | entries
        old = self._bundles.get((s, key, t))
        self._bundles[(s, key, t)] = Bundle(s, event, t, entries if old is None else old.entries | entries, move, key)

    def _enter_batch(self, pending: NodeSet) -> None:
        for t, entries in sorted(self._batch.items()):
            fresh = self.enter(t, entries)
            if fresh != self.false:
                pending[t] = pending.get(t, self.false) | fresh
        self._batch = {}

    def explore(self) -> "SymbolicSync":
        """The reachable aggregated automaton: a worklist over situations, each expanding
        the nodes it gained since its last turn (a plain loop until nothing is pending)."""
        p = self.plant
        init = self.enc.state(p.initial)
        if (init & self.sup.kept) == self.false:
            return self
        values = {n: v for n, v in p.valuation(p.initial).items() if n in self._inputs}
        s0 = self.situation(self.machine.initial(values))
        self.initial = {s0: self.enter(s0, init)}
        pending: NodeSet = dict(self.initial)
        turns = 0
        while pending:
            s = min(pending)
            nodes = pending.pop(s)
            self._successors(s, nodes, pending)
            self._enter_batch(pending)
            turns += 1
            if self.progress is not None and turns % 50 == 0:
                self.progress(f"exploring SYNC symbolically: {len(self.situations)} situations, "
                              f"{len(pending)} pending, {live_nodes(self.engine)} BDD nodes")
        bundles = [self._edges(b) for b in sorted(self._bundles.values(), key=lambda b: (b.source, b.key, b.target))]
        self._sync_states = sum(self.enc.count(r.members) for r in self.regions)
        for r in self.regions:  # only the nodes are read from here on: free the rest
            r.entered = r.pairs = r.members = self.false
        self._bundles = {}
        self.link(bundles)
        return self

    def _edges(self, b: Bundle) -> Bundle:
        """``b`` with its pair relation: source node x, target node x' (the entry n, between
        them, quantified: it is x moved by ``b.move``, or x itself for a timer)."""
        if b.move is None:
            pairs = b.entries & self.regions[b.target].pairs  # (n, x'): n = x
        else:  # n is x moved: the preimage on the current copy
            pairs = pair_preimage(self.enc, b.entries, self.regions[b.target].pairs, b.move)
        return Bundle(b.source, b.event, b.target, self.false, b.move, b.key, pairs)  # entries no longer needed


def symbolic_sync(
    p: Plant,
    constraints: Sequence[Constraint],
    machine: GrafcetMachine,
    *,
    budget: NodeBudget | None = None,
    progress: Callable[[str], None] | None = None,
    sup: SymbolicSupervisor | None = None,
) -> SymbolicSync:
    """Explore SYNC symbolically (see module docstring)."""
    if sup is None:
        sup = SymbolicSupervisor(p, constraints, budget)
    return SymbolicSync(sup, machine, progress=progress).explore()
