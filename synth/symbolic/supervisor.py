"""SUP on BDDs: its state set from the per-constraint product form, its counts exactly.

The explicit engine (:mod:`synth.sup.supervisor`) already writes "a violation is
reachable by uncontrollable events" as a disjunction over constraint monomials of
products of per-element vectors (``CompiledConstraints.level_reach``); here each vector
becomes the disjunction of its local codes, each product a conjunction: the set
``kept`` of states not removed. A move is *allowed* from a kept state when its target is
kept and, for a controllable move, no edge constraint forbids its event there. SUP's
states are the fixpoint of the allowed image from the initial state (a plain frontier
loop); every count of ``Supervisor.summary`` follows by exact model counting, for any
plant size (the explicit engine leaves the plant-wide counts ``null`` above
``GRID_LIMIT`` states; this one computes them).

Example
-------
>>> from synth.plant.rules_check import load_rules
>>> from synth.plant.composition import plant, _plants
>>> rs = load_rules(_plants("tri_annex.rules"))
>>> s = symbolic_supervisor(plant(rs), rs.constraints)
>>> s.summary()["states"] == __import__("synth.sup.supervisor", fromlist=["x"]).supremal_controllable(plant(rs), rs.constraints).size
True
"""

from __future__ import annotations

from functools import cached_property
from typing import Callable, Mapping, Sequence

import numpy as np

from synth.logic.bdd import Function
from synth.logic.counting import Conjunctions
from synth.plant.composition import Plant
from synth.plant.rules import Constraint
from synth.sup.constraints import CompiledConstraints
from synth.symbolic.encoding import Copy, NodeBudget, PlantEncoding, live_nodes
from synth.symbolic.relation import Move, plant_moves

__all__ = ["SymbolicSupervisor", "symbolic_supervisor"]


class SymbolicSupervisor:
    """Constraints and SUP of one plant as BDDs over a :class:`PlantEncoding`."""

    def __init__(self, p: Plant, constraints: Sequence[Constraint], budget: NodeBudget | None = None,
                 anchored: Mapping[int | None, Sequence[str]] | None = None) -> None:
        self.plant = p
        self.constraints = tuple(constraints)
        self.compiled = CompiledConstraints(p, constraints)
        self.enc = PlantEncoding(p, budget, self.constraints, anchored)
        self.moves: tuple[Move, ...] = plant_moves(self.enc)
        self.states: Function = self.enc.engine.false

    # ---- constraint sets
    def _factor(self, axis: int, vec: np.ndarray) -> Function:
        return self.enc.engine.disjunction(self.enc.local_state(axis, int(k)) for k in np.nonzero(vec)[0])

    def _product(self, factors) -> Function:
        return self.enc.engine.conjunction(self._factor(a, v) for a, v in factors)

    @cached_property
    def removed(self) -> Function:
        """Valuations (in or out of the domain) from which a violation is reachable by
        uncontrollable events: the disjunction of the per-constraint products."""
        return self.enc.engine.disjunction(self._product(f) for f in self.compiled.level_reach)

    @cached_property
    def kept(self) -> Function:
        """States from which no violation is reachable by uncontrollable events."""
        return self.enc.domain & ~self.removed

    @cached_property
    def illegal(self) -> Function:
        return self.enc.domain & self.enc.engine.disjunction(self._product(t.factors) for t in self.compiled.level_terms)

    def threatened(self, cid: str) -> Function:
        """States from which uncontrollable events reach a violation of constraint ``cid``."""
        return self.enc.engine.disjunction(
            self._product(f) for t, f in zip(self.compiled.level_terms, self.compiled.level_reach) if t.constraint == cid
        )

    @cached_property
    def forbid(self) -> dict[str, Function]:
        """Per controllable event, the states where an edge constraint forbids it."""
        return {e: self.enc.engine.disjunction(self._product(t.factors) for t in ts)
                for e, ts in self.compiled.edge_terms.items()}

    def allowed(self, move: Move) -> Function:
        """The part of ``move``'s relation SUP keeps, from kept sources (only: the relation
        checks the constraints the move can change): the target is kept and, for a
        controllable move, its event is not forbidden at the source."""
        return self._allowed[move.key]

    @cached_property
    def _allowed(self) -> dict[int, Function]:
        names = self.enc.element_variables
        out = {}
        # from a kept source, a move of element a can only make true the terms with a factor
        # on a (the others read unchanged variables), and its target is in a's domain by the
        # move's relation: each relation reads the variables of a and of its constraints only
        kept_next = {}
        for a in range(self.plant.ndim):
            on_a = self.enc.engine.disjunction(self._product(f) for f in self.compiled.level_reach if any(b == a for b, _ in f))
            kept_next[a] = self.enc.rename(~on_a, Copy.CURRENT, Copy.NEXT, names[a])
        for m in self.moves:
            r = m.relation & kept_next[m.axis]
            if m.controllable and m.event in self.forbid:
                r &= ~self.forbid[m.event]
            out[m.key] = r
        return out

    # ---- SUP
    @cached_property
    def element_relations(self) -> tuple[Function, ...]:
        """Per element, the disjunction of its allowed moves (images quantify its variables only)."""
        out = [self.enc.engine.false] * self.plant.ndim
        for m in self.moves:
            out[m.axis] |= self.allowed(m)
        return tuple(out)

    def explore(self, progress: Callable[[str], None] | None = None) -> "SymbolicSupervisor":
        """SUP's states: forward fixpoint of the allowed moves from the initial state.

        Chained: each element's image is added to the reached set before the next
        element moves, so a sweep over the elements goes as deep as many breadth-first
        levels; the loop ends when a sweep adds nothing."""
        false = self.enc.engine.false
        init = self.enc.state(self.plant.initial)
        if (init & self.kept) == false:
            self.states = false
            return self
        reached = init
        frontier = init
        sweeps = 0
        while frontier != false:
            before = reached
            for axis, rel in enumerate(self.element_relations):
                names = self.enc.element_variables[axis]
                nxt = self.enc.rename(self.enc.and_exists(frontier, rel, Copy.CURRENT, names), Copy.NEXT, Copy.CURRENT, names)
                new = nxt & ~reached
                reached |= new
                frontier |= new
            frontier = reached & ~before
            sweeps += 1
            self.enc.check(f"exploring SUP (sweep {sweeps})")
            if progress is not None:
                progress(f"exploring SUP symbolically: sweep {sweeps}, {live_nodes(self.enc.engine)} BDD nodes")
        self.states = reached
        return self

    @property
    def empty(self) -> bool:
        return self.states == self.enc.engine.false

    @property
    def nodes(self) -> int:
        """Live BDD nodes in the manager (the engine's memory)."""
        return live_nodes(self.enc.engine, exact=True)

    @cached_property
    def _counts(self) -> tuple[int, int, int]:
        """(controllable kept, uncontrollable kept, controllable cut), as Supervisor._counts."""
        kept = [0, 0]
        cut = 0
        # per move, its transitions from SUP's states, and those SUP keeps (allowed(m) lies in m.relation)
        sets = [(m, g, keep) for m in self.moves for g, keep in ((self.allowed(m), True), (m.relation, False))]
        sizes = self._within_counts([g for _, g, _ in sets])
        for (m, _, keep), n in zip(sets, sizes):
            n //= self._others(m.axis)
            if keep:
                kept[0 if m.controllable else 1] += n
                cut -= n if m.controllable else 0
            elif m.controllable:
                cut += n
        return kept[0], kept[1], cut

    def forbidden_counts(self) -> dict[str, int]:
        """Cut controllable transitions per constraint id, as
        :meth:`synth.sup.supervisor.Supervisor.forbidden_counts` (a transition counts for
        every constraint whose violation it would make reachable, or that forbids its event)."""
        counts = {c.id: 0 for c in self.constraints}
        hits: list[tuple[str, int, Function]] = []
        # a constraint none of whose terms reads the move's element is no threat after the
        # move (SUP's states threaten nothing) and forbids its event only by an edge term
        on_axis: dict[str, set[int]] = {}
        for t, f in zip(self.compiled.level_terms, self.compiled.level_reach):
            on_axis.setdefault(t.constraint, set()).update(a for a, _ in f)
        for cid in counts:
            threat = self.threatened(cid)
            edge = {e: self.enc.engine.disjunction(self._product(t.factors) for t in ts if t.constraint == cid)
                    for e, ts in self.compiled.edge_terms.items() if any(t.constraint == cid for t in ts)}
            for m in self.moves:
                reads = m.axis in on_axis.get(cid, ())
                if not m.controllable or not (reads or m.event in edge):
                    continue
                names = self.enc.element_variables[m.axis]
                bad = self.enc.rename(threat, Copy.CURRENT, Copy.NEXT, names) if reads else self.enc.engine.false
                if m.event in edge:
                    bad |= edge[m.event]
                hits.append((cid, m.axis, m.relation & bad))
        for (cid, axis, _), n in zip(hits, self._within_counts([g for _, _, g in hits])):
            counts[cid] += n // self._others(axis)
        return {k: v for k, v in counts.items() if v}

    def _within_counts(self, sets: Sequence[Function]) -> list[int]:
        """``|states ∧ g|`` over both copies for each ``g`` (a move's relation, or part of
        it), exactly, computed in the order of the sets' top levels: one sweep of the cuts."""
        within = Conjunctions(self.enc.engine, self.states, self.enc.levels((Copy.CURRENT, Copy.NEXT)))
        out = [0] * len(sets)
        for k in sorted(range(len(sets)), key=lambda k: self.enc.engine.level_of(sets[k])):
            out[k] = within.count(sets[k])
        return out

    def _others(self, axis: int) -> int:
        """Counting over both copies counts the unconstrained next variables of the other
        elements too: this factor removes them."""
        return 1 << (self._bits - len(self.enc.element_variables[axis]))

    @cached_property
    def _bits(self) -> int:
        return sum(len(v) for v in self.enc.element_variables)

    def summary(self) -> dict[str, int | None]:
        """The same keys as :meth:`synth.sup.supervisor.Supervisor.summary`, all computed."""
        c, u, cut = self._counts
        count = self.enc.count
        legal = self.enc.domain & ~self.illegal
        removed = self.enc.domain & ~self.kept
        defended = self._defended & legal
        weak = removed & legal & ~defended
        return {
            "states": count(self.states),
            "transitions": c + u,
            "controllable": c,
            "uncontrollable": u,
            "forbidden_transitions": cut,
            "illegal": count(self.illegal),
            "defended": count(defended),
            "weakly_defended": count(weak),
            "unreachable_removed": count(self.kept) - count(self.states),
        }

    @cached_property
    def _defended(self) -> Function:
        """Legal states with an uncontrollable move into an illegal state. A move changes
        one element's variables: from a legal state it can only make true the terms with a
        factor on that element, so each move's pre-image is taken of those terms alone
        (small sets, where the whole illegal set made the loop quadratic in the elements);
        its target is in the domain when its source is."""
        from synth.symbolic.relation import preimage

        e = self.enc.engine
        on_axis: dict[int, Function] = {}
        out = e.false
        for m in self.moves:
            if m.controllable:
                continue
            if m.axis not in on_axis:
                on_axis[m.axis] = e.disjunction(self._product(t.factors) for t in self.compiled.level_terms
                                                if any(a == m.axis for a, _ in t.factors))
            out |= preimage(self.enc, on_axis[m.axis], m)
        return out & self.enc.domain & ~self.illegal


def symbolic_supervisor(
    p: Plant,
    constraints: Sequence[Constraint],
    *,
    budget: NodeBudget | None = None,
    progress: Callable[[str], None] | None = None,
) -> SymbolicSupervisor:
    """SUP of ``p`` under ``constraints`` on BDDs (see module docstring)."""
    return SymbolicSupervisor(p, constraints, budget).explore(progress)
