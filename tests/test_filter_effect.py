"""The 'no effect' analysis of ``synth filter solve`` (``Applied.effect``): the race of each
criterion's dropped part alongside the chain gives the verdict of its definition, the final
filter re-solved without the criterion, on the bundled filters, the benchmark families and
random small filters."""

from __future__ import annotations

import random
import sys

import pytest

from conftest import ROOT

sys.path.insert(0, str(ROOT / "bench"))
from filter_scale import chain_filter, grid_filter, ring_filter  # noqa: E402
from synth.filter.language import Filter, Sense
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.model import functions
from synth.filter.solve import criteria, synthesis

def _by_definition(f: Filter) -> list[bool]:
    """Whether the final admissible set differs when criterion i is left out (re-solved)."""
    m = functions(f)
    e, outs = m.engine, m.outputs
    steps = [(c.sense, e.expr(c.expr)) for c in criteria(m.filter)]

    def final(skip: int) -> object:
        s = m.assumed & ~m.forbidden
        for k, (sense, u) in enumerate(steps):
            if k != skip:
                best = e.exists(outs, s & u) if sense is Sense.MAX else e.forall(outs, ~s | u)
                s = s & u.equiv(best)
        return s

    whole = final(-1)
    return [final(i) != whole for i in range(len(steps))]


def _effects(f: Filter) -> list[bool]:
    return [a.effect for a in synthesis(f).applied]


BUNDLED = sorted([*(ROOT / "plants").glob("*.filter"), *(ROOT / "tests" / "data" / "filter").glob("*.filter")])


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.name)
def test_bundled_filters_agree_with_the_definition(path):
    f = load_filter(path)
    assert _effects(f) == _by_definition(f)


def test_benchmark_families_agree_with_the_definition():
    counts = []
    for text in (ring_filter(3), chain_filter(5), grid_filter(8)):
        f = parse_filter(text, "bench.filter")
        mine = _effects(f)
        assert mine == _by_definition(f)
        counts.append((len(mine), mine.count(False)))
    assert counts == [(6, 0), (9, 1), (15, 1)]


def _random_filter(rng: random.Random) -> str:
    outs, ins = ["p", "q", "r"], ["a", "b"]
    lits = [*outs, *ins]

    def term() -> str:
        picked = [rng.choice(outs), *rng.sample(lits, rng.randint(0, 2))]
        picked = list(dict.fromkeys(picked))
        return " & ".join(n if rng.random() < 0.6 else "!" + n for n in picked)

    lines = ["inputs a, b", "outputs p, q, r"]
    lines += [f"safety S{k}: {term()}" for k in range(rng.randint(1, 3))]
    for k in range(rng.randint(2, 5)):
        lines.append(f"{rng.choice(['maximize', 'minimize'])} {term()}")
    lines.append("maximize sim " + ", ".join(rng.sample(outs, 3)))
    return "\n".join(lines) + "\n"


def test_random_filters_agree_with_the_definition():
    rng = random.Random(25)
    verdicts = {True: 0, False: 0}
    for _ in range(60):
        text = _random_filter(rng)
        f = parse_filter(text, "random.filter")
        mine = _effects(f)
        assert mine == _by_definition(f), text
        for v in mine:
            verdicts[v] += 1
    assert verdicts == {True: 132, False: 260}
