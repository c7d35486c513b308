"""The Grafcet's situations on BDDs: one variable per step, the reaction as a relation.

A situation of a Grafcet without stored actions, timers or internal variables is its
set of active steps: one BDD variable per step (``#X<step>``, in the three copies of
:class:`~synth.symbolic.encoding.Copy`, declared next to the plant element the step
drives or reads: :func:`anchors`), so a set of SYNC nodes is one BDD over (steps, plant
state) and a whole breadth-first level of the exploration is a few BDD operations.

The reading of IEC 60848 is the machine's (:class:`~synth.grafcet.machine.GrafcetMachine`):

- a receptivity is the machine's own compiled function (``machine.receptivity(i)``), called on
  recorded inputs and recorded step activity (:class:`~synth.grafcet.recorder.InputRecorder`
  and :class:`_Steps`): each call holds on the cube of what it read, so the BDD of the
  receptivity is the union of the cubes where it answered true (per event: an edge
  ``↑x`` is true only in the first round of the event ``↑x``);
- a round fires every enabled transition (all source steps active) whose receptivity
  holds: its sources leave, its targets enter, a step both left and entered stays
  (rules 2–5, ``GrafcetMachine._fire`` without stored actions); rounds repeat, the edge
  false after the first, until no transition is fireable (search for stability).

What this encoding does not cover raises :class:`Unsupported`, and the caller falls back
to the per-situation engine (:mod:`synth.symbolic.situations.sync`), which calls the machine on
each situation: stored actions, assignments, event actions, timers,
internal variables, ``--semantics sfc`` (:func:`unsupported`), and, met while exploring,
transitions leaving one step fired in the same round (an OR-divergence conflict the
report must show) or a search for stability longer than :data:`MAX_ROUNDS` rounds (a
transient cycle is an input error the machine reports).

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.validation.result import load_model
>>> from synth.grafcet.machine import GrafcetMachine
>>> _, p, g = load_model(_plants("../grafcets/tri.g7"), _plants("tri.rules"))
>>> unsupported(GrafcetMachine(g), p)
'timers'
>>> _, p, g = load_model(_plants("../tests/data/home/production_loop.g7"), _plants("../tests/data/home/cylinder.rules"))
>>> unsupported(GrafcetMachine(g), p) is None
True
"""

from __future__ import annotations

from functools import partial
from typing import Mapping, cast

from synth.grafcet.language import CONDITIONAL, CONTINUOUS, Semantics
from synth.grafcet.machine import GrafcetMachine, Situation
from synth.grafcet.recorder import InputRecorder
from synth.grafcet.situation import CompiledFn, sorted_steps
from synth.logic.bdd import Function
from synth.logic.events import Event
from synth.logic.expr import Edge, names
from synth.plant.composition import Plant
from synth.symbolic.encoding import Copy, PlantEncoding, first_path

__all__ = ["Unsupported", "unsupported", "anchors", "StepEncoding", "MAX_ROUNDS", "step_name"]

MAX_ROUNDS = 64
"""Rounds of one search for stability before giving the reaction back to the machine."""


class Unsupported(Exception):
    """The model needs the per-situation engine (the message says why)."""


def step_name(step: str, copy: Copy = Copy.CURRENT) -> str:
    """The BDD variable of ``step``'s activity: ``step_name("1") == "#X1"`` (``#`` is in no
    plant variable's name)."""
    return "#X" + step + copy.value


def unsupported(machine: GrafcetMachine, p: Plant) -> str | None:
    """Why the step encoding cannot carry this Grafcet (None: it can)."""
    g = machine.grafcet
    if g.semantics is not Semantics.GRAFCET:
        return "not the IEC 60848 semantics"
    if g.timers:
        return "timers"
    if g.internals:
        return "internal variables"
    for s in g.steps:
        for a in s.actions:
            if a.kind not in (CONTINUOUS, CONDITIONAL):
                return f"{a.kind} actions"
    if any(n not in p.owner for n in machine.inputs):
        return "Grafcet inputs that are not plant variables"
    if set(machine.inputs) & set(p.outputs):  # a region move would change what the machine reads
        return "Grafcet inputs that are orders"
    return None


def anchors(machine: GrafcetMachine, p: Plant) -> dict[int | None, list[str]]:
    """Step variables by the element they are declared next to: the element of the step's
    first order, else of the first input its outgoing transitions read, else of its
    incoming ones'; None (declared first) when it has none."""
    out: dict[int | None, list[str]] = {}
    for s in machine.grafcet.steps:
        axis: int | None = None
        for a in s.actions:
            if a.order in p.owner:
                axis = p.owner[a.order]
                break
        for side in ("sources", "targets"):
            if axis is not None:
                break
            for t in machine.transitions:
                if s.name in getattr(t, side):
                    read = [n.name for n in names(t.receptivity) if n.name in p.owner]
                    if read:
                        axis = p.owner[read[0]]
                        break
        out.setdefault(axis, []).append(step_name(s.name))
    return out


class _Steps:
    """Active steps as the compiled receptivities read them (``'1' in A``), recorded."""

    __slots__ = ("values", "read")

    def __init__(self, values: Mapping[str, bool]) -> None:
        self.values = values
        self.read: set[str] = set()

    def __contains__(self, step: object) -> bool:
        assert isinstance(step, str)
        self.read.add(step)
        return self.values.get(step, False)


class StepEncoding:
    """Step variables over a :class:`PlantEncoding` whose order already holds them
    (declared through ``anchored``), and the Grafcet's reaction on them."""

    def __init__(self, machine: GrafcetMachine, enc: PlantEncoding) -> None:
        self.machine = machine
        self.enc = enc
        self.engine = enc.engine
        self.steps: tuple[str, ...] = tuple(s.name for s in machine.grafcet.steps)
        self.inputs = frozenset(machine.inputs)
        self._recs: dict[tuple[int, Event | None], Function] = {}
        self._fire: dict[Event | None, tuple[Function, Function, list[tuple[Function, Function]]]] = {}
        self._qvars = {c: [self.engine.declare(step_name(s, c)) for s in self.steps] for c in Copy}
        self._equal: dict[tuple[Copy, Copy], Function] = {}
        self._cubes: dict[tuple[tuple[str, ...], Copy], Function] = {}
        self._exists: dict[Copy, Function] = {}
        # the events some receptivity compares the event with (its compiled code reads E
        # nowhere else): after any other event every receptivity is its value after none
        self._edges = frozenset(n.event for t in machine.transitions for n in names(t.receptivity) if isinstance(n, Edge))

    # ---- variables
    def var(self, step: str, copy: Copy = Copy.CURRENT) -> Function:
        return self.engine.var(step_name(step, copy))

    def names(self, copy: Copy) -> list[str]:
        """The manager's (inner) names of the ``copy`` of every step variable."""
        return self._qvars[copy]

    def equal(self, a: Copy, b: Copy) -> Function:
        """Copy ``a`` of every step variable equals copy ``b``."""
        hit = self._equal.get((a, b))
        if hit is None:
            hit = self._equal[(a, b)] = self.engine.conjunction(self.var(s, a).equiv(self.var(s, b)) for s in self.steps)
        return hit

    def rename(self, u: Function, source: Copy, target: Copy) -> Function:
        """``u`` with the ``source`` copy of the step variables renamed to ``target``."""
        return self.engine.and_exists(u, self.equal(source, target), self.names(source))

    def exists(self, u: Function, copy: Copy) -> Function:
        """``∃`` the ``copy`` of every step variable in ``u`` (the cube built once)."""
        cube = self._exists.get(copy)
        if cube is None:
            cube = self._exists[copy] = self.engine.bdd.cube(set(self.names(copy)))
        return self.engine.bdd.apply("exists", cube, u)

    def cube(self, sit: Situation, copy: Copy = Copy.CURRENT) -> Function:
        """The step variables of ``sit`` (its active steps, every other step inactive)."""
        hit = self._cubes.get((sit.steps, copy))
        if hit is None:
            active = set(sit.steps)
            hit = self._cubes[(sit.steps, copy)] = self.engine.bdd.cube(  # one call, not a conjunction per step
                {self.engine.declare(step_name(s, copy)): s in active for s in self.steps})
        return hit

    def situation(self, active: Mapping[str, bool]) -> Situation:
        """The situation whose step variables (current copy, by BDD name) are ``active``."""
        return Situation(sorted_steps({s for s in self.steps if active.get(step_name(s), False)}))

    def orders(self) -> dict[str, Function]:
        """Per order some step emits, where it is emitted (X, x): its step active, and for a
        conditional action its condition true (the machine's compiled condition, on cells)."""
        out: dict[str, Function] = {}
        for s in self.machine.grafcet.steps:
            for i, a in enumerate(s.actions):
                where = self.var(s.name)
                if a.kind == CONDITIONAL:
                    where &= self._cells(self.machine.condition(s.name, i), None)
                out[a.order] = out.get(a.order, self.engine.false) | where
        return out

    # ---- receptivities, from the machine's compiled functions on recorded cells
    def receptivity(self, i: int, event: Event | None, copy: Copy = Copy.NEXT) -> Function:
        """Where transition ``i``'s receptivity holds after ``event``: over the plant's
        current copy (the inputs) and the ``copy`` of the step variables."""
        key = (i, event)
        hit = self._recs.get(key)
        if hit is None:
            hit = self._recs[key] = self._cells(self.machine.receptivity(i), event)
        if copy is Copy.CURRENT:
            return hit
        return self.rename(hit, Copy.CURRENT, copy)

    def _cells(self, fn: CompiledFn, event: Event | None) -> Function:
        """Where the machine's compiled ``fn`` (a receptivity or an action's condition)
        holds after ``event``, over the inputs (plant, current copy) and the step variables
        (current copy): the union of the cubes of recorded inputs and steps where a call
        answered true, calls repeated until the cubes cover every valuation."""
        true = self.engine.false
        rest = self.engine.true
        while rest != self.engine.false:
            point = first_path(self.engine, rest)
            inputs = InputRecorder(partial(_inputs, point, self.inputs))
            steps = _Steps({s: point.get(step_name(s), False) for s in self.steps})
            answer = fn(inputs, cast(frozenset[str], steps), frozenset(), event, {})
            cell = self.engine.cube({**inputs.cell(), **{step_name(s): steps.values.get(s, False) for s in steps.read}})
            if answer:
                true |= cell
            rest &= ~cell
        return true

    def _round(self, event: Event | None) -> tuple[Function, Function, list[tuple[Function, Function]]]:
        """For one round (``event``: its edge, None after the first round): the states
        where a transition is fireable, the firing relation from the next copy of the
        steps (the working situation) to the auxiliary copy, and the pairs of fireable
        sets of transitions sharing a source step (conflicts). Over the plant's current
        copy (the inputs after the event)."""
        hit = self._fire.get(event)
        if hit is not None:
            return hit
        if event is not None and (event not in self._edges or all(
                self.receptivity(i, event, Copy.CURRENT) == self.receptivity(i, None, Copy.CURRENT)
                for i in range(len(self.machine.transitions)))):
            hit = self._fire[event] = self._round(None)  # no receptivity reads this edge
            return hit
        fireable: list[Function] = []
        for i, t in enumerate(self.machine.transitions):
            enabled = self.engine.conjunction(self.var(s, Copy.NEXT) for s in t.sources)
            fireable.append(enabled & self.receptivity(i, event) if enabled != self.engine.false else enabled)
        fired = self.engine.disjunction(fireable)
        relation = self.engine.true
        for s in self.steps:
            leaves = self.engine.disjunction(f for f, t in zip(fireable, self.machine.transitions) if s in t.sources)
            enters = self.engine.disjunction(f for f, t in zip(fireable, self.machine.transitions) if s in t.targets)
            after = (self.var(s, Copy.NEXT) & ~leaves) | enters
            relation &= self.var(s, Copy.AUX).equiv(after)
        pairs = []
        ts = self.machine.transitions
        for a in range(len(ts)):
            for b in range(a + 1, len(ts)):
                if set(ts[a].sources) & set(ts[b].sources):
                    pairs.append((fireable[a], fireable[b]))
        hit = self._fire[event] = (fired, relation, pairs)
        return hit

    def reads_edge(self, event: Event) -> bool:
        """Whether a receptivity reads ``event``'s edge (else the reaction after it is the
        reaction after no event)."""
        return self._round(event) is not self._round(None)

    def react(self, entries: Function, event: Event | None) -> Function:
        """The stable situations the machine reaches from ``entries`` (situation X, plant
        state n right after ``event``): the relation over (X, n, X') — X' in the next
        copy of the step variables. Raises :class:`Unsupported` on a conflict or a search
        longer than :data:`MAX_ROUNDS` rounds."""
        false = self.engine.false
        work = entries & self.equal(Copy.CURRENT, Copy.NEXT)
        out = false
        ev = event
        for _ in range(MAX_ROUNDS):
            fired, relation, pairs = self._round(ev)
            unstable = work & fired
            out |= work & ~fired
            if unstable == false:
                return out
            for a, b in pairs:
                if (unstable & a & b) != false:
                    raise Unsupported("transitions leaving one step fired in the same round")
            moved = self.engine.and_exists(unstable, relation, self.names(Copy.NEXT))
            work = self.rename(moved, Copy.AUX, Copy.NEXT)
            ev = None
        raise Unsupported(f"a search for stability longer than {MAX_ROUNDS} rounds")


def _inputs(point: Mapping[str, bool], inputs: frozenset[str]) -> dict[str, bool]:
    return {n: point.get(n, False) for n in inputs}
