"""The covers' shortcuts (:mod:`synth.logic.isop`) give the covers of the plain
Minato–Morreale recursion: a run of split variables in no cube eliminated in one step
(docs/filter.md, "The covers' eliminations"), a probe's parts given what their siblings
leave of the limit. The reference below is the recursion as written before them."""

from __future__ import annotations

import random

import pytest

from synth.logic.bdd import Engine
from synth.logic.isop import CoverTooLarge, Covers, expanded

NAMES = [f"x{i}" for i in range(10)]


class PlainCovers(Covers):
    """The textbook recursion: every split variable's three parts computed, each split
    variable found among dd's support by its rank, each cube expanded literal by literal."""

    def _first(self, u):  # type: ignore[no-untyped-def]
        return None if u.var is None else min(self.bdd.support(u), key=self._ranks.__getitem__)

    def _prime(self, cube, upper):  # type: ignore[no-untyped-def]
        return expanded(self.bdd, cube, upper)  # literal by literal, with dd's substitution

    def _isop(self, lower, upper, memo, limit, after=False):  # type: ignore[no-untyped-def]
        bdd = self.bdd
        if lower == bdd.false:
            return [], bdd.false
        if upper == bdd.true:
            return [{}], bdd.true
        key = (lower, upper)
        if key in memo:
            return memo[key]
        a, b = self._first(lower), self._first(upper)
        v = a if b is None or (a is not None and self._ranks[a] <= self._ranks[b]) else b
        l0, l1 = bdd.let({v: False}, lower), bdd.let({v: True}, lower)
        u0, u1 = bdd.let({v: False}, upper), bdd.let({v: True}, upper)
        c0, f0 = self._isop(l0 & ~u1, u0, memo, limit)
        c1, f1 = self._isop(l1 & ~u0, u1, memo, limit)
        if limit is not None and len(c0) + len(c1) > limit:
            raise CoverTooLarge(limit)
        cd, fd = self._isop((l0 & ~f0) | (l1 & ~f1), u0 & u1, memo, limit)
        if limit is not None and len(c0) + len(c1) + len(cd) > limit:
            raise CoverTooLarge(limit)
        memo[key] = ([{v: False, **c} for c in c0] + [{v: True, **c} for c in c1] + cd,
                     bdd.ite(bdd.var(v), f1, f0) | fd)
        return memo[key]


def _random_function(e: Engine, rng: random.Random, names: list[str], terms: int):
    u = e.false
    for _ in range(terms):
        width = rng.randint(1, 4)
        u |= e.cube({n: rng.random() < 0.5 for n in rng.sample(names, width)})
    return u


def _both(e: Engine):
    ranks = e.inner_ranks()
    return Covers(e.bdd, ranks.__getitem__), PlainCovers(e.bdd, ranks.__getitem__)


def _outcome(covers: Covers, lower, upper, limit):  # type: ignore[no-untyped-def]
    try:
        return covers.cover(lower, upper, limit)
    except CoverTooLarge:
        return "too large"


@pytest.mark.parametrize("seed", range(40))
def test_the_covers_are_the_plain_recursions(seed: int) -> None:
    """Random intervals whose don't-care part hides variables (``f`` on a care set that ties
    further variables to functions, as a chained equation's ``agree`` does), with a text
    order unlike the variable order (one seed in four: the same order): the same cubes, the
    same probes refused."""
    rng = random.Random(seed)
    order = NAMES[:]
    if seed % 4:  # else the text order: a function's first variable is its top one
        rng.shuffle(order)
    e = Engine(order, text_order=NAMES)
    f = _random_function(e, rng, NAMES[:6], rng.randint(1, 6))
    care = e.true
    for tied in NAMES[6:]:  # x6..x9 equal to functions of x0..x5 on the care set
        care &= e.var(tied).equiv(_random_function(e, rng, NAMES[:6], rng.randint(1, 3)))
    lower, upper = f & care, f | ~care
    mine, plain = _both(e)
    full = plain.cover(lower, upper)
    assert mine.cover(lower, upper) == full
    for limit in (0, 1, 2, len(full) - 1, len(full)):
        if limit >= 0:
            assert _outcome(mine, lower, upper, limit) == _outcome(plain, lower, upper, limit)


def test_an_interval_with_a_run_of_eliminations() -> None:
    """``f = x5 & !x8`` known only where ``x8 = x0 & x1``: the recursion splits on x0 and x1
    (text order first) and finds both halves empty each time; the cover reads x8."""
    e = Engine(NAMES, text_order=NAMES)
    x = {n: e.var(n) for n in NAMES}
    care = x["x8"].equiv(x["x0"] & x["x1"])
    f = x["x5"] & ~(x["x0"] & x["x1"])
    lower, upper = f & care, f | ~care
    mine, plain = _both(e)
    assert [{e.name_of(v): b for v, b in c.items()} for c in mine.cover(lower, upper)] == [{"x5": True, "x8": False}]
    assert mine.cover(lower, upper) == plain.cover(lower, upper)


def _factored_recursive(terms: list, top: bool = False) -> str:
    """The greedy factoring as it was written before session 27 (recounting at each level)."""
    if any(not t for t in terms):
        return "1"
    counts: dict = {}
    for t in terms:
        for lit in t:
            counts[lit] = counts.get(lit, 0) + 1
    best = min(counts, key=lambda lit: (-counts[lit], lit)) if counts else None
    if best is None or counts[best] < 2:
        out = " | ".join(" & ".join(text for _, text in t) for t in terms)
        return out if top or len(terms) == 1 else f"({out})"
    inner = [[lit for lit in t if lit != best] for t in terms if best in t]
    rest = [t for t in terms if best not in t]
    if any(not t for t in inner):
        head = best[1]
    else:
        sub = _factored_recursive(inner)
        head = f"{best[1]} & {sub}" if len(inner) > 1 else best[1] + " & " + sub
    if not rest:
        return head
    out = head + " | " + _factored_recursive(rest, top=True)
    return out if top else f"({out})"


@pytest.mark.parametrize("seed", range(6))
def test_one_pass_factoring_is_the_recursive_one(seed: int) -> None:
    from synth.logic.factoring import factored

    rng = random.Random(seed)
    lits = [(k, ("!" if k % 2 else "") + f"x{k // 2}") for k in range(12)]
    for _ in range(300):
        terms = [sorted(rng.sample(lits, rng.randint(1, 6))) for _ in range(rng.randint(1, 12))]
        for top in (True, False):
            assert factored(terms, top) == _factored_recursive(terms, top)


def _nested(rng: random.Random, lits: list, depth: int) -> list:
    """Terms ``a & (b & (… | t3) | t2) | t1``, a chain of nested factors as on the chain of
    outputs, each level with a few terms of its own."""
    terms: list = []
    prefix: list = []
    pool = lits[:]
    rng.shuffle(pool)
    for level in range(depth):
        if len(pool) < 3:
            break
        prefix.append(pool.pop())
        for _ in range(rng.randint(1, 2)):
            terms.append(sorted(set(prefix) | set(rng.sample(pool, rng.randint(1, min(2, len(pool)))))))
    return terms


@pytest.mark.parametrize("seed", range(4))
def test_one_pass_factoring_on_larger_and_nested_covers(seed: int) -> None:
    """Wider covers (up to 40 terms over 80 literals) and nested chains of factors: the
    counts split between the two sides of a literal, either side counted afresh."""
    from synth.logic.factoring import factored

    rng = random.Random(100 + seed)
    for _ in range(60):
        n = rng.randint(1, 40)
        lits = [(k, ("!" if k % 2 else "") + f"x{k // 2}") for k in range(2 * n)]
        terms = [sorted(rng.sample(lits, rng.randint(1, min(len(lits), 10)))) for _ in range(rng.randint(1, 40))]
        nested = _nested(rng, lits, rng.randint(1, 30))
        for case in (terms, nested, terms + nested):
            for top in (True, False):
                assert factored(case, top) == _factored_recursive(case, top)


@pytest.mark.parametrize("seed", range(6))
def test_a_kept_manager_gives_the_covers_of_new_ones(seed: int) -> None:
    """One :class:`Covers` asked for a sequence of intervals whose supports grow, shrink
    and jump (its manager kept and extended, or replaced): each cover and each probe's
    outcome is that of the plain recursion in a manager of its own."""
    rng = random.Random(200 + seed)
    order = NAMES[:]
    if seed % 2:
        rng.shuffle(order)
    e = Engine(order, text_order=NAMES)
    mine = Covers(e.bdd, e.inner_ranks().__getitem__)
    for step in range(12):
        width = rng.choice((4, 5, 7, 8, 10)) if step % 3 else 4 + step % 7
        names = NAMES[:width] if rng.random() < 0.7 else rng.sample(NAMES, width)
        f = _random_function(e, rng, names, rng.randint(1, 5))
        care = _random_function(e, rng, names, rng.randint(2, 6)) if rng.random() < 0.5 else e.true
        lower, upper = f & care, f | ~care
        plain = PlainCovers(e.bdd, e.inner_ranks().__getitem__)
        full = plain.cover(lower, upper)
        assert mine.cover(lower, upper) == full
        limit = rng.choice((0, 1, len(full) - 1, len(full)))
        if limit >= 0:
            assert _outcome(mine, lower, upper, limit) == _outcome(plain, lower, upper, limit)


@pytest.mark.parametrize("seed", range(8))
def test_cudd_s_prime_is_the_expansion_in_the_order_of_the_levels(seed: int) -> None:
    """Where a cover's manager orders its variables as the text order, a cube is made prime
    by CUDD (:meth:`synth.logic.native.Native.prime`): the literals dropped are those
    :func:`expanded` drops, trying them in that order."""
    from synth.logic.native import native

    rng = random.Random(300 + seed)
    e = Engine(NAMES, text_order=NAMES)
    calls = native(e.bdd)
    if calls is None:
        pytest.skip("CUDD's expansion")
    inner = {n: e.var(n).var for n in NAMES}
    dropped = 0
    for _ in range(40):
        upper = _random_function(e, rng, NAMES, rng.randint(1, 8))
        point = {inner[n]: rng.random() < 0.5 for n in NAMES}
        if (e.bdd.cube(point) & ~upper) != e.false:
            continue
        mine = calls.prime(e.bdd.cube(point), upper)
        theirs = expanded(e.bdd, point, upper)
        assert mine == e.bdd.cube(theirs)
        dropped += len(theirs) < len(point)
    assert dropped > 0


def _cube_literals_before(cube: dict, order: dict) -> list:
    """The literals of a cube as written before session 29 (every name marked done)."""
    lits = []
    done: set = set()
    for n, v in cube.items():
        if n in done:
            continue
        if n.endswith("^-1"):
            now = n[:-3]
            if now in cube and cube[now] != v:
                done.update((n, now))
                lits.append((order.get(now, 0), ("↓" if v else "↑") + now))
                continue
        elif n + "^-1" in cube and cube[n + "^-1"] != v:
            continue
        done.add(n)
        lits.append((order.get(n, 0), n if v else "!" + n))
    return sorted(lits)


def test_a_cube_s_literals_and_edges_are_those_written_before() -> None:
    from synth.logic.factoring import cube_literals

    rng = random.Random(7)
    names = [f"x{i}{'^-1' * k}" for i in range(5) for k in range(3)]
    order = {n: i for i, n in enumerate(names) if not n.endswith("^-1")}
    for _ in range(2000):
        chosen = rng.sample(names, rng.randint(0, len(names)))
        cube = {n: rng.random() < 0.5 for n in chosen}
        assert cube_literals(cube, order) == _cube_literals_before(cube, order)
