"""A brute-force truth-table oracle on small random filters: global consistency, P1, P3,
P4 and the synthesis (pointwise optima, uniqueness, the printed equations) must agree
with what `check` and `solve` compute with BDDs."""

from __future__ import annotations

import random
from itertools import product

import pytest

from synth.filter.coherence import Property, coherence
from synth.filter.language import Sense, request_name
from synth.logic.past import pre_name
from synth.filter.language_check import parse_filter
from synth.filter.solve import criteria, synthesis
from synth.logic.expr import Edge, evaluate

OUTPUTS = ("o1", "o2", "o3")
HEAD = "inputs a, b\noutputs o1, o2, o3\n"
LEVEL = ["a", "!a", "b", "!b", "↑a", "!↑a", "a^-1"]
OUT = {"o1": ["o1", "!o1", "↑o1"], "o2": ["o2", "!o2"], "o3": ["o3", "!o3", "↓o3"]}
Y = ["a", "b", pre_name("a"), pre_name("o1"), pre_name("o3"), *map(request_name, OUTPUTS)]


def _filter_text(rng: random.Random) -> str:
    lines = [HEAD]
    if rng.random() < 0.4:
        lines.append("assume !(a & b)\n")
    for i in range(rng.randint(1, 5)):
        outs = rng.sample(OUTPUTS, rng.choice((1, 1, 2, 2, 3)))
        lits = [rng.choice(OUT[o]) for o in outs] + rng.sample(LEVEL, rng.randint(0, 2))
        relief = ""
        body = " & ".join(lits)
        if rng.random() < 0.2:
            body = f"({body}) | {rng.choice(OUT[outs[0]])} & {rng.choice(LEVEL)}"
        elif len(outs) > 1 and rng.random() < 0.8:  # forcing the first output off its literal relieves
            o, lit = outs[0], lits[0]
            relief = f" force {o}={0 if not lit.startswith('!') and not lit.startswith('↓') else 1}"
        lines.append(f"safety K{i}: {body}{relief}\n")
    for _ in range(rng.randint(0, 2)):
        sense = rng.choice(("maximize", "minimize"))
        lits = rng.sample([*OUT["o1"], *OUT["o2"], "o3", "!o3", *LEVEL, "R_o1", "R_o2"], rng.randint(1, 3))
        lines.append(f"{sense} {' & '.join(lits)}\n")
    if rng.random() < 0.3:  # some outputs without a Sim: possibly not functional
        lines.append(f"maximize sim {', '.join(rng.sample(OUTPUTS, rng.randint(1, 2)))}\n")
    return "".join(lines)


def _value(e, point):
    def edge(x: Edge) -> bool:
        now, before = point[x.name], point[pre_name(x.name)]
        return (not before and now) if x.rising else (before and not now)

    return bool(evaluate(e, lambda n: point[n], edge))


def _points(f):
    for ys in product((False, True), repeat=len(Y)):
        y = dict(zip(Y, ys))
        if all(_value(a.expr, y) for a in f.assumptions):
            yield y


def _vectors():
    return [dict(zip(OUTPUTS, os)) for os in product((False, True), repeat=len(OUTPUTS))]


SEEDS = list(range(40))


@pytest.mark.parametrize("seed", SEEDS)
def test_oracle(seed):
    rng = random.Random(seed)
    text = _filter_text(rng)
    f = parse_filter(text, f"r{seed}.filter")
    report = coherence(f)
    s = synthesis(f)
    found = {(x.property, x.subject): x for x in report.findings}
    consistent, p1, p3, p4 = True, {o: True for o in OUTPUTS}, {o: True for o in OUTPUTS}, {o: True for o in OUTPUTS}
    plan = criteria(f)
    eqs = "".join(f"equation {o} = {t}\n" for o, t in s.equations.items())
    reread = {q.output: q.expr for q in parse_filter(HEAD + eqs, "eq.filter", ).equations} if eqs else {}
    choices = 0
    vectors = _vectors()
    simple_ids = [c.id for c in f.simple]
    on = {k: [c.id for c in f.simple if c.outputs == (k,)] for k in OUTPUTS}
    relieving = {(k, v): [c.id for c in f.combined if any(g.output == k and g.value == v for g in c.forced)]
                 for k in OUTPUTS for v in (False, True)}
    for y in _points(f):
        table = {tuple(o.values()): {c.id: _value(c.expr, {**y, **o}) for c in f.safeties} for o in vectors}
        safe = [o for o in vectors if not any(table[tuple(o.values())].values())]
        for o in vectors:
            here = table[tuple(o.values())]
            simple_ok = not any(here[i] for i in simple_ids)
            for i, k in enumerate(OUTPUTS):
                def forced(v: bool) -> bool:  # some CSs on k is violated when k = !v
                    flipped = tuple(not v if j == i else x for j, x in enumerate(o.values()))
                    return any(table[flipped][i] for i in on[k])

                forces = {v: forced(v) for v in (False, True)}
                if forces[False] and forces[True]:
                    p1[k] = False
                reliefs = {v: any(here[i] for i in relieving[(k, v)]) for v in (False, True)}
                if reliefs[False] and forces[True] and simple_ok:
                    p3[k] = False
                if reliefs[True] and forces[False] and simple_ok:
                    p4[k] = False
        if not safe:
            consistent = False
            continue
        for c in plan:  # pointwise optimum, in order
            values = [_value(c.expr, {**y, **o}) for o in safe]
            best = max(values) if c.sense is Sense.MAX else min(values)
            safe = [o for o, v in zip(safe, values) if v == best]
        if len(safe) > 1:
            assert not s.functional, (text, y, safe)
            choices += 1
        for o, e in reread.items():  # a determined output: every remaining vector agrees with it
            assert all(v[o] == _value(e, y) for v in safe), (text, y, o)
    assert found[(Property.CONSISTENCY, "")].holds == consistent, text
    assert s.consistent == consistent, text
    for k in OUTPUTS:
        assert found[(Property.P1, k)].holds == p1[k], (text, k)
        assert found[(Property.P3, k)].holds == p3[k], (text, k)
        assert found[(Property.P4, k)].holds == p4[k], (text, k)
    assert (choices > 0) == (not s.functional), text
    assert set(s.equations) | set(s.free) == set(OUTPUTS)


def test_oracle_covers_both_outcomes():
    outcomes = set()
    for seed in SEEDS:
        f = parse_filter(_filter_text(random.Random(seed)), "r.filter")
        s = synthesis(f)
        outcomes.add((s.consistent, coherence(f).holds, s.functional))
    assert {(True, True, True), (False, False, True), (True, True, False)} <= outcomes
