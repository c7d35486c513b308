"""The chain at a point with the outputs it fixes kept apart (:mod:`synth.filter.at_point`)
against the chain at a point as single BDDs (:meth:`synth.filter.points.Points.chain`,
:func:`synth.filter.points.race_at_point`, the spellings' comparison written out below):
the same states, verdicts, races and differing outputs, point by point, on small filters
of each bench family and on bundled ones."""

from __future__ import annotations

import dataclasses
import random
import sys
from typing import Sequence

import pytest

from conftest import ROOT
from synth.filter import points
from synth.filter.at_point import AtPoint, Fixed
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.model import functions
from synth.filter.narrowing import layout
from synth.filter.reliefs import _other
from synth.filter.spelling_chain import SpellingChain as _Chain
from synth.filter.solve import criteria
from synth.filter.language import Filter, Sense
from synth.logic.bdd import Function

sys.path.insert(0, str(ROOT / "bench"))
from filter_scale import chain_filter, grid_edges_filter, ring_filter  # noqa: E402

CASES = {
    "chain_12": lambda: parse_filter(chain_filter(12), "chain.filter"),
    "ring_4": lambda: parse_filter(ring_filter(4), "ring.filter"),
    "grid_edges_16": lambda: parse_filter(grid_edges_filter(16, stations=4), "grid_edges.filter"),
    "tri": lambda: load_filter(ROOT / "plants" / "tri.filter"),
    "four_cylinders": lambda: load_filter(ROOT / "plants" / "four_cylinders.filter"),
    "palletizer": lambda: load_filter(ROOT / "tests" / "data" / "filter" / "palletizer.filter"),
}


def _points(at: points.Points, count: int) -> list[dict[str, bool]]:
    """All false, all true, then seeded random points."""
    rng = random.Random(37)
    out = [at.point({}, False), at.point({}, True)]
    return out + [{v: rng.random() < 0.5 for v in at.others} for _ in range(count)]


def _setup(f: Filter) -> tuple[points.Points, list[Function]]:
    m = functions(f)
    e = m.engine
    goods = [u if c.sense is Sense.MAX else ~u for c in criteria(f) for u in (e.expr(c.expr),)]
    return points.Points(layout(m, goods), goods), goods


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_chain_and_the_races_at_points_as_on_single_bdds(case: str) -> None:
    at, goods = _setup(CASES[case]())
    bdd, false = at.bdd, at.engine.false
    races = agreed = 0
    for point in _points(at, 12):
        states, bests, there = at.chain(point)
        here = AtPoint(at, point)
        assert here.bests == bests
        assert [s.relation(bdd) for s in here.states] == states
        assert [here.same(here.states[j], here.states[j]) for j in (0, -1)] == [True, True]
        for i in range(len(goods)):
            z = states[i] & ~there[i]
            if not bests[i] or z == false:
                continue
            mine = here.dropped(i)
            assert mine.relation(bdd) == z
            assert here.race(i, mine) == points.race_at_point(z, there[i + 1:], bests[i + 1:], false)
            races += 1
        agreed += here.agreed
    assert races > 0
    if case == "chain_12":  # the races of the Sim criteria end where Z and the chain agree
        assert agreed > 0


def _differ_on_single_bdds(at: points.Points, point: dict[str, bool], i: int, g: Function,
                           outputs: Sequence[str]) -> list[str]:
    """The spellings' comparison at a point as it was written on single BDDs."""
    e, false = at.engine, at.engine.false
    states, _, _ = at.chain(point)
    z, _ = points.narrow(states[i], at.at(g, point), false)
    for j in range(i + 1, len(at.goods)):
        if z == states[j]:
            return []
        z, _ = points.narrow(z, at.at(at.goods[j], point), false)
    if z == states[-1]:
        return []
    return [o for o in outputs
            if ((z & e.var(o)) != false, (z & ~e.var(o)) != false) !=
            ((states[-1] & e.var(o)) != false, (states[-1] & ~e.var(o)) != false)]


@pytest.mark.parametrize("case", ["chain_12", "ring_4", "grid_edges_16", "four_cylinders"])
def test_the_spellings_at_points_as_on_single_bdds(case: str) -> None:
    f = CASES[case]()
    swapped = [(s, dataclasses.replace(s, keep=o.keep, force=o.force))
               for s in f.combined if s.has_priority for o in (_other(s),) if o is not None]
    chain = _Chain(f, swapped)
    at = points.Points(chain.p, chain.goods)
    regions = [chain._region(n) for n, a in enumerate(chain.alternatives) if a is not None]
    picked = [at.point(at.bdd.pick(r), d) for r in regions if r != at.engine.false for d in (False, True)]
    compared = shown = skipped = 0
    for point in _points(at, 6) + picked:
        here = AtPoint(at, point)
        for alternative in chain.alternatives:
            if alternative is None:
                continue
            i, g = alternative
            mine = here.differ(i, g, chain.m.outputs)
            assert mine == _differ_on_single_bdds(at, point, i, g, chain.m.outputs)
            if not at.holds(chain._region(chain.alternatives.index(alternative)), point):
                assert mine == []  # outside its region: the points skip it (SpellingChain.at_points)
                skipped += 1
            compared += 1
            shown += bool(mine)
    assert compared > 0 and shown > 0 and skipped > 0


def test_a_region_is_read_at_a_point_as_its_restriction() -> None:
    """``Points.holds`` (one path walked, complement edges counted) against dd's ``let``."""
    f = parse_filter(ring_filter(4), "ring.filter")
    at, _ = _setup(f)
    rng = random.Random(7)
    names = at.others
    functions = [at.bdd.var(v) for v in names]
    for _ in range(200):
        u = functions[rng.randrange(len(functions))]
        for _ in range(rng.randrange(1, 10)):
            v = functions[rng.randrange(len(functions))]
            u = (u & ~v) if rng.random() < 0.5 else (u | v)
            u = ~u if rng.random() < 0.3 else u
        point = {v: rng.random() < 0.5 for v in names}
        assert at.holds(u, point) == (at.bdd.let(point, u) == at.bdd.true)


def test_same_relation_whatever_the_outputs_kept_apart() -> None:
    f = parse_filter(chain_filter(3), "chain.filter")
    at, _ = _setup(f)
    here = AtPoint(at, at.point({}, False))
    bdd = at.bdd
    o1, o2, o3 = (at.engine.declare(f"o{k}") for k in (1, 2, 3))
    x1, x2, x3 = (bdd.var(v) for v in (o1, o2, o3))
    rest = ~(x2 & x3)
    apart = Fixed({o1: True}, rest)  # o1 & !(o2 & o3)
    whole = Fixed({}, x1 & rest)  # the same relation, o1 in the rest
    assert here.same(apart, whole) and here.same(whole, apart)
    assert not here.same(apart, Fixed({}, rest))  # o1 free
    assert not here.same(apart, Fixed({o1: False}, rest))
    assert here.same(Fixed({o1: True, o2: False}, bdd.true), Fixed({o2: False}, x1))
    assert not here.same(Fixed({o1: True, o2: False}, bdd.true), Fixed({o3: False}, x1 & ~x2))
    assert here.same(Fixed({o1: True}, bdd.false), Fixed({o2: False}, bdd.false))


@pytest.mark.parametrize("case", ["chain_12", "ring_4", "grid_edges_16", "four_cylinders", "palletizer"])
def test_a_chain_run_from_another_points_chain_is_the_chain_run_alone(case: str) -> None:
    """``AtPoint(at, point, like=other)`` (the steps where both chains' relations and criteria
    agree taken from ``other``) against ``AtPoint(at, point)``: the same relations, outputs
    fixed, horizons and verdicts at every step, the same races and spellings (those run from
    the other point's runs too), on a walk of random points one to three variables apart (as
    the witnesses are made sparse)."""
    f = CASES[case]()
    swapped = [(s, dataclasses.replace(s, keep=o.keep, force=o.force))
               for s in f.combined if s.has_priority for o in (_other(s),) if o is not None]
    chain = _Chain(f, swapped)
    at = points.Points(chain.p, chain.goods)
    rng = random.Random(5)
    here = AtPoint(at, {v: rng.random() < 0.5 for v in at.others})
    alternatives = [a for a in chain.alternatives if a is not None]
    for alternative in alternatives:
        here.differ(*alternative, chain.m.outputs)
    taken = run = races = shared = 0
    for _ in range(30):
        point = dict(here.point)
        for v in rng.sample(at.others, min(len(at.others), rng.choice((1, 1, 2, 3)))):
            point[v] = not point[v]
        alone, near = AtPoint(at, point), AtPoint(at, point, like=here)
        assert near.bests == alone.bests
        assert [(s.fixed, s.rest, s.horizon) for s in near.states] == [(s.fixed, s.rest, s.horizon) for s in alone.states]
        for i in range(len(chain.goods)):
            if near.bests[i] and near.dropped(i).rest != at.engine.false:
                assert near.race(i, near.dropped(i)) == alone.race(i, alone.dropped(i))
                races += 1
        for alternative in alternatives:
            assert near.differ(*alternative, chain.m.outputs, here) == alone.differ(*alternative, chain.m.outputs)
        shared += sum(mine[0] and theirs[0] and mine[0][0] is theirs[0][0]
                      for key, mine in near.runs.items() for theirs in (here.runs.get(key),) if theirs is not None)
        mine = sum(s is t for s, t in zip(near.states[1:], here.states[1:]))
        taken, run = taken + mine, run + len(near.states) - 1 - mine
        if rng.random() < 0.5:
            here = near
    assert taken > 0 and run > 0 and races > 0 and shared > 0


@pytest.mark.parametrize("case", ["ring_4", "grid_edges_16", "palletizer"])
def test_s0_set_in_parts_is_s0_at_the_point(case: str) -> None:
    """``S_0`` with a point's variables at 0 set first (``Points.partial``), then the others in
    two halves (``Points.restrict``), as a witness made sparse sets them: ``S_0`` at the point."""
    at, _ = _setup(CASES[case]())
    rng = random.Random(3)
    differ = 0
    for point in _points(at, 10):
        ones = [v for v in at.others if point[v]]
        half = rng.randrange(len(ones) + 1)
        root = at.partial({v: False for v in at.others if not point[v]})
        parts = at.restrict(at.restrict(root, ones[:half], point), ones[half:], point)
        assert parts == at.base_at(point) == at.bdd.let(dict(point), at.partial({}))
        differ += root != parts
    assert differ > 0
