"""SYNC on BDDs with the situations in the BDD: a breadth-first level is a few operations.

The per-situation engine (:mod:`synth.symbolic.situations.sync`) keeps each stable situation an
explicit object and pays a few tens of BDD operations per situation and turn; with the
situation's steps as BDD variables (:mod:`synth.symbolic.steps.encoding`) every set below is one
BDD over (steps X, plant state x), and the exploration, the edges and the fixpoints
handle all the situations of a level at once. Same semantics as :mod:`synth.symbolic.situations.sync`
(outputs first, :mod:`synth.validation.sync`):

- *regions*: an element's region moves depend on the orders emitted for it, which are a
  function of X; per element and set of its own orders (a few), the closure of its region
  moves is computed once (:class:`~synth.symbolic.regions.ElementRegions`) and selected by the step
  variables: ``closure(X, x, x')`` is the product over the elements; ``settled`` states
  have no region move left;
- *exploration*: from the frontier F(X, x), each uncontrollable move gives entries
  E(X, n) (kept by SUP); the Grafcet's reaction ``react(X, n, X')`` (the machine's
  receptivities, search for stability) gives the target situations; the entries not
  entered before settle through the closure into the next frontier;
- *edges* per move: ``edge(X, x, X', x')`` = the reaction from the entry n = x moved,
  and n settling in x' under X'; counted exactly (the aggregated transitions);
- *coreachability* and *held* nodes are fixpoints over the edges.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> from synth.grafcet.machine import GrafcetMachine
>>> rs, p, g = load_model(_plants("../tests/data/home/production_loop.g7"), _plants("../tests/data/home/cylinder.rules"))
>>> m = GrafcetMachine(g)
>>> s = step_sync(p, rs.constraints, m)
>>> s.sync_states, s.aggregated_states, s.edge_count, s.situations
(17, 9, 21, 3)
>>> s.backward(s.initial) == s.nodes  # a livelock: the initial node is never met again
False
"""

from __future__ import annotations

from typing import Callable, Sequence

from synth.grafcet.machine import GrafcetMachine, Situation
from synth.logic.bdd import Function
from synth.logic.counting import count
from synth.logic.events import Event
from synth.plant.composition import Plant
from synth.plant.rules import Constraint
from synth.symbolic.encoding import Copy, NodeBudget, live_nodes
from synth.symbolic.numbering import SituationIndex
from synth.symbolic.regions import ElementRegions
from synth.symbolic.relation import Move, flipped, image
from synth.symbolic.steps.encoding import StepEncoding, Unsupported, anchors, unsupported
from synth.symbolic.supervisor import SymbolicSupervisor

__all__ = ["StepSync", "step_sync", "MAX_OWN_ORDERS"]

MAX_OWN_ORDERS = 6
"""An element with more orders than this goes to the per-situation engine (2^k region
closures per element)."""


class StepSync:
    """The explored SYNC over (steps, plant state): see the module docstring."""

    def __init__(self, sup: SymbolicSupervisor, machine: GrafcetMachine,
                 progress: Callable[[str], None] | None = None) -> None:
        self.sup = sup
        self.enc = sup.enc
        self.engine = sup.enc.engine
        self.plant: Plant = sup.plant
        self.machine = machine
        self.steps = StepEncoding(machine, sup.enc)
        self.closures = ElementRegions(sup)  # per element: region moves and closures, cached
        self.helper = SituationIndex(self.plant, machine)  # the situations as the searches name them
        self.progress = progress
        self.false: Function = self.engine.false
        self.true: Function = self.engine.true
        self.initial: Function = self.false
        self.nodes: Function = self.false
        self.members: Function = self.false
        self.entered: Function = self.false
        self.initial_situation: Situation | None = None
        self.reacted: dict[int, tuple[Move, Function]] = {}  # per move, its entries (X, n) met
        self._reactions: dict[Event | None, Function] = {}  # per event, the reaction (X, n, X') of its entries
        self.edges: list[tuple[Move, Function]] = []
        self.links: list[tuple[Function, Function]] = []  # per element, (where its edges end, their union)
        self.rings: list[Function] = []  # the nodes by distance from the initial nodes (the levels)
        self.refused_by: dict[Event, Function] = {}  # per order event, where SUP refuses it (X, x)
        self.region_moves: list[Function] = []  # per element, its region moves (X, x, x', x''), x the entry
        self.pairs: Function = self.false  # (X, n, x'): entries and their region's states, without a closure
        self.edge_count = 0
        self._renames: dict[tuple[Copy, Copy], tuple[Function, list[str]]] = {}
        self._inputs = frozenset(n for n in machine.inputs if n in self.plant.owner)
        self._moves = tuple(m for m in sup.moves if not m.controllable)
        e = self.engine
        self.current_vars: list[str] = [e.declare(v) for v in self.enc.variables] + self.steps.names(Copy.CURRENT)
        """A node's variables: the plant's and the steps' current copies."""
        self.next_vars: list[str] = [e.declare(v + Copy.NEXT.value) for v in self.enc.variables] + self.steps.names(Copy.NEXT)
        """Their next copies (an edge's target)."""
        self.closure, self.moving, self.refused = self._regions()

    # ---- regions
    def _regions(self) -> tuple[Function | None, Function, Function]:
        """``closure(X, x, x')``: x' reachable from x by region moves under the orders
        emitted in (X, x) — None when an element's region moves read other elements'
        orders (then :meth:`_closure` walks the region moves ``self.region_moves`` per
        entry set); ``moving(X, x)``: a region move is left; ``refused(X, x)``: SUP
        refuses a move towards an order emitted there (a prohibited order)."""
        emitted = self.steps.orders()
        regions = self.closures
        closure: Function | None = self.true
        moving, refused = self.false, self.false
        for axis in range(self.plant.ndim):
            own_all = sorted(regions.orders_of[axis])
            if len(own_all) > MAX_OWN_ORDERS:
                raise Unsupported(f"an element with more than {MAX_OWN_ORDERS} orders")
            piece = moves = self.false
            wanted: dict[str, Function] = {o: emitted[o] if o in emitted else self.false for o in own_all}
            for bits in range(1 << len(own_all)):
                own = frozenset(o for k, o in enumerate(own_all) if bits >> k & 1)
                select = self.engine.conjunction(w if o in own else ~w for o, w in wanted.items())
                if select == self.false:
                    continue
                rel, can, bad = regions.intra(axis, own)
                if regions.reads_others(axis, rel):
                    closure = None
                if closure is not None:
                    piece |= select & regions.closure(axis, rel)
                moves |= select & rel
                moving |= select & can
                for event, b in bad.items():
                    refused |= select & b
                    self.refused_by[event] = self.refused_by.get(event, self.false) | (select & b)
            self.region_moves.append(moves)
            if closure is not None:
                closure &= piece
        return closure, moving, refused

    def _closure(self, entries: Function) -> Function:
        """The pairs (X, n, x') of ``entries`` (X, n) and the states x' their region
        reaches (forward over the region moves, element by element), without a
        precomputed closure."""
        reach = frontier = entries & self.closures.equal
        while frontier != self.false:
            new = self.false  # an element's move: its next copy quantified, its auxiliary copy set
            for axis, moves in enumerate(self.region_moves):
                if moves == self.false:
                    continue
                new |= self.enc.and_exists(frontier, moves, Copy.NEXT, self.enc.element_variables[axis])
            # one renaming for every element (a term has the auxiliary copy of its own element only)
            frontier = self.enc.rename(new, Copy.AUX, Copy.NEXT) & ~reach
            reach |= frontier
        return reach

    def _enter(self, entries: Function) -> Function:
        """Settle ``entries`` (X, n): their members join ``members``; the settled states."""
        if self.closure is None:
            pairs = self._closure(entries)
            self.pairs |= pairs
            members = self.enc.rename(self.enc.exists(pairs, Copy.CURRENT), Copy.NEXT, Copy.CURRENT)
        else:
            members = self.enc.rename(self.enc.and_exists(entries, self.closure, Copy.CURRENT), Copy.NEXT, Copy.CURRENT)
        self.members |= members
        return members & ~self.moving

    # ---- exploration
    def explore(self) -> "StepSync":
        p = self.plant
        init = self.enc.state(p.initial)
        if (init & self.sup.kept) == self.false:
            raise Unsupported("SUP is empty")
        values = {n: v for n, v in p.valuation(p.initial).items() if n in self._inputs}
        s0 = self.initial_situation = self.machine.initial(values)
        self.entered = self.steps.cube(s0) & init
        frontier = self.initial = self.nodes = self._enter(self.entered)
        level = 0
        while frontier != self.false:
            self.rings.append(frontier)
            targets = self.false
            by_event: dict[Event | None, Function] = {}  # the level's entries, per event the Grafcet tells apart
            for m in self._moves:
                entries = image(self.enc, frontier, m) & self.sup.kept
                if entries == self.false:
                    continue
                event = self._event(m)
                by_event[event] = by_event.get(event, self.false) | entries
                old = self.reacted.get(m.key)
                self.reacted[m.key] = (m, entries if old is None else old[1] | entries)
            for event, entries in by_event.items():  # the reaction is node by node: one per event
                r = self.steps.react(entries, event)
                self._reactions[event] = self._reactions.get(event, self.false) | r
                targets |= self.steps.exists(r, Copy.CURRENT)
            targets = self.steps.rename(targets, Copy.NEXT, Copy.CURRENT)  # once per level: a renaming is a bijection
            new = targets & ~self.entered
            self.entered |= new
            frontier = self._enter(new) & ~self.nodes
            self.nodes |= frontier
            level += 1
            self.enc.check(f"exploring level {level} of SYNC")
            if self.progress is not None and level % 10 == 0:
                self.progress(f"exploring SYNC symbolically: level {level}, {live_nodes(self.engine)} BDD nodes")
        settled = (self.pairs if self.closure is None else self.closure) & ~self.enc.rename(self.moving, Copy.CURRENT, Copy.NEXT)
        target = self.steps.rename(settled, Copy.CURRENT, Copy.NEXT)  # (X', n, x')
        for key in sorted(self.reacted):
            m, entries = self.reacted[key]  # its reaction: the event's, on its own entries
            self.edges.append((m, flipped(self.enc, self._reactions[self._event(m)] & entries & target, m)))
        self.reacted = {}
        self._reactions = {}
        self.pairs = self.false
        self.edge_count = sum(self.count(e, self.current_vars + self.next_vars) for _, e in self.edges)
        by_axis: dict[int, tuple[Function, Function]] = {}  # per element: where its edges end, their union
        for m, e in self.edges:
            end, rel = by_axis.get(m.axis, (self.false, self.false))
            by_axis[m.axis] = (end | m.after, rel | e)
        self.links = [by_axis[a] for a in sorted(by_axis)]
        return self

    def _event(self, m: Move) -> Event | None:
        """The event the Grafcet reacts to after ``m``: None when no receptivity reads its
        edge (the reaction is then the same for every such move)."""
        if m.variable not in self._inputs or not self.steps.reads_edge(m.event):
            return None
        return m.event

    # ---- counts
    def count(self, u: Function, inner: Sequence[str]) -> int:
        """Models of ``u`` over the manager's variables ``inner`` (``u`` depends on no other)."""
        return count(self.engine, u, (self.engine.bdd.level_of_var(v) for v in inner))

    @property
    def sync_states(self) -> int:
        return self.count(self.members, self.current_vars)

    @property
    def aggregated_states(self) -> int:
        return self.count(self.nodes, self.current_vars)

    @property
    def situations(self) -> int:
        """The number of stable situations met (with a node)."""
        return self.count(self.enc.exists(self.nodes, Copy.CURRENT), self.steps.names(Copy.CURRENT))

    def reached_steps(self) -> frozenset[str]:
        return frozenset(s for s in self.steps.steps if (self.nodes & self.steps.var(s)) != self.false)

    # ---- fixpoints
    def primed(self, u: Function) -> Function:
        """``u`` from the current copies (plant and steps) to the next ones."""
        return self._rename(u, Copy.CURRENT, Copy.NEXT)

    def _rename(self, u: Function, source: Copy, target: Copy) -> Function:
        """``u`` with the ``source`` copy of the plant and step variables renamed to
        ``target``: one relational product with both equalities (cached)."""
        hit = self._renames.get((source, target))
        if hit is None:
            names = [self.engine.declare(v + source.value) for v in self.enc.variables] + self.steps.names(source)
            equal = self.steps.equal(source, target) & self.engine.conjunction(
                self.engine.var(v + source.value).equiv(self.engine.var(v + target.value)) for v in self.enc.variables)
            hit = self._renames[(source, target)] = (equal, names)
        return self.engine.and_exists(u, hit[0], hit[1])

    def pre(self, u: Function, edges: Sequence[tuple[Move, Function]] | None = None,
            within: Function | None = None) -> Function:
        """Nodes (of ``within``, default all) with an edge (of ``edges``, default all) into
        ``u``. An edge of a move ends where its flipped variable has its new value (region
        moves flip orders only): the others are skipped without a relational product."""
        target = self.primed(u)
        out = self.false
        arcs = self.links if edges is None else [(m.after, e) for m, e in edges]
        for end, e in arcs:
            if (u & end) != self.false:
                found = self.engine.and_exists(e, target, self.next_vars)
                out |= found if within is None else found & within
        return out

    def image(self, u: Function, m: Move, e: Function) -> Function:
        """Targets of the edges ``e`` of move ``m`` from ``u``, in the next copies."""
        if (u & m.guard) == self.false:
            return self.false
        return self.engine.and_exists(e, u, self.current_vars)

    def unprimed(self, u: Function) -> Function:
        """``u`` from the next copies (plant and steps) to the current ones."""
        return self._rename(u, Copy.NEXT, Copy.CURRENT)

    def post(self, u: Function, edges: Sequence[tuple[Move, Function]] | None = None) -> Function:
        """Nodes an edge (of ``edges``, default all) leads to from ``u``."""
        out = self.false
        for m, e in (self.edges if edges is None else edges):
            out |= self.image(u, m, e)
        return self.unprimed(out)

    def backward(self, targets: Function, within: Function | None = None) -> Function:
        """Nodes from which ``targets`` can be reached (targets included; only through
        nodes of ``within`` when given)."""
        reached = frontier = targets
        while frontier != self.false:
            frontier = self.pre(frontier) & ~reached
            if within is not None:
                frontier &= within
            reached |= frontier
        return reached

    def forward(self, sources: Function) -> Function:
        """Nodes reachable from ``sources`` (included)."""
        reached = frontier = sources
        while frontier != self.false:
            frontier = self.post(frontier) & ~reached
            reached |= frontier
        return reached

    def held(self, node: Function) -> bool:
        """Whether no node with other active steps is reachable from ``node`` (one node)."""
        steps = self.enc.exists(node, Copy.CURRENT)
        reached = frontier = node
        while frontier != self.false:
            nxt = self.post(frontier)
            if (nxt & ~steps) != self.false:
                return False
            frontier = nxt & ~reached
            reached |= frontier
        return True


def step_sync(
    p: Plant,
    constraints: Sequence[Constraint],
    machine: GrafcetMachine,
    *,
    budget: NodeBudget | None = None,
    progress: Callable[[str], None] | None = None,
) -> StepSync:
    """Explore SYNC with the steps in the BDD (raises :class:`Unsupported` when it cannot)."""
    why = unsupported(machine, p)
    if why is not None:
        raise Unsupported(why)
    sup = SymbolicSupervisor(p, constraints, budget, anchors(machine, p))
    return StepSync(sup, machine, progress).explore()
