"""PLCopen TC6 XML: written files valid against the shipped XSD, SFC round trips keep the ASS,
an IDE-style SFC imports, what .g7 cannot represent is a located error."""

from __future__ import annotations

from pathlib import Path

import pytest

from synth.codegen.grafcet_st import generate_program, grafcet_program, synth_version
from synth.codegen.plcopen.export import sfc_project_xml, st_project_xml
from synth.codegen.plcopen.importer import import_sfc
from tc6schema import validation_errors
from synth.errors import InputError
from synth.grafcet.ass import stable_situation_automaton
from synth.grafcet.language_check import load_grafcet, parse_grafcet
from synth.grafcet.machine import GrafcetMachine
from synth.output.summary import ass_json

from conftest import ROOT

BUNDLED = [p for p in sorted(ROOT.glob("grafcets/*.g7")) + sorted(ROOT.glob("tests/data/**/*.g7"))
           if "codegen" not in p.parts and p.name != "source_sink.g7"]
DATA = ROOT / "tests/data/codegen"


def _ass(g) -> dict | str:
    try:
        return ass_json(stable_situation_automaton(GrafcetMachine(g), initial_inputs={n: False for n in g.inputs}))
    except InputError as err:
        return err.message


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: str(p.relative_to(ROOT)))
def test_sfc_round_trip_keeps_the_ass_and_the_xml_is_valid(path: Path):
    g = load_grafcet(path)
    xml = sfc_project_xml(g, version="test")
    assert validation_errors(xml) == []
    text = import_sfc(xml, "x.xml")
    back = parse_grafcet(text, "x.g7")
    assert _ass(back) == _ass(g)
    assert [s.name for s in back.steps] == [s.name for s in g.steps]
    assert [(t.sources, t.targets) for t in back.transitions] == [(t.sources, t.targets) for t in g.transitions]


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: str(p.relative_to(ROOT)))
def test_st_program_as_plcopen_xml_is_valid(path: Path):
    xml = st_project_xml(generate_program(load_grafcet(path), version="test").pous, name="p", version="test")
    assert validation_errors(xml) == []
    assert xml.count(b"<pou ") == 1 and b"<ST>" in xml


def test_source_and_sink_transitions_have_no_sfc(tmp_path, capsys):
    from synth.cli.main import main

    out = tmp_path / "s.xml"
    assert main(["sfc", str(ROOT / "grafcets/source_sink.g7"), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "source_sink.g7:4:14: error: a source transition cannot be written as IEC 61131-3 SFC" in err
    assert not out.exists()


def test_written_xml_is_deterministic_and_has_no_time_of_day():
    g = load_grafcet(ROOT / "grafcets/tri.g7")
    a, b = sfc_project_xml(g, version="0.1.0"), sfc_project_xml(load_grafcet(ROOT / "grafcets/tri.g7"), version="0.1.0")
    assert a == b
    assert b'creationDateTime="2000-01-01T00:00:00"' in a


def test_sfc_mapping_of_divergences_timers_edges_and_actions():
    g = parse_grafcet("""grafcet G { initial step 0 step 1: A step 2: B if !c step 3: set M on ↑p, reset M on deactivation
      transition t1: 0 -> 1, 2 when ↑go
      transition 1, 2 -> 3 when 2s/X1 . X2
      transition 3 -> 0 when c
      transition 3 -> 1 when !c }""", "g.g7")
    xml = sfc_project_xml(g, version="test").decode()
    assert xml.count("<simultaneousDivergence ") == 1 and xml.count("<simultaneousConvergence ") == 1
    assert xml.count("<selectionDivergence ") == 1 and xml.count("<selectionConvergence ") == 1
    assert "<![CDATA[_RE_go]]>" in xml
    # Beremiz writes the convergence from step 1, before step 2: X2 is read from step 2's mirror
    assert "<![CDATA[(S1.T >= T#2s) AND _X_S2]]>" in xml
    assert '<variable name="_X_S2">' in xml and '<reference name="_X_S2"/>' in xml
    assert xml.count('qualifier="N"') == 4  # A, B if !c, set M on ↑p, the mirror of step 2
    assert "<![CDATA[B := NOT c;]]>" in xml
    assert "<![CDATA[IF _RE_p THEN M := TRUE; END_IF;]]>" in xml
    assert "<![CDATA[M := FALSE;]]>" in xml and 'qualifier="P0"' in xml
    text = import_sfc(xml.encode(), "g.xml")
    assert text.splitlines()[4:] == [
        "grafcet G {",
        "  initial step 0",
        "  step 1: A",
        "  step 2: B if !c",
        "  step 3: set M on ↑p, reset M on deactivation",
        "  transition t1: 0 -> 1, 2 when ↑go",
        "  transition 1, 2 -> 3 when 2s/X1 & X2",
        "  transition 3 -> 0 when c",
        "  transition 3 -> 1 when !c",
        "}",
    ]


def test_an_sfc_written_by_a_plc_ide_imports():
    path = DATA / "ide_sfc.xml"
    assert validation_errors(path.read_bytes()) == []
    text = import_sfc(path.read_bytes(), "tests/data/codegen/ide_sfc.xml")
    assert text == f"""# Imported by synth {synth_version()} from tests/data/codegen/ide_sfc.xml (POU Press): PLCopen SFC.
inputs start, top, bottom, guard
outputs DOWN, UP, LAMP, BUSY

grafcet G1 {{
  initial step Init: reset BUSY
  step Down: DOWN, set BUSY
  step Lamp: LAMP if !bottom
  step Wait
  step Up: UP
  transition GoDown: Init -> Down, Lamp when start & top & !guard
  transition AtBottom: Down, Lamp -> Wait when bottom
  transition Wait -> Up when 2s/XWait
  transition Wait -> Up when (guard) & !(2s/XWait)
  transition AtTop: Up -> Init when top
}}
"""
    g = parse_grafcet(text, "press.g7")
    assert (len(g.steps), len(g.transitions), g.timers[0].id) == (5, 5, "2s/XWait")


def _edit(old: str, new: str) -> bytes:
    text = (DATA / "ide_sfc.xml").read_text()
    assert old in text
    return text.replace(old, new, 1).encode()


@pytest.mark.parametrize("old, new, first", [
    ('<jumpStep localId="24" targetName="Init" height="10" width="10">',
     '<macroStep localId="25" name="Sub"><position x="1" y="1"/></macroStep><jumpStep localId="24" targetName="Init">',
     "x.xml:195:13: error: unsupported SFC element <macroStep> (a macro-step): .g7 cannot represent it"),
    ('<action localId="22" qualifier="N">', '<action localId="22" qualifier="SD" duration="T#1s">',
     "x.xml:187:15: error: action qualifier SD (stored and timed) cannot be represented in .g7: a .g7 timer belongs "
     "to a step, not to a stored action"),
    ("<![CDATA[Wait.t >= T#2s]]>", "<![CDATA[Wiat.X AND top]]>",
     "x.xml:164:107: error: unknown step 'Wiat'"),
    ("<![CDATA[bottom]]>", "<![CDATA[bottom AND (top]]>",
     "x.xml:147:130: error: expected ')' in an ST condition"),
    ('targetName="Init"', 'targetName="Int"', "x.xml:195:13: error: jump to unknown step 'Int'"),
    ("<project xmlns", "<project xmlns:a='x' xmlns", None),
    ("</types>", "</typos>", "x.xml:208:11: error: not well-formed XML: Opening and ending tag mismatch: types line 18 and typos"),
])
def test_what_g7_cannot_represent_is_a_located_error(old, new, first):
    data = _edit(old, new)
    if first is None:  # harmless edits import
        import_sfc(data, "x.xml")
        return
    with pytest.raises(InputError) as info:
        import_sfc(data, "x.xml")
    rendered = info.value.render().splitlines()
    assert rendered[0] == first
    assert "^" in rendered[2] or first.startswith("x.xml:208")


def test_the_caret_points_at_the_unknown_step():
    with pytest.raises(InputError) as info:
        import_sfc(_edit("<![CDATA[Wait.t >= T#2s]]>", "<![CDATA[Wiat.X AND top]]>"), "x.xml")
    lines = info.value.render().splitlines()
    assert lines[2].index("^") - lines[1].index("Wiat.X") == 0
    assert lines[3:] == ["  = did you mean Wait or Init?"]


def test_a_file_without_sfc_or_not_plcopen():
    with pytest.raises(InputError) as info:
        import_sfc(b"<project xmlns='http://www.plcopen.org/xml/tc6_0201'><types><pous><pou name='P' pouType='program'>"
                   b"<body><ST><p>x</p></ST></body></pou></pous></types></project>", "p.xml")
    assert info.value.render().splitlines()[0] == "p.xml:1:1: error: no POU with an SFC body in this file"
    with pytest.raises(InputError) as info:
        import_sfc(b"<html/>", "h.xml")
    assert info.value.render().splitlines()[0] == "h.xml:1:1: error: not a PLCopen TC6 XML project (root element html)"


def test_named_conditions_and_negated_conditions_import():
    data = _edit('<condition><inline name="AtTop"><ST><xhtml:p xmlns:xhtml="http://www.w3.org/1999/xhtml">'
                 '<![CDATA[top]]></xhtml:p></ST></inline></condition>',
                 '<condition negated="true"><reference name="NotTop" /></condition>')
    text = data.decode().replace(
        "        <body>\n          <SFC>",
        "        <transitions>\n          <transition name=\"NotTop\">\n            <body><ST><xhtml:p xmlns:xhtml="
        "\"http://www.w3.org/1999/xhtml\"><![CDATA[NotTop := NOT top;]]></xhtml:p></ST></body>\n"
        "          </transition>\n        </transitions>\n        <body>\n          <SFC>", 1)
    assert validation_errors(text.encode()) == []
    g7 = import_sfc(text.encode(), "x.xml")
    assert "  transition Up -> Init when !(!top)" in g7.splitlines()
    assert parse_grafcet(g7, "x.g7").transitions[-1].receptivity.text() == "!!top"


def test_steps_that_would_share_an_sfc_name_are_a_located_error():
    g = parse_grafcet("grafcet G { initial step 12  step S12  transition 12 -> S12 when a }", "s.g7")
    with pytest.raises(InputError) as info:
        sfc_project_xml(g, version="test")
    assert info.value.render().splitlines()[0] == "s.g7:1:35: error: steps 12 and S12 would both be the SFC step S12"


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: str(p.relative_to(ROOT)))
def test_each_converging_branch_has_its_own_connection_point(path: Path):
    """As the TC6 example and Beremiz wire them (issue 22): Beremiz silently dropped an AND
    convergence, and everything after it, when one connectionPointIn held several connections."""
    from lxml import etree

    g = load_grafcet(path)
    root = etree.fromstring(sfc_project_xml(g, version="test"))
    ns = {"t": "http://www.plcopen.org/xml/tc6_0201"}
    convergences = root.findall(".//t:selectionConvergence", ns) + root.findall(".//t:simultaneousConvergence", ns)
    branches = sum(len(t.sources) for t in g.transitions if len(t.sources) > 1)
    branches += sum(len(in_) for in_ in ([t for t in g.transitions if s.name in t.targets] for s in g.steps) if len(in_) > 1)
    points = [cp for c in convergences for cp in c.findall("t:connectionPointIn", ns)]
    assert len(points) == branches
    assert all(len(cp.findall("t:connection", ns)) == 1 for cp in points)
