"""The .g7 language: parsing into the frozen model, and located errors."""

from __future__ import annotations


import pytest

from synth.errors import InputError, InputErrors
from synth.logic.expr import Edge, Var, names
from synth.grafcet.language import (
    CONDITIONAL,
    CONTINUOUS,
    ON_ACTIVATION,
    ON_DEACTIVATION,
    ON_EVENT,
    STORED,
    receptivity_inputs,
)
from synth.grafcet.language_check import load_grafcet, parse_grafcet

from conftest import ROOT

TRI_INPUTS = ("dcy", "v10", "v11", "v20", "v21", "v30", "v31", "v40", "v41", "cp11", "cp12")
TRI_OUTPUTS = ("TAPIS", "AVANCER1", "RECULER1", "AVANCER2", "RECULER2", "AVANCER3", "AVANCER4")


def err(text: str, **kw) -> InputError:
    with pytest.raises(InputError) as info:
        parse_grafcet(text, "t.g7", **kw)
    return info.value


# --------------------------------------------------------------------------- parsing


def test_full_syntax_model():
    g = parse_grafcet(
        """
        inputs a, b, c   # comment
        outputs A, B, M
        grafcet G1 {
          initial step 0
          step 1: A, B if a . !b, set M on activation
          step 2: reset M on deactivation, set M on ↑c
          transition t1: 0 -> 1, 2 when ↑a
          transition (4): 1, 2 -> 0 when /b + c   // AND convergence
        }
        """,
        "t.g7",
    )
    assert g.inputs == ("a", "b", "c")
    assert g.outputs == ("A", "B", "M")
    assert [p.name for p in g.grafcets] == ["G1"]
    assert g.initial_steps == ("0",)
    s1 = g.step("1")
    assert [(a.kind, a.order) for a in s1.actions] == [(CONTINUOUS, "A"), (CONDITIONAL, "B"), (STORED, "M")]
    assert s1.actions[1].condition.text() == "a & !b"
    assert (s1.actions[2].value, s1.actions[2].when) == (True, ON_ACTIVATION)
    s2 = g.step("2")
    assert [(a.value, a.when) for a in s2.actions] == [(False, ON_DEACTIVATION), (True, ON_EVENT)]
    assert s2.actions[1].text() == "set M on ↑c"
    t1, t4 = g.transitions
    assert (t1.name, t1.sources, t1.targets, t1.grafcet) == ("t1", ("0",), ("1", "2"), "G1")
    assert (t4.name, t4.sources, t4.targets) == ("(4)", ("1", "2"), ("0",))
    assert t4.receptivity.text() == "!b | c"
    assert (t1.loc.line, t1.loc.column) == (8, 22)


def test_ascii_and_unicode_spellings_are_equal():
    a = parse_grafcet("grafcet G { initial step 0 step 1 transition 0 -> 1 when ^x . _y + ~z * w }")
    b = parse_grafcet("grafcet G { initial step 0 step 1 transition 0 → 1 when ↑x & ↓y | ¬z and w }")
    c = parse_grafcet("grafcet G { initial step 0 step 1 transition 0 -> 1 when ↑x ∧ ↓y or not z & w }")
    assert a.transitions[0].receptivity == b.transitions[0].receptivity == c.transitions[0].receptivity
    assert a.transitions[0].receptivity.text() == "↑x & ↓y | !z & w"


def test_step_variables_timers_and_dots():
    g = parse_grafcet(
        """grafcet G { initial step 103 step 101 step 102
             transition 103 -> 101 when X103.v21.v11
             transition 101 -> 102 when 2s/X101 + 1.50s/X101 + 500ms/X101 }"""
    )
    r0 = g.transitions[0].receptivity
    assert r0.text() == "X103 & v21 & v11"
    assert [n.name for n in names(r0)] == ["X103", "v21", "v11"]
    r1 = g.transitions[1].receptivity
    assert [n.name for n in names(r1)] == ["2s/X101", "1.5s/X101", "500ms/X101"]
    assert all(isinstance(n, Var) for n in names(r1))
    assert [(t.id, t.step, t.seconds) for t in g.timers] == [
        ("500ms/X101", "101", 0.5),
        ("1.5s/X101", "101", 1.5),
        ("2s/X101", "101", 2.0),
    ]
    assert g.inputs == ("v21", "v11")  # inferred: step variables and timers are not inputs
    assert receptivity_inputs(g.transitions[0]) == ("v21", "v11")
    assert receptivity_inputs(g.transitions[0], g.inputs) == ("v21", "v11")
    assert receptivity_inputs(g.transitions[1], g.inputs) == ()


def test_inferred_inputs_and_outputs_in_order_of_appearance():
    g = parse_grafcet(
        "grafcet G { initial step 0 step 1: B, A if z  transition 0 -> 1 when ↑y . x transition 1 -> 0 when !x }"
    )
    assert g.inputs == ("y", "x", "z")
    assert g.outputs == ("B", "A")
    assert g.read_inputs == ("y", "x", "z")


def test_plant_inputs_and_outputs_take_precedence():
    g = parse_grafcet("grafcet G { initial step 0 step 1: TAPIS transition 0 -> 1 when dcy }",
                      inputs=TRI_INPUTS, outputs=TRI_OUTPUTS)
    assert g.inputs == TRI_INPUTS and g.outputs == TRI_OUTPUTS
    assert g.read_inputs == ("dcy",)


def test_source_and_sink_transitions():
    g = load_grafcet(ROOT / "grafcets/source_sink.g7")
    t_in, t_out = g.transitions
    assert (t_in.name, t_in.sources, t_in.targets) == ("in", (), ("1",))
    assert (t_out.name, t_out.sources, t_out.targets) == ("out", ("1",), ())
    assert t_in.receptivity == Edge(True, "arrive")


def test_tri_grafcet_loads_with_the_plant():
    from synth.plant.rules_check import load_rules

    rs = load_rules(ROOT / "plants/tri.rules")
    g = load_grafcet(ROOT / "grafcets/tri.g7", inputs=rs.inputs, outputs=rs.outputs)
    assert [p.name for p in g.grafcets] == ["G1", "G2", "G3", "G4"]
    assert g.initial_steps == ("0", "100", "200", "300")
    assert len(g.steps) == 2 + 13 + 3 + 3
    assert len(g.transitions) == 2 + 14 + 3 + 3
    assert [t.id for t in g.timers] == ["2s/X101", "2s/X111"]
    assert g.step("103").actions[0].order == "AVANCER2"
    m = load_grafcet(ROOT / "grafcets/tri_missing_order.g7", inputs=rs.inputs, outputs=rs.outputs)
    assert m.step("103").actions == ()
    assert len(m.transitions) == len(g.transitions)


# --------------------------------------------------------------------------- errors


def test_syntax_error_located_with_expected_tokens():
    e = err("grafcet G {\n  initial step 0\n  transition 0 -> when a b\n}\n")
    assert e.render().splitlines() == [
        "t.g7:3:26: error: syntax error: unexpected 'b'",
        "  3 |   transition 0 -> when a b",
        "    |                          ^",
        "  = expected & (and), 'initial', 'step', 'transition', a comparison (>= <= = <> < >), | (or), }",
    ]


def test_unknown_step_with_suggestion():
    e = err("grafcet G {\n  initial step 10\n  step 11\n  transition 10 -> 12 when a\n}")
    assert str(e.location) == "t.g7:4:20"
    assert e.message == "unknown step 12"
    assert e.suggestions == ("11", "10")


def test_duplicate_step_across_grafcets():
    e = err("grafcet G1 { initial step 0 }\ngrafcet G2 { initial step 0 }")
    assert e.message == "step 0 is declared twice"
    assert str(e.location) == "t.g7:2:27"
    assert "t.g7:1:27" in e.notes[0]


def test_unknown_variable_with_declared_inputs():
    e = err("inputs dcy, v10\ngrafcet G { initial step 0 step 1 transition 0 -> 1 when dcx . v10 }")
    assert e.message == "unknown variable 'dcx'"
    assert (e.location.line, e.location.column, e.location.width) == (2, 58, 3)
    assert e.suggestions == ("dcy",)


def test_unknown_variable_with_a_plant():
    e = err("grafcet G { initial step 0 step 1 transition 0 -> 1 when cp13 }", inputs=TRI_INPUTS, outputs=TRI_OUTPUTS)
    assert e.message == "unknown variable 'cp13' (not an input of the plant)"
    assert e.suggestions == ("cp12", "cp11")


def test_step_variable_of_a_missing_step():
    e = err("grafcet G { initial step 0 step 1 transition 0 -> 1 when a . X12 }")
    assert e.message == "X12 refers to step 12, which does not exist"
    assert e.suggestions == ("X1",)
    assert e.location.column == 62


def test_timer_of_a_missing_step():
    e = err("grafcet G { initial step 0 step 1 transition 0 -> 1 when 2s/X7 }")
    assert e.message == "timer 2s/X7 refers to step 7, which does not exist"


def test_order_that_is_not_an_output():
    e = err("outputs TAPIS, AVANCER1\ngrafcet G { initial step 0 step 1: TAPIS, AVANCR1 transition 0 -> 1 when a }")
    assert e.message == "'AVANCR1' is not an output (declared)"
    assert e.suggestions == ("AVANCER1",)
    e = err("grafcet G { initial step 0 step 1: TAPI transition 0 -> 1 when dcy }", inputs=TRI_INPUTS, outputs=TRI_OUTPUTS)
    assert e.message == "'TAPI' is not an output (of the plant)"
    assert e.suggestions == ("TAPIS",)


def test_partial_grafcet_without_initial_step_is_an_error():
    e = err("grafcet G {\n  step 0\n  step 1\n  transition 0 -> 1 when a\n}")
    assert e.message == "partial grafcet G has no initial step"
    assert str(e.location) == "t.g7:1:9"
    # a source transition is enough
    parse_grafcet("grafcet G { step 1 transition -> 1 when ↑a transition 1 -> when ↑b }")


def test_other_checks():
    assert err("grafcet G1 { initial step 0 step 1 }\ngrafcet G2 { initial step 5 transition 5 -> 1 when a }").message == (
        "step 1 belongs to grafcet G1; a transition links steps of its own grafcet"
    )
    assert err("grafcet G { initial step 0 step 1: A if ↑a transition 0 -> 1 when a }").message == (
        "an edge is not allowed in a condition of an action; write a level"
    )
    assert err("grafcet G { initial step 0 step 1: set M on a transition 0 -> 1 when a }").message == (
        "the event of 'set M on a' has no edge: it would never occur"
    )
    assert err("grafcet G { initial step 0 step 1 transition 0 -> 1 when 2 }").message == "a constant must be 0 or 1, not 2"
    assert err("grafcet G { initial step 0 step 1 transition 0 -> 1 when ↑X0 }").message == (
        "edges of step variables are not supported: ↑X0"
    )
    assert err("grafcet G { initial step 0 step 1: A, set A transition 0 -> 1 when a }").message == (
        "output A is set/reset by stored actions and also assigned here"
    )
    assert err("").message == "no grafcet in this file"


def test_several_errors_are_reported_together():
    with pytest.raises(InputErrors) as info:
        parse_grafcet("grafcet G { initial step 0 step 1 transition 0 -> 2 when a transition 1 -> 0 when X9 }", "t.g7")
    assert [e.message for e in info.value.errors] == [
        "unknown step 2",
        "X9 refers to step 9, which does not exist",
    ]


@pytest.mark.parametrize(
    "name, message",
    [
        ("syntax", "syntax error: unexpected 'b'"),
        ("unknown_step", "unknown step 12"),
        ("duplicate_step", "step 0 is declared twice"),
        ("unknown_variable", "unknown variable 'dcx'"),
        ("missing_step_variable", "X12 refers to step 12, which does not exist"),
        ("not_an_output", "'AVANCR1' is not an output (declared)"),
        ("no_initial_step", "partial grafcet G has no initial step"),
    ],
)
def test_bad_files(name: str, message: str):
    with pytest.raises(InputError) as info:
        load_grafcet(ROOT / "grafcets/bad" / f"{name}.g7")
    assert info.value.message == message
    assert info.value.location.file.endswith(f"{name}.g7")


def test_unreadable_file():
    with pytest.raises(InputError) as info:
        load_grafcet(ROOT / "grafcets/nope.g7")
    assert info.value.message.startswith("cannot read")
