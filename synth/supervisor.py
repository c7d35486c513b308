"""SUP: the maximal admissible plant behaviour under the constraints (METHOD.md §4).

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
moves, a local state satisfying ``m``'s literals on its variables. That is an outer
product of N small boolean vectors per monomial: linear in the plant size, and
evaluable state by state (:class:`LocalSupervisor`) when the plant is too large to
exist (on-the-fly validation).

Example
-------
>>> from synth.rules import load_rules
>>> from synth.composition import plant
>>> rs = load_rules(_plants("tri_annex.rules"))
>>> sup = supremal_controllable(plant(rs), rs.constraints)
>>> sup.size > 0, sup.size < sup.plant.size
(True, True)
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from functools import cached_property
from typing import Iterable, Sequence

import numpy as np

from .composition import LocalTransition, Plant, _plants
from .expr import Literal, disjunctive_normal_form, edge_text, evaluate
from .rules import Constraint

__all__ = [
    "Supervisor",
    "LocalSupervisor",
    "Explanation",
    "supremal_controllable",
    "explain",
]


@dataclass(frozen=True)
class _Term:
    """One monomial of a constraint, split per element: ``factors[axis]`` is the set of
    local states satisfying its level literals on that element."""

    constraint: str
    factors: tuple[tuple[int, np.ndarray], ...]
    event: str | None  # the edge literal's event, if any


def _terms(p: Plant, constraints: Sequence[Constraint]) -> list[_Term]:
    out: list[_Term] = []
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
            out.append(_Term(c.id, tuple(sorted(per_axis.items(), key=lambda kv: kv[0])), event))
    return out


def _product(p: Plant, factors: Iterable[tuple[int, np.ndarray]]) -> np.ndarray:
    grid = np.ones(p.shape, dtype=bool)
    for axis, vec in factors:
        shape = [1] * p.ndim
        shape[axis] = vec.size
        grid &= vec.reshape(shape)
    return grid


@dataclass(eq=False)
class Supervisor:
    """SUP over the plant grid; every array has the plant's grid shape."""

    plant: Plant
    constraints: tuple[Constraint, ...]
    illegal: np.ndarray
    removed: np.ndarray
    defended: np.ndarray
    forbid: dict[str, np.ndarray]
    reachable: np.ndarray
    terms: list[_Term] = field(repr=False, default_factory=list)

    @property
    def size(self) -> int:
        return int(np.count_nonzero(self.reachable))

    @property
    def empty(self) -> bool:
        return not bool(self.reachable[self.plant.initial])

    def allowed(self, t: LocalTransition) -> np.ndarray:
        """Sources (grid view shape) from which ``t`` stays in SUP."""
        s, d = self.plant.slices(t)
        ok = self.reachable[s] & ~self.removed[d]
        if t.controllable and t.event in self.forbid:
            ok = ok & ~self.forbid[t.event][s]
        return ok

    def count_transitions(self, controllable: bool | None = None) -> int:
        return sum(
            int(np.count_nonzero(self.allowed(t)))
            for t in self.plant.transitions
            if controllable is None or t.controllable == controllable
        )

    def forbidden_counts(self) -> dict[str, int]:
        """Controllable transitions leaving SUP states that SUP cuts, per constraint id
        (a transition counts for every constraint that makes it forbidden)."""
        counts: dict[str, int] = {}
        for c in self.constraints:
            sub = supremal_controllable(self.plant, [c], reach=False)
            n = 0
            for t in self.plant.transitions:
                if not t.controllable:
                    continue
                s, d = self.plant.slices(t)
                bad = sub.removed[d]
                if t.event in sub.forbid:
                    bad = bad | sub.forbid[t.event][s]
                n += int(np.count_nonzero(self.reachable[s] & bad))
            if n:
                counts[c.id] = n
        return counts

    @cached_property
    def forbidden_transitions(self) -> int:
        n = 0
        for t in self.plant.transitions:
            if not t.controllable:
                continue
            s, d = self.plant.slices(t)
            bad = self.removed[d]
            if t.event in self.forbid:
                bad = bad | self.forbid[t.event][s]
            n += int(np.count_nonzero(self.reachable[s] & bad))
        return n

    def summary(self) -> dict[str, int]:
        legal = ~self.illegal
        weak = self.removed & legal & ~self.defended
        kept = ~self.removed
        return {
            "states": self.size,
            "transitions": self.count_transitions(),
            "controllable": self.count_transitions(True),
            "uncontrollable": self.count_transitions(False),
            "forbidden_transitions": self.forbidden_transitions,
            "illegal": int(np.count_nonzero(self.illegal)),
            "defended": int(np.count_nonzero(self.defended)),
            "weakly_defended": int(np.count_nonzero(weak)),
            "unreachable_removed": int(np.count_nonzero(kept & ~self.reachable)),
        }


def supremal_controllable(p: Plant, constraints: Sequence[Constraint], *, reach: bool = True) -> Supervisor:
    """SUP of plant ``p`` under ``constraints`` (see module docstring)."""
    terms = _terms(p, constraints)
    closures = [e.uncontrollable_closure() for e in p.elements]
    illegal = np.zeros(p.shape, dtype=bool)
    removed = np.zeros(p.shape, dtype=bool)
    forbid: dict[str, np.ndarray] = {}
    for term in terms:
        if term.event is not None:
            g = _product(p, term.factors)
            forbid[term.event] = forbid[term.event] | g if term.event in forbid else g
            continue
        illegal |= _product(p, term.factors)
        removed |= _product(p, ((a, (closures[a].astype(np.uint8) @ v.astype(np.uint8)) > 0) for a, v in term.factors))
    defended = p.preimage(illegal, controllable=False) & ~illegal
    reachable = np.zeros(p.shape, dtype=bool)
    sup = Supervisor(p, tuple(constraints), illegal, removed, defended, forbid, reachable, terms)
    if reach and not removed[p.initial]:
        _explore(sup)
    return sup


def _explore(sup: Supervisor) -> None:
    """Forward reachability inside SUP.

    Chaotic (Gauss-Seidel) iteration: each pass runs over the local transitions and
    updates the reached set in place, so states found early in a pass propagate within
    the same pass; passes repeat until one adds nothing. Each pass costs one sweep over
    the plant's transitions as vectorised slice operations.
    """
    p = sup.plant
    reach = sup.reachable
    reach[p.initial] = True
    target_ok = ~sup.removed
    moves = []
    for t in p.transitions:
        s, d = p.slices(t)
        forbid = sup.forbid.get(t.event) if t.controllable else None
        moves.append((s, d, None if forbid is None else ~forbid[s]))
    before = -1
    count = 1
    while count != before:
        before = count
        for s, d, ok in moves:
            add = reach[s] & target_ok[d]
            if ok is not None:
                add &= ok
            reach[d] |= add
        count = int(np.count_nonzero(reach))


class LocalSupervisor:
    """SUP membership decided state by state, without building the plant grid.

    ``kept(local)`` is true iff no constraint violation is reachable from the state by
    uncontrollable events; cost O(monomials × elements) per query.
    """

    def __init__(self, p: Plant, constraints: Sequence[Constraint]) -> None:
        self.plant = p
        self.constraints = tuple(constraints)
        self.terms = _terms(p, constraints)
        closures = [e.uncontrollable_closure() for e in p.elements]
        self._level = [t for t in self.terms if t.event is None]
        self._reach = [
            tuple((a, (closures[a].astype(np.uint8) @ v.astype(np.uint8)) > 0) for a, v in t.factors) for t in self._level
        ]

    def kept(self, local: tuple[int, ...]) -> bool:
        return not any(all(vec[local[a]] for a, vec in factors) for factors in self._reach)

    def violated(self, local: tuple[int, ...]) -> list[str]:
        """Ids of the constraints the state violates (levels)."""
        ids = []
        for t in self._level:
            if all(vec[local[a]] for a, vec in t.factors) and t.constraint not in ids:
                ids.append(t.constraint)
        return ids

    def threatened(self, local: tuple[int, ...]) -> list[str]:
        """Ids of the constraints whose violation is reachable by uncontrollable events."""
        ids = []
        for t, factors in zip(self._level, self._reach):
            if all(vec[local[a]] for a, vec in factors) and t.constraint not in ids:
                ids.append(t.constraint)
        return ids

    def forbidding(self, event: str, local: tuple[int, ...]) -> list[str]:
        """Ids of the edge constraints that forbid controllable ``event`` in this state."""
        ids = []
        for t in self.terms:
            if t.event == event and all(vec[local[a]] for a, vec in t.factors) and t.constraint not in ids:
                ids.append(t.constraint)
        return ids

    def move(self, t: LocalTransition, local: tuple[int, ...]) -> tuple[bool, list[str]]:
        """Whether SUP allows transition ``t`` from ``local`` (a source in SUP), and if
        not, the ids of the constraints responsible."""
        target = list(local)
        target[t.axis] = t.dst
        target_t = tuple(target)
        why = self.forbidding(t.event, local) if t.controllable else []
        why += [c for c in self.threatened(target_t) if c not in why]
        return (not why, why)


@dataclass(frozen=True)
class Explanation:
    """Why a state is kept in or removed from SUP."""

    state: str
    status: str  # illegal | defended | weakly_defended | kept | unreachable
    constraints: tuple[str, ...] = ()
    path: tuple[str, ...] = ()  # uncontrollable events leading to the violation
    forbidden: tuple[tuple[str, tuple[str, ...]], ...] = ()  # (event, constraint ids) cut from here

    def as_dict(self) -> dict:
        return {
            "state": self.state,
            "status": self.status,
            "constraints": list(self.constraints),
            "path": list(self.path),
            "forbidden": [{"event": e, "constraints": list(c)} for e, c in self.forbidden],
        }

    def text(self, labels: dict[str, str] | None = None) -> str:
        labels = labels or {}

        def named(ids: Iterable[str]) -> str:
            return ", ".join(f'{i} "{labels[i]}"' if labels.get(i) else i for i in ids)

        s = self.state
        if self.status == "illegal":
            return f"{s} is illegal: it violates {named(self.constraints)}"
        if self.status == "defended":
            return f"{s} is defended: the uncontrollable event {self.path[0]} leads to a state violating {named(self.constraints)}"
        if self.status == "weakly_defended":
            return (
                f"{s} is weakly defended: the uncontrollable path {' '.join(self.path)} leads to a state "
                f"violating {named(self.constraints)}"
            )
        head = f"{s} is kept in SUP" if self.status == "kept" else f"{s} is legal and not defended, but unreachable in SUP"
        if not self.forbidden:
            return head + "; no controllable event is forbidden there"
        lines = [head + "; forbidden controllable events from it:"]
        for e, ids in self.forbidden:
            lines.append(f"  {e}: {named(ids)}")
        return "\n".join(lines)


def explain(sup: Supervisor, local: tuple[int, ...]) -> Explanation:
    """Why ``local`` is in SUP or not, with the shortest uncontrollable path to a violation."""
    p = sup.plant
    oracle = LocalSupervisor(p, sup.constraints)
    label = p.label(local)
    if sup.illegal[local]:
        return Explanation(label, "illegal", tuple(oracle.violated(local)))
    if sup.removed[local]:
        # breadth-first search over uncontrollable moves to the nearest violation
        parent: dict[tuple[int, ...], tuple[tuple[int, ...], str] | None] = {local: None}
        queue = deque([local])
        while queue:
            cur = queue.popleft()
            if sup.illegal[cur]:
                path = []
                node = cur
                while parent[node] is not None:
                    prev, ev = parent[node]  # type: ignore[misc]
                    path.append(ev)
                    node = prev
                path.reverse()
                status = "defended" if len(path) == 1 else "weakly_defended"
                return Explanation(label, status, tuple(oracle.violated(cur)), tuple(path))
            for t, nxt in p.successors(cur):
                if not t.controllable and nxt not in parent:
                    parent[nxt] = (cur, t.event)
                    queue.append(nxt)
        raise AssertionError("removed state with no uncontrollable path to a violation")  # pragma: no cover
    forbidden = []
    for t, nxt in p.successors(local):
        if t.controllable:
            ok, why = oracle.move(t, local)
            if not ok:
                forbidden.append((t.event, tuple(why)))
    status = "kept" if sup.reachable[local] else "unreachable"
    return Explanation(label, status, (), (), tuple(forbidden))
