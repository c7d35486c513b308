"""The chain of narrowings on truth tables (``synth.filter.local``) is the synthesis: run on
functions of Y (``Symbolic``) it gives the chain's own BDDs (``synth.filter.narrowing``: the
care set, each output's ``∃O.(S ∧ o)`` and ``∃O.(S ∧ !o)``, each criterion's ``b_j``) on the
grid_edges family, the other bench families, every bundled filter and random filters; run
at one valuation of Y (``Booleans``, what a PLC block computes in one cycle) it gives those
functions' values there."""

from __future__ import annotations

import random
import sys

import pytest

from conftest import ROOT
from synth.filter import local, narrowing
from synth.filter.language import Filter, Sense
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.model import FilterFunctions, functions
from synth.filter.solve import criteria
from synth.logic.bdd import Function

sys.path.insert(0, str(ROOT / "bench"))
from filter_scale import chain_filter, grid_edges_filter, grid_filter, ring_filter  # noqa: E402

BUNDLED = sorted([*(ROOT / "plants").glob("*.filter"), *(ROOT / "tests" / "data" / "filter").glob("*.filter")])


def _goods(m: FilterFunctions) -> list[Function]:
    e = m.engine
    return [e.expr(c.expr) if c.sense is Sense.MAX else ~e.expr(c.expr) for c in criteria(m.filter)]


def _same_as_the_chain(f: Filter) -> tuple[FilterFunctions, local.Plan, local.Outcome[Function]]:
    m = functions(f)
    goods = _goods(m)
    chain = narrowing.partitioned(m, goods)
    p = local.plan(m, goods)
    out = local.run(p, local.Symbolic(m.engine))
    assert out.care == chain.care
    assert out.ones == chain.ones
    assert out.zeros == chain.zeros
    return m, p, out


def _points_agree(m: FilterFunctions, p: local.Plan, out: local.Outcome[Function], count: int, seed: int) -> int:
    """At ``count`` random valuations of Y, the plan run there gives the symbolic outcome's values; how many
    of them were in the care set."""
    e, rng = m.engine, random.Random(seed)
    ys = [n for n in e.names if n not in m.outputs]
    inside = 0
    for _ in range(count):
        point = {y: rng.random() < 0.5 for y in ys}
        here = local.run(p, local.Booleans(e, point))
        assert here.care == e.value(out.care, point)
        assert here.ones == {o: e.value(u, point) for o, u in out.ones.items()}
        assert here.zeros == {o: e.value(u, point) for o, u in out.zeros.items()}
        inside += here.care
    return inside


@pytest.mark.parametrize("n, width, entries", [(16, 3, 118), pytest.param(24, 4, 334, marks=pytest.mark.slow)])
def test_grid_edges_plan_is_the_synthesis(n, width, entries):
    m, p, out = _same_as_the_chain(parse_filter(grid_edges_filter(n), "grid_edges.filter"))
    assert (p.width, p.entries, len(p.steps)) == (width, entries, {16: 38, 24: 61}[n])
    assert out.care == m.engine.true  # every Y has a safe vector: the outputs are the functions everywhere
    assert all((out.ones[o] & out.zeros[o]) == m.engine.false for o in m.outputs)  # functional
    assert _points_agree(m, p, out, 60, n) == 60


@pytest.mark.parametrize("family, n", [("ring", 4), ("ring", 8), ("chain", 16), ("grid", 16)])
def test_bench_families_plan_is_the_synthesis(family, n):
    text = {"ring": ring_filter, "chain": chain_filter, "grid": grid_filter}[family](n)
    m, p, out = _same_as_the_chain(parse_filter(text, f"{family}.filter"))
    inside = _points_agree(m, p, out, 40, n)
    assert inside == {"ring": {4: 12, 8: 12}, "chain": {16: 40}, "grid": {16: 40}}[family][n]


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.name)
def test_bundled_filters_plan_is_the_synthesis(path):
    m, p, out = _same_as_the_chain(load_filter(path))
    _points_agree(m, p, out, 20, 7)


def _random_filter(rng: random.Random) -> str:
    """Outputs p..t, inputs a..c; simple constraints with past values and edges, combined ones kept or
    forced, an assumption, stated criteria."""
    outs, ins = ["p", "q", "r", "s", "t"], ["a", "b", "c"]
    lits = [*outs, *ins, "↑a", "p^-1", "r^-1"]
    lines = ["inputs a, b, c", "outputs " + ", ".join(outs)]
    if rng.random() < 0.4:
        lines.append(f"assume {rng.choice(ins)} | !{rng.choice(ins)}")
    for k in range(rng.randint(2, 6)):
        o, other = rng.sample(outs, 2)
        kind = rng.random()
        if kind < 0.35:
            lines.append(f"safety S{k}: {o} & {other}   keep {rng.choice([o, other])}")
        elif kind < 0.5:
            lines.append(f"safety S{k}: {o} & !{other}   force {o}=0")
        else:
            picked = list(dict.fromkeys([o, *rng.sample(lits, rng.randint(1, 2))]))
            lines.append(f"safety S{k}: " + " & ".join(x if rng.random() < 0.6 else "!" + x for x in picked))
    if rng.random() < 0.4:
        lines.append(f"maximize {rng.choice(outs)} & {rng.choice(ins)}")
        lines.append("maximize sim " + ", ".join(rng.sample(outs, rng.randint(2, 5))))
    return "\n".join(lines) + "\n"


def test_random_filters_plan_is_the_synthesis():
    rng = random.Random(29)
    texts = [_random_filter(rng) for _ in range(60)]
    inside, free = 0, 0
    for text in texts:  # each compared on every Y, then at 8 points
        m, p, out = _same_as_the_chain(parse_filter(text, "random.filter"))
        inside += _points_agree(m, p, out, 8, len(text))
        free += any((out.ones[o] & out.zeros[o]) != m.engine.false for o in m.outputs)
    assert (len(texts), inside, free) == (60, 420, 18)  # 18 filters leave an output free somewhere


def test_a_lost_narrowing_is_caught():
    """The comparison can fail: the plan without its last criterion is not the synthesis."""
    m = functions(parse_filter(grid_edges_filter(16), "grid_edges.filter"))
    goods = _goods(m)
    chain = narrowing.partitioned(m, goods)
    out = local.run(local.plan(m, goods[:-1]), local.Symbolic(m.engine))
    assert out.care == chain.care
    last = m.outputs[-1]
    assert [o for o in m.outputs if out.ones[o] != chain.ones[o]] == [last]
