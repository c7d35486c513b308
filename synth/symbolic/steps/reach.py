"""The SYNC over (steps, plant state) seen through :class:`~synth.symbolic.interface.SymbolicGraph`.

A set of nodes is one BDD over (steps, plant state) (:class:`~synth.symbolic.steps.sync.StepSync`),
a move a plant move with its edge relation; the searches are :mod:`synth.symbolic.searches`'s:

- the onion rings are the exploration's levels (a level is exactly the nodes one edge
  beyond the previous ones not met before);
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

from typing import TYPE_CHECKING, Collection, Iterable, Sequence

from synth.errors import LimitExceeded
from synth.grafcet.language import step_variable
from synth.grafcet.machine import Situation
from synth.logic.bdd import Function
from synth.logic.events import Event
from synth.logic.expr import Expr, evaluate
from synth.symbolic.encoding import Copy, first_path
from synth.symbolic.interface import Key, PathKey, Steps
from synth.symbolic.relation import Move
from synth.symbolic.searches import MAX_LISTED, Path, first_node, shortest_trace, terminal_components
from synth.symbolic.steps.encoding import step_name
from synth.symbolic.steps.sync import StepSync

if TYPE_CHECKING:  # pragma: no cover - the explicit order needs the explicit engine's region search
    from synth.symbolic.ties import Settled

__all__ = ["StepReach", "Arc"]

Arc = tuple[Move, Function]  # a plant move and its edges (X, x, X', x')


class StepReach:
    """:class:`~synth.symbolic.interface.SymbolicGraph` over an explored :class:`StepSync`:
    named nodes, and the searches the findings need."""

    def __init__(self, s: StepSync) -> None:
        self.s = s
        self.false = s.false
        self.numbering = s.helper
        self.initial: Function = s.initial  # the graph is explored: its sets no longer change
        self.reached: Function = s.nodes
        self.situations: list[Situation] = s.helper.situations  # the explicit nodes' numbering
        self._cubes: dict[Key, Function] = {}
        self._primed: tuple[Function, Function] | None = None  # the last set renamed to the next copies
        self.settled: Settled | None = None
        """When set, first nodes are the explicit engine's where a region settles in
        several states (:mod:`synth.symbolic.ties`); else the smallest (:meth:`pick`)."""
        assert s.initial_situation is not None
        s.helper.situation(s.initial_situation)  # situation 0

    # ---- node-set algebra
    @property
    def empty(self) -> Function:
        return self.false

    def union(self, a: Function, b: Function) -> Function:
        return a | b

    def join(self, sets: Iterable[Function]) -> Function:
        return self.s.engine.disjunction(sets)

    def meet(self, a: Function, b: Function) -> Function:
        return a & b

    def minus(self, a: Function, b: Function) -> Function:
        return a & ~b

    def is_empty(self, a: Function) -> bool:
        return a == self.false

    def count(self, a: Function) -> int:
        return self.s.count(a, self.s.current_vars)

    # ---- the explored graph
    def rings(self) -> Sequence[Function]:
        return self.s.rings

    def moves_from(self, u: Function) -> list[Arc]:
        return self.s.edges

    def order(self, arc: Arc) -> tuple[int, int, int]:
        """Plant moves by element, then variable (no timers on this path)."""
        m = arc[0]
        return (0, m.axis, self.s.plant.elements[m.axis].variables.index(m.variable))

    def event(self, arc: Arc) -> Event:
        return arc[0].event

    def plant_move(self, arc: Arc) -> Move:
        return arc[0]

    def post_by(self, u: Function, arc: Arc, within: Function | None = None) -> Function:
        v = self.s.image(u, *arc)
        if within is not None:
            v &= self.primed(within)
        return self.false if v == self.false else self.s.unprimed(v)

    def primed(self, u: Function) -> Function:
        """``u`` in the next copies (the last one asked for kept: a search asks again per move)."""
        if self._primed is None or self._primed[0] != u:
            self._primed = (u, self.s.primed(u))
        return self._primed[1]

    def pre_by(self, u: Function, arc: Arc) -> Function:
        return self.s.pre(u, [arc])

    def pre(self, u: Function, within: Function) -> Function:
        return self.s.pre(u, within=within)

    def forward(self, u: Function) -> Function:
        return self.s.forward(u)

    def backward(self, u: Function, within: Function | None = None) -> Function:
        return self.s.backward(u, within)

    def held(self) -> Function:
        """Nodes from which no node with other active steps is reachable."""
        s = self.s
        other = ~s.steps.equal(Copy.CURRENT, Copy.NEXT)
        changers = self.false
        for _, e in s.edges:
            changers |= s.engine.and_exists(e, other, s.next_vars)
        return s.nodes & ~s.backward(changers)

    def is_held(self, key: Key) -> bool:
        return self.s.held(self.cube(key))

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

    def contains(self, u: Function, key: Key) -> bool:
        return (self.cube(key) & u) != self.false

    def within(self, u: Function, sit: Situation) -> Function:
        """The plant states of ``u`` in situation ``sit``."""
        return self.s.steps.exists(u & self.s.steps.cube(sit), Copy.CURRENT)

    def pick(self, u: Function) -> Key:
        """The node of ``u`` (not empty) with the smallest situation, then the smallest state."""
        st = self.s.steps
        if self.count(u) == 1:  # one node: its path to 1 sets every variable
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

    # ---- what the report asks
    def waited(self) -> Function:
        """The initial nodes (no timers on this path: no elapsed initial situation)."""
        return self.s.initial

    def where(self, condition: Expr) -> Function:
        """The nodes where ``condition`` holds (a step variable is the step's BDD variable)."""
        s, owner = self.s, self.s.plant.owner
        variables = {step_variable(st): st for st in s.steps.steps}

        def value(name: str) -> Function:
            if name in owner:
                return s.engine.var(name)
            return s.steps.var(variables[name]) if name in variables else s.engine.false

        v = evaluate(condition, value)  # a condition folding to a constant (`1`, `X0 & 0`) is a bool
        return ((s.engine.true if v else s.engine.false) if isinstance(v, bool) else v) & s.nodes

    def prohibited(self) -> dict[tuple[Steps, Event], Function]:
        """Per (active steps, refused order event), the nodes where SUP refuses it."""
        out: dict[tuple[Steps, Event], Function] = {}
        for event, refused in self.s.refused_by.items():
            hit = self.s.nodes & refused
            if hit == self.false:
                continue
            for sit in self.situations_of(hit):
                out[(sit.steps, event)] = hit & self.s.steps.cube(sit)
        return dict(sorted(out.items()))

    def only_steps(self, u: Function, steps: Collection[Steps]) -> bool:
        covered = self.s.engine.disjunction(self.s.steps.cube(Situation(st)) for st in steps)
        return (self.steps_of(u) & ~covered) == self.false

    def conflicts(self) -> list[tuple[Function, Event, str, tuple[str, ...]]]:
        """None: an OR-divergence conflict sends the model to the per-situation path."""
        return []

    def never_leaves(self) -> bool:
        assert self.s.initial_situation is not None
        return (self.steps_of(self.s.nodes) & ~self.s.steps.cube(self.s.initial_situation)) == self.false

    def one_per_situation(self) -> list[Key]:
        nodes = self.s.nodes
        return [(self.s.helper.situation(sit), self.s.enc.one(self.within(nodes, sit))) for sit in self.situations_of(nodes)]

    def reached_steps(self) -> frozenset[str]:
        return self.s.reached_steps()

    def stats(self) -> dict[str, int]:
        return {"sync_states": self.s.sync_states, "aggregated_states": self.s.aggregated_states,
                "aggregated_transitions": self.s.edge_count}

    def situation_count(self) -> int:
        return self.s.situations

    # ---- the searches (synth.symbolic.searches) on this representation
    def terminal_components(self, stuck: Function) -> list[Function]:
        """The terminal strongly connected components of ``stuck``."""
        return terminal_components(self, stuck)

    def first_node(self, candidates: Function) -> tuple[Key, int, PathKey]:
        """The candidate the explicit engine numbers first: (node, distance, path key),
        with :attr:`settled` ties broken as it breaks them."""
        return first_node(self, candidates, self.settled)

    def shortest_trace(self, key: Key) -> Path:
        """The explicit engine's shortest path from an initial node to ``key`` (events by
        name, then the node it numbers first: :func:`~synth.symbolic.searches.shortest_trace`)."""
        return shortest_trace(self, key, self.settled)
