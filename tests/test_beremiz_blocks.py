"""Blocks wired in a transition network of a file Beremiz wrote, read as Beremiz runs them
(issue 35, item 2): its generator calls them at every scan, after the transitions, from an S
action on the initial step (``COMPUTE_FUNCTION_BLOCKS``), so each is a partial grafcet of its
states read one scan late; a CODESYS file keeps the reading "called while the transition is
evaluated". The fixtures are written here in Beremiz's shape (TC6 2.01, its default
``fileHeader``); where Beremiz, MATIEC and gcc are here, each is built by Beremiz's generator,
compiled and run scan by scan against ``synth run --semantics sfc`` of its import."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from beremiz import find_beremiz
from iec2c import find_iec2c
from test_plcopen_dialects import as_codesys
from test_sfc_beremiz import SCANS, SEQUENCES, Outcome, PlcProgram, beremiz_text, play
from synth.codegen.st import PouKind
from synth.codegen.plcopen.importer import import_sfc
from synth.codegen.plcopen.vendor import Dialect, dialect_of
from synth.errors import InputError
from synth.grafcet.language_check import parse_grafcet

DATA = Path(__file__).resolve().parent / "data" / "plcopen"

HEAD = """<?xml version='1.0' encoding='utf-8'?>
<project xmlns:ns1="http://www.plcopen.org/xml/tc6_0201" xmlns:xhtml="http://www.w3.org/1999/xhtml" xmlns:xsd="http://www.w3.org/2001/XMLSchema" xmlns="http://www.plcopen.org/xml/tc6_0201">
  <fileHeader companyName="Unknown" productName="Unnamed" productVersion="1" creationDateTime="2024-05-02T10:00:00"/>
  <contentHeader name="Unnamed" modificationDateTime="2024-05-02T10:05:00">
    <coordinateInfo>
      <fbd><scaling x="0" y="0"/></fbd>
      <ld><scaling x="0" y="0"/></ld>
      <sfc><scaling x="0" y="0"/></sfc>
    </coordinateInfo>
  </contentHeader>
  <types>
    <dataTypes/>
    <pous>
      <pou name="cell" pouType="program">
        <interface>
          <inputVars>
            <variable name="go"><type><BOOL/></type></variable>
            <variable name="btn"><type><BOOL/></type></variable>
          </inputVars>
          <outputVars>
            <variable name="RUN"><type><BOOL/></type></variable>
          </outputVars>
          <localVars>
%s
          </localVars>
        </interface>
        <body>
          <SFC>
%%STEPS%%
            <jumpStep localId="8" height="13" width="12" targetName="Idle">
              <position x="563" y="200"/>
              <connectionPointIn><relPosition x="6" y="0"/><connection refLocalId="5"/></connectionPointIn>
            </jumpStep>
%s
          </SFC>
        </body>
      </pou>
    </pous>
  </types>
  <instances>
    <configurations>
      <configuration name="config">
        <resource name="resource1">
          <task name="task0" priority="0" interval="T#7ms">
            <pouInstance name="instance0" typeName="cell"/>
          </task>
        </resource>
      </configuration>
    </configurations>
  </instances>
</project>
"""


def step(lid: int, name: str, source: int, y: int, initial: bool = False, actions: bool = False) -> str:
    first = ' initialStep="true"' if initial else ""
    more = ('\n              <connectionPointOutAction formalParameter=""><relPosition x="80" y="15"/>'
            "</connectionPointOutAction>") if actions else ""
    return (f'            <step localId="{lid}" height="30" width="80" name="{name}"{first}>\n'
            f'              <position x="500" y="{y}"/>\n'
            f'              <connectionPointIn><relPosition x="40" y="0"/><connection refLocalId="{source}"/>'
            "</connectionPointIn>\n"
            '              <connectionPointOut formalParameter=""><relPosition x="40" y="30"/></connectionPointOut>'
            f"{more}\n            </step>")


def transition(lid: int, source: int, y: int) -> str:
    """A transition whose condition is wired to the network (``%s``: the element it reads)."""
    return (f'            <transition localId="{lid}" height="2" width="20">\n              <position x="560" y="{y}"/>\n'
            f'              <connectionPointIn><relPosition x="10" y="0"/><connection refLocalId="{source}"/>'
            "</connectionPointIn>\n"
            '              <connectionPointOut><relPosition x="10" y="2"/></connectionPointOut>\n'
            "              <condition>\n"
            '                <connectionPointIn><connection refLocalId="%s"/></connectionPointIn>\n'
            "              </condition>\n            </transition>")


ACTIONS = """            <actionBlock localId="4" height="30" width="100">
              <position x="650" y="100"/>
              <connectionPointIn><relPosition x="0" y="15"/><connection refLocalId="3"/></connectionPointIn>
              <action localId="0"><relPosition x="0" y="0"/><reference name="RUN"/></action>
            </actionBlock>"""
HEAD = HEAD.replace("%%STEPS%%", "\n".join(
    (step(1, "Idle", 8, 10, initial=True), transition(2, 1, 60), step(3, "Busy", 2, 100, actions=True), ACTIONS,
     transition(5, 3, 160))))


def invar(lid: int, expression: str) -> str:
    return (f'            <inVariable localId="{lid}" height="30" width="60" negated="false">\n'
            f'              <position x="100" y="{lid * 10}"/>\n'
            '              <connectionPointOut><relPosition x="60" y="15"/></connectionPointOut>\n'
            f"              <expression>{expression}</expression>\n            </inVariable>")


def block(lid: int, kind: str, instance: str | None, inputs: list[tuple[str, str]], output: str) -> str:
    """A block ``kind`` whose inputs (formal parameter, ``localId`` or ``localId.Output``) are wired."""
    name = f' instanceName="{instance}"' if instance else ""
    ins = "".join(
        f'                <variable formalParameter="{p}">\n                  <connectionPointIn><relPosition x="0" '
        f'y="30"/><connection refLocalId="{ref.split(".")[0]}"'
        + (f' formalParameter="{ref.split(".")[1]}"' if "." in ref else "") + "/></connectionPointIn>\n"
        "                </variable>\n" for p, ref in inputs)
    return (f'            <block localId="{lid}" typeName="{kind}"{name} height="80" width="70">\n'
            f'              <position x="300" y="{lid * 10}"/>\n              <inputVariables>\n{ins}'
            "              </inputVariables>\n              <inOutVariables/>\n              <outputVariables>\n"
            f'                <variable formalParameter="{output}"><connectionPointOut><relPosition x="70" y="30"/>'
            "</connectionPointOut></variable>\n              </outputVariables>\n            </block>")


def project(instances: dict[str, str], to_run: str, to_idle: str, *network: str) -> str:
    """The chart Idle -> Busy -> Idle (RUN while Busy), its two transitions wired to ``to_run`` and
    ``to_idle`` (``localId`` or ``localId.Output``), with the FB instances and the network."""
    local = "\n".join(f'            <variable name="{n}"><type><derived name="{t}"/></type></variable>'
                      for n, t in instances.items())

    def wire(ref: str) -> str:
        return ref.split(".")[0] + (f'" formalParameter="{ref.split(".")[1]}' if "." in ref else "")

    text = HEAD % (local, wire(to_run), wire(to_idle), "\n".join(network))
    return re.sub(r'<connection (refLocalId="\d+"(?: formalParameter="\w+")?)/>',  # Beremiz draws each link
                  r'<connection \1><position x="0" y="0"/><position x="0" y="0"/></connection>', text)


R_TRIG = project({"R_TRIG0": "R_TRIG"}, "20.Q", "11",
                 invar(10, "btn"), invar(11, "NOT go"), block(20, "R_TRIG", "R_TRIG0", [("CLK", "10")], "Q"))
"""Idle -> Busy on a rising edge of btn (an R_TRIG), Busy -> Idle when go is FALSE."""

SR = project({"SR0": "SR"}, "20.Q1", "12",
             invar(10, "btn"), invar(11, "go"), invar(12, "NOT btn AND NOT go"),
             block(20, "SR", "SR0", [("S1", "10"), ("R", "11")], "Q1"))
"""Idle -> Busy while the latch SR0 (set by btn, reset by go) holds; Busy -> Idle when neither."""

TON = project({"TON0": "TON", "TON1": "TON"}, "30.OUT", "21.Q",
              invar(10, "TRUE"), invar(11, "T#100ms"), invar(12, "btn"), invar(13, "T#50ms"), invar(14, "go"),
              block(20, "TON", "TON0", [("IN", "10"), ("PT", "11")], "Q"),
              block(21, "TON", "TON1", [("IN", "12"), ("PT", "13")], "Q"),
              block(30, "AND", None, [("IN1", "20.Q"), ("IN2", "14")], "OUT"))
"""Idle -> Busy when TON0 (IN TRUE: 100 ms after the first scan) and go; Busy -> Idle when btn has
been held 50 ms (TON1, called at every scan, whatever the step)."""

PREFIX = 'a transition network of a file written by Beremiz or the OpenPLC editor (fileHeader companyName="Unknown" '\
         'productName="Unnamed"): Beremiz calls it at every scan whatever the active steps, after the transitions ' \
         "(its action COMPUTE_FUNCTION_BLOCKS, stored on the initial step), so a transition reads its output of the " \
         "previous scan; "


def imported(xml: str) -> tuple[str, list[str]]:
    warnings: list[InputError] = []
    text = import_sfc(xml.encode(), "b.xml", warnings=warnings)
    parse_grafcet(text, "b.g7")
    return text.split("\n", 1)[1], [w.render().splitlines()[0] for w in warnings]


CHART = """inputs go, btn
outputs RUN

grafcet G1 {
  initial step Idle
  step Busy: RUN
  transition Idle -> Busy when %s
  transition Busy -> Idle when %s
}
"""


def test_an_r_trig_is_the_scan_after_clk_rose_whatever_the_step():
    text, warnings = imported(R_TRIG)
    assert text == CHART % ("XR_TRIG0_q", "!go") + """grafcet R_TRIG0_R_TRIG {
  initial step R_TRIG0_off
  step R_TRIG0_q
  step R_TRIG0_held
  transition R_TRIG0_off -> R_TRIG0_q when btn
  transition R_TRIG0_q -> R_TRIG0_held when btn
  transition R_TRIG0_q -> R_TRIG0_off when !btn
  transition R_TRIG0_held -> R_TRIG0_off when !btn
}
"""
    assert warnings == [
        "b.xml:75:13: warning: the R_TRIG R_TRIG0 in " + PREFIX + "read as the partial grafcet R_TRIG0_R_TRIG, whose "
        "step R_TRIG0_q is R_TRIG0.Q: CLK (btn) rose at the previous scan (the PLC's first call sees CLK TRUE as a "
        "rising edge, so does the grafcet)"]
    assert "remembers CLK" not in " ".join(warnings)


def test_an_sr_latch_evolves_at_every_scan_unguarded_by_a_step():
    text, warnings = imported(SR)
    assert text == CHART % ("XSR0_on", "!btn & !go") + """grafcet SR0_SR {
  initial step SR0_off
  step SR0_on
  transition SR0_off -> SR0_on when btn
  transition SR0_on -> SR0_off when go & !btn
}
"""
    assert warnings == [
        "b.xml:80:13: warning: the SR SR0 in " + PREFIX + "read as the partial grafcet SR0_SR (SR0.Q1 is XSR0_on: set "
        "when btn, reset when go & !btn, set dominant)"]


def test_a_ton_of_true_starts_at_the_first_scan_and_a_ton_of_an_input_times_it_at_every_scan():
    text, warnings = imported(TON)
    assert text == CHART % ("XAND30_on", "XTON1_q") + """grafcet TON0_TON {
  initial step TON0_off
  step TON0_timing
  step TON0_q
  transition TON0_off -> TON0_timing when 1
  transition TON0_timing -> TON0_q when 100ms/XTON0_timing
}
grafcet AND30 {
  initial step AND30_off
  step AND30_on
  transition AND30_off -> AND30_on when (XTON0_timing & 100ms/XTON0_timing | XTON0_q) & go
  transition AND30_on -> AND30_off when !((XTON0_timing & 100ms/XTON0_timing | XTON0_q) & go)
}
grafcet TON1_TON {
  initial step TON1_off
  step TON1_timing
  step TON1_q
  transition TON1_off -> TON1_timing when btn
  transition TON1_timing -> TON1_off when !btn
  transition TON1_timing -> TON1_q when btn & 50ms/XTON1_timing
  transition TON1_q -> TON1_off when !btn
}
"""
    assert warnings == [
        "b.xml:91:13: warning: the TON TON0 in " + PREFIX + "read as the partial grafcet TON0_TON: IN is TRUE: a timer "
        "started at the first call, step TON0_timing from the scan IN (1) rises, step TON0_q (TON0.Q) once 100ms have "
        "elapsed, both left when IN falls",
        "b.xml:121:13: warning: the AND AND30 in " + PREFIX + "read as the partial grafcet AND30, whose step AND30_on "
        "is active when (XTON0_timing & 100ms/XTON0_timing | XTON0_q) & go held at the previous scan",
        "b.xml:106:13: warning: the TON TON1 in " + PREFIX + "read as the partial grafcet TON1_TON: step TON1_timing "
        "from the scan IN (btn) rises, step TON1_q (TON1.Q) once 50ms have elapsed, both left when IN falls"]


def test_a_codesys_file_keeps_the_reading_called_while_the_transition_is_evaluated():
    text, warnings = imported(as_codesys(R_TRIG))
    assert text == CHART % ("↑btn", "!go")
    assert warnings[0].startswith("b.xml:75:13: warning: R_TRIG R_TRIG0 is read as ↑btn: the PLC's instance remembers "
                                  "CLK from its last call")
    text, _ = imported(as_codesys(SR))
    assert "  transition SR0_off -> SR0_on when XIdle & btn\n" in text  # called only while Idle is active


@pytest.mark.parametrize("header, dialect", [
    ('companyName="Unknown" productName="Unnamed"', Dialect.BEREMIZ),  # Beremiz's and the OpenPLC editor's defaults
    ('companyName="Beremiz" productName="Unnamed"', Dialect.BEREMIZ),  # Beremiz's own examples
    ('companyName="Acme" productName="OpenPLC line 3"', Dialect.BEREMIZ),
    ('companyName="" productName="CODESYS"', Dialect.CODESYS),
    ('companyName="Beckhoff Automation GmbH" productName="TwinCAT PLC Control"', Dialect.CODESYS),
    ('companyName="Acme" productName="Line 3"', Dialect.OTHER),
])
def test_the_tool_that_wrote_the_file_is_read_from_its_file_header(header, dialect):
    from lxml import etree

    root = etree.fromstring(R_TRIG.replace('companyName="Unknown" productName="Unnamed"', header).encode())
    found = dialect_of(root, lambda tag: f"{{http://www.plcopen.org/xml/tc6_0201}}{tag}")
    assert found == (dialect, f"fileHeader {header}")


FIRST = project({"R_TRIG0": "R_TRIG"}, "12", "20.Q", invar(10, "btn"), invar(12, "go"),
                block(20, "R_TRIG", "R_TRIG0", [("CLK", "10")], "Q"))
"""Idle -> Busy on go (an inVariable: it may fire at the first scan), Busy -> Idle on R_TRIG0(btn)."""


def test_blocks_wait_for_the_initial_step_to_stay_active_after_a_scan():
    """Beremiz's S action COMPUTE_FUNCTION_BLOCKS is stored at the end of a scan after which its
    initial step is active: when Idle is left at the first scan, no block runs until Idle is
    active again after a scan."""
    text, warnings = imported(FIRST)
    guard = "(XCOMPUTE_FUNCTION_BLOCKS_on | XIdle & !(XIdle & go) | XBusy & XR_TRIG0_q)"
    assert text == CHART % ("go", "XR_TRIG0_q") + f"""grafcet R_TRIG0_R_TRIG {{
  initial step R_TRIG0_off
  step R_TRIG0_q
  step R_TRIG0_held
  transition R_TRIG0_off -> R_TRIG0_q when {guard} & btn
  transition R_TRIG0_q -> R_TRIG0_held when {guard} & btn
  transition R_TRIG0_q -> R_TRIG0_off when {guard} & !btn
  transition R_TRIG0_held -> R_TRIG0_off when {guard} & !btn
}}
grafcet COMPUTE_FUNCTION_BLOCKS {{
  initial step COMPUTE_FUNCTION_BLOCKS_off
  step COMPUTE_FUNCTION_BLOCKS_on
  transition COMPUTE_FUNCTION_BLOCKS_off -> COMPUTE_FUNCTION_BLOCKS_on when XIdle & !(XIdle & go) | XBusy & XR_TRIG0_q
}}
"""
    assert warnings[0] == (
        "b.xml:29:13: warning: Beremiz stores COMPUTE_FUNCTION_BLOCKS (the blocks of the transition networks) on "
        "initial step Idle: the PLC calls them at the end of each scan after which Idle is active, then at every scan; "
        "a transition leaving Idle may fire at the first scan (go), so the blocks' partial grafcets move only when step "
        "COMPUTE_FUNCTION_BLOCKS_on of the partial grafcet COMPUTE_FUNCTION_BLOCKS (the action stored) is active or "
        "Idle is active after the scan")
    assert not any("COMPUTE_FUNCTION_BLOCKS (the blocks" in w for w in imported(R_TRIG)[1])  # Idle waits for a block


needs_plc = pytest.mark.skipif(find_beremiz() is None or find_iec2c() is None or shutil.which("gcc") is None,
                               reason="Beremiz (SYNTH_BEREMIZ, SYNTH_BEREMIZ_PYTHON), iec2c and gcc are not here")
LD = (DATA / "beremiz_ld_fbd.xml").read_text().replace('<contact localId="21" height="15" width="21" negated="false">',
                                                      '<contact localId="21" height="15" width="21" negated="false" '
                                                      'edge="rising">').replace('name="On"', 'name="Lit"').replace(
    '<pou name="lamp"', '<pou name="lamps"')
"""LD contacts ↑a and NOT b (Beremiz adds an R_TRIG for the edge), a NOT in a named FBD transition (step On
renamed Lit: ON is a word of MATIEC's; the POU lamps: LAMP is its output and MATIEC's names ignore case)."""
STEP_FLAG = project({"R_TRIG0": "R_TRIG", "TON0": "TON"}, "21.Q", "20.Q", invar(10, "btn"), invar(11, "Idle.X"),
                    invar(12, "T#30ms"), block(20, "R_TRIG", "R_TRIG0", [("CLK", "10")], "Q"),
                    block(21, "TON", "TON0", [("IN", "11"), ("PT", "12")], "Q"))
"""Idle -> Busy once TON0 (IN := Idle.X) has run 30 ms, Busy -> Idle on a rising edge of btn (a
flag of a later step does not compile: MATIEC reads a step flag only after the step's declaration,
and Beremiz writes COMPUTE_FUNCTION_BLOCKS right after the initial step)."""


def test_a_block_reads_a_step_flag_once_the_scans_transitions_have_fired():
    text, warnings = imported(STEP_FLAG)
    idle = "XIdle & !(XIdle & XTON0_q) | XBusy & XR_TRIG0_q"
    assert text.split("grafcet TON0_TON {\n")[1].split("}")[0] == f"""  initial step TON0_off
  step TON0_timing
  step TON0_q
  transition TON0_off -> TON0_timing when ({idle})
  transition TON0_timing -> TON0_off when !({idle})
  transition TON0_timing -> TON0_q when ({idle}) & 30ms/XTON0_timing
  transition TON0_q -> TON0_off when !({idle})
"""
    assert warnings[2] == ("b.xml:93:13: warning: the TON TON0 reads XIdle, which MATIEC updates before it calls the "
                           f"block: read as step Idle once the scan's transitions have fired, {idle}")


F_TRIG = R_TRIG.replace("R_TRIG", "F_TRIG")
RS = SR.replace('typeName="SR"', 'typeName="RS"').replace('<derived name="SR"/>', '<derived name="RS"/>').replace(
    'formalParameter="S1"', 'formalParameter="S"').replace('formalParameter="R"', 'formalParameter="R1"')
FIXTURES = {"R_TRIG": R_TRIG, "SR": SR, "TON": TON, "LD": LD, "FIRST": FIRST, "F_TRIG": F_TRIG, "RS": RS,
            "STEP_FLAG": STEP_FLAG}


def test_an_f_trig_and_an_rs_latch():
    text, _ = imported(F_TRIG)
    assert text.startswith(CHART % ("XF_TRIG0_q", "!go") + "grafcet F_TRIG0_F_TRIG {\n  initial step F_TRIG0_off\n")
    assert [line.split(" -> ") for line in text.splitlines() if line.startswith("  transition F_")] == [
        ["  transition F_TRIG0_off", "F_TRIG0_hi when btn"], ["  transition F_TRIG0_hi", "F_TRIG0_q when !btn"],
        ["  transition F_TRIG0_q", "F_TRIG0_hi when btn"], ["  transition F_TRIG0_q", "F_TRIG0_off when !btn"]]
    text, warnings = imported(RS)
    assert text.endswith("  transition SR0_off -> SR0_on when btn & !go\n  transition SR0_on -> SR0_off when go\n}\n")
    assert warnings[0].endswith("(SR0.Q1 is XSR0_on: set when btn & !go, reset when go, reset dominant)")


def test_an_edge_contact_is_the_r_trig_beremiz_adds():
    text, warnings = imported(LD)
    assert text.split("grafcet R_TRIG21_R_TRIG {")[0].endswith(
        "  transition Idle -> Lit when (XR_TRIG21_q) & !b\n  transition Lit -> Idle when XNOT42_on\n}\n")
    assert "  transition R_TRIG21_off -> R_TRIG21_q when a\n" in text
    assert warnings[0].startswith("b.xml:75:13: warning: the rising edge of a (an R_TRIG Beremiz adds) in a transition "
                                  "network of a file written by Beremiz")
    negated = LD.replace('negated="false" edge="rising"', 'negated="true" edge="rising"')
    assert "  transition Idle -> Lit when (!(a)) & !b\n" in imported(negated)[0]  # Beremiz: NOT(a), the edge ignored


def on_plc(xml: str, g7: str, folder: Path) -> Outcome:
    """The program Beremiz builds from ``xml`` against ``synth run --semantics sfc`` of ``g7``."""
    g = parse_grafcet(g7, "b.g7")
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "b.xml").write_text(xml)
    text = beremiz_text(folder / "b.xml", folder / "generated.st")
    assert "COMPUTE_FUNCTION_BLOCKS(S);" in text
    names = {n: n for n in (*g.inputs, *g.outputs)}
    steps = {s.name: s.name for s in g.steps if "_" not in s.name}  # the chart's, not the blocks'
    return play(g, PlcProgram(text, re.findall(r'<pou name="(\w+)"', xml)[0], PouKind.PROGRAM, names, steps), folder,
                range(SEQUENCES), SCANS)


@needs_plc
@pytest.mark.parametrize("name", FIXTURES)
def test_on_the_plc_the_blocks_evolve_as_their_partial_grafcets(name, tmp_path):
    xml = FIXTURES[name]
    g7 = import_sfc(xml.encode(), "b.xml")
    out = on_plc(xml, g7, tmp_path)
    assert [d.text() for d in out.differences] == [] and out.scans == SEQUENCES * SCANS
    g = parse_grafcet(g7, "b.g7")
    # fired by the first scan, before the scans counted (FIRST: seeds 1, 3, 4 and 8 start with go, leave Idle at
    # once and stay in Busy, the blocks never called, on the PLC as in the .g7)
    first_scan = {"TON": ["TON0_off->TON0_timing"],
                  "FIRST": ["COMPUTE_FUNCTION_BLOCKS_off->COMPUTE_FUNCTION_BLOCKS_on"],
                  "STEP_FLAG": ["TON0_timing->TON0_off"]}.get(name, [])  # STEP_FLAG: Idle is left once TON0 is out
    assert [t.name for t in g.transitions if t not in out.fired] == first_scan


@needs_plc
def test_on_the_plc_the_reading_called_while_the_transition_is_evaluated_differs(tmp_path):
    """The harness sees the old reading of a Beremiz file (R_TRIG as ↑btn, the latch guarded by its step)."""
    for name in ("R_TRIG", "SR"):
        out = on_plc(FIXTURES[name], import_sfc(as_codesys(FIXTURES[name]).encode(), "b.xml"), tmp_path / name)
        assert len(out.differences) >= SEQUENCES // 2, name


@needs_plc
@pytest.mark.parametrize("name, exact, plain, seeds", [
    # the blocks' moves from the first scan: the 4 sequences that start with go (seeds 1, 3, 4, 8) leave Idle at
    # once; the PLC then never calls R_TRIG0, the .g7 would
    ("FIRST", "(XCOMPUTE_FUNCTION_BLOCKS_on | XIdle & !(XIdle & go) | XBusy & XR_TRIG0_q) & ", "", [1, 3, 4, 8]),
    # Idle.X read before the scan's transitions fire: TON0 starts a scan late after each return to Idle
    ("STEP_FLAG", "(XIdle & !(XIdle & XTON0_q) | XBusy & XR_TRIG0_q)", "XIdle", list(range(SEQUENCES))),
])
def test_on_the_plc_each_correction_is_needed(name, exact, plain, seeds, tmp_path):
    g7 = import_sfc(FIXTURES[name].encode(), "b.xml")
    assert exact in g7
    out = on_plc(FIXTURES[name], g7.replace(exact, plain), tmp_path)
    assert [d.seed for d in out.differences] == seeds
