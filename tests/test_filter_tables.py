"""The filter on truth tables, past the size of what the symbolic chain decides against its
order (``synth.filter.solve``'s ``TABLES_SIZE``, lowered here so that small filters take that form): what ``solve`` says, the
block ``filter st`` writes (compiled by MATIEC's ``iec2c`` and gcc, cycle by cycle equal to
the synthesis's functions and to ``synth.filter.local``'s model, past values included), and
``filter run``'s refusal."""

from __future__ import annotations

import random
import shutil
import sys

import pytest

from conftest import ROOT
from iec2c import CompiledProgram, find_iec2c
from schemas import assert_valid
from synth.codegen.filter_st import filter_block
from synth.codegen.program import StProgram
from synth.errors import LimitExceeded
from synth.filter import local, narrowing
from synth.filter.block import algebraic_equations
from synth.filter.cycle import Algorithm, FilterCycle
from synth.filter.language import Filter, Sense
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.model import functions
from synth.filter.solve import TABLES_SIZE, criteria, synthesis
from synth.logic.past import pre_name
from synth.output.filter_text import synthesis_json, synthesis_text

sys.path.insert(0, str(ROOT / "bench"))
from filter_scale import FAMILIES, grid_edges_filter, ring_filter  # noqa: E402

BUNDLED = sorted([*ROOT.glob("plants/*.filter"), *ROOT.glob("tests/data/**/*.filter"), *ROOT.glob("lines/**/*.filter")])

NOTE = ("the chain of narrowings decides outputs against its order (size 41 over the limit of 40; 2 outputs "
        "carried back across one cut): the filter is its chain run on "
        "truth tables each cycle (16 bags, 118 entries; filter st writes it); no equations, the criteria's effects "
        "not decided")


def _grid() -> tuple[object, object]:
    f = parse_filter(grid_edges_filter(16), "grid_edges.filter")
    return f, synthesis(f, tables_size=40)


def test_past_the_limit_solve_prints_the_criteria_and_says_why():
    f, s = _grid()
    assert s.plan is not None and s.plan.entries == 118
    assert s.functional and s.consistent and s.notes == [NOTE] and s.warnings == []
    text = synthesis_text(s).splitlines()
    assert len(text) == 38
    assert text[0] == "criterion 1: minimize R_o1_1 & R_o1_2 & !o1_1  (priority of H1_1)"
    assert text[-1] == "criterion 38: maximize R_o8_2 & o8_2 | !R_o8_2 & !o8_2  (implicit sim o8_2)"
    j = synthesis_json("grid_edges.filter", s)
    assert j["form"] == {"kind": "tables", "bags": 16, "width": 3, "entries": 118}
    assert j["equations"] == {} and j["chained"] == {"order": [], "equations": {}}
    assert {(c["narrows"], c["effect"]) for c in j["criteria"]} == {(None, None)}
    assert_valid("filter_solve", j)
    assert synthesis(f, tables_size=41).plan is None  # at the limit: the equations, as before
    assert synthesis(f).plan is None and TABLES_SIZE > 41


def _against(f: Filter) -> tuple[int, int]:
    """``narrowing.against`` on the partition ``solve`` lays out: the size the form is decided by, and the most
    outputs carried back across one cut."""
    m = functions(f)
    goods = [m.engine.expr(c.expr) if c.sense is Sense.MAX else ~m.engine.expr(c.expr) for c in criteria(f)]
    return narrowing.against(narrowing.layout(m, goods), goods)


@pytest.mark.parametrize("case, size", [("ring_32", (31, 1)), ("chain_256", (0, 0)), ("grid_64", (0, 0)),
                                        ("grid_edges_24", (133, 3)), ("grid_edges_32", (341, 4)),
                                        ("grid_edges_40", (765, 5)), ("grid_edges_64", (4805, 8))])
def test_the_form_is_decided_on_the_filter(case, size):
    """The bench families take the form they took when the chain's BDD lookups decided (10^7, docs/performance.md,
    "Session 29"): equations up to grid_edges 8 × 4 (341: at most 4 outputs carried back across a cut), tables
    from 8 × 5 (765) on; the rings carry one output back, the chains and grids none."""
    family, _, n = case.rpartition("_")
    assert _against(parse_filter(FAMILIES[family](int(n)), f"{case}.filter")) == size
    assert (size[0] > TABLES_SIZE) == (case in ("grid_edges_40", "grid_edges_64"))


def test_grid_edges_8_by_5_is_on_tables():
    """8 × 5, the first of the family past the limit: no symbolic chain runs (8 × 4's is what its equations cost,
    4.6 M BDD lookups; 8 × 5's would be 21 M), the plan comes from the layout alone."""
    s = synthesis(parse_filter(grid_edges_filter(40), "grid_edges_40.filter"))
    assert s.plan is not None and (len(s.plan.bags), s.plan.width, s.plan.entries) == (40, 6, 1806)
    assert s.notes == ["the chain of narrowings decides outputs against its order (size 765 over the limit of 500; "
                       "5 outputs carried back across one cut): the filter is its chain run on truth tables each "
                       "cycle (40 bags, 1806 entries; filter st writes it); no equations, the criteria's effects not "
                       "decided"]


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.name)
def test_bundled_filters_keep_their_equations(path):
    f = load_filter(path)
    s = synthesis(f)
    assert s.plan is None and s.chained
    assert _against(f)[0] <= 3


def test_past_the_limit_every_output_needs_its_sim():
    f = parse_filter("outputs a, b\nsafety K: a & b keep a\nmaximize sim a\n", "partial.filter")
    with pytest.raises(LimitExceeded, match="b has no similarity criterion"):
        synthesis(f, tables_size=-1)


def test_filter_run_evaluates_the_tables():
    """``filter run`` (and the explicit closed loop) evaluate the block on tables: the same outputs as the
    equations of the synthesis below the limit, cycle after cycle (past values included)."""
    f, s = _grid()
    tables, equations = FilterCycle(s, Algorithm.ALGEBRAIC), FilterCycle(f, Algorithm.ALGEBRAIC)
    assert tables.plan is not None and equations.plan is None and tables.used == equations.used
    rng = random.Random(16)
    rows = [{n: rng.random() < 0.5 for n in tables.reads} for _ in range(200)]
    mine, theirs = tables.initial(), equations.initial()
    on = 0
    for values in rows:
        (a, mine), (b, theirs) = tables.step(mine, values), equations.step(theirs, values)
        assert a == b
        on += sum(a.outputs)
    assert on == 516
    with pytest.raises(LimitExceeded, match="it has no equations"):
        algebraic_equations(s)


@pytest.mark.slow  # 5-10 s a case: iec2c and gcc, then the model at each of 300 cycles
@pytest.mark.skipif(find_iec2c() is None or shutil.which("gcc") is None, reason="MATIEC's iec2c (and gcc) are not on PATH")
@pytest.mark.parametrize("case", ["grid_edges_16", "ring_4"])
def test_the_compiled_tables_block_is_the_synthesis(case, tmp_path):
    f = parse_filter(grid_edges_filter(16) if case == "grid_edges_16" else ring_filter(4), f"{case}.filter")
    solved = synthesis(f)  # the equations: the oracle
    s = synthesis(f, tables_size=-1)
    assert solved.plan is None and s.plan is not None
    block = filter_block(f, synthesis=s)
    plc = CompiledProgram(StProgram(block.text, block.name, (), (block.pou,)), tmp_path, pou=block.name)
    e, oracle, rng = s.functions.engine, solved.functions.engine, random.Random(case)
    previous = {n: False for n in (*f.inputs, *f.outputs)}
    seen = {"cycles": 0, "outside the care set": 0, "outputs on": 0}
    try:
        for _ in range(300):
            values = {n: rng.random() < 0.5 for n in (*f.requests, *f.inputs)}
            point = {**values, **{pre_name(n): v for n, v in previous.items()}}
            plc.cycle(values)
            got = {o: plc[o] for o in f.outputs}
            model = local.run(s.plan, local.Booleans(e, point))
            assert got == model.ones
            if oracle.value(solved.care, point):
                assert got == {o: oracle.value(solved.outputs[o], point) for o in f.outputs}
            else:
                seen["outside the care set"] += 1
                assert not any(got.values())
            seen["cycles"] += 1
            seen["outputs on"] += sum(got.values())
            previous = {**{n: values[n] for n in f.inputs}, **got}
    finally:
        plc.close()
    assert seen == {"grid_edges_16": {"cycles": 300, "outside the care set": 0, "outputs on": 781},
                    "ring_4": {"cycles": 300, "outside the care set": 0, "outputs on": 296}}[case]
