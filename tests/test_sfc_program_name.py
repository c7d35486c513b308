"""synth sfc's PROGRAM name never equals a name the program declares (IEC 61131-3 ignores
case: MATIEC refuses ``PROGRAM clamp`` declaring ``CLAMP``, found exporting the example line's
press station)."""

from __future__ import annotations

import pytest
from conftest import ROOT

from synth.codegen.plcopen.export import sfc_project_xml
from synth.codegen.plcopen.importer import import_sfc
from synth.errors import InputError
from synth.grafcet.language_check import load_grafcet, parse_grafcet

CLAMP = ROOT / "lines" / "example" / "grafcets" / "clamp.g7"


def test_a_default_name_equal_to_an_output_gets_a_suffix():
    xml = sfc_project_xml(load_grafcet(CLAMP), version="test").decode()
    assert '<pou name="clamp_1" pouType="program">' in xml and '<variable name="CLAMP">' in xml
    text = import_sfc(xml, "c.xml")
    assert "(POU clamp_1)" in text.splitlines()[0] and "outputs CLAMP, PRESS, RAISE" in text
    assert parse_grafcet(text, "c.g7").outputs == ("CLAMP", "PRESS", "RAISE")


def test_a_given_name_equal_to_a_step_is_refused_at_the_option():
    g = parse_grafcet("inputs a\ngrafcet G { initial step 0 step 1 transition 0 -> 1 when a transition 1 -> 0 "
                      "when !a }", "g.g7")
    assert '<pou name="G" pouType="program">' in sfc_project_xml(g, name="G", version="test").decode()
    with pytest.raises(InputError) as err:
        sfc_project_xml(g, name="s1", version="test")
    assert err.value.render().splitlines()[0] == (
        "--name:1:1: error: the program name s1 is also the name of a variable or step of the chart (IEC 61131-3 "
        "ignores case)")
