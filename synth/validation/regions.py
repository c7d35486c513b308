"""Plant states as integer codes, and many regions searched at once: the plant's side of
the frontier explorer (:mod:`synth.validation.frontier`).

A plant state is its flat code (mixed radices, :meth:`~synth.plant.composition.Plant.index`),
or on a plant of :data:`WIDE` states or more the dense number of its words
(:mod:`synth.validation.words`: the states met, numbered as met); :class:`PlantCodes`
reads the element-local digits, the Grafcet's inputs and the orders' values of whole
arrays of codes (a run of elements at a time, :mod:`synth.validation.masks`), follows the
uncontrollable moves of a frontier, and decides SUP membership and SUP's refusals with the
compiled constraints' factors (the same terms
:class:`~synth.sup.constraints.CompiledConstraints` asks one state at a time).
:func:`regions` runs :func:`synth.validation.sync.region` for many (entry, wanted orders)
at once, layer by layer: the members of each region in the same breadth-first order, its
settled states with the same prohibitions (each refused move's constraints responsible
read from the same bits as the verdict, named as :meth:`CompiledConstraints.move` names
them).

Example
-------
>>> from synth.plant.composition import _plants, load_plant
>>> from synth.sup.constraints import CompiledConstraints
>>> from synth.plant.rules_check import load_rules
>>> rs = load_rules(_plants("tri.rules"))
>>> p = load_plant(_plants("tri.rules"))
>>> pc = PlantCodes(p, CompiledConstraints(p, rs.constraints))
>>> pc.kept(np.array([p.initial_index])).tolist()
[True]
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Iterable

import numpy as np

from synth.plant.composition import LocalTransition, Plant
from synth.sup.constraints import CompiledConstraints
from synth.validation.keys import ROW_BITS, distinct, distinct_rows, row_codes, slices
from synth.validation.masks import Masks, Runs, pack, unpack
from synth.validation.sync import Prohibition, moves_by_order

if TYPE_CHECKING:  # imported for plants of WIDE states or more only
    from synth.validation.words import Interned, Layout

__all__ = ["Digits", "PlantCodes", "Regions", "regions", "WIDE"]

WIDE = 1 << 40
"""From this many plant states on, plant codes are the dense numbers of the states met
(their flat codes would leave too few bits of the 64-bit keys to the situations)."""


class Digits:
    """The element-local indices of an array of plant codes, each element's computed when
    first read (``digits[axis]``)."""

    def __init__(self, pc: PlantCodes, codes: np.ndarray) -> None:
        self.codes, self.n = codes, len(codes)
        self._pc = pc
        self._axes: dict[int, np.ndarray] = {}
        self._runs: dict[int, np.ndarray] = {}
        self._full: np.ndarray | None = None
        lay, ids = pc.layout, pc.interned
        self._wide = (lay, ids.words[codes]) if lay is not None and ids is not None else None  # (layout, words)
        self.words = [codes] if self._wide is None else list(self._wide[1].T)
        """Each word of the codes, one column per word (the flat codes themselves when not wide)."""

    def __getitem__(self, axis: int) -> np.ndarray:
        if self._full is not None:
            return self._full[axis]
        hit = self._axes.get(axis)
        if hit is None:
            pc = self._pc
            hit = self._axes[axis] = (self.words[pc.word_of[axis]] // pc.stride[axis]) % pc.radix[axis]
        return hit

    def run(self, g: int) -> np.ndarray:
        """The joint index of run ``g`` of :attr:`PlantCodes.runs` at each state."""
        hit = self._runs.get(g)
        if hit is None:
            hit = self._runs[g] = Runs.index(self._pc.runs.items[g], self.words)
        return hit

    def full(self) -> np.ndarray:
        """Every element's indices, ndim × n."""
        if self._full is None:
            if self._wide is None:
                self._full = (self.codes[None, :] // self._pc.strides[:, None]) % self._pc.shape[:, None]
            else:
                lay, words = self._wide
                self._full = np.ascontiguousarray(lay.decode(words).T)
        return self._full

    def moved(self, moves: _Moves, rank: np.ndarray, row: np.ndarray) -> np.ndarray:
        """The index of the element of move ``rank[i]`` (of ``moves``) at state ``row[i]``."""
        if self._full is not None:
            return self._full[moves.axis[rank], row]
        w = self.codes[row] if self._wide is None else self._wide[1][row, moves.word[rank]]
        return (w // moves.stride[rank]) % moves.radix[rank]


class _Moves:
    """Local transitions as columns: element, source, code difference, order column."""

    def __init__(self, moves: list[LocalTransition], strides: tuple[int, ...] | np.ndarray, column: list[int],
                 word: np.ndarray, shape: tuple[int, ...]) -> None:
        self.moves = moves
        self.axis = np.array([t.axis for t in moves], dtype=np.int64)
        self.src = np.array([t.src for t in moves], dtype=np.int64)
        self.stride = np.array([int(strides[t.axis]) for t in moves], dtype=np.int64)  # its element's, in its word
        self.radix = np.array([shape[t.axis] for t in moves], dtype=np.int64)
        self.delta = np.array([(t.dst - t.src) * int(strides[t.axis]) for t in moves], dtype=np.int64)
        self.word = word[self.axis]
        self.column = np.array(column, dtype=np.int64)
        self.guarded = [k for k, t in enumerate(moves) if t.guard is not None]
        self.forbidding: list[int] = []  # moves an edge constraint may forbid


class PlantCodes:
    """Array reads of a plant's states given as flat codes (see module doc)."""

    def __init__(self, p: Plant, oracle: CompiledConstraints) -> None:
        self.plant, self.oracle = p, oracle
        self.layout: Layout | None = None
        self.interned: Interned | None = None
        self.P = p.size
        """The radix of the explorer's keys (situation × code): more than any code."""
        if p.size >= WIDE:
            from synth.validation.words import CAPACITY, Interned, Layout

            self.layout = Layout(p.shape)
            self.interned = Interned(self.layout.count)
            self.P = CAPACITY
        code_strides = self.layout.stride if self.layout is not None else np.array(p.strides, dtype=np.int64)
        word = self.layout.word if self.layout is not None else np.zeros(len(p.shape), dtype=np.int64)
        self.word_of, self.stride, self.radix = word.tolist(), code_strides.tolist(), p.shape
        self.runs = Runs(p.shape, word, code_strides)
        self.strides, self.shape = np.array(code_strides, dtype=np.int64), np.array(p.shape, dtype=np.int64)
        self.uncontrollable = [t for t in p.transitions if not t.controllable]
        self.moves = moves_by_order(p)
        self.orders = tuple(sorted(self.moves))  # the region's order of the orders
        self._values: dict[tuple[str, ...], Masks] = {}
        self._guards: dict[int, tuple[list[tuple[int, np.ndarray]], np.ndarray]] = {}
        self._u = _Moves(self.uncontrollable, code_strides, [0] * len(self.uncontrollable), word, p.shape)
        controllable = [t for o in self.orders for t in self.moves[o]]
        self._c = _Moves(controllable, code_strides, [j for j, o in enumerate(self.orders) for _ in self.moves[o]], word,
                         p.shape)
        self._c.forbidding = [k for k, t in enumerate(controllable) if oracle.edge_terms.get(t.event)]
        self.controllable_moves = self._c
        self.order_starts = np.searchsorted(self._c.column, np.arange(len(self.orders) + 1))
        self._reach = [g.ravel() for g in oracle.reach_grids] if oracle.reach_grids is not None else None
        self.prohibitions: list[Prohibition] = []  # the refusals met: one move, its constraints responsible
        self._why: dict[int | tuple[int, bytes], int] = {}
        self._edge_width = max((len(oracle.edge_terms.get(t.event, ())) for t in controllable), default=0)
        self._threat_masks = Masks(self.runs, self._level_tables(), len(oracle.level_terms), conj=True)
        self._order_masks = Masks(self.runs, self._value_tables(self.orders), len(self.orders), conj=False)

    def _level_tables(self) -> dict[int, np.ndarray]:
        """Per element, which level terms' reach factors hold at each local state (True
        where the term has no factor there)."""
        out: dict[int, np.ndarray] = {}
        for i, factors in enumerate(self.oracle.level_reach):
            for a, vec in factors:
                table = out.setdefault(a, np.ones((self.radix[a], len(self.oracle.level_reach)), dtype=bool))
                table[:, i] &= vec.astype(bool)
        return out

    def _value_tables(self, names: tuple[str, ...]) -> dict[int, np.ndarray]:
        """Per element owning some of ``names``, their values at each local state (False
        in the other columns)."""
        out: dict[int, np.ndarray] = {}
        for a, cols, table in self._tables(names):
            out[a] = np.zeros((self.radix[a], len(names)), dtype=bool)
            out[a][:, cols] = table
        return out

    def digits(self, codes: np.ndarray) -> Digits:
        return Digits(self, codes)

    def encode(self, states: list[tuple[int, ...]]) -> np.ndarray:
        """The codes of plant states given as element-local tuples."""
        local = np.array(states, dtype=np.int64).reshape(len(states), len(self.radix))
        if self.layout is None or self.interned is None:  # below 2^40 states: the flat code fits
            return (local * self.strides).sum(axis=1)
        return self.interned.find_or_add(self.layout.encode(local))

    def step(self, codes: np.ndarray, moves: _Moves, rank: np.ndarray) -> np.ndarray:
        """The codes after the moves ``rank`` (one per code)."""
        if self.interned is None:
            return codes + moves.delta[rank]
        words = self.interned.words[codes]
        words[np.arange(len(codes)), moves.word[rank]] += moves.delta[rank]
        return self.interned.find_or_add(words)

    def values(self, names: tuple[str, ...], digits: Digits) -> np.ndarray:
        """The plant variables ``names`` at each state (n × len(names)); False for a name
        the plant does not have."""
        masks = self._values.get(names)
        if masks is None:
            masks = self._values[names] = Masks(self.runs, self._value_tables(names), len(names), conj=False)
        return unpack(masks.of(digits.run, digits.n), len(names))

    def _tables(self, names: tuple[str, ...]) -> list[tuple[int, np.ndarray, np.ndarray]]:
        """Per element owning some of ``names``: their columns and their values per local state."""
        by_axis: dict[int, list[int]] = {}
        for j, n in enumerate(names):
            if n in self.plant.owner:
                by_axis.setdefault(self.plant.owner[n], []).append(j)
        return [(a, np.array(cols), np.stack([self.plant.elements[a].value(names[j]) for j in cols], axis=1))
                for a, cols in sorted(by_axis.items())]

    @staticmethod
    def holds(factors: Iterable[tuple[int, np.ndarray]], digits: Digits, rows: np.ndarray | None = None) -> np.ndarray:
        """Whether a product term holds at each state (of ``rows`` only, when given)."""
        out = np.ones(digits.n if rows is None else len(rows), dtype=bool)
        for a, vec in factors:
            out &= vec[digits[a] if rows is None else digits[a][rows]]
        return out

    def kept(self, codes: np.ndarray) -> np.ndarray:
        """SUP membership of each state: no violation reachable by uncontrollable events."""
        return np.logical_not(self.threats(codes).any(axis=1))

    def threats(self, codes: np.ndarray) -> np.ndarray:
        """Which level terms' violation each state can reach by uncontrollable events, in
        the compiled constraints' order, packed (n × words, :func:`~synth.validation.masks.pack`)."""
        if self._reach is None:
            digits = self.digits(codes)
            return self._threat_masks.of(digits.run, len(codes))
        out = np.zeros((len(codes), len(self.oracle.level_terms)), dtype=bool)
        at: np.ndarray | tuple[np.ndarray, ...] = codes if self.interned is None else tuple(self.digits(codes).full())
        for i, g in enumerate(self._reach if self.interned is None else self.oracle.reach_grids or ()):
            out[:, i] = g[at]
        return pack(out)

    def order_bits(self, digits: Digits) -> np.ndarray:
        """The values of :attr:`orders` at each state, packed."""
        return self._order_masks.of(digits.run, digits.n)

    def forbidden(self, t: LocalTransition, digits: Digits, rows: np.ndarray) -> np.ndarray:
        """Where an edge constraint forbids the controllable ``t``, at ``rows``."""
        out = np.zeros(len(rows), dtype=bool)
        for term in self.oracle.edge_terms.get(t.event, ()):
            out |= self.holds(term.factors, digits, rows)
        return out

    def successors(self, codes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The uncontrollable moves from ``codes`` into SUP: (row, move rank, target code),
        sorted by row then rank (the explicit engine's order)."""
        digits = self.digits(codes)
        u = self._u
        ok = digits.full()[u.axis, :].T == u.src
        for k in u.guarded:
            rows = ok[:, k].nonzero()[0]
            if rows.size:
                ok[rows, k] = self._guard(k, digits, rows)
        row, rank = ok.nonzero()  # row-major: by row, then rank
        target = self.step(codes[row], u, rank)
        keep = self.kept(target)  # cannot fail from a SUP state; kept for safety, as the machine's path
        if keep.all():
            return row, rank, target
        return row[keep], rank[keep], target[keep]

    def _guard(self, k: int, digits: Digits, rows: np.ndarray) -> np.ndarray:
        """Uncontrollable move ``k``'s guard at ``rows`` (:meth:`Plant.enabled_digits`, its
        read variables' tables made once)."""
        hit = self._guards.get(k)
        if hit is None:
            t = self.uncontrollable[k]
            assert t.guard is not None
            reads = self.plant.elements[t.axis].reads
            parts = [(self.plant.owner[r], self.plant.elements[self.plant.owner[r]].value(r).astype(np.int64) << j)
                     for j, r in enumerate(reads)]
            hit = self._guards[k] = (parts, np.asarray(t.guard, dtype=bool))
        parts, guard = hit
        code = np.zeros(len(rows), dtype=np.int64)
        for axis, bits in parts:
            code |= bits[digits[axis][rows]]
        return guard[code]

    def refused(self, digits: Digits, row: np.ndarray, rank: np.ndarray, threats: np.ndarray) -> np.ndarray:
        """The refusal (index into :attr:`prohibitions`) of each controllable move SUP
        refuses (from the state ``row`` of ``digits``, move ``rank`` of
        :attr:`controllable_moves`, to a target of :meth:`threats` ``threats``): its event
        and the constraints responsible as :meth:`CompiledConstraints.move` names them, the
        edge constraints forbidding it, then those whose violation the target can reach."""
        c, terms = self._c, self.oracle.edge_terms
        edge = np.zeros((len(row), self._edge_width), dtype=bool)
        for k in c.forbidding:
            at = (rank == k).nonzero()[0]
            for j, term in enumerate(terms[c.moves[k].event] if at.size else ()):
                edge[at, j] = self.holds(term.factors, digits, row[at])
        level = unpack(threats, len(self.oracle.level_terms))
        bits = np.concatenate([edge, level], axis=1)
        rank_bits = len(c.moves).bit_length()
        keys: list[int | tuple[int, bytes]]
        if bits.shape[1] + rank_bits <= ROW_BITS:  # (bits, move) as one integer
            codes = (row_codes(bits) << rank_bits) | rank
            first, inverse = distinct(codes)
            keys = codes[first].tolist()
        else:
            first, inverse = distinct_rows(np.hstack([bits, (rank[:, None] >> np.arange(32)) & 1 == 1]))
            keys = [(int(rank[r]), np.packbits(bits[r]).tobytes()) for r in first.tolist()]
        ids = np.empty(len(first), dtype=np.int64)
        for u, (r, key) in enumerate(zip(first.tolist(), keys)):
            hit = self._why.get(key)
            if hit is None:
                t = c.moves[int(rank[r])]
                why = [terms[t.event][j].constraint for j in edge[r].nonzero()[0].tolist()]
                why += [self.oracle.level_terms[i].constraint for i in level[r].nonzero()[0].tolist()]
                hit = self._why[key] = len(self.prohibitions)
                self.prohibitions.append(Prohibition(t.event, tuple(dict.fromkeys(why))))
            ids[u] = hit
        return ids[inverse]


class Regions:
    """Regions searched so far, numbered in order: members and settled states as slices
    of flat arrays (``starts[g]:starts[g + 1]``), prohibitions as indices into
    :attr:`prohibitions`."""

    def __init__(self) -> None:
        self.member_starts = np.zeros(1, dtype=np.int64)
        self.members = np.empty(0, dtype=np.int64)
        self.settled_starts = np.zeros(1, dtype=np.int64)
        self.settled = np.empty(0, dtype=np.int64)
        self.settled_proh = np.empty(0, dtype=np.int64)
        self.prohibitions: list[tuple[Prohibition, ...]] = [()]
        self._proh_ids: dict[tuple[Prohibition, ...], int] = {(): 0}
        self._sets: dict[tuple[int, ...], int] = {}

    @property
    def count(self) -> int:
        return len(self.member_starts) - 1

    def proh_id(self, proh: tuple[Prohibition, ...]) -> int:
        hit = self._proh_ids.get(proh)
        if hit is None:
            hit = self._proh_ids[proh] = len(self.prohibitions)
            self.prohibitions.append(proh)
        return hit

    def refusal_sets(self, rows: np.ndarray, refusals: np.ndarray, met: list[Prohibition]) -> tuple[np.ndarray, np.ndarray]:
        """Per state of ``rows`` (sorted, repeated once per refused move), its refusals
        (indices into ``met``) as one prohibition set: (the states, their set's index in
        :attr:`prohibitions`)."""
        starts = np.concatenate([[True], rows[1:] != rows[:-1]]).nonzero()[0]
        bounds, ids = starts.tolist() + [len(rows)], refusals.tolist()
        out = np.empty(len(starts), dtype=np.int64)
        for u in range(len(starts)):
            key = tuple(ids[bounds[u]:bounds[u + 1]])
            hit = self._sets.get(key)
            if hit is None:
                hit = self._sets[key] = self.proh_id(tuple(sorted(met[q] for q in key)))
            out[u] = hit
        return rows[starts], out

    def append(self, members: np.ndarray, member_counts: np.ndarray, settled: np.ndarray, proh: np.ndarray,
               settled_counts: np.ndarray) -> None:
        self.member_starts = np.concatenate([self.member_starts, self.members.size + member_counts.cumsum()])
        self.members = np.concatenate([self.members, members])
        self.settled_starts = np.concatenate([self.settled_starts, self.settled.size + settled_counts.cumsum()])
        self.settled = np.concatenate([self.settled, settled])
        self.settled_proh = np.concatenate([self.settled_proh, proh])


def regions(pc: PlantCodes, store: Regions, entries: np.ndarray, wanted: np.ndarray) -> None:
    """Search the regions entered at ``entries`` under ``wanted`` (one row of bits over
    ``pc.orders`` per entry) and append them to ``store``, in the order given."""
    R = len(entries)
    if R * pc.P >= 1 << 62:
        raise OverflowError("region keys")
    reg, cur = np.arange(R, dtype=np.int64), entries.astype(np.int64)
    wanted_bits, k = pack(wanted), len(pc.orders)
    seen = set((reg * pc.P + cur).tolist())  # (region, member) keys: a set, one look-up per move kept
    member_parts, settled_parts = [(reg, cur)], []
    while cur.size:
        digits = pc.digits(cur)
        c = pc.controllable_moves
        row, order = unpack(pc.order_bits(digits) ^ wanted_bits[reg], k).nonzero()  # the orders to change, row-major
        counts, rank = slices(pc.order_starts, order)  # their moves (the region's order of the moves)
        row = row.repeat(counts)
        app = digits.moved(c, rank, row) == c.src[rank]
        row, rank = row[app], rank[app]  # by row, then rank
        target = pc.step(cur[row], c, rank)
        threat = pc.threats(target)
        ok = np.logical_not(threat.any(axis=1))
        for k in c.forbidding:
            at = (rank == k).nonzero()[0]
            if at.size:
                ok[at] &= ~pc.forbidden(c.moves[k], digits, row[at])
        still = np.ones(cur.size, dtype=bool)  # settled: no allowed move
        still[row[ok]] = False
        proh = np.zeros(cur.size, dtype=np.int64)
        sel = still[row].nonzero()[0]  # the moves from settled states: every one refused
        if sel.size:
            at, ids = store.refusal_sets(row[sel], pc.refused(digits, row[sel], rank[sel], threat[sel]), pc.prohibitions)
            proh[at] = ids
        settled_parts.append((reg[still], cur[still], proh[still]))
        if not ok.any():
            break
        nreg, target = reg[row[ok]], target[ok]
        add = seen.add  # the first move into each state not met before, in order
        first = np.array([i for i, key in enumerate((nreg * pc.P + target).tolist()) if key not in seen and not add(key)],
                         dtype=np.int64)
        reg, cur = nreg[first], target[first]
        member_parts.append((reg, cur))
    _store(store, R, member_parts, settled_parts)


def _store(store: Regions, R: int, member_parts: list[tuple[np.ndarray, np.ndarray]],
           settled_parts: list[tuple[np.ndarray, np.ndarray, np.ndarray]]) -> None:
    """Group the layers' members and settled states (with their prohibitions) by region
    (breadth-first order kept)."""
    mreg = np.concatenate([r for r, _ in member_parts])
    mcode = np.concatenate([c for _, c in member_parts])
    order = mreg.argsort(kind="stable")
    sreg = np.concatenate([r for r, _, _ in settled_parts])
    scode = np.concatenate([c for _, c, _ in settled_parts])
    sproh = np.concatenate([f for _, _, f in settled_parts])
    sorder = sreg.argsort(kind="stable")
    sreg, scode, proh = sreg[sorder], scode[sorder], sproh[sorder]
    store.append(mcode[order], np.bincount(mreg, minlength=R), scode, proh, np.bincount(sreg, minlength=R))
