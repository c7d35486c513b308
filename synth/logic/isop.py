"""Irredundant covers of prime implicants (what :meth:`synth.logic.bdd.Engine.text` prints):
the Minato–Morreale ISOP of an interval ``[lower, upper]`` built in the *text order*, each
cube then expanded to a prime implicant (literals dropped in text order) and the cover made
irredundant (each cube the others cover dropped, in order). A cover depends on the
interval and the text order only, never on the manager's variable order.

Each cover is computed in a manager apart from the engine's (:class:`Covers`) that declares
the interval's support (the last cover's manager when it declares that support, or can
add it at its end, at most twice over), in the engine's variable order: a transfer there is linear (the
text order would make the functions exponentially larger: a request first, each output's
constraints last), the cofactors and conjunctions of the recursion run on a small unique
table, away from the engine's millions of nodes, and dd's substitutions, quantifications
and supports, whose cost grows with the variables declared, see a few dozen rather than all
of the engine's. The recursion splits on the first variable, in the text order, that
``lower`` or ``upper`` depends on (its top variable where the manager's order on the
support is the text order), and remembers each function's first variable and each
interval's cover (memoised on the pair of nodes). A probe (a cover asked for with at most
N cubes) is refused first by the lower bounds of :mod:`synth.logic.cover_bound` where they
exceed N.

Example
-------
>>> from dd import autoref
>>> b = autoref.BDD(); b.declare("x", "y")
>>> c = Covers(b, {"x": 1, "y": 0}.__getitem__)
>>> u = b.add_expr(r"x \\/ y")
>>> c.cover(u)
[{'y': True}, {'x': True}]
"""

from __future__ import annotations

import ctypes
from typing import Any, Callable, Mapping

from synth.logic.cover_bound import cubes_at_least, path_bound
from synth.logic.native import Native, native

__all__ = ["Covers", "CoverTooLarge", "Cube", "expanded"]

Cube = dict[str, bool]  # a name -> its value
CACHE = 2 ** 14
"""A cover's manager's first computed-table slots (CUDD's default, 2^18, is 8 MiB more)."""
MEMORY = 2 ** 24
"""A cover's manager's memory target in bytes (past it, CUDD collects its dead nodes more
eagerly; no limit): CUDD sets aside a part of it when a manager opens, so that opening
takes time with it: dd's default, 1 GiB, 1.3 ms; 2^28, 0.35–0.6 ms; 2^24, 0.09 ms (the
chain of 256 opens 257 managers)."""
LOOSE = 2 ** 18
"""Unique-table slots up to which a cover's manager grows its table instead of collecting its
dead nodes (dd's default, 6.7·10^6, let the eliminations' intermediate BDDs pile up: 200 MiB
and slower covers at 64 outputs)."""
REUSE = 2
"""A cover reuses the last cover's manager when it declares at most this many times the
variables the cover needs (dd's substitutions and quantifications walk every declared one)."""
Function = Any  # a dd Function


class CoverTooLarge(Exception):
    """An irredundant cover needs more cubes than the caller's limit (:meth:`Covers.cover`)."""

    def __init__(self, limit: int) -> None:
        super().__init__(f"more than {limit} terms")
        self.limit = limit


def expanded(bdd: Any, cube: Cube, upper: Function, leq: Callable[[Function, Function], bool] | None = None) -> Cube:
    """``cube`` (implying ``upper``, over ``bdd``'s variables) with literals dropped, in
    its order, while it still implies ``upper``: a prime implicant of ``upper``. ``leq``:
    CUDD's containment test (:meth:`synth.logic.native.Native.leq`), which tells whether a
    cube implies ``upper`` without building its cofactor."""
    if leq is None:
        kept = dict(cube)
        for n in list(cube):
            trial = {m: v for m, v in kept.items() if m != n}
            if (bdd.let(trial, upper) if trial else upper) == bdd.true:  # the cube implies upper
                kept = trial
        return kept
    # the literal at j is tested with the kept ones before it and all after it: the cubes of
    # the literals after each j built once, those kept before it grown one literal at a time
    names = list(cube)
    literals = [bdd.var(n) if cube[n] else ~bdd.var(n) for n in names]
    after = [bdd.true] * (len(names) + 1)
    for j in range(len(names) - 1, -1, -1):
        after[j] = literals[j] & after[j + 1]
    before, out = bdd.true, {}
    for j, n in enumerate(names):
        if not leq(before & after[j + 1], upper):  # needed: kept
            out[n] = cube[n]
            before &= literals[j]
    return out


class Covers:
    """The covers of the functions of one dd manager ``source``; ``rank`` gives a
    variable's position in the text order (variables are the manager's own names)."""

    def __init__(self, source: Any, rank: Callable[[str], int]) -> None:
        self.source = source
        self.rank = rank
        self.native = type(source).__module__ == "dd.cudd"  # complemented edges, low and high of the regular node
        # CUDD's containment test u ≤ v in the cover's manager (no BDD built; None: dd's operations)
        self._leq: Callable[[Function, Function], bool] | None = None
        # CUDD's support as indices (None: dd's support); a cover's manager's variables by index, their ranks
        self._indices: Callable[[Function], list[int]] | None = None
        self._calls: Native | None = None  # a cover's manager's direct calls into CUDD
        # the engine's direct calls into CUDD, its variables by index and their indices
        self._source_calls: Native | None = None
        self._source_names: dict[int, str] = {}
        self._source_index: dict[str, int] = {}
        # the last cover's manager and its direct calls, kept for the next cover (:meth:`_manager`)
        self._kept: tuple[Any, Native | None] | None = None
        self._by_index: list[str] = []  # the kept manager's variables by index, their ranks, their indices
        self._rank_of_index: list[int] = []
        self._declared: dict[str, int] = {}
        self._aligned = False  # a cover's manager's order is the text order: a function's first variable is its top one
        # the manager of the cover being computed: dd.autoref's, the engine's; CUDD's, one per cover (:meth:`_opened`)
        self.bdd = source
        self._firsts: dict[Function, str] = {}  # during one cover: no function outlives it
        self._ranks: dict[str, int] = {}  # variable -> its rank, for every variable met

    def _opened(self, lower: Function, upper: Function) -> tuple[Function, Function]:
        """``lower`` and ``upper`` in the manager of this cover: with CUDD, a new one that
        declares their support only, in the engine's order (a transfer is linear). dd's
        substitutions, quantifications and supports take time in the number of variables
        declared, whatever the function (a cube of all of them, in Python): the flat probes'
        small functions over 336 variables at 64 outputs spent more there than in CUDD."""
        source = self.source
        if self.native and self._source_calls is None:
            self._source_calls = native(source)
        given = self._source_calls
        if given is None:
            names = source.support(lower) | source.support(upper)
        else:  # the engine's indices named
            names = {self._source_name(i) for i in set(given.support_indices(lower)).union(given.support_indices(upper))}
        for v in names:
            if v not in self._ranks:
                self._ranks[v] = self.rank(v)
        if not self.native:
            return lower, upper
        bdd, calls = self._manager(names)
        # the cover's manager never reorders: its indices are its levels
        ranks = [self._ranks[v] for v in sorted(names, key=self._declared.__getitem__)]
        self._aligned = all(a < b for a, b in zip(ranks, ranks[1:]))
        self.bdd = bdd
        self._leq = None if calls is None else calls.leq
        self._indices = None if calls is None else calls.support_indices
        self._calls = calls
        if given is None or calls is None:
            lower_here = source.copy(lower, bdd)
            return lower_here, lower_here if upper == lower else source.copy(upper, bdd)
        renaming = (ctypes.c_int * given.size())()  # the engine's index -> the cover manager's
        for v in names:
            renaming[self._source_index[v]] = self._declared[v]
        lower_here = given.transfer(lower, calls, renaming)
        return lower_here, lower_here if upper == lower else given.transfer(upper, calls, renaming)

    def _source_name(self, index: int) -> str:
        """The engine's variable of CUDD index ``index``."""
        name = self._source_names.get(index)
        if name is None:  # a variable declared since: name them all again
            assert self._source_calls is not None
            self._source_index = {v: self._source_calls.index(self.source.var(v)) for v in self.source.vars}
            self._source_names = {i: v for v, i in self._source_index.items()}
            name = self._source_names[index]
        return name

    def _manager(self, names: set[str]) -> tuple[Any, Native | None]:
        """A CUDD manager that declares ``names`` in the engine's order: the last cover's when
        it declares them all, or all but some that come after every variable it declares
        (declared then at its end), and declares at most twice as many as ``names``; else a
        new one. Index ``i`` is the ``i``-th variable in the engine's order either way."""
        source = self.source
        if self._kept is not None:
            new = sorted((v for v in names if v not in self._declared), key=source.level_of_var)
            declared = self._by_index
            if (len(declared) + len(new) <= REUSE * len(names)
                    and (not new or not declared or source.level_of_var(new[0]) > source.level_of_var(declared[-1]))):
                self._declare(new)
                return self._kept
        # a small cache to start with (it grows with its hits)
        bdd = type(source)(memory_estimate=MEMORY, initial_cache_size=CACHE)
        bdd.configure(reordering=False, loose_up_to=LOOSE)
        self._kept = (bdd, native(bdd))
        self._by_index, self._rank_of_index, self._declared = [], [], {}
        self._declare(sorted(names, key=source.level_of_var))
        return self._kept

    def _declare(self, names: list[str]) -> None:
        """Declare ``names`` (in the engine's order, after every variable declared) in the kept manager."""
        assert self._kept is not None
        self._kept[0].declare(*names)  # index i: the i-th variable in the engine's order
        for v in names:
            self._declared[v] = len(self._by_index)
            self._by_index.append(v)
            self._rank_of_index.append(self._ranks[v])

    def cover(self, lower: Function, upper: Function | None = None, limit: int | None = None) -> list[Cube]:
        """An irredundant cover of prime implicants of some function between ``lower`` and
        ``upper`` (``upper`` defaults to ``lower``; the gap is the don't-care set), each
        cube's names in text order. :class:`CoverTooLarge` when the Minato–Morreale cover
        has more than ``limit`` cubes."""
        try:
            kept = self._covered(*self._opened(lower, lower if upper is None else upper), limit)
        finally:
            self._firsts.clear()
            self._indices, self._aligned, self._calls = None, False, None
            self.bdd, self._leq = self.source, None  # the manager stays (kept), its functions go
        if kept is None:
            raise CoverTooLarge(limit or 0)  # from a frame without the cover's BDDs
        return kept

    def _covered(self, lower: Function, upper: Function, limit: int | None) -> list[Cube] | None:
        """:meth:`cover` in the cover's manager; None past ``limit``."""
        if limit is not None and self._leq is not None and self._too_many(lower, upper, limit):
            return None
        try:
            cubes, _ = self._isop(lower, upper, {}, limit)
        except CoverTooLarge:
            return None
        if limit is not None and len(cubes) > limit:
            return None
        primes: list[Cube] = []
        for c in (self._prime(self._ordered(c), upper) for c in cubes):
            if c not in primes:
                primes.append(c)
        # drop, in order, each cube the others (the kept ones before it, all after it) cover
        bdd = self.bdd
        functions = [bdd.cube(c) for c in primes]
        after = [bdd.false] * (len(primes) + 1)
        for i in range(len(primes) - 1, -1, -1):
            after[i] = functions[i] | after[i + 1]
        kept: list[Cube] = []
        before = bdd.false
        for i, c in enumerate(primes):
            if not self._below(lower, before | after[i + 1]):
                kept.append(c)
                before |= functions[i]
        return kept

    def _too_many(self, lower: Function, upper: Function, limit: int) -> bool:
        """Every cover of ``[lower, upper]`` has more than ``limit`` cubes, by the lower bounds of
        :mod:`synth.logic.cover_bound`: along one path, then (where the manager's order is not
        the text order, so that the recursion's cofactors are not its nodes' children and
        cost more than the bound) on a few pairs of nodes."""
        assert self._leq is not None
        if path_bound(self.bdd, lower, upper, self._leq) > limit:
            return True
        return not self._aligned and cubes_at_least(self.bdd, lower, upper, self._leq, limit) > limit

    def _prime(self, cube: Cube, upper: Function) -> Cube:
        """:func:`expanded`; where the manager's order is the text order, by CUDD's own
        expansion (the same literals tried in the same order, in one call)."""
        if self._aligned and self._calls is not None and self._indices is not None:
            prime = self._calls.prime(self.bdd.cube(cube), upper)
            if prime is not None:
                kept = {self._by_index[i] for i in self._indices(prime)}
                return {n: v for n, v in cube.items() if n in kept}
        return expanded(self.bdd, cube, upper, self._leq)

    def _ordered(self, cube: Mapping[str, bool]) -> Cube:
        return dict(sorted(cube.items(), key=lambda kv: self._ranks[kv[0]]))

    def _first(self, u: Function) -> str | None:
        """The first variable of ``u`` in the text order (None for a constant)."""
        if u.var is None:
            return None
        first = self._firsts.get(u)
        if first is None:
            if self._aligned:  # the top variable: its level is its rank among the support's
                first = u.var
            elif self._indices is None:
                first = min(self.bdd.support(u), key=self._ranks.__getitem__)
            else:  # CUDD's indices
                first = self._by_index[min(self._indices(u), key=self._rank_of_index.__getitem__)]
            self._firsts[u] = first
        return first

    def _cofactors(self, u: Function, v: str) -> tuple[Function, Function]:
        """``u`` with ``v`` false, then true: the children when ``v`` is ``u``'s top variable."""
        if self.native and u.var == v:
            low, high = u.low, u.high  # the regular node's children
            return (~low, ~high) if u.negated else (low, high)
        if self._calls is not None:
            return self._calls.cofactor(u, v, False), self._calls.cofactor(u, v, True)
        return self.bdd.let({v: False}, u), self.bdd.let({v: True}, u)

    def _eliminated(self, lower: Function, upper: Function) -> tuple[Function, Function]:
        """``[∃V.lower, ∀V.upper]`` for a prefix V (in the text order) of the interval's
        support such that ``∃V.lower ≤ ∀V.upper``: the recursion would split on each
        variable of V in turn and find both halves empty (docs/filter.md, "The covers'
        eliminations"), so its cover is that of the smaller interval. The longest such
        prefix is found by bisection (any such prefix gives the same cover; a longer one
        saves more): a trial costs about one pass over ``upper`` whatever its length, and
        the long runs of the chained covers (about a quarter of 150–260 variables at 64
        outputs) take fewer trials than galloping from one variable."""
        bdd = self.bdd
        if lower == bdd.false or upper == bdd.true:
            return lower, upper
        names = self._support_in_text_order(lower, upper)
        done, failed = 0, len(names) + 1  # the prefix taken; a longer one known to fail
        # ∀V.upper depends on no variable of V, so ∃V.lower ≤ ∀V.upper iff lower ≤ ∀V.upper: each
        # trial tests the given lower (∃V.lower, often larger, is built once, for the prefix taken)
        while failed - done > 1 and upper != bdd.true:  # lower is not false, nor is ∃V.lower
            size = (done + failed) // 2
            every = self._quantified(names[done:size], upper, True)
            if self._below(lower, every):
                upper, done = every, size
            else:
                failed = size
        if done == 0 or upper == bdd.true:  # the cover of [lower, true] is that of [∃V.lower, true]
            return lower, upper
        return self._quantified(names[:done], lower, False), upper

    def _quantified(self, names: list[str], u: Function, every: bool) -> Function:
        """``∀`` (``every``) or ``∃`` of ``names`` in ``u``, by CUDD directly where it can."""
        if self._calls is None:
            return self.bdd.forall(names, u) if every else self.bdd.exist(names, u)
        return self._calls.quantified(u, sorted(self._declared[v] for v in names), every)

    def _support_in_text_order(self, lower: Function, upper: Function) -> list[str]:
        """The variables ``lower`` or ``upper`` depends on, in the text order."""
        if self._indices is None:
            return sorted(self.bdd.support(lower) | self.bdd.support(upper), key=self._ranks.__getitem__)
        indices = set(self._indices(lower)).union(self._indices(upper))
        return [self._by_index[i] for i in sorted(indices, key=self._rank_of_index.__getitem__)]

    def _below(self, lower: Function, upper: Function) -> bool:
        """``lower ≤ upper``: with CUDD its containment test, which builds nothing and stops at
        the first point of ``lower`` outside ``upper``."""
        if self._leq is None:
            return (lower & ~upper) == self.bdd.false
        return self._leq(lower, upper)

    def _isop(self, lower: Function, upper: Function, memo: dict, limit: int | None,
              after: bool = False) -> tuple[list[Cube], Function]:
        """The Minato–Morreale cover of ``[lower, upper]`` and its function; ``after``: the
        caller eliminated a variable (its two halves were empty)."""
        bdd = self.bdd
        if lower == bdd.false:
            return [], bdd.false
        if upper == bdd.true:
            return [{}], bdd.true
        key = (lower, upper)
        found = memo.get(key)
        if found is not None:
            return found
        a, b = self._first(lower), self._first(upper)
        ranks = self._ranks
        v = a if b is None or (a is not None and ranks[a] <= ranks[b]) else b
        assert v is not None  # lower is not false, upper not true
        # a function whose first variable comes after v does not depend on v: its cofactors are itself
        if v == b:
            l0, l1 = self._cofactors(lower, v) if v == a else (lower, lower)
            u0, u1 = self._cofactors(upper, v)
            if self._leq is not None and self._leq(l0, u1) and self._leq(l1, u0):
                empty = True  # both halves empty, found without building them
            else:
                x0, x1 = l0 & ~u1, l1 & ~u0
                empty = x0 == bdd.false and x1 == bdd.false
        else:  # lower ≤ upper at either value of v: both halves are empty
            empty = True
        if empty:  # v appears in no cube: the cover of [∃v.lower, ∀v.upper]
            lower, upper = (l0 | l1, u0 & u1) if v == b else (bdd.exist([v], lower), upper)
            if after:  # the second in a row: look for a longer run at once
                lower, upper = self._eliminated(lower, upper)
            result = self._isop(lower, upper, memo, limit, True)
            memo[key] = result
            return result
        # each part's cover is in this one's: a part gets what its siblings leave of the limit
        c0, f0 = self._isop(x0, u0, memo, limit)
        if limit is not None and len(c0) > limit:
            raise CoverTooLarge(limit)
        c1, f1 = self._isop(x1, u1, memo, None if limit is None else limit - len(c0))
        if limit is not None and len(c0) + len(c1) > limit:  # the cover holds them: too large already
            raise CoverTooLarge(limit)
        cd, fd = self._isop((l0 & ~f0) | (l1 & ~f1), u0 & u1, memo, None if limit is None else limit - len(c0) - len(c1))
        if limit is not None and len(c0) + len(c1) + len(cd) > limit:
            raise CoverTooLarge(limit)
        cover = [{v: False, **c} for c in c0] + [{v: True, **c} for c in c1] + cd
        result = (cover, bdd.ite(bdd.var(v), f1, f0) | fd)
        memo[key] = result
        return result
