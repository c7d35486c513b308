"""PLCopen files as IDEs write them (issue 21): TC6 2.00 (CODESYS V3.5), 2.01 (Beremiz) and
1.0 (``tc6.xsd``); conditions wired as FBD ``<inVariable>``/blocks or LD contacts, named
transitions with FBD bodies; every SFC POU of a project; nothing dropped silently; what has
no Boolean meaning is an error at its XML element. The fixtures are written here in each
dialect's shape (the public files measured by ``bench/import_corpus.py`` stay out)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from synth.cli.main import main
from synth.codegen.plcopen.importer import import_sfc, list_pous
from synth.errors import InputError
from synth.grafcet.ass import stable_situation_automaton
from synth.grafcet.language_check import load_grafcet, parse_grafcet
from synth.grafcet.machine import GrafcetMachine
from synth.output.summary import ass_json

DATA = Path(__file__).resolve().parent / "data" / "plcopen"


def _ass(g) -> dict:
    return ass_json(stable_situation_automaton(GrafcetMachine(g), initial_inputs={n: False for n in g.inputs}))


def test_a_codesys_export_imports_every_sfc_pou_with_fbd_conditions():
    xml = (DATA / "codesys_v35.xml").read_bytes()
    notes: list[str] = []
    text = import_sfc(xml, "codesys_v35.xml", notes=notes)
    assert text.split("\n", 1)[1] == """inputs xStart, xDown, xGripOk, xPart
outputs LOWER, MOTOR

grafcet Crane_G1 {
  initial step Crane_Init
  step Crane_Lower: LOWER
  transition Crane_Init -> Crane_Lower when xStart & !xDown
  transition Crane_Lower -> Crane_Init when (xDown) & !(xGripOk)
}
grafcet Belt_G1 {
  initial step Belt_Idle
  step Belt_Run: MOTOR
  transition Belt_Idle -> Belt_Run when xPart
  transition Belt_Run -> Belt_Idle when !(xPart)
}
"""
    assert notes == ["POU PLC_PRG not imported: an ST body: .g7 holds SFC charts only"]
    by_hand = load_grafcet(DATA / "codesys_v35.g7", inputs=("xStart", "xDown", "xGripOk", "xPart"),
                           outputs=("LOWER", "MOTOR"))
    imported = parse_grafcet(text, "imported.g7")
    assert _ass(imported)["transitions"] == _ass(by_hand)["transitions"]
    assert _ass(imported)["states"] == _ass(by_hand)["states"]


def test_list_and_select_pous(capsys):
    path = str(DATA / "codesys_v35.xml")
    assert main(["import", "--list", path]) == 0
    assert capsys.readouterr().out == ("Crane\tprogram\tSFC\timported\nBelt\tprogram\tSFC\timported\n"
                                       "PLC_PRG\tprogram\tST\tnot imported: an ST body: .g7 holds SFC charts only\n")
    assert main(["import", path, "--pou", "Belt"]) == 0
    out, err = capsys.readouterr()
    assert "grafcet G1 {\n  initial step Idle\n" in out and "Crane" not in out and err == ""
    assert main(["import", path, "--pou", "Crne"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("--pou:1:1: error: no SFC POU named Crne in this file\n") and "did you mean Crane?" in err
    assert main(["import", path]) == 0
    assert capsys.readouterr().err == f"{path}: note: POU PLC_PRG not imported: an ST body: .g7 holds SFC charts only\n"


CODESYS_HEADER = '<fileHeader companyName="" productName="CODESYS" productVersion="CODESYS V3.5 SP16"/>'


def as_codesys(xml: str) -> str:
    """``xml`` (a Beremiz file) with a CODESYS ``fileHeader``: its blocks read as CODESYS calls them."""
    header = re.search(r"<fileHeader [^>]*/>", xml)
    assert header is not None
    return xml.replace(header[0], CODESYS_HEADER, 1)


def test_beremiz_ld_contacts_and_an_fbd_named_transition():
    """The NOT of the named transition's FBD body: Beremiz computes it after the transitions
    (its output of the previous scan, a register grafcet), from the end of the first scan after
    which Idle is active (Idle may be left at the first scan); CODESYS while evaluating the
    transition."""
    for name in ("beremiz_ld_fbd.xml", "beremiz_tc6_1_0.xml"):  # TC6 2.01, and the same chart in the 1.0 namespace
        text = import_sfc((DATA / name).read_bytes(), name)
        assert text.split("\n", 1)[1] == """inputs a, b, c
outputs LAMP

grafcet G1 {
  initial step Idle
  step On: LAMP
  transition Idle -> On when (a) & !b
  transition On -> Idle when XNOT42_on
}
grafcet NOT42 {
  initial step NOT42_off
  step NOT42_on
  transition NOT42_off -> NOT42_on when (XCOMPUTE_FUNCTION_BLOCKS_on | XIdle & !(XIdle & (a) & !b) | XOn & XNOT42_on) & !c
  transition NOT42_on -> NOT42_off when (XCOMPUTE_FUNCTION_BLOCKS_on | XIdle & !(XIdle & (a) & !b) | XOn & XNOT42_on) & c
}
grafcet COMPUTE_FUNCTION_BLOCKS {
  initial step COMPUTE_FUNCTION_BLOCKS_off
  step COMPUTE_FUNCTION_BLOCKS_on
  transition COMPUTE_FUNCTION_BLOCKS_off -> COMPUTE_FUNCTION_BLOCKS_on when XIdle & !(XIdle & (a) & !b) | XOn & XNOT42_on
}
"""
        text = import_sfc(as_codesys((DATA / name).read_text()).encode(), name)
        assert text.split("\n", 1)[1] == """inputs a, b, c
outputs LAMP

grafcet G1 {
  initial step Idle
  step On: LAMP
  transition Idle -> On when (a) & !b
  transition On -> Idle when !(c)
}
"""


@pytest.mark.parametrize("old, new, first", [
    ('<block localId="9" typeName="AND">', '<block localId="9" typeName="CTU">',
     "x.xml:73:13: error: an FBD block CTU in a transition condition: only AND, OR, NOT, SEL, R_TRIG, F_TRIG, TON, "
     "SR and RS have a Boolean or step-timer meaning in .g7"),
    ('<block localId="9" typeName="AND">', '<block localId="9" typeName="TON">',
     "x.xml:73:13: error: an FBD TON block without its input IN"),
    ('<reference name="LOWER" />', "<inline><ST><xhtml xmlns=\"http://www.w3.org/1999/xhtml\">Cnt := Cnt + 1;</xhtml>"
     "</ST></inline>", "x.xml:60:73: error: an assignment of data in an action body (Cnt := Cnt + 1;): Cnt is not a "
     "local variable of an integer type (.g7 internal variables are the chart's own)"),
    ('<connection refLocalId="2" />', '<connection refLocalId="77" />',
     "x.xml:46:17: error: connection to unknown localId 77"),
])
def test_what_has_no_boolean_meaning_is_located_in_the_xml(old, new, first):
    text = (DATA / "codesys_v35.xml").read_text()
    assert old in text
    with pytest.raises(InputError) as info:
        import_sfc(text.replace(old, new, 1).encode(), "x.xml")
    assert info.value.render().splitlines()[0] == first


def test_list_pous_of_a_file_without_sfc():
    xml = (DATA / "codesys_v35.xml").read_text().replace("<SFC>", "<FBD>").replace("</SFC>", "</FBD>")
    assert [p.imported for p in list_pous(xml.encode())] == [False, False, False]


LAMP_HELD = [
    "ide_sfc.xml:132:15: warning: an N action assigning LAMP in step Lamp is read as the continuous action "
    "'LAMP if !bottom': LAMP falls when the step is left, while the PLC keeps its last value",
    '  132 |               <action localId="12" qualifier="N">',
    "      |               ^~~~~~~",
    "  = note: to keep the continuous meaning on the PLC, add a P0 action 'LAMP := FALSE;' to step Lamp; for a stored "
    "order, write S/R actions (set LAMP / reset LAMP)"]


def test_a_selection_divergence_keeps_its_sfc_priority_with_a_warning():
    warnings: list[InputError] = []
    root = Path(__file__).resolve().parent / "data" / "codegen"
    text = import_sfc((root / "ide_sfc.xml").read_bytes(), "ide_sfc.xml", warnings=warnings)
    assert "  transition Wait -> Up when 2s/XWait\n  transition Wait -> Up when (guard) & !(2s/XWait)\n" in text
    assert [w.render().splitlines() for w in warnings] == [[
        "ide_sfc.xml:154:13: warning: a selection divergence: IEC 61131-3 SFC fires the first true branch (left to "
        "right), .g7 every true branch; the later branches' receptivities are made exclusive",
        '  154 |             <selectionDivergence localId="16">',
        "      |             ^~~~~~~~~~~~~~~~~~~~",
        "  = note: Wait -> Up when (guard) & !(2s/XWait)",
        "  = note: on MATIEC (the compiler of Beremiz and OpenPLC) every true branch fires, priorities ignored: for a "
        "program that runs there, validate the receptivities as written, without this rewrite"], LAMP_HELD]


def _selection_of(n: int) -> bytes:
    """A Beremiz chart: from Init, a selection divergence of ``n`` branches (branch k on
    ``ck``), each one step and a jump back to Init on ``done``."""
    def cond(i: int, text: str) -> str:
        return (f'<transition localId="{i}"><position x="0" y="0" />{{into}}<condition><inline name="">'
                f"<ST><xhtml:p><![CDATA[{text}]]></xhtml:p></ST></inline></condition></transition>")
    parts = ['<step localId="1" name="Init" initialStep="true"><position x="0" y="0" /></step>',
             '<selectionDivergence localId="2"><position x="0" y="0" /><connectionPointIn><connection refLocalId="1" />'
             '</connectionPointIn>' + "".join(f'<connectionPointOut formalParameter="{k}" />' for k in range(n)) +
             "</selectionDivergence>"]
    for k in range(n):
        t, s, back, jump = 10 + 4 * k, 11 + 4 * k, 12 + 4 * k, 13 + 4 * k
        parts.append(cond(t, f"c{k}").format(into=f'<connectionPointIn><connection refLocalId="2" formalParameter="{k}" />'
                                                  "</connectionPointIn>"))
        parts.append(f'<step localId="{s}" name="B{k}"><position x="0" y="0" /><connectionPointIn><connection '
                     f'refLocalId="{t}" /></connectionPointIn></step>')
        parts.append(cond(back, "done").format(into=f'<connectionPointIn><connection refLocalId="{s}" /></connectionPointIn>'))
        parts.append(f'<jumpStep localId="{jump}" targetName="Init"><position x="0" y="0" /><connectionPointIn>'
                     f'<connection refLocalId="{back}" /></connectionPointIn></jumpStep>')
    inputs = "".join(f'<variable name="{v}"><type><BOOL /></type></variable>' for v in [*(f"c{k}" for k in range(n)), "done"])
    return ('<?xml version="1.0" encoding="utf-8"?>\n<project xmlns="http://www.plcopen.org/xml/tc6_0201" '
            'xmlns:xhtml="http://www.w3.org/1999/xhtml"><fileHeader companyName="x" productName="Beremiz" '
            'productVersion="1" creationDateTime="2024-01-01T00:00:00" /><contentHeader name="p">'
            '<coordinateInfo><fbd><scaling x="1" y="1" /></fbd><ld><scaling x="1" y="1" /></ld><sfc><scaling x="1" '
            'y="1" /></sfc></coordinateInfo></contentHeader><types><dataTypes /><pous><pou name="Sel" pouType="program">'
            f'<interface><inputVars>{inputs}</inputVars></interface><body><SFC>\n' + "\n".join(parts) +
            "\n</SFC></body></pou></pous></types><instances><configurations /></instances></project>\n").encode()


def test_each_later_branch_of_a_selection_excludes_the_earlier_ones_as_written():
    """Branch k excludes branches 0..k-1 as the chart writes them, not their rewrites (which
    would double the text at each branch: 2^k copies of the first condition)."""
    warnings: list[InputError] = []
    text = import_sfc(_selection_of(4), "sel.xml", warnings=warnings)
    assert [line for line in text.splitlines() if line.startswith("  transition Init")] == [
        "  transition Init -> B0 when c0",
        "  transition Init -> B1 when (c1) & !(c0)",
        "  transition Init -> B2 when (c2) & !(c0) & !(c1)",
        "  transition Init -> B3 when (c3) & !(c0) & !(c1) & !(c2)"]
    assert [w.render().splitlines()[3:6] for w in warnings] == [[
        "  = note: Init -> B1 when (c1) & !(c0)", "  = note: Init -> B2 when (c2) & !(c0) & !(c1)",
        "  = note: Init -> B3 when (c3) & !(c0) & !(c1) & !(c2)"]]
    text = import_sfc(_selection_of(16), "sel.xml")  # a mode selector of sixteen
    assert next(line for line in text.splitlines() if line.startswith("  transition Init -> B15 ")) == "  transition Init -> B15 when (c15) & !(c0) & " + " & ".join(f"!(c{k})" for k in range(1, 15))


def test_a_level_self_loop_jump_is_imported_with_a_warning():
    xml = as_codesys((DATA / "beremiz_ld_fbd.xml").read_text().replace('targetName="Idle"', 'targetName="On"'))
    warnings: list[InputError] = []
    text = import_sfc(xml.encode(), "loop.xml", warnings=warnings)
    assert "  transition On -> On when !(c)\n" in text
    assert [w.render().splitlines()[0] for w in warnings] == [
        "loop.xml:106:13: warning: a jump from step On back to itself on a level condition (!(c)): IEC 61131-3 SFC "
        "re-activates the step at every PLC scan while it holds, IEC 60848 (.g7) never stabilises there"]


def test_a_chart_inside_an_action_of_a_function_block_is_named_not_dropped(cli, tmp_path):
    fb = ('<pou name="Cyl" pouType="functionBlock"><interface/><actions><action name="ACT_Extend"><body><SFC>'
          '<step localId="1" name="Init" initialStep="true"><position x="0" y="0"/></step></SFC></body></action>'
          '</actions><body><ST><xhtml:p>ACT_Extend();</xhtml:p></ST></body></pou>\n    </pous>')
    xml = (DATA / "beremiz_ld_fbd.xml").read_text().replace("</pous>", fb, 1)
    (tmp_path / "fb.xml").write_text(xml)
    code, out, _ = cli("import", "--list", tmp_path / "fb.xml")
    assert code == 0 and out.splitlines()[-1].split("\t") == [
        "Cyl", "functionBlock", "ST", "not imported: an ST body: .g7 holds SFC charts only; SFC in its action ACT_Extend: "
        "not imported (.g7 reads the SFC body of a POU, not a chart inside an action of a function block)"]
    code, _, err = cli("import", tmp_path / "fb.xml", "-o", tmp_path / "fb.g7")
    assert code == 0 and "SFC in its action ACT_Extend: not imported" in err


def test_a_chart_inside_an_action_is_named_when_its_pou_alone_is_imported(cli, tmp_path):
    """`--pou Stack` of an SFC function block whose action holds another chart: the chart
    imported is the body's, and the one inside the action is named as not imported."""
    text = (DATA / "codesys_v35.xml").read_text()
    action = ('<actions><action name="ACT_Auto"><body><SFC><step localId="1" name="A0" initialStep="true">'
              '<position x="0" y="0"/></step></SFC></body></action></actions>\n        <body>\n          <SFC>')
    assert text.count("<body>\n          <SFC>") >= 1
    (tmp_path / "fb.xml").write_text(text.replace("<body>\n          <SFC>", action, 1))
    code, _, err = cli("import", tmp_path / "fb.xml", "--pou", "Crane", "-o", tmp_path / "fb.g7")
    last = err.splitlines()[-1]
    assert code == 0 and ": note: POU Crane: " in last and last.endswith(
        "; SFC in its action ACT_Auto: not imported (.g7 reads the SFC body of a POU, not a chart "
        "inside an action of a function block)")
    code, _, err = cli("import", tmp_path / "fb.xml", "--pou", "Belt", "-o", tmp_path / "belt.g7")
    assert code == 0 and "ACT_Auto" not in err


def _with_pou_action(body: str, qualifier: str = "N") -> bytes:
    text = (DATA / "codesys_v35.xml").read_text()
    text = text.replace('<variable name="LOWER"><type><BOOL /></type></variable>',
                        '<variable name="LOWER"><type><BOOL /></type></variable>\n'
                        '            <variable name="GRIP"><type><BOOL /></type></variable>', 1)
    text = text.replace("        <body>\n          <SFC>",
                        '        <actions>\n          <action name="Grip">\n            <body>\n              <ST><xhtml '
                        f'xmlns="http://www.w3.org/1999/xhtml">{body}</xhtml></ST>\n            </body>\n'
                        "          </action>\n        </actions>\n        <body>\n          <SFC>", 1)
    text = text.replace('<reference name="LOWER" />\n              </action>',
                        '<reference name="LOWER" />\n              </action>\n'
                        f'              <action localId="0" qualifier="{qualifier}"><relPosition x="0" y="0" />'
                        '<reference name="Grip" /></action>', 1)
    return text.encode()


def test_a_reference_to_a_pou_action_is_read_as_its_assignments():
    text = import_sfc(_with_pou_action("GRIP := TRUE; (* close the gripper *)"), "x.xml", pou="Crane")
    assert "  step Lower: LOWER, set GRIP\n" in text and "outputs LOWER, GRIP\n" in text
    text = import_sfc(_with_pou_action("GRIP := FALSE;", "P0"), "x.xml", pou="Crane")
    assert "  step Lower: LOWER, reset GRIP on deactivation\n" in text
    with pytest.raises(InputError) as info:
        import_sfc(_with_pou_action("GRIP := xDown;"), "x.xml", pou="Crane")
    assert info.value.render().splitlines()[0] == (
        "x.xml:34:63: error: a statement of action Grip that .g7 cannot hold (GRIP := xDown): a PLC keeps what an "
        "action body assigns after its step is left, so only X := TRUE; and X := FALSE; (and, in an N action, IF "
        "condition THEN X := TRUE; END_IF) are read")


def test_names_a_transition_reads_are_checked_in_the_xml():
    text = (DATA / "codesys_v35.xml").read_text().replace("<expression>xPart</expression>",
                                                         "<expression>xLocal</expression>", 1)
    with pytest.raises(InputError) as info:
        import_sfc(text.encode(), "x.xml")
    assert info.value.render().splitlines()[0] == (
        "x.xml:124:13: error: a transition reads 'xLocal', which the POU Belt does not declare")
    local = text.replace("</outputVars>\n        </interface>\n        <body>\n          <SFC>\n            <step "
                         'localId="1" name="Idle"', "</outputVars>\n          <localVars>\n            <variable "
                         'name="xLocal"><type><BOOL /></type></variable>\n          </localVars>\n        </interface>\n'
                         '        <body>\n          <SFC>\n            <step localId="1" name="Idle"', 1)
    warnings: list[InputError] = []
    out = import_sfc(local.encode(), "x.xml", pou="Belt", warnings=warnings)
    assert "inputs xPart, xLocal\n" in out
    assert [w.message for w in warnings] == [
        "'xLocal', declared in <localVars> of POU Belt, is read as an input: nothing the chart does assigns it"]


def test_a_comparison_becomes_a_declared_predicate():
    text = (DATA / "codesys_v35.xml").read_text().replace("<expression>xDown</expression>",
                                                         "<expression>rPos &gt; 24290.0</expression>", 1)
    warnings: list[InputError] = []
    out = import_sfc(text.encode(), "x.xml", pou="Crane", warnings=warnings)
    assert "inputs xStart, xDown, xGripOk, rPos_gt_24290_0\n" in out
    assert "  transition Lower -> Init when (rPos_gt_24290_0) & !(xGripOk)\n" in out
    assert [w.render().splitlines()[0] for w in warnings] == [
        "x.xml:66:15: warning: declared predicate rPos_gt_24290_0 stands for 'rPos > 24290.0': a Boolean input of "
        "the imported Grafcet (.g7 reads no numeric values); bind it to a sensor of the plant, or leave it free"]
    g = parse_grafcet(out, "crane.g7")
    assert "rPos_gt_24290_0" in g.inputs


def test_a_twincat3_export_with_step_actions_in_vendor_data_equals_the_chart_by_hand():
    """TwinCAT 3 (and CODESYS V3.5) keep a step's entry/active/exit actions in its addData: read as P1/N/P0
    references to the POU's actions; D and L action blocks are step timers; an output read is its feedback."""
    warnings: list[InputError] = []
    text = import_sfc((DATA / "twincat3.xml").read_bytes(), "twincat3.xml", warnings=warnings)
    by_hand = (DATA / "twincat3.g7").read_text()
    assert text.split("\n", 1)[1] == by_hand.split("\n", 1)[1]
    assert [w.render().splitlines()[0] for w in warnings] == [
        "twincat3.xml:127:13: warning: a transition reads the output 'bLamp' of POU FB_Door: .g7 receptivities read "
        "inputs, so it reads the input bLamp_fb (bind it to the output's value)",
        "twincat3.xml:80:1: warning: IF (bOpenCmd = TRUE) AND NOT bIsOpen in action Idle_active (run while its step "
        "is active) is read as the stored action on the rising edge ↑bOpenCmd & !bIsOpen | bOpenCmd & ↓bIsOpen: if "
        "the condition already holds when the step becomes active, the PLC assigns at once and .g7 waits for the edge"]
    imported, hand = parse_grafcet(text, "imported.g7"), load_grafcet(DATA / "twincat3.g7")
    assert _ass(imported) == _ass(hand)


@pytest.mark.parametrize("old, new, first", [
    ('qualifier="D" duration="T#10s"', 'qualifier="SD" duration="T#10s"',
     "x.xml:167:15: error: action qualifier SD (stored and timed) cannot be represented in .g7: a .g7 timer belongs "
     "to a step, not to a stored action"),
    ('<reference name="bAlarm" />', '<reference name="Motor.ACT_Stop" />',
     "x.xml:167:15: error: action Motor.ACT_Stop belongs to the instance Motor of another block: .g7 holds this "
     "chart's Boolean actions, not another block's code"),
    (">Opening_active</attribute>", ">Opening_run</attribute>",
     "x.xml:156:21: error: step action Opening_run is not an action of this POU"),
    ("bMotorOpen := TRUE;</xhtml>", "Timer(IN := bIsOpen, PT := T#1s);</xhtml>",
     "x.xml:90:61: error: a call of the block instance Timer in action Opening_active (Timer(IN := bIsOpen, PT := "
     "T#1s)): .g7 runs no function blocks (its timers time a step's activity: 2s/X1)"),
    ("bMotorOpen := TRUE;</xhtml>", "nCount := nCount + 1;</xhtml>",
     "x.xml:90:61: error: an assignment of data in action Opening_active (nCount := nCount + 1): nCount is not a "
     "local variable of an integer type (.g7 internal variables are the chart's own)"),
    ("IF (bOpenCmd = TRUE) AND NOT bIsOpen THEN", "IF bOpenCmd OR bIsOpen THEN",
     "x.xml:80:3: error: IF bOpenCmd OR bIsOpen in action Idle_active: only a condition that is a conjunction of "
     "inputs (a AND NOT b) has a rising edge .g7 can write"),
])
def test_what_a_twincat3_step_action_cannot_be_is_located(old, new, first):
    text = (DATA / "twincat3.xml").read_text()
    assert old in text
    with pytest.raises(InputError) as info:
        import_sfc(text.replace(old, new, 1).encode(), "x.xml")
    assert info.value.render().splitlines()[0] == first


def test_qualifier_p_is_a_pulse_on_activation_and_true_false_literals_are_boolean():
    text = (DATA / "codesys_v35.xml").read_text()
    text = text.replace('<reference name="LOWER" />', '<inline><ST><xhtml xmlns="http://www.w3.org/1999/xhtml">'
                        "LOWER := TRUE;</xhtml></ST></inline>", 1).replace('qualifier="N"', 'qualifier="P"', 1)
    text = text.replace("<expression>xPart</expression>", "<expression>xPart = FALSE</expression>", 1)
    out = import_sfc(text.encode(), "x.xml")
    assert "  step Crane_Lower: set LOWER on activation\n" in out
    assert "  transition Belt_Idle -> Belt_Run when !xPart\n" in out


def test_an_integer_local_assigned_in_p1_p0_bodies_is_an_internal_variable():
    """Beremiz (TC6 2.01): Cnt := Cnt + 1 under P1, Cnt := 0 under P0, 3 <= Cnt in a condition."""
    warnings: list[InputError] = []
    text = import_sfc((DATA / "beremiz_counter.xml").read_bytes(), "beremiz_counter.xml", warnings=warnings)
    assert text.split("\n", 1)[1] == """inputs go
outputs FULL
internal Cnt : -32768..32767 = 0

grafcet G1 {
  initial step Start
  step Count: Cnt := Cnt + 1
  step Full: FULL, Cnt := 0 on deactivation
  transition Start -> Count when go
  transition Count -> Full when !go & Cnt >= 3
  transition Full -> Start when go
  transition Count -> Start when !go & Cnt < 3
}
"""
    assert [w.render().splitlines()[0] for w in warnings] == [
        "beremiz_counter.xml:23:13: warning: local variable Cnt (INT) of POU CounterSFC, assigned by its actions, is "
        "the internal variable Cnt : -32768..32767 = 0: give it the range it really has"]
    g = parse_grafcet(text, "counter.g7")
    assert [(v.name, v.low, v.high, v.initial) for v in g.internals] == [("Cnt", -32768, 32767, 0)]
    assert len(_ass(g)["states"]) == 7  # Start/Count with Cnt 0..3, then Full


@pytest.mark.parametrize("old, new, first", [
    ('<action localId="0" qualifier="P1">', '<action localId="0">',
     "x.xml:66:39: error: Cnt := Cnt + 1; in an N action, run at every PLC scan while its step is active: .g7 assigns "
     "once, on activation, on deactivation or on an event (use P1 or P0, or IF condition THEN ... END_IF)"),
    ("Cnt := 0;", "Cnt := Cnt * 2;",
     "x.xml:109:50: error: the assignment to Cnt is not a sum of integers and internal variables ('Cnt * 2'): .g7 "
     "assigns sums such as Cnt + 1"),
    ("Cnt := 0;", "Cnt := FULL + 1;",
     "x.xml:109:46: error: 'FULL' in the assignment to Cnt: .g7 adds integer internal variables and integer constants"),
    ("<![CDATA[go]]>", "<![CDATA[Cnt]]>", "x.xml:42:39: error: Cnt is an integer (-32768..32767): compare it, e.g. Cnt >= 1"),
    ('<variable name="Cnt"><type><INT/></type></variable>',
     '<variable name="Cnt"><type><INT/></type><initialValue><simpleValue value="40000"/></initialValue></variable>',
     "x.xml:23:67: error: the initial value '40000' of Cnt is not a value of its type INT (-32768..32767)"),
])
def test_what_an_internal_variable_cannot_be_is_located(old, new, first):
    text = (DATA / "beremiz_counter.xml").read_text()
    assert old in text
    with pytest.raises(InputError) as info:
        import_sfc(text.replace(old, new, 1).encode(), "x.xml")
    assert info.value.render().splitlines()[0] == first


def test_sfc_round_trip_of_internal_variables():
    """synth sfc writes INT locals documented 'internal 0..3' and P1/P0 bodies; import reads them back."""
    from synth.codegen.plcopen.export import sfc_project_xml

    g = load_grafcet(Path(__file__).resolve().parent.parent / "grafcets/tri_counting.g7")
    warnings: list[InputError] = []
    text = import_sfc(sfc_project_xml(g, version="test"), "x.xml", warnings=warnings)
    assert "\ninternal boxes : 0..3 = 0\n" in text
    assert "  step 2: boxes := 0 on deactivation\n" in text and text.count(": boxes := boxes + 1\n") == 2
    assert "  transition 1 -> 0 when !dcy & X100 & boxes < 3\n  transition 1 -> 2 when X100 & boxes >= 3\n" in text
    assert not [w for w in warnings if "boxes" in w.message]
    back = parse_grafcet(text, "x.g7")
    assert back.internals == g.internals


def test_codesys_step_timers_globals_and_data_of_step_actions():
    """CODESYS V3.5: TON T(IN:=TRUE, PT:=D); V := T.Q is the step timer, with IN:=c a two-step partial
    grafcet; GVL.x a flattened name (its reads the _fb input); an INT output and locals internal; an input the
    chart assigns its _out output."""
    warnings: list[InputError] = []
    text = import_sfc((DATA / "codesys_data.xml").read_bytes(), "codesys_data.xml", warnings=warnings)
    assert text.split("\n", 1)[1] == """inputs xPart, xGo, xStart, GVL_xBusy_fb
outputs Belt, GVL_xBusy, xStart_out
internal xSeen : bool = 0
internal nBoxes : 0..255 = 1
internal Pressure : -32768..32767 = 0

grafcet G1 {
  initial step Init
  step Count: nBoxes := nBoxes + 1, set GVL_xBusy, set Belt, set xSeen on ↑xPart, Pressure := 6000 on deactivation, \
reset xStart_out on deactivation
  step Settle
  step Check
  step Done: nBoxes := 0, reset GVL_xBusy
  transition Init -> Count when xStart & !GVL_xBusy_fb
  transition Count -> Settle when !xPart
  transition Settle -> Check when 50ms/XSettle & xSeen
  transition Check -> Done when 2s/XHold_on & nBoxes >= 3
  transition Done -> Init when nBoxes = 0
}
grafcet Hold_TON {
  initial step Hold_off
  step Hold_on
  transition Hold_off -> Hold_on when XCheck & xPart
  transition Hold_on -> Hold_off when !(XCheck & xPart)
}
"""
    assert [w.render().splitlines()[0] for w in warnings] == [
        "codesys_data.xml:109:1: warning: IF xPart in action Count_active (run while its step is active) is read as "
        "the stored action on the rising edge ↑xPart: if the condition already holds when the step becomes active, "
        "the PLC assigns at once and .g7 waits for the edge",
        "codesys_data.xml:128:61: warning: the TON Delay called with IN:=TRUE in action Settle_active of step Settle: "
        "Delay_Q is read as the step timer 50ms/XSettle (a TON keeps Q until it is called with IN FALSE; a .g7 timer "
        "restarts at each activation of its step)",
        "codesys_data.xml:137:61: warning: the TON Hold called with IN:=xPart in action Check_active of step Check: "
        "Hold_Q is read as 2s/XHold_on, the timer of step Hold_on of the partial grafcet Hold_TON, active while step "
        "Check is and xPart holds (a TON keeps Q until it is called with IN FALSE; a .g7 timer restarts at each "
        "activation of its step)",
        "codesys_data.xml:171:42: warning: the global GVL.xBusy is read here: .g7 names have no dot, so it is the "
        "input GVL_xBusy",
        "codesys_data.xml:60:13: warning: local variable xSeen (BOOL) of POU Sorter, assigned by its actions, is the "
        "internal variable xSeen : bool = 0",
        "codesys_data.xml:52:13: warning: local variable nBoxes (USINT) of POU Sorter, assigned by its actions, is the "
        "internal variable nBoxes : 0..255 = 1: give it the range it really has",
        "codesys_data.xml:100:1: warning: the global GVL.xBusy is assigned here: .g7 names have no dot, so it is the "
        "output GVL_xBusy",
        "codesys_data.xml:45:13: warning: output Pressure (INT) of POU Sorter, assigned by its actions, is the "
        "internal variable Pressure : -32768..32767 = 0: give it the range it really has (.g7 outputs are Boolean: "
        "it is not an output of the .g7)",
        "codesys_data.xml:120:1: warning: the chart assigns its input xStart: .g7 inputs are read only, so it assigns "
        "the output xStart_out (bind it to what writes xStart; transitions still read the input)",
        "codesys_data.xml:173:13: warning: GVL_xBusy is assigned by the imported chart and read by a transition: .g7 "
        "receptivities read inputs, so it reads the input GVL_xBusy_fb (bind it to the output's value)"]
    g = parse_grafcet(text, "sorter.g7")
    assert [t.id for t in g.timers] == ["2s/XHold_on", "50ms/XSettle"]


@pytest.mark.parametrize("old, new, first", [
    ("Belt := TRUE;", "nBoxes := nBoxes + 1;",
     "x.xml:108:61: error: nBoxes := nBoxes + 1 in action Count_active, run at every PLC scan while its step is "
     "active: .g7 assigns once, on activation, on deactivation or on an event (use P1 or P0, or IF condition THEN "
     "... END_IF)"),
    ("GVL.xBusy := TRUE;", "Motor.xBusy := TRUE;",
     "x.xml:100:1: error: Motor.xBusy is a member of the block instance Motor: .g7 holds this chart's variables, not "
     "another block's"),
    ("Delay(IN:=TRUE, PT:=Delay_PT);", "Delay(IN:=TRUE, PT:=Delay_Q);",
     "x.xml:128:61: error: a call of the block instance Delay in action Settle_active (Delay(IN:=TRUE, PT:=Delay_Q)): "
     ".g7 runs no function blocks (its timers time a step's activity: 2s/X1)"),
])
def test_what_a_codesys_data_body_cannot_be_is_located(old, new, first):
    text = (DATA / "codesys_data.xml").read_text()
    assert old in text
    with pytest.raises(InputError) as info:
        import_sfc(text.replace(old, new, 1).encode(), "x.xml")
    assert info.value.render().splitlines()[0] == first


def test_sel_r_trig_and_ton_blocks_wired_in_fbd_transitions():
    """FBD read as CODESYS calls it (while the transition is evaluated): SEL(auto, R_TRIG(step_btn).Q, go);
    TON(IN:=PRESSING, PT:=T#1500ms).Q with PRESSING only the continuous action of step Press: the step
    timer of Press (test_beremiz_blocks: the same file as Beremiz runs it)."""
    warnings: list[InputError] = []
    text = import_sfc(as_codesys((DATA / "beremiz_fbd_blocks.xml").read_text()).encode(), "b.xml", warnings=warnings)
    assert text.split("\n", 1)[1] == """inputs auto, go, step_btn
outputs PRESS, PRESSING

grafcet G1 {
  initial step Wait
  step Press: PRESS, PRESSING
  transition Wait -> Press when !auto & ↑step_btn | auto & go
  transition Press -> Wait when 1500ms/XPress
}
"""
    assert [w.render().splitlines()[0] for w in warnings] == [
        "b.xml:84:13: warning: R_TRIG R_TRIG0 is read as ↑step_btn: the PLC's instance remembers CLK from its last "
        "call (made while the transition is evaluated, i.e. while its step is active), so a change of CLK while the "
        "step was inactive is seen at its activation by the PLC, never by .g7",
        "b.xml:124:13: warning: the TON TON0 wired with IN:=PRESSING (only the continuous action of step Press: "
        "XPress) to the condition of a transition leaving step Press: TON0.Q is read as the step timer 1500ms/XPress "
        "(a TON keeps Q until it is called with IN FALSE; a .g7 timer restarts at each activation of its step)"]
    xml = as_codesys((DATA / "beremiz_fbd_blocks.xml").read_text()).replace("<expression>PRESSING</expression>",
                                                                             "<expression>go</expression>")
    text = import_sfc(xml.encode(), "b.xml")
    assert "  transition Press -> Wait when 1500ms/XTON0_on\n" in text
    assert "  transition TON0_off -> TON0_on when XPress & go\n  transition TON0_on -> TON0_off when !(XPress & go)\n" in text
    with pytest.raises(InputError) as info:
        import_sfc(xml.replace("<expression>T#1500ms</expression>", "<expression>Delay</expression>").encode(), "b.xml")
    assert info.value.render().splitlines()[0] == (
        "b.xml:119:13: error: the PT of TON TON0 is 'Delay': a step timer needs a constant duration such as T#2s")


def _crane(expression: str, *, by: str = "xDown") -> str:
    return (DATA / "codesys_v35.xml").read_text().replace(f"<expression>{by}</expression>",
                                                          f"<expression>{expression}</expression>", 1)


def test_xor_step_times_members_and_two_names_in_a_row_in_st_conditions():
    warnings: list[InputError] = []
    out = import_sfc(_crane("xDown XOR xGripOk").encode(), "x.xml", pou="Crane")
    assert "  transition Lower -> Init when (xDown & !xGripOk | !xDown & xGripOk) & !(xGripOk)\n" in out
    out = import_sfc(_crane("xDown XOR xGripOk AND xStart OR NOT xStart").encode(), "x.xml", pou="Crane")
    assert "when (xDown & !(xGripOk & xStart) | !xDown & (xGripOk & xStart) | !xStart) & !(xGripOk)\n" in out
    out = import_sfc(_crane("Lower.t &gt; T#2s").replace("<expression>xGripOk</expression>",
                                                         "<expression>T#5s &gt; Lower.T</expression>").encode(),
                     "x.xml", pou="Crane", warnings=warnings)
    assert "  transition Lower -> Init when (2s/XLower) & !(!5s/XLower)\n" in out
    assert [w.render().splitlines()[0] for w in warnings] == [
        "x.xml:66:15: warning: Lower.t > T#2s is read as 2s/XLower: > and >= differ only at the instant the step has "
        "been active exactly that long, the same at this abstraction (a step timer elapses once)",
        "x.xml:71:15: warning: T#5s > Lower.T is read as !5s/XLower: < and <= differ only at the instant the step "
        "has been active exactly that long, the same at this abstraction (a step timer elapses once)"]
    with pytest.raises(InputError) as info:
        import_sfc(_crane("Lower.t = T#2s").encode(), "x.xml", pou="Crane")
    assert info.value.render().splitlines()[0] == (
        "x.xml:66:35: error: a step time Lower.t is compared with '=': only < <= > >= with a duration have a "
        "step-timer meaning (D/XS, or its negation)")
    member = _crane("Motor.xReady", by="xStart AND NOT xDown").replace(
        '<variable name="xStart"><type><BOOL /></type></variable>',
        '<variable name="xStart"><type><BOOL /></type></variable>\n'
        '            <variable name="Motor"><type><derived name="FB_Motor" /></type></variable>', 1)
    warnings.clear()
    out = import_sfc(member.encode(), "x.xml", pou="Crane", warnings=warnings)
    assert "inputs xStart, xDown, xGripOk, Motor_xReady\n" in out and "  transition Init -> Lower when Motor_xReady\n" in out
    assert warnings[0].render().splitlines()[0] == (
        "x.xml:40:27: warning: Motor.xReady, a member of Motor (a variable of POU Crane), is read here: .g7 names "
        "have no dot, so it is the input Motor_xReady (bind it to the member's value)")
    with pytest.raises(InputError) as info:
        import_sfc(_crane("Power ON").encode(), "x.xml", pou="Crane")
    assert info.value.render().splitlines()[0] == (
        "x.xml:66:33: error: unexpected 'ON' in an ST condition: 'Power ON' is two names in a row, not an ST "
        "expression (an operator is missing)")


def test_non_numeric_local_ids_are_renumbered_when_unique():
    xml = (DATA / "beremiz_ld_fbd.xml").read_text().replace('localId="1" ', 'localId="idle" ').replace(
        '<connection refLocalId="1">', '<connection refLocalId="idle">')
    assert 'localId="idle"' in xml and 'refLocalId="idle"' in xml
    assert import_sfc(xml.encode(), "x.xml") == import_sfc((DATA / "beremiz_ld_fbd.xml").read_bytes(), "x.xml")
    with pytest.raises(InputError) as info:
        import_sfc(xml.replace('localId="4" ', 'localId="idle" ').encode(), "x.xml")
    assert info.value.render().splitlines()[0] == "x.xml:95:13: error: <step> with localId 'idle', which another element has"


def _counter(*pairs: tuple[str, str]) -> bytes:
    text = (DATA / "beremiz_counter.xml").read_text()
    for old, new in pairs:
        assert old in text
        text = text.replace(old, new, 1)
    return text.encode()


def test_constants_multi_statement_p1_bodies_and_a_step_left_at_the_first_scan():
    consts = ('          <localVars>\n', '          <localVars constant="true">\n            <variable name="Limit"><type>'
              '<INT/></type><initialValue><simpleValue value="3"/></initialValue></variable>\n          </localVars>\n'
              '          <localVars>\n')
    out = import_sfc(_counter(consts, ("3 <= Cnt", "Limit <= Cnt"), ("Cnt < 3", "Cnt < Limit"),
                              ("Cnt := 0;", "Cnt := Limit - 1; FULL := FALSE;")), "x.xml")
    assert "  step Full: FULL, Cnt := 3 - 1 on deactivation, reset FULL on deactivation\n" in out
    assert "  transition Count -> Full when !go & Cnt >= 3\n" in out and "  transition Count -> Start when !go & Cnt < 3\n" in out
    with pytest.raises(InputError) as info:
        import_sfc(_counter(("Cnt := 0;", "Cnt := Limit - 1;")), "x.xml")
    assert info.value.render().splitlines()[0] == (
        "x.xml:109:46: error: 'Limit' in the assignment to Cnt: .g7 adds integer internal variables and integer constants")
    warnings: list[InputError] = []
    out = import_sfc(_counter(('<action localId="0" qualifier="P1">', '<action localId="0">'),
                              ("NOT go AND 3 <= Cnt", "3 <= Cnt"),
                              ("NOT go AND Cnt < 3", "Cnt < 3")), "x.xml", warnings=warnings)
    assert "  step Count: Cnt := Cnt + 1\n" in out
    assert [w.render().splitlines()[0] for w in warnings if "first scan" in w.message] == [(
        "x.xml:66:39: warning: Cnt := Cnt + 1; in an N action runs at every PLC scan while step Count is active; the "
        "step is left at the first scan (its transitions' receptivities Cnt >= 3 | Cnt < 3 always hold), so it runs "
        "once: read as an assignment on activation")]


def test_a_ton_in_if_then_and_one_alias_timing_two_steps():
    text = (DATA / "codesys_data.xml").read_text()
    for old, new in [("Delay(IN:=TRUE, PT:=Delay_PT);\nDelay_Q := Delay.Q;", "Hold(IN:=TRUE, PT:=T#1S);\nHold_Q := Hold.Q;"),
                     ("Hold(IN:=xPart, PT:=T#2S);\nHold_Q := Hold.Q;",
                      "IF xPart = TRUE THEN\n  Hold(IN:=xPart, PT:=T#2S);\n  Hold_Q := Hold.Q;\nEND_IF"),
                     ("<expression>Delay_Q", "<expression>Hold_Q")]:
        assert old in text
        text = text.replace(old, new, 1)
    warnings: list[InputError] = []
    out = import_sfc(text.encode(), "x.xml", warnings=warnings)
    assert "  transition Settle -> Check when 1s/XSettle & xSeen\n  transition Check -> Done when 2s/XHold_Check_on & " \
           "nBoxes >= 3\n" in out
    assert "grafcet Hold_Check_TON {\n  initial step Hold_Check_off\n  step Hold_Check_on\n  transition Hold_Check_off -> " \
           "Hold_Check_on when XCheck & xPart\n" in out
    assert [w.render().splitlines()[0] for w in warnings][1:3] == [
        "x.xml:128:61: warning: the TON Hold called with IN:=TRUE in action Settle_active of step Settle: Hold_Q is read "
        "as the step timer 1s/XSettle in the transitions leaving step Settle (a TON keeps Q until it is called with IN "
        "FALSE; a .g7 timer restarts at each activation of its step)",
        "x.xml:138:3: warning: the TON Hold called with IN:=xPart in action Check_active of step Check: Hold_Q is read "
        "as 2s/XHold_Check_on, the timer of step Hold_Check_on of the partial grafcet Hold_Check_TON, active while step "
        "Check is and xPart holds in the transitions leaving step Check (a TON keeps Q until it is called with IN FALSE; "
        "a .g7 timer restarts at each activation of its step; the PLC calls it only while the IF condition holds, so it "
        "does not restart when the condition falls)"]


def test_an_sr_latch_an_ld_blinker_and_d_flags_are_helper_grafcets_and_step_timers():
    """Beremiz traffic-light shape, read as CODESYS calls the blocks (while the transition is
    evaluated): SR(S1:=btn, R:=HOLD.Q) feeding TON HOLD(IN:=SR.Q1) in an FBD transition (a loop
    through the latch), an LD action that blinks LAMP with two TONs and two R_TRIGs, a local
    Boolean that is only a D action, and a P action LAMP := 1."""
    warnings: list[InputError] = []
    text = import_sfc(as_codesys((DATA / "beremiz_latch_blink.xml").read_text()).encode(), "l.xml", warnings=warnings)
    assert text.split("\n", 1)[1] == """inputs go, btn
outputs LAMP

grafcet G1 {
  initial step Idle: set LAMP on activation
  step Run: reset LAMP
  transition Idle -> Run when go
  transition Run -> Idle when (2s/XHOLD_on) | (5s/XRun)
}
grafcet HOLD_TON {
  initial step HOLD_off
  step HOLD_on
  transition HOLD_off -> HOLD_on when XRun & XASKED_on
  transition HOLD_on -> HOLD_off when !(XRun & XASKED_on)
}
grafcet BLINK {
  initial step BLINK_off
  step BLINK_on: set LAMP on activation, reset LAMP on deactivation
  transition BLINK_off -> BLINK_on when XIdle & 700ms/XBLINK_off
  transition BLINK_on -> BLINK_off when XIdle & 300ms/XBLINK_on
}
grafcet ASKED_SR {
  initial step ASKED_off
  step ASKED_on
  transition ASKED_off -> ASKED_on when XRun & btn
  transition ASKED_on -> ASKED_off when XRun & 2s/XHOLD_on & !btn
}
"""
    assert [w.render().splitlines()[0] for w in warnings] == [
        "l.xml:184:15: warning: DONE, a local Boolean that is only the action D T#5s of step Run, is read as the step "
        "timer 5s/XRun: IEC 61131-3 makes it TRUE from 5s after the step's activation until its deactivation, as the "
        "timer (on MATIEC, the compiler of Beremiz and OpenPLC, it turns TRUE one scan after the timer)",
        "l.xml:47:17: warning: the LD action BLINK (run while XIdle holds) blinks LAMP: T_OFF (IN:=NOT LAMP, "
        "PT:=T#700ms) sets it on the rising edge of its Q (R_TRIG UP), T_ON (IN:=LAMP, PT:=T#300ms) resets it on the "
        "rising edge of its Q (R_TRIG DOWN); read as the partial grafcet BLINK, whose steps "
        "BLINK_off and BLINK_on (LAMP set on its activation, reset on its deactivation) alternate after 700ms and "
        "300ms while XIdle holds (the PLC's phase is LAMP itself, which other steps may set or reset; the grafcet's "
        "phase is its step, and its timers run while the action is not called, as a TON called again with IN still "
        "TRUE counts from when IN rose)",
        "l.xml:198:13: warning: the TON HOLD wired with IN:=XASKED_on to the condition of a transition leaving step "
        "Run: HOLD.Q is read as 2s/XHOLD_on, the timer of step HOLD_on of the partial grafcet HOLD_TON, active while "
        "step Run is and XASKED_on holds (a TON keeps Q until it is called with IN FALSE; a .g7 timer restarts at "
        "each activation of its step)",
        "l.xml:229:13: warning: the SR ASKED wired to the condition of a transition leaving step Run: ASKED.Q1 is read "
        "as XASKED_on, the activity of step ASKED_on of the partial grafcet ASKED_SR, set when XRun & btn and reset "
        "when XRun & 2s/XHOLD_on & !btn (set dominant: Q1 := S1 OR (NOT R AND Q1)); the PLC calls ASKED only while "
        "the transition is evaluated and reads the outputs of the blocks it calls after the latch from the previous "
        "scan, .g7 sets and resets the latch in the evolution where its conditions hold (one scan earlier)"]
    ass = _ass(parse_grafcet(text, "l.g7"))
    assert len(ass["states"]) == 14
    assert ass["states"][0]["situation"] == ["ASKED_off", "BLINK_off", "HOLD_off", "Idle"]
    assert ass["states"][0]["stored"] == ["LAMP"]
    assert [(t["event"], t["condition"]) for t in ass["transitions"] if t["source"] == 0] == [
        ("↑go", "!btn"), ("↑go", "btn"), ("700ms/XBLINK_off", "any")]
    held = [s["situation"] for s in ass["states"] if "HOLD_on" in s["situation"]]
    assert held and all("Run" in s and "ASKED_on" in s for s in held)  # the TON runs while Run and the latch hold


def test_an_rs_latch_is_reset_dominant():
    xml = as_codesys((DATA / "beremiz_latch_blink.xml").read_text())
    rs = xml.replace('typeName="SR"', 'typeName="RS"').replace('formalParameter="S1"', 'formalParameter="S"') \
        .replace('<variable formalParameter="R">', '<variable formalParameter="R1">')
    warnings: list[InputError] = []
    text = import_sfc(rs.encode(), "l.xml", warnings=warnings)
    assert text.endswith("""grafcet ASKED_RS {
  initial step ASKED_off
  step ASKED_on
  transition ASKED_off -> ASKED_on when XRun & btn & !2s/XHOLD_on
  transition ASKED_on -> ASKED_off when XRun & 2s/XHOLD_on
}
""")
    assert "(reset dominant: Q1 := NOT R1 AND (S OR Q1))" in warnings[-1].message
    parse_grafcet(text, "l.g7")


@pytest.mark.parametrize("old, new, first", [
    ('<variable formalParameter="R">', '<variable formalParameter="X">',
     "l.xml:229:13: error: an FBD SR block without its input R"),
    ('<variable>LAMP</variable>\n                </coil>\n                <rightPowerRail localId="14"',
     '<variable>GO</variable>\n                </coil>\n                <rightPowerRail localId="14"',
     "l.xml:166:15: error: action BLINK referenced here has an LD body that is not a blinker run by an N action (two "
     "TONs that set and reset one variable, each timing its other value): .g7 reads the ST bodies' Boolean "
     "assignments"),
    ('<expression>T#300ms</expression>', '<expression>Delay</expression>',
     "l.xml:166:15: error: action BLINK referenced here has an LD body that is not a blinker run by an N action (two "
     "TONs that set and reset one variable, each timing its other value): .g7 reads the ST bodies' Boolean "
     "assignments"),
    ('<action localId="0"><relPosition x="0" y="0"/><reference name="BLINK"/>',
     '<action localId="0" qualifier="S"><relPosition x="0" y="0"/><reference name="BLINK"/>',
     "l.xml:166:15: error: action BLINK referenced here has an LD body that is not a blinker run by an N action (two "
     "TONs that set and reset one variable, each timing its other value): .g7 reads the ST bodies' Boolean "
     "assignments"),
])
def test_what_is_not_a_latch_or_a_blinker_is_located(old, new, first):
    xml = (DATA / "beremiz_latch_blink.xml").read_text()
    assert xml.count(old) == 1
    with pytest.raises(InputError) as info:
        import_sfc(xml.replace(old, new).encode(), "l.xml")
    assert info.value.render().splitlines()[0] == first


def _ide_sfc_with_priorities(first: str, second: str) -> bytes:
    root = Path(__file__).resolve().parent / "data" / "codegen"
    text = (root / "ide_sfc.xml").read_text()
    assert text.count('<transition localId="17">') == 1 and text.count('<transition localId="18">') == 1
    return (text.replace('<transition localId="17">', f'<transition localId="17" priority="{first}">')
            .replace('<transition localId="18">', f'<transition localId="18" priority="{second}">').encode())


def test_a_selection_divergence_honours_the_transitions_priorities():
    # the right branch (guard) has priority 1, the left one (2s/XWait) priority 2: the PLC tests guard first
    warnings: list[InputError] = []
    text = import_sfc(_ide_sfc_with_priorities("2", "1"), "prio.xml", warnings=warnings)
    assert "  transition Wait -> Up when (2s/XWait) & !(guard)\n  transition Wait -> Up when guard\n" in text
    assert [w.render().splitlines()[0] for w in warnings] == [
        "prio.xml:154:13: warning: a selection divergence: IEC 61131-3 SFC fires the true branch of highest priority "
        "(smallest `priority`, then left to right), .g7 every true branch; the later branches' receptivities are "
        "made exclusive", LAMP_HELD[0].replace("ide_sfc.xml", "prio.xml")]
    assert warnings[0].render().splitlines()[-2] == "  = note: Wait -> Up when (2s/XWait) & !(guard)"


def test_equal_priorities_fall_back_to_the_branch_order():
    text = import_sfc(_ide_sfc_with_priorities("1", "1"), "prio.xml", warnings=[])
    assert "  transition Wait -> Up when 2s/XWait\n  transition Wait -> Up when (guard) & !(2s/XWait)\n" in text


@pytest.mark.parametrize("bad", ["-1", "high", "1" * 30])
def test_a_priority_that_is_not_a_number_is_located(bad):
    with pytest.raises(InputError) as info:
        import_sfc(_ide_sfc_with_priorities(bad, "1"), "prio.xml", warnings=[])
    assert info.value.render().splitlines()[0] == (
        f"prio.xml:160:13: error: transition priority '{bad[:40]}' is not a non-negative integer")


def test_an_n_assignment_with_its_p0_reset_is_continuous_without_a_warning():
    """synth sfc writes `A if c` as N `A := c;` and P0 `A := FALSE;`: the pair is the continuous
    action on the PLC too, so no warning; without the P0 body the PLC keeps A (warning above)."""
    root = Path(__file__).resolve().parent / "data" / "codegen"
    text = (root / "ide_sfc.xml").read_text()
    p0 = ('<action localId="12" qualifier="N">',
          '<action localId="90" qualifier="P0"><inline><ST><xhtml:p><![CDATA[LAMP := FALSE;]]></xhtml:p></ST>'
          '</inline></action><action localId="12" qualifier="N">')
    assert text.count(p0[0]) == 1
    warnings: list[InputError] = []
    g7 = import_sfc(text.replace(*p0).encode(), "ide_sfc.xml", warnings=warnings)
    assert "LAMP if !bottom" in g7 and "reset LAMP on deactivation" not in g7
    assert [w.render().splitlines()[0].split(": warning: ")[1][:24] for w in warnings] == ["a selection divergence: "]


@pytest.mark.parametrize("value, action", [("TRUE", "set LAMP on activation"), ("0", "reset LAMP on activation")])
def test_an_n_assignment_of_a_constant_is_a_stored_action(value, action):
    """`pump := 1;` in an N action: the PLC sets it while the step is active and keeps it after;
    not the continuous `pump if 1` (which ends with the step), nor `pump if 0` (a no-op)."""
    root = Path(__file__).resolve().parent / "data" / "codegen"
    text = (root / "ide_sfc.xml").read_text()
    assert text.count("LAMP := NOT bottom;") == 1
    warnings: list[InputError] = []
    g7 = import_sfc(text.replace("LAMP := NOT bottom;", f"LAMP := {value};").encode(), "ide_sfc.xml",
                    warnings=warnings)
    assert f"step Lamp: {action}" in g7 and "LAMP if" not in g7
    assert len(warnings) == 1  # the selection divergence's alone


def test_codesys_implicit_chart_flags_are_named_not_silently_dropped():
    """CODESYS's SFCReset/SFCInit/SFCPause (declared in the POU, set by the caller on an emergency
    stop) force the chart on the PLC; the .g7 has no such forcing: a located warning each."""
    text = (DATA / "codesys_v35.xml").read_text()
    old = '            <variable name="xGripOk"><type><BOOL /></type></variable>\n          </inputVars>\n'
    assert text.count(old) == 1
    flags = ('            <variable name="SFCReset"><type><BOOL /></type></variable>\n'
             '            <variable name="SFCError"><type><BOOL /></type></variable>\n')
    warnings: list[InputError] = []
    import_sfc(text.replace(old, old.replace("          </inputVars>\n", flags + "          </inputVars>\n")).encode(),
               "flags.xml", pou="Crane", warnings=warnings)
    found = [w.render().splitlines() for w in warnings if "implicit SFC flag" in w.render()]
    assert found == [[
        "flags.xml:25:13: warning: 'SFCReset' is CODESYS's implicit SFC flag: on the PLC it puts the chart back to its "
        "initial step while it is TRUE; the .g7 has no such forcing, so the import reads it as a plain variable and "
        "the chart ignores it",
        '  25 |             <variable name="SFCReset"><type><BOOL /></type></variable>',
        "     |             ^~~~~~~~~",
        "  = note: validate the emergency stop separately, or model it as transitions back to the initial steps "
        "guarded by the flag"]]


def test_several_pous_keep_their_own_variables():
    """Two POUs declaring the same names (two cranes) imported whole: each keeps its own
    variables on the PLC, so each chart's are prefixed, with a warning at each declaration."""
    lines = (DATA / "codesys_v35.xml").read_text().splitlines(keepends=True)
    assert lines[18].strip() == '<pou name="Crane" pouType="program">' and lines[102].strip() == "</pou>"
    crane2 = "".join(lines[18:103]).replace('<pou name="Crane"', '<pou name="Crane2"')
    xml = "".join(lines[:103]) + crane2 + "".join(lines[103:])
    warnings: list[InputError] = []
    g7 = import_sfc(xml.encode(), "cranes.xml", warnings=warnings)
    assert g7.splitlines()[1:3] == [
        "inputs Crane_xStart, Crane_xDown, Crane_xGripOk, Crane2_xStart, Crane2_xDown, Crane2_xGripOk, xPart",
        "outputs Crane_LOWER, Crane2_LOWER, MOTOR"]
    assert "  transition Crane2_Init -> Crane2_Lower when Crane2_xStart & !Crane2_xDown\n" in g7
    assert "  step Crane2_Lower: Crane2_LOWER\n" in g7 and "  step Belt_Run: MOTOR\n" in g7
    own = [w.render().splitlines()[0] for w in warnings if "each has its own" in w.render()]
    assert len(own) == 8 and own[0] == (
        "cranes.xml:22:13: warning: 'xStart' is declared by POU Crane and by Crane2: each has its own on the PLC, "
        "so this chart's is named Crane_xStart in the .g7")
    parse_grafcet(g7, "cranes.g7")  # a valid .g7


LD_OFF = """<LD>
                <leftPowerRail localId="40"><connectionPointOut formalParameter=""/></leftPowerRail>
                <contact localId="41" negated="{negated}">
                  <connectionPointIn><connection refLocalId="40"/></connectionPointIn>
                  <connectionPointOut/>
                  <variable>c</variable>
                </contact>
                <coil localId="44" negated="false">
                  <connectionPointIn><connection refLocalId="41"/></connectionPointIn>
                  <connectionPointOut/>
                  <variable>OFF</variable>
                </coil>
              </LD>"""


@pytest.mark.parametrize("negated, expr", [("true", "!c"), ("false", "c")])
def test_a_named_transition_written_in_ld_is_read(negated, expr):
    """OpenPLC writes a named transition's body in LD: a coil named after the transition."""
    text = (DATA / "beremiz_ld_fbd.xml").read_text()
    start, end = text.index("<FBD>"), text.index("</FBD>") + len("</FBD>")
    g7 = import_sfc((text[:start] + LD_OFF.format(negated=negated) + text[end:]).encode(), "ld.xml")
    assert f"  transition On -> Idle when {expr}\n" in g7


def test_a_named_transition_body_without_its_name_is_read():
    """`:= c;` (the transition's name left out) as well as `OFF := c;`."""
    text = (DATA / "beremiz_ld_fbd.xml").read_text()
    start, end = text.index("<FBD>"), text.index("</FBD>") + len("</FBD>")
    st = '<ST><xhtml:p xmlns:xhtml="http://www.w3.org/1999/xhtml"><![CDATA[:= NOT c;]]></xhtml:p></ST>'
    g7 = import_sfc((text[:start] + st + text[end:]).encode(), "st.xml")
    assert "  transition On -> Idle when !c\n" in g7


def test_tc6_1_0_condition_connected_without_connection_point():
    """TC6 1.0 files wire a condition as <condition><connection refLocalId=…/></condition>."""
    text = (DATA / "beremiz_tc6_1_0.xml").read_text()
    old = '<connectionPointIn><connection refLocalId="22"><position x="559" y="109"/><position x="401" y="109"/></connection></connectionPointIn>'
    assert text.count(old) == 1
    g7 = import_sfc(text.replace(old, '<connection refLocalId="22"/>').encode(), "tc6.xml")
    assert "  transition Idle -> On when (a) & !b\n" in g7


def test_two_statements_in_an_inline_n_action_are_stored_actions():
    root = Path(__file__).resolve().parent / "data" / "codegen"
    text = (root / "ide_sfc.xml").read_text()
    assert text.count("LAMP := NOT bottom;") == 1
    g7 = import_sfc(text.replace("LAMP := NOT bottom;", "LAMP := TRUE; BUSY := FALSE;").encode(), "x.xml")
    assert "  step Lamp: set LAMP, reset BUSY\n" in g7
    with pytest.raises(InputError) as info:
        import_sfc(text.replace("LAMP := NOT bottom;", "LAMP := NOT bottom; BUSY := TRUE;").encode(), "x.xml")
    assert info.value.render().splitlines()[0].startswith(
        "x.xml:134:90: error: a statement of action N (inline) that .g7 cannot hold (LAMP := NOT bottom)")


def test_the_scan_note_says_when_it_is_not_computed(cli, tmp_path):
    """The import's note on steps a PLC keeps for a scan explores both readings within a small
    budget; past it, the note says it was not checked instead of disappearing."""
    lines = ["inputs " + ", ".join(f"a{i}" for i in range(12)), "outputs " + ", ".join(f"Q{i}" for i in range(12))]
    lines += [f"grafcet G{i} {{ initial step {i}0 step {i}1: Q{i} transition {i}0 -> {i}1 when a{i} "
              f"transition {i}1 -> {i}0 when !a{i} }}" for i in range(12)]  # 4 096 situations
    (tmp_path / "wide.g7").write_text("\n".join(lines) + "\n")
    assert cli("sfc", tmp_path / "wide.g7", "-o", tmp_path / "wide.xml")[0] == 0
    code, _, err = cli("import", tmp_path / "wide.xml", "-o", tmp_path / "back.g7")
    assert code == 0 and err == (
        f"{tmp_path / 'wide.xml'}: note: not checked whether some steps stay active for a PLC scan where IEC 60848 "
        "passes through them (more than 2000 situations or 8000 reactions to explore): validate with --semantics sfc "
        "for the meaning the program has on the PLC\n")


def test_the_scan_note_has_a_budget_of_reactions_too():
    """Partial grafcets over many inputs (the blocks of a Beremiz chart) make each situation
    costly: the note also stops after IMPORT_REACTIONS runs of the machine per reading."""
    from synth.errors import LimitExceeded
    from synth.grafcet.semantics import scan_only_steps

    g = parse_grafcet("inputs a, b\ngrafcet G { initial step 0 step 1 transition 0 -> 1 when a & b "
                      "transition 1 -> 0 when !a }\n", "n.g7")
    assert scan_only_steps(g) == ()
    with pytest.raises(LimitExceeded, match="more than 3 reactions while building the ASS"):
        scan_only_steps(g, max_reactions=3)


def test_import_list_says_refused_for_a_pou_the_import_refuses(cli, tmp_path):
    text = (DATA / "codesys_v35.xml").read_text()
    assert text.count("<expression>xStart AND NOT xDown</expression>") == 1
    (tmp_path / "p.xml").write_text(text.replace("xStart AND NOT xDown", "xStart AND NOT xNowhere"))
    code, out, _ = cli("import", "--list", tmp_path / "p.xml")
    assert code == 0 and out.splitlines() == [
        "Crane\tprogram\tSFC\tnot imported: refused: a transition reads 'xNowhere', which the POU Crane does not "
        "declare",
        "Belt\tprogram\tSFC\timported",
        "PLC_PRG\tprogram\tST\tnot imported: an ST body: .g7 holds SFC charts only"]
