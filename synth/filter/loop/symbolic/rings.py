"""``synth filter verify --any-control --engine symbolic``: the closed loop of
:mod:`synth.filter.loop.verify` explored on BDDs, breadth-first by levels (onion rings).

A node is (plant state, filter memory, Blocked latch) as in the explicit engine; a level
is every PLC cycle from the nodes found at the previous one: up to K uncontrollable plant
events (one element at a time), then the outcomes of every request vector
(:class:`~synth.filter.loop.symbolic.cycle.SymbolicCycle`: the filter's outputs, memory and
flags as BDDs, the requests existentially quantified), then the ordered (or atomic)
write. What the explicit engine counts is counted here exactly, on the same sets:

- ``states``: the reachable nodes; ``plant_states``: their plant states; ``outside_sup``:
  those outside SUP; a *violation*: a reachable plant state violating a level constraint;
- ``cycles``: one per (node, state after the plant's events, distinct outcome), the
  outcome being (orders written, memory after, fallback, outside the care set);
- the other findings: the plant states after the plant's events from which some request
  vector breaks an edge constraint, is refused by the plant, falls back, leaves the care
  set or passes through a violating intermediate state; or (transient) a state reached by
  the plant's events that violates a constraint the node did not.

The level at which each kind of finding first appears is kept: the shortest traces come
from the explicit engine run for that many levels only (:mod:`synth.filter.loop.symbolic.verify`).

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.filter.from_rules import skeleton
>>> sk = skeleton(_plants("tri.rules"), _plants("F.filter"))  # the text only: nothing is written
>>> from synth.plant.composition import load_plant
>>> loop = SymbolicLoop(sk.filter, load_plant(_plants("tri.rules")), Algorithm.ALGEBRAIC, Mode.SUPERVISOR, False, 1)
>>> loop.run()
>>> loop.complete, loop.states, loop.cycles, sorted(map(str, loop.first_level))
(True, 12996, 2357952, ['outside_sup', 'transient'])
"""

from __future__ import annotations

from typing import Callable

from synth.filter.cycle import Algorithm, Mode
from synth.filter.language import Filter
from synth.filter.loop.product import rules_of
from synth.filter.loop.symbolic.cycle import FALLBACK, OUTSIDE, SymbolicCycle, next_name
from synth.filter.loop.verification import FindingKind
from synth.logic.bdd import Function
from synth.logic.counting import count
from synth.plant.composition import Plant
from synth.symbolic.encoding import Copy
from synth.symbolic.relation import image

__all__ = ["SymbolicLoop"]


class SymbolicLoop:
    """The breadth-first search on BDDs (module docstring); :meth:`run` fills the counts,
    ``found[kind]`` (the plant states showing each kind) and ``first_level[kind]`` (the
    level whose cycles first show it: 0 for the cycles from the initial node; a violation
    or a node outside SUP counts at the level that reaches it, -1 for the initial node)."""

    def __init__(self, f: Filter, p: Plant, algorithm: Algorithm, mode: Mode, atomic: bool,
                 events_per_cycle: int, max_states: int | None = None) -> None:
        self.report: Callable[[str], None] | None = None  # progress lines, one per level (the CLI's live line)
        self.sc = sc = SymbolicCycle(f, rules_of(p), p, algorithm, mode, atomic)
        self.k, self.max_states = events_per_cycle, max_states
        enc, e = sc.enc, sc.engine
        self.enc, self.engine = enc, e
        names = enc.variables
        self.equal_aux = e.conjunction(e.var(v).equiv(e.var(v + Copy.AUX.value)) for v in names)
        self.illegal_aux = enc.rename(sc.illegal, Copy.CURRENT, Copy.AUX)
        memory = [e.var(m) for m in sc.state_memory]
        self.initial = enc.state(sc.plant.initial) & e.conjunction(~m for m in memory)
        self.after = [next_name(m) for m in sc.state_memory]
        self.flags = [FALLBACK, OUTSIDE]
        targets = [z + Copy.NEXT.value for z in sc.orders]
        # the variables of the counts
        self.node_vars = [*names, *sc.state_memory]
        self.cycle_vars = [*names, *(v + Copy.AUX.value for v in names), *sc.state_memory, *targets,
                           *self.after, *self.flags]
        self.targets = targets
        # the relational products of one level: (post, memory) with the outcome, quantified at once
        inner = e.declare
        self.q_kind = [inner(n) for n in [*sc.state_memory, *targets]]
        flag_of = {FindingKind.EDGE: sc.edge_bad, FindingKind.REFUSED: sc.refused,
                   FindingKind.FALLBACK: e.var(FALLBACK), FindingKind.OUTSIDE_CARE: e.var(OUTSIDE),
                   FindingKind.TRANSIENT: sc.middle_bad}
        self.by_kind = {k: e.exists([*self.after, *self.flags], sc.outcome & u) for k, u in flag_of.items()}
        self.q_written = [inner(n) for n in [*sc.state_memory, *sc.orders]]
        self.written = e.exists(self.flags, sc.outcome & ~sc.refused)
        self.reach: Function = self.initial
        self.levels: list[Function] = [self.initial]  # the rings
        self.found: dict[FindingKind, Function] = {k: e.false for k in FindingKind}
        self.first_level: dict[FindingKind, int] = {}
        self.cycles = 0
        self.complete = True
        self.states = self.plant_states = self.outside_sup = 0

    # ------------------------------------------------------------------ counting
    def count(self, u: Function, names: list[str]) -> int:
        """The valuations of ``names`` in ``u`` (which depends on them only), exactly."""
        return count(self.engine, u, (self.engine.level(n) for n in names))

    def plant_part(self, u: Function) -> Function:
        """``u`` projected on the plant's current variables."""
        sc = self.sc
        u = self.engine.exists([*sc.state_memory, *self.after, *self.flags], u)
        return self.enc.exists(u, Copy.NEXT, sc.orders)

    def note(self, kind: FindingKind, states: Function, level: int) -> None:
        if states == self.engine.false:
            return
        self.found[kind] |= states
        self.first_level.setdefault(kind, level)

    # ------------------------------------------------------------------ one level
    def level(self, frontier: Function, depth: int) -> Function:
        """Every cycle from the nodes of ``frontier``; returns the new nodes."""
        sc, enc, e = self.sc, self.enc, self.engine
        pairs = frontier & self.equal_aux  # (node's state x'', memory, state after the events x)
        layer, moved = pairs, e.false
        for _ in range(self.k):
            layer = e.disjunction(image(enc, layer, m) for m in sc.uncontrollable)
            if layer == e.false:
                break
            moved |= layer
        self.note(FindingKind.TRANSIENT, self.plant_part(
            enc.exists(moved & sc.illegal & ~self.illegal_aux, Copy.AUX)), depth)
        pairs |= moved
        self.cycles += self.count(pairs & sc.outcome, self.cycle_vars)
        post = enc.exists(pairs, Copy.AUX)
        for kind, rel in self.by_kind.items():  # the post states where some request vector shows it
            self.note(kind, e.and_exists(post, rel, self.q_kind), depth)
        written = e.and_exists(post, self.written, self.q_written)  # (x but the orders, targets, memory after)
        written = enc.rename(written, Copy.NEXT, Copy.CURRENT, sc.orders)
        succ = e.let(dict(zip(self.after, sc.state_memory)), written) if self.after else written
        self.note(FindingKind.VIOLATION, self.plant_part(succ & sc.illegal), depth)
        self.note(FindingKind.OUTSIDE_SUP, self.plant_part(succ & ~self.reach & sc.removed), depth)
        new = succ & ~self.reach
        self.reach |= new
        return new

    def run(self) -> None:
        sc, e = self.sc, self.engine
        init_plant = self.plant_part(self.initial)
        if init_plant & sc.illegal != e.false:
            self.note(FindingKind.VIOLATION, init_plant, -1)
        if init_plant & sc.removed != e.false:
            self.note(FindingKind.OUTSIDE_SUP, init_plant, -1)
        frontier, depth = self.initial, 0
        while frontier != e.false:
            if self.max_states is not None and self.count(self.reach, self.node_vars) > self.max_states:
                self.complete = False
                break
            frontier = self.level(frontier, depth)
            self.levels.append(frontier)
            depth += 1
            if self.report is not None:
                self.report(f"closed loop (symbolic): level {depth}, {e.live_nodes()} BDD nodes")
        if self.levels[-1] == e.false:
            self.levels.pop()
        self.states = self.count(self.reach, self.node_vars)
        plant = self.plant_part(self.reach)
        self.plant_states = self.count(plant, list(self.enc.variables))
        self.outside_sup = self.count(plant & sc.removed, list(self.enc.variables))
        self.found[FindingKind.VIOLATION] = plant & sc.illegal
        self.found[FindingKind.OUTSIDE_SUP] = plant & sc.removed

    def counts(self) -> dict[FindingKind, int]:
        """How many plant states show each kind found."""
        names = list(self.enc.variables)
        return {k: self.count(self.found[k], names) for k in FindingKind if k in self.first_level}

