"""Safety constraints compiled against a plant, for SUP queries state by state.

Each constraint is put in disjunctive normal form; each monomial becomes per-element
factors (the local states satisfying its level literals on that element). "Can reach a
violation by uncontrollable events" is then a product of per-element closures
(see :mod:`synth.sup.supervisor` and ``docs/method.md``). The questions about one state
(kept, threatened, forbidding, move) read the factors as integers, one per element and
local state whose bit ``i`` says whether term ``i``'s factor holds there: a query is one
AND per element, with no plant grid (this is what on-the-fly validation uses), and the
refusals of several moves from one state (:meth:`CompiledConstraints.verdicts`) share the
state's ANDs.

Example
-------
>>> from synth.plant.rules_check import load_rules
>>> from synth.plant.composition import plant, _plants
>>> rs = load_rules(_plants("tri_annex.rules"))
>>> cc = CompiledConstraints(plant(rs), rs.constraints)
>>> cc.kept(cc.plant.initial)
True
"""

from __future__ import annotations

import weakref
from typing import Iterable, Sequence

import numpy as np

from synth.frozen import frozen
from synth.logic.expr import disjunctive_normal_form, edge_text
from synth.plant.closure import backward_closures
from synth.plant.composition import LocalTransition, Plant
from synth.plant.rules import Constraint

__all__ = ["CompiledConstraints", "GRID_LIMIT", "Term", "split_terms", "grid_of_term", "term_holds"]


@frozen
class Term:
    """One monomial of a constraint, split per element: ``factors[axis]`` is the set of
    local states satisfying its level literals on that element."""

    constraint: str
    factors: tuple[tuple[int, np.ndarray], ...]
    event: str | None  # the edge literal's event, if any


def split_terms(p: Plant, constraints: Sequence[Constraint]) -> list[Term]:
    """Each constraint's forbidden monomials split per element (:class:`Term`), in the
    constraints' order: what SUP compiles and the symbolic closed loop encodes."""
    out: list[Term] = []
    for c in constraints:
        for m in disjunctive_normal_form(c.forbidden):
            edges = [l for l in m if l.edge]
            per_axis: dict[int, np.ndarray] = {}
            for l in sorted(m):
                if l.edge:
                    continue
                axis = p.owner[l.name]
                v = p.elements[axis].value(l.name)
                sat = v if l.positive else ~v
                per_axis[axis] = per_axis.get(axis, np.ones_like(sat)) & sat
            event = edge_text(edges[0].positive, edges[0].name) if edges else None
            out.append(Term(c.id, tuple(sorted(per_axis.items(), key=lambda kv: kv[0])), event))
    return out


def grid_of_term(p: Plant, factors: Iterable[tuple[int, np.ndarray]]) -> np.ndarray:
    grid = np.ones(p.shape, dtype=bool)
    for axis, vec in factors:
        shape = [1] * p.ndim
        shape[axis] = vec.size
        grid &= vec.reshape(shape)
    return grid


def _closed(p: Plant, factors: Iterable[tuple[int, np.ndarray]]) -> tuple[tuple[int, np.ndarray], ...]:
    """Per-element factors of "can reach, by own uncontrollable moves, a satisfying state"."""
    return tuple((a, p.elements[a].can_reach(v)) for a, v in factors)


_reach_cache: "weakref.WeakKeyDictionary[Plant, dict[tuple[Constraint, ...], list[np.ndarray]]]" = weakref.WeakKeyDictionary()


def _reach_grids(p: Plant, constraints: tuple[Constraint, ...], level_terms: Sequence[Term]) -> list[np.ndarray]:
    """Per level term, the states from which uncontrollable moves (guards evaluated) reach
    it: computed once per plant and constraints (compared by content; validation, SUP and
    the filter's closed loop share them), kept on disk for the next run (:mod:`synth.sup.stored`), read-only."""
    per_plant = _reach_cache.setdefault(p, {})
    if constraints not in per_plant:
        from synth.sup import stored

        grids = stored.kept(p, [t.factors for t in level_terms],
                            lambda: backward_closures(p, [grid_of_term(p, t.factors) for t in level_terms], controllable=False))
        for g in grids:
            g.flags.writeable = False
        per_plant[constraints] = grids
    return list(per_plant[constraints])


def term_holds(factors: Sequence[tuple[int, np.ndarray]], digits: np.ndarray) -> np.ndarray:
    """Whether a product term holds at each of the states whose digits (ndim × n) are given."""
    out = np.ones(digits.shape[1], dtype=bool)
    for a, vec in factors:
        out &= vec[digits[a]]
    return out


GRID_LIMIT = 200_000_000
"""Plant-wide statistics (illegal, defended, ... counts over every plant state) need
grids of the plant's size; above this many states they are not computed."""


class CompiledConstraints:
    """Constraints compiled against a plant: each monomial as per-element factors
    (``level_terms`` / ``edge_terms``), and for level terms the factors of "can reach a
    violating local state by the element's own uncontrollable moves" (``level_reach``)."""

    def __init__(self, p: Plant, constraints: Sequence[Constraint]) -> None:
        self.plant = p
        self.constraints = tuple(constraints)
        self.terms = split_terms(p, constraints)
        self.level_terms = [t for t in self.terms if t.event is None]
        self.level_reach = [_closed(p, t.factors) for t in self.level_terms]
        # elements that read each other: "can reach" is no product of per-element closures
        # (a move depends on other elements' values); one exact grid per term instead
        self.reach_grids: list[np.ndarray] | None = _reach_grids(p, self.constraints, self.level_terms) if p.reads else None
        self._kept: dict[tuple[int, ...], bool] = {}
        self._masks: _Bits | None = None
        self._level_names: dict[int, list[str]] = {}
        self.edge_terms: dict[str, list[Term]] = {}
        for t in self.terms:
            if t.event is not None:
                self.edge_terms.setdefault(t.event, []).append(t)

    # ------------------------------------------------------------------ one state at a time
    def _bits(self) -> _Bits:
        """The level terms' reach factors and the edge terms' factors as bit masks per
        element and local state (made on the first question of one state)."""
        if self._masks is None:
            self._masks = _Bits(self.plant, self.level_reach if self.reach_grids is None else None,
                                [t for t in self.terms if t.event is not None])
        return self._masks

    def kept(self, local: tuple[int, ...]) -> bool:
        """No constraint violation is reachable from ``local`` by uncontrollable events
        (remembered per state: validation asks again for every situation it meets there)."""
        hit = self._kept.get(local)
        if hit is None:
            if self.reach_grids is not None:
                hit = not any(g[local] for g in self.reach_grids)
            else:
                hit = not self._bits().reach(local)
            self._kept[local] = hit
        return hit

    def violated(self, local: tuple[int, ...]) -> list[str]:
        """Ids of the constraints the state violates (levels)."""
        ids: list[str] = []
        for term in self.level_terms:
            if term.constraint not in ids and all(vec[local[a]] for a, vec in term.factors):
                ids.append(term.constraint)
        return ids

    def threatened(self, local: tuple[int, ...]) -> list[str]:
        """Ids of the constraints whose violation is reachable by uncontrollable events."""
        if self.reach_grids is not None:
            return list(dict.fromkeys(t.constraint for t, g in zip(self.level_terms, self.reach_grids) if g[local]))
        return self._level_ids(self._bits().reach(local))

    def forbidding(self, event: str, local: tuple[int, ...]) -> list[str]:
        """Ids of the edge constraints that forbid controllable ``event`` in this state."""
        bits = self._bits()
        return bits.edge_ids(bits.edges(local) & bits.of_event.get(event, 0))

    def move(self, t: LocalTransition, local: tuple[int, ...]) -> tuple[bool, list[str]]:
        """Whether SUP allows transition ``t`` from ``local`` (a source in SUP), and if
        not, the ids of the constraints responsible."""
        return self.verdicts([t], local)[0]

    def verdicts(self, ts: Sequence[LocalTransition], local: tuple[int, ...]) -> list[tuple[bool, list[str]]]:
        """:meth:`move` of each of ``ts`` from ``local``, the state's masks read once."""
        bits = self._bits()
        edges = bits.edges(local) if bits.of_event else 0
        if self.reach_grids is None:
            others = bits.reach_without(local)
            reach = bits.reach_table
        out = []
        for t in ts:
            why = bits.edge_ids(edges & bits.of_event.get(t.event, 0)) if t.controllable and edges else []
            if self.reach_grids is None:
                threat = self._level_ids(others[t.axis] & reach[t.axis][t.dst])
            else:
                target = list(local)
                target[t.axis] = t.dst
                threat = self.threatened(tuple(target))
            if why:
                why += [c for c in threat if c not in why]
            else:
                why = threat
            out.append((not why, why))
        return out

    def _level_ids(self, mask: int) -> list[str]:
        """Constraint ids (first-seen order, no repeats) of the level terms in ``mask``."""
        hit = self._level_names.get(mask)
        if hit is None:
            hit = self._level_names[mask] = _ids(self.level_terms, mask)
        return list(hit)


def _ids(terms: Sequence[Term], mask: int) -> list[str]:
    """Constraint ids (first-seen order, no repeats) of the terms whose bit is in ``mask``."""
    return list(dict.fromkeys(terms[i].constraint for i in range(mask.bit_length()) if mask >> i & 1))


class _Bits:
    """Per element and local state, an integer whose bit ``i`` says that term ``i``'s factor
    on that element holds there (set where the term has no factor on the element): a term
    holds at a state when its bit survives the AND over the elements. ``reach_table``: the
    level terms' reach factors (none where the plant's elements read each other);
    ``edge_table``: the edge terms' factors, ``of_event``: each event's edge terms."""

    def __init__(self, p: Plant, level_reach: Sequence[Sequence[tuple[int, np.ndarray]]] | None,
                 edge_terms: list[Term]) -> None:
        self.reach_table = self._table(p, level_reach or [])
        self.reach_full = (1 << len(level_reach or [])) - 1
        self.edge_terms = edge_terms
        self.edge_table = self._table(p, [t.factors for t in edge_terms])
        self.edge_full = (1 << len(edge_terms)) - 1
        self.of_event: dict[str, int] = {}
        for i, t in enumerate(edge_terms):
            assert t.event is not None
            self.of_event[t.event] = self.of_event.get(t.event, 0) | 1 << i
        self._edge_names: dict[int, list[str]] = {}

    @staticmethod
    def _table(p: Plant, factors: Sequence[Sequence[tuple[int, np.ndarray]]]) -> list[list[int]]:
        full = (1 << len(factors)) - 1
        table = [[full] * n for n in p.shape]
        for i, term in enumerate(factors):
            for a, vec in term:
                row = table[a]
                for s in (~vec.astype(bool)).nonzero()[0].tolist():
                    row[s] &= ~(1 << i)
        return table

    def reach(self, local: tuple[int, ...]) -> int:
        """The level terms whose violation ``local`` can reach."""
        out = self.reach_full
        for row, s in zip(self.reach_table, local):
            out &= row[s]
        return out

    def reach_without(self, local: tuple[int, ...]) -> list[int]:
        """Per element ``a``, :meth:`reach` of ``local`` with element ``a`` left out (a move
        of ``a`` then ANDs its target's row)."""
        n = len(local)
        before, after = [self.reach_full] * (n + 1), [self.reach_full] * (n + 1)
        table = self.reach_table
        for a in range(n):
            before[a + 1] = before[a] & table[a][local[a]]
        for a in range(n - 1, -1, -1):
            after[a] = after[a + 1] & table[a][local[a]]
        return [before[a] & after[a + 1] for a in range(n)]

    def edges(self, local: tuple[int, ...]) -> int:
        """The edge terms whose level factors hold at ``local``."""
        out = self.edge_full
        for row, s in zip(self.edge_table, local):
            out &= row[s]
        return out

    def edge_ids(self, mask: int) -> list[str]:
        """Constraint ids (first-seen order, no repeats) of the edge terms in ``mask``."""
        if not mask:
            return []
        hit = self._edge_names.get(mask)
        if hit is None:
            hit = self._edge_names[mask] = _ids(self.edge_terms, mask)
        return list(hit)
