"""The plant of ``synth filter verify``'s explicit closed loop as functions of plant state
codes: a variable's value, an event's successor, illegal, outside SUP, an edge forbidden,
each computed for the codes the search asks about and indexed like the array over the
plant's grid it stands for (:class:`Column`). Nothing is held per plant state, so the
loop's memory follows the states it reaches, not the grid (24^N states for N cylinders).

A code's local indices are its digits (mixed radices: the plant's strides); a move of one
element changes one digit, its guard reads the digits of the elements it reads. An
event's moves are read from the element's transition arrays at once (:class:`Moves`);
an element's uncontrollable events stand side by side in a table over its local states
(:class:`Table`, when it fits in :data:`TABLE_ENTRIES`), so that a batch of codes gets
every event's successor in one gather. *Outside SUP* (a violation reachable by
uncontrollable moves) is SUP's closed form when no element reads another (a product of
each element's own closures); otherwise, guards read where the moves occur, a search
forward from the codes asked through the uncontrollable moves and back from the
violating states it meets: the fixpoint SUP computes on the grid, restricted to what the
codes can reach; the states a search decides are kept, and the next search stops there.

Example
-------
>>> from synth.plant.composition import _plants, load_plant
>>> p = load_plant(_plants("tri.rules"))
>>> cols = PlantColumns(p, p.rules.constraints)
>>> bool(cols.illegal[p.initial_index]), cols.val["TAPIS"][np.array([p.initial_index])].tolist()
(False, [False])
"""

from __future__ import annotations

from typing import Any, Callable, Iterator, NamedTuple, Sequence

import numpy as np

from synth.errors import LimitExceeded
from synth.logic.events import Event
from synth.plant.composition import Plant
from synth.plant.rules import Constraint
from synth.sup.constraints import Term, split_terms

__all__ = ["Column", "PlantColumns"]


class Moves(NamedTuple):
    """One event's local transitions in one element: from local index ``src[j]`` of element
    ``axis`` (sorted, each at most once: an element flips a variable one way per state) the
    code moves by ``shift[j]`` where ``guard[j]`` holds on the code of what the element
    reads (``guard`` None: always)."""

    axis: int
    src: np.ndarray
    shift: np.ndarray
    guard: np.ndarray | None


def _events(p: Plant) -> Iterator[tuple[Event, bool, Moves]]:
    """Every event of each element (the plant's transition order: element, then first
    seen by source), whether it is controllable, and its :class:`Moves`, built from the
    elements' transition arrays at once (no object per transition)."""
    for axis, e in enumerate(p.elements):
        if not e.src.size:
            continue
        rising = (e.codes[e.dst] >> e.var) & 1
        kind = e.var.astype(np.int64) * 2 + rising
        order = np.argsort(kind, kind="stable")  # by event, by source within each (the arrays are by source)
        kinds, first, counts = np.unique(kind[order], return_index=True, return_counts=True)
        starts = np.concatenate(([0], np.cumsum(counts)))
        for k in np.argsort(order[first], kind="stable"):  # events by their first transition
            sel = order[starts[k]:starts[k + 1]]
            src = e.src[sel].astype(np.int64)
            if src.size > 1 and not (np.diff(src) > 0).all():
                raise AssertionError(f"element {e.name}: an event with two moves from one state")
            guard = None if e.guards is None or bool(e.guards[sel].all()) else np.asarray(e.guards[sel], dtype=bool)
            yield (Event.edge(e.variables[int(kinds[k]) // 2], bool(kinds[k] & 1)), bool(e.controllable[sel[-1]]),
                   Moves(axis, src, (e.dst[sel].astype(np.int64) - src) * p.strides[axis], guard))


class Table(NamedTuple):
    """The uncontrollable ``events`` of element ``axis``, side by side: ``slot[k, i]`` is the
    move of ``events[k]`` from local index ``i`` (a row of ``shift`` and ``guard``) or -1."""

    axis: int
    events: tuple[str, ...]
    slot: np.ndarray
    shift: np.ndarray
    guard: np.ndarray | None


TABLE_ENTRIES = 1 << 22
"""The largest table (events × local states) of an element's moves; a larger element's
events look their sources up one event at a time."""


def _tables(p: Plant, events: Sequence[tuple[str, tuple[Moves, ...]]]
            ) -> list[Table | tuple[str, tuple[Moves, ...]]]:
    """``events`` (each with its moves, in order) grouped into a :class:`Table` per run of
    events of one element that fits in :data:`TABLE_ENTRIES`; the others left as they are."""
    out: list[Table | tuple[str, tuple[Moves, ...]]] = []
    run: list[tuple[str, Moves]] = []

    def close() -> None:
        axis = run[0][1].axis if run else 0
        if len(run) > 1 and len(run) * p.shape[axis] <= TABLE_ENTRIES:
            slot = np.full((len(run), p.shape[axis]), -1, dtype=np.int32)  # at most 16 MiB
            start = 0
            for k, (_, m) in enumerate(run):
                slot[k, m.src] = np.arange(start, start + m.src.size)
                start += m.src.size
            width = 1 << len(p.elements[axis].reads)
            guard = None if all(m.guard is None for _, m in run) else np.concatenate(
                [np.ones((m.src.size, width), dtype=bool) if m.guard is None else m.guard for _, m in run])
            out.append(Table(axis, tuple(e for e, _ in run), slot, np.concatenate([m.shift for _, m in run]), guard))
        else:
            out.extend((e, (m,)) for e, m in run)
        run.clear()

    for e, ms in events:
        if len(ms) != 1 or (run and run[0][1].axis != ms[0].axis):
            close()
        if len(ms) == 1:
            run.append((e, ms[0]))
        else:
            out.append((e, ms))
    close()
    return out


class Column:
    """A value per plant state code, computed for the codes asked: ``column[codes]`` as
    ``array[codes]`` would be (an array of codes, or one code)."""

    def __init__(self, fn: Callable[[np.ndarray], np.ndarray]) -> None:
        self.fn = fn

    def __getitem__(self, codes: Any) -> Any:
        arr = np.asarray(codes, dtype=np.int64)
        out = self.fn(arr.reshape(-1))
        return out.reshape(arr.shape) if arr.ndim else out[0]


class PlantColumns:
    """The plant ``p`` and its ``constraints`` as :class:`Column` objects (module docstring):
    ``val[v]``, ``toggle[event]`` (a controllable event's successor, -1 where it cannot
    occur; both edges of every order), ``illegal``, ``outside_sup``, ``forbid[event]``;
    :meth:`moves` gives every uncontrollable event's successors at once."""

    def __init__(self, p: Plant, constraints: Sequence[Constraint]) -> None:
        if p.size >= 2**62:
            raise LimitExceeded(f"the plant has {p.size} states; verify's state codes must fit in 62 bits")
        self.plant = p
        terms = split_terms(p, constraints)
        self.level_terms = [t for t in terms if t.event is None]
        self.edge_terms: dict[str, list[Term]] = {}
        for t in terms:
            if t.event is not None:
                self.edge_terms.setdefault(t.event, []).append(t)
        # without reads, the moves of one element never depend on another's state: what the
        # uncontrollable moves reach is the product of each element's own closure, and a
        # term is reachable when each of its factors is (SUP's closed form)
        self.level_reach: list[Term] | None = None if p.reads else [
            Term(t.constraint, tuple((a, p.elements[a].can_reach(v)) for a, v in t.factors), None)
            for t in self.level_terms]
        by_event: dict[str, list[Moves]] = {}  # per event, its moves in each element, first-seen order
        controllable: dict[str, bool] = {}
        for event, ctrl, mv in _events(p):
            by_event.setdefault(event, []).append(mv)
            controllable[event] = ctrl
        self.uncontrollable: tuple[tuple[str, tuple[Moves, ...]], ...] = tuple(
            (e, tuple(ms)) for e, ms in by_event.items() if not controllable[e])
        self.tables = _tables(p, self.uncontrollable)  # the same events, an element's side by side
        # per element, the (element, values) of each variable it reads (its moves' guards read them)
        self.reads = [[(p.owner[r], p.elements[p.owner[r]].value(r)) for r in e.reads] for e in p.elements]
        self.val = {v: self._value(v) for v in p.variables}
        self.toggle = {e: self._move(tuple(ms)) for e, ms in by_event.items() if controllable[e]}
        for z in p.outputs:
            for edge in (Event.rise(z), Event.fall(z)):
                self.toggle.setdefault(edge, self._move(()))
        self.illegal = self._terms(self.level_terms)
        self.forbid = {e: self._terms(ts) for e, ts in self.edge_terms.items()}
        self.outside_sup = Column(self._removed)
        # the states decided by the searches of outside SUP so far (sorted) and whether each is outside
        self._decided: tuple[np.ndarray, np.ndarray] = (np.zeros(0, dtype=np.int64), np.zeros(0, dtype=bool))

    # ------------------------------------------------------------------ digits and moves
    def digit(self, codes: np.ndarray, axis: int) -> np.ndarray:
        """The local index of element ``axis`` in each code."""
        return (codes // self.plant.strides[axis]) % self.plant.shape[axis]

    def _value(self, name: str) -> Column:
        axis = self.plant.owner[name]
        vec = self.plant.elements[axis].value(name)
        return Column(lambda c: vec[self.digit(c, axis)])

    def _terms(self, terms: Sequence[Term]) -> Column:
        return Column(lambda c: self.holds(terms, c))

    def _move(self, moves: tuple[Moves, ...]) -> Column:
        return Column(lambda c: self.step(moves, c, {}))

    def step(self, moves: Sequence[Moves], codes: np.ndarray, digits: dict[int, np.ndarray]) -> np.ndarray:
        """The successor of each code by one event's ``moves`` (-1 where none applies; an
        element listed later wins, as an array filled element by element would hold);
        ``digits`` caches what :meth:`dig` computes."""
        out = np.full(codes.size, -1, dtype=np.int64)
        for m in moves:
            d = self.dig(codes, digits, m.axis)
            j = np.searchsorted(m.src, d)
            np.minimum(j, m.src.size - 1, out=j)
            sel = m.src[j] == d
            if m.guard is not None:
                sel &= m.guard[j, self.dig(codes, digits, -1 - m.axis)]
            out[sel] = codes[sel] + m.shift[j[sel]]
        return out

    def table_step(self, t: Table, codes: np.ndarray, digits: dict[int, np.ndarray]) -> np.ndarray:
        """:meth:`step` of every event of the table at once: a row per event."""
        row = t.slot[:, self.dig(codes, digits, t.axis)]
        ok = row >= 0
        if t.guard is not None:
            ok &= t.guard[row, self.dig(codes, digits, -1 - t.axis)]
        return np.where(ok, codes + t.shift[row], -1)

    def dig(self, codes: np.ndarray, digits: dict[int, np.ndarray], a: int) -> np.ndarray:
        """Element ``a``'s local index in each code; at ``a = -1 - axis``, the code of the
        variables element ``axis`` reads (bit j: its j-th read); kept in ``digits``."""
        if a not in digits:
            if a >= 0:
                digits[a] = self.digit(codes, a)
            else:
                read = np.zeros(codes.size, dtype=np.int64)
                for j, (e, vec) in enumerate(self.reads[-1 - a]):
                    read |= vec[self.dig(codes, digits, e)].astype(np.int64) << j
                digits[a] = read
        return digits[a]

    def moves(self, codes: np.ndarray) -> Iterator[tuple[str, np.ndarray]]:
        """Every uncontrollable event (the plant's first-seen order) and its successor of
        each code (-1 where it cannot occur)."""
        digits: dict[int, np.ndarray] = {}
        for t in self.tables:
            if isinstance(t, Table):
                yield from zip(t.events, self.table_step(t, codes, digits))
            else:
                yield t[0], self.step(t[1], codes, digits)

    # ------------------------------------------------------------------ constraints
    def holds(self, terms: Sequence[Term], codes: np.ndarray) -> np.ndarray:
        """Whether some product term of ``terms`` holds at each code."""
        out = np.zeros(codes.size, dtype=bool)
        digits: dict[int, np.ndarray] = {}
        for t in terms:
            here = np.ones(codes.size, dtype=bool)
            for a, vec in t.factors:
                here &= vec[self.dig(codes, digits, a)]
            out |= here
        return out

    def closure(self, codes: np.ndarray, known: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The states reachable from ``codes`` by uncontrollable moves (sorted, ``codes``
        included) and those moves, as positions in it (sources, targets); the search does
        not go on from the states of the sorted array ``known``."""
        nodes = np.unique(codes)
        src: list[np.ndarray] = [np.zeros(0, dtype=np.int64)]
        dst: list[np.ndarray] = [np.zeros(0, dtype=np.int64)]
        frontier = nodes if known is None else nodes[~_member(nodes, known)]
        while frontier.size:
            found = []
            for _, nxt in self.moves(frontier):
                ok = nxt >= 0
                src.append(frontier[ok])
                dst.append(nxt[ok])
                found.append(nxt[ok])
            reached = np.unique(np.concatenate([np.zeros(0, dtype=np.int64), *found]))
            reached = reached[~_member(reached, nodes)]
            nodes = np.union1d(nodes, reached)
            frontier = reached if known is None else reached[~_member(reached, known)]
        s, d = np.concatenate(src), np.concatenate(dst)
        return nodes, np.searchsorted(nodes, s), np.searchsorted(nodes, d)

    def _removed(self, codes: np.ndarray) -> np.ndarray:
        """Outside SUP: a violating state is reachable from the code by uncontrollable moves.
        Without the closed form, every state a search meets is decided (what it reaches is
        searched too) and kept: a later search stops at the states decided before."""
        if not codes.size:
            return np.zeros(0, dtype=bool)
        if self.level_reach is not None:
            return self.holds(self.level_reach, codes)
        known, known_bad = self._decided
        nodes, s, d = self.closure(codes, known)
        old = _member(nodes, known)
        bad = np.zeros(nodes.size, dtype=bool)
        bad[old] = known_bad[np.searchsorted(known, nodes[old])]
        bad[~old] = self.holds(self.level_terms, nodes[~old])
        while True:  # back along the moves, until nothing is added
            more = bad[d] & ~bad[s]
            if not more.any():
                break
            bad[s[more]] = True
        fresh = nodes[~old]
        if fresh.size:
            merged = np.concatenate((known, fresh))
            order = np.argsort(merged, kind="stable")
            self._decided = merged[order], np.concatenate((known_bad, bad[~old]))[order]
        return bad[np.searchsorted(nodes, codes)]

    def _ids(self, terms: Sequence[Term], codes: np.ndarray) -> tuple[str, ...]:
        """The constraints (first-seen order, no repeats) of the terms holding at one of ``codes``."""
        return tuple(dict.fromkeys(t.constraint for t in terms if self.holds([t], codes).any()))

    def violated(self, code: int) -> tuple[str, ...]:
        """The constraints the state violates (levels)."""
        return self._ids(self.level_terms, np.array([code], dtype=np.int64))

    def forbidding(self, event: str, code: int) -> tuple[str, ...]:
        """The edge constraints that forbid controllable ``event`` in the state."""
        return self._ids(self.edge_terms.get(event, ()), np.array([code], dtype=np.int64))

    def threatened(self, code: int) -> tuple[str, ...]:
        """The constraints whose violation uncontrollable moves can reach from the state."""
        if self.level_reach is not None:
            return self._ids(self.level_reach, np.array([code], dtype=np.int64))
        return self._ids(self.level_terms, self.closure(np.array([code], dtype=np.int64))[0])


def _member(values: np.ndarray, sorted_set: np.ndarray) -> np.ndarray:
    """Whether each of ``values`` is in the sorted array ``sorted_set``."""
    if not sorted_set.size:
        return np.zeros(values.size, dtype=bool)
    pos = np.minimum(np.searchsorted(sorted_set, values), sorted_set.size - 1)
    return sorted_set[pos] == values
