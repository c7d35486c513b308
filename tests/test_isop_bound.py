"""The lower bounds of :mod:`synth.logic.cover_bound` never exceed the fewest cubes of a
cover (found here by exhaustive search on small intervals) nor the Minato–Morreale cover's
count, and a probe refused by them is one the plain recursion refuses
(``tests/test_isop_eliminations.py`` compares the probes' outcomes at every limit)."""

from __future__ import annotations

import itertools
import random

import pytest

from synth.logic.bdd import Engine
from synth.logic.cover_bound import cubes_at_least, path_bound
from synth.logic.isop import Covers
from synth.logic.native import native

NAMES = [f"x{i}" for i in range(4)]


def _fewest_cubes(ones: set[tuple[int, ...]], upper: set[tuple[int, ...]], n: int) -> int:
    """The fewest cubes (each inside ``upper``) whose union holds ``ones``: the primes of
    ``upper``, then a search branching on the first point not yet covered."""
    cubes = [c for c in itertools.product((0, 1, None), repeat=n)
             if all(p in upper for p in itertools.product(*[(v,) if v is not None else (0, 1) for v in c]))]
    points = {c: {p for p in itertools.product(*[(v,) if v is not None else (0, 1) for v in c])} for c in cubes}
    primes = [c for c in cubes if not any(d != c and points[c] < points[d] for d in cubes)]
    best = [len(ones)]

    def search(left: frozenset, used: int) -> None:
        if used >= best[0]:
            return
        if not left:
            best[0] = used
            return
        first = min(left)
        for c in primes:
            if first in points[c]:
                search(left - points[c], used + 1)

    search(frozenset(ones), 0)
    return best[0]


def _points(e: Engine, u) -> set[tuple[int, ...]]:  # type: ignore[no-untyped-def]
    return {p for p in itertools.product((0, 1), repeat=len(NAMES))
            if (e.cube({n: bool(v) for n, v in zip(NAMES, p)}) & ~u) == e.false}


@pytest.mark.parametrize("seed", range(12))
def test_the_bounds_are_below_the_fewest_cubes(seed: int) -> None:
    rng = random.Random(seed)
    order = NAMES[:]
    rng.shuffle(order)
    e = Engine(order, text_order=NAMES)
    calls = native(e.bdd)
    if calls is None:
        pytest.skip("the bounds run on CUDD")
    covers = Covers(e.bdd, e.inner_ranks().__getitem__)
    for _ in range(25):
        table = {p: rng.choice((0, 1, 1, None)) for p in itertools.product((0, 1), repeat=len(NAMES))}
        lower = e.false
        upper = e.false
        for p, v in table.items():
            point = e.cube({n: bool(b) for n, b in zip(NAMES, p)})
            if v == 1:
                lower |= point
            if v != 0:
                upper |= point
        fewest = _fewest_cubes(_points(e, lower), _points(e, upper), len(NAMES))
        mm = len(covers.cover(lower, upper)) if lower != e.false else 0
        path = path_bound(e.bdd, lower, upper, calls.leq)
        deep = cubes_at_least(e.bdd, lower, upper, calls.leq, need=100)
        assert path <= fewest <= mm
        assert deep <= fewest
        assert cubes_at_least(e.bdd, lower, upper, calls.leq, need=100, pairs=1) <= fewest
    # the parity of the four variables: its eight minterms are its primes, and the deep bound finds them all
    parity = e.false
    for p in itertools.product((0, 1), repeat=len(NAMES)):
        if sum(p) % 2:
            parity |= e.cube({n: bool(b) for n, b in zip(NAMES, p)})
    assert cubes_at_least(e.bdd, parity, parity, calls.leq, need=100) == 8
    assert cubes_at_least(e.bdd, parity, parity, calls.leq, need=3) > 3


def test_the_chain_s_path_bound_is_its_cover_s_count() -> None:
    """The flat function of the chain's output k (``o_k = R_k & !o_(k-1)``, ``o_1 = R_1``)
    has a Minato–Morreale cover of ⌈k/2⌉ cubes, and the path bound finds all of them."""
    names = [f"R{i}" for i in range(1, 41)]
    e = Engine(names, text_order=names)
    calls = native(e.bdd)
    if calls is None:
        pytest.skip("the bounds run on CUDD")
    covers = Covers(e.bdd, e.inner_ranks().__getitem__)
    o = e.false
    for k, n in enumerate(names, 1):
        o = e.var(n) & ~o
        assert len(covers.cover(o)) == (k + 1) // 2 == path_bound(e.bdd, o, o, calls.leq)
