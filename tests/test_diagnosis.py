"""The verdict cascade of :mod:`synth.validation.diagnosis`, one small plant and Grafcet
per verdict (and per branch where a verdict has two wordings): exact trace, verdict and
summary of the single blocking situation."""

from __future__ import annotations

import pytest

from synth.validation.diagnosis import Verdict
from synth.validation.validate import validate

EA = "element EA { order A = 0  sensor a = 0  ↑A -> ↑a  ↓A -> ↓a }\n"
EB = "element EB { order B = 0  sensor b = 0  ↑B -> ↑b  ↓B -> ↓b }\n"
NOT_BOTH = 'constraint C1 "not both": A & B = 0\n'
GO = "free go = 0\n"

# name: (rules, grafcet, expert, trace, verdict, summary)
CASES = {
    "dead_end": (
        GO + EA,
        "grafcet G { initial step 0 step 1 transition 0 -> 1 when ↑go }",
        False, ["↑go"], Verdict.DEAD_END,
        "no transition leaves the active steps {X1}: the Grafcet stops here and never returns to its initial situation",
    ),
    "prohibited_order": (
        GO + EA + EB + NOT_BOTH,
        "grafcet G { initial step 0 step 1: B step 2: A, B "
        "transition 0 -> 1 when ↑go transition 1 -> 2 when b transition 2 -> 0 when a }",
        False, ["↑go", "↑b"], Verdict.PROHIBITED_ORDER,
        'order A in step 2 prohibited by C1 "not both": transition 2->0 of G awaits a, which needs ↑a, caused by A '
        "(element EA, rule ↑A -> ↑a); SUP forbids ↑A here: wrong control or over-strict constraint",
    ),
    "prohibited_order_expert_blames_constraint": (
        GO + EA + EB + "element F { order C = 0  sensor t = 0 }\n" + NOT_BOTH,
        "grafcet G { initial step 0 step 1: B step 2: A, B "
        "transition 0 -> 1 when ↑go transition 1 -> 2 when b transition 2 -> 0 when t }",
        True, ["↑go", "↑b"], Verdict.PROHIBITED_ORDER,
        'order A prohibited by C1 "not both": the trusted Grafcet emits it and SUP forbids ↑A here, '
        "so the constraint is over-strict",
    ),
    "element_model": (
        GO + "element F { order B = 0  sensor t = 0  sensor u = 0  ↑B [u] -> ↑t }\n",
        "grafcet G { initial step 0 step 1: B transition 0 -> 1 when ↑go transition 1 -> 0 when t }",
        True, ["↑go"], Verdict.ELEMENT_MODEL,
        "element F cannot produce the awaited ↑t: B is emitted and authorised, F is in {B}, and no rule of F "
        "produces ↑t there: an occurrence rule is missing or its guard is wrong (transition 1->0 of G awaits t); "
        "under these orders it does not move",
    ),
    "missing_order": (
        GO + EA,
        "grafcet G { initial step 0 step 1 transition 0 -> 1 when ↑go transition 1 -> 0 when a }",
        False, ["↑go"], Verdict.MISSING_ORDER,
        "missing order A in step 1: transition 1->0 of G awaits a, which needs ↑a; only A causes ↑a "
        "(element EA, rule ↑A -> ↑a) and SUP authorises it here",
    ),
    "missing_order_release": (
        GO + EA,
        "grafcet G { initial step 0 step 1: A step 2: A "
        "transition 0 -> 1 when ↑go transition 1 -> 2 when a transition 2 -> 0 when !a }",
        False, ["↑go", "↑a"], Verdict.MISSING_ORDER,
        "order A must be released in step 2: transition 2->0 of G awaits !a, which needs ↓a; ↓a only follows ↓A "
        "(element EA, rule ↓A -> ↓a) and SUP authorises it here",
    ),
    "livelock": (
        GO + EA,
        "grafcet G { initial step 0 step 1: A step 2 "
        "transition 0 -> 1 when ↑go transition 1 -> 2 when a transition 2 -> 1 when !a }",
        False, ["↑go"], Verdict.LIVELOCK,
        "the Grafcet keeps running through {X1} → {X2} and never returns to a home state: transition 1->2 of G "
        "awaits a, and ↑a occurs with the orders as they are (element EA); if this loop is the intended cycle, "
        'declare its home with --home "X1"',
    ),
    "trap": (
        "free dcy = 0\n" + EA,
        "grafcet G { initial step 0  step 1  step 2: A "
        "transition 0 -> 1 when dcy  transition 1 -> 2 when !dcy  transition 2 -> 1 when dcy }",
        False, ["↑dcy"], Verdict.TRAP,
        "the Grafcet keeps evolving on operator inputs (↓dcy) between {X1}, {X2} but can never return to its "
        "initial situation: a loop with no way out (transition 1->2 of G awaits !dcy)",
    ),
    "unproducible_event": (
        GO + EA + "element F { order B = 0  sensor t = 0 }\n",
        "grafcet G { initial step 0 step 1: B transition 0 -> 1 when ↑go transition 1 -> 0 when t }",
        False, ["↑go"], Verdict.UNPRODUCIBLE_EVENT,
        "awaited event ↑t can never occur: transition 1->0 of G awaits t and element F has no rule producing ↑t",
    ),
    "unproducible_event_from_this_state": (
        GO + "element F { order B = 0  sensor t = 0  sensor u = 0  ↑B [u] -> ↑t }\n",
        "grafcet G { initial step 0 step 1: B transition 0 -> 1 when ↑go transition 1 -> 0 when t }",
        False, ["↑go"], Verdict.UNPRODUCIBLE_EVENT,
        "awaited event ↑t cannot occur from the current state of element F: transition 1->0 of G awaits t",
    ),
    "waiting": (
        GO + EA,
        "grafcet G { initial step 0 step 1 step 4 transition 0 -> 4 when ↑go transition 4 -> 1 when X3 }\n"
        "grafcet H { initial step 2 step 3 transition 2 -> 3 when 0 }",
        False, ["↑go"], Verdict.WAITING,
        "the situation only waits on steps X3, which can no longer become active",
    ),
    "unknown": (
        GO + EA,
        "grafcet G { initial step 0 step 4 transition 0 -> 4 when ↑go transition 4 -> 0 when 0 }",
        False, ["↑go"], Verdict.UNKNOWN,
        "no awaited receptivity can become true and no order change is prohibited",
    ),
}


def test_every_verdict_has_a_case():
    assert {c[4] for c in CASES.values()} == set(Verdict) - {Verdict.NEVER_STARTS}


def test_never_starts(tmp_path):
    """Not the verdict of a blocking state but of the whole Grafcet, with the verdict on
    its initial situation as the cause."""
    (tmp_path / "p.rules").write_text(EA)
    (tmp_path / "g.g7").write_text("grafcet G { initial step 0 step 1: A transition 0 -> 1 when a }")
    v = validate(tmp_path / "g.g7", tmp_path / "p.rules")
    assert v.analysis.blocking == () and not v.passed
    d = v.never_starts
    assert (d.verdict, d.cause) == (Verdict.NEVER_STARTS, Verdict.MISSING_ORDER)
    assert d.summary == (
        "the Grafcet never leaves its initial steps {X0}: missing order A in step 0: transition 0->1 of G awaits a, "
        "which needs ↑a; only A causes ↑a (element EA, rule ↑A -> ↑a) and SUP authorises it here"
    )


@pytest.mark.parametrize("name", CASES)
def test_verdict(tmp_path, name):
    rules, grafcet, expert, trace, verdict, summary = CASES[name]
    (tmp_path / "p.rules").write_text(rules)
    (tmp_path / "g.g7").write_text(grafcet)
    v = validate(tmp_path / "g.g7", tmp_path / "p.rules", expert=expert)
    (b,) = v.analysis.blocking
    assert list(v.analysis.traces[b].events) == trace
    d = v.diagnoses[b]
    assert (d.verdict, d.summary) == (verdict, summary)


def test_an_edge_and_a_level_name_the_missing_order():
    """No single input event makes ``↑dcy & v1`` true with ``v1`` false: the diagnosis looks
    for the fewest changes (``↓dcy``, ``↑v1``, then ``↑dcy``) and blames the order behind
    ``↑v1`` (it said ``unknown``, "waiting on steps" with no step involved)."""
    import json

    from conftest import ROOT
    from schemas import assert_valid
    from synth.output.result import validation_json
    from test_symbolic import validate_symbolic

    g7, rules = ROOT / "tests/data/home/edge_and_level.g7", ROOT / "tests/data/home/cylinder.rules"
    v = validate(g7, rules)
    (d,) = [v.diagnoses[i] for i in v.analysis.blocking]
    assert d.verdict is Verdict.MISSING_ORDER
    assert d.summary.startswith("missing order AVANCER in step 1: transition 1->2 of G awaits ↑dcy & v1, which needs ↑v1")
    assert "it needs ↓dcy, ↑v1 first, then ↑dcy" in d.details[0]
    assert not any("waiting on steps" in line for line in d.details)
    data = validation_json(v)
    assert_valid("validate", data)
    awaited = data["blocking"][0]["diagnosis"]["awaited"][0]
    assert (awaited["events"], awaited["first"], awaited["then"]) == ([], ["↓dcy", "↑v1"], "↑dcy")
    assert json.dumps(validation_json(validate_symbolic(g7, rules)), ensure_ascii=False) == json.dumps(data, ensure_ascii=False)


def test_an_input_with_the_initial_steps_timer_names_the_missing_order():
    """``v1 & 2s/X0``: on the initial state the timer has not elapsed, so no input event
    alone makes it true; read once time has passed, ``↑v1`` does, and AVANCER is missing."""
    from conftest import ROOT

    v = validate(ROOT / "tests/data/home/timer_and_level.g7", ROOT / "tests/data/home/cylinder.rules")
    assert v.never_starts is not None
    assert v.never_starts.summary.startswith(
        "the Grafcet never leaves its initial steps {X0}: missing order AVANCER in step 0: "
        "transition 0->1 of G awaits v1 & 2s/X0, which needs ↑v1")
