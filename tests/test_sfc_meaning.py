"""``synth sfc`` with its IEC 61131-3 meaning (issue 22): a conditional action ``A if c`` leaves
``A`` FALSE once its step is left; names differing in case only are renamed as ``synth st``
renames them; and, where Beremiz and MATIEC are installed here, every bundled Grafcet's SFC
loads in Beremiz with all its steps and transitions and compiles, and the compiled
``conditional.g7`` resets its pump when its step is left."""

from __future__ import annotations

import re
import shutil

import pytest

from beremiz import beremiz_program, find_beremiz
from conftest import ROOT
from iec2c import CompiledProgram, compile_st, find_iec2c
from synth.codegen.grafcet_st import generate_program
from synth.codegen.plcopen.export import sfc_project_xml
from synth.codegen.plcopen.importer import import_sfc
from synth.codegen.program import StProgram
from synth.codegen.st import Declaration, Pou, PouKind, SectionKind, VarSection
from synth.grafcet.language_check import load_grafcet, parse_grafcet

GRAFCETS = [p for p in sorted((ROOT / "grafcets").glob("*.g7")) if p.name != "source_sink.g7"]


def interpreted(program: StProgram):
    from synth.codegen.interpreter.machine import load_st

    return load_st(program.text, "p.st").instance(program.program)


def test_a_conditional_action_is_reset_when_its_step_is_left():
    g = load_grafcet(ROOT / "grafcets/conditional.g7")
    xml = sfc_project_xml(g, version="test").decode()
    assert re.search(r'qualifier="N">.*?<!\[CDATA\[PUMP := NOT high;\]\]>', xml, re.S)
    assert re.search(r'qualifier="P0">.*?<!\[CDATA\[PUMP := FALSE;\]\]>', xml, re.S)
    back = import_sfc(xml.encode(), "conditional.xml")
    assert "  step 1: PUMP if !high, LIGHT\n" in back and "on deactivation" not in back
    pytest.importorskip("blark")
    inst = interpreted(generate_program(parse_grafcet(back, "back.g7"), version="test"))
    assert [inst.cycle(i)["PUMP"] for i in ({"go": False, "high": False}, {"go": True}, {}, {"go": False}, {})] == [
        False, True, True, False, False]


def test_names_differing_in_case_only_are_renamed_in_the_sfc():
    g = load_grafcet(ROOT / "tests/data/codegen/case_clash.g7")
    xml = sfc_project_xml(g, version="test").decode()
    assert re.findall(r'<variable name="(\w+)">', xml) == ["go", "a", "b", "_RE_go", "A_1", "B_1", "C"]
    assert "<Comment>renamed (Structured Text ignores case): A -&gt; A_1, B -&gt; B_1</Comment>" in xml
    back = import_sfc(xml.encode(), "case_clash.xml")
    assert "outputs A_1, B_1, C\n" in back and "  step 1: A_1\n" in back


def test_an_edge_is_an_input_the_caller_sets_and_reads_back_as_the_edge():
    """``↑b`` is the input ``_RE_b`` (an SFC cannot compute it before its transitions), with the
    caller's rule in its documentation; synth import reads it back as ``↑b``, not as an input."""
    g = load_grafcet(ROOT / "grafcets/timers.g7")
    xml = sfc_project_xml(g, version="test").decode()
    inputs = re.search(r"<inputVars>(.*?)</inputVars>", xml, re.S)
    assert inputs is not None and re.findall(r'<variable name="(\w+)">', inputs[1]) == ["start", "ok", "_RE_start",
                                                                                       "_FE_start"]
    assert "<localVars>" not in xml
    assert ("falling edge of start, set by the caller before each scan: NOT start AND start_previous "
            "(start_previous: start at the previous scan, start itself at the first scan: no edge then)") in xml
    back = import_sfc(xml.encode(), "timers.xml")
    assert back.splitlines()[1:3] == ["inputs start, ok", "outputs HEAT, ALARM"]
    assert "  transition 0 -> 1 when ↑start\n" in back and "  transition 2 -> 0 when ↓start\n" in back


needs_beremiz = pytest.mark.skipif(find_beremiz() is None or find_iec2c() is None,
                                   reason="Beremiz (SYNTH_BEREMIZ, SYNTH_BEREMIZ_PYTHON) and iec2c are not here")


@needs_beremiz
@pytest.mark.parametrize("path", GRAFCETS, ids=lambda p: p.name)
def test_beremiz_loads_every_step_and_transition_and_matiec_compiles_it(path, tmp_path):
    g = load_grafcet(path)
    (tmp_path / "plc.xml").write_bytes(sfc_project_xml(g, version="test"))
    done = beremiz_program(tmp_path / "plc.xml", tmp_path / "generated.st")
    assert done.returncode == 0, done.stderr
    text = (tmp_path / "generated.st").read_text()
    assert len(re.findall(r"^\s*(?:INITIAL_)?STEP \w+:", text, re.M)) == len(g.steps)
    assert len(re.findall(r"^\s*INITIAL_STEP", text, re.M)) == sum(s.initial for s in g.steps)
    assert len(re.findall(r"^\s*TRANSITION\b", text, re.M)) == len(g.transitions)
    compiled = compile_st(text, tmp_path / "c")
    assert compiled.returncode == 0, compiled.stdout + compiled.stderr


@needs_beremiz
@pytest.mark.skipif(shutil.which("gcc") is None, reason="no gcc")
def test_on_the_plc_the_pump_stops_when_its_step_is_left(tmp_path):
    g = load_grafcet(ROOT / "grafcets/conditional.g7")
    (tmp_path / "plc.xml").write_bytes(sfc_project_xml(g, version="test"))
    assert beremiz_program(tmp_path / "plc.xml", tmp_path / "generated.st").returncode == 0
    pou = Pou(PouKind.PROGRAM, "conditional", (
        VarSection(SectionKind.INPUT, (Declaration("go"), Declaration("high"))),
        VarSection(SectionKind.OUTPUT, (Declaration("PUMP"), Declaration("LIGHT")))), ())
    plc = CompiledProgram(StProgram((tmp_path / "generated.st").read_text(), "conditional", (), (pou,)), tmp_path / "c")
    try:
        pump = []
        for inputs in ({"go": False, "high": False}, {"go": True}, {}, {"go": False}, {}):
            plc.cycle(inputs)
            pump.append(plc.value("PUMP"))
    finally:
        plc.close()
    assert pump == [False, True, True, False, False]


def test_st_xml_with_a_task_carries_the_configuration(tmp_path):
    from synth.cli.main import main
    from tc6schema import validation_errors

    out = tmp_path / "plc.xml"
    assert main(["st", str(ROOT / "grafcets/tri.g7"), "--xml", "--task", "10ms", "-o", str(out)]) == 0
    xml = out.read_bytes()
    assert validation_errors(xml) == []
    assert re.sub(rb"\s+", b" ", xml).count(
        b'<configuration name="Config0"> <resource name="Res0"> <task name="MainTask" interval="T#10ms" '
        b'priority="0"> <pouInstance name="Inst0" typeName="tri"/> </task> </resource> </configuration>') == 1


@pytest.mark.skipif(find_beremiz() is None or find_iec2c() is None
                    or not (find_beremiz()[1].parent / "matiec" / "iec2c").exists(),  # type: ignore[index]
                    reason="Beremiz with MATIEC beside it (its layout: <dir>/beremiz, <dir>/matiec) is not here")
def test_beremiz_cli_builds_the_st_project(tmp_path):
    import subprocess

    from synth.cli.main import main

    python, home = find_beremiz()  # type: ignore[misc]
    assert main(["st", str(ROOT / "grafcets/tri.g7"), "--plant", str(ROOT / "plants/tri.rules"), "--filter",
                 str(ROOT / "tests/data/codegen/tri_box.filter"), "--xml", "--task", "10ms",
                 "-o", str(tmp_path / "plc.xml")]) == 0
    (tmp_path / "beremiz.xml").write_text('<?xml version="1.0" encoding="utf-8"?>\n<BeremizRoot '
                                          'xmlns:xsd="http://www.w3.org/2001/XMLSchema" URI_location="LOCAL://">'
                                          '<TargetType/><Libraries Enable_Python_Library="false"/></BeremizRoot>\n')
    done = subprocess.run([python, "Beremiz_cli.py", "--project-home", str(tmp_path), "build"], cwd=home,
                          capture_output=True, text=True, timeout=600)
    assert "Successfully built." in done.stdout + done.stderr, (done.stdout + done.stderr)[-2000:]


SHARED = """inputs go, a, b, c
outputs RUN
grafcet G {
  initial step 0
  step 1: RUN
  step 2: RUN if c
  step 3
  step 4
  transition 0 -> 1, 2 when go
  transition 1 -> 3 when a
  transition 2 -> 4 when b
  transition 3, 4 -> 0 when !go
}
"""


def test_a_shared_order_is_one_or_of_per_step_flags_and_reads_back():
    """RUN emitted by steps 1 and 2: each step drives its own flag, an S action on the initial
    step (and on the steps the first scan reaches) writes RUN as their OR at every scan; the
    import reads the .g7 back."""
    g = parse_grafcet(SHARED, "shared.g7")
    xml = sfc_project_xml(g, version="test").decode()
    assert xml.count('<variable name="_N_RUN_S1">') == 1 and xml.count('<variable name="_N_RUN_S2">') == 1
    assert "RUN := _N_RUN_S1 OR _N_RUN_S2;" in xml and '<reference name="_N_RUN_S1"/>' in xml
    assert "_N_RUN_S2 := c; RUN := _N_RUN_S1 OR _N_RUN_S2;" in xml  # the OR again, after the flag
    assert "_N_RUN_S2 := FALSE; RUN := _N_RUN_S1 OR _N_RUN_S2;" in xml
    # the S action writing RUN on the initial step 0 and on steps 1 and 2, which the first scan reaches
    assert xml.count('qualifier="S"') == 3
    back = import_sfc(xml.encode(), "shared.xml")
    assert "  step 1: RUN\n  step 2: RUN if c\n" in back and back.splitlines()[2] == "outputs RUN"


def test_the_shared_or_on_a_step_the_first_scan_reaches_is_read_only_as_a_copy_of_the_initial_one():
    """Without the initial step's S action, the one on step 1 runs only once step 1 is reached."""
    from synth.errors import InputError

    xml = sfc_project_xml(parse_grafcet(SHARED, "shared.g7"), version="test").decode()
    alone = re.sub(r'<action localId="\d+" qualifier="S">.*?</action>', "", xml, count=1, flags=re.S)
    assert alone.count('qualifier="S"') == 2
    with pytest.raises(InputError) as err:
        import_sfc(alone.encode(), "shared.xml")
    assert str(err.value).splitlines()[0] == (
        "shared.xml:93:13: error: the order RUN written as _N_RUN_S1 OR _N_RUN_S2 by an S action of step 1, which "
        "is not initial: that action runs only once the step is reached")


@needs_beremiz
@pytest.mark.skipif(shutil.which("gcc") is None, reason="no gcc")
def test_on_the_plc_a_shared_order_stays_on_while_one_of_its_steps_is_active(tmp_path):
    """MATIEC resets an N action's variable for one scan when one of its steps is left while
    another keeps it; the exported flags and their OR keep RUN on, as synth run does."""
    g = parse_grafcet(SHARED, "shared.g7")
    (tmp_path / "plc.xml").write_bytes(sfc_project_xml(g, version="test"))
    assert beremiz_program(tmp_path / "plc.xml", tmp_path / "generated.st").returncode == 0
    pou = Pou(PouKind.PROGRAM, "shared", (
        VarSection(SectionKind.INPUT, tuple(Declaration(n) for n in ("go", "a", "b", "c"))),
        VarSection(SectionKind.OUTPUT, (Declaration("RUN"),))), ())
    plc = CompiledProgram(StProgram((tmp_path / "generated.st").read_text(), "shared", (), (pou,)), tmp_path / "c")
    try:
        run = []
        for inputs in ({"go": False, "a": False, "b": False, "c": True}, {"go": True}, {"b": True}, {},
                       {"c": False}, {"a": True}, {"go": False}, {}):
            plc.cycle(inputs)
            run.append(plc.value("RUN"))
    finally:
        plc.close()
    # go: steps 1, 2; b leaves step 2 (step 1 keeps RUN); a leaves step 1
    assert run == [False, True, True, True, True, False, False, False]


MIRRORS = """grafcet G1 {
  initial step 0
  step 1: A if !X11
  transition 0 -> 1 when X10 . go
  transition 1 -> 0 when !go
}
grafcet G2 {
  initial step 10
  step 11
  transition 10 -> 11 when X1
  transition 11 -> 10 when X0
}"""


def test_a_step_flag_read_before_its_step_reads_a_mirror_and_reads_back():
    """G1 reads steps 10 and 11 of G2, which Beremiz writes after G1 (MATIEC refuses S11.X
    there): each drives its mirror from an N action, initially its initial activity; G2 reads
    G1's steps as S0.X, S1.X. The import reads the .g7 back, without a warning about them."""
    g = parse_grafcet(MIRRORS, "mirrors.g7")
    xml = sfc_project_xml(g, version="test").decode()
    assert re.findall(r'<variable name="(_X_\w+)">.*?<simpleValue value="(\w+)"/>', xml, re.S) == [
        ("_X_S10", "TRUE"), ("_X_S11", "FALSE")]
    assert '<reference name="_X_S10"/>' in xml and '<reference name="_X_S11"/>' in xml
    assert "<![CDATA[A := NOT _X_S11;]]>" in xml and "<![CDATA[_X_S10 AND go]]>" in xml
    assert "<![CDATA[S1.X]]>" in xml and "<![CDATA[S0.X]]>" in xml
    warnings: list = []
    back = import_sfc(xml.encode(), "mirrors.xml", warnings=warnings)
    assert [w.message for w in warnings] == []
    assert back.splitlines()[4:] == [
        "grafcet G1 {", "  initial step 0", "  step 1: A if !X11",
        "  transition 0 -> 1 when X10 & go", "  transition 1 -> 0 when !go", "}",
        "grafcet G2 {", "  initial step 10", "  step 11",
        "  transition 10 -> 11 when X1", "  transition 11 -> 10 when X0", "}"]


def test_a_mirror_without_its_step_action_stays_a_local_read_as_an_input():
    """A hand-written _X_S10 that step 10 does not drive is no mirror: an input, with the warning."""
    xml = sfc_project_xml(parse_grafcet(MIRRORS, "mirrors.g7"), version="test").decode()
    xml = re.sub(r'<action localId="\d+" qualifier="N">\s*<relPosition[^>]*/>\s*<reference name="_X_S10"/>\s*</action>',
                 "", xml)
    warnings: list = []
    back = import_sfc(xml.encode(), "mirrors.xml", warnings=warnings)
    assert back.splitlines()[1] == "inputs go, _X_S10" and "transition 0 -> 1 when _X_S10 & go" in back
    assert [w.message for w in warnings] == [
        "'_X_S10', declared in <localVars> of POU mirrors, is read as an input: nothing the chart does assigns it"]
