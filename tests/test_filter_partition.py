"""The partitioned chain of narrowings (``synth.filter.narrowing.partitioned``, on
``synth.logic.partition``) gives the same BDDs as the monolithic one: per criterion
whether it narrows and whether it has an effect, the care set, each output's
``∃O.(S ∧ o)`` and ``∃O.(S ∧ !o)`` and the final admissible set, on the bundled filters,
the benchmark families and random filters; and ``synthesis`` the same result."""

from __future__ import annotations

import random
import sys

import pytest

from conftest import ROOT

sys.path.insert(0, str(ROOT / "bench"))
from filter_scale import chain_filter, grid_filter, ring_filter  # noqa: E402
from synth.filter import narrowing
from synth.filter.language import Filter, Sense
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.model import functions
from synth.filter.solve import criteria, synthesis
from synth.logic.bdd import Engine
from synth.logic.partition import Partition

BUNDLED = sorted([*(ROOT / "plants").glob("*.filter"), *(ROOT / "tests" / "data" / "filter").glob("*.filter")])


def _both(f: Filter) -> tuple[narrowing.Narrowing, narrowing.Narrowing]:
    m = functions(f)
    e = m.engine
    goods = [e.expr(c.expr) if c.sense is Sense.MAX else ~e.expr(c.expr) for c in criteria(f)]
    return narrowing.partitioned(m, goods), narrowing.monolithic(m, goods)


def _same_synthesis(f: Filter) -> None:
    mine, theirs = synthesis(f), synthesis(f, partitioned=False)
    assert mine.equations == theirs.equations
    assert mine.chained == theirs.chained and list(mine.chained) == list(theirs.chained)
    assert [(a.narrows, a.effect) for a in mine.applied] == [(a.narrows, a.effect) for a in theirs.applied]
    assert mine.free == theirs.free
    assert mine.inconsistent_text == theirs.inconsistent_text


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.name)
def test_bundled_filters_partitioned_as_monolithic(path):
    f = load_filter(path)
    mine, theirs = _both(f)
    assert mine == theirs
    _same_synthesis(f)


@pytest.mark.parametrize("family, n, counts", [
    ("ring", 4, (8, 8, 8)), ("ring", 8, (16, 16, 16)), ("chain", 16, (31, 31, 30)),
    ("grid", 16, (38, 38, 36)), ("grid", 24, (61, 61, 59)), ("grid", 32, (84, 84, 82))])
def test_benchmark_families_partitioned_as_monolithic(family, n, counts):
    text = {"ring": ring_filter, "chain": chain_filter, "grid": grid_filter}[family](n)
    f = parse_filter(text, f"{family}.filter")
    mine, theirs = _both(f)
    assert mine == theirs
    assert (len(mine.narrows), sum(mine.narrows), sum(mine.effects)) == counts
    if n <= 16:
        _same_synthesis(f)


def _random_filter(rng: random.Random) -> str:
    outs, ins = ["p", "q", "r", "s", "t"], ["a", "b", "c"]
    lits = [*outs, *ins, "p^-1", "q^-1"]

    def term(first: str) -> str:
        picked = list(dict.fromkeys([first, *rng.sample(lits, rng.randint(0, 2))]))
        return " & ".join(n if rng.random() < 0.6 else "!" + n for n in picked)

    lines = ["inputs a, b, c", "outputs p, q, r, s, t"]
    if rng.random() < 0.3:
        x, y = rng.sample(ins, 2)
        lines.append(f"assume {x} | !{y}")
    for k in range(rng.randint(2, 5)):
        o = rng.choice(outs)
        keep = f"   keep {o}" if rng.random() < 0.5 else ""
        other = rng.choice([x for x in outs if x != o])
        lines.append(f"safety S{k}: {o} & {other}{keep}" if keep else f"safety S{k}: {term(o)}")
    if rng.random() < 0.5:
        for k in range(rng.randint(1, 3)):
            lines.append(f"{rng.choice(['maximize', 'minimize'])} {term(rng.choice(outs))}")
        lines.append("maximize sim " + ", ".join(rng.sample(outs, 5)))
    return "\n".join(lines) + "\n"


def test_random_filters_partitioned_as_monolithic():
    rng = random.Random(2025)
    seen = {"narrows": 0, "effect": 0, "no effect": 0}
    for _ in range(80):
        text = _random_filter(rng)
        f = parse_filter(text, "random.filter")
        mine, theirs = _both(f)
        assert mine == theirs, text
        seen["narrows"] += sum(mine.narrows)
        seen["effect"] += sum(mine.effects)
        seen["no effect"] += sum(not x for x in mine.effects)
    assert seen == {"narrows": 417, "effect": 397, "no effect": 154}


def test_partition_projects_as_the_whole_relation():
    rng = random.Random(7)
    names = ["y1", "a", "y2", "b", "c", "y3", "d"]
    e = Engine(names)
    outs = ["a", "b", "c", "d"]
    for _ in range(40):
        factors = []
        for _ in range(rng.randint(1, 5)):
            picked = rng.sample(names, rng.randint(1, 3))
            lits = [e.var(n) if rng.random() < 0.5 else ~e.var(n) for n in picked]
            factors.append(~e.conjunction(lits))
        p = Partition(e, outs, factors)
        s = p.refine(p.initial, 1, e.var("b").equiv(e.var("y2")))
        whole = p.relation(s)
        for k, o in enumerate(outs):
            assert p.project(s, k, e.var(o)) == e.exists(outs, whole & e.var(o))
        assert p.project(s, 0) == e.exists(outs, whole)


def test_a_walk_projects_as_the_states_over_the_same_domains():
    """``Partition.walk``: messages keyed by value, shared with the states' and with other
    walks wherever they agree; each projection the states' over the same domains, and the
    walk's domains changed only by a narrowing that narrows."""
    rng = random.Random(11)
    names = ["y1", "a", "y2", "b", "c", "y3", "d", "e"]
    e = Engine(names)
    outs = ["a", "b", "c", "d", "e"]
    shared = 0
    for _ in range(30):
        factors = []
        for _ in range(rng.randint(2, 6)):
            picked = rng.sample(names, rng.randint(1, 3))
            factors.append(~e.conjunction([e.var(n) if rng.random() < 0.5 else ~e.var(n) for n in picked]))
        p = Partition(e, outs, factors)
        s = p.initial
        for _ in range(3):  # the states' messages, by domains, for the walks to meet
            k = rng.randrange(len(outs))
            s = p.refine(s, k, e.var(outs[k]).equiv(e.var(rng.choice(["y1", "y2", "y3"]))))
            p.project(s, k, e.var(outs[k]))
        w, t = p.walk(s), s
        for _ in range(6):
            k = rng.randrange(len(outs))
            u = e.var(outs[k]) | ~e.var(rng.choice(["y1", "y2", "y3"]))
            before = p.steps
            assert w.project(k, u) == p.project(t, k, u)
            shared += p.steps == before
            assert w.refine(k, u) == (p.refine(t, k, u) is not t)
            t = p.refine(t, k, u)
            assert tuple(w.domains) == t.domains
            for j, o in enumerate(outs):
                assert w.project(j, e.var(o)) == p.project(t, j, e.var(o))
            assert w.project(0) == p.project(t, 0)
    assert shared > 0
