"""The Boolean engine: expressions to BDDs and back (minimised, deterministic, edges
recognised), prime covers with don't-cares, counterexample cubes."""

from __future__ import annotations

import random
from itertools import product

import pytest

from synth.logic.bdd import Engine, cube_text
from synth.filter.language_check import parse_filter
from synth.logic.expr import Edge, evaluate

HEAD = "inputs a, b, c, d\noutputs o\n"
NAMES = ["a", "b", "c", "d", "a^-1", "b^-1"]
ORDER = ["a^-1", "a", "b^-1", "b", "c", "d"]


def _expr(text: str):
    return parse_filter(HEAD + f"equation o = {text}\n", "e.filter").equations[0].expr


def _random_text(rng: random.Random, depth: int = 3) -> str:
    if depth == 0 or rng.random() < 0.3:
        return rng.choice(["a", "!b", "c", "d", "a^-1", "↑a", "↓b", "!↑b", "0", "1"])
    op = rng.choice([" & ", " | "])
    parts = [_random_text(rng, depth - 1) for _ in range(rng.randint(2, 3))]
    return ("!" if rng.random() < 0.2 else "") + "(" + op.join(parts) + ")"


def _truth(e):
    def edge(x: Edge) -> bool:
        now, before = point[x.name], point[x.name + "^-1"]
        return (not before and now) if x.rising else (before and not now)

    rows = []
    for vals in product((False, True), repeat=len(NAMES)):
        point = dict(zip(NAMES, vals))
        rows.append(bool(evaluate(e, lambda n: point[n], edge)))
    return rows


@pytest.mark.parametrize("seed", range(30))
def test_printed_expression_is_the_same_function(seed):
    text = _random_text(random.Random(seed))
    e = Engine(ORDER)
    u = e.expr(_expr(text))
    printed = e.text(u)
    assert _truth(_expr(printed)) == _truth(_expr(text)), (text, printed)  # truth tables as the oracle
    again = Engine(ORDER)
    assert again.text(again.expr(_expr(text))) == printed  # deterministic


def test_edges_are_recognised():
    e = Engine(ORDER)
    assert e.text(e.expr(_expr("!a^-1 & a & c | b^-1 & !b & d"))) == "↑a & c | ↓b & d"
    assert e.text(e.expr(_expr("!(↑a) & c"))) == "c & (a^-1 | !a)"
    assert e.text(e.expr(_expr("a & !a"))) == "0" and e.text(e.true) == "1"


def test_factoring():
    e = Engine(ORDER)
    assert e.text(e.expr(_expr("a & b & c | a & b & d | a & !c & !d"))) == "a & (b | !c & !d)"


def test_cover_is_prime_and_irredundant():
    rng = random.Random(7)
    for _ in range(20):
        e = Engine(ORDER)
        lower = e.expr(_expr(_random_text(rng)))
        upper = lower | e.expr(_expr(_random_text(rng)))
        cubes = e.cover(lower, upper)
        union = e.disjunction(e.cube(c) for c in cubes)
        assert e.implies(lower, union) and e.implies(union, upper)
        for i, c in enumerate(cubes):
            for n in c:  # prime: no literal can go
                assert not e.implies(e.cube({m: v for m, v in c.items() if m != n}), upper)
            others = e.disjunction(e.cube(d) for j, d in enumerate(cubes) if j != i)
            assert not e.implies(lower, others)  # irredundant


def test_dont_cares_shorten():
    e = Engine(ORDER)
    on = e.expr(_expr("a & b"))
    care = e.expr(_expr("!(a & !b)"))
    assert e.text(on, on | ~care) == "a"


def test_cubes():
    e = Engine(ORDER)
    u = e.expr(_expr("a & !b | c & d"))
    assert e.path_cube(~u) == {"a": False, "c": False}  # a complemented BDD walked correctly
    assert e.path_cube(e.false) is None and e.minimal_cube(e.false) is None
    assert e.minimal_cube(e.expr(_expr("a & !b & c | a & !b & !c"))) == {"a": True, "b": False}
    w = e.witness(u, e.expr(_expr("!c")))
    assert w == {"a": True, "b": False}
    assert cube_text(w) == "a & !b" and cube_text({}) == "1"


def test_let_exists_forall_support():
    e = Engine(ORDER)
    u = e.expr(_expr("a & b | c"))
    assert e.support(u) == ["a", "b", "c"]
    assert e.text(e.exists(["a"], u)) == "b | c"
    assert e.text(e.forall(["a"], u)) == "c"
    assert e.text(e.let({"a": "d"}, u)) == "b & d | c"
    assert e.value(u, {"a": True, "b": True, "c": False})


def test_pure_python_backend_gives_the_same_filter(monkeypatch):
    """Without the CUDD extension synth falls back to dd.autoref: same equations, same checks."""
    from dd import autoref

    from conftest import ROOT
    from synth.logic import bdd
    from synth.filter.coherence import coherence
    from synth.filter.language_check import load_filter
    from synth.filter.solve import synthesis

    f = load_filter(ROOT / "plants" / "tri.filter")
    cudd_solve, cudd_check = synthesis(f), coherence(f)
    monkeypatch.setattr(bdd, "_backend", autoref)
    assert type(Engine().bdd).__module__ == "dd.autoref"
    python_solve, python_check = synthesis(f), coherence(f)
    assert python_solve.equations == cudd_solve.equations and python_solve.chained == cudd_solve.chained
    assert python_check.as_dict() == cudd_check.as_dict()


def test_dd_loads_without_networkx_and_leaves_it_importable() -> None:
    import subprocess
    import sys

    code = ("import sys; import synth.logic.bdd as b; loaded = 'networkx' in sys.modules; "
            "import networkx; print(b.BACKEND, loaded, networkx.__name__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out[1:] == ["False", "networkx"] and out[0] in ("dd.cudd", "dd.autoref")


def test_a_cover_limit_counts_the_minato_morreale_cubes():
    """``limit`` refuses a cover by the cubes of its Minato–Morreale form (a probe may stop
    early, the answer is the same): refused below some k, given unchanged from k on."""
    from synth.logic.bdd import CoverTooLarge

    rng = random.Random(11)
    for _ in range(20):
        e = Engine(ORDER)
        lower = e.expr(_expr(_random_text(rng)))
        upper = lower | e.expr(_expr(_random_text(rng)))
        full = e.cover(lower, upper)
        refused = []
        for k in range(len(full) + 8):
            try:
                assert e.cover(lower, upper, k) == full
                refused.append(False)
            except CoverTooLarge as too_large:
                assert too_large.limit == k
                refused.append(True)
        assert refused == sorted(refused, reverse=True) and not refused[-1]  # monotonic
        assert refused.index(False) >= len(full)
