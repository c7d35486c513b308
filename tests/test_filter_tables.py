"""The filter on truth tables, past the size of what the symbolic chain decides against its
order (``synth.filter.solve``'s ``TABLES_SIZE``, lowered here so that small filters take that form): what ``solve`` says, the
block ``filter st`` writes (a fixed loop nest over constant tables; compiled by MATIEC's
``iec2c`` and gcc, directly and through Beremiz's generator from ``filter st --xml``, cycle by
cycle equal to the synthesis's functions and to ``synth.filter.local``'s model, past values
included), and ``filter run``'s refusal."""

from __future__ import annotations

import random
import re
import shutil
import sys

import pytest

from beremiz import find_beremiz
from conftest import ROOT
from iec2c import CompiledProgram, find_iec2c
from schemas import assert_valid
from synth.codegen.filter_st import filter_block
from synth.codegen.program import StProgram
from synth.codegen.st import SectionKind
from synth.codegen.targets import Target, render
from synth.errors import InputError, LimitExceeded
from synth.filter import local, narrowing
from synth.filter.block import algebraic_equations
from synth.filter.cycle import Algorithm, FilterCycle
from synth.filter.language import Filter, Sense
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.model import functions
from synth.filter.solve import TABLES_SIZE, Synthesis, criteria, synthesis
from synth.logic.past import pre_name
from synth.output.filter_text import synthesis_json, synthesis_text

sys.path.insert(0, str(ROOT / "bench"))
from filter_scale import FAMILIES, grid_edges_filter, ring_filter  # noqa: E402
from test_sfc_beremiz import beremiz_text  # noqa: E402

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


CLASH = "inputs i, j\noutputs a, b, c\nsafety K1: a & b keep a\nsafety K2: b & c keep c\nsafety K3: !a & i\nsafety K4: a & j\n"
"""No safe vector when ``i & j``: there the block's outputs are all FALSE."""


def _filter(case: str) -> Filter:
    text = {"grid_edges_16": grid_edges_filter, "ring_4": ring_filter}.get(case)
    return parse_filter(text(16 if case == "grid_edges_16" else 4) if text else CLASH, f"{case}.filter")


def _cases(case: str) -> tuple[Filter, Synthesis, Synthesis]:
    """The filter of ``case``, its equations (the oracle) and its tables form."""
    f = _filter(case)
    solved = synthesis(f)
    s = synthesis(f, tables_size=-1)
    assert solved.plan is None and s.plan is not None
    return f, solved, s


def _drive(plc: CompiledProgram, f: Filter, solved: Synthesis, s: Synthesis, seed: str) -> dict[str, int]:
    """300 random cycles of the compiled block against the tables' model and the equations."""
    e, oracle, rng = s.functions.engine, solved.functions.engine, random.Random(seed)
    previous = {n: False for n in (*f.inputs, *f.outputs)}
    seen = {"cycles": 0, "outside the care set": 0, "outputs on": 0}
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
    return seen


SEEN = {"grid_edges_16": {"cycles": 300, "outside the care set": 0, "outputs on": 781},
        "ring_4": {"cycles": 300, "outside the care set": 0, "outputs on": 296},
        "clash": {"cycles": 300, "outside the care set": 77, "outputs on": 254}}
"""What the 300 cycles of each case saw (the same on every path to the PLC)."""


def _loop_nest(body: tuple[str, ...]) -> list[str]:
    """The statements from the bags' tables to the outputs, numbers made ``N``."""
    start = body.index("(* each bag's table from its relation's row *)")
    end = next(i for i, line in enumerate(body) if " := TabO[" in line and not line.startswith(" "))
    return [re.sub(r"\d+", "N", line) for line in body[start:end]]


def test_the_tables_are_data_and_the_loop_is_fixed():
    """The block's statements do not grow with the filter: a fixed loop nest, one row line per
    cofactor that reads the cycle's inputs, one line per output; the rest is constant data."""
    f = _filter("grid_edges_16")
    block = filter_block(f, synthesis=synthesis(f, tables_size=-1))
    body = block.pou.body
    rows = [line for line in body if line.startswith("TabR[")]
    assert len(rows) == 16 + 22 + 2 * 16  # each bag's relation once, each priority once, each sim twice
    assert rows[0] == ("TabR[1] := b1_1 AND (h1_1_1 OR NOT h1_1) OR o1_1_1 AND (h1_1_1 OR NOT h1_1); "
                       "(* bag 1's relation at o1_1=1, o1_2=0, o2_1=0 *)")
    assert rows[-1] == "TabR[165] := R_o8_2; (* criterion 38 at o8_2=1 *)"
    assert [line for line in body if " := TabO[" in line] == [f"{o} := TabO[{k}];" for k, o in enumerate(
        ["o1_1", "o1_2", "o2_1", "o2_2", "o3_1", "o3_2", "o4_1", "o4_2", "o5_1", "o5_2", "o6_1", "o6_2", "o7_1",
         "o7_2", "o8_1", "o8_2"])]
    assert not any(line.startswith("FOR") for line in body)  # MATIEC skips some one-pass FOR loops: WHILE only
    loop = _loop_nest(body)
    constant = next(x for x in block.pou.sections if x.kind is SectionKind.CONSTANT)
    assert [d.name for d in constant.declarations] == ["TabKD", "TabKM", "TabKP", "TabUR", "TabUP", "TabP",
                                                       "TabSK", "TabSU"]
    assert constant.declarations[0].init == "[0, 8, 16, 24, 32, 40, 48, 56, 64, 72, 80, 88, 96, 104, 112, 116, 118]"
    ring = _filter("ring_4")
    other = filter_block(ring, synthesis=synthesis(ring, tables_size=-1)).pou.body
    assert len(loop) == 96 and loop == _loop_nest(other)  # the same statements but for the counts of bags and steps
    assert sum(x.lstrip().startswith("WHILE") for x in loop) == 11


def test_the_plcopen_tables_block_is_valid_tc6_with_its_data_constant():
    from lxml import etree

    from tc6schema import validation_errors

    f = _filter("ring_4")
    block = filter_block(f, synthesis=synthesis(f, tables_size=-1))
    [(_, xml)] = render(Target.PLCOPEN, [block.pou], text=block.text, name=block.name, header=["test"])
    assert validation_errors(xml) == []
    ns = {"tc6": "http://www.plcopen.org/xml/tc6_0201"}
    sections = etree.fromstring(xml).findall(".//tc6:interface/tc6:localVars", ns)
    assert [(x.get("constant"), [v.get("name") for v in x.findall("tc6:variable", ns)][-1]) for x in sections] == [
        (None, "TabCut"), ("true", "TabSU")]


def test_a_filter_name_the_tables_need_is_refused():
    f = parse_filter("inputs TabVF\noutputs a, b\nsafety K: a & b & TabVF keep a\n", "clash.filter")
    with pytest.raises(InputError, match="TabVF is a name the generated block needs for itself"):
        filter_block(f, synthesis=synthesis(f, tables_size=-1))


@pytest.mark.slow  # 5-10 s a case: iec2c and gcc, then the model at each of 300 cycles
@pytest.mark.skipif(find_iec2c() is None or shutil.which("gcc") is None, reason="MATIEC's iec2c (and gcc) are not on PATH")
@pytest.mark.parametrize("case", ["grid_edges_16", "ring_4", "clash"])
def test_the_compiled_tables_block_is_the_synthesis(case, tmp_path):
    f, solved, s = _cases(case)
    assert solved.consistent is (case != "clash")
    block = filter_block(f, synthesis=s)
    plc = CompiledProgram(StProgram(block.text, block.name, (), (block.pou,)), tmp_path, pou=block.name)
    try:
        assert _drive(plc, f, solved, s, case) == SEEN[case]
    finally:
        plc.close()


@pytest.mark.slow  # about 10 s: Beremiz's generator, iec2c and gcc, then 300 cycles
@pytest.mark.skipif(find_beremiz() is None or find_iec2c() is None or shutil.which("gcc") is None,
                    reason="Beremiz (SYNTH_BEREMIZ, SYNTH_BEREMIZ_PYTHON), iec2c and gcc are not here")
def test_the_plcopen_tables_block_built_by_beremiz_is_the_synthesis(tmp_path):
    """``filter st --xml`` of the tables form opened by Beremiz, whose generator writes the
    program it hands to MATIEC; that program compiled and run equals the synthesis (on the
    ring; the grid takes the same path, tested above without Beremiz)."""
    case = "ring_4"
    f, solved, s = _cases(case)
    block = filter_block(f, synthesis=s)
    [(name, xml)] = render(Target.PLCOPEN, [block.pou], text=block.text, name=block.name, header=["test"])
    (tmp_path / name).write_bytes(xml)
    text = beremiz_text(tmp_path / name, tmp_path / "generated.st")
    assert "VAR CONSTANT" in text and "TabSU : ARRAY [0.." in text
    plc = CompiledProgram(StProgram(text, block.name, (), (block.pou,)), tmp_path / "c", pou=block.name)
    try:
        assert _drive(plc, f, solved, s, case) == SEEN[case]
    finally:
        plc.close()
