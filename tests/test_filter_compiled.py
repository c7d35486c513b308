"""Verified = deployed, on the real compiler: every bundled filter block compiled by MATIEC's
``iec2c`` and gcc (the harness of ``tests/iec2c.py``) equals ``synth filter run`` on the
same 1 000 random cycles as the interpreted block (``tests/test_filter_deployed.py``), off
the care set included. Skipped without ``iec2c`` and gcc."""

from __future__ import annotations

import shutil

import pytest

from iec2c import CompiledProgram, find_iec2c
from st_blocks import interpreted
from synth.codegen.program import StProgram
from synth.filter.cycle import Algorithm, FilterCycle, Mode
from synth.filter.language_check import load_filter
from synth.filter.run import run
from test_filter_deployed import CASES, ROOT, _rows, _runnable

pytestmark = pytest.mark.skipif(find_iec2c() is None or shutil.which("gcc") is None,
                                reason="MATIEC's iec2c (and gcc) are not on PATH")


@pytest.mark.parametrize(("name", "algorithm", "mode"), CASES, ids=[f"{n}-{a}-{m}" for n, a, m in CASES])
def test_the_compiled_block_is_filter_run(name: str, algorithm: Algorithm, mode: Mode, tmp_path) -> None:
    if not _runnable(name, algorithm):
        pytest.skip("not functional / a combined constraint without priority: no block")
    f = load_filter(ROOT / "plants" / f"{name}.filter")
    block, _ = interpreted(name, algorithm.value, mode.value)
    plc = CompiledProgram(StProgram(block.text, block.name, (), (block.pou,)), tmp_path, pou=block.name)
    cycle = FilterCycle(f, algorithm, mode)
    rows = _rows(cycle.reads, f"{name}{algorithm}{mode}")
    try:
        for n, (row, result) in enumerate(zip(rows, run(cycle, rows))):
            plc.cycle(dict(row.values))
            assert tuple(plc[o] for o in f.outputs) == result.outputs, f"cycle {n + 1}"
            if algorithm is Algorithm.LOOP:
                assert plc["Fallback"] == result.fallback, f"cycle {n + 1}"
            if mode is Mode.BLOCKING:
                assert plc["Blocked"] == result.blocked, f"cycle {n + 1}"
    finally:
        plc.close()
