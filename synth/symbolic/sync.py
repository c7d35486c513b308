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
>>> from synth.plant.rules_check import load_rules
>>> from synth.plant.composition import plant, _plants
>>> from synth.grafcet.language_check import load_grafcet
>>> from synth.grafcet.machine import GrafcetMachine
>>> rs = load_rules(_plants("tri.rules"))
>>> p = plant(rs)
>>> g = load_grafcet(_plants("../grafcets/tri.g7"), inputs=p.inputs, outputs=p.outputs)
>>> s = symbolic_sync(p, rs.constraints, GrafcetMachine(g))
>>> s.aggregated_states == 0
False
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Iterable, Mapping, Sequence

from synth.logic.bdd import Function
from synth.grafcet.language import ON_EVENT, Transition
from synth.grafcet.machine import GrafcetMachine, Situation
from synth.logic.events import Event
from synth.logic.expr import Edge as ExprEdge, names
from synth.plant.composition import Plant
from synth.plant.rules import Constraint
from synth.symbolic.encoding import Copy, NodeBudget, live_nodes
from synth.symbolic.relation import Move, image, pair_preimage, preimage
from synth.symbolic.supervisor import SymbolicSupervisor

__all__ = ["Bundle", "Link", "Region", "SymbolicSync", "symbolic_sync"]

NodeSet = dict[int, Function]  # situation index -> plant states (current copy)


class _Recorder(dict):
    """Input values that remember which names were read (the machine is deterministic,
    so its answer holds for every valuation agreeing on them). The values are fetched
    (a state picked from a BDD) only when the machine first looks at them: a situation
    whose orders do not depend on the inputs costs no pick."""

    def __init__(self, fetch: Callable[[], Mapping[str, bool]]) -> None:
        super().__init__()
        self.read: set[str] = set()
        self._fetch: Callable[[], Mapping[str, bool]] | None = fetch

    def _load(self) -> None:
        if self._fetch is not None:
            dict.update(self, self._fetch())
            self._fetch = None

    def __getitem__(self, name: str) -> bool:
        self._load()
        self.read.add(name)
        return dict.__getitem__(self, name)

    def __contains__(self, name: object) -> bool:
        self._load()
        return dict.__contains__(self, name)

    def __iter__(self):  # type: ignore[no-untyped-def]
        self._load()
        return dict.__iter__(self)

    def __len__(self) -> int:
        self._load()
        return dict.__len__(self)

    def keys(self):  # type: ignore[no-untyped-def]
        self._load()
        return dict.keys(self)

    def get(self, name: str, default: object = None) -> object:
        return self[name] if name in self else default

    def items(self):  # type: ignore[no-untyped-def]
        self.read.update(self)
        return dict.items(self)

    def values(self):  # type: ignore[no-untyped-def]
        self.read.update(self)
        return dict.values(self)


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


class SymbolicSync:
    """The explored SYNC (see module docstring)."""

    def __init__(self, sup: SymbolicSupervisor, machine: GrafcetMachine, *, progress: Callable[[str], None] | None = None) -> None:
        self.sup = sup
        self.enc = sup.enc
        self.plant: Plant = sup.plant
        self.machine = machine
        self.engine = sup.enc.engine
        self.false = self.engine.false
        self.true = self.engine.true
        self.situations: list[Situation] = []
        self._index: dict[Situation, int] = {}
        self.regions: list[Region] = []
        self.bundles: list[Bundle] = []
        self.links: list[Link] = []
        self._bundles: dict[tuple[int, tuple[int, int], int], Bundle] = {}
        self._batch: NodeSet = {}
        self.rings: list[NodeSet] = []
        self.edge_count = 0
        self.conflicts: list[tuple[int, Function, Event, str, tuple[str, ...]]] = []
        self._conflict_keys: set[tuple[str, tuple[str, ...]]] = set()
        self._inputs = tuple(n for n in machine.inputs if n in self.plant.owner)
        self._intra: dict[frozenset[str], tuple[tuple[Function, ...], Function, dict[Event, Function]]] = {}
        self._eq: Function | None = None
        self._domain_cache: dict[frozenset[str], tuple[Function, ...]] = {}
        self._unread_cache: dict[Situation, frozenset[str]] = {}
        self._region_moves: dict[int, tuple[Function, Function, Function]] = {}
        self._products: dict[frozenset[str], tuple[Function, Function] | None] = {}
        self._pieces: dict[tuple[int, frozenset[str]], Function | None] = {}  # None: reads other elements' orders
        self._element_intras: dict[tuple[int, frozenset[str]], tuple[Function, Function, dict[Event, Function]]] = {}
        self._orders_of = tuple(frozenset(e.orders) for e in self.plant.elements)
        self._controllable = tuple(tuple(m for m in sup.moves if m.controllable and m.axis == a) for a in range(self.plant.ndim))
        self._other_orders: tuple[frozenset[str], ...] = tuple(
            frozenset(o + Copy.NEXT.value for b, e in enumerate(self.plant.elements) if b != a for o in e.orders)
            for a in range(self.plant.ndim))
        self.progress = progress
        self.initial: NodeSet = {}
        self._sync_states = 0

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

    def _cell(self, rec: _Recorder) -> Function:
        return self.engine.cube({n: dict.__getitem__(rec, n) for n in sorted(rec.read)})

    def partition(self, states: Function, answer: Callable[[_Recorder], object]) -> list[tuple[object, Function]]:
        """``states`` cut into cells on which ``answer`` (a call of the machine on recorded
        inputs) gives one result; results in the order first met."""
        out: list[tuple[object, Function]] = []
        rest = states
        while rest != self.false:
            rec = _Recorder(lambda rest=rest: self.values(rest))
            result = answer(rec)
            part = rest & self._cell(rec)
            rest = rest & ~part
            for k, (r, u) in enumerate(out):
                if r == result:
                    out[k] = (r, u | part)
                    break
            else:
                out.append((result, part))
        return out

    @property
    def equal(self) -> Function:
        """x = x' on every plant variable."""
        if self._eq is None:
            self._eq = self.engine.conjunction(
                self.engine.var(v).equiv(self.engine.var(v + Copy.NEXT.value)) for v in self.enc.variables)
        return self._eq

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
            r, can, bad = self._element_intra(axis, self._own_orders(axis, wanted))
            rel.append(r)
            progress |= can
            refused.update(bad)
        hit = (tuple(rel), progress, refused)
        self._intra[wanted] = hit
        return hit

    def _own_orders(self, axis: int, wanted: frozenset[str]) -> frozenset[str]:
        return wanted & self._orders_of[axis]

    def _element_intra(self, axis: int, own: frozenset[str]) -> tuple[Function, Function, dict[Event, Function]]:
        """:meth:`intra` for one element, whose region moves depend only on its own
        emitted orders ``own`` (a controllable move flips one of its orders)."""
        key = (axis, own)
        hit = self._element_intras.get(key)
        if hit is None:
            rel = progress = self.false
            refused: dict[Event, Function] = {}
            for m in self._controllable[axis]:
                if m.event.rising != (m.variable in own):
                    continue
                shifted, can, bad = self._region_move(m)
                progress |= can
                if bad != self.false:
                    refused[m.event] = refused.get(m.event, self.false) | bad
                rel |= shifted
            hit = self._element_intras[key] = (rel, progress, refused)
        return hit

    def _region_move(self, m: Move) -> tuple[Function, Function, Function]:
        """For one controllable move, computed once: its allowed part over (member x',
        next member x''), the states where it is allowed, those where SUP refuses it."""
        hit = self._region_moves.get(m.key)
        if hit is None:
            ok = self.sup.allowed(m)
            names = self.enc.element_variables[m.axis]
            can = self.enc.exists(ok, Copy.NEXT, names)
            bad = m.guard & ~can  # the guard: where the move exists at all
            shifted = self.enc.rename(self.enc.rename(ok, Copy.NEXT, Copy.AUX, names), Copy.CURRENT, Copy.NEXT)
            hit = (shifted, can, bad)
            self._region_moves[m.key] = hit
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
            key = (axis, self._own_orders(axis, wanted))
            if key not in self._pieces:
                others = self._other_orders[axis]
                reads_others = r != self.false and any(n in others for n in self.engine.support(r))
                self._pieces[key] = None if reads_others else self._element_region(axis, r)
            piece = self._pieces[key]
            if piece is None:
                self._products[wanted] = None
                return None
            pieces.append(piece)
        members = self.engine.conjunction(pieces)
        hit = (members, members & ~self.enc.rename(progress, Copy.CURRENT, Copy.NEXT))
        self._products[wanted] = hit
        return hit

    def _element_region(self, axis: int, r: Function) -> Function:
        """Pairs (x_a, x'_a) of element ``axis``: x'_a reachable from x_a by its region moves ``r``."""
        names = self.enc.element_variables[axis]
        reach = self.engine.conjunction(self.engine.var(v).equiv(self.engine.var(v + Copy.NEXT.value)) for v in names)
        frontier = reach
        while frontier != self.false and r != self.false:
            step = self.enc.rename(self.enc.and_exists(frontier, r, Copy.NEXT, names), Copy.AUX, Copy.NEXT, names)
            frontier = step & ~reach
            reach |= frontier
        return reach

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
            return entries & self.equal, entries, entries
        product = self._product_region(wanted)
        if product is not None:
            members, settled = product
            members = self.post_pairs(entries, members)
            return entries & settled, members, members & ~progress  # settled: members with no region move left
        domains = self._domains(wanted)
        reach = entries & self.equal
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

    def post_pairs(self, sources: Function, pairs: Function) -> Function:
        """The x' of the pairs ``(x, x')`` whose x is in ``sources``, as current states."""
        return self.enc.rename(self.enc.and_exists(sources, pairs, Copy.CURRENT), Copy.NEXT, Copy.CURRENT)

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
            assert isinstance(wanted, frozenset)
            pairs, members, settled = self.region_pairs(part, wanted)
            reg.pairs |= pairs
            reg.members |= members
            reg.by_orders[wanted] = reg.by_orders.get(wanted, self.false) | settled
            fresh |= settled & ~reg.nodes
            reg.nodes |= settled
        self.enc.check(f"entering situation {sit.text()}")
        return fresh

    # ------------------------------------------------------------------ exploration
    def _new_conflicts(self, rounds: Sequence[Sequence[Transition]]) -> bool:
        """Whether ``rounds`` fire several transitions of one step not reported yet."""
        for fired in rounds:
            by_step: dict[str, list[str]] = {}
            for tr in fired:
                for st in tr.sources:
                    by_step.setdefault(st, []).append(tr.name)
            if any(len(v) > 1 and (st, tuple(v)) not in self._conflict_keys for st, v in by_step.items()):
                return True
        return False

    def _note_conflicts(self, s: int, sources: Function, event: Event, rounds: Sequence[Sequence[Transition]]) -> None:
        for fired in rounds:
            by_step: dict[str, list[str]] = {}
            for tr in fired:
                for st in tr.sources:
                    by_step.setdefault(st, []).append(tr.name)
            for st, fired_names in by_step.items():
                key = (st, tuple(fired_names))
                if len(fired_names) > 1 and key not in self._conflict_keys:
                    self._conflict_keys.add(key)
                    self.conflicts.append((s, sources, event, st, tuple(fired_names)))

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

            def react(rec: _Recorder, event: Event | None = event) -> tuple[Situation, tuple]:
                return machine.react_event(sit, event, rec)

            for (target, rounds), part in self.partition(entries, react):
                t = self.situation(target)
                if rounds and self._new_conflicts(rounds):
                    self._note_conflicts(s, preimage(self.enc, part, m) & nodes, m.event, rounds)
                self._bundle(s, m.event, t, part, m, (0, m.key), pending)
        for rank, timer in enumerate(machine.timers(sit)):
            def fire(rec: _Recorder, timer: Event = timer) -> tuple[Situation, tuple]:
                return machine.fire_timer_with_trace(sit, timer, rec)

            for (target, rounds), part in self.partition(nodes, fire):
                t = self.situation(target)
                if rounds and self._new_conflicts(rounds):
                    self._note_conflicts(s, part, timer, rounds)
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
            has_events = any(machine._event_inputs[st] or any(getattr(a, "when", None) == ON_EVENT for a in machine.grafcet.step(st).actions)
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
        self.bundles = [self._edges(b) for b in sorted(self._bundles.values(), key=lambda b: (b.source, b.key, b.target))]
        self._sync_states = sum(self.enc.count(r.members) for r in self.regions)
        for r in self.regions:  # only the nodes are read from here on: free the rest
            r.entered = r.pairs = r.members = self.false
        self._bundles = {}
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
        self._into: dict[int, list[Link]] = {}
        self._out: dict[int, list] = {}
        self._from: dict[int, list[Link]] = {}
        for link in self.links:
            self._into.setdefault(link.target, []).append(link)
            self._from.setdefault(link.source, []).append(link)
        self._in: dict[int, list[Bundle]] = {}
        for b in self.bundles:
            self._out.setdefault(b.source, []).append(b)
            self._in.setdefault(b.target, []).append(b)
        return self

    def _edges(self, b: Bundle) -> Bundle:
        """``b`` with its pair relation: source node x, target node x' (the entry n, between
        them, quantified: it is x moved by ``b.move``, or x itself for a timer)."""
        if b.move is None:
            pairs = b.entries & self.regions[b.target].pairs  # (n, x'): n = x
        else:  # n is x moved: the preimage on the current copy
            pairs = pair_preimage(self.enc, b.entries, self.regions[b.target].pairs, b.move)
        return Bundle(b.source, b.event, b.target, self.false, b.move, b.key, pairs)  # entries no longer needed

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
                u = self.enc.rename(u, Copy.NEXT, Copy.CURRENT) & ~seen.get(s, self.false)
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

    def in_bundles(self, target: int) -> list[Bundle]:
        return self._in.get(target, [])

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
                old = reached.get(t, self.false)
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
                old = reached.get(link.target, self.false)
                grown = u & ~old
                if grown != self.false:
                    reached[link.target] = old | grown
                    if link.target not in work:
                        work.append(link.target)
        return reached

    def nodes(self) -> NodeSet:
        return {s: r.nodes for s, r in enumerate(self.regions) if r.nodes != self.false}

    def depth(self, s: int, u: Function) -> int | None:
        """The ring of the first node of ``u`` (in situation ``s``)."""
        for k, ring in enumerate(self.onion_rings()):
            if (ring.get(s, self.false) & u) != self.false:
                return k
        return None


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
