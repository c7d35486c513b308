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
moves, a local state satisfying ``m``'s literals on its variables: a product of N
small boolean vectors per monomial, evaluated for whole arrays of states at once
(:class:`Supervisor`), for one state (:class:`LocalSupervisor`, on-the-fly validation),
or over the whole plant grid when it fits in memory (the plant-wide statistics).

SUP's states are then explored breadth-first from the initial state over state codes
held in numpy arrays: the work is linear in SUP's transitions, not in the plant.

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
from dataclasses import dataclass
from functools import cached_property
from typing import Callable, Iterable, Iterator, Sequence

import numpy as np

from .composition import LocalTransition, Plant, _plants
from .errors import LimitExceeded
from .expr import disjunctive_normal_form, edge_text
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


def _closed(closures: Sequence[np.ndarray], factors: Iterable[tuple[int, np.ndarray]]) -> tuple[tuple[int, np.ndarray], ...]:
    """Per-element factors of "can reach, by own uncontrollable moves, a satisfying state"."""
    return tuple((a, (closures[a] @ v.astype(np.uint8)) > 0) for a, v in factors)


def _holds(factors: Sequence[tuple[int, np.ndarray]], digits: np.ndarray) -> np.ndarray:
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
        self.terms = _terms(p, constraints)
        closures = [e.uncontrollable_closure().astype(np.uint8) for e in p.elements]
        self.level_terms = [t for t in self.terms if t.event is None]
        self.level_reach = [_closed(closures, t.factors) for t in self.level_terms]
        self.edge_terms: dict[str, list[_Term]] = {}
        for t in self.terms:
            if t.event is not None:
                self.edge_terms.setdefault(t.event, []).append(t)


    # ------------------------------------------------------------------ one state at a time
    @staticmethod
    def _ids(pairs: Iterable[tuple[_Term, Sequence[tuple[int, np.ndarray]]]], local: tuple[int, ...]) -> list[str]:
        """Constraint ids (first-seen order, no repeats) of the terms whose factors hold at ``local``."""
        ids: list[str] = []
        for term, factors in pairs:
            if term.constraint not in ids and all(vec[local[a]] for a, vec in factors):
                ids.append(term.constraint)
        return ids

    def kept(self, local: tuple[int, ...]) -> bool:
        """No constraint violation is reachable from ``local`` by uncontrollable events."""
        return not any(all(vec[local[a]] for a, vec in factors) for factors in self.level_reach)

    def violated(self, local: tuple[int, ...]) -> list[str]:
        """Ids of the constraints the state violates (levels)."""
        return self._ids(((t, t.factors) for t in self.level_terms), local)

    def threatened(self, local: tuple[int, ...]) -> list[str]:
        """Ids of the constraints whose violation is reachable by uncontrollable events."""
        return self._ids(zip(self.level_terms, self.level_reach), local)

    def forbidding(self, event: str, local: tuple[int, ...]) -> list[str]:
        """Ids of the edge constraints that forbid controllable ``event`` in this state."""
        return self._ids(((t, t.factors) for t in self.edge_terms.get(event, ())), local)

    def move(self, t: LocalTransition, local: tuple[int, ...]) -> tuple[bool, list[str]]:
        """Whether SUP allows transition ``t`` from ``local`` (a source in SUP), and if
        not, the ids of the constraints responsible."""
        target = list(local)
        target[t.axis] = t.dst
        why = self.forbidding(t.event, local) if t.controllable else []
        why += [c for c in self.threatened(tuple(target)) if c not in why]
        return (not why, why)

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

    # ------------------------------------------------------------------ vectorised membership
    def digits(self, codes: np.ndarray) -> np.ndarray:
        """Local state indices (ndim × n) of the plant states with these codes."""
        return (codes[None, :] // self.strides[:, None]) % self.radices[:, None]

    def kept_digits(self, digits: np.ndarray) -> np.ndarray:
        """Not removed: no violation reachable by uncontrollable events."""
        bad = np.zeros(digits.shape[1], dtype=bool)
        for factors in self.level_reach:
            bad |= _holds(factors, digits)
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
            if not sel.any():
                continue
            src = codes[sel]
            dst = src + (t.dst - t.src) * self.strides[t.axis]
            hits = [
                (self.level_terms[k].constraint, rest[(k, t.axis)][sel])
                for k, a, vec in self._on_axis[t.axis]
                if vec[t.dst]
            ]
            if t.controllable:
                for term in self.edge_terms.get(t.event, ()):
                    hits.append((term.constraint, _holds(term.factors, digits[:, sel])))
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
    def _grid(self, terms: Iterable[tuple[int, np.ndarray]]) -> np.ndarray:
        out = np.zeros(self.plant.shape, dtype=bool)
        for factors in terms:
            out |= _product(self.plant, factors)
        return out

    @cached_property
    def illegal(self) -> np.ndarray:
        return self._grid(t.factors for t in self.level_terms)

    @cached_property
    def removed(self) -> np.ndarray:
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
        out.update(
            {
                "illegal": int(np.count_nonzero(self.illegal)),
                "defended": int(np.count_nonzero(self.defended)),
                "weakly_defended": int(np.count_nonzero(weak)),
                "unreachable_removed": int(np.count_nonzero(~self.removed)) - self.size,
            }
        )
        return out


def supremal_controllable(
    p: Plant,
    constraints: Sequence[Constraint],
    *,
    progress: Callable[[str], None] | None = None,
) -> Supervisor:
    """SUP of plant ``p`` under ``constraints`` (see module docstring).

    Breadth-first exploration from the initial state over codes held in numpy arrays,
    frontier by frontier: each frontier costs a few vectorised operations per local
    transition, so the work is linear in SUP's transitions and no array of the plant's
    size is built beyond a bitmap of visited states. ``progress`` receives a short text
    after each frontier.
    """
    sup = Supervisor(p, constraints)
    init = np.array([p.initial_index], dtype=np.int64)
    if not sup.kept_digits(sup.digits(init))[0]:
        return sup
    visited = np.zeros((p.size + 7) // 8, dtype=np.uint8)

    def mark(codes: np.ndarray) -> None:
        np.bitwise_or.at(visited, codes >> 3, (1 << (codes & 7)).astype(np.uint8))

    def seen(codes: np.ndarray) -> np.ndarray:
        return ((visited[codes >> 3] >> (codes & 7).astype(np.uint8)) & 1).astype(bool)

    mark(init)
    parts = [init]
    frontier = init
    depth = 0
    while frontier.size:
        new_parts = []
        for t, src, dst, ok in sup.moves(frontier):
            dst = dst[ok]
            dst = np.unique(dst[~seen(dst)])
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


class LocalSupervisor(CompiledConstraints):
    """SUP membership decided state by state, without building the plant grid:
    ``kept``, ``violated``, ``threatened``, ``forbidding`` and ``move`` cost
    O(monomials × elements) per query.
    """


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
    label = p.label(local)
    violated = sup.violated(local)
    if violated:
        return Explanation(label, "illegal", tuple(violated))
    if not sup.kept(local):
        # breadth-first search over uncontrollable moves to the nearest violation
        parent: dict[tuple[int, ...], tuple[tuple[int, ...], str] | None] = {local: None}
        queue = deque([local])
        while queue:
            cur = queue.popleft()
            if sup.violated(cur):
                path = []
                node = cur
                while parent[node] is not None:
                    prev, ev = parent[node]  # type: ignore[misc]
                    path.append(ev)
                    node = prev
                path.reverse()
                status = "defended" if len(path) == 1 else "weakly_defended"
                return Explanation(label, status, tuple(sup.violated(cur)), tuple(path))
            for t, nxt in p.successors(cur):
                if not t.controllable and nxt not in parent:
                    parent[nxt] = (cur, t.event)
                    queue.append(nxt)
        raise AssertionError("removed state with no uncontrollable path to a violation")  # pragma: no cover
    forbidden = []
    for t, nxt in p.successors(local):
        if t.controllable:
            ok, why = sup.move(t, local)
            if not ok:
                forbidden.append((t.event, tuple(why)))
    inside = bool(sup.contains(np.array([p.index(local)], dtype=np.int64))[0])
    status = "kept" if inside else "unreachable"
    return Explanation(label, status, (), (), tuple(forbidden))
