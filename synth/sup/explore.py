"""SUP explored and counted over flat state codes, element by element (plants whose
elements read nothing).

A move of element ``a`` changes one digit of the mixed-radix state code: its target is
the source's code plus ``(dst - src) * stride[a]``. Whether SUP keeps the move depends on
the source's digit ``a`` and on a few *context bits* read on the other digits: for each
constraint term with a factor on ``a``, the product of its other factors at the source
(the target can only violate the terms on ``a``, see :mod:`synth.sup.supervisor`), and for
each edge term on one of ``a``'s controllable events, its factors on the other elements.
So each element gets one small table (:class:`AxisTable`) over the keys ``digit +
radix * context``: the code offsets of the kept moves, and per key the kept controllable
and uncontrollable moves, the cut ones and the cuts per constraint. A whole array of
states then moves by one gather and one addition per table column, and SUP's counts are
a histogram of the keys times the table.

The exploration runs over a denser code: the local states that a single-element term
excludes (no SUP state has them: ``Ai & Ri = 0`` leaves 9 of a cylinder's 12 states) are
left out of each digit's radix; the order of the codes is the plant's, so the sorted
result maps back to sorted plant codes. The visited states are a bitmap of that code in
blocks of its low digits, one block per value of the high digits actually met
(:class:`Visited`), so memory follows SUP rather than the plant.

Example
-------
>>> from synth.plant.rules_check import load_rules
>>> from synth.plant.composition import plant, _plants
>>> from synth.sup.constraints import CompiledConstraints
>>> rs = load_rules(_plants("tri_annex.rules"))
>>> cc = CompiledConstraints(plant(rs), rs.constraints)
>>> ex = Explorer.of(cc)
>>> states, counts = ex.explore()
>>> int(states.size) > 0, bool((states[1:] > states[:-1]).all())
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from synth.sup.codes import Layout, Visited
from synth.sup.constraints import CompiledConstraints

__all__ = ["AxisTable", "Counts", "Explorer", "TABLE_BITS", "CHUNK"]

TABLE_BITS = 10
"""Context bits per element at most (a table of ``2^bits × radix`` keys); beyond, the
per-transition exploration of :class:`synth.sup.supervisor.Supervisor` runs."""

CHUNK = 1 << 14
"""States per vectorised pass: the pass's arrays stay in the processor's cache."""

Factors = tuple[tuple[int, np.ndarray], ...]


@dataclass(frozen=True)
class Counts:
    """The moves leaving SUP's states: kept controllable and uncontrollable ones, cut
    controllable ones, and the cuts per constraint id (a cut counts for every constraint
    whose violation it would make reachable, or that forbids its event)."""

    controllable: int
    uncontrollable: int
    cut: int
    per_constraint: dict[str, int]


class AxisTable:
    """One element's moves as a table over the keys ``digit + radix * context``."""

    def __init__(self, cc: CompiledConstraints, axis: int, layout: Layout, reduced: np.ndarray) -> None:
        p = cc.plant
        self.layout = layout
        moves = [t for t in p.transitions if t.axis == axis]
        self.axis = axis
        self.radix = radix = p.shape[axis]
        src = np.array([t.src for t in moves], dtype=np.int64)
        dst = np.array([t.dst for t in moves], dtype=np.int64)
        ctrl = np.array([t.controllable for t in moves], dtype=bool)
        contexts: list[Factors] = []
        columns: list[np.ndarray] = []  # per context: over moves, whether the term hits
        owners: list[str] = []
        const: dict[str, np.ndarray] = {}  # constraint -> moves its one-element terms hit
        for term, factors in zip(cc.level_terms, cc.level_reach):
            own = [vec for a, vec in factors if a == axis]
            if own:
                self._add(term.constraint, own[0][dst], factors, contexts, columns, owners, const)
        for event, terms in cc.edge_terms.items():
            hit = ctrl & np.array([t.event == event for t in moves], dtype=bool)
            for term in terms:
                own = [vec for a, vec in term.factors if a == axis]
                if hit.any():
                    self._add(term.constraint, hit & (own[0][src] if own else True), term.factors, contexts, columns,
                              owners, const)
        self.contexts = contexts
        self.constraints = tuple(dict.fromkeys([*const, *owners]))
        m = len(contexts)
        self.fits = m <= TABLE_BITS
        if not self.fits:
            return
        bits = ((np.arange(1 << m)[:, None] >> np.arange(m)[None, :]) & 1).astype(np.int64)  # (contexts × m)

        def hits(cols: Sequence[int], base: np.ndarray) -> np.ndarray:
            """(contexts × moves): the moves these terms hit in each context."""
            if not cols:
                return np.broadcast_to(base, (1 << m, len(moves)))
            mat = np.array([columns[j] for j in cols], dtype=np.int64)  # (terms × moves)
            return base[None, :] | (bits[:, list(cols)] @ mat > 0)

        none = np.zeros(len(moves), dtype=bool)
        by_constraint = [hits([j for j, o in enumerate(owners) if o == c], const.get(c, none)) for c in self.constraints]
        bad = np.logical_or.reduce(by_constraint) if by_constraint else np.zeros((1 << m, len(moves)), dtype=bool)
        at_src = np.zeros((len(moves), radix), dtype=np.int64)
        at_src[np.arange(len(moves)), src] = 1
        per_key = lambda x: (x.astype(np.int64) @ at_src).reshape(-1)  # noqa: E731  (contexts × moves) -> keys
        self.stats = np.stack([per_key(~bad & ctrl), per_key(~bad & ~ctrl), per_key(bad & ctrl),
                               *(per_key(h & ctrl) for h in by_constraint)], axis=1)
        # the kept moves' code offsets in the reduced code, slot by slot (0: no move)
        rmap = np.cumsum(reduced) - 1
        c, t = np.nonzero(~bad & reduced[src][None, :] & reduced[dst][None, :])
        keys = c * radix + src[t]
        order = np.argsort(keys, kind="stable")
        keys, t = keys[order], t[order]
        first = np.searchsorted(keys, keys, side="left")
        slot = np.arange(keys.size) - first
        deltas = np.zeros((int(slot.max()) + 1 if slot.size else 0, (1 << m) * radix), dtype=np.int64)
        deltas[slot, keys] = (rmap[dst[t]] - rmap[src[t]]) * layout.offsets[axis]
        self.deltas = list(deltas)  # per slot, the offset of each key's move (0: none, the state itself)
        degree = np.count_nonzero(deltas, axis=0)
        self.more = [degree > j for j in range(len(self.deltas))]  # per slot, the keys with a move there
        self.cross: list[tuple[int, Factors]] = []  # contexts read across groups: (bit, factors)
        self.parts = self._parts()  # (group, key part of each group code)

    def _add(self, constraint: str, column: np.ndarray, factors: Factors, contexts: list[Factors],
             columns: list[np.ndarray], owners: list[str], const: dict[str, np.ndarray]) -> None:
        """One term hitting ``column`` (over the moves) where its factors on other elements hold."""
        others = tuple((a, vec) for a, vec in factors if a != self.axis)
        if not others:
            const[constraint] = const.get(constraint, np.zeros(column.shape, dtype=bool)) | column
            return
        contexts.append(others)
        columns.append(column)
        owners.append(constraint)

    def _parts(self) -> list[tuple[int, np.ndarray]]:
        """The keys read from the layout's group codes: one table per group that holds the
        digit or whole contexts; the contexts that span groups go to ``cross``, read bit by bit."""
        layout = self.layout
        parts: dict[int, np.ndarray] = {}

        def part(g: int) -> np.ndarray:
            if g not in parts:
                parts[g] = np.zeros(layout.moduli[g], dtype=np.int64)
            return parts[g]

        g = layout.group_of[self.axis]
        part(g)[:] += layout.digit_table[self.axis]
        for j, factors in enumerate(self.contexts):
            groups = {layout.group_of[a] for a, _ in factors}
            if len(groups) > 1:
                self.cross.append((self.radix << j, factors))
                continue
            bit = np.ones(1, dtype=bool)
            for a, vec in factors:
                bit = bit & vec[layout.digit_table[a]]
            part(groups.pop())[:] += bit * (self.radix << j)
        return sorted(parts.items())

    def keys(self, groups: Sequence[np.ndarray]) -> np.ndarray:
        """The key of each state whose group codes are given."""
        (g, table), *rest = self.parts
        key = table[groups[g]]
        for g, table in rest:
            key += table[groups[g]]
        for weight, factors in self.cross:
            bit = np.ones(key.shape, dtype=bool)
            for a, vec in factors:
                bit &= vec[self.layout.digit_table[a][groups[self.layout.group_of[a]]]]
            key += bit.astype(np.int64) * weight
        return key

    def targets(self, codes: np.ndarray, keys: np.ndarray, out: np.ndarray) -> int:
        """Write into ``out`` the codes the kept moves lead to from the states ``codes``
        with these keys, slot by slot (a state without a move gives itself in the first
        slot); return how many."""
        n = 0
        for j, deltas in enumerate(self.deltas):
            if j:
                more = self.more[j][keys]
                codes, keys = codes[more], keys[more]
            np.add(codes, deltas[keys], out=out[n:n + codes.size])
            n += codes.size
        return n


class Explorer:
    """SUP of a plant without reads, explored and counted with one :class:`AxisTable` per element."""

    def __init__(self, cc: CompiledConstraints, layout: Layout, tables: list[AxisTable]) -> None:
        self.cc = cc
        self.layout = layout
        self.tables = tables

    @classmethod
    def of(cls, cc: CompiledConstraints) -> "Explorer | None":
        """The explorer of ``cc``'s plant, or None where it does not apply (elements that
        read each other, or an element in more than :data:`TABLE_BITS` terms with others)."""
        p = cc.plant
        if p.reads or not p.ndim or cc.reach_grids is not None:
            return None
        kept = [np.ones(n, dtype=bool) for n in p.shape]
        for factors in cc.level_reach:
            if len(factors) == 1:
                a, vec = factors[0]
                kept[a] &= ~vec
        layout = Layout(kept, p.strides)
        tables = [AxisTable(cc, a, layout, kept[a]) for a in range(p.ndim)]
        return cls(cc, layout, tables) if all(t.fits for t in tables) else None

    def explore(self, progress: Callable[[str], None] | None = None) -> tuple[np.ndarray, Counts]:
        """SUP's states (sorted plant codes), breadth-first from the initial state (the
        caller checks that it is kept), and the counts of the moves leaving them."""
        hist = [np.zeros(t.stats.shape[0], dtype=np.int64) for t in self.tables]
        init = self.layout.code(self.cc.plant.initial)
        if init is None:
            return np.zeros(0, dtype=np.int64), self._counts(hist)
        visited = Visited(self.layout.size)
        frontier = np.array([init], dtype=np.int64)
        visited.add(frontier)
        total, depth = 1, 0
        buffer = np.empty(CHUNK * sum(len(t.deltas) for t in self.tables), dtype=np.int64)
        while frontier.size:
            found: list[np.ndarray] = []
            for lo in range(0, frontier.size, CHUNK):
                chunk = frontier[lo:lo + CHUNK]
                groups = self.layout.split(chunk)
                n = 0
                for h, table in zip(hist, self.tables):
                    keys = table.keys(groups)
                    h += np.bincount(keys, minlength=h.size)
                    n += table.targets(chunk, keys, buffer[n:])
                new = buffer[:n]
                new = new[~visited.test(new)]
                new.sort()
                new = new[np.concatenate(([True], new[1:] != new[:-1]))] if new.size else new
                visited.add(new)  # met again from a later chunk of this frontier: not new
                found.append(new)
            frontier = np.concatenate(found)
            frontier.sort()
            total += frontier.size
            depth += 1
            if progress is not None:
                progress(f"exploring SUP: depth {depth}, {total} states")
        states = visited.codes()  # every state met, sorted
        for lo in range(0, states.size, CHUNK):
            states[lo:lo + CHUNK] = self.layout.plant_codes(states[lo:lo + CHUNK])
        return states, self._counts(hist)

    def _counts(self, hist: Sequence[np.ndarray]) -> Counts:
        kept_c = kept_u = cut = 0
        per: dict[str, int] = {}
        for h, table in zip(hist, self.tables):
            sums = [int(x) for x in h @ table.stats]
            kept_c, kept_u, cut = kept_c + sums[0], kept_u + sums[1], cut + sums[2]
            for cid, n in zip(table.constraints, sums[3:]):
                per[cid] = per.get(cid, 0) + n
        return Counts(kept_c, kept_u, cut, per)
