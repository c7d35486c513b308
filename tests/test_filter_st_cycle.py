"""The generated FUNCTION_BLOCK (run by the ST interpreter on blark's tree) against the
Python reference of one PLC cycle (``synth.filter.cycle``, what ``run`` and ``verify``
use): same outputs, Fallback and Blocked on random multi-cycle runs, for every bundled
filter, algorithm and mode (so every block blark parses)."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from synth.filter.cycle import Algorithm, FilterCycle, Mode
from synth.filter.language_check import load_filter
from synth.filter.solve import synthesis
from st_blocks import interpreted

ROOT = Path(__file__).resolve().parent.parent
CASES = [(p.stem, a, m) for p in sorted((ROOT / "plants").glob("*.filter"))
         for a in Algorithm for m in Mode]


def _runnable(f, algorithm: Algorithm) -> bool:
    if algorithm is Algorithm.LOOP:
        return all(s.forced for s in f.combined)
    return synthesis(f).functional


@pytest.mark.parametrize(("name", "algorithm", "mode"), CASES, ids=[f"{n}-{a}-{m}" for n, a, m in CASES])
def test_block_equals_the_reference_cycle(name: str, algorithm: Algorithm, mode: Mode) -> None:
    f = load_filter(ROOT / "plants" / f"{name}.filter")
    if not _runnable(f, algorithm):
        pytest.skip("not functional / a combined constraint without priority")
    block, module = interpreted(name, algorithm.value, mode.value)  # blark parses it
    fb = module.instance(block.name)
    ref = FilterCycle(f, algorithm, mode)
    memory = ref.initial()
    rnd = random.Random(f"{name}{algorithm}{mode}")
    compared = 0
    for n in range(150):
        values = {x: rnd.random() < 0.5 for x in ref.reads}
        result, memory = ref.step(memory, values)
        fb.cycle(values)
        if algorithm is Algorithm.ALGEBRAIC and result.outside_care:
            # the equations promise nothing there; take the block's outputs as the memory
            memory = _resync(ref, memory, fb)
            continue
        got = tuple(fb[o] for o in f.outputs)
        assert got == result.outputs, f"cycle {n}: {values}"
        if algorithm is Algorithm.LOOP:
            assert fb["Fallback"] == result.fallback, f"cycle {n}"
        if mode is Mode.BLOCKING:
            assert fb["Blocked"] == result.blocked, f"cycle {n}"
        compared += 1
    assert compared >= 50


def _resync(ref: FilterCycle, memory, fb):
    previous = tuple(fb[x] if x in ref.outputs else p for x, p in zip(ref.remembered, memory.previous))
    return type(memory)(previous, memory.blocked)
