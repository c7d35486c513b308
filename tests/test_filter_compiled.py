"""Verified = deployed, on the real compiler: every bundled filter block compiled by MATIEC's
``iec2c`` and gcc (the harness of ``tests/iec2c.py``) equals ``synth filter run`` on the
same 1 000 random cycles as the interpreted block (``tests/test_filter_deployed.py``), off
the care set included. Skipped without ``iec2c`` and gcc."""

from __future__ import annotations

import shutil

import pytest

from iec2c import CompiledProgram, find_iec2c
from synth.codegen.filter_st import filter_block
from synth.codegen.program import StProgram
from synth.filter.cycle import Algorithm, FilterCycle, Mode
from synth.filter.language_check import load_filter
from synth.filter.run import run
from test_filter_deployed import CASES, ROOT, _rows, _runnable, drive

pytestmark = pytest.mark.skipif(find_iec2c() is None or shutil.which("gcc") is None,
                                reason="MATIEC's iec2c (and gcc) are not on PATH")


@pytest.mark.parametrize(("name", "algorithm", "mode"), CASES, ids=[f"{n}-{a}-{m}" for n, a, m in CASES])
def test_the_compiled_block_is_filter_run(name: str, algorithm: Algorithm, mode: Mode, tmp_path) -> None:
    if not _runnable(name, algorithm):
        pytest.skip("not functional / a combined constraint without priority: no block")
    f = load_filter(ROOT / "plants" / f"{name}.filter")
    block = filter_block(f, algorithm.value, mode.value)  # its text only: no blark parse (about 4 s a block)
    plc = CompiledProgram(StProgram(block.text, block.name, (), (block.pou,)), tmp_path, pou=block.name)
    cycle = FilterCycle(f, algorithm, mode)
    rows = _rows(cycle.reads, f"{name}{algorithm}{mode}")
    try:
        drive(plc, f.outputs, algorithm, mode, rows, run(cycle, rows))
    finally:
        plc.close()


@pytest.mark.parametrize("filter_file", ["plants/tri.filter", "tests/data/codegen/tri_box.filter"])
def test_the_box_sorting_program_with_its_filter_runs_compiled_as_interpreted(filter_file: str, tmp_path) -> None:
    """The whole PROGRAM (Grafcet, then the filter's block) compiled and interpreted, on the
    same 2 000 random PLC cycles (every input drawn each cycle, the clock moving 10 ms)."""
    import random

    from synth.codegen.grafcet_st import generate_program
    from synth.codegen.interpreter.machine import load_st
    from synth.codegen.program import filter_call
    from synth.grafcet.language_check import load_grafcet
    from synth.plant.rules_check import load_rules

    rs = load_rules(ROOT / "plants/tri.rules")
    g = load_grafcet(ROOT / "grafcets/tri.g7", inputs=rs.inputs, outputs=rs.outputs)
    program = generate_program(g, version="test", filter_call=filter_call(filter_block(load_filter(ROOT / filter_file))))
    module = load_st(program.text, "tri.st")
    inst = module.instance(program.program)
    plc = CompiledProgram(program, tmp_path)
    main = next(p for p in program.pous if p.name == program.program)
    inputs = [d.name for s in main.sections if s.kind.value == "VAR_INPUT" for d in s.declarations]
    outputs = [d.name for s in main.sections if s.kind.value == "VAR_OUTPUT" for d in s.declarations]
    rnd = random.Random(filter_file)
    seen = set()
    try:
        for n in range(2000):
            values = {i: rnd.random() < 0.3 for i in inputs}
            module.advance(10)
            plc.advance(10)
            inst.cycle(values)
            plc.cycle(values)
            assert [plc[o] for o in outputs] == [bool(inst[o]) for o in outputs], f"cycle {n + 1}"
            seen.add(tuple(plc[o] for o in outputs))
    finally:
        plc.close()
    assert len(seen) > 4  # the program moves: the comparison is not between two idle outputs


def test_split_blocks_compiled_run_as_the_whole_filter(tmp_path) -> None:
    """``filter st --split`` on the real compiler: each cluster's block compiled by iec2c
    and gcc, driven on its own inputs, gives the whole filter's outputs cycle after cycle."""
    from synth.codegen.filter_st import split_blocks
    from synth.filter.language_check import parse_filter
    from test_filter_scale import MIXED, assert_split_runs_as_whole

    f = parse_filter(MIXED, "mixed.filter")
    blocks = split_blocks(f)
    assert len(blocks) == 3
    parts = [CompiledProgram(StProgram(b.text, b.name, (), (b.pou,)), tmp_path / b.name, pou=b.name) for b in blocks]
    try:
        assert_split_runs_as_whole(f, blocks, parts, 5)
    finally:
        for plc in parts:
            plc.close()
