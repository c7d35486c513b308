"""Generated Structured Text as a real IEC 61131-3 compiler reads it (issue 22).

blark, the parser the execution proof uses, accepts an ``END_IF`` without its ``;``; MATIEC's
``iec2c`` (the compiler of Beremiz and OpenPLC) refuses it ("';' missing at the end of
statement"). So:

* a strict check that always runs: every structured statement ends with ``;`` and no ``FOR``
  loop has a single pass (MATIEC's releases of June to November 2024 run ``FOR i := 1 TO 1``
  zero times); it is shown failing on the old output;
* with ``iec2c`` on PATH (``SYNTH_IEC2C`` may name it, with its ``lib`` folder beside it or in
  ``SYNTH_IEC2C_LIB``), every bundled Grafcet's program and every bundled filter block compiles;
  skipped otherwise (CI has no MATIEC: it is built from its public sources, never committed).
"""

from __future__ import annotations

import re

import pytest

from conftest import ROOT
from iec2c import compile_st, find_iec2c
from synth.codegen.filter_st import filter_block
from synth.codegen.grafcet_st import grafcet_program
from synth.errors import SynthError
from synth.filter.language_check import load_filter
from synth.grafcet.language_check import load_grafcet

GRAFCETS = sorted((ROOT / "grafcets").glob("*.g7"))
FILTERS = sorted((ROOT / "plants").glob("*.filter")) + sorted((ROOT / "tests/data/codegen").glob("*.filter"))
CLOSERS = re.compile(r"^\s*(END_IF|END_WHILE|END_FOR|END_REPEAT|END_CASE)\b(.*)$")
SINGLE_PASS = re.compile(r"\bFOR\s+\w+\s*:=\s*(\d+)\s+TO\s+(\d+)\s+DO\b")


def conformance_problems(text: str) -> list[str]:
    """Lines a strict IEC 61131-3 compiler refuses or misruns: a structured statement not
    closed by ``;``, a ``FOR`` loop whose bounds make one pass."""
    problems = []
    for n, line in enumerate(text.splitlines(), 1):
        code = re.sub(r"\(\*.*?\*\)", "", line)
        m = CLOSERS.match(code)
        if m and not m[2].strip().startswith(";"):
            problems.append(f"{n}: {m[1]} without ';'")
        for lo, hi in SINGLE_PASS.findall(code):
            if lo == hi:
                problems.append(f"{n}: a FOR loop with a single pass")
    return problems


def generated() -> list[tuple[str, str]]:
    from synth.codegen.program import configuration

    out = [(str(g.relative_to(ROOT)), grafcet_program(load_grafcet(g), version="test")) for g in GRAFCETS]
    tri = grafcet_program(load_grafcet(ROOT / "grafcets/tri.g7"), version="test")
    from synth.codegen.grafcet_st import generate_program
    from synth.codegen.program import filter_call
    from synth.plant.rules_check import load_rules

    rs = load_rules(ROOT / "plants/tri.rules")
    with_plant = load_grafcet(ROOT / "grafcets/tri.g7", inputs=rs.inputs, outputs=rs.outputs)
    out.append(("grafcets/tri.g7 --plant plants/tri.rules", generate_program(with_plant, version="test").text))
    for f in ("plants/tri.filter", "tests/data/codegen/tri_box.filter"):
        call = filter_call(filter_block(load_filter(ROOT / f)))
        out.append((f"grafcets/tri.g7 --plant plants/tri.rules --filter {f}",
                    generate_program(with_plant, version="test", filter_call=call).text))
    out.append(("grafcets/tri.g7 --task 10ms", tri + "\n".join(configuration("tri", "10ms").lines()) + "\n"))
    for f in FILTERS:
        for algorithm in ("algebraic", "loop"):
            for mode in ("supervisor", "blocking"):
                try:
                    block = filter_block(load_filter(f), algorithm, mode)
                except SynthError:  # not functional, or a loop without priorities: nothing is written
                    continue
                out.append((f"{f.relative_to(ROOT)} {algorithm} {mode}", block.text))
    return out


def test_the_strict_check_refuses_what_iec2c_refuses():
    text = grafcet_program(load_grafcet(ROOT / "grafcets/tri.g7"), version="test")
    old = text.replace("END_IF;", "END_IF").replace("END_WHILE;", "END_WHILE")  # the output before issue 22
    assert conformance_problems(text) == []
    assert len(conformance_problems(old)) >= 6 and conformance_problems(old)[0].endswith("without ';'")
    assert conformance_problems("FOR i := 1 TO 1 DO\n    x := TRUE;\nEND_FOR;") == ["1: a FOR loop with a single pass"]


def test_every_generated_file_passes_the_strict_check():
    files = generated()
    assert len(files) >= 40
    assert {name: conformance_problems(text) for name, text in files if conformance_problems(text)} == {}


@pytest.mark.skipif(find_iec2c() is None, reason="MATIEC's iec2c is not on PATH")
def test_every_generated_file_compiles_with_iec2c(tmp_path):
    failures = {}
    for k, (name, text) in enumerate(generated()):
        done = compile_st(text, tmp_path / f"p{k}")
        if done.returncode != 0 or not (tmp_path / f"p{k}" / "POUS.c").exists():
            failures[name] = (done.stdout + done.stderr)[-400:]
    assert failures == {}


def test_task_adds_a_configuration_and_a_bad_period_is_located(tmp_path, capsys):
    from synth.cli.main import main

    out = tmp_path / "tri.st"
    assert main(["st", str(ROOT / "grafcets/tri.g7"), "--plant", str(ROOT / "plants/tri.rules"), "--task", "10ms",
                 "-o", str(out)]) == 0
    assert out.read_text().endswith("CONFIGURATION Config0\n  RESOURCE Res0 ON PLC\n"
                                    "    TASK MainTask(INTERVAL := T#10ms, PRIORITY := 0);\n"
                                    "    PROGRAM Inst0 WITH MainTask : tri;\n  END_RESOURCE\nEND_CONFIGURATION\n")
    assert main(["st", str(ROOT / "grafcets/tri.g7"), "--task", "10", "-o", str(tmp_path / "x.st")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("--task:1:1: error: not a period\n  1 | 10\n") and "a period such as 10ms" in err
    assert not (tmp_path / "x.st").exists()
