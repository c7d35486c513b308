"""What runs is what was proven: the C that MATIEC's ``iec2c`` compiles from the generated ST,
run by a small harness (``tests/iec2c.py``), equals ``synth run`` on every event sequence to
depth 3 — the same exploration as ``synth st --check``, with the compiled program in place of
the interpreter (issue 22). Skipped without ``iec2c`` and gcc (CI has no MATIEC)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from conftest import ROOT
from iec2c import CompiledProgram, find_iec2c
from randgrafcet import random_grafcet
from synth.codegen.check import differential_check
from synth.codegen.grafcet_st import generate_program
from synth.codegen.program import StProgram
from synth.grafcet.language import Grafcet
from synth.grafcet.language_check import load_grafcet, parse_grafcet

pytestmark = pytest.mark.skipif(find_iec2c() is None or shutil.which("gcc") is None,
                                reason="MATIEC's iec2c (and gcc) are not on PATH")

BUNDLED = [p for p in sorted(ROOT.glob("grafcets/*.g7")) + sorted(ROOT.glob("tests/data/**/*.g7"))
           if "codegen" not in p.parts]


def compiled_check(g: Grafcet, folder: Path, initial=None, program: StProgram | None = None, depth: int = 3):
    runners: list[CompiledProgram] = []

    def runner(p: StProgram) -> CompiledProgram:
        runners.append(CompiledProgram(p, folder))
        return runners[-1]

    try:
        report = differential_check(g, initial, depth=depth, program=program, runner=runner)
    finally:
        for r in runners:
            r.close()
    return report, runners[0].cycles


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: str(p.relative_to(ROOT)))
def test_the_compiled_program_equals_synth_run(path: Path, tmp_path):
    report, cycles = compiled_check(load_grafcet(path), tmp_path)
    assert report.ok, report.text()
    assert report.cycles == cycles >= 2


def test_box_sorting_with_the_plants_initial_inputs(tmp_path):
    from synth.plant.rules_check import load_rules

    rs = load_rules(ROOT / "plants/tri.rules")
    g = load_grafcet(ROOT / "grafcets/tri.g7", inputs=rs.inputs, outputs=rs.outputs)
    report, cycles = compiled_check(g, tmp_path, {v.name: v.initial for v in rs.variables if v.is_input})
    assert report.ok, report.text()
    assert report.cycles == cycles > 1000


def test_random_grafcets(tmp_path):
    total = 0
    for seed in range(20):
        g = parse_grafcet(random_grafcet(seed), f"random{seed}.g7")
        report, cycles = compiled_check(g, tmp_path / str(seed))
        assert report.ok, (seed, report.text())
        total += cycles
    assert total > 100


def test_a_wrong_compiled_program_is_caught(tmp_path):
    g = load_grafcet(ROOT / "grafcets/tri.g7")
    good = generate_program(g, version="test")
    broken = StProgram(good.text.replace(" AND ", " OR ", 1), good.program, good.renamed, good.pous)
    report, _ = compiled_check(g, tmp_path, program=broken, depth=2)
    assert [m.text() for m in report.mismatches] == ["initially: stability of synth run stable, of the ST program "
                                                     "Unstable = TRUE"]
