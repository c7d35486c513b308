"""Verified = deployed (issue 22, item 5): ``synth filter run`` executes exactly the block
``synth filter st`` emits, on and off the care set. The emitted block, parsed by blark and
run by synth's ST interpreter (what ``st --check`` uses), and ``filter run``'s cycle are
driven by the same 1 000 random cycles — off-care cycles included, nothing skipped or
re-synchronised — for every bundled filter, algorithm and mode."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from synth.filter.cycle import Algorithm, FilterCycle, Mode
from synth.filter.language_check import load_filter
from synth.filter.run import Row, run, run_trace
from synth.filter.solve import synthesis
from st_blocks import interpreted

from conftest import ROOT

CASES = [(p.stem, a, m) for p in sorted((ROOT / "plants").glob("*.filter")) for a in Algorithm for m in Mode]
CYCLES = 1000


def _runnable(name: str, algorithm: Algorithm) -> bool:
    f = load_filter(ROOT / "plants" / f"{name}.filter")
    if algorithm is Algorithm.LOOP:
        return all(s.forced for s in f.combined)
    return synthesis(f).functional


def _rows(reads: tuple[str, ...], seed: str) -> list[Row]:
    rnd = random.Random(seed)
    return [Row(n + 2, tuple((x, rnd.random() < 0.5) for x in reads)) for n in range(CYCLES)]


def drive(fb, outputs, algorithm: Algorithm, mode: Mode, rows: list[Row], results) -> None:
    """Run the block ``fb`` (anything with ``cycle(values)`` and ``fb[name]``) on ``rows`` and
    compare it with ``filter run``'s ``results``, cycle after cycle."""
    for n, (row, result) in enumerate(zip(rows, results)):
        fb.cycle(dict(row.values))
        assert tuple(fb[o] for o in outputs) == result.outputs, f"cycle {n + 1}"
        if algorithm is Algorithm.LOOP:
            assert fb["Fallback"] == result.fallback, f"cycle {n + 1}"
        if mode is Mode.BLOCKING:
            assert fb["Blocked"] == result.blocked, f"cycle {n + 1}"


@pytest.mark.parametrize(("name", "algorithm", "mode"), CASES, ids=[f"{n}-{a}-{m}" for n, a, m in CASES])
def test_filter_run_is_the_emitted_block(name: str, algorithm: Algorithm, mode: Mode) -> None:
    if not _runnable(name, algorithm):
        pytest.skip("not functional / a combined constraint without priority: no block")
    f = load_filter(ROOT / "plants" / f"{name}.filter")
    block, module = interpreted(name, algorithm.value, mode.value)
    fb = module.instance(block.name)
    cycle = FilterCycle(f, algorithm, mode)
    rows = _rows(cycle.reads, f"{name}{algorithm}{mode}")
    results = run(cycle, rows)
    drive(fb, f.outputs, algorithm, mode, rows, results)
    if algorithm is Algorithm.ALGEBRAIC and mode is Mode.SUPERVISOR and cycle.care != ((),):
        assert any(r.outside_care for r in results)  # the cycles left the care set


def test_off_the_care_set_the_flat_equations_would_differ(cli) -> None:
    """The comparison above can fail: on the 2-cycle trace ``tests/data/filter/tri_off_care.csv``
    of the box sorting (off the care set), the flat Y-only equations — what ``run`` evaluated
    before — give A4 = 1 at cycle 2, while the block, and now ``filter run``, give 0."""
    trace = ROOT / "tests" / "data" / "filter" / "tri_off_care.csv"
    code, out, _ = cli("filter", "run", ROOT / "plants" / "tri.filter", "--trace", trace)
    assert code == 1  # outside the care set: not coherent
    assert [line.split("O: ")[1][:7] for line in out.splitlines() if "O: " in line] == ["0010011", "0110011"]
    f = load_filter(ROOT / "plants" / "tri.filter")
    s = synthesis(f)
    e = s.functions.engine
    cycle = FilterCycle(s)
    rows = [dict(r.values) for r in run_trace(f, str(trace)).rows]
    block, module = interpreted("tri", "algebraic", "supervisor")
    fb = module.instance(block.name)
    memory = cycle.initial()
    flat = []
    for values in rows:
        point = values | {n + "^-1": v for n, v in zip(cycle.remembered, memory.previous)}
        flat.append(tuple(e.value(_flat(s, o), point) for o in f.outputs))
        result, memory = cycle.step(memory, values)
        fb.cycle(values)
        assert tuple(fb[o] for o in f.outputs) == result.outputs
    assert flat[1][f.outputs.index("A4")] is True and result.outputs[f.outputs.index("A4")] is False


def _flat(s, o: str):
    """The function the flat equation of ``o`` prints (its cover: don't-cares resolved)."""
    e = s.functions.engine
    one = s.output(o)
    return e.disjunction(e.cube(c) for c in e.cover(one, one | ~s.care))


def test_cli_run_matches_the_block_on_a_trace(tmp_path: Path) -> None:
    """``synth filter run`` itself (the CSV path) on an off-care trace of the box sorting."""
    f = load_filter(ROOT / "plants" / "tri.filter")
    cycle = FilterCycle(f)
    rows = _rows(cycle.reads, "tri-cli")[:40]
    trace = tmp_path / "t.csv"
    trace.write_text(",".join(cycle.reads) + "\n" + "".join(
        ",".join("1" if v else "0" for _, v in r.values) + "\n" for r in rows), encoding="utf-8")
    ran = run_trace(f, str(trace))
    block, module = interpreted("tri", "algebraic", "supervisor")
    fb = module.instance(block.name)
    for row, result in zip(rows, ran.results):
        fb.cycle(dict(row.values))
        assert tuple(fb[o] for o in f.outputs) == result.outputs
    assert any(r.outside_care for r in ran.results)
