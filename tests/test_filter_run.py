"""`synth filter run` and the cycle evaluator (synth/filter/cycle.py): the loop examples
A, B, C of docs/filter.md, "The correction loop" (specified and literal loops), memory and edges, blocking mode,
the care set, the CSV trace's located errors, and the lanes (many cycles at once)
agreeing with single cycles."""

from __future__ import annotations

import json
import random

import pytest

from conftest import ROOT
from schemas import assert_valid
from synth.errors import InputError
from synth.filter.cycle import ACK, Algorithm, FilterCycle, Memory, Mode
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.run import read_trace, run
from synth.filter.solve import synthesis

PLANTS = ROOT / "plants"
DATA = ROOT / "tests" / "data" / "filter"


def _one(name: str, g: tuple[int, ...], literal: bool = False, algorithm: Algorithm = Algorithm.LOOP):
    f = load_filter(PLANTS / f"{name}.filter")
    c = FilterCycle(f, algorithm, literal=literal)
    return c.step(c.initial(), {r: bool(v) for r, v in zip(f.requests, g)})[0]


def _bits(v) -> str:
    return "".join(str(int(b)) for b in v)


@pytest.mark.parametrize("name, g, specified, literal", [
    # name, requests, (iterations, O, fallback) specified, the same for the literal published code
    ("loop_a", (1, 1), (["11", "10"], "10", False), (["11", "10"], "00", True)),
    ("loop_b", (1, 1, 1), (["111", "101", "100"], "100", False), (["111", "101", "110"], "000", True)),
    ("loop_c", (1, 1, 1), (["111", "101", "111"], "000", True), (["111", "101", "111"], "000", True)),
    ("loop_no_cycle", (1, 1), (["11", "10", "00"], "00", False), (["11", "10", "01"], "00", True)),
])
def test_loop_examples(name, g, specified, literal):
    for lit, (iterations, outputs, fallback) in ((False, specified), (True, literal)):
        r = _one(name, g, lit)
        assert ([_bits(si) for si in r.iterations], _bits(r.outputs), r.fallback) == (iterations, outputs, fallback)


def test_algebraic_examples():
    """The synthesis relieves the same examples without iterating (C included: its Sim order decides)."""
    assert _bits(_one("loop_a", (1, 1), algorithm=Algorithm.ALGEBRAIC).outputs) == "10"
    assert _bits(_one("loop_b", (1, 1, 1), algorithm=Algorithm.ALGEBRAIC).outputs) == "100"
    r = _one("loop_c", (1, 1, 1), algorithm=Algorithm.ALGEBRAIC)
    assert (_bits(r.outputs), r.fallback, r.outside_care, r.iterations) == ("100", False, False, ())
    assert (r.violated, r.corrections, r.unsafe) == (("K1",), ("o2", "o3"), ())


def test_loop_needs_priorities():
    f = parse_filter("outputs o1, o2\nsafety K: o1 & o2", "k.filter")
    with pytest.raises(InputError, match="K is a combined constraint without priority"):
        FilterCycle(f, Algorithm.LOOP)
    assert FilterCycle(f).step(FilterCycle(f).initial(), {"R_o1": True, "R_o2": True})[0].outputs == (True, False)


def test_memory_and_edges():
    """x^-1 starts FALSE and is the last cycle's input / produced output; ↑o uses the produced o."""
    f = parse_filter("inputs b, i\noutputs o\nsafety S: ↑b & o\nsafety T: ↑o & i", "e.filter")
    c = FilterCycle(f)
    assert c.remembered == ("b", "i", "o") and c.used == ("b", "o")
    memory = c.initial()
    seen = []
    for b, i, r in [(1, 0, 1), (1, 0, 1), (0, 1, 0), (0, 1, 1), (0, 0, 1), (0, 1, 1)]:
        result, memory = c.step(memory, {"b": bool(b), "i": bool(i), "R_o": bool(r)})
        seen.append((int(result.outputs[0]), result.violated))
    # 1: ↑b forces o=0; 2: no edge; 3: o falls; 4: i forbids the rise; 5: rises; 6: stays on under i
    assert seen == [(0, ("S",)), (1, ()), (0, ()), (0, ("T",)), (1, ()), (1, ())]
    assert memory == Memory((False, True, True), False)


def test_blocking_mode():
    """A violation latches Blocked (g1 = 0) until Ack; Ack and a new violation in one cycle: blocked."""
    f = load_filter(PLANTS / "loop_a.filter")
    c = FilterCycle(f, Algorithm.LOOP, Mode.BLOCKING)
    assert c.reads == ("R_o1", "R_o2", ACK)
    memory, seen = c.initial(), []
    for r1, r2, ack in [(1, 0, 0), (1, 1, 0), (1, 0, 0), (1, 0, 1), (1, 1, 1), (0, 1, 1)]:
        result, memory = c.step(memory, {"R_o1": bool(r1), "R_o2": bool(r2), ACK: bool(ack)})
        seen.append((_bits(result.outputs), result.blocked))
    assert seen == [("10", False), ("00", True), ("00", True), ("10", False), ("00", True), ("01", False)]


def test_outside_care_and_unsafe():
    """Y outside the care set: an assumption broken, or no safe vector at all."""
    f = parse_filter("inputs i, j\noutputs o\nassume !j\nsafety S: i & o\nsafety T: i & !o", "c.filter")
    c = FilterCycle(f)
    out = [c.step(c.initial(), {"i": bool(i), "j": bool(j), "R_o": True})[0] for i, j in ((0, 0), (0, 1), (1, 0))]
    assert [(r.outside_care, _bits(r.outputs)) for r in out] == [(False, "1"), (True, "1"), (True, "1")]
    assert out[2].unsafe == ("S",) and out[0].unsafe == ()


def test_lanes_agree_with_single_cycles():
    """All 2^7 request vectors at once (as verify --any-control) equal one cycle each, for
    both algorithms on the box-sorting filter, at random inputs and memories."""
    f = load_filter(PLANTS / "tri.filter")
    rnd = random.Random(11)
    for algorithm in (Algorithm.ALGEBRAIC, Algorithm.LOOP):
        c = FilterCycle(f, algorithm)
        for _ in range(6):
            fixed = {n: rnd.random() < 0.4 for n in c.reads if n not in c.requests}
            memory = Memory(tuple(rnd.random() < 0.3 for _ in c.remembered))
            lanes = c.lanes(memory, fixed, c.requests)
            for j in rnd.sample(range(lanes.count), 12):
                values = dict(fixed, **{r: bool((j >> i) & 1) for i, r in enumerate(c.requests)})
                single, after = c.step(memory, values)
                many, after_many = lanes.lane(j)
                assert (many.outputs, many.iterations, many.fallback, many.violated, many.outside_care) == (
                    single.outputs, single.iterations, single.fallback, single.violated, single.outside_care)
                assert after == after_many


def test_algebraic_is_the_synthesis_on_the_care_set():
    f = load_filter(PLANTS / "tri.filter")
    s = synthesis(f)
    c = FilterCycle(s.functions)
    e = s.functions.engine
    rnd = random.Random(3)
    checked = 0
    while checked < 40:
        point = {n: rnd.random() < 0.4 for n in e.names if n not in f.outputs}
        if not e.value(s.care, point):
            continue
        memory = Memory(tuple(point.get(n + "^-1", False) for n in c.remembered))
        r, _ = c.step(memory, {n: point[n] for n in c.reads})
        assert r.outputs == tuple(e.value(s.output(o), point) for o in f.outputs)
        assert not r.outside_care and r.unsafe == ()
        checked += 1


# ---------------------------------------------------------------- the CSV trace and the command

def test_cli_run_loop_c(cli):
    code, out, err = cli("filter", "run", PLANTS / "loop_c.filter", "--trace", DATA / "loop_c.csv", "--algorithm", "loop")
    assert code == 1
    assert out.splitlines() == [
        "outputs: o1, o2, o3   (loop, supervisor)",
        "1  Y: {}  R: 111 -> O: 000  violated: K1  corrected: o1, o2, o3  FALLBACK",
        "   iterations: 111 101 111",
        "2  Y: {}  R: 101 -> O: 000  violated: K2  corrected: o1, o3  FALLBACK",
        "   iterations: 101 111 111",
        "3  Y: {}  R: 000 -> O: 000",
        "   iterations: 000",
        "3 cycles, 2 corrected, 2 fallback, 0 outside the care set",
    ]
    code, out, _ = cli("filter", "run", PLANTS / "loop_c.filter", "--trace", DATA / "loop_c.csv", "--json")
    data = json.loads(out)
    assert_valid("filter_run", data)
    assert code == 0 and data["coherent"] and data["algorithm"] == "algebraic"
    # cycle 2: the priority of K2 (o2:=1) is a leading Min criterion, so o1 gives way
    assert [c["outputs"] for c in data["cycles"]] == [{"o1": 1, "o2": 0, "o3": 0}, {"o1": 0, "o2": 1, "o3": 1},
                                                      {"o1": 0, "o2": 0, "o3": 0}]


def test_trace_errors(cli, tmp_path):
    reads = ("i", "R_o1", "R_o2")
    with pytest.raises(InputError) as info:
        read_trace("R_o1, i\n1,0\n", "cycles.csv", reads)
    assert str(info.value.location) == "cycles.csv:1:8" and info.value.message == "missing column R_o2"
    with pytest.raises(InputError) as info:
        read_trace("i,R_o1,R_o2\n0,1,1\n1, 0 ,x\n", "cycles.csv", reads)
    assert (str(info.value.location), info.value.message) == ("cycles.csv:3:7", "0/1 expected for R_o2, got 'x'")
    with pytest.raises(InputError) as info:
        read_trace("# a comment\ni,R_o,R_o2\n", "cycles.csv", reads)
    assert (str(info.value.location), info.value.suggestions) == ("cycles.csv:2:3", ("R_o2", "R_o1"))
    with pytest.raises(InputError) as info:
        read_trace("i,R_o1,R_o2\n0,1\n", "cycles.csv", reads)
    assert (str(info.value.location), info.value.message) == ("cycles.csv:2:4", "2 cells, the header has 3")
    rows = read_trace("R_o2,i,R_o1\n\n1,0,1\n", "cycles.csv", reads)
    assert [(r.line, r.value("R_o2"), r.value("i")) for r in rows] == [(3, True, False)]
    bad = tmp_path / "cycles.csv"
    bad.write_text("R_o1,R_o2\n1,2\n")
    code, out, err = cli("filter", "run", PLANTS / "loop_a.filter", "--trace", bad)
    assert code == 2 and out == ""
    assert err.splitlines()[:3] == [f"{bad}:2:3: error: 0/1 expected for R_o2, got '2'", "  2 | 1,2", "    |   ^"]
    code, _, err = cli("filter", "run", PLANTS / "loop_a.filter", "--trace", bad, "--mode", "blocking")
    assert code == 2 and err.startswith(f"{bad}:1:10: error: missing column Ack")


def test_run_helper_uses_fresh_memory():
    f = parse_filter("inputs b\noutputs o\nsafety S: ↑b & o", "e.filter")
    c = FilterCycle(f)
    rows = read_trace("b,R_o\n1,1\n1,1\n", "t.csv", c.reads)
    assert [r.outputs for r in run(c, rows)] == [(False,), (True,)]
    assert [r.outputs for r in run(c, rows)] == [(False,), (True,)]


def test_algebraic_is_the_printed_equations_everywhere():
    """Outside the care set too, the outputs are those of the chained equations `solve`
    prints and the function block implements, read back as `equation` lines (substituted
    in dependency order, as the block assigns them). Before issue 22's "verified =
    deployed" this test read the flat Y-only equations, which differ off the care set."""
    from synth.filter.model import equation_functions, functions

    text = (PLANTS / "tri.filter").read_text()
    s = synthesis(parse_filter(text, "tri.filter"))
    printed = parse_filter(text + "".join(f"\nequation {o} = {t}" for o, t in s.chained.items()), "tri.filter")
    m = functions(printed)
    eqs = equation_functions(m)
    c = FilterCycle(s.functions)
    rnd = random.Random(5)
    outside = 0
    for _ in range(60):
        point = {n: rnd.random() < 0.5 for n in m.engine.names if n not in printed.outputs}
        memory = Memory(tuple(point.get(n + "^-1", False) for n in c.remembered))
        r, _ = c.step(memory, {n: point[n] for n in c.reads})
        assert r.outputs == tuple(m.engine.value(eqs[o], point) for o in printed.outputs)
        outside += r.outside_care
    assert 0 < outside < 60  # both sides of the care set were visited
