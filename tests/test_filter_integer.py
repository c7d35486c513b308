"""Integer observers (issue 23): ``observer cpt : 0..3`` and comparisons ``cpt >= 2``,
``cpt^-1 <> cpt``. The palletizer of seed 001 (``tests/data/filter/palletizer.filter``) is
checked and solved exactly; its ``filter st`` block, run by synth's ST interpreter (and
compiled by MATIEC's iec2c when it is installed), agrees with ``filter run`` and with a truth
table written by hand on every combination of requests and inputs × every value of ``cpt``
× every previous value. Every mistake is located."""

from __future__ import annotations

import itertools
import re
import shutil
from pathlib import Path

import pytest

from conftest import ROOT
from iec2c import CompiledProgram, find_iec2c
from synth.codegen.filter_st import FilterBlock, filter_block
from synth.codegen.interpreter.machine import load_st
from synth.codegen.program import StProgram
from synth.errors import InputError
from synth.filter.cycle import Algorithm, FilterCycle, Mode
from synth.filter.language import IntegerObserver
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.model import functions
from synth.filter.run import Row, read_trace, run, run_trace
from synth.logic.bdd import Engine
from synth.filter.solve import synthesis

PALLETIZER = ROOT / "tests" / "data" / "filter" / "palletizer.filter"
BOOLS = ("R_push", "R_lift", "ready", "top")


def _trace() -> str:
    """Every previous value p × every combination of requests and inputs × every value c:
    a cycle with cpt = p (nothing requested), then the combination with cpt = c."""
    lines = [",".join((*BOOLS, "cpt"))]
    for p in range(4):
        for combo in itertools.product("01", repeat=len(BOOLS)):
            for c in range(4):
                lines += [",".join(("0",) * len(BOOLS) + (str(p),)), ",".join((*combo, str(c)))]
    return "\n".join(lines) + "\n"


def _truth_table(values: dict[str, bool], cpt: int, before: int) -> tuple[bool, bool]:
    """The filter by hand, from the constraints read as integers: lift when asked, a layer on
    the pallet, the count settled and not at the top; push when asked, ready, the pallet not
    full and not lifting (BOTH keeps lift)."""
    lift = values["R_lift"] and cpt >= 1 and before == cpt and not values["top"]
    push = values["R_push"] and values["ready"] and cpt != 3 and not lift
    return push, lift


def _inputs(block: FilterBlock, row: Row) -> dict[str, bool | int]:
    """The block's inputs on a row: the Booleans, and cpt as an integer."""
    return {n: v for n, v in row.values if n in block.inputs} | dict(row.numbers)


def test_the_palletizer_is_checked(cli) -> None:
    code, out, _ = cli("filter", "check", PALLETIZER)
    assert code == 0
    assert out.splitlines() == ["P1 on push: holds", "P1 on lift: holds", "P2: holds: GO is acyclic",
                                "P3 on push: holds", "P3 on lift: holds", "P4 on push: holds", "P4 on lift: holds",
                                "pair on BOTH: holds", "consistency: holds"]
    f = load_filter(PALLETIZER)
    assert f.integers == (IntegerObserver("cpt", 0, 3),)
    assert f.observer_names == ("cpt_b0", "cpt_b1")
    assert [s.expr.text() for s in f.safeties[:3]] == ["push & cpt = 3", "lift & !(cpt >= 1)", "lift & cpt^-1 <> cpt"]


def test_the_palletizer_is_solved_exactly(cli) -> None:
    code, out, _ = cli("filter", "solve", PALLETIZER)
    assert code == 0
    assert out.splitlines() == [
        "equation lift = R_lift & !top & (cpt^-1 = 2 & cpt = 2 | cpt^-1 = 1 & cpt = 1 | cpt^-1 = 3 & cpt = 3)",
        "equation push = R_push & cpt <= 2 & ready & !lift"]


def test_block_run_and_truth_table_agree(tmp_path: Path) -> None:
    f = load_filter(PALLETIZER)
    trace = tmp_path / "all.csv"
    trace.write_text(_trace(), encoding="utf-8")
    ran = run_trace(f, str(trace))
    assert len(ran.rows) == 2 * 4 * 16 * 4 and ran.coherent
    block = filter_block(f)
    assert block.inputs == ("R_push", "R_lift", "ready", "top", "cpt")
    assert "    cpt : INT; (* integer observer 0..3 *)" in block.text
    assert "    cpt_1 : INT; (* cpt at the previous cycle *)" in block.text
    fb = load_st(block.text, "palletizer.st").instance(block.name)
    before = 0
    counts = [0, 0]
    for n, (row, result) in enumerate(zip(ran.rows, ran.results)):
        cpt = dict(row.numbers)["cpt"]
        expected = _truth_table(dict(row.values), cpt, before)
        fb.cycle(_inputs(block, row))
        assert result.outputs == expected, f"cycle {n + 1}"
        assert (fb["push"], fb["lift"]) == expected, f"cycle {n + 1}"
        counts = [c + int(v) for c, v in zip(counts, expected)]
        before = cpt
    assert counts == [46, 12]  # both outputs are written, and often corrected


@pytest.mark.skipif(find_iec2c() is None or shutil.which("gcc") is None,
                    reason="MATIEC's iec2c (and gcc) are not on PATH")
def test_the_compiled_block_is_filter_run(tmp_path: Path) -> None:
    f = load_filter(PALLETIZER)
    cycle = FilterCycle(f)
    rows = read_trace(_trace(), "all.csv", cycle.reads, f.integers)
    block = filter_block(f)
    plc = CompiledProgram(StProgram(block.text, block.name, (), (block.pou,)), tmp_path, pou=block.name)
    try:
        for n, (row, result) in enumerate(zip(rows, run(cycle, rows))):
            plc.cycle(_inputs(block, row))
            assert (plc["push"], plc["lift"]) == result.outputs, f"cycle {n + 1}"
            assert plc.number("cpt_1") == dict(row.numbers)["cpt"]
    finally:
        plc.close()


@pytest.mark.parametrize("mode", list(Mode))
def test_the_loop_block_is_filter_run(mode: Mode) -> None:
    """With the loop, the counter ``Cpt`` of the block takes the name: ``layers`` here."""
    text = PALLETIZER.read_text(encoding="utf-8").replace("cpt", "layers")
    f = parse_filter(text, "layers.filter")
    cycle = FilterCycle(f, Algorithm.LOOP, mode)
    head = _trace().replace("cpt", "layers")
    if mode is Mode.BLOCKING:
        lines = head.splitlines()
        head = "\n".join([lines[0] + ",Ack"] + [line + f",{k % 3 == 0:d}" for k, line in enumerate(lines[1:])]) + "\n"
    rows = read_trace(head, "all.csv", cycle.reads, f.integers)
    block = filter_block(f, Algorithm.LOOP, mode)
    fb = load_st(block.text, f"layers_{mode}.st").instance(block.name)
    blocked = 0
    for n, (row, result) in enumerate(zip(rows, run(cycle, rows))):
        fb.cycle(_inputs(block, row))
        assert (fb["push"], fb["lift"], fb["Fallback"]) == (*result.outputs, result.fallback), f"cycle {n + 1}"
        if mode is Mode.BLOCKING:
            assert fb["Blocked"] == result.blocked
            blocked += result.blocked
    assert blocked == (0 if mode is Mode.SUPERVISOR else 275)


def test_cpt_clashes_with_the_loop_counter(cli) -> None:
    code, out, err = cli("filter", "st", PALLETIZER, "--algorithm", "loop")
    assert code == 2 and out == ""
    assert err.splitlines()[0] == (f"{PALLETIZER}:5:10: error: cannot write the filter as Structured Text: "
                                   "cpt is a name the generated block needs for itself (Cpt)")


def test_bits_are_decoded_when_an_equation_reads_them() -> None:
    """``n : 1..5`` has 3 bits (the code n - 1); ``n`` odd (code even) is no interval: the
    equation reads a bit, which the block decodes."""
    f = parse_filter("outputs o\nobserver n : 1..5\nsafety S: o & !(n = 1 | n = 3 | n = 5)", "odd.filter")
    assert synthesis(f).equations == {"o": "R_o & !n_b0"}
    block = filter_block(f)
    body = block.text.split("END_VAR\n")[-1]
    assert body.splitlines()[:5] == ["(* the integer observers' bits *)", "n_b0 := (n - 1) MOD 2 = 1;",
                                     "n_b1 := ((n - 1) / 2) MOD 2 = 1;", "n_b2 := ((n - 1) / 4) MOD 2 = 1;",
                                     "o := R_o AND NOT n_b0;"]
    fb = load_st(block.text, "odd.st").instance(block.name)
    for n in range(1, 6):
        fb.cycle({"R_o": True, "n": n})
        assert fb["o"] is (n % 2 == 1)


def test_the_domain_assumption_hides_illegal_codes(cli, tmp_path: Path) -> None:
    """Codes 5..7 of ``n : 0..4`` are no value: constraints met only there are no inconsistency."""
    text = "outputs o\nobserver n : {}\nsafety A: o & n_b2 & n_b0\nsafety B: !o & n_b2 & n_b0\n"
    f = tmp_path / "d.filter"
    f.write_text(text.format("0..4"))
    code, out, _ = cli("filter", "check", f)
    assert code == 0 and out.splitlines()[-1] == ("consistency: holds under assumptions: fails only outside "
                                                  "the assumptions, e.g. when n_b0 & n_b2")
    m = functions(parse_filter(text.format("0..4"), "d.filter"))
    assert Engine.text(m.engine, m.assumed) == "!n_b0 & !n_b1 | !n_b2"  # code <= 4, in bits
    assert m.engine.text(m.assumed) == "1"  # over the legal values
    f.write_text(text.format("0..7"))
    code, out, _ = cli("filter", "check", f)
    assert code == 1
    assert out.splitlines()[-1] == "consistency: violated: no output vector satisfies A, B when n_b0 & n_b2"


def test_a_past_comparison_reads_the_domain_of_the_past() -> None:
    f = parse_filter("outputs o\nobserver n : 0..2\nsafety S: o & n^-1 < n", "p.filter")
    m = functions(f)
    assert Engine.text(m.engine, m.assumed) == "!n_b0^-1 & (!n_b0 | !n_b1) | !n_b1^-1 & (!n_b0 | !n_b1)"
    assert synthesis(f).equations == {"o": "R_o & (n^-1 = 1 & n <= 1 | n = 0 | n^-1 = 2)"}  # n^-1 >= n
    g = parse_filter("outputs o\nobserver n : 0..2\nsafety S: o & n = 1", "q.filter")
    mg = functions(g)
    assert Engine.text(mg.engine, mg.assumed) == "!n_b0 | !n_b1"  # n is not read at t-1


def _error(text: str) -> str:
    with pytest.raises(InputError) as info:
        parse_filter(text, "x.filter")
    e = info.value
    return f"{e.location}: {e.message}" + "".join(f" | {s}" for s in e.suggestions)


@pytest.mark.parametrize(("text", "message"), [
    ("inputs top\noutputs o\nsafety S: o & top >= 1",
     "x.filter:3:15: 'top' is a Boolean input: read it as a level (top or !top), not in the comparison top >= 1"),
    ("outputs o\nobserver cpt : 0..3\nsafety S: o & cp >= 1",
     "x.filter:3:15: unknown variable 'cp' in the comparison cp >= 1 in constraint S | cpt"),
    ("outputs o\nobserver cpt : 0..3\nsafety S: o & cpt = 4",
     "x.filter:3:15: the constant 4 in cpt = 4 is outside the range 0..3 of 'cpt'"),
    ("outputs o\nobserver cpt : 0..3\nsafety S: o & cpt",
     "x.filter:3:15: 'cpt' is not a Boolean level: 'cpt' is an integer observer (0..3)"),
    ("outputs o\nobserver cpt : 0..3\nsafety S: o & !cpt^-1",
     "x.filter:3:16: 'cpt^-1' is not a Boolean level: 'cpt' is an integer observer (0..3)"),
    ("outputs o\nobserver cpt : 0..3\nsafety S: o & ↑cpt",
     "x.filter:3:16: the edge ↑cpt is not a Boolean level: 'cpt' is an integer observer (0..3)"),
    ("outputs o\nobserver cpt : 0..3\nsafety S: cpt < o",
     "x.filter:3:11: 'o' is a Boolean output: read it as a level (o or !o), not in the comparison cpt < o"),
    ("outputs o\nobserver cpt : 3..0", "x.filter:2:16: the range 3..0 of 'cpt' is empty"),
    ("outputs o\nobserver cpt : 0..1024", "x.filter:2:16: the range 0..1024 of 'cpt' has more than 1024 values"),
    ("inputs cpt_b1\noutputs o\nobserver cpt : 0..3",
     "x.filter:1:8: 'cpt_b1' is bit 1 of the integer observer cpt; it cannot be declared"),
    ("outputs o\nobserver cpt : 0..3\nobserver P := cpt >= 2\nsafety S: o & P",
     "x.filter:3:15: observer P cannot read the integer observer 'cpt' at t"),
    ("outputs o\nobserver cpt : 0..3\nsafety S: o & cbt",
     "x.filter:3:15: unknown variable 'cbt' in constraint S | cpt"),
])
def test_mistakes_are_located(text: str, message: str) -> None:
    assert _error(text) == message


def test_the_cli_reports_a_located_error(cli, tmp_path: Path) -> None:
    f = tmp_path / "bad.filter"
    f.write_text("outputs o\nobserver cpt : 0..3\nsafety S: o & cpt >= 7\n")
    code, out, err = cli("filter", "check", f)
    assert code == 2 and out == ""
    assert err.splitlines()[:3] == [f"{f}:3:15: error: the constant 7 in cpt >= 7 is outside the range 0..3 of 'cpt'",
                                    "  3 | safety S: o & cpt >= 7", "    |               ^~~~~~~~"]


def test_run_reads_an_integer_column(cli, tmp_path: Path) -> None:
    trace = tmp_path / "t.csv"
    trace.write_text("R_push,R_lift,ready,top,cpt\n1,1,1,0,1\n0,1,0,0,1\n1,0,1,0,3\n")
    code, out, _ = cli("filter", "run", PALLETIZER, "--trace", trace)
    assert code == 0
    assert out.splitlines() == [
        "outputs: push, lift   (algebraic, supervisor)",
        "1  Y: {ready, cpt_b0}  R: 11 -> O: 10  violated: SETTLED, BOTH  corrected: lift",
        "2  Y: {cpt_b0}  R: 01 -> O: 01",
        "3  Y: {ready, cpt_b0, cpt_b1}  R: 10 -> O: 00  violated: FULL  corrected: push",
        "3 cycles, 2 corrected, 0 fallback, 0 outside the care set: coherent"]
    trace.write_text("R_push,R_lift,ready,top,cpt\n1,1,1,0,4\n")
    code, out, err = cli("filter", "run", PALLETIZER, "--trace", trace)
    assert code == 2 and err.splitlines()[0] == f"{trace}:2:9: error: an integer in 0..3 expected for cpt, got '4'"
    trace.write_text("R_push,R_lift,ready,top,cpt_b0\n")
    code, out, err = cli("filter", "run", PALLETIZER, "--trace", trace)
    assert code == 2 and err.splitlines()[0] == f"{trace}:1:25: error: unknown column 'cpt_b0'"


def _doc_section() -> str:
    text = (ROOT / "docs" / "filter.md").read_text(encoding="utf-8")
    return text.split("## Integer observers\n", 1)[1].split("\n## ", 1)[0]


def test_the_doc_example_is_the_data_file_and_solves_as_printed(cli) -> None:
    blocks = re.findall(r"```\n(.*?)```", _doc_section(), re.S)
    assert blocks[0] == "".join(line + "\n" for line in PALLETIZER.read_text(encoding="utf-8").splitlines()
                                if not line.startswith("#"))
    command, *printed = blocks[1].splitlines()
    assert command == "$ synth filter solve tests/data/filter/palletizer.filter"
    code, out, _ = cli("filter", "solve", PALLETIZER)
    assert code == 0 and out.splitlines() == printed
