"""SUP: the maximal admissible plant behaviour under the constraints (docs/method.md, SUP).

Tajer's algorithm (thesis figure 2.4):

a. a controllable transition whose target violates a constraint (or whose event an
   edge constraint forbids) is *forbidden*;
b. a state is *defended* if an uncontrollable event leads from it to a violating
   state, *weakly defended* if uncontrollable events lead from it to a defended one;
c. defended and weakly defended states are removed, then every state that is no
   longer reachable from the initial state.

Removal needs no fixpoint over the whole plant. Uncontrollable events never change
orders and each element moves on its own, so the states reachable from ``s`` by
uncontrollable events are the product ``U_1(s_1) × … × U_N(s_N)`` of per-element
closures. Writing each constraint as a disjunction of monomials, ``s`` is removed iff
for some monomial ``m`` every element ``i`` can reach, by its own uncontrollable
moves, a local state satisfying ``m``'s literals on its variables: a product of N
small boolean vectors per monomial, evaluated for whole arrays of states at once
(:class:`Supervisor`), for one state (:class:`~synth.sup.constraints.CompiledConstraints`, on-the-fly validation),
or over the whole plant grid when it fits in memory (the plant-wide statistics).

SUP's states are then explored breadth-first from the initial state over state codes
held in numpy arrays: the work is linear in SUP's transitions, not in the plant.

Example
-------
>>> from synth.plant.rules_check import load_rules
>>> from synth.plant.composition import plant, _plants
>>> rs = load_rules(_plants("tri_annex.rules"))
>>> sup = supremal_controllable(plant(rs), rs.constraints)
>>> sup.size > 0, sup.size < sup.plant.size
(True, True)
"""
from __future__ import annotations

from functools import cached_property
from typing import Callable, Iterable, Iterator, Sequence

import numpy as np

from synth.errors import LimitExceeded
from synth.plant.composition import LocalTransition, Plant
from synth.plant.element import distinct
from synth.plant.rules import Constraint
from synth.sup.codes import Visited
from synth.sup.constraints import GRID_LIMIT, CompiledConstraints, term_holds, grid_of_term
from synth.sup.explore import Counts, Explorer

__all__ = ["Supervisor", "supremal_controllable"]


class Supervisor(CompiledConstraints):
    """SUP: its states as a sorted array of plant state codes, explored from the initial
    state; SUP membership of any state is the closed form of the module docstring.

    Grids over the whole plant (``illegal``, ``removed``, ``defended``, ``forbid``,
    ``reachable``) are built on first use, for plants that fit in memory.
    """

    def __init__(self, p: Plant, constraints: Sequence[Constraint], states: np.ndarray | None = None) -> None:
        super().__init__(p, constraints)
        if p.size >= 2**62:
            raise LimitExceeded(f"the plant has {p.size} states; SUP state codes must fit in 62 bits")
        self.strides = np.array(p.strides, dtype=np.int64)
        self.radices = np.array(p.shape, dtype=np.int64)
        self.states = states if states is not None else np.zeros(0, dtype=np.int64)
        self.explored: Counts | None = None  # the moves' counts, when :mod:`synth.sup.explore` found the states

    # ------------------------------------------------------------------ vectorised membership
    def digits(self, codes: np.ndarray) -> np.ndarray:
        """Local state indices (ndim × n) of the plant states with these codes."""
        return (codes[None, :] // self.strides[:, None]) % self.radices[:, None]

    def kept_digits(self, digits: np.ndarray) -> np.ndarray:
        """Not removed: no violation reachable by uncontrollable events."""
        bad = np.zeros(digits.shape[1], dtype=bool)
        if self.reach_grids is not None:  # elements read each other: exact grids
            codes = (digits * self.strides[:, None]).sum(axis=0)
            for g in self.reach_grids:
                bad |= g.ravel()[codes]
            return ~bad
        for factors in self.level_reach:
            bad |= term_holds(factors, digits)
        return ~bad

    # ------------------------------------------------------------------ SUP
    @property
    def size(self) -> int:
        return int(self.states.size)

    @property
    def empty(self) -> bool:
        return self.states.size == 0

    def _move_terms(self, codes: np.ndarray) -> Iterator[tuple[LocalTransition, np.ndarray, np.ndarray, list[tuple[str, np.ndarray]]]]:
        """For each local transition leaving some of ``codes`` (kept states): its sources,
        targets, and per constraint term the sources where the term makes the move bad.

        A move on element ``a`` changes only digit ``a``, and no term holds at a kept
        source, so only the terms with a factor on ``a`` can hold at the target: each is
        its factor's value at the target digit (a constant per local transition) and the
        product of its other factors at the source (computed once per call).
        """
        digits = self.digits(codes)
        rest: dict[tuple[int, int], np.ndarray] = {}
        for k, factors in enumerate(self.level_reach):
            values = {a: vec[digits[a]] for a, vec in factors}
            for a, _ in factors:
                r = np.ones(codes.size, dtype=bool)
                for b, v in values.items():
                    if b != a:
                        r &= v
                rest[(k, a)] = r
        for t in self.plant.transitions:
            sel = digits[t.axis] == t.src
            if t.guard is not None:
                sel &= self.plant.enabled_digits(t, digits)
            if not sel.any():
                continue
            src = codes[sel]
            dst = src + (t.dst - t.src) * self.strides[t.axis]
            if self.reach_grids is not None:  # the target threatened, read on the exact grids
                hits = [(term.constraint, g.ravel()[dst]) for term, g in zip(self.level_terms, self.reach_grids)]
            else:
                hits = [
                    (self.level_terms[k].constraint, rest[(k, t.axis)][sel])
                    for k, a, vec in self._on_axis[t.axis]
                    if vec[t.dst]
                ]
            if t.controllable:
                for term in self.edge_terms.get(t.event, ()):
                    hits.append((term.constraint, term_holds(term.factors, digits[:, sel])))
            yield t, src, dst, hits

    @cached_property
    def _on_axis(self) -> list[list[tuple[int, int, np.ndarray]]]:
        out: list[list[tuple[int, int, np.ndarray]]] = [[] for _ in range(self.plant.ndim)]
        for k, factors in enumerate(self.level_reach):
            for a, vec in factors:
                out[a].append((k, a, vec))
        return out

    def moves(self, codes: np.ndarray) -> Iterator[tuple[LocalTransition, np.ndarray, np.ndarray, np.ndarray]]:
        """For each local transition: the sources among ``codes`` (kept states) it leaves,
        their targets, and whether SUP keeps the move."""
        for t, src, dst, hits in self._move_terms(codes):
            bad = np.zeros(src.size, dtype=bool)
            for _, h in hits:
                bad |= h
            yield t, src, dst, ~bad

    @cached_property
    def _counts(self) -> tuple[int, int, int]:
        """(controllable kept, uncontrollable kept, controllable cut), one sweep over SUP."""
        if self.explored is not None:
            return self.explored.controllable, self.explored.uncontrollable, self.explored.cut
        kept = [0, 0]
        cut = 0
        for start in range(0, self.states.size, 1 << 20):
            for t, _, _, ok in self.moves(self.states[start:start + (1 << 20)]):
                n_ok = int(np.count_nonzero(ok))
                kept[0 if t.controllable else 1] += n_ok
                if t.controllable:
                    cut += ok.size - n_ok
        return kept[0], kept[1], cut

    def count_transitions(self, controllable: bool | None = None) -> int:
        c, u, _ = self._counts
        return c + u if controllable is None else (c if controllable else u)

    @property
    def forbidden_transitions(self) -> int:
        """Controllable transitions leaving SUP states that SUP cuts."""
        return self._counts[2]

    def forbidden_counts(self) -> dict[str, int]:
        """The cut controllable transitions per constraint id (a transition counts for
        every constraint whose violation it would make reachable, or that forbids its event)."""
        counts = {c.id: 0 for c in self.constraints}
        if self.explored is not None:
            counts.update(self.explored.per_constraint)
            return {k: v for k, v in counts.items() if v}
        for start in range(0, self.states.size, 1 << 20):
            for t, src, _, hits in self._move_terms(self.states[start:start + (1 << 20)]):
                if not t.controllable:
                    continue
                per: dict[str, np.ndarray] = {}
                for cid, h in hits:
                    per[cid] = per[cid] | h if cid in per else h
                for cid, h in per.items():
                    counts[cid] += int(np.count_nonzero(h))
        return {k: v for k, v in counts.items() if v}

    def contains(self, codes: np.ndarray) -> np.ndarray:
        """Whether each plant state code is a SUP state."""
        pos = np.searchsorted(self.states, codes)
        pos = np.minimum(pos, max(self.states.size - 1, 0))
        return (self.states[pos] == codes) if self.states.size else np.zeros(np.shape(codes), dtype=bool)

    # ------------------------------------------------------------------ grids (on demand)
    def _grid(self, terms: Iterable[tuple[tuple[int, np.ndarray], ...]]) -> np.ndarray:
        """The union of the terms, each a product of per-element factors (axis, local states)."""
        out = np.zeros(self.plant.shape, dtype=bool)
        for factors in terms:
            out |= grid_of_term(self.plant, factors)
        return out

    @cached_property
    def illegal(self) -> np.ndarray:
        return self._grid(t.factors for t in self.level_terms)

    @cached_property
    def removed(self) -> np.ndarray:
        if self.reach_grids is not None:
            return np.logical_or.reduce(self.reach_grids) if self.reach_grids else np.zeros(self.plant.shape, dtype=bool)
        return self._grid(self.level_reach)

    @cached_property
    def defended(self) -> np.ndarray:
        return self.plant.preimage(self.illegal, controllable=False) & ~self.illegal

    @cached_property
    def forbid(self) -> dict[str, np.ndarray]:
        return {e: self._grid(t.factors for t in ts) for e, ts in self.edge_terms.items()}

    @cached_property
    def reachable(self) -> np.ndarray:
        grid = np.zeros(self.plant.size, dtype=bool)
        grid[self.states] = True
        return grid.reshape(self.plant.shape)

    def summary(self) -> dict[str, int | None]:
        out: dict[str, int | None] = {
            "states": self.size,
            "transitions": self.count_transitions(),
            "controllable": self.count_transitions(True),
            "uncontrollable": self.count_transitions(False),
            "forbidden_transitions": self.forbidden_transitions,
        }
        if self.plant.size > GRID_LIMIT:
            out.update({"illegal": None, "defended": None, "weakly_defended": None, "unreachable_removed": None})
            return out
        legal = ~self.illegal
        weak = self.removed & legal & ~self.defended
        inside = self.plant.reachable if self.plant.reads else True  # elements reading each other: reachable states only
        out.update(
            {
                "illegal": int(np.count_nonzero(self.illegal & inside)),
                "defended": int(np.count_nonzero(self.defended & inside)),
                "weakly_defended": int(np.count_nonzero(weak & inside)),
                "unreachable_removed": int(np.count_nonzero(~self.removed & inside)) - self.size,
            }
        )
        return out


def supremal_controllable(
    p: Plant,
    constraints: Sequence[Constraint],
    *,
    progress: Callable[[str], None] | None = None,
    per_transition: bool = False,
) -> Supervisor:
    """SUP of plant ``p`` under ``constraints`` (see module docstring).

    Breadth-first exploration from the initial state over codes held in numpy arrays,
    frontier by frontier: each frontier costs a few vectorised operations per local
    transition, so the work is linear in SUP's transitions and no array of the plant's
    size is built beyond a bitmap of visited states. ``progress`` receives a short text
    after each frontier. Plants whose elements read nothing move through one table per
    element (:mod:`synth.sup.explore`); the others, and ``per_transition`` (the tables'
    reference in the tests), move local transition by local transition.
    """
    sup = Supervisor(p, constraints)
    init = np.array([p.initial_index], dtype=np.int64)
    if not sup.kept_digits(sup.digits(init))[0]:
        return sup
    explorer = None if per_transition else Explorer.of(sup)
    if explorer is not None:
        sup.states, sup.explored = explorer.explore(progress)
        return sup
    visited = Visited(p.size)
    mark, seen = visited.add, visited.test

    mark(init)
    parts = [init]
    frontier = init
    depth = 0
    while frontier.size:
        new_parts = []
        for t, src, dst, ok in sup.moves(frontier):
            dst = dst[ok]
            dst = distinct(dst[~seen(dst)])
            if dst.size:
                mark(dst)
                new_parts.append(dst)
        frontier = np.concatenate(new_parts) if new_parts else np.zeros(0, dtype=np.int64)
        parts.append(frontier)
        depth += 1
        if progress is not None:
            progress(f"exploring SUP: depth {depth}, {sum(x.size for x in parts)} states")
    sup.states = np.sort(np.concatenate(parts))
    return sup
