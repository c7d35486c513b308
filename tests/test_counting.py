"""Exact model counts (synth/logic/counting.py, issue 37): past a double's range without
CUDD's count (which raised "overflow of integer type double" from line_200 on), deeper than
Python's recursion limit, and the counts of ``f ∧ g`` through the cuts of ``f`` equal to the
counts of the conjunctions built; the symbolic SUP of a line of 400 cylinders counted exactly."""

from __future__ import annotations

import random
import subprocess
import sys

import pytest

from conftest import ROOT
from synth.logic.bdd import Engine
from synth.logic.counting import DOUBLE_VARIABLES, Conjunctions, count


def _random_function(e: Engine, rnd: random.Random, cubes: int, lo: int, hi: int):
    f = e.false
    for _ in range(cubes):
        cube = e.true
        for v in rnd.sample(range(lo, hi), 4):
            cube &= e.var(f"x{v}") if rnd.random() < 0.5 else ~e.var(f"x{v}")
        f |= cube
    return f


def test_conjunction_counts_equal_the_counts_of_the_conjunctions():
    names = [f"x{i}" for i in range(40)]
    e = Engine(names)
    levels = [e.level(n) for n in names]
    rnd = random.Random(1)
    for _ in range(25):
        f = _random_function(e, rnd, 12, 0, 40)
        within = Conjunctions(e, f, levels)
        gs = [_random_function(e, rnd, 3, lo, lo + 8) for lo in rnd.sample(range(0, 32), 6)]
        gs += [e.true, e.false, ~f, f]
        rnd.shuffle(gs)  # out of level order: the sweep starts again where it must
        for g in gs:
            assert within.count(g) == count(e, f & g, levels)
    assert within.count(e.true) == count(e, f, levels) > 0


def test_counts_past_a_double_and_deeper_than_the_recursion_limit():
    n = 1500
    assert n > DOUBLE_VARIABLES and n > sys.getrecursionlimit()
    names = [f"x{i}" for i in range(n)]
    e = Engine(names)
    levels = [e.level(v) for v in names]
    every = e.conjunction(e.var(v) for v in names)
    assert count(e, ~every, levels) == 2**n - 1
    # a chain of n levels: no two neighbours both true (Fibonacci numbers)
    chain = e.conjunction(~(e.var(names[i]) & e.var(names[i + 1])) for i in range(n - 1))
    a, b = 1, 2  # valuations of 0 and 1 variables
    for _ in range(n - 1):
        a, b = b, a + b
    assert count(e, chain, levels) == b
    odd = e.conjunction(e.var(names[i]) for i in range(1, n, 2))
    assert Conjunctions(e, chain, levels).count(odd) == count(e, chain & odd, levels) == 1


@pytest.mark.nightly  # about 30 CPU s: SUP of a line of 400 cylinders on BDDs, then its counts (pytest -m nightly)
def test_symbolic_sup_of_line_400_counts_exactly(tmp_path):
    from synth.plant.composition import plant
    from synth.plant.rules_check import load_rules
    from synth.symbolic.encoding import Copy
    from synth.symbolic.supervisor import symbolic_supervisor

    subprocess.run([sys.executable, str(ROOT / "bench" / "gen_line.py"), "400", str(tmp_path)], check=True, capture_output=True)
    rs = load_rules(tmp_path / "line_400.rules")
    p = plant(rs)
    s = symbolic_supervisor(p, rs.constraints)
    data = s.summary()
    assert p.size == 12**400
    # every plant state is illegal, defended, weakly defended, removed as unreachable, or in SUP
    parts = ("illegal", "defended", "weakly_defended", "unreachable_removed", "states")
    assert sum(int(data[k] or 0) for k in parts) == 12**400
    assert data["illegal"] > 2**1024 and data["states"] > 2**900  # past a double's range, past its precision
    assert data["transitions"] == data["controllable"] + data["uncontrollable"]
    assert data["forbidden_transitions"] > 0 and data["unreachable_removed"] == 0
    # the moves' counts through the cuts equal exact counts of the conjunctions built, at both ends of the line
    both = (Copy.CURRENT, Copy.NEXT)
    for m in [m for m in s.moves if m.axis in (0, 199, 399)]:
        direct = s.enc.count(s.states & m.relation, both)
        assert s._within_counts([m.relation]) == [direct]
    forbidden = s.forbidden_counts()
    assert sorted(forbidden) == sorted([f"K{i}" for i in range(1, 401)] + [f"N{i}" for i in range(1, 400)])
